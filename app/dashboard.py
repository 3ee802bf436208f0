"""Server-side state of the dashboard: one source of truth, recomputed when a control changes.

The page (over ``/api/dashboard/*``) and the viser scene (through its GUI callbacks) both change
the same :class:`Dashboard`; every change is validated against the registry, bumps a generation
counter and wakes one worker thread. The worker drives both algorithms (the pseudoinverse (8) and
the extended inverse (11)) through the legs with :func:`jik.engine.repeatability.repeatability`,
whose hooks let a newer change cancel a stale computation between legs, builds the figures once
and pushes them to every subscriber (server-sent events for the page, a callback for the scene).

Continuous mode integrates in tau = gamma theta (see :mod:`jik.engine.solver`): x(theta) does not
depend on gamma, so the worker solves at gamma = 1 and divides theta by gamma, and a gamma change
in continuous mode only rescales the theta axis without a new integration.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import logging
import multiprocessing
import multiprocessing.connection
import os
import threading
import time
from collections.abc import Callable, Mapping
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field, replace
from typing import cast

import numpy as np

from jik.app.controls import MAX_DASHBOARD_CYCLES, MODES, controls_message, expand
from jik.engine.exceptions import InvalidInputError, JikError, RunCancelled
from jik.engine.registry import ROBOTS, make_inverse, robot_spec
from jik.engine.repeatability import MAX_PATH_POINTS, Leg, Resume, closed_path, repeatability
from jik.engine.solver import MAX_ITERATIONS, SolveResult, Trajectory
from jik.engine.unicycle import Unicycle
from jik.engine.validation import count, positive

ALGORITHMS = ("pseudoinverse", "extended")
#: One colour per algorithm, used in the scene and in every plot.
COLORS = {"pseudoinverse": "#d62728", "extended": "#1f77b4"}
LABELS = {"pseudoinverse": "pseudoinverse J^P# (8)", "extended": "extended Jacobian J^E# (11)"}
#: Time grid points of one unicycle platform path q(t).
UNICYCLE_TIME_POINTS = 96
DEFAULT_ROBOT = "manipulator2"
log = logging.getLogger("jik.dashboard")


class Cancelled(Exception):
    """A newer change superseded the computation."""


@dataclass(frozen=True)
class DashboardState:
    """Every control of the dashboard (JSON-friendly)."""

    robot: str
    robot_parameters: dict
    augmentation: str
    augmentation_parameters: dict
    gamma: float
    mode: str
    x0: tuple[float, ...]
    task: str  # "path": closed path driven ``cycles`` times; "target": one solve
    target: tuple[float, ...]
    path: tuple[tuple[float, ...], ...]
    cycles: int
    tolerance: float = 1e-10

    def as_dict(self) -> dict:
        return {
            "robot": self.robot,
            "robot_parameters": {
                k: list(v) if isinstance(v, tuple | list) else v
                for k, v in self.robot_parameters.items()
            },
            "augmentation": self.augmentation,
            "augmentation_parameters": dict(self.augmentation_parameters),
            "gamma": self.gamma,
            "mode": self.mode,
            "x0": list(self.x0),
            "task": self.task,
            "target": list(self.target),
            "path": [list(p) for p in self.path],
            "cycles": self.cycles,
            "tolerance": self.tolerance,
        }


def default_state(robot: str = DEFAULT_ROBOT) -> DashboardState:
    """The registry's defaults for ``robot``."""
    spec = robot_spec(robot)
    aug = spec.augmentation(None)
    # A platform (the unicycle) starts with the paper's experiment of sec. 6.2: one target.
    closed = bool(spec.default_path) and not hasattr(spec.build(), "path")
    params: dict[str, object] = {p.name: p.default for p in spec.parameters}
    params.update({v.name: tuple(v.default) for v in spec.vector_parameters})
    return DashboardState(
        robot=spec.name,
        robot_parameters=params,
        augmentation=aug.name,
        augmentation_parameters={p.name: p.default for p in aug.parameters},
        gamma=float(spec.default_gamma),
        mode=spec.default_mode,
        x0=tuple(float(v) for v in spec.default_x0),
        task="path" if closed else "target",
        target=tuple(float(v) for v in spec.default_target),
        path=tuple(tuple(float(v) for v in p) for p in spec.default_path),
        cycles=3 if closed else 1,
    )


def updated_state(state: DashboardState, patch: Mapping[str, object]) -> DashboardState:
    """Apply a partial change and validate the result against the registry.

    ``patch`` is keyed by state fields or by control keys (:func:`jik.app.controls.expand`:
    ``{"x0.1": 0.4}``, ``{"path": "1, 1; 1, 2"}``). Changing ``robot`` starts from that robot's
    defaults; changing ``augmentation`` resets its parameters to their defaults. Nested
    parameter dicts are merged.

    Raises
    ------
    InvalidInputError
        Unknown keys, or any value the registry or the engine rejects; its ``field`` names the
        field (a dotted path).
    """
    patch = expand(state, patch)
    known = set(DashboardState.__dataclass_fields__)
    unknown = set(patch) - known
    if unknown:
        raise InvalidInputError(
            f"unknown dashboard field(s) {sorted(unknown)}; known: {sorted(known)}",
            sorted(unknown)[0],
        )
    if "robot" in patch and patch["robot"] != state.robot:
        if not isinstance(patch["robot"], str) or patch["robot"] not in ROBOTS:
            raise InvalidInputError(
                f"unknown robot {patch['robot']!r}; choose one of {sorted(ROBOTS)}", "robot"
            )
        state = default_state(str(patch["robot"]))
    if "augmentation" in patch and patch["augmentation"] != state.augmentation:
        with _field("augmentation"):
            aug = robot_spec(state.robot).augmentation(str(patch["augmentation"]))
        state = replace(
            state,
            augmentation=aug.name,
            augmentation_parameters={p.name: p.default for p in aug.parameters},
        )
    values: dict = {}
    for key, value in patch.items():
        if key in ("robot", "augmentation"):
            continue
        if key in ("robot_parameters", "augmentation_parameters"):
            if not isinstance(value, Mapping):
                raise InvalidInputError(f"{key} must be an object of parameters", key)
            value = {**getattr(state, key), **dict(value)}
        values[key] = value
    return validate(replace(state, **values))


@contextlib.contextmanager
def _field(name: str):
    """Name ``name`` as the field of an :class:`InvalidInputError` raised within that names
    none (the registry's and the engine's validators name it only in their message)."""
    try:
        yield
    except InvalidInputError as exc:
        if exc.field is None:
            exc.field = name
        raise
    except (TypeError, ValueError) as exc:  # a value of the wrong type (a list for a number)
        raise InvalidInputError(f"{name}: {exc}", name) from None


