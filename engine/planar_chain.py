"""Planar serial chains of revolute and prismatic joints, a kinematics k: R^p -> R^r, eq. (4).

Joint i (1-based) turns the chain by its angle (revolute, R) or stretches its own link (prismatic,
P). With theta_i the sum of the revolute joint angles up to joint i and a_i the length of link i,

    k(x) = sum_i a_i (cos theta_i, sin theta_i)            (end point, r = 2)
    k(x) = (sum_i a_i cos theta_i, sum_i a_i sin theta_i, theta_p)   (with orientation, r = 3)

where theta_i = sum_{j <= i, joint j is R} (x_j + o_j) and a_i = l_i for a revolute joint,
a_i = l_i + x_i + o_i for a prismatic one (l the link lengths, o the joint offsets). The planar 3R
arm of the repeatability papers (Klein and Huang; Roberts and Maciejewski) is
``PlanarChain("RRR", [1.0, 0.8, 0.6])``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .exceptions import InvalidInputError
from .kinematics import Kinematics
from .validation import MAX_JOINTS, FloatArray, json_number


class PlanarChain(Kinematics):
    """A planar serial chain, its end point (and orientation) as the task, eq. (4).

    Parameters
    ----------
    joints : str
        One letter per joint, base first: ``"R"`` revolute, ``"P"`` prismatic (case-insensitive).
    lengths : sequence of float, shape (p,)
        Link lengths l_i > 0 (for a prismatic joint the link's length at x_i + o_i = 0) [length].
    offsets : sequence of float, shape (p,), optional
        Joint offsets o_i, added to x_i: an angle [rad] for R, an extension [length] for P.
    orientation : bool
        False: the task is the end point (r = 2); True: the end point and the end's angle
        theta_p (r = 3).

    Notes
    -----
    The Jacobian is analytic: for a revolute joint j, dk/dx_j = (-(Y - y_{j-1}), X - x_{j-1}, 1)
    with (X, Y) the end point and (x_{j-1}, y_{j-1}) joint j's position; for a prismatic joint
    dk/dx_j = (cos theta_j, sin theta_j, 0). The kernel's orientation is that of the cofactor
    vector (``kernel_orientation = 1``), which fixes the sign of the term -2 dh K of E2, (19).
    """

    name = "planar_chain"

    def __init__(
        self,
        joints: str,
        lengths: Sequence[float],
        offsets: Sequence[float] | None = None,
        orientation: bool = False,
    ) -> None:
        if not isinstance(joints, str) or not joints:
            raise InvalidInputError("joints must be a string of R and P, e.g. 'RRR'", "joints")
        kinds = joints.upper()
        bad = [i for i, c in enumerate(kinds) if c not in "RP"]
        if bad:
            raise InvalidInputError(
                f"joints must contain only R (revolute) and P (prismatic); "
                f"got {joints[bad[0]]!r} at position {bad[0]}",
                "joints",
            )
        if len(kinds) > MAX_JOINTS:
            raise InvalidInputError(f"at most {MAX_JOINTS} joints, got {len(kinds)}", "joints")
        self.joints = kinds
        self.lengths = _vector(lengths, len(kinds), "lengths")
        short = np.flatnonzero(self.lengths <= 0)
        if short.size:
            i = int(short[0])
            raise InvalidInputError(
                f"lengths[{i}] must be positive (a link's length), got {self.lengths[i]:g}",
                f"lengths.{i}",
            )
        self.offsets = _vector(
            [0.0] * len(kinds) if offsets is None else offsets, len(kinds), "offsets"
        )
        if not isinstance(orientation, bool):
            raise InvalidInputError("orientation must be true or false", "orientation")
        self.orientation = orientation
        self.p = len(kinds)
        self.r = 3 if orientation else 2
        if self.p < self.r:
            raise InvalidInputError(
                f"a chain with a task of dimension r = {self.r} needs at least {self.r} joints, "
                f"got {self.p}",
                "joints",
            )
        self.revolute = np.array([c == "R" for c in kinds])
        self.variable_names = tuple(f"x{i + 1}" for i in range(self.p))

    @property
    def parameters(self) -> dict[str, object]:
        return {
            "joints": self.joints,
            "lengths": self.lengths.tolist(),
            "offsets": self.offsets.tolist(),
            "orientation": self.orientation,
        }

    def _described(self) -> dict[str, object]:
        out: dict[str, object] = {"joints": self.joints, "lengths": self.lengths}
        if np.any(self.offsets != 0):
            out["offsets"] = self.offsets
        out["task"] = "x y angle" if self.orientation else "x y"
        return out

    @property
    def scratch(self) -> int:
        """Float64 numbers per configuration of an evaluation of J: angles, link vectors and
        joint positions, a few (p + 1, 2) arrays."""
        return 12 * (self.p + 1)

    def _angles_lengths(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """theta_i (..., p) [rad] and a_i (..., p) [length]."""
        q = np.asarray(x, dtype=float) + self.offsets
        theta = np.cumsum(np.where(self.revolute, q, 0.0), axis=-1)
        a = np.where(self.revolute, self.lengths, self.lengths + q)
        return theta, a

    def points(self, x: FloatArray) -> FloatArray:
        """Joint positions and the end point, base (0, 0) first: (..., p) -> (..., p + 1, 2)."""
        theta, a = self._angles_lengths(x)
        steps = a[..., None] * np.stack([np.cos(theta), np.sin(theta)], axis=-1)  # (..., p, 2)
        zero = np.zeros((*steps.shape[:-2], 1, 2))
        return np.concatenate([zero, np.cumsum(steps, axis=-2)], axis=-2)

    def drawn_points(self, x: FloatArray) -> FloatArray:
        """The chain as a polyline through its links: its :meth:`points`, from its first joint
        at the base (as :meth:`UrdfChain.drawn_points <jik.engine.urdf.UrdfChain.drawn_points>`
        draws an arm)."""
        return self.points(x)

    @property
    def joint_points(self) -> dict[int, int]:
        """Which point of :meth:`drawn_points` is each joint variable's joint: joint i at i."""
        return {i: i for i in range(self.p)}

    def forward(self, x: FloatArray) -> FloatArray:
        """k(x): (..., p) -> (..., r)."""
        pts = self.points(x)
        end = pts[..., -1, :]
        if not self.orientation:
            return end
        theta, _ = self._angles_lengths(x)
        return np.concatenate([end, theta[..., -1:]], axis=-1)

    def jacobian(self, x: FloatArray) -> FloatArray:
        """J(x) = dk/dx: (..., p) -> (..., r, p), analytic (see the class notes)."""
        theta, _ = self._angles_lengths(x)
        pts = self.points(x)
        arm = pts[..., -1:, :] - pts[..., :-1, :]  # (..., p, 2): end minus joint j's position
        rev = np.stack([-arm[..., 1], arm[..., 0]], axis=-2)  # (..., 2, p)
        pri = np.stack([np.cos(theta), np.sin(theta)], axis=-2)  # (..., 2, p)
        J = np.where(self.revolute, rev, pri)
        if not self.orientation:
            return J
        last = np.broadcast_to(self.revolute.astype(float), (*J.shape[:-2], 1, self.p))
        return np.concatenate([J, last], axis=-2)

    def hessian(self, x: FloatArray) -> FloatArray:
        """d^2 k_i / dx_j dx_k: (..., p) -> (..., r, p, p) (the characteristics need it).

        Notes
        -----
        With v_i = a_i u_i the link vectors, u_i = (cos theta_i, sin theta_i) and R the rotation
        by +90 degrees: d^2 v_i / dx_j dx_k = -v_i for revolute j, k <= i; R u_i for a revolute
        j <= i and the prismatic k = i (and symmetrically); 0 otherwise. theta_p is linear in x.
        """
        theta, a = self._angles_lengths(x)
        u = np.stack([np.cos(theta), np.sin(theta)], axis=-1)  # (..., p, 2)
        v = a[..., None] * u
        w = np.stack([-u[..., 1], u[..., 0]], axis=-1)  # R u
        idx = np.arange(self.p)
        A = (self.revolute[:, None] & (idx[:, None] <= idx[None, :])).astype(float)  # A[j, i]
        H = -np.einsum("ji,ki,...ic->...cjk", A, A, v)
        mixed = np.einsum("jk,...kc->...cjk", A * ~self.revolute[None, :], w)
        H = H + mixed + np.swapaxes(mixed, -1, -2)
        if self.orientation:
            H = np.concatenate([H, np.zeros((*H.shape[:-3], 1, self.p, self.p))], axis=-3)
        return H


def _vector(values, n: int, name: str) -> FloatArray:
    """n finite numbers (a JSON list), the message naming ``name`` and the bad entry."""
    if isinstance(values, str | bytes) or not isinstance(values, Sequence | np.ndarray):
        raise InvalidInputError(f"{name} must be a list of {n} numbers", name)
    if len(values) != n:
        raise InvalidInputError(
            f"{name} must have one entry per joint ({n}), got {len(values)}", name
        )
    return np.array([json_number(v, f"{name}[{i}]", f"{name}.{i}") for i, v in enumerate(values)])
