"""Closed self-motion curves: engine.self_motion traces one turn and reports its period, and the
atlas lays its starts over that turn once (engine.atlas)."""

import inspect
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from jik.engine.atlas import plan_atlas
from jik.engine.exceptions import InvalidInputError
from jik.engine.inverses import Pseudoinverse
from jik.engine.kinematics import Kinematics, Manipulator2
from jik.engine.planar_chain import PlanarChain
from jik.engine.self_motion import (
    MAX_ARC,
    MAX_STEPS,
    SPACING,
    drawn_curves,
    periodic_joints,
    trace,
)

ARM4 = Path(__file__).parents[1] / "data" / "arm4.urdf"
#: A planar 3R arm's link lengths, and a base configuration whose fibre of the end point is a
#: loop in R^3 (the end angle phi sweeps an interval and back: elbow up, then elbow down).
LENGTHS = (1.0, 0.8, 0.5)
LOOP_BASE = (0.3, 0.4, 0.5)


class Circles(Kinematics):
    """k(x) = x1^2 + x2^2: the fibre of y0 is a circle of radius sqrt(y0), length 2 pi sqrt(y0)."""

    name = "circles"
    p, r = 2, 1

    def forward(self, x):
        x = np.asarray(x, dtype=float)
        return np.sum(x**2, axis=-1, keepdims=True)

    def jacobian(self, x):
        return 2 * np.asarray(x, dtype=float)[..., None, :]


def rrr_urdf(kind: str) -> str:
    """A planar 3R arm of LENGTHS about z as a URDF, its joints of type ``kind``."""
    origins = ["0 0 0", f"{LENGTHS[0]} 0 0", f"{LENGTHS[1]} 0 0"]
    joints = "".join(
        f'<joint name="j{i}" type="{kind}"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="{o}"/><axis xyz="0 0 1"/>'
        + ('<limit lower="-3" upper="3" effort="1" velocity="1"/>' if kind == "revolute" else "")
        + "</joint>"
        for i, o in enumerate(origins)
    )
    return (
        '<robot name="rrr">'
        + "".join(f'<link name="l{i}"/>' for i in range(4))
        + '<link name="tool"/>'
        + joints
        + f'<joint name="tip" type="fixed"><parent link="l3"/><child link="tool"/>'
        f'<origin xyz="{LENGTHS[2]} 0 0"/></joint></robot>'
    )


def rrr_speed(P, phi: float, sigma: float) -> float:
    """|dx/dphi| on the planar 3R's fibre of the end point P, on the branch of elbow sign
    ``sigma``, phi the last link's angle (closed-form inverse kinematics: the wrist
    W = P - l3 (cos phi, sin phi), x2 = sigma acos(c2), x1 = atan2(W) - atan2(l2 sin x2,
    l1 + l2 cos x2), x3 = phi - x1 - x2, differentiated by hand)."""
    l1, l2, l3 = LENGTHS
    W = P - l3 * np.array([math.cos(phi), math.sin(phi)])
    dW = l3 * np.array([math.sin(phi), -math.cos(phi)])
    rho2 = W @ W
    x2 = sigma * math.acos((rho2 - l1**2 - l2**2) / (2 * l1 * l2))
    dx2 = -(W @ dW) / (l1 * l2) / math.sin(x2)
    dx1 = (W[0] * dW[1] - W[1] * dW[0]) / rho2 - l2 * (l1 * math.cos(x2) + l2) * dx2 / rho2
    return math.sqrt(dx1**2 + dx2**2 + (1 - dx1 - dx2) ** 2)


def test_a_circle_is_traced_once_round_and_its_period_is_its_length():
    """Asked for the whole arc (+-MAX_ARC, 320 turns), the tracer stops where the circle comes
    back to its start: period 2 pi R to 1e-10, the two ends of the turn the same point, a few
    dozen steps; s beyond the turn is taken modulo the period."""
    kin = Circles()
    base = np.array([0.6, -0.8]) * 1.5
    curve = trace(kin, base, (-MAX_ARC, MAX_ARC))
    assert curve.closed
    assert curve.period == pytest.approx(3 * math.pi, rel=1e-10)
    assert curve.arc == (0.0, curve.period)
    assert curve.steps < 60
    ends = curve.points(np.array(curve.arc))
    np.testing.assert_allclose(ends[1], ends[0], rtol=0, atol=1e-12)
    s = np.linspace(0.0, curve.period, 7)
    angle = math.atan2(base[1], base[0]) + np.sign(kin.kernel(base) @ [-base[1], base[0]]) * s / 1.5
    np.testing.assert_allclose(
        curve.points(s), 1.5 * np.stack([np.cos(angle), np.sin(angle)], 1), rtol=0, atol=1e-10
    )
    for turns in (2, -1):
        np.testing.assert_allclose(
            curve.points(s[1:3] + turns * curve.period), curve.points(s[1:3]), rtol=0, atol=1e-14
        )