def validate(state: DashboardState) -> DashboardState:
    """Check every field through the registry and the engine's validators; normalise types.
    Each error names its field (:attr:`InvalidInputError.field`)."""
    spec = robot_spec(state.robot)
    given, given_aug = state.robot_parameters, state.augmentation_parameters
    scalars, vectors = {}, {}
    for p in spec.parameters:
        with _field(f"robot_parameters.{p.name}"):
            scalars[p.name] = p.check(given.get(p.name, p.default))
    for v in spec.vector_parameters:
        with _field(f"robot_parameters.{v.name}"):
            vectors[v.name] = v.check(given.get(v.name, v.default))
    unknown = set(given) - set(scalars) - set(vectors)
    if unknown:
        name = sorted(unknown)[0]
        raise InvalidInputError(f"{spec.name} has no parameter {name!r}",
                                f"robot_parameters.{name}")  # fmt: skip
    with _field("robot_parameters"):
        kin = spec.build(**scalars, **vectors)
    with _field("augmentation"):
        aug = spec.augmentation(state.augmentation)
    aug_params = {}
    for p in aug.parameters:
        with _field(f"augmentation_parameters.{p.name}"):
            aug_params[p.name] = p.check(given_aug.get(p.name, p.default))
    with _field("x0"):
        x0 = kin.check(state.x0, "x0")
        if x0.ndim != 1:
            raise InvalidInputError(f"x0 must be one configuration of length {kin.p}")
    with _field("target"):
        target = kin.check_task(state.target, "target")
        if target.ndim != 1:
            raise InvalidInputError(f"target must be one task point of length {kin.r}")
    if state.task not in ("path", "target"):
        raise InvalidInputError(f"task must be 'path' or 'target', got {state.task!r}", "task")
    with _field("path"):
        path = kin.check_task(state.path, "path") if len(state.path) else np.zeros((0, kin.r))
        if state.task == "path" and (path.ndim != 2 or len(path) < 1):
            raise InvalidInputError("a closed-path task needs at least one path point")
        if len(path) > MAX_PATH_POINTS:
            raise InvalidInputError(
                f"path has {len(path)} points; at most {MAX_PATH_POINTS} allowed"
            )
    if state.mode not in MODES:
        raise InvalidInputError(f"mode must be one of {list(MODES)}, got {state.mode!r}", "mode")
    with _field("gamma"):
        gamma = positive(state.gamma, "gamma")
        if state.mode == "discrete" and gamma >= 2:
            raise InvalidInputError(f"gamma must be < 2 in discrete mode, got {gamma:g}")
    with _field("cycles"):
        cycles = count(state.cycles, "cycles", 1, MAX_DASHBOARD_CYCLES)
    with _field("tolerance"):
        tolerance = positive(state.tolerance, "tolerance")
    return DashboardState(
        robot=spec.name,
        robot_parameters={**scalars, **vectors},
        augmentation=aug.name,
        augmentation_parameters=aug_params,
        gamma=gamma,
        mode=state.mode,
        x0=tuple(float(v) for v in x0),
        task=state.task,
        target=tuple(float(v) for v in target),
        path=tuple(tuple(float(v) for v in p) for p in path),
        cycles=cycles,
        tolerance=tolerance,
    )


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
    platform : ndarray, shape (m, T, 3) or None
        Unicycle only: the platform path q(t) for the controls of every iteration.
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
    platform: np.ndarray | None = None


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


def _leg_targets(kin, state: DashboardState) -> np.ndarray:
    if state.task == "target":
        return np.asarray([state.target])
    return closed_path(kin, np.asarray([state.x0]), np.asarray(state.path))[0]


#: Discrete mode runs in chunks of this many iterations, so that a newer change cancels it.
CHUNK = 80


def _run_legs(
    inverse, state, targets, cycles, progress, cancelled, partial, resume=None
) -> AlgorithmRun:
    """Drive ``inverse`` through the legs by :func:`jik.engine.repeatability.repeatability`,
    keeping every point of every leg (its ``on_leg``) with theta cumulative over the legs.

    ``resume``: a successful run of fewer cycles of the same legs, whose cycles are kept; the
    engine goes on from its end with its last cycle's legs as Picard guides (the numbers of a
    run from the start). Discrete legs run in chunks of :data:`CHUNK` iterations, between which
    ``cancelled`` is polled and ``partial`` told the leg's progress. A leg whose solve raises (a
    map undefined where it starts) stops this algorithm; the other one is still shown.
    """
    t0 = time.perf_counter()
    x0 = np.asarray(state.x0)
    continuous = state.mode == "continuous"
    L = len(targets)
    parts = []  # (theta, x, y, error, h, leg index) of every leg
    offset, last, failure = 0.0, "", ""  # (the last leg's message; what stopped the run)
    earlier = None
    if resume is not None:
        parts.append((resume.theta, resume.x, resume.y, resume.error, resume.h, resume.leg))
        offset = float(resume.theta[-1])
        done = (len(resume.drift) - 1) * L  # (the legs before its last cycle)
        guides = [_leg_trajectory(resume, done + j) for j in range(L)] if continuous else []
        earlier = Resume(resume.leg_end, guides)

    def on_leg(leg: Leg) -> None:
        nonlocal offset, last, failure
        res = cast(SolveResult, leg.result)  # (one start, recorded)
        tr = cast(Trajectory, res.trajectory)
        parts.append((tr.theta + offset, tr.x, tr.y, tr.error, tr.h, leg.cycle * L + leg.index))
        offset += float(tr.theta[-1])
        where = f"cycle {leg.cycle + 1}, leg {leg.index + 1}"
        if leg.stopped_by is not None:
            failure = f"{where} stopped: {leg.stopped_by}"
        elif not res.success:
            failure = f"{where}: {_leg_message(res)}"
        else:
            last = _leg_message(res)
        progress()

    path, close = (state.path, True) if state.task == "path" else (targets, False)
    try:
        run = repeatability(
            inverse, x0, path, cycles, gamma=1.0 if continuous else state.gamma, mode=state.mode,
            tol=state.tolerance, record=True, close=close, resume=earlier, on_leg=on_leg,
            cancelled=cancelled, chunk=None if continuous else CHUNK, on_chunk=partial,
            on_undefined="stop",
        )  # fmt: skip
    except RunCancelled:
        raise Cancelled from None
    ends = run.legs[np.isfinite(run.legs).all(axis=1)]
    cycle_ends = ends[L - 1 :: L] if state.task == "path" else []
    drift = [float(np.linalg.norm(e - x0)) for e in cycle_ends]
    return AlgorithmRun(
        algorithm=inverse.name,
        theta=np.concatenate([p[0] for p in parts]),
        x=np.concatenate([p[1] for p in parts]),
        y=np.concatenate([p[2] for p in parts]),
        error=np.concatenate([p[3] for p in parts]),
        h=None if parts[0][4] is None else np.concatenate([p[4] for p in parts]),
        leg=np.concatenate([np.broadcast_to(p[5], len(p[0])) for p in parts]),
        leg_end=ends,
        drift=np.asarray(drift),
        success=bool(run.success),
        message=failure or _legs_message(len(ends), drift, last),
        seconds=time.perf_counter() - t0,
    )


def _leg_message(res: SolveResult) -> str:
    """A leg's message; a discrete leg's in the dashboard's words (iterations, not tol)."""
    if res.mode == "continuous":
        return res.message
    if res.success:
        return f"converged: task error {res.error:.3g} after {res.nit} iterations"
    if res.nit == MAX_ITERATIONS:  # (the engine's cap, which the dashboard keeps)
        return (
            f"did not converge within {res.nit} iterations (error {res.error:.3g}); "
            "raise gamma or move the start"
        )
    return res.message


