"""One algorithm driven through the legs of a task, point by point, by the engine's one cycle
loop (:func:`jik.engine.repeatability.repeatability`, legs by eq. (7)), the unicycle's platform
paths of a run (:class:`PlatformPaths`), and the result of every chosen algorithm for one state
(:class:`DashboardResult`)."""

from __future__ import annotations

import functools
import operator
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, cast

import numpy as np

from ...engine.exceptions import RunCancelled
from ...engine.limits import LimitsReport
from ...engine.progress import ProgressCallbacks
from ...engine.repeatability import Leg, Resume, closed_path, repeatability
from ...engine.results import SolveResult, Trajectory
from ...engine.run_settings import RunSettings
from ...engine.stall import reach_note
from ...engine.unicycle import Unicycle
from .controls import max_iterations
from .joint_limits import run_limits
from .model import DashboardState
from .robots import state_inverse, state_kinematics

#: Time grid points of one unicycle platform path q(t).
UNICYCLE_TIME_POINTS = 96
#: Paths kept per run: the task panel and the scene draw a few spaced iterations.
KEPT = 256


class Cancelled(Exception):
    """A newer change superseded the computation."""


class PlatformPaths:
    """q(t) on the time grid ``t`` for the controls of each iteration ``x`` (m, 4) of a run,
    indexed like an array of shape (m, T, 3): ``P[i]``, ``P[i, :, 0]``, ``P[-1]``, ``len(P)``.
    A path is computed (:meth:`jik.engine.unicycle.Unicycle.path`) when its iteration is first
    asked for, and kept (:data:`KEPT` of them): a long discrete run has 10^5 iterations, of
    which a dozen are drawn."""

    def __init__(self, kinematics, x: np.ndarray, t: np.ndarray) -> None:
        self._kinematics, self._x, self._t = kinematics, np.asarray(x), np.asarray(t)
        self._kept: dict[int, np.ndarray] = {}

    def __len__(self) -> int:
        return len(self._x)

    @property
    def shape(self) -> tuple[int, int, int]:
        return len(self._x), len(self._t), 3

    def __getitem__(self, key):
        i, rest = (key[0], key[1:]) if isinstance(key, tuple) else (key, ())
        i = operator.index(i)
        i += len(self) if i < 0 else 0
        if not 0 <= i < len(self):
            raise IndexError(f"iteration {i} of a run of {len(self)}")
        path = self._kept.get(i)
        if path is None:
            path = self._kinematics.path(self._x[i], self._t)
            if len(self._kept) < KEPT:
                self._kept[i] = path
        return path[rest] if rest else path


@dataclass(frozen=True)
class AlgorithmRun:
    """One algorithm driven through every leg of the task, point by point.

    Attributes
    ----------
    theta : ndarray, shape (m,)
        Continuation parameter, cumulative over the legs (iterations in discrete mode).
    x : ndarray, shape (m, p)
    y : ndarray, shape (m, r)
    error : ndarray, shape (m,)
        Distance to the current leg's target.
    h : ndarray, shape (m,) or None
        The augmenting map along the run (extended inverse only).
    leg : ndarray of int, shape (m,)
        Leg index (cycle * legs_per_cycle + leg) of every point.
    leg_end : ndarray, shape (n_legs_done, p)
    drift : ndarray, shape (cycles_done,)
        ||x at the end of cycle c - x0|| (closed-path task only, else empty).
    platform : PlatformPaths or None
        Unicycle only: the platform path q(t) for the controls of every iteration, (m, T, 3),
        computed as drawn.
    status : str
        Why its last leg stopped, the engine's :attr:`~jik.engine.results.SolveResult.status`
        ("converged"; "undefined": its augmenting map h undefined there; ...).
    settings : RunSettings or None
        The engine's record of the inverse, targets and settings of the legs
        (:attr:`jik.engine.results.RepeatabilityResult.settings`): a run going on from this
        one must have the same.
    field : str or None
        The input its first leg's error names (``x0``: a singular start), which the page marks.
    """

    algorithm: str
    theta: np.ndarray
    x: np.ndarray
    y: np.ndarray
    error: np.ndarray
    h: np.ndarray | None
    leg: np.ndarray
    leg_end: np.ndarray
    drift: np.ndarray
    success: bool
    message: str
    seconds: float
    status: str = "converged"
    platform: PlatformPaths | None = None
    settings: RunSettings | None = None
    field: str | None = None