def test_a_loop_closing_behind_is_one_turn_ending_at_the_arc_asked_ahead():
    """Arc (-5, 3) on a circle of length 2 pi: ahead to 3, then behind until the curve comes
    round to x(3), at s = 3 - 2 pi; an arc shorter than a turn stays open, as asked."""
    kin = Circles()
    curve = trace(kin, (1.0, 0.0), (-5.0, 3.0))
    assert curve.period == pytest.approx(2 * math.pi, rel=1e-10)
    assert curve.arc[1] == 3.0 and curve.arc[0] == pytest.approx(3.0 - 2 * math.pi, rel=1e-10)
    ends = curve.points(np.array(curve.arc))
    np.testing.assert_allclose(ends[1], ends[0], rtol=0, atol=1e-12)
    short = trace(kin, (1.0, 0.0), (-3.0, 3.0))
    assert not short.closed and short.period is None and short.arc == (-3.0, 3.0)


@pytest.mark.parametrize("tol", [1e-8, 1e-6])
def test_a_loosely_traced_curve_still_closes_and_its_samples_lie_on_the_fibre(tol):
    """Traced to a drawing's tolerance: the circle and the planar 3R's loop are still found
    closed after one turn (the return is judged within CLOSE_PER_TOL tol), with the period
    to about 1e3 tol, in fewer steps; sample(n) gives n points evenly spaced in s over the turn,
    each on k(x) = y0 to 1e-12 and within 1e3 tol of the accurate curve's point at that s."""
    for kin, base in ((Circles(), np.array([0.9, -1.2])), (PlanarChain("RRR", LENGTHS), LOOP_BASE)):
        exact = trace(kin, base, (-50.0, 50.0))
        loose = trace(kin, base, (-50.0, 50.0), tol=tol)
        assert loose.closed and loose.steps < exact.steps
        assert loose.period == pytest.approx(exact.period, rel=0, abs=1e3 * tol)
        x = loose.sample(101)
        assert x.shape == (101, kin.p)
        y0 = np.broadcast_to(kin.forward(np.asarray(base, dtype=float)), (101, kin.r))
        np.testing.assert_allclose(kin.forward(x), y0, rtol=0, atol=1e-12)
        s = np.linspace(*loose.arc, 101)
        np.testing.assert_allclose(x, exact.points(s), rtol=0, atol=1e3 * tol)
        np.testing.assert_allclose(x[-1], x[0], rtol=0, atol=1e3 * tol)


@pytest.mark.parametrize(
    ("call", "field", "text"),
    [
        (lambda c: trace(Circles(), (1.0, 0.0), (-1.0, 1.0), tol=1e-3), "tol", "from 1e-12"),
        (lambda c: trace(Circles(), (1.0, 0.0), (-1.0, 1.0), tol="x"), "tol", "a number"),
        (lambda c: c.sample(1), "n", "between 2 and 100000"),
    ],
)
def test_a_bad_tolerance_or_sample_count_is_named(call, field, text):
    curve = trace(Circles(), (1.0, 0.0), (-1.0, 1.0))
    with pytest.raises(InvalidInputError, match=text) as info:
        call(curve)
    assert info.value.field == field


