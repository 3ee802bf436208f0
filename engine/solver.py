"""The continuation (Wazewski-Davidenko) IK algorithm, eq. (7), batched over start configurations.

Continuous mode follows the trajectory of dx/dtheta = -gamma J#(x) (k(x) - y_d) with two
adaptive high-order methods: Chebyshev-Picard iteration on the equivalent homotopy form (spectral,
adaptive segments; :mod:`jik.engine.picard`), and, where that cannot resolve the path or a very
small tolerance needs it, an embedded 8(5,3) Dormand-Prince pair (DOP853, the coefficients of
SciPy's ``solve_ivp``, :mod:`jik.engine.dop853`) on (7) itself, each batch member with its own
adaptive step. Both work in tau = gamma theta, so x(theta) does not depend on gamma at all:
gamma only rescales theta (NOTES.md). Discrete mode iterates x <- x - gamma J#(x) (k(x) - y_d),
as in section 6.2 (:mod:`jik.engine.solve_chunks` runs it as short solves with a hook between
them). The limits, gamma's rule and the stop messages are in :mod:`jik.engine.solve_rules`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .dop853 import integrate
from .exceptions import InvalidInputError
from .inverses import Inverse
from .picard import picard_path
from .picard_guesses import picard_guesses
from .results import BatchSolveResult, SolveResult, Trajectory
from .solve_rules import (
    DIVERGED_NORM,
    Record,
    Status,
    check_inverse,
    check_map_value,
    check_settings,
    solve_bytes,
    start_problem,
    stop_message,
)
from .validation import check_memory, flag

#: Picard sweeps per member in method "auto" before DOP853 takes over.
PICARD_BUDGET = 80


def _continuous(inverse, x0, y_d, tol, max_steps, record, method="auto", guess=None):
    """Chebyshev-Picard on the homotopy form (engine.picard), then DOP853 where needed.

    Members that Picard integrates to sigma = 1 with error < tol are done. The others (an
    unresolved path near a singularity, or an end-point error above a very small tol) continue
    with DOP853 on (7) itself from their last point, at tau = -ln(1 - sigma) (or ln(e0 / e)),
    for the steps that Picard's sweeps left of ``max_steps``.
    """
    n = len(x0)
    if not inverse.right_inverse:
        method = "dop853"  # the homotopy form needs e = e0 exp(-tau), which J J# != I breaks
    e0 = inverse.kinematics.forward_unchecked(x0) - y_d
    err0 = np.linalg.norm(e0, axis=-1)
    moving = np.flatnonzero(~(err0 < tol))
    # A singular start raises. Picard's first sweep evaluates J# at every moving start: only
    # the members already at their target (and every start for DOP853 alone) are checked here.
    _check_start(inverse, x0, e0, slice(None) if method == "dop853" else err0 < tol)
    x = x0.copy()
    tau = np.zeros(n)
    status = np.full(n, Status.CONVERGED)
    nit = np.zeros(n, dtype=int)
    rec: Record | None = [(np.arange(n), tau.copy(), x.copy())] if record else None
    if moving.size == 0:
        return x, tau, status, nit, rec
    if method == "dop853":
        xr, taur, st, steps, rrec = integrate(
            inverse, x0[moving], y_d[moving], tol, max_steps, record, np.zeros(moving.size)
        )
        x[moving], tau[moving], status[moving], nit[moving] = xr, taur, st, steps
        if rec is not None:
            rec.extend((moving[m], t, xs) for m, t, xs in rrec[1:])
        return x, tau, status, nit, rec
    # Picard pays (DEGREE + 1) evaluations of J# per sweep: on a path that needs many halvings
    # (near a singularity) DOP853 is cheaper, so Picard gets a budget and DOP853 takes over.
    budget = max_steps if method == "picard" else min(max_steps, PICARD_BUDGET)
    x1, done, sigma, sweeps, prec = picard_path(
        inverse,
        x0[moving],
        e0[moving],
        budget,
        None if guess is None else [guess[i] for i in moving],
        check_start=True,
    )
    nit[moving] = sweeps
    if rec is not None:
        for mem, sig, xs in prec:
            keep = sig > 0
            rec.append((moving[mem[keep]], -np.log1p(-sig[keep]), xs[keep]))
    x[moving] = x1
    err1 = np.linalg.norm(inverse.kinematics.forward_unchecked(x1) - y_d[moving], axis=-1)
    with np.errstate(divide="ignore"):
        tau_end = np.where(
            done,
            np.log(err0[moving] / np.maximum(err1, 1e-3 * tol)),
            -np.log1p(-np.minimum(sigma, 1 - 1e-16)),
        )
    tau[moving] = tau_end
    good = done & (err1 < tol)
    if rec is not None:
        rec.append((moving[good], tau_end[good], x1[good]))
    # The cap counts Picard's sweeps and DOP853's steps together: DOP853 gets what is left.
    left = max_steps - sweeps
    spent = ~good & (left <= 0)
    status[moving[spent]] = Status.MAX_STEPS
    more = ~good & ~spent
    rest = moving[more]
    if rest.size:
        xr, taur, st, steps, rrec = integrate(
            inverse, x1[more], y_d[rest], tol, left[more], record, tau_end[more]
        )
        x[rest], tau[rest], status[rest] = xr, taur, st
        nit[rest] += steps
        if rec is not None:
            rec.extend((rest[m], t, xs) for m, t, xs in rrec[1:])
    return x, tau, status, nit, rec


def _check_start(inverse, x0, e0, which) -> None:
    """Raise the inverse's typed error at the first singular start among ``x0[which]`` and the
    starts where k is not finite (e0 NaN or inf); at none singular, an InvalidInputError
    (field ``x0``) at the first where k is not finite."""
    undefined = ~np.isfinite(e0).all(axis=-1)
    checked = np.zeros(len(x0), dtype=bool)
    checked[which] = True
    idx = np.flatnonzero(checked | undefined)
    if idx.size:
        _, bad = inverse.apply_masked(x0[idx], np.where(undefined[idx, None], 1.0, e0[idx]))
        if bad.any():
            error = inverse.singular_error(x0[idx[np.flatnonzero(bad)[0]]])
            error.field = "x0"
            raise error
    if undefined.any():
        raise InvalidInputError(start_problem(inverse, x0[np.flatnonzero(undefined)[0]]), "x0")


def _discrete(inverse, x0, y_d, gamma, tol, max_iterations, record):
    """x <- x - gamma J#(x) (k(x) - y_d) (section 6.2) until ||e|| < tol."""
    n = x0.shape[0]
    x = x0.copy()
    e = inverse.kinematics.forward_unchecked(x) - y_d
    _check_start(inverse, x, e, slice(None))
    err = np.linalg.norm(e, axis=-1)
    err0 = err.copy()
    status = np.full(n, Status.RUNNING)
    status[err < tol] = Status.CONVERGED
    nit = np.zeros(n, dtype=int)
    rec: Record | None = [(np.arange(n), np.zeros(n), x.copy())] if record else None
    for k in range(1, max_iterations + 1):
        idx = np.flatnonzero(status == Status.RUNNING)
        if idx.size == 0:
            break
        v, bad = inverse.apply_masked(x[idx], e[idx])
        status[idx[bad]] = Status.SINGULAR
        ok = idx[~bad]
        x[ok] -= gamma * v[~bad]
        nit[ok] = k
        e[ok] = inverse.kinematics.forward_unchecked(x[ok]) - y_d[ok]
        err[ok] = np.linalg.norm(e[ok], axis=-1)
        if rec is not None:
            rec.append((ok, np.full(ok.size, float(k)), x[ok].copy()))
        fin = np.isfinite(err[ok]) & (np.linalg.norm(x[ok], axis=-1) < DIVERGED_NORM)
        status[ok[~fin | (err[ok] > 1e6 * np.maximum(err0[ok], 1.0))]] = Status.DIVERGED
        status[ok[fin & (err[ok] < tol)]] = Status.CONVERGED
    status[status == Status.RUNNING] = Status.MAX_STEPS
    return x, nit.astype(float), status, nit, rec