@dataclass(frozen=True)
class DashboardResult:
    """Both runs for one state, with what the figures need to label them."""

    state: DashboardState
    generation: int
    title: str
    variable_names: tuple[str, ...]
    task_names: tuple[str, ...]
    targets: np.ndarray  # (L, r) legs of one cycle
    runs: dict[str, AlgorithmRun]
    time: np.ndarray | None = None  # unicycle time grid [s]
    augmenting: dict | None = None  # h on a grid, see augmenting_grid()
    seconds: float = 0.0
    cached: dict = field(default_factory=dict)

    @functools.cached_property
    def limits(self) -> dict[str, LimitsReport]:
        """Per algorithm, the limits report of its run (:func:`~.joint_limits.run_limits`),
        built once for the verdict's sentence and the summary; empty for a robot without
        limits."""
        reports = {algorithm: run_limits(self, algorithm) for algorithm in self.runs}
        return {a: report for a, report in reports.items() if report is not None}


def leg_targets(kin, state: DashboardState) -> np.ndarray:
    if state.task == "target":
        return np.asarray([state.target])
    return closed_path(kin, np.asarray([state.x0]), np.asarray(state.path))[0]


def algorithm_run(
    state: DashboardState,
    algorithm: str,
    targets: np.ndarray,
    cycles: int,
    progress: Callable[[], None] = lambda: None,
    cancelled: Callable[[], bool] = lambda: False,
    partial: Callable[[float], None] = lambda f: None,
    kin=None,
    resume: AlgorithmRun | None = None,
) -> AlgorithmRun:
    """One algorithm through ``cycles`` cycles of the legs to ``targets`` (see :func:`compute`)
    by :func:`jik.engine.repeatability.repeatability`, keeping every point of every leg (its
    progress's ``leg``) with theta cumulative over the legs; for the unicycle with the platform
    paths q(t) of its iterates. ``kin``: the state's kinematics when the caller has built it.

    ``resume``: a successful run of fewer cycles of the same legs, whose cycles are kept; the
    engine goes on from its end with its last cycle's legs as Picard guides (the numbers of a
    run from the start). Discrete legs run in chunks (the engine's ``POLL_ITERATIONS``), between
    which ``cancelled`` is polled and ``partial`` told the leg's progress. A leg whose solve
    raises (a map undefined where it starts) stops this algorithm; the other one is still shown.
    """
    t0 = time.perf_counter()
    kin = state_kinematics(state) if kin is None else kin
    inverse = state_inverse(state, algorithm, kin)
    x0 = np.asarray(state.x0)
    continuous = state.mode == "continuous"
    cap = max_iterations(state)
    L = len(targets)
    parts: list[tuple] = []  # (theta, x, y, error, h, leg index) of every leg
    offset, last, failure = 0.0, "", ""  # (the last leg's message; what stopped the run)
    start_field: str | None = None
    status = "converged"  # (the last leg's)
    earlier = None
    if resume is not None:
        parts.append((resume.theta, resume.x, resume.y, resume.error, resume.h, resume.leg))
        offset = float(resume.theta[-1])
        done = (len(resume.drift) - 1) * L  # (the legs before its last cycle)
        guides = [_leg_trajectory(resume, done + j) for j in range(L)] if continuous else []
        earlier = Resume(x0, resume.leg_end, guides, resume.settings)

    def on_leg(leg: Leg) -> None:
        nonlocal offset, last, failure, status, start_field
        res = cast(SolveResult, leg.result)  # (one start, recorded)
        status = res.status
        tr = cast(Trajectory, res.trajectory)
        parts.append((tr.theta + offset, tr.x, tr.y, tr.error, tr.h, leg.cycle * L + leg.index))
        offset += float(tr.theta[-1])
        # (a single target's run is one leg: no cycle or leg to name)
        where = "" if state.task == "target" else f"cycle {leg.cycle + 1}, leg {leg.index + 1}"
        if leg.stopped_by is not None:
            failure = f"{where} stopped: {leg.stopped_by}".lstrip()
            if leg.cycle == leg.index == 0:  # (a leg from x0: the error's input is the state's)
                start_field = getattr(leg.stopped_by, "field", None)
        elif not res.success:
            message = _leg_message(res, cap, inverse.kinematics)
            failure = f"{where}: {message}" if where else message
        else:
            last = _leg_message(res, cap, inverse.kinematics)
        progress()

    path, close = (state.path, True) if state.task == "path" else (targets, False)
    try:
        run = repeatability(
            inverse,
            x0 if earlier is None else earlier,
            path,
            cycles,
            gamma=1.0 if continuous else state.gamma,
            mode=state.mode,
            tol=state.tolerance,
            max_iterations=cap,
            record=True,
            close=close,
            progress=ProgressCallbacks(
                on_leg, lambda done, total: partial(done / total), cancelled, stop_at_error=True
            ),
        )
    except RunCancelled:
        raise Cancelled from None
    ends = run.legs[np.isfinite(run.legs).all(axis=1)]
    # (the cycles that ended: a failed leg leaves NaN from there on)
    drift = run.drift[np.isfinite(run.drift)] if state.task == "path" else run.drift[:0]
    out = AlgorithmRun(
        algorithm=inverse.name,
        theta=np.concatenate([p[0] for p in parts]),
        x=np.concatenate([p[1] for p in parts]),
        y=np.concatenate([p[2] for p in parts]),
        error=np.concatenate([p[3] for p in parts]),
        h=None if parts[0][4] is None else np.concatenate([p[4] for p in parts]),
        leg=np.concatenate([np.broadcast_to(p[5], len(p[0])) for p in parts]),
        leg_end=ends,
        drift=drift,
        success=bool(run.success),
        message=failure or _legs_message(len(ends), drift, last),
        seconds=time.perf_counter() - t0,
        status=status,
        settings=run.settings,
        field=start_field,
    )
    t = platform_time(kin)
    return out if t is None else replace(out, platform=PlatformPaths(kin, out.x, t))


