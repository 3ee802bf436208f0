"""Rotations: the SO(3) exponential and logarithm and the log's derivative, batched.

A pose task's orientation coordinates are the rotation vector phi = log(R0^T R) of the end
link's orientation R relative to a reference R0 (:mod:`jik.engine.pose_task`). Their rate is
``dphi/dt = Jl^-1(phi) R0^T omega`` with omega the end link's angular velocity in the base frame
and Jl the left Jacobian of SO(3) (Barfoot, *State Estimation for Robotics*, eq. (7.86)); with
Pinocchio's local angular velocity R^T omega the same rate is ``Jlog3(R0^T R) R^T omega``.

The coordinates are those of the principal logarithm, |phi| <= pi: at |phi| = pi the log is
not differentiable (a half turn has two rotation vectors), so a task's orientations should stay
within a half turn of R0.
"""

from __future__ import annotations

import math

import numpy as np

from .validation import FloatArray

#: Below this angle [rad] the series of the log and its derivative replace the closed forms.
SMALL_ANGLE = 1e-4
#: Within this of pi [rad] the log's axis comes from the symmetric part of R.
NEAR_PI = 1e-3


#: H (3, 9) with (w @ H).reshape(3, 3) = [w]x; V (9, 3) with R.ravel() @ V = vee(R - R^T).
_HAT3 = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _HAT3[_i, _k, _j], _HAT3[_i, _j, _k] = 1.0, -1.0  # [w]x[k, j] = w_i, [w]x[j, k] = -w_i
_HAT = _HAT3.reshape(3, 9)
_VEE = _HAT.T  # vee(R - R^T) is linear in R: the transpose of the hat map


def hat(w: FloatArray) -> FloatArray:
    """The skew matrix [w]x of w (..., 3): (..., 3, 3), [w]x v = w x v."""
    w = np.asarray(w, dtype=float)
    return (w @ _HAT).reshape(*w.shape[:-1], 3, 3)


def exp(w: FloatArray) -> FloatArray:
    """The rotation exp([w]x) of rotation vectors w (..., 3): (..., 3, 3) (Rodrigues)."""
    w = np.asarray(w, dtype=float)
    theta = np.linalg.norm(w, axis=-1)[..., None, None]
    small = theta < SMALL_ANGLE
    t = np.where(small, 1.0, theta)
    a = np.where(small, 1.0 - theta**2 / 6.0, np.sin(t) / t)
    b = np.where(small, 0.5 - theta**2 / 24.0, (1.0 - np.cos(t)) / t**2)
    K = hat(w)
    return np.eye(3) + a * K + b * (K @ K)