def solve(
    inverse: Inverse,
    x0,
    y_d,
    *,
    gamma: float = 1.0,
    mode: str = "continuous",
    tol: float = 1e-10,
    max_iterations: int | None = None,
    record: bool = True,
    method: str = "auto",
    guess: Trajectory | None = None,
) -> SolveResult:
    """Solve k(x) = y_d from one start by the continuation algorithm (7) with the right inverse J#.

    Parameters
    ----------
    inverse : Inverse
        The pseudoinverse (8), the extended Jacobian inverse (11), or one of
        :mod:`jik.engine.practical_inverses` (damped, weighted, posture).
    x0 : array_like, shape (p,)
        Start configuration (a batch: :func:`solve_batch`).
    y_d : array_like, shape (r,)
        Target task point.
    gamma : float
        Decay rate of eq. (5), in [:data:`GAMMA_MIN`, :data:`GAMMA_MAX`]. In continuous mode it
        only rescales theta; in discrete mode it is the step and must be below
        :data:`DISCRETE_GAMMA_BOUND` (near the solution the error shrinks by |1 - gamma|).
    mode : {"continuous", "discrete"}
    tol : float
        Stop when ||k(x) - y_d|| < tol.
    max_iterations : int, optional
        Cap on integrator steps (continuous, default :data:`MAX_STEPS`) or iterations (discrete,
        default :data:`MAX_ITERATIONS`).
    record : bool
        Keep the whole trajectory.
    method : {"auto", "picard", "dop853"}
        Continuous mode only ("auto" in discrete mode; another is refused): Chebyshev-Picard
        with a sweep budget and DOP853 after it ("auto"), Picard alone (DOP853 only where it
        fails), or DOP853 alone. "dop853" suits maps that are expensive per point (the
        unicycle's characteristics map). An inverse that is not a right inverse
        (``inverse.right_inverse`` False: damped least squares) always takes DOP853, since
        Picard's homotopy form needs J J# = I.
    guess : Trajectory, optional
        Continuous mode: the trajectory of a nearby earlier solve with the same gamma, such as
        the same leg in the previous cycle of a closed path. Picard starts its sweeps from it
        where its nodes are those of a segment (:mod:`jik.engine.picard`). The result is the same
        to the sweep tolerance; only the work falls. It is not used by DOP853.

    Returns
    -------
    SolveResult
        A run that does not converge (singularity reached, divergence, step cap) has
        ``success=False`` and a message saying why.

    Raises
    ------
    InvalidInputError
        Wrong shapes (a batch of starts or targets), non-finite values or coordinates beyond
        :data:`~jik.engine.validation.MAX_COORDINATE`, gamma out of range, bad tol, mode,
        method or max_iterations, a start where k is not finite; ``error.field`` names the
        argument.
    KinematicSingularityError, AlgorithmicSingularityError
        When the start configuration is singular for ``inverse``; the latter also (field
        ``x0``) where the extended inverse's augmenting map has no real value at the start
        (:func:`~jik.engine.solve_rules.check_map_value`: h(x) = h(x0) means nothing there).
    """
    kin = check_inverse(inverse)
    x0 = kin.check_start(x0)
    y_d = kin.check_target(y_d, "target y_d", "y_d")
    if x0.ndim != 1 or y_d.ndim != 1:
        raise InvalidInputError(
            f"solve takes one start x0 (p,) and one target y_d (r,), got shapes {x0.shape} and "
            f"{y_d.shape}; solve_batch solves a batch",
            "x0" if x0.ndim != 1 else "y_d",
        )
    # (one guess, not a list of one: its refusals name "guess")
    return _batch(
        inverse, x0[None], y_d[None], gamma, mode, tol, max_iterations, record, method, guess, True
    )[0]


