"""The continuation (Wazewski-Davidenko) IK algorithm, eq. (7), batched over start configurations.

(It stays whole, at about 730 lines: the two continuous integrators, the discrete iteration and
:func:`solve_in_chunks` share one stopping rule, one check of the start and one message; the
result types (:mod:`jik.engine.results`), the DOP853 coefficients and the Picard sweeps live in
modules of their own.)

Continuous mode follows the trajectory of dx/dtheta = -gamma J#(x) (k(x) - y_d) with two
adaptive high-order methods: Chebyshev-Picard iteration on the equivalent homotopy form (spectral,
adaptive segments; :mod:`jik.engine.picard`), and, where that cannot resolve the path or a very
small tolerance needs it, an embedded 8(5,3) Dormand-Prince pair (DOP853, the coefficients of
SciPy's ``solve_ivp``, :mod:`jik.engine.dop853`) on (7) itself, each batch member with its own
adaptive step. Both work in tau = gamma theta, so x(theta) does not depend on gamma at all:
gamma only rescales theta (NOTES.md). Discrete mode iterates x <- x - gamma J#(x) (k(x) - y_d),
as in section 6.2; :func:`solve_in_chunks` runs it as short solves with a hook between them (for
progress and cancellation), the same iterates.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np

from jik.engine import dop853 as _dop
from jik.engine.exceptions import InvalidInputError, JikError
from jik.engine.inverses import Inverse
from jik.engine.picard import Guess, picard_chain, picard_path
from jik.engine.results import BatchSolveResult, SolveResult, Trajectory
from jik.engine.validation import FloatArray, count, positive

_NS = _dop.N_STAGES
_A = _dop.A
_B = _dop.B
_E3 = _dop.E3
_E5 = _dop.E5
_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0
_EXPONENT = -1.0 / 8.0  # error estimator of order 7

#: The smallest task-error tolerance ``tol`` of a solve (double precision).
TOL_MIN = 1e-14
#: Tolerances of the continuous integrator on x (relative and absolute).
RTOL = 1e-12
ATOL = 1e-12
#: Default caps of :func:`solve`: integrator steps (continuous), iterations (discrete).
MAX_STEPS = 20000
MAX_ITERATIONS = 2000
#: The largest cap ``max_iterations`` (and ``chunk``) that a solve accepts.
MAX_ITERATIONS_LIMIT = 10**6
#: Picard sweeps per member in method "auto" before DOP853 takes over.
PICARD_BUDGET = 80
#: Largest |x| before a run counts as diverged.
DIVERGED_NORM = 1e8
#: The modes of eq. (7): its ODE (continuous), or the iteration x <- x - gamma J# e (discrete).
MODES = ("continuous", "discrete")
#: The decay rate gamma of eq. (5) that the engine, the API and the dashboard accept. Continuous
#: runs depend on gamma only through theta = -log(1 - s) / gamma (theta's scale); far below
#: GAMMA_MIN that scale leaves the floating-point range.
GAMMA_MIN, GAMMA_MAX = 1e-6, 1e6
#: Discrete mode converges near a solution only for gamma below this: the task error shrinks
#: by |1 - gamma| per iteration there.
DISCRETE_GAMMA_BOUND = 2.0

_RUNNING, _CONVERGED, _SINGULAR, _MAX_STEPS, _DIVERGED, _STALLED = range(6)


def gamma_problem(gamma: float, mode: str) -> str | None:
    """What is wrong with a positive ``gamma`` in ``mode``, as a phrase to follow the field's
    name ("must be < 2 in discrete mode, got 2.5 (...)"), or None: the one wording of gamma's
    rules, for the engine's errors and the app's."""
    if not GAMMA_MIN <= gamma <= GAMMA_MAX:
        return f"must be between {GAMMA_MIN:g} and {GAMMA_MAX:g}, got {gamma:g}"
    if mode == "discrete" and gamma >= DISCRETE_GAMMA_BOUND:
        return (
            f"must be < {DISCRETE_GAMMA_BOUND:g} in discrete mode, got {gamma:g} (near the "
            "solution the error shrinks by |1 - gamma| per iteration)"
        )
    return None


def check_gamma(gamma, mode: str) -> float:
    """``gamma`` as a float, checked for ``mode`` (:func:`gamma_problem`).

    Raises
    ------
    InvalidInputError
        With ``field="gamma"``: not a number, <= 0, outside [GAMMA_MIN, GAMMA_MAX], or not below
        :data:`DISCRETE_GAMMA_BOUND` in discrete mode.
    """
    try:
        value = positive(gamma, "gamma")
    except InvalidInputError as exc:
        raise InvalidInputError(str(exc), field="gamma") from None
    why = gamma_problem(value, mode)
    if why is not None:
        raise InvalidInputError(f"gamma {why}", field="gamma")
    return value


def _rhs(inverse: Inverse, x: FloatArray, y_d: FloatArray):
    """-J#(x) (k(x) - y_d) per unit tau = gamma theta; also e and the singular mask."""
    e = inverse.kinematics.forward(x) - y_d
    v, bad = inverse.apply_masked(x, e)
    return -v, e, bad


