"""The self-motion manifold of a task point, traced and parametrized so that it can be drawn.

For one degree of redundancy (p = r + 1, eq. (4)) the configurations with k(x) = y0 form curves
in R^p, tangent everywhere to the kernel K(x) of J(x). A curve through a base configuration x_b
(k(x_b) = y0) is the orbit of dx/ds = K(x), x(0) = x_b; with the unit K of
:meth:`jik.engine.kinematics.Kinematics.kernel` (the paper's orientation, last component
positive for Manipulators 1 and 2) the parameter s is the arc length from x_b, signed along K.
For Manipulator 2, whose m = sqrt(1 + l^2) is constant, s = m (x3 - x3_b): the arm angle.

The orbit is integrated once (DOP853 with dense output, both ways from x_b); a point at any s is
the dense output there, projected back onto k(x) = y0 by Newton steps with the pseudoinverse (8),
which move it normal to K and so keep s its arc length to first order. Points depend only on s,
not on which other points are asked for at the same time: an atlas computes its starts chunk by
chunk and gets the same numbers.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.integrate import OdeSolution, solve_ivp

from .exceptions import InvalidInputError
from .inverses import Pseudoinverse
from .kinematics import Kinematics
from .validation import FloatArray, finite

#: Tolerances of the traced orbit (relative and absolute, on x).
TRACE_TOL = 1e-12
#: Newton steps onto k(x) = y0 stop below this task error.
PROJECT_TOL = 1e-14
PROJECT_STEPS = 6
#: Longest arc traced either way from the base configuration.
MAX_ARC = 1e3


@dataclass(frozen=True)
class SelfMotionManifold:
    """The arc [lo, hi] of the self-motion curve {x : k(x) = y0} through ``base``.

    Attributes
    ----------
    kinematics : Kinematics
    y0 : ndarray, shape (r,)
        The task point.
    base : ndarray, shape (p,)
        The configuration at s = 0 (k(base) = y0 to :data:`PROJECT_TOL`).
    arc : (float, float)
        The traced range of the arc length s, lo <= 0 <= hi.
    """

    kinematics: Kinematics
    y0: FloatArray
    base: FloatArray
    arc: tuple[float, float]
    _ahead: OdeSolution | None
    _behind: OdeSolution | None

    def points(self, s) -> FloatArray:
        """Configurations at arc lengths ``s`` (shape (n,)), shape (n, p), each on k(x) = y0.

        Raises
        ------
        InvalidInputError
            An s outside the traced arc.
        """
        s = np.asarray(s, dtype=float)
        lo, hi = self.arc
        if s.ndim != 1 or not np.all((s >= lo) & (s <= hi)):
            raise InvalidInputError(
                f"arc lengths must be a 1-D array within the traced arc [{lo:g}, {hi:g}]",
                field="arc",
            )
        x = np.empty((len(s), self.kinematics.p))
        for part, sol in ((s > 0, self._ahead), (s <= 0, self._behind)):
            if part.any():
                x[part] = self.base if sol is None else sol(s[part]).T
        return project(self.kinematics, x, self.y0)


def project(kinematics: Kinematics, x: FloatArray, y0: FloatArray) -> FloatArray:
    """Newton steps x <- x - J#(x) (k(x) - y0) with the pseudoinverse (8), batched over x.

    Each member stops when its task error is below :data:`PROJECT_TOL` (so a point's result does
    not depend on the others in the batch).
    """
    inverse = Pseudoinverse(kinematics)
    x = np.array(x, dtype=float)
    for _ in range(PROJECT_STEPS):
        e = kinematics.forward(x) - y0
        moving = np.linalg.norm(e, axis=-1) >= PROJECT_TOL
        if not moving.any():
            break
        v, _ = inverse.apply_masked(x[moving], e[moving])
        x[moving] -= v
    return x


def trace(
    kinematics: Kinematics,
    base,
    arc: Sequence[float],
    box: Sequence[Sequence[float]] | None = None,
) -> SelfMotionManifold:
    """Trace the self-motion curve through ``base`` over the arc lengths ``arc`` = (lo, hi).

    Parameters
    ----------
    kinematics : Kinematics
        One degree of redundancy (p = r + 1).
    base : array_like, shape (p,)
        A configuration on the curve: s = 0 there, and y0 = k(base).
    arc : (lo, hi)
        lo <= 0 <= hi, |lo|, |hi| <= :data:`MAX_ARC`.
    box : sequence of p (low, high), optional
        Stop the curve where it leaves this box of configurations (the robot's ``x_range``):
        the traced ``arc`` is then shorter than asked.

    Returns
    -------
    SelfMotionManifold

    Raises
    ------
    InvalidInputError
        Not one degree of redundancy, a bad ``arc``, or ``base`` outside ``box``.
    """
    if kinematics.p - kinematics.r != 1:
        raise InvalidInputError(
            f"a self-motion curve needs one degree of redundancy (p = r + 1); {kinematics.name} "
            f"has p = {kinematics.p}, r = {kinematics.r}: give the starts explicitly",
            field="starts",
        )
    base = kinematics.check(base, "base")
    lo, hi = (finite(a, "arc") for a in arc)
    if not (-MAX_ARC <= lo <= 0 <= hi <= MAX_ARC):
        raise InvalidInputError(
            f"arc must be (lo, hi) with -{MAX_ARC:g} <= lo <= 0 <= hi <= {MAX_ARC:g}, "
            f"got ({lo:g}, {hi:g})",
            field="arc",
        )
    y0 = kinematics.forward(base)
    base = project(kinematics, base[None], y0)[0]
    bounds = None if box is None else np.asarray(box, dtype=float)
    if bounds is not None:
        outside = np.flatnonzero((base < bounds[:, 0]) | (base > bounds[:, 1]))
        if outside.size:
            i = int(outside[0])
            raise InvalidInputError(
                f"the base configuration lies outside the box: x{i + 1} = {base[i]:.6g} is not "
                f"in [{bounds[i, 0]:.6g}, {bounds[i, 1]:.6g}]",
                field="base",
            )

    def kernel(_s, x):
        return kinematics.kernel(x)

    events = []
    if bounds is not None:
        # (a margin inside the box: the curve may run along a face of it)
        def leaves(_s, x):
            return float(np.min(np.minimum(x - bounds[:, 0], bounds[:, 1] - x)))

        leaves.terminal = True  # type: ignore[attr-defined]  # solve_ivp reads it off the function
        events.append(leaves)
    ends: list[float] = []
    sols: list[OdeSolution | None] = []
    for end in (hi, lo):
        if end == 0:
            ends.append(0.0)
            sols.append(None)
            continue
        sol = solve_ivp(
            kernel,
            (0.0, end),
            base,
            method="DOP853",
            rtol=TRACE_TOL,
            atol=TRACE_TOL,
            dense_output=True,
            events=events or None,
        )
        if not sol.success and sol.status != 1:
            raise InvalidInputError(
                f"the self-motion curve could not be traced from the base: {sol.message}",
                field="starts",
            )
        ends.append(float(sol.t[-1]))
        sols.append(sol.sol if sol.t[-1] != 0 else None)
    return SelfMotionManifold(
        kinematics, y0, base, (ends[1], ends[0]), _ahead=sols[0], _behind=sols[1]
    )