def _leg_trajectory(run: AlgorithmRun, k: int) -> Trajectory | None:
    """Leg ``k`` of a run as a trajectory (theta from the leg's start), None if not there."""
    at = run.leg == k
    if np.count_nonzero(at) < 2:
        return None
    return Trajectory(theta=run.theta[at] - run.theta[at][0], x=run.x[at], y=run.y[at],
                      error=run.error[at], h=None if run.h is None else run.h[at])  # fmt: skip


def _legs_message(legs: int, drift, last_message: str) -> str:
    """The message of a successful run of ``legs`` legs."""
    if legs == 1:
        return last_message
    return f"{legs} legs converged" + (
        f", drift after cycle {len(drift)}: {drift[-1]:.3g}" if len(drift) else ""
    )


def first_cycles(run: AlgorithmRun, cycles: int, legs: int) -> AlgorithmRun:
    """The first ``cycles`` cycles of a successful closed-path run of ``legs`` legs a cycle:
    what a run of that many cycles gives (see :func:`_run_legs`)."""
    keep = run.leg < cycles * legs
    drift = run.drift[:cycles]
    return replace(
        run, theta=run.theta[keep], x=run.x[keep], y=run.y[keep], error=run.error[keep],
        h=None if run.h is None else run.h[keep], leg=run.leg[keep],
        leg_end=run.leg_end[: cycles * legs], drift=drift,
        message=_legs_message(cycles * legs, drift, run.message), seconds=0.0,
    )  # fmt: skip


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
    """One algorithm through ``cycles`` cycles of the legs to ``targets`` (see :func:`compute`);
    for the unicycle with the platform paths q(t) of its iterates. ``kin``: the state's
    kinematics when the caller has built it; ``resume``: see :func:`_run_legs`."""
    spec = robot_spec(state.robot)
    kin = spec.build(**state.robot_parameters) if kin is None else kin
    inverse = make_inverse(
        kin, algorithm, state.augmentation, state.augmentation_parameters, spec.name
    )
    run = _run_legs(inverse, state, targets, cycles, progress, cancelled, partial, resume)
    if hasattr(kin, "path"):
        t = np.linspace(0.0, float(cast(Unicycle, kin).T), UNICYCLE_TIME_POINTS)
        run = replace(run, platform=kin.path(run.x, t))
    return run


# Each lane's newest generation, which the offload processes compare theirs against (set by
# _offload_init): lane k is one dashboard session's.
_newest_generation = None


def _offload_init(newest) -> None:
    global _newest_generation
    _newest_generation = newest
    # Leave with the server, however it ends (a killed server would leave this process behind).
    parent = multiprocessing.parent_process()
    if parent is not None:
        sentinel = parent.sentinel

        def watch() -> None:
            multiprocessing.connection.wait([sentinel])
            os._exit(0)

        threading.Thread(target=watch, name="jik-offload-parent", daemon=True).start()


def _offload_ready() -> bool:
    return True  # importing this module (numpy, the engine) is the warm-up


def _offload_run(lane, state, algorithm, targets, cycles, generation, resume=None) -> AlgorithmRun:
    def cancelled() -> bool:
        return _newest_generation is not None and _newest_generation[lane] > generation

    return algorithm_run(state, algorithm, targets, cycles, cancelled=cancelled, resume=resume)


#: Most lanes (dashboard sessions) one :class:`Offload` serves at once.
MAX_LANES = 1024


class Offload:
    """Processes that the dashboards share for their computation (spawned, first come first
    served).

    :func:`compute` runs the pseudoinverse here and the extended inverse in its own thread at the
    same time: on two cores a change costs the slower of the two instead of their sum. Each
    dashboard takes a :meth:`lane`; a newer change in that dashboard cancels its offloaded run
    between legs through the lane's generation counter in shared memory. If a process dies, the
    run is redone in the calling thread and the pool is started anew.

    Parameters
    ----------
    workers : int
        Processes in the pool.
    """

    def __init__(self, workers: int = 1) -> None:
        self._context = multiprocessing.get_context("spawn")  # (the server has threads: no fork)
        self._newest = self._context.Array("q", MAX_LANES, lock=False)
        self._free = list(range(MAX_LANES - 1, -1, -1))
        self._workers = workers
        self._lock = threading.Lock()
        self._pool = self._start()

    def _start(self) -> ProcessPoolExecutor:
        pool = ProcessPoolExecutor(
            max_workers=self._workers, mp_context=self._context, initializer=_offload_init,
            initargs=(self._newest,),
        )  # fmt: skip
        for _ in range(self._workers):
            pool.submit(_offload_ready)  # start and import now, not on the first change
        return pool

    def lane(self) -> OffloadLane:
        """A lane for one dashboard (:class:`OffloadLane`; close it when the dashboard stops)."""
        with self._lock:
            if not self._free:
                raise RuntimeError(f"all {MAX_LANES} lanes of the dashboards' pool are taken")
            lane = self._free.pop()
        self._newest[lane] = 0
        return OffloadLane(self, lane)

    def _release(self, lane: int) -> None:
        with self._lock:
            self._newest[lane] = 0
            self._free.append(lane)

    def _restart(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)
        self._pool = self._start()

    def _submit(self, job) -> Future:
        with self._lock:
            try:
                return self._pool.submit(job)
            except (BrokenProcessPool, RuntimeError):  # died, or shut down after a death
                self._restart()
                return self._pool.submit(job)

    def _result(self, future: Future, fallback: Callable[[], AlgorithmRun]) -> AlgorithmRun:
        try:
            return future.result()
        except BrokenProcessPool:
            log.warning("a dashboard compute process died; restarting the pool")
            with self._lock:
                self._restart()
            return fallback()

    def close(self) -> None:
        with self._lock:
            self._pool.shutdown(wait=False, cancel_futures=True)


class OffloadLane:
    """One dashboard's way into an :class:`Offload`: its runs, and their cancellation."""

    def __init__(self, offload: Offload, lane: int) -> None:
        self._offload = offload
        self._lane = lane

    def newest(self, generation: int) -> None:
        """The dashboard's newest generation: its older offloaded runs stop at their next leg."""
        self._offload._newest[self._lane] = generation

    def submit(self, state, algorithm, targets, cycles, generation, resume=None) -> Future:
        """Run :func:`algorithm_run` there (``resume``: see :func:`algorithm_run`)."""
        job = functools.partial(
            _offload_run, self._lane, state, algorithm, targets, cycles, generation, resume
        )
        return self._offload._submit(job)

    def result(self, future: Future, fallback: Callable[[], AlgorithmRun]) -> AlgorithmRun:
        """The offloaded run (Cancelled and the engine's errors propagate); if the process
        died, ``fallback()`` computes it here."""
        return self._offload._result(future, fallback)

    def close(self) -> None:
        """Give the lane back (the pool goes on serving the other dashboards)."""
        self._offload._release(self._lane)


def _cache_key(state: DashboardState, algorithm: str) -> str:
    d = state.as_dict()
    if algorithm == "pseudoinverse":
        d.pop("augmentation"), d.pop("augmentation_parameters")
    if state.mode == "continuous":
        d.pop("gamma")
    return json.dumps(d, sort_keys=True)


