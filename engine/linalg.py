"""Small batched linear algebra with few numpy calls (the solver's hot path).

The pseudoinverse's step J^T (J J^T)^-1 e, eq. (8), by Gram-Schmidt on J's rows
(:func:`min_norm_solve`, accurate to ~ kappa(J) eps); square systems by Cramer's rule written
out (:func:`solve_small`): ``np.linalg.solve`` on (n, 2, 2) or (n, 3, 3) stacks spends most of
its time in per-call overhead, and the rule written out is several times faster.
"""

from __future__ import annotations

import numpy as np

from .validation import FloatArray


def gram(J: FloatArray) -> FloatArray:
    """J J^T for a batch of small (..., r, p) matrices, entry by entry.

    ``J @ J^T`` on stacks of 2 x 3 matrices runs numpy's generic matmul loop per member and costs
    about three times as much as these r (r + 1) / 2 row dot products.
    """
    r = J.shape[-2]
    M = np.empty((*J.shape[:-1], r))
    for i in range(r):
        for j in range(i, r):
            M[..., i, j] = M[..., j, i] = np.einsum("...k,...k->...", J[..., i, :], J[..., j, :])
    return M


_NEXT, _AFTER = [1, 2, 0], [2, 0, 1]


def cofactor_rows(A: FloatArray) -> FloatArray:
    """Rows a1 x a2, a2 x a0, a0 x a1 of a batch of 3 x 3 matrices with rows a0, a1, a2.

    They are the columns of the adjugate: A^-1 = C^T / det A, det A = a0 . (a1 x a2). Written
    with index arrays: ``np.cross`` spends most of its time moving axes (80 us a call on 500
    members, against 10 us of arithmetic).
    """
    P, Q = A[..., _NEXT, :], A[..., _AFTER, :]  # rows i+1 and i+2
    return P[..., _NEXT] * Q[..., _AFTER] - P[..., _AFTER] * Q[..., _NEXT]


def det_small(A: FloatArray) -> FloatArray:
    """Determinant of (..., n, n) with n <= 3 written out, else ``np.linalg.det``."""
    n = A.shape[-1]
    if n == 2:
        return A[..., 0, 0] * A[..., 1, 1] - A[..., 0, 1] * A[..., 1, 0]
    if n == 3:
        return np.einsum("...i,...i->...", A[..., 0, :], cofactor_rows(A)[..., 0, :])
    return np.linalg.det(A)


def solve_small(A: FloatArray, b: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Solve A z = b for a batch; returns z (..., n) and det(A) (...,).

    Members with det(A) = 0 get non-finite z; callers mask them with their own criterion.
    """
    n = A.shape[-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        if n == 2:
            d = det_small(A)
            z0 = (A[..., 1, 1] * b[..., 0] - A[..., 0, 1] * b[..., 1]) / d
            z1 = (A[..., 0, 0] * b[..., 1] - A[..., 1, 0] * b[..., 0]) / d
            return np.stack([z0, z1], axis=-1), d
        if n == 3:
            C = cofactor_rows(A)  # A^-1 = C^T / det
            d = np.einsum("...i,...i->...", A[..., 0, :], C[..., 0, :])
            return np.einsum("...ij,...i->...j", C, b) / d[..., None], d
    d = np.linalg.det(A)
    ok = np.abs(d) > 0
    safe = np.where(ok[..., None, None], A, np.eye(n))
    z = np.linalg.solve(safe, b[..., None])[..., 0]
    return np.where(ok[..., None], z, np.nan), d


def min_norm_solve(J: FloatArray, e: FloatArray) -> tuple[FloatArray, FloatArray]:
    """J^T (J J^T)^-1 e, eq. (8), for a batch J (..., r, p) and e (..., r); returns it (..., p)
    and det(J J^T) = m(x)^2 (...,).

    Modified Gram-Schmidt on J's rows: J = L U with L unit lower triangular and U's rows u_i
    orthogonal (u_i / |u_i| are the columns of Q and |u_i| the diagonal of R in J^T = Q R), so
    the step is sum_i z_i u_i / |u_i|^2 with L z = e, and det(J J^T) = prod |u_i|^2. Unlike
    Cramer's rule on the normal equations (error ~ kappa(J)^2 eps) the step is accurate to
    ~ kappa(J) eps, and m = sqrt(det) to ~ eps |J|^r absolutely. Members with a zero row u_i
    get non-finite steps and det 0 (NaN only from a non-finite J): callers mask them with det.
    The rows are moved to the front so that each operation runs over the batch's contiguous
    lanes.
    """
    nd = J.ndim
    lead = tuple(range(nd - 2))
    rows = J.transpose(nd - 2, nd - 1, *lead).astype(float, order="C")  # (r, p, ...)
    z = np.asarray(e, dtype=float).transpose(nd - 2, *lead).copy()  # (r, ...)
    v, det = _orthogonal_solve(rows, z)
    return v.transpose(*range(1, nd - 1), 0), det


def min_norm_matrix(J: FloatArray) -> tuple[FloatArray, FloatArray]:
    """J^T (J J^T)^-1, eq. (8), shape (..., p, r), and det(J J^T) (...,): :func:`min_norm_solve`
    with e the r columns of the identity, in one factorisation."""
    nd, r = J.ndim, J.shape[-2]
    lead = tuple(range(nd - 2))
    rows = J.transpose(nd - 2, nd - 1, *lead)[:, :, None].astype(float, order="C")
    z = np.broadcast_to(np.eye(r).reshape(r, r, *(1,) * (nd - 2)), (r, r, *J.shape[:-2]))
    v, det = _orthogonal_solve(rows, z.copy())  # v: (p, r, ...)
    return v.transpose(*range(2, nd), 0, 1), det[0]


def _orthogonal_solve(rows: FloatArray, z: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Gram-Schmidt of :func:`min_norm_solve` on ``rows`` (r, p, ...), overwritten, with L z = e
    solved in place in ``z`` (r, ...; broadcast against rows[i]'s batch axes); returns
    sum_i z_i u_i / |u_i|^2 and prod |u_i|^2."""
    r = rows.shape[0]
    s = np.empty((r, *rows.shape[2:]))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for i in range(r):
            u = rows[i]
            s[i] = np.einsum("k...,k...->...", u, u)
            if i + 1 < r:  # the rows after i lose their component along u_i
                c = np.einsum("jk...,k...->j...", rows[i + 1 :], u) / s[i]
                rows[i + 1 :] -= c[:, None] * u
                z[i + 1 :] -= c * z[i]
        z /= s
        v, det = rows[0] * z[0], s[0]
        for i in range(1, r):
            v += rows[i] * z[i]
            det = det * s[i]
    if np.isnan(det).any():  # a zero row u_i (0/0 in the rows after it): J J^T is singular
        det = np.where(np.any(s == 0, axis=0), 0.0, det)
    return v, det