def test_a_planar_3r_loop_has_the_length_of_its_closed_form_fibre():
    """The 3R arm's fibre through LOOP_BASE: phi sweeps [a, b] (where the wrist's distance
    reaches l1 + l2) on both elbow branches; its length by quadrature of the closed-form
    inverse's speed (phi = m + h sin t takes out the folds' 1/sqrt) is the period to 1e-9."""
    kin = PlanarChain("RRR", LENGTHS)
    P = kin.forward(np.array(LOOP_BASE))

    def reach(phi):
        return float(np.linalg.norm(P - LENGTHS[2] * np.array([math.cos(phi), math.sin(phi)])))

    phi = np.linspace(-math.pi, math.pi, 721)
    far = np.array([reach(f) for f in phi]) - sum(LENGTHS[:2])
    k = np.flatnonzero(np.diff(np.sign(far)))
    assert len(k) == 2  # (one interval of phi, so one loop)
    a, b = (brentq(lambda f: reach(f) - sum(LENGTHS[:2]), phi[i], phi[i + 1]) for i in k)
    if reach((a + b) / 2) > sum(LENGTHS[:2]):
        a, b = b, a + 2 * math.pi
    m, h = (a + b) / 2, (b - a) / 2
    length = sum(
        quad(
            lambda t, sg=sg: rrr_speed(P, m + h * math.sin(t), sg) * h * math.cos(t),
            -math.pi / 2,
            math.pi / 2,
            epsabs=1e-12,
            limit=200,
        )[0]
        for sg in (1.0, -1.0)
    )
    curve = trace(kin, LOOP_BASE, (-MAX_ARC, MAX_ARC))
    assert curve.closed and curve.steps < 100
    assert curve.period == pytest.approx(length, rel=1e-9, abs=0)
    ends = curve.points(np.array(curve.arc))
    np.testing.assert_allclose(ends[1], ends[0], rtol=0, atol=1e-10)


def test_a_continuous_joint_closes_a_loop_modulo_two_pi():
    """Where the end angle turns all the way round (|P| = 0.9: every phi reachable), the fibre
    in R^3 is open (x3 gains 2 pi a turn); with the joints a URDF's continuous joints it is
    closed, its period the integral of the closed-form speed over one turn of phi (periodic
    and smooth: the trapezoid rule is exact to round-off), and its ends differ by 2 pi in x3."""
    planar = PlanarChain("RRR", LENGTHS)
    urdf = pytest.importorskip("jik.engine.urdf").UrdfChain(
        rrr_urdf("continuous"), "tool", task="x y"
    )
    limited = pytest.importorskip("jik.engine.urdf").UrdfChain(
        rrr_urdf("revolute"), "tool", task="x y"
    )
    assert periodic_joints(urdf).all() and not periodic_joints(limited).any()
    assert not periodic_joints(planar).any()
    # A base whose end point is at distance 0.9 from the base, elbow up.
    P = np.array([0.9, 0.0])
    phi0 = 0.4
    W = P - LENGTHS[2] * np.array([math.cos(phi0), math.sin(phi0)])
    x2 = math.acos((W @ W - LENGTHS[0] ** 2 - LENGTHS[1] ** 2) / (2 * LENGTHS[0] * LENGTHS[1]))
    x1 = math.atan2(W[1], W[0]) - math.atan2(
        LENGTHS[1] * math.sin(x2), LENGTHS[0] + LENGTHS[1] * math.cos(x2)
    )
    base = np.array([x1, x2, phi0 - x1 - x2])
    np.testing.assert_allclose(urdf.forward(base), P, atol=1e-14)
    np.testing.assert_allclose(planar.forward(base), P, atol=1e-14)
    phi = np.linspace(0.0, 2 * math.pi, 4097)[:-1]
    length = 2 * math.pi * np.mean([rrr_speed(P, f, 1.0) for f in phi])
    curve = trace(urdf, base, (-MAX_ARC, MAX_ARC))
    assert curve.closed and curve.steps < 100
    assert curve.period == pytest.approx(length, rel=1e-9, abs=0)
    ends = curve.points(np.array(curve.arc))
    np.testing.assert_allclose(ends[1, :2], ends[0, :2], rtol=0, atol=1e-10)
    assert abs(abs(ends[1, 2] - ends[0, 2]) - 2 * math.pi) < 1e-10
    open_ = trace(planar, base, (-3 * length, 3 * length))
    assert not open_.closed and open_.arc == (-3 * length, 3 * length)
    assert not trace(limited, base, (-3 * length, 3 * length)).closed
    # A box of +-1 rad about the base: a window on the continuous joints' turn (the loop is
    # still found) unless they are bounded by it too, when the curve stops where an angle
    # leaves it, on the box's face.
    box = [(v - 1.0, v + 1.0) for v in base]
    assert trace(urdf, base, (-MAX_ARC, MAX_ARC), box).closed
    cut = trace(urdf, base, (-MAX_ARC, MAX_ARC), box, bound_free_joints=True)
    assert not cut.closed and cut.arc[1] - cut.arc[0] < length
    ends = cut.points(np.array(cut.arc))
    assert np.all(np.isclose(np.abs(ends - base), 1.0, atol=1e-9).any(axis=1))


