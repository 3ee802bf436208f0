"""The Dormand-Prince 8(5,3) Runge-Kutta pair (DOP853) and the batched integrator of eq. (7) on it.

The coefficients of Hairer, Norsett and Wanner, *Solving Ordinary Differential Equations I*
(2nd ed., Springer 1993), section II.10, as in Hairer's ``dop853.f`` and SciPy's ``solve_ivp``.
They are written here rather than imported from SciPy's private
``scipy.integrate._ivp.dop853_coefficients``, which may change without notice;
``tests/engine/test_dop853.py`` pins them to SciPy's where that module exists and checks the
order conditions either way.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .solve_rules import DIVERGED_NORM, Record, Status
from .validation import FloatArray

if TYPE_CHECKING:
    from .inverses import Inverse

#: Stages of one step (the 13th evaluation, at the new point, is the next step's first).
N_STAGES = 12

#: Nodes c_i (eq. (1.7) of Hairer et al. II.1: c_i = sum_j a_ij).
C = np.array(
    [
        0.0,
        0.05260015195876773,
        0.0789002279381516,
        0.1183503419072274,
        0.2816496580927726,
        0.3333333333333333,
        0.25,
        0.3076923076923077,
        0.6512820512820513,
        0.6,
        0.8571428571428571,
        1.0,
    ]
)

#: Lower-triangular a_ij, row i holding a_i0 .. a_i,i-1.
_A_ROWS: list[list[float]] = [
    [],
    [0.05260015195876773],
    [0.0197250569845379, 0.0591751709536137],
    [0.02958758547680685, 0.0, 0.08876275643042054],
    [0.2413651341592667, 0.0, -0.8845494793282861, 0.924834003261792],
    [0.037037037037037035, 0.0, 0.0, 0.17082860872947386, 0.12546768756682242],
    [0.037109375, 0.0, 0.0, 0.17025221101954405, 0.06021653898045596, -0.017578125],
    [
        0.03709200011850479,
        0.0,
        0.0,
        0.17038392571223998,
        0.10726203044637328,
        -0.015319437748624402,
        0.008273789163814023,
    ],
    [
        0.6241109587160757,
        0.0,
        0.0,
        -3.3608926294469414,
        -0.868219346841726,
        27.59209969944671,
        20.154067550477894,
        -43.48988418106996,
    ],
    [
        0.47766253643826434,
        0.0,
        0.0,
        -2.4881146199716677,
        -0.590290826836843,
        21.230051448181193,
        15.279233632882423,
        -33.28821096898486,
        -0.020331201708508627,
    ],
    [
        -0.9371424300859873,
        0.0,
        0.0,
        5.186372428844064,
        1.0914373489967295,
        -8.149787010746927,
        -18.52006565999696,
        22.739487099350505,
        2.4936055526796523,
        -3.0467644718982196,
    ],
    [
        2.273310147516538,
        0.0,
        0.0,
        -10.53449546673725,
        -2.0008720582248625,
        -17.9589318631188,
        27.94888452941996,
        -2.8589982771350235,
        -8.87285693353063,
        12.360567175794303,
        0.6433927460157636,
    ],
]
A = np.zeros((N_STAGES, N_STAGES))
for _i, _row in enumerate(_A_ROWS):
    A[_i, : len(_row)] = _row

#: Weights b_i of the 8th-order solution.
B = np.array(
    [
        0.054293734116568765,
        0.0,
        0.0,
        0.0,
        0.0,
        4.450312892752409,
        1.8915178993145003,
        -5.801203960010585,
        0.3111643669578199,
        -0.1521609496625161,
        0.20136540080403034,
        0.04471061572777259,
    ]
)

#: Error estimators of orders 3 and 5 (over the 12 stages and the new point's derivative).
E3 = np.array(
    [
        -0.18980075407240762,
        0.0,
        0.0,
        0.0,
        0.0,
        4.450312892752409,
        1.8915178993145003,
        -5.801203960010585,
        -0.4226823213237919,
        -0.1521609496625161,
        0.20136540080403034,
        0.02265179219836082,
        0.0,
    ]
)
E5 = np.array(
    [
        0.01312004499419488,
        0.0,
        0.0,
        0.0,
        0.0,
        -1.2251564463762044,
        -0.4957589496572502,
        1.6643771824549864,
        -0.35032884874997366,
        0.3341791187130175,
        0.08192320648511571,
        -0.022355307863886294,
        0.0,
    ]
)

# The integrator :func:`integrate`: its step-size control (as SciPy's ``solve_ivp``).
_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0
_EXPONENT = -1.0 / 8.0  # error estimator of order 7
#: Tolerances of the continuous integrator on x (relative and absolute).
RTOL = 1e-12
ATOL = 1e-12
#: A run whose task error fell by less than the fraction :data:`PLATEAU_DECREASE` over
#: :data:`PLATEAU_TAU` of tau while x moved by less than :data:`PLATEAU_MOVE` (1 + ||x||) has
#: stalled: it has settled at a point it cannot leave (damped least squares at the point nearest
#: a target out of reach, where the flow is stiff and its steps are short).
PLATEAU_DECREASE = 1e-9
PLATEAU_MOVE = 1e-10
PLATEAU_TAU = 5.0
#: A run's step budget is cut into :data:`PACE_WINDOWS` windows, and at the end of each the run
#: compares the fall of ln ||e|| over it (its pace; Delta tau for a right inverse, eq. (5)) with
#: the window before. A pace that fell and that, kept for every step left, would not bring
#: ||e|| below tol, has stalled: the flow nears a point where J# is undefined (a kinematic
#: singularity, or a joint pressed against its limit by the weighted inverse) in a finite tau
#: that its shrinking steps approach but do not reach, and the steps left would be spent there.
#: A run that is only slow keeps its pace.
#: Only a right inverse's pace says so: damped least squares (J J# != I) settles at a task error
#: above 0 by design, where the plateau rule stops it.
PACE_WINDOWS = 20


def _rhs(inverse: Inverse, x: FloatArray, y_d: FloatArray):
    """-J#(x) (k(x) - y_d) per unit tau = gamma theta; also e and the singular mask."""
    e = inverse.kinematics.forward_unchecked(x) - y_d
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
    h = np.minimum(100 * h0, h1)
    # A trial point where k is not finite (a formula's log or sqrt past its domain) gives no
    # estimate (NaN, a step never accepted nor shrunk): start from h0, which the step control
    # shrinks until the stages are finite.
    return np.where(np.isfinite(h) & (h > 0), h, np.where(np.isfinite(h0) & (h0 > 0), h0, 1e-6))