def _initial_step(inverse, x, f, y_d, rtol, atol):
    """Hairer-Norsett-Wanner starting step, per member (as scipy's ``select_initial_step``)."""
    p = x.shape[-1]
    scale = atol + np.abs(x) * rtol
    d0 = np.sqrt(np.sum((x / scale) ** 2, axis=-1) / p)
    d1 = np.sqrt(np.sum((f / scale) ** 2, axis=-1) / p)
    with np.errstate(divide="ignore", invalid="ignore"):
        h0 = np.where((d0 < 1e-5) | (d1 < 1e-5), 1e-6, 0.01 * d0 / d1)
    f1, _, _ = _rhs(inverse, x + h0[:, None] * f, y_d)
    d2 = np.sqrt(np.sum(((f1 - f) / scale) ** 2, axis=-1) / p) / h0
    dm = np.maximum(d1, d2)
    with np.errstate(divide="ignore"):
        h1 = np.where(dm <= 1e-15, np.maximum(1e-6, h0 * 1e-3), (0.01 / dm) ** (1.0 / 8.0))
    return np.minimum(100 * h0, h1)


def _combine(weights: FloatArray, K: FloatArray) -> FloatArray:
    """sum_j weights[j] K[j] over the stages K (s, n, p), term by term in a fixed order.

    ``np.tensordot`` hands this to BLAS, whose kernels round a member's sum differently with
    the batch's size and the member's place in it; a sum of whole arrays does not, so a member's
    numbers are the same in any batch (an atlas's do not depend on its chunking).
    """
    out = np.zeros(K.shape[1:])
    for w, k in zip(weights, K, strict=True):
        if w != 0.0:
            out += w * k
    return out


# Recorded steps: (member indices (k,), theta (k,), x (k, p)) per accepted step.
_Record = list[tuple[FloatArray, FloatArray, FloatArray]]


def _dop853(inverse, x0, y_d, tol, max_steps, record, tau0, rtol=RTOL, atol=ATOL):
    """Batched DOP853 on dx/dtau = -J# e from tau = tau0 until ||e|| < tol."""
    n, p = x0.shape
    x = x0.copy()
    tau = tau0.copy()
    f, e, bad = _rhs(inverse, x, y_d)
    err0 = np.linalg.norm(e, axis=-1)
    status = np.full(n, _RUNNING)
    status[bad] = _SINGULAR
    status[err0 < tol] = _CONVERGED
    # exp(-tau) decay: tau_needed = ln(err0 / tol); far past that the run has stalled.
    tau_cap = tau0 + np.log(np.maximum(err0, tol) / tol) + 40.0
    h = _initial_step(inverse, x, f, y_d, rtol, atol)
    nsteps = np.zeros(n, dtype=int)
    last_bad = np.zeros(n, dtype=bool)
    rec: _Record | None = [(np.arange(n), tau.copy(), x.copy())] if record else None
    K = np.empty((_NS + 1, n, p))
    while True:
        idx = np.flatnonzero(status == _RUNNING)
        if idx.size == 0:
            break
        m = idx.size
        xs, hs, yds = x[idx], h[idx], y_d[idx]
        Ks = K[:, :m]
        Ks[0] = f[idx]
        stage_bad = np.zeros(m, dtype=bool)
        for s in range(1, _NS):
            dx = _combine(_A[s, :s], Ks[:s]) * hs[:, None]
            Ks[s], _, b = _rhs(inverse, xs + dx, yds)
            stage_bad |= b
        x_new = xs + hs[:, None] * _combine(_B, Ks[:_NS])
        f_new, e_new, b = _rhs(inverse, x_new, yds)
        stage_bad |= b
        Ks[_NS] = f_new
        scale = atol + np.maximum(np.abs(xs), np.abs(x_new)) * rtol
        err5 = np.sum((_combine(_E5, Ks) / scale) ** 2, axis=-1)
        err3 = np.sum((_combine(_E3, Ks) / scale) ** 2, axis=-1)
        denom = err5 + 0.01 * err3
        with np.errstate(divide="ignore", invalid="ignore"):
            enorm = np.where(denom > 0, hs * err5 / np.sqrt(denom * p), 0.0)
            enorm = np.where(np.isfinite(enorm), enorm, np.inf)
            factor = np.where(
                enorm == 0,
                _MAX_FACTOR,
                np.clip(_SAFETY * enorm**_EXPONENT, _MIN_FACTOR, _MAX_FACTOR),
            )
        accept = (enorm < 1.0) & ~stage_bad
        factor = np.where(accept, factor, np.minimum(factor, 1.0))
        factor = np.where(stage_bad, _MIN_FACTOR, factor)
        last_bad[idx] = stage_bad
        h[idx] = hs * factor

        ai = idx[accept]
        x[ai] = x_new[accept]
        f[ai] = f_new[accept]
        tau[ai] += hs[accept]
        nsteps[idx] += 1
        if rec is not None:
            rec.append((ai, tau[ai].copy(), x[ai].copy()))
        err = np.linalg.norm(e_new[accept], axis=-1)
        status[ai[err < tol]] = _CONVERGED
        run = idx[status[idx] == _RUNNING]
        tiny = h[run] < 1e-12 * (1.0 + tau[run])
        status[run[tiny & last_bad[run]]] = _SINGULAR
        status[run[tiny & ~last_bad[run]]] = _STALLED
        status[run[tau[run] > tau_cap[run]]] = _STALLED
        status[run[np.linalg.norm(x[run], axis=-1) > DIVERGED_NORM]] = _DIVERGED
        status[run[(nsteps[run] >= max_steps) & (status[run] == _RUNNING)]] = _MAX_STEPS
    return x, tau, status, nsteps, rec


