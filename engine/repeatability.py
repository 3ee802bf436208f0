"""Repeatability test of an IK algorithm on a closed task-space path (paper, sec. 5.2.1, Table 1).

An algorithm is repeatable when closed paths in the task space give closed paths in the joint
space. The extended Jacobian inverse (11) is repeatable by design; the pseudoinverse (8) is not.

:func:`repeatability` is the one loop over cycles and legs in jik: a batch runs it for a map of
starts, and an interactive caller (the dashboard) for one start, with a
:class:`jik.engine.progress.Progress` that sees every leg as it ends, hears a cancellation
between legs (and between the pieces of a long discrete leg) and the progress within such a leg,
and decides whether a leg that raises ends the run or the error propagates. A :class:`Resume`
given as the start goes on with more cycles from the end of a run the caller already has.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .exceptions import InvalidInputError, JikError, format_vector
from .exports import plural
from .inverses import Inverse
from .picard_guesses import cycle_guesses
from .progress import Progress, check_cancelled, check_progress, stops_at
from .repeatability_result import RepeatabilityResult
from .results import BatchSolveResult, SolveResult, Trajectory
from .run_settings import Resume, RunSettings, inverse_fingerprint, resumed_legs
from .solve_chunks import solve_in_chunks
from .solve_rules import (
    check_inverse,
    check_map_value,
    check_settings,
    run_bytes,
)
from .solver import solve, solve_batch
from .validation import FloatArray, as_numbers, check_memory, count, flag

#: A run is called repeatable when its joints come back to x0 within this after every cycle
#: (‖x − x0‖ in the joint coordinates' own units): the API's verdict and the dashboard's.
REPEATABLE_DRIFT = 1e-6
#: Largest number of cycles and of path points accepted.
MAX_CYCLES = 1000
MAX_PATH_POINTS = 100
#: The path is closed by a return leg to k(x0) when its last point is farther than this.
CLOSE_TOL = 1e-12
#: With a ``progress``, a discrete leg of one start runs as solves of at most this many
#: iterations (:func:`jik.engine.solve_chunks.solve_in_chunks`: the same iterates), between which a
#: cancellation is heard and the leg's progress told.
POLL_ITERATIONS = 80


@dataclass(frozen=True)
class Leg:
    """One leg of a run, as :func:`repeatability` hands it to :meth:`Progress.leg` when it
    ends: eq. (7) from where the leg before ended to the cycle's target ``index``.

    Attributes
    ----------
    cycle, index : int
        The cycle and the leg's place in it, both from 0.
    members : ndarray of int, shape (k,)
        The starts that ran it (those still running), as indices into the batch; [0] for one.
    result : SolveResult or BatchSolveResult
        One start: its SolveResult, with the leg's trajectory (theta from 0) when ``record``.
        A batch: the k members' BatchSolveResult. In continuous mode its ``nit`` counts the
        solver's sweeps and steps, which the leg's guess lowers (one or two where a cold
        :func:`jik.engine.solver.solve` of the same leg takes about ten; see
        :class:`SolveResult`): the same leg, the same x to the sweep tolerance.
    stopped_by : JikError or None
        The error the leg's solve raised, when the progress stopped the run there
        (:attr:`Progress.stop_at_error`); ``result`` is then the leg's start alone (one point,
        ``success=False``).
    """

    cycle: int
    index: int
    members: np.ndarray
    result: SolveResult | BatchSolveResult
    stopped_by: JikError | None = None


def repeatable(drift) -> bool | None:
    """Whether the joints came back to x0 after every cycle that ended: each finite drift
    ||x - x0|| (a :class:`RepeatabilityResult`'s ``drift``, NaN from a failed leg on) below
    :data:`REPEATABLE_DRIFT`; None when no cycle ended (sec. 5.2.1: closed task paths give
    closed joint paths)."""
    d = as_numbers(drift, "drift")
    d = d[np.isfinite(d)]
    return bool(np.all(d < REPEATABLE_DRIFT)) if d.size else None


def closed_path(kinematics, x0: FloatArray, path: FloatArray) -> FloatArray:
    """Legs of one cycle: the path, closed by k(x0) when its last point differs (batched over x0).

    ``path`` is (L, r), shared by all starts, or (n, L, r), one path per start.
    Returns shape (n, L, r) for x0 of shape (n, p).
    """
    with np.errstate(all="ignore"):
        home = np.asarray(kinematics.forward(x0), dtype=float)  # (n, r)
    bad = ~np.all(np.isfinite(home), axis=-1)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        shown = ", ".join(f"{v:.6g}" for v in home[i])
        raise InvalidInputError(
            f"x0: the kinematics are not finite at the start {format_vector(x0[i])}: k(x0) = "
            f"({shown}), which closes the path (the task is undefined there, or overflows); "
            "choose a start where k is finite",
            "x0",
        )
    pts = np.broadcast_to(path, (len(x0), *path.shape[-2:]))
    if np.any(np.linalg.norm(pts[:, -1] - home, axis=-1) > CLOSE_TOL):
        pts = np.concatenate([pts, home[:, None, :]], axis=1)
    return pts


def open_loop(path: FloatArray) -> FloatArray:
    """An atlas's loop (L, r) as the points its cycle's legs go to from path[1] before the leg
    back to k(x): without a last point repeating the first, when more than two remain."""
    closes = len(path) > 2 and np.linalg.norm(path[-1] - path[0]) <= CLOSE_TOL
    return path[:-1] if closes else path


def repeatability(
    inverse: Inverse,
    x0,
    path,
    cycles: int = 1,
    *,
    gamma: float = 1.0,
    mode: str = "continuous",
    tol: float = 1e-10,
    max_iterations: int | None = None,
    record: bool = False,
    close: bool = True,
    progress: Progress | None = None,
) -> RepeatabilityResult:
    """Drive the robot through ``path`` and back to k(x0), ``cycles`` times, each leg by eq. (7).

    Parameters
    ----------
    inverse : Inverse
    x0 : array_like, shape (p,) or (n, p), or Resume
        Start configuration(s); a batch runs every leg as one vectorized solve. A
        :class:`Resume` (cycles already driven from its ``x0``): the run goes on from their end,
        and the result is that of a run from its x0 (``leg_results`` holds the new legs only).
    path : array_like, shape (L, r) or (n, L, r)
        Task points visited in order (one path for all starts, or one per start); k(x0) is
        appended when the last point differs from it.
    cycles : int
        1 to 1000.
    gamma, mode, tol, max_iterations
        As in :func:`jik.engine.solver.solve` (a leg's cap).
    record : bool
        Keep every leg's trajectory (one start only: a batch's record=True is refused).
    close : bool
        False: the legs are the points of ``path`` as given, without the return leg to k(x0)
        (one solve to a target is the run of one such leg).
    progress : Progress, optional
        Told every leg as it ends (:meth:`Progress.leg`, with a :class:`Leg`: the last one too,
        whether it converged or not), asked before every leg whether to go on
        (:meth:`Progress.cancelled`). In discrete mode with one start, each leg runs as solves of
        at most :data:`POLL_ITERATIONS` iterations (the same iterates), between which it is
        asked too and told the leg's progress (:meth:`Progress.advance`, a fraction of 1).
        With one start, a leg whose solve raises a typed error (a map undefined where the leg
        starts, an algorithmic singularity (11) there) ends the run there with what it has
        when ``progress.stop_at_error`` is True; otherwise the error propagates.

    Returns
    -------
    RepeatabilityResult
        A member whose leg fails (singularity, divergence) stops there: ``success`` is False, its
        message names the leg, and its remaining configurations are NaN.

    Raises
    ------
    InvalidInputError
        Bad shapes or settings, coordinates beyond
        :data:`~jik.engine.validation.MAX_COORDINATE` (``error.field`` names the argument), a
        start where k is not finite (``x0``), a :class:`Resume` that is
        not whole cycles of this run or is of another run (its settings: the message names the
        field that differs), or, before any work, starts whose estimated memory
        (:func:`jik.engine.solve_rules.run_bytes`) exceeds
        :data:`jik.engine.validation.MEMORY_LIMIT` (field ``x0``).
    JikError
        A leg's solve raised (a singular start configuration) and the progress, if any, did not
        stop the run there (the map having no value at the start
        (:func:`~jik.engine.solve_rules.check_map_value`, field ``x0``) stops its first
        leg; a batch with such a start is refused).
    RunCancelled
        ``progress.cancelled()`` returned True.
    """
    kin, progress = check_inverse(inverse), check_progress(progress)
    resume = x0 if isinstance(x0, Resume) else None
    x0 = kin.check_start(x0 if resume is None else resume.x0)
    path = kin.check_target(path, "path")
    if path.ndim not in (2, 3) or path.shape[-2] < 1:
        raise InvalidInputError(
            "path must be a list of task points, shape (L, r) with L >= 1", "path"
        )
    if path.shape[-2] > MAX_PATH_POINTS:
        raise InvalidInputError(
            f"path has {path.shape[-2]} points; at most {MAX_PATH_POINTS} allowed", "path"
        )
    cycles, record = count(cycles, "cycles", 1, MAX_CYCLES), flag(record, "record")
    single = x0.ndim == 1
    if record and not single:
        raise InvalidInputError("record: a batch of starts records no trajectories", "record")
    xb = np.atleast_2d(x0)
    if xb.ndim != 2:
        raise InvalidInputError("x0 must be one configuration or a 2-D batch", "x0")
    if path.ndim == 3 and len(path) != len(xb):
        raise InvalidInputError(
            f"{len(path)} paths given for {len(xb)} start configurations", "path"
        )
    mode, gamma, tol, cap = check_settings(mode, gamma, tol, max_iterations)
    if not single and resume is None:  # (one start: its first leg's solve refuses it)
        check_map_value(inverse, xb)
    L = path.shape[-2] + int(flag(close, "close"))  # (at most: k(x0) is added when needed)
    check_memory(
        len(xb),
        run_bytes(kin, cycles, L, mode, record and single, gamma, tol, cap),
        "x0",
        f"starts of a repeatability run ({plural(cycles, 'cycle')} x {plural(L, 'leg')})",
        "run them in smaller batches, with fewer cycles, or as an atlas streamed by iter_atlas",
    )
    chunked = progress is not None and mode == "discrete" and single
    if close:
        targets = closed_path(kin, xb, path)  # (n, L, r)
    else:
        targets = np.broadcast_to(path, (len(xb), *path.shape[-2:]))
    n, L = targets.shape[:2]
    legs = np.full((n, cycles * L, kin.p), np.nan)
    stopped_at = np.full((n, kin.p), np.nan)  # (where a failed leg stopped)
    alive = np.ones(n, dtype=bool)
    messages = ["repeatability run completed"] * n
    current = xb.copy()
    leg_results: list[SolveResult] = []
    # One start in continuous mode: each leg starts its Picard sweeps from a guess
    # (cycle_guesses). Batches do without: a guess is per member.
    guided = single and mode == "continuous"
    guides: list[Trajectory | None] = [None] * L
    settings: dict[str, Any] = {
        "gamma": gamma,
        "mode": mode,
        "tol": tol,
        "max_iterations": max_iterations,
    }
    run = RunSettings(
        inverse.name,
        repr(inverse),
        inverse_fingerprint(inverse),
        targets[0].copy() if single else targets.copy(),
        mode,
        gamma,
        tol,
        max_iterations,
    )
    first = 0
    if resume is not None:
        differs = None if resume.settings is None else resume.settings.difference(run)
        if differs is not None:
            raise InvalidInputError(
                f"x0: the Resume is of another run, {differs}; go on only from a run of the "
                "same inverse, path and settings",
                "x0",
            )
        done, given = resumed_legs(resume, n, L, kin.p, cycles)
        first = done.shape[1] // L
        # (legs that did not reach their targets are no run's: 100 tol leaves room for round-off)
        off = np.linalg.norm(kin.forward(done) - np.tile(targets, (1, first, 1)), axis=-1)
        if not np.all(off < 100 * tol):
            bad = np.unravel_index(int(np.argmax(off)), off.shape)
            at = f"{bad[0]}, {bad[1]}" if n > 1 else f"{bad[1]}"
            raise InvalidInputError(
                f"x0: resume.legs are not this run's: resume.legs[{at}] ends {off[bad]:.3g} from "
                "its target (more than 100 tol); go on only from a run of this path",
                "x0",
            )
        legs[:, : first * L] = done
        current = done[:, -1].copy()
        guides = given or guides
    for c in range(first, cycles):
        if not alive.any():
            break
        guesses = []
        if guided:
            guesses = cycle_guesses(inverse, current[0], targets[0], guides, gamma, cap)
        for j in range(L):
            ids = np.flatnonzero(alive)
            if ids.size == 0:
                break
            where = f"cycle {c + 1}, leg {j + 1}"
            check_cancelled(progress, f"repeatability run cancelled before {where}")
            stopped = None
            try:
                if chunked:  # (one start, with a progress)
                    res: SolveResult | BatchSolveResult = solve_in_chunks(
                        inverse,
                        current[0],
                        targets[0, j],
                        chunk=POLL_ITERATIONS,
                        gamma=gamma,
                        tol=tol,
                        max_iterations=max_iterations,
                        record=record,
                        between=_between(progress, f"in {where}"),
                    )
                elif single:  # (a SolveResult: its trajectory guides the next cycle's leg)
                    res = solve(
                        inverse,
                        current[0],
                        targets[0, j],
                        record=record or guided,
                        guess=guesses[j] if guided else None,
                        **settings,
                    )
                else:  # (current[ids] is (k, p): a BatchSolveResult)
                    res = solve_batch(
                        inverse, current[ids], targets[ids, j], record=False, **settings
                    )
            except JikError as exc:
                if not (single and stops_at(progress, exc)):
                    raise
                res = _stopped_leg(inverse, current[0], targets[0, j], exc, mode, gamma, record)
                stopped = exc
            why: Sequence[str]
            if isinstance(res, SolveResult):
                xs, ok, why = res.x[None], np.array([res.success]), (res.message,)
                if guided and res.success:
                    guides[j] = res.trajectory
                if record:
                    leg_results.append(res)
            else:
                xs, ok, why = res.x, res.success, res.message
            current[ids] = xs
            legs[ids, c * L + j] = xs
            for k in np.flatnonzero(~ok):
                alive[ids[k]] = False
                messages[ids[k]] = f"cycle {c + 1}, leg {j + 1} " + (
                    f"stopped: {stopped}" if stopped is not None else f"failed: {why[k]}"
                )
                stopped_at[ids[k]] = xs[k]
                legs[ids[k], c * L + j] = np.nan
            if progress is not None:
                progress.leg(Leg(c, j, ids, res, stopped))
    return RepeatabilityResult.of_run(
        inverse, xb, targets, legs, alive, messages, leg_results, run, stopped_at
    )


def _between(progress, where: str):
    """What runs between two chunks of a discrete leg: the cancellation poll, then progress."""

    def between(fraction: float) -> None:
        check_cancelled(progress, f"repeatability run cancelled {where}")
        progress.advance(fraction, 1.0)

    return between


def _stopped_leg(inverse, x, target, exc, mode, gamma, record) -> SolveResult:
    """A leg whose solve raised ``exc``: its start alone, as the run's last point."""
    x = x.copy()
    y = inverse.kinematics.forward(x)
    error = np.linalg.norm(y - target)
    trajectory = None
    if record:
        h = inverse.augmenting_value(x[None, :])
        h = None if h is None else np.asarray(h)
        trajectory = Trajectory(np.zeros(1), x[None, :], y[None, :], np.array([error]), h)
    return SolveResult(
        x,
        y,
        float(error),
        False,
        str(exc),
        0,
        trajectory,
        mode,
        gamma,
        inverse.name,
        x.copy(),
        np.asarray(target, dtype=float),
        inverse,
        status="raised",
    )