def _decay_rate(inverse: Inverse, x: FloatArray) -> FloatArray:
    """The rate at which the task error of (7) falls at the starts ``x`` (n, p) under an
    inverse that is not a right inverse: along de/dtau = -J J# e, ||e|| falls at least at the
    least eigenvalue of the symmetric part of J J# (damped least squares: sigma^2 / (sigma^2 +
    lambda^2) for the least singular value sigma of J); within [1e-3, 1], 1 where unknown."""
    (n, p), r = x.shape, inverse.kinematics.r
    J = inverse.kinematics.jacobian_unchecked(x)
    # J# e_i for each unit task vector e_i, in one batch: row (k, i) is start k's column i
    columns = inverse.apply_masked(np.repeat(x, r, axis=0), np.tile(np.eye(r), (n, 1)))[0]
    M = J @ np.swapaxes(columns.reshape(n, r, p), -1, -2)  # (n, r, r): J J#
    with np.errstate(all="ignore"):
        least = np.linalg.eigvalsh(0.5 * (M + np.swapaxes(M, -1, -2)))[..., 0]
    return np.where(np.isfinite(least), np.clip(least, 1e-3, 1.0), 1.0)


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


def _pace_stall(status, run, nsteps, cap, window, err, tol, pace_step, pace_err, pace) -> None:
    """Mark STALLED the members of ``run`` whose pace window (``window`` steps, a
    :data:`PACE_WINDOWS`-th of their budget ``cap``) ended with a pace (the fall of ln ||e||
    over it) below the window before's and too slow for the steps left to bring ||e|| below
    ``tol``; then start their next window. Updates in place."""
    due = run[(nsteps[run] >= pace_step[run]) & (status[run] == Status.RUNNING)]
    with np.errstate(divide="ignore", invalid="ignore"):
        now = np.log(pace_err[due] / err[due])
        short = now * (cap[due] - nsteps[due]) < np.log(err[due] / tol) * window[due]
    status[due[(now < pace[due]) & short]] = Status.STALLED
    pace[due], pace_err[due], pace_step[due] = now, err[due], nsteps[due] + window[due]