def _guesses(guess, n: int, p: int, gamma: float) -> list[Guess | None] | None:
    """Picard guesses (sigma, x) from earlier trajectories (see :func:`solve`), validated."""
    if guess is None:
        return None
    items = [guess] if isinstance(guess, Trajectory) else list(guess)
    if len(items) != n:
        raise InvalidInputError(
            f"guess has {len(items)} trajectories for {n} start configurations; give one "
            "Trajectory (or None) per start"
        )
    out: list[Guess | None] = []
    for k, tr in enumerate(items):
        if tr is None:
            out.append(None)
            continue
        if not isinstance(tr, Trajectory):
            raise InvalidInputError(
                f"guess[{k}] must be a Trajectory (a SolveResult's .trajectory) or None"
            )
        theta = np.asarray(tr.theta, dtype=float)
        x = np.asarray(tr.x, dtype=float)
        if theta.ndim != 1 or x.shape != (len(theta), p) or len(theta) < 2:
            raise InvalidInputError(
                f"guess[{k}] must have theta of shape (m,) and x of shape (m, {p}), m >= 2"
            )
        if not (np.all(np.isfinite(theta)) and np.all(np.isfinite(x))):
            raise InvalidInputError(f"guess[{k}] contains NaN or infinite values")
        if np.any(np.diff(theta) <= 0):
            raise InvalidInputError(f"guess[{k}].theta must be increasing")
        # The homotopy parameter of (*) in engine.picard: sigma = 1 - exp(-gamma theta); the
        # last point of a converged leg is its end, sigma = 1.
        sigma = -np.expm1(-gamma * (theta - theta[0]))
        sigma[-1] = 1.0
        out.append((sigma, x))
    return out