def solve_batch(
    inverse: Inverse,
    x0,
    y_d,
    *,
    gamma: float = 1.0,
    mode: str = "continuous",
    tol: float = 1e-10,
    max_iterations: int | None = None,
    record: bool = True,
    method: str = "auto",
    guess: Sequence[Trajectory | None] | None = None,
) -> BatchSolveResult:
    """:func:`solve` for a batch of starts and targets, in one vectorized run.

    Parameters
    ----------
    inverse : Inverse
    x0 : array_like, shape (n, p) or (p,)
        Start configurations (one is shared by all targets).
    y_d : array_like, shape (n, r) or (r,)
        Target task points (one is shared by all starts).
    gamma, mode, tol, max_iterations, record, method
        As in :func:`solve`, for every member.
    guess : sequence of Trajectory or None, one per member, optional
        As in :func:`solve`.

    Returns
    -------
    BatchSolveResult
        Index it for a member's :class:`SolveResult`.

    Raises
    ------
    InvalidInputError, KinematicSingularityError, AlgorithmicSingularityError
        As :func:`solve` (the first singular start, or start where the augmenting map has no
        real value, names its configuration: the whole batch is refused); also, before any
        work, a batch whose estimated memory (:func:`jik.engine.solve_rules.solve_bytes`)
        exceeds :data:`jik.engine.validation.MEMORY_LIMIT`, naming ``x0`` (``y_d`` for a batch
        of targets from one start) and how many starts fit.
    """
    return _batch(inverse, x0, y_d, gamma, mode, tol, max_iterations, record, method, guess, False)