def inert_variables(kin, amap, box: tuple[tuple[float, float], ...], samples: int = 8):
    """Joint variables x_k that neither J nor h nor dh depends on.

    At seeded points of ``box`` (one interval per variable), shifting x_k must leave J, h and dh
    bitwise unchanged (NaN where undefined included): an expression without x_k evaluates the
    same, one that merely cancels it would not and counts as dependent. A slice of h at x_k's
    start value then does not depend on that value, nor do E1 (13) and E2 (18), whose integrands
    are functions of J and dh. Maps that solve a problem per point are not probed (empty set).
    """
    if expensive_map(amap):
        return frozenset()
    lo, hi = np.array(box, dtype=float).T
    X = np.random.default_rng(0).uniform(lo, hi, (samples, len(lo)))

    def probe(x):
        with np.errstate(all="ignore"):
            return (kin.jacobian(x), amap.value_masked(x)[0], amap.gradient_masked(x)[0])

    inert = set()
    try:
        at = probe(X)
        for k in range(len(lo)):
            shifted = X.copy()
            shifted[:, k] += 0.371 * (hi[k] - lo[k])
            again = probe(shifted)
            if all(np.array_equal(a, b, equal_nan=True) for a, b in zip(at, again, strict=True)):
                inert.add(k)
    except (JikError, ValueError, ArithmeticError):  # a map that cannot be probed: all matter
        return frozenset()
    return frozenset(inert)


_inert_cache: dict[str, frozenset[int]] = {}


def state_inert_variables(state: DashboardState) -> frozenset[int]:
    """:func:`inert_variables` of the state's kinematics and map over the robot's x_range
    (cached per robot, map and parameters)."""
    d = state.as_dict()
    keys = ("robot", "robot_parameters", "augmentation", "augmentation_parameters")
    key = json.dumps({k: d[k] for k in keys}, sort_keys=True)
    if key not in _inert_cache:
        kin, amap = kinematics_and_map(state)
        box = robot_spec(state.robot).x_range or ((-1.0, 1.0),) * kin.p
        if len(_inert_cache) >= 64:  # (slider values of l, a, b: keep the recent ones)
            del _inert_cache[next(iter(_inert_cache))]
        _inert_cache[key] = inert_variables(kin, amap, box)
    return _inert_cache[key]


def functionals_key(state: DashboardState) -> str:
    """Everything E1, E2 and their sensitivity depend on (see :func:`error_functionals`).

    On a robot's design region: the robot, the map and the start values of the variables
    outside the region (held fixed) that J, h or dh depends on (:func:`inert_variables`); the path,
    the cycles, gamma and the rest of x0 do not matter. Without a design region the box follows
    the runs: everything they depend on.
    """
    spec = robot_spec(state.robot)
    design = spec.functional_region
    if not design:
        return _cache_key(state, "extended")
    d = state.as_dict()
    inert = state_inert_variables(state)
    fixed = {
        n: d["x0"][k]
        for k, n in enumerate(spec.variable_names)
        if n not in design and k not in inert
    }
    return json.dumps(
        {k: d[k] for k in ("robot", "robot_parameters", "augmentation",
                           "augmentation_parameters")} | {"fixed": fixed},
        sort_keys=True,
    )  # fmt: skip


def runs_key(state: DashboardState) -> tuple[str, ...]:
    """Everything the runs of both algorithms depend on, up to the scale of theta.

    Two states with the same key have the same configurations along the same legs (in
    continuous mode gamma only divides theta, see the module's docstring).
    """
    return tuple(_cache_key(state, a) for a in ALGORITHMS)


def _other_cycles(cache: dict, state: DashboardState, algorithm: str, legs: int):
    """A cached successful run of the same closed path with another number of cycles: the
    closest with more cycles, else the longest with fewer; None if there is none."""
    if state.task != "path" or legs < 2:
        return None
    found = {}
    for c in range(1, MAX_DASHBOARD_CYCLES + 1):
        run = cache.get(_cache_key(replace(state, cycles=c), algorithm))
        if c != state.cycles and run is not None and run.success and run.platform is None:
            found[c] = run
    more = [c for c in found if c > state.cycles]
    if more:
        return found[min(more)]
    return found[max(found)] if found else None


def compute(
    state: DashboardState,
    generation: int = 0,
    *,
    progress: Callable[[float], None] | None = None,
    cancelled: Callable[[], bool] = lambda: False,
    cache: dict | None = None,
    with_augmenting: bool = True,
    offload: OffloadLane | None = None,
    grid_before: dict | None = None,
) -> DashboardResult:
    """Solve the state's task with both algorithms.

    Parameters
    ----------
    progress : callable, optional
        Called with the fraction of legs done, in [0, 1].
    cancelled : callable
        Polled between legs; when it returns True the computation raises :class:`Cancelled`.
    cache : dict, optional
        Runs keyed by everything they depend on (gamma excluded in continuous mode); reused
        and filled.
    with_augmenting : bool
        Evaluate h on a grid for the h panel now (see :func:`augmenting_grid`).
    offload : OffloadLane, optional
        A lane of the shared compute processes: the pseudoinverse runs there, concurrently with
        the extended inverse here (same results).
    grid_before : dict, optional
        The h grid on screen, whose box the new grid keeps when it fits (see
        :func:`augmenting_grid`).

    Raises
    ------
    Cancelled, JikError
        A singular start configuration raises the engine's typed error.
    """
    t0 = time.perf_counter()
    spec = robot_spec(state.robot)
    kin = spec.build(**state.robot_parameters)
    targets = _leg_targets(kin, state)
    cycles = state.cycles if state.task == "path" else 1
    total = 2 * cycles * len(targets)
    cache = {} if cache is None else cache
    keys = {a: _cache_key(state, a) for a in ALGORITHMS}
    todo = [a for a in ALGORITHMS if keys[a] not in cache]
    # Another number of cycles of the same legs: its first cycles are this run's, or this run
    # goes on from its end (cycles slider: only the new legs are solved).
    other = {a: _other_cycles(cache, state, a, len(targets)) for a in todo}
    for a in [a for a in todo if other[a] is not None and len(other[a].drift) >= cycles]:
        cache[keys[a]] = first_cycles(other[a], cycles, len(targets))
        todo.remove(a)
    done = [(len(ALGORITHMS) - len(todo)) * cycles * len(targets)]  # legs, cached runs included
    done[0] += sum(len(other[a].leg_end) for a in todo if other[a] is not None)

    # With a second process, the pseudoinverse runs there while this thread runs the extended
    # inverse (the two are independent); each local leg then stands for two in the progress.
    remote: Future | None = None
    if offload is not None and len(todo) == 2:
        remote = offload.submit(
            state, "pseudoinverse", targets, cycles, generation, other["pseudoinverse"]
        )
    weight = 1 if remote is None else 2

    def step() -> None:
        done[0] += weight
        if progress is not None:
            progress(min(done[0] / total, 1.0))

    def partial(fraction: float) -> None:
        if progress is not None:
            progress(min((done[0] + weight * float(fraction)) / total, 1.0))

    for algorithm in todo:
        if remote is None or algorithm != "pseudoinverse":
            cache[keys[algorithm]] = algorithm_run(
                state, algorithm, targets, cycles, step, cancelled, partial, kin,
                resume=other[algorithm],
            )  # fmt: skip
    if offload is not None and remote is not None:
        cache[keys["pseudoinverse"]] = offload.result(remote, lambda: algorithm_run(
            state, "pseudoinverse", targets, cycles, cancelled=cancelled, kin=kin,
            resume=other["pseudoinverse"]))  # fmt: skip
    runs: dict[str, AlgorithmRun] = {}
    for algorithm in ALGORITHMS:
        run = cache[keys[algorithm]]
        if state.mode == "continuous":
            run = replace(run, theta=run.theta / state.gamma)
        runs[algorithm] = run
    if len(cache) > 64:
        for k in list(cache)[: len(cache) - 64]:
            del cache[k]
    return DashboardResult(
        state=state,
        generation=generation,
        title=spec.title,
        variable_names=tuple(spec.variable_names),
        task_names=tuple(spec.task_names),
        targets=targets,
        runs=runs,
        time=np.linspace(0.0, float(cast(Unicycle, kin).T), UNICYCLE_TIME_POINTS)
        if hasattr(kin, "path")
        else None,
        augmenting=augmenting_grid(kin, state, runs, before=grid_before)
        if with_augmenting
        else None,
        seconds=time.perf_counter() - t0,
        cached={a: a not in todo for a in ALGORITHMS},
    )


