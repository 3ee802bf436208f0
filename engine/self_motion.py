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

A curve that is a closed loop (a component of the fibre that is a circle inside the box: the fibres
of a revolute arm often are) is traced once round, not round and round until the arc is used up.
Going ahead from x_b, the tracer watches a Poincare section, the hyperplane through x_b normal to
the curve there: when the curve crosses it again in the same direction (coming from behind it) at a
point within :data:`CLOSE_TOL` of x_b (:data:`CLOSE_PER_TOL` times the integrator's tolerance, if
that is more), with the same tangent, the loop has closed; the crossing is located on the dense
output (Brent's method, as ``solve_ivp`` locates events) and its arc length is the loop's period T.
Going behind, it watches the section through the end of the arc traced ahead, the first point of
that arc it can come round to. The angle of a joint that turns freely (a URDF's continuous joint,
:func:`periodic_joints`) is compared modulo 2 pi, so a loop that closes after that joint has turned
a whole turn is found too.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.integrate import DOP853, OdeSolution
from scipy.optimize import brentq

from .exceptions import InvalidInputError, JikError
from .inverses import Pseudoinverse
from .kinematics import Kinematics
from .urdf import UrdfChain
from .validation import FloatArray, as_box, count, finite

#: Tolerances of the traced orbit (relative and absolute, on x).
TRACE_TOL = 1e-12
#: The loosest tolerance :func:`trace` takes (a curve traced to be drawn: its points are projected
#: onto k(x) = y0 either way, so the tolerance moves them along the curve only).
LOOSEST_TOL = 1e-6
#: Newton steps onto k(x) = y0 stop below this task error.
PROJECT_TOL = 1e-14
PROJECT_STEPS = 6
#: Longest arc traced either way from the base configuration.
MAX_ARC = 1e3
#: Integrator steps either way by default: a smooth curve takes about 2.5 per unit of arc at
#: TRACE_TOL (2,500 over MAX_ARC); one running into a point where k is undefined creeps.
MAX_STEPS = 10_000
#: A curve has closed when it crosses its start's section again this close to the start.
CLOSE_TOL = 1e-6
#: ... or this many times the integrator's tolerance (an orbit traced loosely drifts off k = y0).
CLOSE_PER_TOL = 1e3
#: Brent's tolerance on s where an event is located (``solve_ivp``'s).
EVENT_TOL = 4 * np.finfo(float).eps
#: A curve drawn (:func:`drawn_curves`) is traced this many box diagonals each way (to a
#: drawing's tolerance) and drawn with a point every SPACING of them.
ARC_SPANS, SPACING, DRAW_TOL = 3.2, 0.02, 1e-6
#: Integrator steps each way of a drawn curve: a smooth one takes under ten; one that runs
#: into a configuration where k is undefined creeps there and is drawn up to it.
DRAW_STEPS = 1000


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
        The traced range of the arc length s, lo <= 0 <= hi: one turn, hi - lo = period, when
        the curve is closed.
    period : float or None
        The length T of a closed curve (x(s + T) = x(s)), None for an open one (cut by the box
        or by the asked arc).
    steps : int
        Integrator steps taken, both ways.
    """

    kinematics: Kinematics
    y0: FloatArray
    base: FloatArray
    arc: tuple[float, float]
    _ahead: OdeSolution | None
    _behind: OdeSolution | None
    period: float | None = None
    steps: int = 0

    @property
    def closed(self) -> bool:
        """Whether the curve closes on itself within the traced arc (one turn is traced)."""
        return self.period is not None

    def points(self, s) -> FloatArray:
        """Configurations at arc lengths ``s`` (shape (n,)), shape (n, p), each on k(x) = y0.

        On a closed curve any s is a point: an s outside the traced turn is taken modulo the
        period (the point's freely turning joints are then those of the traced turn).

        Raises
        ------
        InvalidInputError
            An s outside the traced arc of an open curve.
        """
        s = np.asarray(s, dtype=float)
        lo, hi = self.arc
        if self.period is not None and s.ndim == 1 and np.all(np.isfinite(s)):
            s = np.where((s >= lo) & (s <= hi), s, lo + np.mod(s - lo, self.period))
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

    def sample(self, n: int) -> FloatArray:
        """``n`` points (2 to 10^5) evenly spaced in arc length over the traced arc, ends
        included, shape (n, p): the curve as a polyline (one turn of a closed one, which ends
        where it began)."""
        return self.points(np.linspace(*self.arc, count(n, "n", 2, 10**5)))


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


def periodic_joints(kinematics: Kinematics) -> FloatArray:
    """Which variables (bool, shape (p,)) are angles of joints that turn freely, so that x and
    x + 2 pi e_i are one posture: a URDF's continuous joints and its revolute joints without
    limits. Every other variable (the paper's robots', a planar chain's) is a coordinate of R^p,
    as in the paper's drift ||x - x0||."""
    periodic = np.zeros(kinematics.p, dtype=bool)
    if isinstance(kinematics, UrdfChain):
        free = ~np.isfinite(np.asarray(kinematics.joint_limits, dtype=float)).all(axis=1)
        for joint in kinematics.chain:
            if joint.index >= 0 and joint.type == "revolute":
                periodic[joint.index] = free[joint.index]
    return periodic


def trace(
    kinematics: Kinematics,
    base,
    arc: Sequence[float],
    box: Sequence[Sequence[float]] | None = None,
    tol: float = TRACE_TOL,
    bound_free_joints: bool = False,
    max_steps: int = MAX_STEPS,
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
        the traced ``arc`` is then shorter than asked. A joint that turns freely
        (:func:`periodic_joints`) is not bounded by it: its angle's range in the box is a
        window on one turn, not a limit (unless ``bound_free_joints``).
    tol : float
        The integrator's relative and absolute tolerance on x, :data:`TRACE_TOL` to
        :data:`LOOSEST_TOL`: the points of :meth:`SelfMotionManifold.points` lie on k(x) = y0
        whatever it is, their arc lengths are within about ``tol`` of s.
    bound_free_joints : bool
        Stop the curve where a freely turning joint's angle leaves ``box`` too, as any other
        variable's (a curve drawn in the box's view).
    max_steps : int
        Integrator steps each way at most (:data:`MAX_STEPS`), ``arc`` then shorter (K flips
        where k is undefined).

    Returns
    -------
    SelfMotionManifold
        Open, over ``arc`` or the part of it within ``box``; or closed, when the curve comes
        back to where it began within ``arc`` (the module's notes): then over one turn, (0, T)
        when it closes ahead (hi >= T), else (hi - T, hi), with ``period`` T.

    Raises
    ------
    InvalidInputError
        Not one degree of redundancy, a bad ``arc`` or ``tol``, or ``base`` outside ``box``.
    """
    if kinematics.p - kinematics.r != 1:
        raise InvalidInputError(
            f"a self-motion curve needs one degree of redundancy (p = r + 1); {kinematics.name} "
            f"has p = {kinematics.p}, r = {kinematics.r}: give the starts explicitly",
            field="starts",
        )
    base = kinematics.check(base, "base")
    tol = finite(tol, "tol")
    if not TRACE_TOL <= tol <= LOOSEST_TOL:
        raise InvalidInputError(
            f"tol must be from {TRACE_TOL:g} to {LOOSEST_TOL:g}, got {tol:g}", field="tol"
        )
    lo, hi = (finite(a, "arc") for a in arc)
    if not (-MAX_ARC <= lo <= 0 <= hi <= MAX_ARC):
        raise InvalidInputError(
            f"arc must be (lo, hi) with -{MAX_ARC:g} <= lo <= 0 <= hi <= {MAX_ARC:g}, "
            f"got ({lo:g}, {hi:g})",
            field="arc",
        )
    max_steps = count(max_steps, "max_steps", 1, 2**31)
    y0 = kinematics.forward(base)
    base = project(kinematics, base[None], y0)[0]
    periodic = periodic_joints(kinematics)
    if not isinstance(bound_free_joints, bool):
        raise InvalidInputError("bound_free_joints must be True or False", "bound_free_joints")
    bounds, leaves = None if box is None else as_box(box, kinematics.p, finite=False), None
    if bounds is not None:
        if not bound_free_joints:
            bounds[periodic] = (-np.inf, np.inf)  # (x and x + 2 pi: one posture)
        outside = np.flatnonzero((base < bounds[:, 0]) | (base > bounds[:, 1]))
        if outside.size:
            i = int(outside[0])
            raise InvalidInputError(
                f"the base configuration lies outside the box: x{i + 1} = {base[i]:.6g} is not "
                f"in [{bounds[i, 0]:.6g}, {bounds[i, 1]:.6g}]",
                field="base",
            )

        # (a margin inside the box: the curve may run along a face of it)
        def leaves(_s, x):
            return float(np.min(np.minimum(x - bounds[:, 0], bounds[:, 1] - x)))

    start = (base, kinematics.kernel(base))
    ahead = _leg(kinematics, base, hi, leaves, start, periodic, tol, max_steps)
    if ahead.closed:
        return SelfMotionManifold(
            kinematics, y0, base, (0.0, ahead.end), ahead.sol, None, ahead.end, ahead.steps
        )
    # Behind, the curve closes where it comes round to the end of the arc traced ahead (unless
    # the box cut that end: a curve that leaves the box is no loop within it).
    watch = None
    if not ahead.cut:
        end = base if ahead.sol is None else ahead.sol(ahead.end)
        watch = (end, -kinematics.kernel(end))
    behind = _leg(kinematics, base, lo, leaves, watch, periodic, tol, max_steps)
    period = ahead.end - behind.end if behind.closed else None
    arc, steps = (behind.end, ahead.end), ahead.steps + behind.steps
    return SelfMotionManifold(kinematics, y0, base, arc, ahead.sol, behind.sol, period, steps)


class _Leg(NamedTuple):
    """One way of a traced curve: where it ended, its dense output (None: no arc), its steps,
    and whether the box cut it or it closed."""

    end: float
    sol: OdeSolution | None
    steps: int
    cut: bool
    closed: bool


def _leg(kinematics, base, end, leaves, watch, periodic, tol, max_steps) -> _Leg:
    """Integrate dx/ds = K(x), x(0) = ``base``, from s = 0 toward ``end`` (DOP853 with dense
    output to ``tol``, stepped as ``solve_ivp`` steps it), stopping at the first of: ``end``; a
    zero of ``leaves(s, x)`` (the box, located as ``solve_ivp`` locates a terminal event); the
    return to ``watch`` = (w, v), w a point of the curve and v the unit tangent the curve has
    there in the direction of integration: a crossing of the section v . (x - w) = 0 from behind
    it (v . d < 0 at the step's start, >= 0 at its end, so the start's own crossing at s = 0 is
    none), at which x is within :data:`CLOSE_TOL` (or :data:`CLOSE_PER_TOL` ``tol``) of w with
    its tangent near v (angles of ``periodic`` joints compared modulo 2 pi); or ``max_steps``."""
    if end == 0:
        return _Leg(0.0, None, 0, False, False)

    def wrapped(x):
        d = x - watch[0]
        d[periodic] = np.mod(d[periodic] + np.pi, 2 * np.pi) - np.pi
        return d

    def section(x):
        return float(watch[1] @ wrapped(x))

    def returned(x) -> bool:
        along = np.sign(end) * kinematics.kernel(x) @ watch[1]
        near = np.linalg.norm(wrapped(x)) <= max(CLOSE_TOL, CLOSE_PER_TOL * tol)
        return bool(near and along > 0.5)

    solver = DOP853(lambda _s, x: kinematics.kernel(x), 0.0, base, float(end), rtol=tol, atol=tol)
    ts, interpolants = [0.0], []
    g = 0.0 if leaves is None else leaves(0.0, base)
    stop, cut, closed, steps = None, False, False, 0
    while solver.status == "running" and stop is None and steps < max_steps:
        message = solver.step()
        steps += 1
        if solver.status == "failed":
            raise InvalidInputError(
                f"the self-motion curve could not be traced from the base: {message}",
                field="starts",
            )
        t_old, t, sol = solver.t_old, solver.t, solver.dense_output()
        interpolants.append(sol)
        if leaves is not None:
            g_new = leaves(t, solver.y)
            if g <= 0 <= g_new or g >= 0 >= g_new:
                stop = brentq(
                    lambda u, sol=sol: leaves(u, sol(u)), t_old, t, xtol=EVENT_TOL, rtol=EVENT_TOL
                )
                cut = True
            g = g_new
        if watch is not None and section(sol(t_old)) < 0 <= section(sol(t)):
            root = brentq(
                lambda u, sol=sol: section(sol(u)), t_old, t, xtol=EVENT_TOL, rtol=EVENT_TOL
            )
            if returned(sol(root)) and (stop is None or abs(root) < abs(stop)):
                stop, cut, closed = root, False, True
        t = t if stop is None else stop
        if len(ts) > 1 and ts[-1] == t:  # (an event where the step began: no new segment)
            interpolants.pop()
        else:
            ts.append(t)
    cut = cut or (stop is None and solver.status == "running")  # (max_steps: as by the box)
    if ts[-1] == 0:
        return _Leg(0.0, None, steps, cut, False)
    return _Leg(float(ts[-1]), OdeSolution(np.array(ts), interpolants), steps, cut, closed)


def drawn_curves(kinematics: Kinematics, seeds: FloatArray, lo, hi) -> list[FloatArray]:
    """Points of the self-motion manifolds k(x) = k(seed) through ``seeds`` (n, p), (m, p)
    each: a polyline with a point every :data:`SPACING` diagonals of the box [``lo``, ``hi``]
    (p,), within that box widened by half its width each way (and to the seeds); none for a
    seed where the curve cannot be traced.

    Notes
    -----
    Each curve is :func:`trace`'s, to a drawing's tolerance :data:`DRAW_TOL`: the orbit of the
    unit kernel K(x) both ways from its seed over an arc of :data:`ARC_SPANS` box diagonals,
    stopped where any variable (a freely turning joint's angle too) leaves the widened box,
    after one turn of a closed curve or after :data:`DRAW_STEPS` steps, its points projected
    onto k(x) = y by the pseudoinverse (8).
    """
    span = hi - lo
    defined = seeds[np.isfinite(seeds).all(axis=1)]  # (a seed beyond x_range widens the box)
    low = np.minimum(lo - 0.5 * span, np.min(defined, axis=0, initial=np.inf))
    high = np.maximum(hi + 0.5 * span, np.max(defined, axis=0, initial=-np.inf))
    diagonal = float(np.linalg.norm(span))
    arc = min(ARC_SPANS * diagonal, MAX_ARC)
    box = list(zip(low.tolist(), high.tolist(), strict=True))
    curves = []
    for seed in seeds:
        try:
            curve = trace(kinematics, seed, (-arc, arc), box, DRAW_TOL, True, DRAW_STEPS)
        except JikError:  # (a singular seed: no kernel to follow)
            curves.append(np.empty((0, kinematics.p)))
            continue
        n = int(np.ceil((curve.arc[1] - curve.arc[0]) / (SPACING * diagonal or 1.0))) + 1
        curves.append(curve.sample(max(n, 2)))
    return curves