def _batch(inverse, x0, y_d, gamma, mode, tol, max_iterations, record, method, guess, single):
    """:func:`solve_batch`; with ``single``, ``guess`` is one start's Trajectory (or None)."""
    kin = check_inverse(inverse)
    x0 = kin.check_start(x0)
    y_d = kin.check_target(y_d, "target y_d", "y_d")
    if x0.ndim > 2 or y_d.ndim > 2:
        raise InvalidInputError(
            "x0 and y_d must be one point or a 2-D batch of points", "x0" if x0.ndim > 2 else "y_d"
        )
    xb, yb = np.atleast_2d(x0), np.atleast_2d(y_d)
    n = max(len(xb), len(yb))
    if len(xb) not in (1, n) or len(yb) not in (1, n):
        raise InvalidInputError(
            f"x0 has {len(xb)} configurations but y_d has {len(yb)} targets: give as many of "
            "each, or one of either",
            "x0" if len(xb) == 0 else "y_d",
        )
    xb, yb = np.broadcast_to(xb, (n, kin.p)), np.broadcast_to(yb, (n, kin.r))
    mode, gamma, tol, cap = check_settings(mode, gamma, tol, max_iterations, method)
    record = flag(record, "record")
    if guess is not None and mode != "continuous":
        raise InvalidInputError("guess applies to continuous mode only", "guess")
    check_memory(
        len(xb),
        solve_bytes(kin, 1, mode, record, gamma, tol, cap),
        "x0" if x0.ndim == 2 or y_d.ndim == 1 else "y_d",
        "starts of a batched solve" + (" with record=True" if record else ""),
        "solve them in smaller batches" + (", or with record=False" if record else ""),
    )
    xb, yb = np.array(xb), np.array(yb)
    check_map_value(inverse, xb)
    guesses = picard_guesses(guess, len(xb), kin.p, gamma, single)

    if mode == "continuous":
        x, _, status, nit, rec = _continuous(inverse, xb, yb, tol, cap, record, method, guesses)
        theta_scale = 1.0 / gamma
    else:
        x, _, status, nit, rec = _discrete(inverse, xb, yb, gamma, tol, cap, record)
        theta_scale = 1.0
    singular = np.flatnonzero(status == Status.SINGULAR)
    if singular.size:  # (the inverse undefined there because its map h is)
        status[singular[inverse.map_undefined(x[singular])]] = Status.UNDEFINED
    y = kin.forward_unchecked(x)
    err = np.linalg.norm(y - yb, axis=-1)
    messages = tuple(
        stop_message(s, int(k), float(er), tol, mode, gamma, xi, inverse, cap, yi)
        for s, k, er, xi, yi in zip(status, nit, err, x, yb, strict=True)
    )
    rec_m = rec_t = rec_x = None
    if record:
        rec_m = np.concatenate([r[0] for r in rec])
        rec_t = np.concatenate([r[1] for r in rec]) * theta_scale
        rec_x = np.concatenate([r[2] for r in rec])
        order = np.argsort(rec_m, kind="stable")
        rec_m, rec_t, rec_x = rec_m[order], rec_t[order], rec_x[order]
    batch = BatchSolveResult(
        x=x,
        y=y,
        error=err,
        success=status == Status.CONVERGED,
        message=messages,
        nit=nit,
        mode=mode,
        gamma=gamma,
        algorithm=inverse.name,
        _inverse=inverse,
        y_d=yb,
        x0=xb,
        _rec_member=rec_m,
        _rec_theta=rec_t,
        _rec_x=rec_x,
        _status=status,
    )
    return batch