def augmenting_axes(amap, x: np.ndarray) -> tuple[int, int]:
    """The two joint variables h depends on most along the configurations ``x`` (n, p)."""
    with np.errstate(all="ignore"):
        if hasattr(amap, "evaluate"):
            g = np.abs(np.asarray(amap.evaluate(x)[1], dtype=float))
        else:
            g = np.abs(np.asarray(amap.gradient(x), dtype=float))
    weight = np.nan_to_num(np.nanmean(g, axis=0)) * (np.ptp(x, axis=0) + 1.0)
    i, j = sorted(np.argsort(-weight, kind="stable")[:2])
    return int(i), int(j)


def kinematics_and_map(state: DashboardState, kin=None):
    """The state's kinematics (``kin`` when the caller has built it) and its augmenting map h,
    built from the registry."""
    spec = robot_spec(state.robot)
    kin = spec.build(**state.robot_parameters) if kin is None else kin
    return kin, spec.augmentation(state.augmentation).build(kin, **state.augmentation_parameters)


def expensive_map(amap) -> bool:
    """Maps evaluated by solving a problem per point (characteristics): h is computed after
    the runs have been shown, on a coarser grid."""
    return hasattr(amap, "evaluate")


#: The h panel keeps its box while the trajectories fill at least this fraction of it.
BOX_FILL = 0.5


def augmenting_grid(
    kin, state: DashboardState, runs: Mapping[str, AlgorithmRun], n: int = 41,
    before: dict | None = None,
):  # fmt: skip
    """h on a grid over the two variables it depends on most, other variables at x0.

    The box covers both trajectories with a margin, clipped to the robot's x_range. The box of
    ``before`` (the grid on screen) is kept while the trajectories lie inside it and span at
    least :data:`BOX_FILL` of it, like the other panels' axes (``app.figures.keep_ranges``): a
    small change then gives the same grid, often the same h, and the page moves only the
    trajectories. Returns None when h cannot be evaluated on the grid.
    """
    spec = robot_spec(state.robot)
    try:
        _, amap = kinematics_and_map(state, kin)
        xs = np.concatenate([r.x for r in runs.values()])
        i, j = augmenting_axes(amap, xs)
        box = []
        for k in (i, j):
            lo, hi = float(np.min(xs[:, k])), float(np.max(xs[:, k]))
            pad = 0.25 * (hi - lo) + 0.25
            lo, hi = lo - pad, hi + pad
            if spec.x_range:
                lo, hi = max(lo, spec.x_range[k][0]), min(hi, spec.x_range[k][1])
            box.append((lo, hi))
        if expensive_map(amap):
            n = min(n, 15)  # h solves a collocation problem per point
        if before is not None and tuple(before["axes"]) == (i, j) and before["n"] == n:
            inside = all(
                b_lo <= np.min(xs[:, k]) and np.max(xs[:, k]) <= b_hi
                and hi - lo >= BOX_FILL * (b_hi - b_lo)
                for k, (lo, hi), (b_lo, b_hi) in zip((i, j), box, before["box"], strict=True)
            )  # fmt: skip
            if inside:
                box = [tuple(b) for b in before["box"]]
        u, v = np.linspace(*box[0], n), np.linspace(*box[1], n)
        X = np.broadcast_to(np.asarray(state.x0, dtype=float), (n, n, kin.p)).copy()
        X[..., i] = u[None, :]
        X[..., j] = v[:, None]
        with np.errstate(all="ignore"):
            if hasattr(amap, "evaluate"):  # maps that can be undefined at some points
                H = np.asarray(amap.evaluate(X.reshape(-1, kin.p))[0], dtype=float)
            else:
                H = np.asarray(amap.value(X.reshape(-1, kin.p)), dtype=float)
        H = H.reshape(n, n)
    except (JikError, ValueError, ArithmeticError):
        return None
    H = np.where(np.isfinite(H), H, np.nan)
    return {"axes": (i, j), "u": u, "v": v, "h": H, "box": box, "n": n, "map": amap,
            "kinematics": kin}  # fmt: skip


def error_functionals(result: DashboardResult, nodes: int = 12) -> dict | None:
    """E1 (13) and E2 (18) of the current map, or None if unavailable.

    Over the robot's design region from the registry (the boxes of sec. 5, the ones
    ``jik reproduce`` uses) where it has one, so the values do not move with the start point and
    a synthesized map is judged on the box it was built for; else over the heat-map box.
    """
    grid = result.augmenting
    if grid is None:
        return None
    if expensive_map(grid["map"]):
        nodes = min(nodes, 6)
    try:
        from jik.engine.functionals import error_functional_e1, error_functional_e2
    except ImportError:
        return None
    names = result.variable_names
    i, j = grid["axes"]
    design = robot_spec(result.state.robot).functional_region
    region = dict(design) or {names[i]: tuple(grid["box"][0]), names[j]: tuple(grid["box"][1])}
    fixed = {n: float(result.state.x0[k]) for k, n in enumerate(names) if n not in region}
    out = {
        "region": {k: list(v) for k, v in region.items()},
        "fixed": fixed,
        "nodes": nodes,
        "design_region": bool(design),
    }
    for key, fn in (("E1", error_functional_e1), ("E2", error_functional_e2)):
        try:
            value = fn(grid["kinematics"], grid["map"], region, nodes=nodes, fixed=fixed)
            out[key] = value.value if np.isfinite(value.value) else None
            out[f"{key}_singular_points"] = int(value.singular_points.shape[0])
        except (JikError, ValueError, ArithmeticError) as exc:
            out[key] = None
            out[f"{key}_error"] = str(exc)
    return out


#: Values of each parameter in the E1/E2 sweep of the dashboard (over v - 1 .. v + 1).
SENSITIVITY_SAMPLES = 11