def arm4_plan(n: int, **kw):
    """An atlas of arm4.urdf (a continuous wrist) as a dashboard session asks for it: the loop
    from k(x0) through a square, the curve of k(x0) cut by the joints' ranges."""
    kin = pytest.importorskip("jik.engine.urdf").UrdfChain(ARM4.read_text(), "tool")
    x0 = np.full(4, 0.5)
    y = kin.forward(x0)
    path = [y, y + [0.05, 0, 0], y + [0.05, 0.05, 0], y + [0, 0.05, 0]]
    return plan_atlas(
        Pseudoinverse(kin),
        path,
        n_starts=n,
        arc=(-MAX_ARC, MAX_ARC),
        reference=x0,
        box=kin.limits,
        **kw,
    )


def test_arm4s_atlas_lays_its_starts_over_one_turn():
    """arm4's curve of k(x0) is a loop inside its joints' ranges: the plan traces it once (a
    few dozen steps where the whole arc took thousands), its period that of the first return
    solve_ivp finds on its own; a grid of n starts is n even steps of one turn, the end (the
    first start again) left out, and samples stay within the turn."""
    plan = arm4_plan(6, sampling="grid")
    curve = plan.manifolds[0]
    assert curve.closed and curve.steps < 100
    kin = curve.kinematics
    tangent = kin.kernel(curve.base)

    def section(_s, x):
        return float(tangent @ (x - curve.base))

    section.direction = 1  # type: ignore[attr-defined]
    sol = solve_ivp(
        lambda _s, x: kin.kernel(x),
        (0.0, 1.5 * curve.period),
        curve.base,
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
        events=section,
    )
    returns = [
        t
        for t, x in zip(sol.t_events[0], sol.y_events[0], strict=True)
        if t > 1 and np.linalg.norm(x - curve.base) < 1e-6
    ]
    assert curve.period == pytest.approx(returns[0], rel=1e-10, abs=0)
    s = plan.parameter(np.arange(6))
    np.testing.assert_allclose(s, curve.period * np.arange(6) / 6, rtol=0, atol=1e-12)
    starts = plan.starts(0, 6)
    np.testing.assert_allclose(
        kin.forward(starts), np.broadcast_to(kin.forward(curve.base), (6, 3)), atol=1e-13
    )
    gaps = np.linalg.norm(np.diff(np.vstack([starts, starts[:1]]), axis=0), axis=1)
    assert gaps.min() > 0.1  # (no start twice: the turn's end is not one)
    sampled = arm4_plan(50, sampling="sample", seed=3).parameter(np.arange(50))
    assert sampled.min() >= 0 and sampled.max() < curve.period


def test_a_family_of_loops_takes_each_loops_s_modulo_its_own_period():
    """Shifted paths have circles of other radii: traced over the first circle's turn, a
    smaller one closes sooner, and its starts' s (the first's grid) wrap round it."""
    kin = Circles()
    plan = plan_atlas(
        Pseudoinverse(kin),
        [(1.0,), (1.2,)],
        n_starts=8,
        arc=(-MAX_ARC, MAX_ARC),
        reference=(1.0, 0.0),
        sampling="grid",
        shifts=[(0.0,), (-0.75,)],
    )
    first, second = plan.manifolds
    assert first.period == pytest.approx(2 * math.pi, rel=1e-10)
    assert second.period == pytest.approx(math.pi, rel=1e-10)  # (radius 1/2)
    s = plan.parameter(np.arange(8))
    starts = plan.starts(0, 16)
    np.testing.assert_allclose(kin.forward(starts[8:]), 0.25, rtol=0, atol=1e-13)
    np.testing.assert_allclose(starts[8:], second.points(np.mod(s, math.pi)), rtol=0, atol=1e-9)
    np.testing.assert_allclose(starts[12], starts[8], rtol=0, atol=1e-9)  # (s = pi: once round)


