"""Repeatability test of an IK algorithm on a closed task-space path (paper, sec. 5.2.1, Table 1).

An algorithm is repeatable when closed paths in the task space give closed paths in the joint
space. The extended Jacobian inverse (11) is repeatable by design; the pseudoinverse (8) is not.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np

from jik.engine.exceptions import InvalidInputError
from jik.engine.inverses import Inverse
from jik.engine.solver import BatchSolveResult, SolveResult, Trajectory, chain_guesses, solve
from jik.engine.unicycle import Unicycle
from jik.engine.validation import FloatArray, count

#: Largest number of cycles and of path points accepted.
MAX_CYCLES = 1000
MAX_PATH_POINTS = 100
#: The path is closed by a return leg to k(x0) when its last point is farther than this.
CLOSE_TOL = 1e-12


@dataclass(frozen=True)
class RepeatabilityResult:
    """Configurations along a closed path driven ``cycles`` times.

    Attributes
    ----------
    targets : ndarray, shape (L, r) or (n, L, r)
        The task point of every leg of one cycle (the given path, closed by k(x0) if needed).
    legs : ndarray, shape (cycles * L, p) or (n, cycles * L, p)
        Configuration after each leg.
    cycle_end : ndarray, shape (cycles, p) or (n, cycles, p)
    drift : ndarray, shape (cycles,) or (n, cycles)
        ||cycle_end[c] - x0||.
    success : bool or ndarray of bool, shape (n,)
    message : str or tuple of str
    leg_results : list of SolveResult
        Every leg with its trajectory (single start with ``record=True`` only).
    """

    x0: FloatArray
    targets: FloatArray
    legs: FloatArray
    cycle_end: FloatArray
    drift: FloatArray
    success: bool | FloatArray
    message: str | tuple[str, ...]
    leg_results: list[SolveResult]


def closed_path(kinematics, x0: FloatArray, path: FloatArray) -> FloatArray:
    """Legs of one cycle: the path, closed by k(x0) when its last point differs (batched over x0).

    ``path`` is (L, r), shared by all starts, or (n, L, r), one path per start.
    Returns shape (n, L, r) for x0 of shape (n, p).
    """
    home = kinematics.forward(x0)  # (n, r)
    pts = np.broadcast_to(path, (len(x0), *path.shape[-2:]))
    if np.any(np.linalg.norm(pts[:, -1] - home, axis=-1) > CLOSE_TOL):
        pts = np.concatenate([pts, home[:, None, :]], axis=1)
    return pts


def cycle_guesses(
    inverse: Inverse, start, targets, guides: list[Trajectory | None], gamma: float = 1.0
) -> list[Trajectory | None]:
    """Picard guesses for one cycle's legs of a closed path from ``start`` (continuous mode,
    one start): the ``guess`` of each leg's :func:`jik.engine.solver.solve`, eq. (7).

    The extended inverse is repeatable: a leg repeats the same leg of the cycle before, so
    ``guides`` (those legs' trajectories, None in the first cycle) are its guesses, and a leg
    then takes one or two sweeps. The pseudoinverse drifts, so the cycle before saves almost
    nothing: its legs are swept together from ``start`` (:func:`jik.engine.solver.chain_guesses`),
    one or two sweeps a leg instead of about ten, and a cycle's numbers depend only on its
    start. A chain evaluates J# about three times as often as the legs would, so it pays only
    where an evaluation costs little beyond numpy's per-call overhead: not for the unicycle.
    """
    if (
        inverse.name == "pseudoinverse" and len(targets) > 1
        and not isinstance(inverse.kinematics, Unicycle)
    ):  # fmt: skip
        chained = chain_guesses(inverse, start, targets, gamma=gamma)
        if chained is not None:
            return list(chained)
    return list(guides)


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
) -> RepeatabilityResult:
    """Drive the robot through ``path`` and back to k(x0), ``cycles`` times, each leg by eq. (7).

    Parameters
    ----------
    inverse : Inverse
    x0 : array_like, shape (p,) or (n, p)
        Start configuration(s); a batch runs every leg as one vectorized solve.
    path : array_like, shape (L, r) or (n, L, r)
        Task points visited in order (one path for all starts, or one per start); k(x0) is
        appended when the last point differs from it.
    cycles : int
        1 to 1000.
    gamma, mode, tol, max_iterations
        As in :func:`jik.engine.solver.solve`.
    record : bool
        Keep every leg's trajectory (single start only).

    Returns
    -------
    RepeatabilityResult
        A member whose leg fails (singularity, divergence) stops there: ``success`` is False, its
        message names the leg, and its remaining configurations are NaN.
    """
    kin = inverse.kinematics
    x0 = kin.check(x0, "x0")
    path = kin.check_task(path, "path")
    if path.ndim not in (2, 3) or path.shape[-2] < 1:
        raise InvalidInputError("path must be a list of task points, shape (L, r) with L >= 1")
    if path.shape[-2] > MAX_PATH_POINTS:
        raise InvalidInputError(
            f"path has {path.shape[-2]} points; at most {MAX_PATH_POINTS} allowed"
        )
    cycles = count(cycles, "cycles", 1, MAX_CYCLES)
    single = x0.ndim == 1
    xb = np.atleast_2d(x0)
    if xb.ndim != 2:
        raise InvalidInputError("x0 must be one configuration or a 2-D batch")
    if path.ndim == 3 and len(path) != len(xb):
        raise InvalidInputError(f"{len(path)} paths given for {len(xb)} start configurations")
    targets = closed_path(kin, xb, path)  # (n, L, r)
    n, L = targets.shape[:2]
    legs = np.full((n, cycles * L, kin.p), np.nan)
    alive = np.ones(n, dtype=bool)
    messages = ["repeatability run completed"] * n
    current = xb.copy()
    leg_results: list[SolveResult] = []
    # One start in continuous mode: each leg starts its Picard sweeps from a guess
    # (cycle_guesses). Batches do without: a guess is per member.
    guided = single and mode == "continuous"
    guides: list = [None] * L
    for c in range(cycles):
        guesses = cycle_guesses(inverse, current[0], targets[0], guides, gamma) if guided else []
        for j in range(L):
            ids = np.flatnonzero(alive)
            if ids.size == 0:
                break
            # current[ids] is (k, p), so solve returns a batch.
            res = cast(
                BatchSolveResult,
                solve(
                    inverse,
                    current[ids],
                    targets[ids, j],
                    gamma=gamma,
                    mode=mode,
                    tol=tol,
                    max_iterations=max_iterations,
                    record=(record or guided) and single,
                    guess=[guesses[j]] if guided else None,
                ),
            )
            if guided and res.success[0]:
                guides[j] = res.trajectory(0)
            if record and single:
                leg_results.append(res[0])
            current[ids] = res.x
            legs[ids, c * L + j] = res.x
            for k in np.flatnonzero(~res.success):
                alive[ids[k]] = False
                messages[ids[k]] = f"cycle {c + 1}, leg {j + 1} failed: {res.message[k]}"
                legs[ids[k], c * L + j] = np.nan
    cycle_end = legs[:, L - 1 :: L]
    drift = np.linalg.norm(cycle_end - xb[:, None, :], axis=-1)
    if single:
        return RepeatabilityResult(
            xb[0],
            targets[0],
            legs[0],
            cycle_end[0],
            drift[0],
            bool(alive[0]),
            messages[0],
            leg_results,
        )
    return RepeatabilityResult(xb, targets, legs, cycle_end, drift, alive, tuple(messages), [])