def integrate(inverse, x0, y_d, tol, max_steps, record, tau0, rtol=RTOL, atol=ATOL):
    """Batched DOP853 on dx/dtau = -J# e from tau = tau0 until ||e|| < tol, at most
    ``max_steps`` steps (an int, or one per member: shape (n,))."""
    n, p = x0.shape
    cap = np.broadcast_to(np.asarray(max_steps), (n,))
    x = x0.copy()
    tau = tau0.copy()
    f, e, bad = _rhs(inverse, x, y_d)
    err0 = np.linalg.norm(e, axis=-1)
    status = np.full(n, Status.RUNNING)
    status[bad] = Status.SINGULAR
    status[err0 < tol] = Status.CONVERGED
    # exp(-rate tau) decay: tau_needed = ln(err0 / tol) / rate; far past that the run has
    # stalled (rate 1 for a right inverse, eq. (5)).
    rate = 1.0 if inverse.right_inverse else _decay_rate(inverse, x0)
    tau_cap = tau0 + (np.log(np.maximum(err0, tol) / tol) + 40.0) / rate
    err_now = err0.copy()
    # (the last checkpoint of each run's error and x)
    plateau_tau, plateau_err, plateau_x = tau0 + PLATEAU_TAU, err0.copy(), x0.copy()
    # (the step and error at the start of each run's pace window, the pace of the window
    # before: NaN, which no pace falls below, before the first)
    window = np.maximum(cap // PACE_WINDOWS, 1)
    pace_step, pace_err, pace = window.copy(), err0.copy(), np.full(n, np.nan)
    h = _initial_step(inverse, x, f, y_d, rtol, atol)
    nsteps = np.zeros(n, dtype=int)
    last_bad = np.zeros(n, dtype=bool)
    rec: Record | None = [(np.arange(n), tau.copy(), x.copy())] if record else None
    K = np.empty((N_STAGES + 1, n, p))
    while True:
        idx = np.flatnonzero(status == Status.RUNNING)
        if idx.size == 0:
            break
        m = idx.size
        xs, hs, yds = x[idx], h[idx], y_d[idx]
        Ks = K[:, :m]
        Ks[0] = f[idx]
        stage_bad = np.zeros(m, dtype=bool)
        for s in range(1, N_STAGES):
            dx = _combine(A[s, :s], Ks[:s]) * hs[:, None]
            Ks[s], _, b = _rhs(inverse, xs + dx, yds)
            stage_bad |= b
        x_new = xs + hs[:, None] * _combine(B, Ks[:N_STAGES])
        f_new, e_new, b = _rhs(inverse, x_new, yds)
        stage_bad |= b
        Ks[N_STAGES] = f_new
        scale = atol + np.maximum(np.abs(xs), np.abs(x_new)) * rtol
        err5 = np.sum((_combine(E5, Ks) / scale) ** 2, axis=-1)
        err3 = np.sum((_combine(E3, Ks) / scale) ** 2, axis=-1)
        denom = err5 + 0.01 * err3
        with np.errstate(divide="ignore", invalid="ignore"):
            enorm = np.where(denom > 0, hs * err5 / np.sqrt(denom * p), 0.0)
            enorm = np.where(np.isfinite(enorm), enorm, np.inf)
            factor = np.where(
                enorm == 0,
                _MAX_FACTOR,
                np.clip(_SAFETY * enorm**_EXPONENT, _MIN_FACTOR, _MAX_FACTOR),
            )
        # A right inverse's task error falls along (7) as exp(-tau) (eq. (5)): a step that
        # raised it is refused, however small its error in x (a task of large ||J|| turns an
        # error in x within RTOL into a task error above tol, near the end of a run).
        err_new = np.linalg.norm(e_new, axis=-1)
        grew = (err_new > err_now[idx]) & bool(inverse.right_inverse)
        accept = (enorm < 1.0) & ~stage_bad & ~grew
        factor = np.where(accept, factor, np.minimum(factor, 1.0))
        factor = np.where(grew, np.minimum(factor, 0.5), factor)
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
        err_now[ai] = err_new[accept]
        status[ai[err_now[ai] < tol]] = Status.CONVERGED
        run = idx[status[idx] == Status.RUNNING]
        tiny = h[run] < 1e-12 * (1.0 + tau[run])
        status[run[tiny & last_bad[run]]] = Status.SINGULAR
        status[run[tiny & ~last_bad[run]]] = Status.STALLED
        status[run[tau[run] > tau_cap[run]]] = Status.STALLED
        due = run[tau[run] >= plateau_tau[run]]
        moved = np.linalg.norm(x[due] - plateau_x[due], axis=-1)
        settled = (err_now[due] > (1.0 - PLATEAU_DECREASE) * plateau_err[due]) & (
            moved <= PLATEAU_MOVE * (1.0 + np.linalg.norm(x[due], axis=-1))
        )
        status[due[settled]] = Status.STALLED
        plateau_tau[due] = tau[due] + PLATEAU_TAU
        plateau_err[due], plateau_x[due] = err_now[due], x[due]
        if inverse.right_inverse:
            _pace_stall(status, run, nsteps, cap, window, err_now, tol, pace_step, pace_err, pace)
        status[run[np.linalg.norm(x[run], axis=-1) > DIVERGED_NORM]] = Status.DIVERGED
        status[run[(nsteps[run] >= cap[run]) & (status[run] == Status.RUNNING)]] = Status.MAX_STEPS
    return x, tau, status, nsteps, rec
