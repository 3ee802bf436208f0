"""Synthesis of an augmenting map by characteristics, one degree of redundancy (section 4).

(It stays whole, at about 610 lines: the one-form, the homotopy and the map class share the
collocation nodes, the Newton system and its linearisation, from which the exact gradient comes;
split, the gradient would live apart from the system it differentiates.)

The one-form omega annihilates J^T (omega J^T = 0) and is normalised by one component,
``omega[fixed_index] = 1``. A linear homotopy Phi_s contracts every configuration onto a reference
leaf along the components transverse to the leaves, eqs. (21), (22), (45); the augmenting map h is
the end point z(0) of the characteristic (28) started at z(1) = z, eq. (29). Its exact gradient
comes from the variational equations along the same characteristic.

The characteristic is solved by spectral (Chebyshev-Lobatto) collocation in s on [0, 1] with
Newton's method, for a whole batch at once; the variational equations are the linearisation of
the same collocation system, so the gradient is exact for the computed h.
"""

from __future__ import annotations

import functools
import itertools
from typing import Any

import numpy as np

from jik.engine.augmentations import AugmentingMap
from jik.engine.exceptions import InvalidInputError, OneFormUndefinedError, format_vector
from jik.engine.kinematics import SINGULAR_MANIPULABILITY, Kinematics, kernel_cofactors
from jik.engine.progress import Progress, check_cancelled
from jik.engine.unicycle import Unicycle
from jik.engine.validation import FloatArray, as_vector, count, finite

#: |kernel component fixed_index| <= ONE_FORM_TOL |kernel| counts as "omega undefined" (so does a
#: kinematic singularity, |kernel cofactors| = m(x) < SINGULAR_MANIPULABILITY).
ONE_FORM_TOL = 1e-9
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
#: Warm-start Newton from the previous characteristics when x moved by at most this (max norm).
WARM_RADIUS = 0.5
#: Most members solved in one batched Newton solve: its arrays (the collocation systems on the
#: refined grid, (B, 2n - 1, 2n - 1) each) grow with the batch; larger batches are solved this
#: many members at a time, which bounds a worker's memory whatever the number of points.
MAX_MEMBERS = 1024


def _levi_civita(p: int) -> FloatArray:
    eps = np.zeros((p,) * p)
    for perm in itertools.permutations(range(p)):
        eps[perm] = np.linalg.det(np.eye(p)[list(perm)])
    return eps


#: Levi-Civita symbol of R^4, shape (4, 4, 4, 4), and its reshapes for contracting two rows:
#: _E23[(k, l), (i, j)] = _E13[(j, l), (i, k)] = _E12[(j, k), (i, l)] = eps_ijkl.
_EPS4 = _levi_civita(4)
_E23 = _EPS4.transpose(2, 3, 0, 1).reshape(16, 16)
_E13 = _EPS4.transpose(1, 3, 0, 2).reshape(16, 16)
_E12 = _EPS4.transpose(1, 2, 0, 3).reshape(16, 16)


