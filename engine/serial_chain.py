"""A serial chain compiled for speed: the end link's pose and geometric Jacobian, batched.

A URDF chain alternates fixed transforms and joint motions about (or along) arbitrary axes.
Compiling it merges the fixed joints into the origin of the next movable joint (and into a final
tip transform), and turns each joint's frame so that its axis is z: the motion of a revolute
joint is then Rz(q), of a prismatic one a translation q along z. The work per configuration is
one batched product (origins times motions) and one 4x4 product per joint along the chain, the
same count as a dedicated kinematics library's forward pass, with a few numpy calls in all. For
one configuration of revolute joints numpy's per-call cost dominates, so the chain's prefix
products are taken in ceil(log2(m + 1)) batched steps instead of m calls.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .validation import FloatArray

#: E (9, 3) with (z d^T).ravel() @ E = z x d: the cross product as one matrix product.
_LEVI_CIVITA = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _LEVI_CIVITA[_j, _k, _i], _LEVI_CIVITA[_k, _j, _i] = 1.0, -1.0
_CROSS = _LEVI_CIVITA.reshape(9, 3)


@dataclass(frozen=True)
class ChainStep:
    """One joint of a chain: its origin (4, 4) relative to the previous link, its unit axis,
    its type (``"revolute"``, ``"prismatic"`` or ``"fixed"``), its index in x (-1: not
    active) and its value when not active."""

    origin: FloatArray
    axis: FloatArray
    type: str
    index: int
    value: float


def _frame_of_axis(a: FloatArray) -> FloatArray:
    """A rotation (4, 4) whose third column is the unit vector a (the identity for a = z)."""
    b = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = b - (b @ a) * a
    u /= np.linalg.norm(u)
    F = np.eye(4)
    F[:3, :3] = np.column_stack([u, np.cross(a, u), a])
    return F


class CompiledChain:
    """The movable joints of a chain, fixed transforms merged, axes turned to z.

    Parameters
    ----------
    steps : sequence of ChainStep
        The chain from the base link to the end link, fixed joints included.
    p : int
        Number of active joints (the length of x).
    """

    def __init__(self, steps: Sequence[ChainStep], p: int) -> None:
        pending = np.eye(4)
        origins, prismatic, index, values = [], [], [], []
        for s in steps:
            pending = pending @ s.origin
            if s.type == "fixed":
                continue
            turn = _frame_of_axis(np.asarray(s.axis, dtype=float))
            origins.append(pending @ turn)
            pending = turn.T  # (a rotation: its inverse is its transpose)
            prismatic.append(s.type == "prismatic")
            index.append(s.index)
            values.append(s.value)
        self.p, self.m = p, len(origins)
        self.origins = np.array(origins).reshape(self.m, 4, 4)
        self.tip = pending  # (4, 4): from the last movable joint's frame to the end link
        self.prismatic = np.array(prismatic, dtype=bool)
        self.revolute = ~self.prismatic
        self.index = np.array(index, dtype=int)
        self.values = np.array(values, dtype=float)
        self.active = np.flatnonzero(self.index >= 0)
        #: Every movable joint active, in chain order: x is the joint vector itself.
        self.direct = bool(np.array_equal(self.index, np.arange(self.m)))
        self._all_revolute = not self.prismatic.any()
        # A joint's transform origin @ motion(q) is linear in (1, cos q, sin q, q):
        # origin @ (M0 + cos q Kc + sin q Ks + q Kq), with Rz(q) or Tz(q) as the motion.
        rev, pri = self.revolute[:, None, None], self.prismatic[:, None, None]
        M0, Kc, Ks, Kq = np.zeros((4, self.m, 4, 4))
        M0[:, 2, 2] = M0[:, 3, 3] = 1.0
        M0[:, 0, 0] = M0[:, 1, 1] = np.where(self.prismatic, 1.0, 0.0)
        Kc[:, 0, 0] = Kc[:, 1, 1] = 1.0
        Ks[:, 1, 0], Ks[:, 0, 1] = 1.0, -1.0
        Kq[:, 2, 3] = 1.0
        self._P0 = self.origins @ M0
        self._Pc, self._Ps = self.origins @ (rev * Kc), self.origins @ (rev * Ks)
        self._Pq = self.origins @ (pri * Kq)
        # One configuration of a chain of revolute joints (x the joint vector): the m joint
        # transforms and the tip as rows of one product w @ stack, w_j = (1, cos q_j, sin q_j)
        # (the tip's w = (1, 0, 0)).
        self._stack = np.concatenate(
            [
                np.stack([self._P0, self._Pc, self._Ps], axis=1).reshape(self.m, 3, 16),
                np.stack([self.tip, 0.0 * self.tip, 0.0 * self.tip]).reshape(1, 3, 16),
            ]
        )
        self._w = np.zeros((self.m + 1, 1, 3))
        self._w[:, 0, 0] = 1.0
        self._one = self.direct and self._all_revolute

    def joint_values(self, x: FloatArray) -> FloatArray:
        """Every movable joint's value: x where active, the locked value elsewhere (..., m)."""
        if self.direct:
            return x
        q = np.broadcast_to(self.values, (*x.shape[:-1], self.m)).copy()
        q[..., self.active] = x[..., self.index[self.active]]
        return q

    def frames(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Each movable joint's frame after its motion (..., m, 4, 4), its axis the third
        column and (revolute) its origin the fourth, and the end link's pose (..., 4, 4)."""
        q = self.joint_values(np.asarray(x, dtype=float))[..., None, None]
        A = self._P0 + np.cos(q) * self._Pc + np.sin(q) * self._Ps  # (..., m, 4, 4)
        if not self._all_revolute:
            A = A + q * self._Pq
        if A.ndim == 3:  # one configuration: 4x4 products into one array
            F = np.empty_like(A)
            F[0] = A[0]
            for j in range(1, self.m):
                np.matmul(F[j - 1], A[j], out=F[j])
            return F, F[-1] @ self.tip
        F = np.empty_like(A)
        F[..., 0, :, :] = A[..., 0, :, :]
        for j in range(1, self.m):
            np.matmul(F[..., j - 1, :, :], A[..., j, :, :], out=F[..., j, :, :])
        return F, F[..., self.m - 1, :, :] @ self.tip

    def pose(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The end link's rotation (..., 3, 3) and position (..., 3) at x (..., p)."""
        _, T = self.frames(x)
        return T[..., :3, :3], T[..., :3, 3]

    def pose_jacobian(self, x: FloatArray):
        """The end pose and its geometric Jacobian in the base frame.

        Returns
        -------
        R, t : (..., 3, 3), (..., 3)
        Jv, Jw : (..., 3, p), (..., 3, p)
            Linear and angular velocity of the end link per unit joint rate: a revolute joint's
            column is (z x (t - o), z), a prismatic joint's (z, 0).
        """
        x = np.asarray(x, dtype=float)
        if x.ndim == 1 and self._one:
            return self._one_pose_jacobian(x)
        F, T = self.frames(x)
        z, t = F[..., :3, 2], T[..., :3, 3]  # (..., m, 3), (..., 3)
        d = t[..., None, :] - F[..., :3, 3]
        outer = z[..., :, None] * d[..., None, :]  # (..., m, 3, 3)
        lin = outer.reshape(*outer.shape[:-2], 9) @ _CROSS  # z x d, (..., m, 3)
        if not self._all_revolute:
            lin = np.where(self.prismatic[:, None], z, lin)
            z = np.where(self.prismatic[:, None], 0.0, z)
        Jv, Jw = np.swapaxes(lin, -1, -2), np.swapaxes(z, -1, -2)  # (..., 3, m)
        if not self.direct:
            cols = self.index[self.active]
            Jv_, Jw_ = np.zeros((*Jv.shape[:-1], self.p)), np.zeros((*Jw.shape[:-1], self.p))
            Jv_[..., cols], Jw_[..., cols] = Jv[..., self.active], Jw[..., self.active]
            Jv, Jw = Jv_, Jw_
        return T[..., :3, :3], t, Jv, Jw

    def _one_pose_jacobian(self, q: FloatArray):
        """:meth:`pose_jacobian` of one configuration q (m,) of a chain of revolute joints, in
        few numpy calls: the joint transforms and the tip from one product, their prefix
        products F_j = A_0 ... A_j by ceil(log2(m + 1)) batched products (each step
        F_j <- F_(j-s) F_j for j >= s, s = 1, 2, 4, ...), the end pose F_m."""
        m = self.m
        w = self._w.copy()
        np.cos(q, out=w[:m, 0, 1])
        np.sin(q, out=w[:m, 0, 2])
        F = (w @ self._stack).reshape(m + 1, 4, 4)
        s = 1
        while s <= m:
            F[s:] = F[:-s] @ F[s:]
            s *= 2
        z, t = F[:m, :3, 2], F[m, :3, 3]
        lin = (z[:, :, None] * (t - F[:m, :3, 3])[:, None, :]).reshape(m, 9) @ _CROSS
        return F[m, :3, :3], t, lin.T, z.T