def chain_guesses(inverse: Inverse, x0, y_d, *, gamma: float = 1.0) -> list[Trajectory] | None:
    """Guesses for solving legs of eq. (7) one after another in continuous mode: leg j from
    where leg j - 1 ends, to ``y_d[j]`` (a closed path's legs, cycle after cycle).

    Pass ``guesses[j]`` as ``guess`` of the solve of leg j (:func:`solve`): the results are
    the same to the sweep tolerance; each leg then takes one or two Picard sweeps instead of
    about ten, and the guesses cost about three legs' worth (:func:`jik.engine.picard.picard_chain`;
    ``jik bench solver``).

    Parameters
    ----------
    inverse : Inverse
    x0 : array_like, shape (p,)
        Start of the first leg.
    y_d : array_like, shape (L, r)
        The legs' targets.
    gamma : float
        The decay rate the legs will be solved with (it only sets their theta).

    Returns
    -------
    list of L Trajectory (at the Chebyshev nodes of each leg), or None when the legs
    cannot all be swept on one segment each (a singular J# on the way, a path that needs finer
    segments): solve them without guesses then.
    """
    kin = inverse.kinematics
    x0 = kin.check(x0, "x0")
    y_d = kin.check_task(y_d, "y_d")
    gamma = check_gamma(gamma, "continuous")
    if x0.ndim != 1 or y_d.ndim != 2 or len(y_d) == 0:
        raise InvalidInputError(
            f"x0 must be one configuration (p,) and y_d the legs' targets (L, r), L >= 1; "
            f"got shapes {x0.shape} and {y_d.shape}"
        )
    chained = picard_chain(inverse, x0, y_d)
    if chained is None:
        return None
    sigma, X = chained
    # sigma = 1 - exp(-gamma theta) (engine.picard); the last node, sigma = 1, is the leg's end
    # and stands at any later theta (see _guesses).
    theta = -np.log1p(-sigma[:-1]) / gamma
    theta = np.append(theta, theta[-1] + 1.0)
    y = kin.forward(X)  # (L, nodes, r)
    error = np.linalg.norm(y - y_d[:, None, :], axis=-1)
    return [
        Trajectory(theta=theta, x=X[j], y=y[j], error=error[j], h=inverse.augmenting_value(X[j]))
        for j in range(len(X))
    ]


def _continuous(inverse, x0, y_d, tol, max_steps, record, method="auto", guess=None):
    """Chebyshev-Picard on the homotopy form (engine.picard), then DOP853 where needed.

    Members that Picard integrates to sigma = 1 with error < tol are done. The others (an
    unresolved path near a singularity, or an end-point error above a very small tol) continue
    with DOP853 on (7) itself from their last point, at tau = -ln(1 - sigma) (or ln(e0 / e)).
    """
    n = len(x0)
    if not inverse.right_inverse:
        method = "dop853"  # the homotopy form needs e = e0 exp(-tau), which J J# != I breaks
    e0 = inverse.kinematics.forward(x0) - y_d
    err0 = np.linalg.norm(e0, axis=-1)
    moving = np.flatnonzero(err0 >= tol)
    # A singular start raises. Picard's first sweep evaluates J# at every moving start: only
    # the members already at their target (and every start for DOP853 alone) are checked here.
    _check_start(inverse, x0, e0, slice(None) if method == "dop853" else err0 < tol)
    x = x0.copy()
    tau = np.zeros(n)
    status = np.full(n, _CONVERGED)
    nit = np.zeros(n, dtype=int)
    rec: _Record | None = [(np.arange(n), tau.copy(), x.copy())] if record else None
    if moving.size == 0:
        return x, tau, status, nit, rec
    if method == "dop853":
        xr, taur, st, steps, rrec = _dop853(
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
        inverse, x0[moving], e0[moving], budget,
        None if guess is None else [guess[i] for i in moving], check_start=True,
    )  # fmt: skip
    nit[moving] = sweeps
    if rec is not None:
        for mem, sig, xs in prec:
            keep = sig > 0
            rec.append((moving[mem[keep]], -np.log1p(-sig[keep]), xs[keep]))
    x[moving] = x1
    err1 = np.linalg.norm(inverse.kinematics.forward(x1) - y_d[moving], axis=-1)
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
    rest = moving[~good]
    if rest.size:
        xr, taur, st, steps, rrec = _dop853(
            inverse, x1[~good], y_d[rest], tol, max_steps, record, tau_end[~good]
        )
        x[rest], tau[rest], status[rest] = xr, taur, st
        nit[rest] += steps
        if rec is not None:
            rec.extend((rest[m], t, xs) for m, t, xs in rrec[1:])
    return x, tau, status, nit, rec


def _check_start(inverse, x0, e0, which) -> None:
    """Raise the inverse's typed error at the first singular start among ``x0[which]``."""
    x, e = x0[which], e0[which]
    if len(x):
        _, bad = inverse.apply_masked(x, e)
        if bad.any():
            raise inverse.singular_error(x[np.flatnonzero(bad)[0]])