def sensitivity(
    result: DashboardResult,
    functionals: dict | None,
    cancelled: Callable[[], bool] = lambda: False,
) -> dict:
    """How E1 (13) and E2 (18) change with the parameters of the current map (issue 5).

    Over the same box and fixed variables as ``functionals`` (see :func:`error_functionals`):

    * a map with parameters (C1, C2 or a, b): ``{"kind": "parameters", "parameters": {...},
      "E1": ..., "E2": ...}``, each from :func:`jik.engine.functionals.parameter_sensitivity`
      (the value, the gradient and a sweep of every parameter over v - 1 .. v + 1);
    * a map without parameters: ``{"kind": "alternatives", "maps": [{"name", "E1", "E2",
      "current"}]}``, the functionals of every map the robot offers, at their defaults;
    * ``{"kind": "unavailable", "reason": ...}`` when they cannot be evaluated here.

    ``cancelled`` is polled before every evaluation of a functional (raises :class:`Cancelled`).
    """
    grid = result.augmenting
    if grid is None:
        return {"kind": "unavailable", "reason": "h could not be evaluated on a grid"}
    if functionals is None:
        return {"kind": "unavailable", "reason": "E1, E2 could not be evaluated"}
    state = result.state
    if expensive_map(grid["map"]):
        return {"kind": "unavailable", "reason": "each value of E1, E2 of this map solves a "
                "collocation problem per node: no sweep in the dashboard"}  # fmt: skip
    if functionals.get("E1") is None and functionals.get("E2") is None:
        return {"kind": "unavailable", "reason": "E1, E2 are undefined on this box"}
    from jik.engine.functionals import (
        error_functional_e1,
        error_functional_e2,
        parameter_sensitivity,
    )

    spec = robot_spec(state.robot)
    kin, nodes, fixed = grid["kinematics"], functionals["nodes"], functionals["fixed"]
    region = {k: tuple(v) for k, v in functionals["region"].items()}
    aug = spec.augmentation(state.augmentation)

    def build(other, **params):
        if cancelled():
            raise Cancelled
        return other.build(kin, **params)

    try:
        if aug.parameters:
            out: dict = {"kind": "parameters", "parameters": dict(state.augmentation_parameters)}
            for key in ("E1", "E2"):
                out[key] = parameter_sensitivity(
                    kin, lambda **p: build(aug, **p), state.augmentation_parameters, region,
                    functional=key.lower(), span=1.0, samples=SENSITIVITY_SAMPLES, nodes=nodes,
                    fixed=fixed,
                )  # fmt: skip
            return out
        maps = []
        for other in spec.augmentations:
            amap = build(other, **{p.name: p.default for p in other.parameters})
            if expensive_map(amap):
                continue
            row: dict = {"name": other.name, "current": other.name == aug.name}
            for key, fn in (("E1", error_functional_e1), ("E2", error_functional_e2)):
                try:
                    v = fn(kin, amap, region, nodes=nodes, fixed=fixed).value
                    row[key] = float(v) if np.isfinite(v) else None
                except (JikError, ValueError, ArithmeticError):
                    row[key] = None
            maps.append(row)
        return {"kind": "alternatives", "maps": maps}
    except (JikError, ValueError, ArithmeticError) as exc:
        return {"kind": "unavailable", "reason": str(exc)}


def robots_catalogue() -> list[dict]:
    """Every robot of the registry with its parameters, ranges and defaults."""
    return [spec.as_dict() for spec in ROBOTS.values()]


@dataclass(frozen=True)
class Event:
    """A message to the subscribers: ``data`` is the JSON sent to the page."""

    kind: str  # "state" | "progress" | "result" | "functionals" | "error" | "ahead"
    generation: int
    data: str
    result: DashboardResult | None = None


def _digest(text: str) -> str:
    return hashlib.md5(text.encode()).hexdigest()[:16]


def _json(obj) -> str:
    return json.dumps(obj, separators=(",", ":"), allow_nan=False, default=_jsonable)


def _with_figures(message: dict, figures: Mapping[str, str]) -> str:
    """The JSON of ``message`` with a "figures" object of already serialized figures."""
    body = ",".join(f'"{k}":{t}' for k, t in figures.items())
    return _json(message)[:-1] + ',"figures":{' + body + "}}"


def _jsonable(v):
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, np.generic):
        return v.item()
    raise TypeError(f"not JSON serialisable: {type(v).__name__}")


def summary(result: DashboardResult) -> dict:
    """Numbers shown beside the plots: per algorithm success, message, drift, final x."""
    out = {}
    for a, run in result.runs.items():
        out[a] = {
            "success": run.success,
            "message": run.message,
            "drift": [float(d) for d in run.drift],
            "x_final": [float(v) for v in run.x[-1]],
            "h_change": None if run.h is None else float(np.max(run.h) - np.min(run.h)),
            "points": len(run.theta),
            "seconds": round(run.seconds, 4),
            "cached": bool(result.cached.get(a, False)),
        }
    return out


#: Robots whose default state the idle dashboard solves ahead (:meth:`Dashboard._prefetch`).
#: Not the unicycle: its ~1 s would hold the CPU that a change made meanwhile needs (its
#: switch shows progress instead).
PREFETCH_ROBOTS = ("manipulator1", "manipulator2")


