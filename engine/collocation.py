"""The characteristic (28) of section 4, batched: Chebyshev-Lobatto collocation in s on [0, 1]
with Newton's method, and the variational equations as the linearisation of the same system.

The linear homotopy Phi_s (eqs. (21), (22), (45)) contracts every configuration onto a reference
leaf; the characteristic started at z(1) = z ends at z(0) = h(x), eq. (29). Its sensitivities
S = dz(s)/dx solve the linearised collocation system, so dh = S(0) is exact for the computed h.
:class:`jik.engine.characteristics.CharacteristicsMap` is the augmenting map built on it.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from .kinematics import Kinematics
from .one_form import derivatives, one_form_parts
from .unicycle import Unicycle
from .validation import FloatArray, as_vector, count

#: Default number of collocation nodes in s (including s = 0 and s = 1).
COLLOCATION_NODES = 24
#: Newton iterations on the collocation system before giving up.
NEWTON_MAX = 30
#: Newton stops when the largest update is below this (relative to 1 + |z|); by quadratic
#: convergence z is then exact to rounding, and dh (linearised one update earlier) to ~NEWTON_TOL.
NEWTON_TOL = 1e-12
#: On fine grids rounding can keep updates above NEWTON_TOL: an update below NEWTON_FLOOR that
#: did not shrink by 4x (quadratic convergence would shrink it far more) counts as converged.
NEWTON_FLOOR = 1e-9
#: Largest relative size of the last three Chebyshev coefficients of z(s) accepted before the
#: characteristic is solved again on a finer nested grid (2n - 1 nodes, see REFINE_LEVELS).
TAIL_TOL = 1e-10
#: A Chebyshev tail still above this after refinement means the characteristic is not resolved
#: (it runs into a near-zero of omega's normalising component): h is reported undefined there.
TAIL_FAIL = 1e-6
#: Refinement levels (grids of (n - 1) 2^k + 1 nodes, k = 1 .. REFINE_LEVELS).
REFINE_LEVELS = 1
#: Most members solved in one batched Newton solve: its arrays (the collocation systems on the
#: refined grid, (B, 2n - 1, 2n - 1) each) grow with the batch; larger batches are solved this
#: many members at a time, which bounds a worker's memory whatever the number of points.
MAX_MEMBERS = 1024


class LinearHomotopy:
    """Phi_t(x) = t x + (1 - t) x_ref on the components transverse to the leaves, eq. (45).

    The leaf coordinate z = x[fixed_index] is left unchanged, so Phi_1 = id, Phi_0 maps onto the
    reference leaf {x : x_j = x_ref_j for j != fixed_index} and Phi_s o Phi_t = Phi_st.
    X(x) = dPhi_t/dt at t = 1 = x - x_ref (zero in the z component), eq. (21), and
    t dPhi_t/dt = X(Phi_t), eq. (22).
    """

    def __init__(self, reference, fixed_index: int) -> None:
        self.reference = as_vector(reference, np.size(reference), "reference point").copy()
        self.fixed_index = count(fixed_index, "fixed_index", 0, self.reference.size - 1)
        self.reference[self.fixed_index] = 0.0
        self.transverse = np.ones(self.reference.size)
        self.transverse[self.fixed_index] = 0.0

    def __call__(self, x: FloatArray, t) -> FloatArray:
        """Phi_t(x): x (..., p), t broadcastable to x[..., 0]."""
        t = np.asarray(t, dtype=float)[..., None]
        return x + (t - 1.0) * self.field(x)

    def field(self, x: FloatArray) -> FloatArray:
        """X(x), eq. (21)."""
        return (x - self.reference) * self.transverse


@functools.lru_cache(maxsize=8)
def collocation(n: int) -> tuple[FloatArray, FloatArray]:
    """Chebyshev-Lobatto nodes s (n,) on [0, 1] (s[0] = 0, s[-1] = 1) and the matrix W (n, n).

    ``(W g)_i`` is the integral from s_i to 1 of the interpolating polynomial of g at the nodes.
    """
    cheb = np.polynomial.chebyshev
    u = -np.cos(np.pi * np.arange(n) / (n - 1))  # [-1, 1], increasing
    V = cheb.chebvander(u, n - 1)  # (n, n)
    A = np.empty((n, n))
    for k in range(n):
        P = cheb.chebint(np.eye(n)[k])
        A[:, k] = cheb.chebval(1.0, P) - cheb.chebval(u, P)
    W = 0.5 * A @ np.linalg.inv(V)
    s = 0.5 * (u + 1.0)
    s.flags.writeable = False
    W.flags.writeable = False
    return s, W


@functools.lru_cache(maxsize=8)
def _chebyshev_analysis(n: int) -> FloatArray:
    """(n, n) matrix: values at the Lobatto nodes of :func:`collocation` -> Chebyshev coeffs."""
    u = -np.cos(np.pi * np.arange(n) / (n - 1))
    out = np.linalg.inv(np.polynomial.chebyshev.chebvander(u, n - 1))
    out.flags.writeable = False
    return out


@functools.lru_cache(maxsize=8)
def _chebyshev_resample(n_from: int, n_to: int) -> FloatArray:
    """(n_to, n_from) matrix interpolating from one Lobatto grid onto another."""
    u = -np.cos(np.pi * np.arange(n_to) / (n_to - 1))
    out = np.polynomial.chebyshev.chebvander(u, n_from - 1) @ _chebyshev_analysis(n_from)
    out.flags.writeable = False
    return out


def moments_ignore(kinematics: Kinematics, fixed_index: int) -> bool:
    """Whether the kinematics' quadrature moments ignore the leaf coordinate x[fixed_index].

    True for the unicycle with z = lambda10 or lambda11 (q3 depends on lambda20, lambda21
    only): Newton, which varies only z, then reuses the moments of the base points.
    """
    return isinstance(kinematics, Unicycle) and fixed_index in (0, 1)


def _collocate(kin: Kinematics, homotopy: LinearHomotopy, xb, Y, n, guess):
    """Newton on the n-node collocation system of (28) and its variational system.

    Returns Z (B, n), S (B, n, p), the 'omega undefined' mask (B, n), Newton's convergence
    flags (B,), the points Phi_s (B, n, p) and the Chebyshev tail of Z (B,) (error estimate).
    """
    s, W = collocation(n)
    f = homotopy.fixed_index
    base = homotopy(xb, 0.0)[:, None, :] + s[:, None] * Y[:, None, :]  # (B, n, p)
    z1 = xb[:, f : f + 1]
    Z = np.repeat(z1, n, axis=1) if guess is None else guess  # cold: z(s) = z(1)
    eye = np.eye(n)
    # Quadrature moments that do not depend on the leaf coordinate are computed once.
    # (moments_ignore implies a Unicycle; the isinstance tells the type checker.)
    uni = kin if isinstance(kin, Unicycle) and moments_ignore(kin, f) else None
    mom = None if uni is None else uni.moments(base)

    def derivs(pts: FloatArray) -> tuple[FloatArray, FloatArray]:
        return derivatives(kin, pts) if uni is None else uni.derivatives(pts, moments=mom)

    with np.errstate(all="ignore"):
        prev = np.full(len(xb), np.inf)
        conv = np.zeros(len(xb), dtype=bool)
        for _ in range(NEWTON_MAX):
            pts = base.copy()
            pts[..., f] = Z
            omega, domega, bad = one_form_parts(*derivs(pts), f)
            DY = np.einsum("bnkj,bk->bnj", domega, Y)  # (d omega / dx) Y, (B, n, p)
            A = eye - W * DY[:, None, :, f]  # I + W diag(G_z), G_z = -(d omega/dz) Y
            R = Z - z1 - (omega @ Y[:, :, None])[..., 0] @ W.T  # G = -omega Y
            dZ = np.linalg.solve(A, R[..., None])[..., 0]
            Z = Z - dZ
            step = np.max(np.abs(dZ) / (1.0 + np.abs(Z)), axis=-1, initial=0.0)
            # converged: below NEWTON_TOL, or stalled at the rounding floor of a fine grid
            conv |= (step <= NEWTON_TOL) | ((step <= NEWTON_FLOOR) & (step > 0.25 * prev))
            prev = step
            if np.all(conv | ~np.isfinite(step)):  # NaN members are flagged by the caller
                break
        Gy = -s[:, None] * DY - omega  # (B, n, p)
        rhs = -(W @ Gy)  # d/dy_j columns
        rhs[..., f] = 1.0  # d/dz(1) column
        S = np.linalg.solve(A, rhs)
        coef = Z @ _chebyshev_analysis(n).T  # Chebyshev coefficients of z(s)
    tail = np.max(np.abs(coef[:, -3:]), axis=-1) / (1.0 + np.max(np.abs(Z), axis=-1))
    return Z, S, bad, conv & np.isfinite(step), pts, tail


def solve_characteristics(
    kin: Kinematics, homotopy: LinearHomotopy, xb: FloatArray, n: int, guess=None
) -> tuple[FloatArray, FloatArray, FloatArray, Any]:
    """The characteristics (28) through the points ``xb`` (B, p) on ``n`` nodes, at most
    :data:`MAX_MEMBERS` members per batched solve.

    Returns Z (B, n), S (B, n, p), the failure mask (B,) and where the first failure is (None if
    none): (Phi_s or None, s or None, x) (see
    :meth:`jik.engine.characteristics.CharacteristicsMap.characteristic`).
    """
    B, p = xb.shape
    Z, S, failed = np.empty((B, n)), np.empty((B, n, p)), np.empty(B, dtype=bool)
    where = None
    for lo in range(0, B, MAX_MEMBERS):
        part = slice(lo, lo + MAX_MEMBERS)
        Z[part], S[part], failed[part], first = _characteristic(
            kin, homotopy, xb[part], n, None if guess is None else guess[part]
        )
        where = first if where is None else where
    return Z, S, failed, where


def _characteristic(kin, homotopy, xb, n, g) -> tuple[FloatArray, FloatArray, FloatArray, Any]:
    """The characteristics through the points ``xb`` (B, p) in one batched solve, refined where
    their Chebyshev tail is too large, and where the first failure is (None if none)."""
    Y = homotopy.field(xb)  # (B, p)
    Z, S, bad_nodes, conv, pts, tail = _collocate(kin, homotopy, xb, Y, n, g)
    bad = np.any(bad_nodes, axis=-1)
    active, Zc, m_prev = np.arange(len(xb)), Z, n
    for level in range(1, REFINE_LEVELS + 1):
        need = ~(tail[active] <= TAIL_TOL) & np.isfinite(tail[active]) & ~bad[active]
        if not np.any(need):
            break
        active, Zc = active[need], Zc[need]
        m = (n - 1) * 2**level + 1
        Zf, Sf, badf, convf, _, tailf = _collocate(
            kin, homotopy, xb[active], Y[active], m, Zc @ _chebyshev_resample(m_prev, m).T
        )
        ok = convf & ~np.any(badf, axis=-1) & np.all(np.isfinite(Sf), (1, 2))
        sub = 2**level  # nested grids: every sub-th fine node is a base node
        upd = active[ok]
        Z[upd], S[upd], tail[upd] = Zf[ok, ::sub], Sf[ok, ::sub], tailf[ok]
        active, Zc, m_prev = active[ok], Zf[ok], m
    failed = bad | ~np.all(np.isfinite(S[:, 0, :]), axis=-1)
    failed |= ~np.all(np.isfinite(Z), axis=-1) | ~conv | ~(tail <= TAIL_FAIL)
    where = None
    s0 = collocation(n)[0]
    if np.any(failed):
        i = np.flatnonzero(failed)[0]
        j = np.flatnonzero(bad_nodes[i])
        where = (pts[i, j[0]], s0[j[0]], xb[i]) if j.size else (None, None, xb[i])
    return Z, S, failed, where