def _discrete(inverse, x0, y_d, gamma, tol, max_iterations, record):
    """x <- x - gamma J#(x) (k(x) - y_d) (section 6.2) until ||e|| < tol."""
    n = x0.shape[0]
    x = x0.copy()
    e = inverse.kinematics.forward(x) - y_d
    _check_start(inverse, x, e, slice(None))
    err = np.linalg.norm(e, axis=-1)
    err0 = err.copy()
    status = np.full(n, _RUNNING)
    status[err < tol] = _CONVERGED
    nit = np.zeros(n, dtype=int)
    rec: _Record | None = [(np.arange(n), np.zeros(n), x.copy())] if record else None
    for k in range(1, max_iterations + 1):
        idx = np.flatnonzero(status == _RUNNING)
        if idx.size == 0:
            break
        v, bad = inverse.apply_masked(x[idx], e[idx])
        status[idx[bad]] = _SINGULAR
        ok = idx[~bad]
        x[ok] -= gamma * v[~bad]
        nit[ok] = k
        e[ok] = inverse.kinematics.forward(x[ok]) - y_d[ok]
        err[ok] = np.linalg.norm(e[ok], axis=-1)
        if rec is not None:
            rec.append((ok, np.full(ok.size, float(k)), x[ok].copy()))
        fin = np.isfinite(err[ok]) & (np.linalg.norm(x[ok], axis=-1) < DIVERGED_NORM)
        status[ok[~fin | (err[ok] > 1e6 * np.maximum(err0[ok], 1.0))]] = _DIVERGED
        status[ok[fin & (err[ok] < tol)]] = _CONVERGED
    status[status == _RUNNING] = _MAX_STEPS
    return x, nit.astype(float), status, nit, rec