class Dashboard:
    """One session's live dashboard: one state, a worker thread, and subscribers.

    Parameters
    ----------
    state : DashboardState, optional
        Initial state (registry defaults of :data:`DEFAULT_ROBOT`).
    debounce : float
        Seconds the worker waits after a change for a newer one (short: the page already
        coalesces a slider drag into one request in flight at a time).
    offload : Offload, optional
        Compute processes shared with other dashboards: one algorithm runs there, in this
        dashboard's own lane (:meth:`Offload.lane`); ``jik serve`` gives one.
    """

    def __init__(
        self,
        state: DashboardState | None = None,
        *,
        debounce: float = 0.002,
        offload: Offload | None = None,
    ) -> None:
        self._cond = threading.Condition()
        self._offload = offload.lane() if offload is not None else None
        self._state = validate(state or default_state())
        self._generation = 1
        self._done = 0  # last generation whose computation finished (or failed)
        self._debounce = debounce
        self._changed_at = {1: time.perf_counter()}
        self._listeners: list[Callable[[Event], None]] = []
        self._fast = 0  # the first ``_fast`` listeners are the quick ones
        self._cache: dict = {}
        self._figures: dict[tuple[str, str], str] = {}  # (panel, key) -> figure JSON
        self._layouts: dict[str, tuple[tuple, dict]] = {}  # panel -> (robot, task), last layout
        # Results solved ahead (_prefetch): when each robot's went to the page (the value of
        # _robot_since then), the latest by robot, and since when the robot on screen is
        # (the generation of its first result).
        self._ahead_sent: dict[str, int] = {}
        self._latest_ahead: dict[str, Event] = {}
        self._robot_since = 0
        # key -> (E1/E2 functionals or None, their sensitivity)
        self._functionals_cache: dict[str, tuple[dict | None, dict]] = {}
        self._latest: dict[str, Event] = {
            "state": Event("state", 1, _json(self._state_message(1, self._state, "initial")))
        }
        self.result: DashboardResult | None = None
        self.functionals: dict | None = None
        #: What the 3D scene last drew (set by app.scene), for the page and the tests.
        self.scene_status: dict = {}
        self._thread: threading.Thread | None = None
        self._stopped = False

    # -- public API -------------------------------------------------------------------------
    @property
    def state(self) -> DashboardState:
        return self._state

    @property
    def generation(self) -> int:
        return self._generation

    def start(self) -> None:
        """Start the worker thread (idempotent)."""
        with self._cond:
            if self._thread is None:
                self._thread = threading.Thread(
                    target=self._work, name="jik-dashboard", daemon=True
                )
                self._thread.start()

    def stop(self) -> None:
        with self._cond:
            self._stopped = True
            self._cond.notify_all()
        if self._offload is not None:
            self._offload.close()

    def update(
        self, patch: Mapping[str, object], source: str = "page"
    ) -> tuple[int, DashboardState]:
        """Validate and apply a change; the worker recomputes. Returns (generation, state).

        A change the registry refuses raises :class:`InvalidInputError` and is announced to
        every listener as a ``refused`` event (the page and the scene both show it, and their
        controls go back to the values in force).
        """
        refusal: InvalidInputError | None = None
        with self._cond:
            try:
                state = updated_state(self._state, patch)
            except InvalidInputError as exc:
                refusal = exc
                generation, state = self._generation, self._state
            else:
                if state == self._state:
                    return self._generation, state
                self._state = state
                self._generation += 1
                generation = self._generation
                self._changed_at[generation] = time.perf_counter()
                if self._offload is not None:
                    self._offload.newest(generation)
                self._cond.notify_all()
        if refusal is not None:
            refused = {"type": "refused", "generation": generation, "source": source,
                       "field": refusal.field, "message": str(refusal),
                       "state": state.as_dict(), **controls_message(state)}  # fmt: skip
            self._emit(Event("refused", generation, _json(refused)))
            raise refusal
        self._emit(
            Event("state", generation, _json(self._state_message(generation, state, source)))
        )
        self.start()
        return generation, state

    def subscribe(
        self, listener: Callable[[Event], None], *, last: bool = False
    ) -> Callable[[], None]:
        """Call ``listener(event)`` on every event (from the worker thread); replay the latest.

        ``last``: a slow listener (the 3D scene draws in it) is called after the others, so
        that it does not hold up the events queued for the page.
        """
        with self._cond:
            if last:
                self._listeners.append(listener)
            else:
                self._listeners.insert(self._fast, listener)
                self._fast += 1
            kinds = ("state", "result", "functionals")
            latest = [self._latest[k] for k in kinds if k in self._latest]
            latest += [e for r, e in self._latest_ahead.items() if r != self._state.robot]
        for event in latest:
            listener(event)
        self.start()

        def unsubscribe() -> None:
            with self._cond:
                if listener in self._listeners:
                    if self._listeners.index(listener) < self._fast:
                        self._fast -= 1
                    self._listeners.remove(listener)

        return unsubscribe

    def wait(self, generation: int | None = None, timeout: float = 30.0) -> bool:
        """Block until the computation of ``generation`` (default: current) has finished."""
        self.start()
        deadline = time.monotonic() + timeout
        with self._cond:
            target = self._generation if generation is None else generation
            while self._done < target:
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self._cond.wait(left)
        return True

    def snapshot(self) -> dict:
        """The current state and the summary of the last result."""
        with self._cond:
            result = self.result
            return {
                "generation": self._generation,
                "computed_generation": None if result is None else result.generation,
                "state": self._state.as_dict(),
                "summary": None if result is None else summary(result),
                "functionals": self.functionals,
                "scene": dict(self.scene_status),
            }

    # -- worker -----------------------------------------------------------------------------
    def _state_message(self, generation: int, state: DashboardState, source: str) -> dict:
        return {"type": "state", "generation": generation, "state": state.as_dict(),
                "source": source, **controls_message(state)}  # fmt: skip

    def _emit(self, event: Event) -> None:
        with self._cond:
            if event.kind in ("state", "result", "functionals", "error"):
                self._latest[event.kind] = event
            listeners = list(self._listeners)
        for listener in listeners:
            listener(event)

    def _work(self) -> None:
        while True:
            with self._cond:
                while self._done >= self._generation and not self._stopped:
                    self._cond.wait()
                if self._stopped:
                    return
                # Debounce: wait until no change arrived for ``debounce`` seconds.
                while True:
                    seen = self._generation
                    self._cond.wait(self._debounce)
                    if self._generation == seen or self._stopped:
                        break
                generation, state = self._generation, self._state
            try:
                self._compute(generation, state)
                self._prefetch(generation)
            except Exception as exc:  # keep the worker alive; the page shows the message
                log.exception("dashboard computation failed")
                message = f"internal error: {type(exc).__name__}: {exc}"
                self._emit(Event("error", generation, _json(
                    {"type": "error", "generation": generation, "message": message})))  # fmt: skip
                self._finish(generation)

    def _prefetch(self, generation: int) -> None:
        """While no change comes, solve the other robots' default states into the run cache:
        switching robot starts from those defaults (:func:`updated_state`), so the switch then
        only draws (Manipulator 1: ~90 ms of computation less in the browser test).

        Each is announced by an ``ahead`` event with the figures the switch will show: the
        page draws them off screen and shows them on the switch (when they are the same), the
        3D scene builds the robot's nodes, hidden (from the event's result, given when the
        runs were solved now). A robot is announced again after every switch of robot (the
        page has shown what it drew ahead); meanwhile its figures stay the same (no sticky
        axes or known E1/E2 carry over from another robot) and nothing is done again.

        Only :data:`PREFETCH_ROBOTS`; any change cancels it between legs.
        """
        from jik.app.figures import PANELS

        for robot in PREFETCH_ROBOTS:
            state = default_state(robot)
            if self._generation != generation or self._stopped:
                return
            if robot == self._state.robot:
                continue
            solved = all(_cache_key(state, a) in self._cache for a in ALGORITHMS)
            if solved and self._ahead_sent.get(robot) == self._robot_since:
                continue  # (its figures stay the same while the robot on screen stays)
            try:
                _, amap = kinematics_and_map(state)
                result = compute(
                    state, generation, cancelled=lambda: self._generation != generation,
                    cache=self._cache, with_augmenting=not expensive_map(amap),
                    offload=self._offload,
                )  # fmt: skip
                # The figures as the switch will make them (see _compute; no panel to reuse
                # from another robot).
                cached, stale = self._known_functionals(state)
                functionals, sens = cached or (None, None)
                texts = self._panel_texts(
                    result, functionals, sens, set(PANELS) - stale, remember=False
                )
            except (Cancelled, JikError, ValueError):
                return
            except Exception:  # (work ahead: logged, never shown as the current result's error)
                log.exception("solving %s ahead failed", robot)
                return
            digests = {k: _digest(t) for k, t in texts.items()}
            self._ahead_sent[robot] = self._robot_since
            head = {"type": "ahead", "generation": generation, "robot": robot,
                    "digests": digests}  # fmt: skip
            event = Event(
                "ahead", generation, _with_figures(head, texts), None if solved else result
            )
            with self._cond:
                self._latest_ahead[robot] = event
            self._emit(event)

    def _known_functionals(self, state: DashboardState) -> tuple[tuple | None, set[str]]:
        """E1/E2 and their sensitivity for ``state`` when known (same map, same fixed
        variables), and the panels that wait for the second phase: the E1/E2 panel unless
        known (the page dims it meanwhile instead of redrawing a placeholder, 20-40 ms of its
        redraw)."""
        cached = self._functionals_cache.get(functionals_key(state))
        return cached, (set() if cached else {"sensitivity"})

    def _panel_texts(
        self, result: DashboardResult, functionals, sens, todo: set[str], remember: bool
    ) -> dict[str, str]:
        """The JSON of the panels in ``todo``, with sticky axes (keep_ranges): against the
        layout each panel last went out with, for the same robot and task. ``remember``: these
        panels go out now (a result, not one solved ahead)."""
        from jik.app.figures import figure_json, figure_specs, keep_ranges

        layout_key = (result.state.robot, result.state.task)
        texts = {}
        for k, f in figure_specs(result, functionals, todo, sensitivity=sens).items():
            shown = self._layouts.get(k)
            keep_ranges(f, shown[1] if shown is not None and shown[0] == layout_key else None)
            if remember:
                self._layouts[k] = (layout_key, f["layout"])
            texts[k] = figure_json(f)
        return texts

    def _finish(self, generation: int) -> None:
        with self._cond:
            self._done = max(self._done, generation)
            self._cond.notify_all()

    def _compute(self, generation: int, state: DashboardState) -> None:
        from jik.app.figures import (
            PANELS,
            augmenting_title,
            figure_json,
            figure_specs,
            gamma_free_panels,
        )

        started = self._changed_at.get(generation, time.perf_counter())
        t0 = time.perf_counter()
        last = [0.0]

        def progress(fraction: float) -> None:
            now = time.perf_counter()
            if now - last[0] > 0.1 or fraction >= 1:
                last[0] = now
                self._emit(Event("progress", generation, _json({
                    "type": "progress", "generation": generation, "fraction": fraction,
                    "elapsed": now - t0,
                })))  # fmt: skip

        # The h panel's box stays while it fits (augmenting_grid), for the same robot and task.
        on_screen = self.result
        grid_before = (
            on_screen.augmenting
            if on_screen is not None
            and (on_screen.state.robot, on_screen.state.task) == (state.robot, state.task)
            else None
        )
        try:
            kin, amap = kinematics_and_map(state)
            deferred = expensive_map(amap)
            result = compute(
                state, generation, progress=progress,
                cancelled=lambda: self._generation != generation, cache=self._cache,
                with_augmenting=not deferred, offload=self._offload, grid_before=grid_before,
            )  # fmt: skip
        except Cancelled:
            return
        except (JikError, ValueError) as exc:
            self._emit(Event("error", generation, _json({
                "type": "error", "generation": generation, "message": str(exc)})))  # fmt: skip
            self._finish(generation)
            return
        # Panels that do not depend on gamma are reused from the last result with the same key.
        key = _cache_key(state, "extended")
        reuse = {k for k in gamma_free_panels(result) if (k, key) in self._figures}
        texts = {k: self._figures[(k, key)] for k in reuse}
        cached, stale = self._known_functionals(state)
        todo = set(PANELS) - reuse - stale
        functionals, sens = cached or (None, None)
        texts.update(self._panel_texts(result, functionals, sens, todo, remember=True))
        texts = {k: texts[k] for k in PANELS if k not in stale}
        self._figures = {(k, key): texts[k] for k in gamma_free_panels(result)}
        ready = time.perf_counter()
        head = {
            "type": "result", "generation": generation, "state": state.as_dict(),
            "summary": summary(result), "colors": COLORS, "labels": LABELS,
            "timing": {"compute": result.seconds, "figures": ready - t0 - result.seconds,
                       "server_total": ready - started},
        }  # fmt: skip
        head["digests"] = {k: _digest(t) for k, t in texts.items()}
        head["stale"] = sorted(stale)
        data = _with_figures(head, texts)
        with self._cond:
            if self.result is None or self.result.state.robot != state.robot:
                self._robot_since = generation
            self.result, self.functionals = result, functionals
            self._changed_at = {g: t for g, t in self._changed_at.items() if g > generation}
        self._emit(Event("result", generation, data, result))
        self._finish(generation)
        # Second phase: h on a grid when it is expensive, then E1 and E2 (quadrature), unless a
        # newer change came meanwhile. Known functionals went out with
        # the result: their event only carries the h panel's title (a reused panel can lack it,
        # and a page that connects now gets this event with the latest result).
        known = bool(cached) and not deferred
        if not known:
            if self._generation != generation:
                return
        if deferred:
            grid = augmenting_grid(kin, state, result.runs, before=grid_before)
            if self._generation != generation:
                return
            result = replace(result, augmenting=grid)
            with self._cond:
                self.result = result
        # E1, E2 and their sensitivity depend on what the grid does (not on gamma in
        # continuous mode): reused.
        if cached:
            functionals, sens = cached
        else:
            functionals = error_functionals(result)
            try:
                sens = sensitivity(result, functionals, lambda: self._generation != generation)
            except Cancelled:
                return
            self._functionals_cache = {functionals_key(state): (functionals, sens)}
        if self._generation != generation:
            return
        message = {"type": "functionals", "generation": generation, "functionals": functionals,
                   "sensitivity": sens}  # fmt: skip
        with self._cond:
            self.functionals = functionals
        panels = set() if known else {"sensitivity"}
        if deferred:  # the h panel was a placeholder: the whole figure
            panels.add("augmenting")
        elif functionals is not None:  # h is on screen: only its title changes (no redraw)
            message["titles"] = {"augmenting": augmenting_title(result, functionals)}
        specs = figure_specs(result, functionals, panels, sensitivity=sens)
        redrawn = {k: figure_json(f) for k, f in specs.items()}
        message["digests"] = {k: _digest(t) for k, t in redrawn.items()}
        self._emit(Event("functionals", generation, _with_figures(message, redrawn)))