def log(R: FloatArray) -> FloatArray:
    """The principal rotation vector phi (..., 3), |phi| <= pi, of rotations R (..., 3, 3).

    Notes
    -----
    phi = theta / (2 sin theta) vee(R - R^T), with sin theta = |vee(R - R^T)| / 2, cos theta =
    (tr R - 1) / 2 and theta = atan2(sin, cos): log(exp(w)) is within 2e-13 of w at every
    angle, where arccos(cos) loses half the digits near pi (3e-8 at pi, 2e-9 at 1e-3 from it;
    tests/engine/test_pose_task.py). Near 0
    the factor's series 1/2 + theta^2/12; near pi the axis a is read from the symmetric part,
    a a^T = ((R + R^T)/2 - cos theta I) / (1 - cos theta), its sign from vee(R - R^T).
    """
    R = np.asarray(R, dtype=float)
    c = (np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0
    v = R.reshape(*R.shape[:-2], 9) @ _VEE  # vee(R - R^T) = 2 sin(theta) a
    s = 0.5 * np.linalg.norm(v, axis=-1)
    theta = np.arctan2(s, c)
    small = theta < SMALL_ANGLE
    factor = np.where(small, 0.5 + theta**2 / 12.0, theta / (2.0 * np.where(small, 1.0, s)))
    phi = factor[..., None] * v
    near = theta > np.pi - NEAR_PI
    if np.any(near):
        Rn, cn, vn, tn = R[near], c[near], v[near], theta[near]
        B = (0.5 * (Rn + np.swapaxes(Rn, -1, -2)) - cn[:, None, None] * np.eye(3)) / (
            1.0 - cn[:, None, None]
        )
        col = np.argmax(np.diagonal(B, axis1=-2, axis2=-1), axis=-1)
        a = B[np.arange(len(B)), :, col]
        a /= np.linalg.norm(a, axis=-1, keepdims=True)
        a *= np.where(np.sum(a * vn, axis=-1) < 0.0, -1.0, 1.0)[:, None]
        phi[near] = tn[:, None] * a
    return phi


def left_jacobian_inverse(phi: FloatArray) -> FloatArray:
    """Jl^-1(phi) (..., 3, 3): the map from R0^T omega to dphi/dt for phi = log(R0^T R).

    ``Jl^-1 = I - [phi]x / 2 + (1/theta^2 - (1 + cos theta) / (2 theta sin theta)) [phi]x^2``,
    theta = |phi|; the last coefficient's series near 0 is 1/12 + theta^2/720. It is bounded
    up to theta = pi (||Jl^-1|| = pi/2 there) and grows without bound toward 2 pi, beyond the
    principal log's range.
    """
    phi = np.asarray(phi, dtype=float)
    theta = np.linalg.norm(phi, axis=-1)[..., None, None]
    small = theta < SMALL_ANGLE
    t = np.where(small, 1.0, theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        big = 1.0 / t**2 - (1.0 + np.cos(t)) / (2.0 * t * np.sin(t))
    beta = np.where(small, 1.0 / 12.0 + theta**2 / 720.0, big)
    K = hat(phi)
    return np.eye(3) - 0.5 * K + beta * (K @ K)


def log_and_jacobian(R: FloatArray) -> tuple[FloatArray, FloatArray]:
    """log(R) (3,) and Jl^-1(log R) (3, 3) of one rotation R (3, 3), in scalar arithmetic.

    The same numbers as :func:`log` and :func:`left_jacobian_inverse` for a single rotation,
    without the cost of numpy's calls on 3-vectors (a chain's one-configuration evaluation is
    a few dozen of them); near pi it defers to :func:`log`.
    """
    (a, b, c), (d, e, f), (g, h, i) = R.tolist()
    cos = (a + e + i - 1.0) / 2.0
    sin = 0.5 * math.sqrt((h - f) ** 2 + (c - g) ** 2 + (d - b) ** 2)
    theta = math.atan2(sin, cos)  # (as in log)
    if theta > math.pi - NEAR_PI:
        phi = log(R)
        return phi, left_jacobian_inverse(phi)
    if theta < SMALL_ANGLE:
        factor, beta = 0.5 + theta * theta / 12.0, 1.0 / 12.0 + theta * theta / 720.0
    else:
        factor = theta / (2.0 * sin)
        beta = 1.0 / (theta * theta) - (1.0 + cos) / (2.0 * theta * sin)
    x, y, z = factor * (h - f), factor * (c - g), factor * (d - b)
    xx, yy, zz, xy, xz, yz = x * x, y * y, z * z, x * y, x * z, y * z
    # I - [phi]x / 2 + beta [phi]x^2, with [phi]x^2 = phi phi^T - |phi|^2 I
    return np.array([x, y, z]), np.array(
        [
            [1.0 - beta * (yy + zz), 0.5 * z + beta * xy, -0.5 * y + beta * xz],
            [-0.5 * z + beta * xy, 1.0 - beta * (xx + zz), 0.5 * x + beta * yz],
            [0.5 * y + beta * xz, -0.5 * x + beta * yz, 1.0 - beta * (xx + yy)],
        ]
    )