def _message(status, nit, err, tol, mode, x, inverse, max_iterations) -> str:
    steps = "steps" if mode == "continuous" else "iterations"
    if status == _CONVERGED:
        if nit == 0:
            return f"already at the target (error {err:.3g} < {tol:g}): no motion"
        return f"converged: task error {err:.3g} < {tol:g} after {nit} {steps}"
    if status == _SINGULAR:
        return str(inverse.singular_error(x)) + "; the run stopped there"
    if status == _DIVERGED:
        return f"diverged after {nit} {steps} (error {err:.3g}); " + (
            "lower gamma" if mode == "discrete" else "the target may be unreachable"
        )
    if status == _STALLED:
        return (
            f"stalled after {nit} {steps} at error {err:.3g}: the step size collapsed near a "
            "singularity or the target is unreachable"
        )
    return (
        f"did not converge within {max_iterations} {steps} (error {err:.3g} >= {tol:g}); "
        "raise max_iterations or gamma"
    )


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
        Continuous mode only: Chebyshev-Picard with a sweep budget and DOP853 after it
        ("auto"), Picard alone (DOP853 only where it fails), or DOP853 alone. "dop853" suits
        maps that are expensive per point (the unicycle's characteristics map). An inverse that
        is not a right inverse (``inverse.right_inverse`` False: damped least squares) always
        takes DOP853, since Picard's homotopy form needs J J# = I.
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
        Wrong shapes (a batch of starts or targets), non-finite values, gamma out of range,
        bad tol.
    KinematicSingularityError, AlgorithmicSingularityError
        When the start configuration is singular for ``inverse``.
    """
    kin = inverse.kinematics
    x0 = kin.check(x0, "x0")
    y_d = kin.check_task(y_d, "target y_d")
    if x0.ndim != 1 or y_d.ndim != 1:
        raise InvalidInputError(
            f"solve takes one start x0 (p,) and one target y_d (r,), got shapes {x0.shape} and "
            f"{y_d.shape}; solve_batch solves a batch"
        )
    batch = solve_batch(
        inverse, x0[None], y_d[None], gamma=gamma, mode=mode, tol=tol,
        max_iterations=max_iterations, record=record, method=method,
        guess=None if guess is None else [guess],
    )  # fmt: skip
    return batch[0]


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
        As :func:`solve` (the first singular start names its configuration).
    """
    kin = inverse.kinematics
    x0 = kin.check(x0, "x0")
    y_d = kin.check_task(y_d, "target y_d")
    if x0.ndim > 2 or y_d.ndim > 2:
        raise InvalidInputError("x0 and y_d must be one point or a 2-D batch of points")
    xb = np.atleast_2d(x0)
    yb = np.broadcast_to(np.atleast_2d(y_d), (max(len(xb), len(np.atleast_2d(y_d))), kin.r))
    if len(xb) != len(yb):
        if len(xb) == 1:
            xb = np.broadcast_to(xb, (len(yb), kin.p))
        else:
            raise InvalidInputError(
                f"x0 has {len(xb)} configurations but y_d has {len(np.atleast_2d(y_d))} targets"
            )
    xb, yb = np.array(xb), np.array(yb)
    if mode not in MODES:
        raise InvalidInputError(f"mode must be 'continuous' or 'discrete', got {mode!r}")
    gamma = check_gamma(gamma, mode)
    tol = positive(tol, "tol")
    if tol < TOL_MIN:
        raise InvalidInputError(f"tol must be >= {TOL_MIN:g} (double precision), got {tol:g}")
    if method not in ("auto", "picard", "dop853"):
        raise InvalidInputError(f"method must be 'auto', 'picard' or 'dop853', got {method!r}")
    if guess is not None and mode != "continuous":
        raise InvalidInputError("guess applies to continuous mode only")
    guesses = _guesses(guess, len(xb), kin.p, gamma)
    default_cap = MAX_STEPS if mode == "continuous" else MAX_ITERATIONS
    cap = default_cap if max_iterations is None else max_iterations
    cap = count(cap, "max_iterations", 1, MAX_ITERATIONS_LIMIT)

    if mode == "continuous":
        x, _, status, nit, rec = _continuous(inverse, xb, yb, tol, cap, record, method, guesses)
        theta_scale = 1.0 / gamma
    else:
        x, _, status, nit, rec = _discrete(inverse, xb, yb, gamma, tol, cap, record)
        theta_scale = 1.0
    y = kin.forward(x)
    err = np.linalg.norm(y - yb, axis=-1)
    messages = tuple(
        _message(s, int(k), float(er), tol, mode, xi, inverse, cap)
        for s, k, er, xi in zip(status, nit, err, x, strict=True)
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
        success=status == _CONVERGED,
        message=messages,
        nit=nit,
        mode=mode,
        gamma=gamma,
        algorithm=inverse.name,
        _inverse=inverse,
        _y_d=yb,
        _rec_member=rec_m,
        _rec_theta=rec_t,
        _rec_x=rec_x,
        _status=status,
    )
    return batch


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
    x = kin.check(x0, "x0")
    y_d = kin.check_task(y_d, "target y_d")
    if x.ndim != 1 or y_d.ndim != 1:
        raise InvalidInputError(
            f"solve_in_chunks takes one start (p,) and one target (r,); got shapes {x.shape} "
            f"and {y_d.shape}"
        )
    size = count(chunk, "chunk", 1, MAX_ITERATIONS_LIMIT)
    cap = count(MAX_ITERATIONS if max_iterations is None else max_iterations,
                "max_iterations", 1, MAX_ITERATIONS_LIMIT)  # fmt: skip
    e0 = float(np.linalg.norm(kin.forward(x[None]) - y_d, axis=-1)[0])
    pieces: list[Trajectory] = []
    done, status = 0, _RUNNING
    last: SolveResult | None = None
    stopped: JikError | None = None
    while True:
        try:
            batch = solve_batch(
                inverse, x[None], y_d[None], gamma=gamma, mode="discrete", tol=tol,
                max_iterations=min(size, cap - done), record=record,
            )  # fmt: skip
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
        assert batch._status is not None  # (solve sets it)
        done, x, last, status = done + res.nit, res.x, res, int(batch._status[0])
        if res.success or res.nit < size or done >= cap:
            break
        if between is not None:
            between(_fraction(e0, res.error, tol))
    if last is None:
        assert stopped is not None
        raise stopped
    if stopped is not None:
        message = f"stopped after {done} iterations: {stopped}"
    elif status == _SINGULAR:
        message = last.message  # (names the configuration, not the count)
    else:
        message = _message(status, done, last.error, tol, "discrete", last.x, inverse, cap)
    trajectory = _joined(pieces) if pieces else None
    return replace(last, message=message, nit=done, trajectory=trajectory)


def _joined(pieces: list[Trajectory]) -> Trajectory:
    """One trajectory of consecutive pieces."""

    def cat(name: str) -> FloatArray:
        return np.concatenate([getattr(p, name) for p in pieces])

    return Trajectory(theta=cat("theta"), x=cat("x"), y=cat("y"), error=cat("error"),
                      h=None if pieces[0].h is None else cat("h"))  # fmt: skip


def _fraction(e0: float, e: float, tol: float) -> float:
    """How far the task error has come from e0 toward tol, on a log scale, in [0, 0.99]."""
    if not e0 > e > 0:
        return 0.0
    return float(np.clip(np.log(e0 / e) / np.log(e0 / tol), 0.0, 0.99))