def export_json(result: DashboardResult, functionals: dict | None = None) -> dict:
    """The current result as plain JSON: the state, and both runs point by point."""
    runs = {}
    for a, run in result.runs.items():
        runs[a] = {
            "success": run.success,
            "message": run.message,
            "theta": run.theta,
            "x": run.x,
            "y": run.y,
            "error": run.error,
            "h": run.h,
            "leg": run.leg,
            "leg_end": run.leg_end,
            "drift": run.drift,
        }
        if run.platform is not None:
            runs[a]["platform_final"] = run.platform[-1]
    return json.loads(_json({
        "robot": result.title, "state": result.state.as_dict(), "generation": result.generation,
        "variable_names": result.variable_names, "task_names": result.task_names,
        "targets": result.targets, "runs": runs, "functionals": functionals,
    }))  # fmt: skip


def export_csv(result: DashboardResult) -> str:
    """One row per trajectory point: algorithm, leg, theta, x..., y..., error, h."""
    names, tasks = result.variable_names, result.task_names
    header = ["algorithm", "leg", "theta", *names, *tasks, "error", "h"]
    lines = [",".join(header)]
    for a, run in result.runs.items():
        h = run.h if run.h is not None else np.full(len(run.theta), np.nan)
        for k in range(len(run.theta)):
            vals = [a, str(int(run.leg[k]) + 1), repr(float(run.theta[k]))]
            vals += [repr(float(v)) for v in run.x[k]] + [repr(float(v)) for v in run.y[k]]
            vals += [repr(float(run.error[k])), "" if np.isnan(h[k]) else repr(float(h[k]))]
            lines.append(",".join(vals))
    return "\n".join(lines) + "\n"