def test_starts_on_a_manifold_of_two_dimensions_stay_on_it_and_in_the_box():
    """A planar 4R chain with a position task (p - r = 2): the starts are x0, then points of
    k(x) = k(x0) farther and farther from it, within the box, the same for the same seed."""
    import jik.engine as jik

    chain = jik.PlanarChain("RRRR", [1.0, 0.8, 0.6, 0.4])
    x0 = np.array([0.3, 0.5, 0.7, 0.9])
    box = [(-np.pi, np.pi)] * 4
    X = jik.manifold_starts(chain, x0, 12, box)
    assert 8 <= len(X) <= 12 and np.array_equal(X[0], x0)
    np.testing.assert_allclose(
        chain.forward(X), chain.forward(x0)[None].repeat(len(X), 0), atol=1e-10
    )
    assert np.all(np.abs(X) <= np.pi)
    distance = np.linalg.norm(X - x0, axis=1)
    assert distance[-1] > 0.5 and np.all(np.diff(distance[:4]) > 0)
    np.testing.assert_array_equal(X, jik.manifold_starts(chain, x0, 12, box))
    with pytest.raises(jik.InvalidInputError) as refused:
        jik.manifold_starts(chain, x0, 0, box)
    assert refused.value.field == "n"


class Ratio(Kinematics):
    """k(x) = (x1^2 + x2, x3 / x1): undefined at x1 = 0, which the fibre of k(0.5, 0.5, 0.5)
    reaches (x3 = x1, x2 = 0.75 - x1^2); there the field K flips and an integrator creeps."""

    name = "ratio"
    p, r = 3, 2

    def forward(self, x):
        x = np.asarray(x, dtype=float)
        return np.stack([x[..., 0] ** 2 + x[..., 1], x[..., 2] / x[..., 0]], axis=-1)

    def jacobian(self, x):
        x1, _, x3 = np.moveaxis(np.asarray(x, dtype=float), -1, 0)
        zero = np.zeros_like(x1)
        return np.stack(
            [
                np.stack([2 * x1, np.ones_like(x1), zero], axis=-1),
                np.stack([-x3 / x1**2, zero, 1 / x1], axis=-1),
            ],
            axis=-2,
        )


def test_a_curve_that_creeps_stops_after_max_steps_each_way():
    """Toward x1 = 0 the curve creeps (steps of about 1e-5); max_steps stops each way there,
    with a shorter arc than asked, every point still on k(x) = y0."""
    kin = Ratio()
    base = np.array([0.5, 0.5, 0.5])
    curve = trace(kin, base, (-30.0, 30.0), None, 1e-6, max_steps=300)
    assert curve.steps <= 600
    assert not curve.closed and curve.arc[0] > -30.0
    points = curve.sample(50)
    assert np.allclose(kin.forward(points), kin.forward(base), atol=1e-9)


def test_trace_is_bounded_by_default_and_the_bound_holds_a_smooth_curve_of_the_longest_arc():
    """trace's steps were unbounded unless asked (2**31): a notebook's curve into a point where
    k is undefined crept for ever, as the dashboard's and an atlas's did. By default it stops
    after MAX_STEPS each way, which Manipulator 2's curve over MAX_ARC each way stays within."""
    assert inspect.signature(trace).parameters["max_steps"].default == MAX_STEPS
    curve = trace(Manipulator2(), [0.0, 0.0, math.pi / 2], (-MAX_ARC, MAX_ARC))
    assert curve.arc == (-MAX_ARC, MAX_ARC) and curve.steps < MAX_STEPS


@pytest.mark.parametrize("max_steps", [0, -1, 2.5, True])
def test_max_steps_must_be_a_positive_integer(max_steps):
    with pytest.raises(InvalidInputError, match="max_steps"):
        trace(Circles(), [1.0, 0.0], (-1.0, 1.0), max_steps=max_steps)


def test_drawn_curves_lie_on_their_fibres_a_point_every_spacing_within_the_widened_box():
    """Manipulator 2's fibres through two seeds, drawn in the box [lo, hi]: every point on
    k(x) = k(seed), a point every SPACING box diagonals, inside the box widened by half."""
    kin = Manipulator2()
    seeds = np.array([[0.0, 0.0, math.pi / 2], [0.3, 0.5, 1.0]])
    lo, hi = np.array([-1.0, -1.0, 0.0]), np.array([1.0, 1.0, 3.0])
    diagonal = float(np.linalg.norm(hi - lo))
    for seed, x in zip(seeds, drawn_curves(kin, seeds, lo, hi), strict=True):
        assert len(x) > 20
        np.testing.assert_allclose(
            kin.forward(x), np.broadcast_to(kin.forward(seed), (len(x), 2)), atol=1e-9
        )
        assert np.all(np.linalg.norm(np.diff(x, axis=0), axis=1) <= SPACING * diagonal * 1.001)
        assert np.all(x >= lo - 0.5 * (hi - lo) - 1e-5) and np.all(x <= hi + 0.5 * (hi - lo) + 1e-5)
