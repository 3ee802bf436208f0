"""The one-form omega of section 4 and its derivative, batched.

omega annihilates J^T (omega J^T = 0) and is normalised by one component,
``omega[fixed_index] = 1``: it is the kernel cofactor vector of J divided by that component,
undefined where the component vanishes or J is singular. d omega needs the kinematics' second
derivatives.
"""

from __future__ import annotations

import itertools

import numpy as np

from .exceptions import InvalidInputError, OneFormUndefinedError
from .kinematics import SINGULAR_MANIPULABILITY, Kinematics, kernel_cofactors
from .validation import FloatArray, count

#: |kernel component fixed_index| <= ONE_FORM_TOL |kernel| counts as "omega undefined" (so does a
#: kinematic singularity, |kernel cofactors| = m(x) < SINGULAR_MANIPULABILITY).
ONE_FORM_TOL = 1e-9


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


def one_form_parts(J, H, fixed_index):
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


def check_index(kinematics: Kinematics, fixed_index) -> int:
    """``fixed_index`` checked for ``kinematics``, which must have one degree of redundancy."""
    if kinematics.p - kinematics.r != 1:
        raise InvalidInputError(
            "characteristics synthesis here needs one degree of redundancy (p - r = 1); "
            f"{kinematics.name} has p - r = {kinematics.p - kinematics.r}",
            "kinematics",
        )
    return count(fixed_index, "fixed_index", 0, kinematics.p - 1)


def undefined_error(kinematics, x, bad, fixed_index, where=""):
    """The error naming the first configuration of ``x`` where ``bad`` says omega is undefined."""
    xb = np.reshape(x, (-1, kinematics.p))[np.flatnonzero(np.ravel(bad))[0]]
    return OneFormUndefinedError(
        f"the one-form omega (omega J^T = 0) of {kinematics.name} cannot be normalised by its "
        f"component {fixed_index} (0-based): that kernel component vanishes{where}",
        xb,
        "x",
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
    fixed_index = check_index(kinematics, fixed_index)
    x = kinematics.check(x)
    omega, _, bad = one_form_parts(kinematics.jacobian(x), None, fixed_index)
    if np.any(bad):
        raise undefined_error(kinematics, x, bad, fixed_index)
    return omega


def one_form_derivative(
    kinematics: Kinematics, x, fixed_index: int
) -> tuple[FloatArray, FloatArray]:
    """omega (..., p) and its derivative d omega_i / d x_k (..., p, p).

    Needs ``kinematics.hessian`` (or ``kinematics.derivatives``); d omega follows analytically
    from the derivative of the kernel cofactors, :func:`kernel_cofactors_derivative`.
    """
    fixed_index = check_index(kinematics, fixed_index)
    x = kinematics.check(x)
    J, H = derivatives(kinematics, x)
    omega, domega, bad = one_form_parts(J, H, fixed_index)
    if np.any(bad):
        raise undefined_error(kinematics, x, bad, fixed_index)
    return omega, domega


def derivatives(kinematics, x):
    """The Jacobian J and the second derivatives H of ``kinematics`` at ``x``."""
    if hasattr(kinematics, "derivatives"):
        return kinematics.derivatives(x)
    if hasattr(kinematics, "hessian"):
        return kinematics.jacobian(x), kinematics.hessian(x)
    raise InvalidInputError(f"{kinematics.name} has no hessian(); d omega needs second derivatives")
