"""Discrete mode of eq. (7) for one start as a sequence of short solves, with a hook between
them (for progress and cancellation): the iterates of one :func:`solve`
(:func:`jik.engine.solver.solve`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from .exceptions import InvalidInputError, JikError
from .inverses import Inverse
from .results import SolveResult, Trajectory
from .solve_rules import MAX_ITERATIONS, MAX_ITERATIONS_LIMIT, Status, stop_message
from .solver import solve_batch
from .validation import FloatArray, count


def solve_in_chunks(
    inverse: Inverse,
    x0,
    y_d,
    *,
    chunk: int,
    gamma: float = 1.0,
    tol: float = 1e-10,
    max_iterations: int | None = None,
    record: bool = True,
    between: Callable[[float], None] | None = None,
) -> SolveResult:
    """Discrete mode of eq. (7) for one start, as solves of at most ``chunk`` iterations each.

    The iteration x <- x - gamma J#(x) (k(x) - y_d) of section 6.2 has no memory: a solve from
    where the one before stopped goes on with the same sequence, so the iterates, ``nit``, the
    trajectory and the message are those of one :func:`solve` in discrete mode (see Notes).
    Between two chunks ``between`` is called: a caller reports progress there, or stops a run
    that is no longer wanted by raising.

    Parameters
    ----------
    inverse : Inverse
    x0 : array_like, shape (p,)
    y_d : array_like, shape (r,)
    chunk : int
        Iterations per solve, >= 1.
    gamma, tol, record
        As in :func:`solve`.
    max_iterations : int, optional
        Cap on the iterations of the whole run (default :data:`MAX_ITERATIONS`).
    between : callable, optional
        Called after each chunk that leaves the run unfinished, with how far the task error has
        come from its start value toward ``tol`` on a log scale (it decays geometrically, eq. (5)),
        a fraction in [0, 0.99]. What it raises propagates.

    Returns
    -------
    SolveResult
        As :func:`solve` gives. A typed error raised inside a chunk (a map undefined where the
        chunk starts, say) stops the run there: the chunk is redone one iteration at a time to
        keep every iterate before the error, and the result has ``success=False`` and the message
        "stopped after N iterations: <the error>".

    Raises
    ------
    JikError
        Raised before the first iteration is kept (a singular start, as in :func:`solve`).

    Notes
    -----
    Each chunk is a :func:`solve`, so divergence is judged from the chunk's start error, a chunk
    that runs all its iterations is followed by the next whatever its last iterate is, and a
    singular iterate where a chunk starts stops the run as above (one solve would report the
    singularity with the same iterates). Where a run neither diverges nor meets a singularity,
    the results agree bit for bit.
    """
    kin = inverse.kinematics
    x = kin.check_start(x0)
    y_d = kin.check_target(y_d, "target y_d", "y_d")
    if x.ndim != 1 or y_d.ndim != 1:
        raise InvalidInputError(
            f"solve_in_chunks takes one start (p,) and one target (r,); got shapes {x.shape} "
            f"and {y_d.shape}",
            "x0" if x.ndim != 1 else "y_d",
        )
    size = count(chunk, "chunk", 1, MAX_ITERATIONS_LIMIT)
    cap = count(
        MAX_ITERATIONS if max_iterations is None else max_iterations,
        "max_iterations",
        1,
        MAX_ITERATIONS_LIMIT,
    )
    start = x.copy()  # (x0 may be a view of the caller's array, which moves on)
    e0 = float(np.linalg.norm(kin.forward(x[None]) - y_d, axis=-1)[0])
    pieces: list[Trajectory] = []
    done, status = 0, Status.RUNNING
    last: SolveResult | None = None
    stopped: JikError | None = None
    while True:
        try:
            batch = solve_batch(
                inverse,
                x[None],
                y_d[None],
                gamma=gamma,
                mode="discrete",
                tol=tol,
                max_iterations=min(size, cap - done),
                record=record,
            )
            res = batch[0]
        except JikError as exc:
            if size == 1:
                stopped = exc
                break
            size = 1  # (the chunk again, one iteration at a time: up to the error)
            continue
        if res.trajectory is not None:
            tr = res.trajectory
            k = 1 if pieces else 0  # (a chunk starts where the one before ended)
            h = None if tr.h is None else tr.h[k:]
            pieces.append(Trajectory(tr.theta[k:] + done, tr.x[k:], tr.y[k:], tr.error[k:], h))
        done, x, last, status = done + res.nit, res.x, res, Status.NAMES.index(res.status)
        if res.success or res.nit < size or done >= cap:
            break
        if between is not None:
            between(_fraction(e0, res.error, tol))
    if last is None:
        assert stopped is not None
        raise stopped
    if stopped is not None:
        message = f"stopped after {done} iterations: {stopped}"
    elif status in (Status.SINGULAR, Status.UNDEFINED):
        message = last.message  # (names the configuration, not the count)
    else:
        message = stop_message(
            status, done, last.error, tol, "discrete", gamma, last.x, inverse, cap, y_d
        )
    trajectory = _joined(pieces) if pieces else None
    return replace(
        last,
        message=message,
        nit=done,
        trajectory=trajectory,
        x0=start,
        status="raised" if stopped is not None else last.status,
    )


def _joined(pieces: list[Trajectory]) -> Trajectory:
    """One trajectory of consecutive pieces."""

    def cat(name: str) -> FloatArray:
        return np.concatenate([getattr(p, name) for p in pieces])

    return Trajectory(
        theta=cat("theta"),
        x=cat("x"),
        y=cat("y"),
        error=cat("error"),
        h=None if pieces[0].h is None else cat("h"),
    )


def _fraction(e0: float, e: float, tol: float) -> float:
    """How far the task error has come from e0 toward tol, on a log scale, in [0, 0.99]."""
    if not e0 > e > 0:
        return 0.0
    return float(np.clip(np.log(e0 / e) / np.log(e0 / tol), 0.0, 0.99))