def _contract(E: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """The 4 x 4 matrix E : (a outer b), e.g. P23_ij = eps_ijkl a_k b_l: (..., 4, 4)."""
    return ((a[..., :, None] * b[..., None, :]).reshape(*a.shape[:-1], 16) @ E).reshape(
        *a.shape[:-1], 4, 4
    )


def cofactors(J: FloatArray) -> FloatArray:
    """Kernel cofactor vector of J (..., r, r + 1), as
    :func:`jik.engine.kinematics.kernel_cofactors`.

    For r = 3, c_i = -eps_ijkl J_1j J_2k J_3l (Levi-Civita), a few einsum calls instead of
    batched determinants; other sizes fall back to the generic determinant formula.
    """
    if J.shape[-2:] != (3, 4):
        return kernel_cofactors(J)
    P23 = _contract(_E23, J[..., 1, :], J[..., 2, :])
    return -(P23 @ J[..., 0, :, None])[..., 0]


def _cofactors_and_derivative34(J: FloatArray, H: FloatArray) -> tuple[FloatArray, FloatArray]:
    """c (..., 4) and dc/dx (..., 4, 4) for r = 3 from the Levi-Civita contractions."""
    R1, R2, R3 = J[..., 0, :], J[..., 1, :], J[..., 2, :]
    P23, P13, P12 = _contract(_E23, R2, R3), _contract(_E13, R1, R3), _contract(_E12, R1, R2)
    c = -(P23 @ R1[..., None])[..., 0]
    return c, -(P23 @ H[..., 0, :, :] + P13 @ H[..., 1, :, :] + P12 @ H[..., 2, :, :])


def kernel_cofactors_derivative(J: FloatArray, H: FloatArray) -> FloatArray:
    """Derivative of the kernel cofactor vector c(J(x)) with respect to x.

    Parameters
    ----------
    J : ndarray, shape (..., r, r + 1)
        Jacobian.
    H : ndarray, shape (..., r, r + 1, r + 1)
        Its derivative, ``H[..., i, j, k] = d J_ij / d x_k``.

    Returns
    -------
    dc : ndarray, shape (..., p, p)
        ``dc[..., i, k] = d c_i / d x_k``.

    Notes
    -----
    c is the generalised cross product of the rows of J, multilinear in them, so
    dc/dx_k = sum_j c(J with row j replaced by dJ_j/dx_k).
    """
    r, p = J.shape[-2:]
    if (r, p) == (3, 4):
        return _cofactors_and_derivative34(J, H)[1]
    Jm = np.broadcast_to(J[..., None, None, :, :], (*J.shape[:-2], r, p, r, p)).copy()
    for j in range(r):
        Jm[..., j, :, j, :] = np.swapaxes(H[..., j, :, :], -1, -2)
    return np.swapaxes(kernel_cofactors(Jm).sum(axis=-3), -1, -2)


def _one_form_parts(J, H, fixed_index):
    """omega (..., p), d omega/dx (..., p, p) or None, and the 'undefined' mask (...,)."""
    dc: FloatArray | None
    if H is not None and J.shape[-2:] == (3, 4):
        c, dc = _cofactors_and_derivative34(J, H)
    else:
        c = cofactors(J)
        dc = None if H is None else kernel_cofactors_derivative(J, H)
    cf = c[..., fixed_index]
    norm = np.linalg.norm(c, axis=-1)  # = m(x), Cauchy-Binet
    bad = (np.abs(cf) <= ONE_FORM_TOL * norm) | ~(norm >= SINGULAR_MANIPULABILITY)
    cf = np.where(bad, 1.0, cf)
    omega = c / cf[..., None]
    if dc is None:  # H is None
        return omega, None, bad
    domega = (dc - omega[..., :, None] * dc[..., fixed_index, None, :]) / cf[..., None, None]
    return omega, domega, bad


def _check_index(kinematics: Kinematics, fixed_index) -> int:
    if kinematics.p - kinematics.r != 1:
        raise InvalidInputError("characteristics synthesis here needs one degree of redundancy")
    return count(fixed_index, "fixed_index", 0, kinematics.p - 1)


def _undefined_error(kinematics, x, bad, fixed_index, where=""):
    xb = np.reshape(x, (-1, kinematics.p))[np.flatnonzero(np.ravel(bad))[0]]
    return OneFormUndefinedError(
        f"the one-form omega (omega J^T = 0) of {kinematics.name} cannot be normalised by its "
        f"component {fixed_index} (0-based): that kernel component vanishes{where}",
        xb,
    )


def one_form(kinematics: Kinematics, x, fixed_index: int) -> FloatArray:
    """The one-form omega spanning the annihilator of J^T, normalised by one component (sec. 4).

    Parameters
    ----------
    kinematics : Kinematics
        With p = r + 1.
    x : array_like, shape (..., p)
    fixed_index : int
        0-based component set to 1 (the unicycle of sec. 6.1 uses lambda11, index 1).

    Returns
    -------
    omega : ndarray, shape (..., p)
        omega = c / c[fixed_index] with c the kernel cofactor vector, so omega J^T = 0.

    Raises
    ------
    OneFormUndefinedError
        Where |c[fixed_index]| <= ONE_FORM_TOL |c|, naming the configuration.
    """
    fixed_index = _check_index(kinematics, fixed_index)
    x = kinematics.check(x)
    omega, _, bad = _one_form_parts(kinematics.jacobian(x), None, fixed_index)
    if np.any(bad):
        raise _undefined_error(kinematics, x, bad, fixed_index)
    return omega


def one_form_derivative(
    kinematics: Kinematics, x, fixed_index: int
) -> tuple[FloatArray, FloatArray]:
    """omega (..., p) and its derivative d omega_i / d x_k (..., p, p).

    Needs ``kinematics.hessian`` (or ``kinematics.derivatives``); d omega follows analytically
    from the derivative of the kernel cofactors, :func:`kernel_cofactors_derivative`.
    """
    fixed_index = _check_index(kinematics, fixed_index)
    x = kinematics.check(x)
    J, H = _derivatives(kinematics, x)
    omega, domega, bad = _one_form_parts(J, H, fixed_index)
    if np.any(bad):
        raise _undefined_error(kinematics, x, bad, fixed_index)
    return omega, domega


def _derivatives(kinematics, x):
    if hasattr(kinematics, "derivatives"):
        return kinematics.derivatives(x)
    if hasattr(kinematics, "hessian"):
        return kinematics.jacobian(x), kinematics.hessian(x)
    raise InvalidInputError(f"{kinematics.name} has no hessian(); d omega needs second derivatives")


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


class CharacteristicsMap(AugmentingMap):
    """Augmenting map h(y, z) = z(0) of the characteristic (28), eq. (29), with its exact gradient.

    Parameters
    ----------
    kinematics : Kinematics
        p = r + 1, with ``hessian`` (needed for d omega).
    reference : array_like, shape (p,)
        A point of the reference leaf (its z component is ignored).
    fixed_index : int
        0-based index of the leaf coordinate z; omega is normalised with omega_z = 1.
    nodes : int
        Collocation nodes in s (default :data:`COLLOCATION_NODES`).
    on_undefined : {"raise", "nan"}
        What :meth:`value` and :meth:`gradient` do where omega is undefined along the
        characteristic (or Newton fails): raise :class:`OneFormUndefinedError`, or return NaN
        (the extended inverse then reports an algorithmic singularity there).

    Notes
    -----
    With Phi_s(y, z) = x_ref + s y (transverse), z (leaf), X(Phi_s) = s Y where Y = X(x), so
    eq. (28) reads dz/ds = -F(Phi_s)/s = -omega(Phi_s(y, z)) Y: regular at s = 0. The
    variational equations for S = dz(s)/d(y, z(1)) are
    dS/ds = G_z S + G_y, S(1) = (0, ..., 1), with G_z = -(d omega/dz) Y and
    G_y = -s (d omega/dy) Y - omega_y; then dh = S(0).
    """

    name = "characteristics"

    def __init__(
        self,
        kinematics: Kinematics,
        reference,
        fixed_index: int,
        nodes: int = COLLOCATION_NODES,
        on_undefined: str = "raise",
    ) -> None:
        self.kinematics = kinematics
        self.p = kinematics.p
        self.fixed_index = _check_index(kinematics, fixed_index)
        self.homotopy = LinearHomotopy(as_vector(reference, self.p, "reference"), fixed_index)
        self.nodes = count(nodes, "collocation nodes", 4, 200)
        if on_undefined not in ("raise", "nan"):
            raise InvalidInputError(f"on_undefined must be 'raise' or 'nan', got {on_undefined!r}")
        self.on_undefined = on_undefined
        self._cache: tuple | None = None
        #: Where the last characteristic() failed first: (Phi_s or None, s or None, x), or None.
        self._where: Any = None

    def moments_ignore(self, f: int) -> bool:
        """Whether the kinematics' quadrature moments ignore the leaf coordinate x[f].

        True for the unicycle with z = lambda10 or lambda11 (q3 depends on lambda20, lambda21
        only): Newton, which varies only z, then reuses the moments of the base points.
        """
        return isinstance(self.kinematics, Unicycle) and f in (0, 1)

    def _collocate(self, xb, Y, n, guess):
        """Newton on the n-node collocation system of (28) and its variational system.

        Returns Z (B, n), S (B, n, p), the 'omega undefined' mask (B, n), Newton's convergence
        flags (B,), the points Phi_s (B, n, p) and the Chebyshev tail of Z (B,) (error estimate).
        """
        s, W = collocation(n)
        f = self.fixed_index
        base = self.homotopy(xb, 0.0)[:, None, :] + s[:, None] * Y[:, None, :]  # (B, n, p)
        z1 = xb[:, f : f + 1]
        Z = np.repeat(z1, n, axis=1) if guess is None else guess  # cold: z(s) = z(1)
        eye = np.eye(n)
        kin = self.kinematics
        # Quadrature moments that do not depend on the leaf coordinate are computed once.
        # moments_ignore(f) implies kin is a Unicycle.
        uni = kin if isinstance(kin, Unicycle) and self.moments_ignore(f) else None
        mom = None if uni is None else uni.moments(base)

        def derivs(pts: FloatArray) -> tuple[FloatArray, FloatArray]:
            return _derivatives(kin, pts) if uni is None else uni.derivatives(pts, moments=mom)

        with np.errstate(all="ignore"):
            prev = np.full(len(xb), np.inf)
            conv = np.zeros(len(xb), dtype=bool)
            for _ in range(NEWTON_MAX):
                pts = base.copy()
                pts[..., f] = Z
                omega, domega, bad = _one_form_parts(*derivs(pts), f)
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

    def characteristic(
        self, x, guess=None
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Solve the characteristic (28) through each x, batched.

        Parameters
        ----------
        x : array_like, shape (..., p)
        guess : ndarray, shape (..., n), optional
            Initial z(s) at the n = ``nodes`` nodes for Newton (default: z(s) = z(1)).

        Returns
        -------
        s : ndarray, shape (n,)
            Collocation nodes, s[0] = 0, s[-1] = 1.
        z : ndarray, shape (..., n)
            z(s) at the nodes; h(x) = z[..., 0].
        S : ndarray, shape (..., n, p)
            dz(s)/dx at the nodes (variational equations); dh = S[..., 0, :].
        failed : ndarray of bool, shape (...,)
            Where omega is undefined along the characteristic or Newton failed.

        Notes
        -----
        Every Newton iteration evaluates omega and d omega at all nodes; the last update is at
        most NEWTON_TOL (relative), so the variational system, linearised at that last
        evaluation, gives dh consistent with h to about NEWTON_TOL. Members whose last three
        Chebyshev coefficients of z(s) exceed TAIL_TOL (a steep characteristic, e.g. one that
        passes near a zero of the normalising kernel component) are solved again on the nested
        Lobatto grid of 2n - 1 nodes (REFINE_LEVELS); results are returned on the n base nodes.
        Batches of more than MAX_MEMBERS are solved MAX_MEMBERS members at a time.
        """
        x = self.kinematics.check(x)
        shape = x.shape[:-1]
        xb = x.reshape(-1, self.p)
        n, B = self.nodes, len(xb)
        g = None if guess is None else np.array(guess, dtype=float).reshape(-1, n)
        Z, S, failed = np.empty((B, n)), np.empty((B, n, self.p)), np.empty(B, dtype=bool)
        where = None
        for lo in range(0, B, MAX_MEMBERS):
            part = slice(lo, lo + MAX_MEMBERS)
            Z[part], S[part], failed[part], first = self._characteristic(
                xb[part], None if g is None else g[part]
            )
            where = first if where is None else where
        self._where = where
        s0 = collocation(n)[0]
        return s0, Z.reshape(*shape, n), S.reshape(*shape, n, self.p), failed.reshape(shape)

    def _characteristic(self, xb, g) -> tuple[FloatArray, FloatArray, FloatArray, Any]:
        """:meth:`characteristic` of the points ``xb`` (B, p) in one batched solve, and where
        its first failure is (None if none): (Phi_s or None, s or None, x)."""
        n = self.nodes
        Y = self.homotopy.field(xb)  # (B, p)
        Z, S, bad_nodes, conv, pts, tail = self._collocate(xb, Y, n, g)
        bad = np.any(bad_nodes, axis=-1)
        active, Zc, m_prev = np.arange(len(xb)), Z, n
        for level in range(1, REFINE_LEVELS + 1):
            need = ~(tail[active] <= TAIL_TOL) & np.isfinite(tail[active]) & ~bad[active]
            if not np.any(need):
                break
            active, Zc = active[need], Zc[need]
            m = (n - 1) * 2**level + 1
            Zf, Sf, badf, convf, _, tailf = self._collocate(
                xb[active], Y[active], m, Zc @ _chebyshev_resample(m_prev, m).T
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

    def evaluate(self, x) -> tuple[FloatArray, FloatArray, FloatArray]:
        """h(x) (...,), dh/dx (..., p) and the failure mask (...,), without raising.

        Notes
        -----
        The last result is cached (the solver asks for h and dh at the same x), and Newton is
        warm-started from the last characteristics, extrapolated to first order with their
        sensitivities, when the batch has the same shape and moved by at most WARM_RADIUS; a
        warm start that fails is retried cold.
        """
        x = self.kinematics.check(x)
        last = self._cache
        if last is not None and last[0].shape == x.shape and np.array_equal(last[0], x):
            return last[1]
        guess = None
        if last is not None and last[0].shape == x.shape:
            dx = x - last[0]
            if np.max(np.abs(dx), initial=0.0) <= WARM_RADIUS:
                guess = last[3] + np.einsum("...nk,...k->...n", last[4], dx)
        _, Z, S, failed = self.characteristic(x, guess)
        if guess is not None and np.any(failed):
            _, Z, S, failed = self.characteristic(x)
        h = np.where(failed, np.nan, Z[..., 0])
        dh = np.where(failed[..., None], np.nan, S[..., 0, :])
        out = (h, dh, failed)
        self._cache = (x.copy(), out, self._where, Z, S)
        return out

    def evaluate_batches(
        self,
        x,
        batch: int = 45,
        progress: Progress | None = None,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """:meth:`evaluate` of a large set of points, ``batch`` members at a time.

        Parameters
        ----------
        x : array_like, shape (n, p)
        batch : int
            Members per Newton solve (each one cold, from z(s) = z(1): the result never depends
            on the order of the batches).
        progress : Progress, optional
            Told ``advance(batches_done, batches_total)`` after each batch, then asked whether to
            go on (:meth:`Progress.cancelled`: True raises ``RunCancelled``); what it raises
            stops the evaluation there.

        Returns
        -------
        h : ndarray, shape (n,)
        dh : ndarray, shape (n, p)
        failed : ndarray of bool, shape (n,)

        Notes
        -----
        Each member's characteristic (28) is its own Newton solve; a batch only shares the
        iterations, which go on until its slowest member converges. Batches bound that, so that
        a few slow members do not hold up the rest, and give the caller a place to report
        progress and to stop.
        """
        x = self.kinematics.check(x)
        xb = x.reshape(-1, self.p)
        size = count(batch, "batch", 1, 1_000_000)
        total = -(-len(xb) // size)
        h, dh = np.empty(len(xb)), np.empty((len(xb), self.p))
        failed = np.empty(len(xb), dtype=bool)
        for k in range(total):
            part = slice(k * size, (k + 1) * size)
            _, Z, S, bad = self.characteristic(xb[part])
            h[part] = np.where(bad, np.nan, Z[:, 0])
            dh[part] = np.where(bad[:, None], np.nan, S[:, 0, :])
            failed[part] = bad
            if progress is not None:
                progress.advance(k + 1, total)
                check_cancelled(progress, f"h evaluation cancelled after batch {k + 1} of {total}")
        shape = x.shape[:-1]
        return h.reshape(shape), dh.reshape(*shape, self.p), failed.reshape(shape)

    def _raise_if(self, failed) -> None:
        if self.on_undefined == "raise" and np.any(failed):
            assert self._cache is not None  # evaluate() ran first and filled it
            phi, s, x = self._cache[2]
            if phi is None:
                raise OneFormUndefinedError(
                    "h(x) is undefined: its characteristic (28) could not be resolved (Newton "
                    "on the collocation system did not converge or z(s) is unresolved): it runs "
                    f"into a near-zero of the kernel component {self.fixed_index} (0-based) of "
                    f"{self.kinematics.name}, where omega and dz/ds blow up",
                    x,
                )
            raise OneFormUndefinedError(
                f"h(x) is undefined: along its characteristic (28), at s = {s:.3g}, "
                f"Phi_s = {format_vector(phi)}, the kernel component {self.fixed_index} "
                f"(0-based) of {self.kinematics.name} vanishes, so omega cannot be normalised",
                x,
            )

    def value(self, x: FloatArray) -> FloatArray:
        """h(x) = z(0), eq. (29): (..., p) -> (...,)."""
        h, _, failed = self.evaluate(x)
        self._raise_if(failed)
        return h

    def gradient(self, x: FloatArray) -> FloatArray:
        """dh/dx from the variational equations: (..., p) -> (..., p)."""
        _, dh, failed = self.evaluate(x)
        self._raise_if(failed)
        return dh

    def value_masked(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """h(x) with NaN and a mask where it is undefined, whatever ``on_undefined`` says."""
        h, _, failed = self.evaluate(x)
        return h, np.asarray(failed, dtype=bool)

    def gradient_masked(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """dh/dx with NaN rows and a mask where h is undefined, whatever ``on_undefined`` says.

        The solver evaluates trial points (Runge-Kutta stages, Picard nodes) off the final path;
        one undefined trial point must stop that member only, not raise for the whole batch.
        """
        _, dh, failed = self.evaluate(x)
        return dh, np.asarray(failed, dtype=bool)


class UnicycleCharacteristics(CharacteristicsMap):
    """The unicycle's augmenting map of section 6.1: reference leaf E_{a,0} = a e1 + R e2.

    y1 = l10 - a, y2 = l20, y3 = l21, z = l11 (eq. (45), (46)); omega is normalised with
    omega2 = 1 (1-based), i.e. ``fixed_index = 1``.

    Parameters
    ----------
    kinematics : Unicycle
        The unicycle (its q0 and T define omega and so h).
    a : float
        Reference leaf parameter, a != 0 (omega is undefined at lambda10 = 0).
    """

    name = "characteristics"

    def __init__(
        self,
        kinematics: Unicycle | None = None,
        a: float = 1.0,
        nodes: int = COLLOCATION_NODES,
        on_undefined: str = "raise",
    ) -> None:
        self.a = finite(a, "a")
        if self.a == 0:
            raise InvalidInputError(
                "a must be nonzero: omega is undefined on lambda10 = 0, so the reference "
                "leaf E_{a,0} = a e1 + R e2 needs a != 0"
            )
        kinematics = Unicycle() if kinematics is None else kinematics
        super().__init__(kinematics, (self.a, 0.0, 0.0, 0.0), 1, nodes, on_undefined)

    @property
    def parameters(self) -> dict[str, float]:
        return {"a": self.a}


__all__ = [
    "CharacteristicsMap",
    "LinearHomotopy",
    "UnicycleCharacteristics",
    "cofactors",
    "collocation",
    "kernel_cofactors_derivative",
    "one_form",
    "one_form_derivative",
]