def _leg_message(res: SolveResult, cap: int, kinematics) -> str:
    """A leg's message: the engine's (the REST API's), but for a leg stopped by the cap
    (``cap``, :attr:`~jik.engine.results.SolveResult.status` "max_steps"), which names the
    control that sets it, or the target out of reach (:func:`jik.engine.stall.reach_note`)."""
    if res.status == "max_steps":
        what = "iterations" if res.mode == "discrete" else "integrator steps"
        advice, _ = reach_note(kinematics, res.y_d)
        if advice is None:
            nearer = ", take γ nearer 1" if res.mode == "discrete" and res.gamma != 1.0 else ""
            advice = f"raise “max {what} per leg” (a control above){nearer} or move the start"
        return f"did not converge within {cap} {what} (error {res.error:.3g}); {advice}"
    return res.message


def _leg_trajectory(run: AlgorithmRun, k: int) -> Trajectory | None:
    """Leg ``k`` of a run as a trajectory (theta from the leg's start), None if not there."""
    at = _points(run, run.leg == k)
    if len(at["theta"]) < 2:
        return None
    return Trajectory(**{**at, "theta": at["theta"] - at["theta"][0]})


def _points(run: AlgorithmRun, keep: np.ndarray) -> dict[str, Any]:
    """The points ``keep`` (a mask) of a run: its theta, x, y, error and h (None stays None)."""
    arrays = {k: getattr(run, k) for k in ("theta", "x", "y", "error", "h")}
    return {k: None if v is None else v[keep] for k, v in arrays.items()}


def _legs_message(legs: int, drift, last_message: str) -> str:
    """The message of a successful run of ``legs`` legs."""
    if legs == 1:
        return last_message
    return f"{legs} legs converged" + (
        f", drift after cycle {len(drift)}: {drift[-1]:.3g}" if len(drift) else ""
    )


def first_cycles(run: AlgorithmRun, cycles: int, legs: int) -> AlgorithmRun:
    """The first ``cycles`` cycles of a successful closed-path run of ``legs`` legs a cycle:
    what a run of that many cycles gives (see :func:`algorithm_run`)."""
    keep = run.leg < cycles * legs
    drift = run.drift[:cycles]
    return replace(
        run,
        **_points(run, keep),
        leg=run.leg[keep],
        leg_end=run.leg_end[: cycles * legs],
        drift=drift,
        message=_legs_message(cycles * legs, drift, run.message),
        seconds=0.0,
    )


def platform_time(kin) -> np.ndarray | None:
    """The time grid [s] of a platform's (the unicycle's) paths q(t); None for an arm."""
    if not hasattr(kin, "path"):
        return None
    return np.linspace(0.0, float(cast(Unicycle, kin).T), UNICYCLE_TIME_POINTS)


def spaced_iterations(m: int, count: int) -> np.ndarray:
    """About ``count`` geometrically spaced iterations of ``m`` (ascending, each once), the first
    and the last always: the unicycle's platform paths q(t) that the task panel and the scene
    draw, dense at the start where they change most."""
    return np.union1d(np.geomspace(1, m, num=count).astype(int) - 1, [0, m - 1]).astype(int)
