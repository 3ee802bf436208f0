"""Damped least squares, the weighted least-norm inverse and the posture inverse, against the
pseudoinverse (8), the extended inverse (11) and independent integrations of their ODEs."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from jik.engine.exceptions import InvalidInputError, KinematicSingularityError
from jik.engine.kinematics import Manipulator2
from jik.engine.planar_chain import PlanarChain
from jik.engine.practical_inverses import (
    DampedInverse,
    PostureInverse,
    WeightedInverse,
    limit_gradient,
)
from jik.engine.registry import ALGORITHMS, make_inverse
from jik.engine.repeatability import repeatability
from jik.engine.solver import solve

X0 = np.array([0.0, 0.0, math.pi / 2])
#: Table 1's closed path (the return leg to k(x0) = (0, 1) is added by repeatability).
TABLE1 = [(1.0, 1.0), (1.0, 2.0), (0.0, 2.0)]
KIN = Manipulator2()
LIMITS = np.array([[-3.0, 3.0], [-3.0, 3.0], [-math.pi, 2 * math.pi]])
#: A planar RRR chain's limits: x2 has no lower bound.
LIMITS_RRR = [[-1.0, 1.0], [None, 1.2], [-3.0, 3.0]]


def _inverse(name: str, **params):
    return make_inverse(KIN, name, algorithm_parameters=params)


def test_catalogue_lists_all_five_with_parameters():
    assert list(ALGORITHMS) == ["pseudoinverse", "extended", "damped", "weighted", "posture"]
    assert [p.name for p in ALGORITHMS["damped"].parameters] == ["damping", "damping_threshold"]
    assert [p.name for p in ALGORITHMS["posture"].parameters] == ["gain"]
    assert ALGORITHMS["posture"].vectors == ("rest",)


def test_the_classes_defaults_are_the_catalogue_s():
    """DampedInverse(robot) is make_inverse(robot, "damped"): one default of each parameter."""
    assert DampedInverse(KIN).parameters == _inverse("damped").parameters
    assert PostureInverse(KIN, X0).parameters["gain"] == _inverse("posture").parameters["gain"]
    assert _inverse("damped").parameters["damping"] > 0


@pytest.mark.parametrize("mode", ["continuous", "discrete"])
@pytest.mark.parametrize("name, params", [("damped", {"damping": 0.0}), ("posture", {"gain": 0.0})])
def test_zero_parameter_is_the_pseudoinverse(name, params, mode):
    """damping 0 and gain 0 give the pseudoinverse's loop bit for bit (the same code runs)."""
    kw = {"gamma": 1.0 if mode == "continuous" else 0.5, "mode": mode}
    ref = repeatability(_inverse("pseudoinverse"), X0, TABLE1, cycles=3, **kw)
    got = repeatability(_inverse(name, **params), X0, TABLE1, cycles=3, **kw)
    assert ref.drift[-1] > 0.1
    np.testing.assert_array_equal(got.legs, ref.legs)


def test_zero_parameter_apply_matches_on_a_batch():
    rng = np.random.default_rng(3)
    x, e = rng.normal(size=(50, 3)), rng.normal(size=(50, 2))
    v_ref, _ = _inverse("pseudoinverse").apply_masked(x, e)
    for inv in (_inverse("damped", damping=0.0), _inverse("posture", gain=0.0)):
        v, bad = inv.apply_masked(x, e)
        assert not bad.any()
        np.testing.assert_allclose(v, v_ref, rtol=0, atol=1e-14)


def _pinv_ivp(J, e):
    return np.linalg.pinv(J) @ e


def _damped_ivp(lam):
    def f(J, e):
        return J.T @ np.linalg.inv(J @ J.T + lam**2 * np.eye(2)) @ e

    return f


def _weighted_ivp(x, J, e):
    lo, hi = LIMITS[:, 0], LIMITS[:, 1]
    dH = (hi - lo) ** 2 * (2 * x - hi - lo) / (4 * (hi - x) ** 2 * (x - lo) ** 2)
    Winv = np.diag(1.0 / (1.0 + np.abs(dH)))
    return Winv @ J.T @ np.linalg.inv(J @ Winv @ J.T) @ e


def _posture_ivp(k, rest):
    def f(x, J, e):
        Jp = np.linalg.pinv(J)
        return Jp @ e - k * np.linalg.norm(e) * (np.eye(3) - Jp @ J) @ (rest - x)

    return f


def _ivp_loop(velocity, x0, targets, theta=60.0):
    """Legs of eq. (7), dx/dtheta = -v(x, k(x) - y_d), each integrated by solve_ivp."""
    x, ends = np.array(x0, dtype=float), []
    for y_d in np.asarray(targets):

        def rhs(_t, x, y_d=y_d):
            return -velocity(x, KIN.jacobian(x[None])[0], KIN.forward(x[None])[0] - y_d)

        sol = solve_ivp(rhs, (0.0, theta), x, method="DOP853", rtol=1e-13, atol=1e-13)
        x = sol.y[:, -1]
        ends.append(x)
    return np.array(ends)


@pytest.mark.parametrize(
    "name, params, velocity",
    [
        ("damped", {"damping": 1.0}, lambda x, J, e: _damped_ivp(1.0)(J, e)),
        ("weighted", {}, _weighted_ivp),
        ("posture", {"gain": 0.5}, _posture_ivp(0.5, X0)),
    ],
)
def test_continuous_loop_agrees_with_solve_ivp(name, params, velocity):
    """Table 1's loop on Manipulator 2: every leg's end agrees with solve_ivp to 1e-8."""
    got = repeatability(_inverse(name, **params), X0, TABLE1, cycles=1, tol=1e-12)
    assert got.success
    want = _ivp_loop(velocity, X0, got.targets)
    np.testing.assert_allclose(got.legs, want, rtol=0, atol=1e-8)
    ref = repeatability(_inverse("pseudoinverse"), X0, TABLE1, cycles=1, tol=1e-12)
    assert np.max(np.abs(got.legs - ref.legs)) > 1e-3  # not the pseudoinverse's path


def test_the_pseudoinverse_reference_integration_is_itself_right():
    """The independent integration reproduces the pseudoinverse's loop (a check of the check)."""
    got = repeatability(_inverse("pseudoinverse"), X0, TABLE1, cycles=1, tol=1e-12)
    want = _ivp_loop(lambda x, J, e: _pinv_ivp(J, e), X0, got.targets)
    np.testing.assert_allclose(got.legs, want, rtol=0, atol=1e-8)


def test_posture_drifts_less_than_the_pseudoinverse_but_is_not_repeatable():
    """After 10 cycles of Table 1's loop: pseudoinverse > posture > 1e-12 > extended."""
    drift = {
        name: repeatability(_inverse(name, **p), X0, TABLE1, cycles=10).drift[-1]
        for name, p in [("pseudoinverse", {}), ("posture", {"gain": 1.0}), ("extended", {})]
    }
    assert drift["posture"] < 0.1 * drift["pseudoinverse"]
    assert drift["posture"] > 1e-12
    assert drift["extended"] < 1e-12


def test_posture_pull_stays_in_the_kernel():
    """J v = e for the posture inverse: the pull moves only within the self-motion."""
    rng = np.random.default_rng(5)
    x, e = rng.normal(size=(40, 3)), rng.normal(size=(40, 2))
    inv = PostureInverse(KIN, X0, gain=2.0)
    v, _ = inv.apply_masked(x, e)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", KIN.jacobian(x), v), e, atol=1e-12)
    v0, _ = _inverse("pseudoinverse").apply_masked(x, e)
    assert np.max(np.abs(v - v0)) > 0.1


STRETCHED = np.zeros(3)
ARM3R = PlanarChain("RRR", [1.0, 1.0, 1.0])


@pytest.mark.filterwarnings("error")
def test_posture_pull_of_a_diverged_iterate_is_marked_bad_without_a_warning():
    """A continuous run's Picard sweeps may diverge (the Panda with k = 60 did): the pull of
    such an iterate overflows, and is marked bad (the sweep gives up) with no RuntimeWarning,
    which ``jik serve`` would print to its log."""
    inv = PostureInverse(KIN, X0, gain=60.0)
    x = np.array([[1e160, -1e160, 1.0], [0.1, 0.2, 1.0]])
    e = np.array([[1e150, 1.0], [0.1, 0.1]])
    v, bad = inv.apply_masked(x, e)
    assert bad.tolist() == [True, False]
    assert np.isfinite(v).all()


@pytest.mark.filterwarnings("error")
def test_weighted_run_whose_trial_points_reach_a_limit_does_not_warn():
    """A Picard sweep of the 3R arm toward (0, 2.5) within [-1, 1] per joint evaluates trial
    points at a limit, where two weights are 0 and J W^-1 J^T is singular: those members are
    marked bad with no RuntimeWarning (under ``-W error`` the run raised)."""
    inv = WeightedInverse(ARM3R, [[-1.0, 1.0]] * 3)
    res = solve(inv, (0.3, 0.4, 0.5), (0.0, 2.5))
    assert res.success and res.error < 1e-10
    assert not inv.outside(res.x)


def test_damped_leaves_a_singular_start_where_the_pseudoinverse_cannot():
    """The 3R arm stretched (J of rank 1): damped least squares moves off and converges."""
    with pytest.raises(KinematicSingularityError):
        solve(make_inverse(ARM3R, "pseudoinverse"), STRETCHED, (2.0, 1.0))
    res = solve(DampedInverse(ARM3R, 0.1), STRETCHED, (2.0, 1.0))
    assert res.success and res.error < 1e-10
    assert ARM3R.manipulability(res.x[None])[0] > 0.1  # ends away from the singularity


@pytest.mark.parametrize("damping", [2.0, 4.0, 10.0])
def test_a_large_damping_converges_slower_and_is_no_stall(damping):
    """Under damped least squares the task error falls at sigma^2 / (sigma^2 + lambda^2), not
    exp(-tau): with lambda = 2 to 10 on Manipulator 2 from Table 1's start a run needs tau of
    100 to 2,000 and converges (it was called a stall near a singularity of J# at tau = 64)."""
    res = solve(DampedInverse(Manipulator2(), damping), (0.0, 0.0, math.pi / 2), (1.0, 1.0))
    assert res.success and res.error < 1e-10, res.message
    assert res.trajectory is not None and res.trajectory.theta[-1] > 100


@pytest.mark.parametrize("threshold", [0.0, 0.3])
def test_damped_reaches_the_singularity_and_reports_its_task_error(threshold):
    """A target beyond reach: the pseudoinverse stalls short of the boundary, damped least
    squares stretches the arm to the singular configuration toward the target and reports
    the task error it is left with (0.5 = 3.5 - reach), success False."""
    x0, target = (0.3, 0.3, 0.3), (3.5, 0.0)
    plain = solve(make_inverse(ARM3R, "pseudoinverse"), x0, target)
    assert not plain.success and plain.error > 1.0
    res = solve(DampedInverse(ARM3R, 0.1, threshold), x0, target)
    assert not res.success
    assert res.error == pytest.approx(0.5, abs=1e-9)
    assert "error 0.5" in res.message
    np.testing.assert_allclose(res.x, STRETCHED, atol=1e-9)
    assert res.trajectory is not None and res.trajectory.error[-1] == pytest.approx(0.5)


def test_adaptive_damping_is_zero_away_from_singularities():
    """lambda(x) = 0 where the smallest singular value is above the threshold."""
    inv = DampedInverse(ARM3R, 0.2, damping_threshold=0.05)
    x = np.array([[0.3, 0.9, 0.8], [0.0, 0.0, 1e-3]])
    lam2 = inv.damping_squared(ARM3R.jacobian(x))
    assert lam2[0] == 0.0 and 0.0 < lam2[1] < 0.04
    e = np.array([[0.1, -0.2]] * 2)
    v, _ = inv.apply_masked(x[:1], e[:1])
    v0, _ = make_inverse(ARM3R, "pseudoinverse").apply_masked(x[:1], e[:1])
    np.testing.assert_allclose(v, v0, atol=1e-14)


@pytest.mark.parametrize("threshold", [1e-320, 1e-300])
def test_a_tiny_damping_threshold_damps_only_a_singular_jacobian_without_overflow(threshold):
    """epsilon subnormal, or s(x) / epsilon beyond the float range (s = 1e10): lambda(x) = 0
    where s(x) > epsilon and lambda where J is exactly singular, with no RuntimeWarning."""
    inv = DampedInverse(ARM3R, 0.2, damping_threshold=threshold)
    J = np.array([[[1e10, 0.0, 0.0], [0.0, 1e10, 0.0]], [[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lam2 = inv.damping_squared(J)
        res = solve(inv, (0.3, 0.4, 0.5), (1.0, 1.5))
    np.testing.assert_allclose(lam2, [0.0, 0.04], rtol=1e-15, atol=0)
    assert res.success


def test_limit_gradient_matches_finite_differences():
    rng = np.random.default_rng(7)
    lim = np.array([[-1.0, 2.0], [0.5, 1.5], [-np.inf, np.inf]])

    def H(x):
        lo, hi = lim[:2, 0], lim[:2, 1]
        return np.sum((hi - lo) ** 2 / (4 * (hi - x[..., :2]) * (x[..., :2] - lo)), axis=-1)

    x = np.column_stack(
        [rng.uniform(-0.8, 1.8, 20), rng.uniform(0.6, 1.4, 20), rng.normal(size=20)]
    )
    g = limit_gradient(x, lim)
    h = 1e-6
    for i in range(3):
        d = np.zeros(3)
        d[i] = h
        np.testing.assert_allclose(g[:, i], (H(x + d) - H(x - d)) / (2 * h), rtol=1e-6, atol=1e-8)


def test_weighted_keeps_a_joint_off_its_limit_where_the_pseudoinverse_crosses_it():
    """A limit on x3 that the pseudoinverse's leg crosses: the weighted inverse stays inside."""
    target = (1.0, 1.0)
    plain = solve(_inverse("pseudoinverse"), X0, target)
    lim = LIMITS.copy()
    lim[2] = (plain.x[2] + 0.3, 2 * math.pi) if plain.x[2] < X0[2] else (-math.pi, plain.x[2] - 0.3)
    res = solve(WeightedInverse(KIN, lim), X0, target)
    assert res.success
    xs = res.trajectory.x
    assert np.all((xs > lim[:, 0]) & (xs < lim[:, 1]))
    assert not np.all((plain.trajectory.x > lim[:, 0]) & (plain.trajectory.x < lim[:, 1]))


def test_batched_runs_equal_one_by_one_runs():
    rng = np.random.default_rng(11)
    x0 = X0 + rng.normal(scale=0.2, size=(4, 3))
    for inv in (_inverse("damped", damping=0.2), _inverse("weighted"), _inverse("posture")):
        batch = repeatability(inv, x0, TABLE1, cycles=2, mode="discrete", gamma=0.5)
        for i in range(4):
            one = repeatability(inv, x0[i], TABLE1, cycles=2, mode="discrete", gamma=0.5)
            np.testing.assert_allclose(batch.legs[i], one.legs, rtol=0, atol=1e-13)


@pytest.mark.parametrize(
    "name, params, field",
    [
        ("damped", {"damping": -1.0}, "damping"),
        ("damped", {"damping_threshold": math.inf}, "damping_threshold"),
        ("posture", {"gain": -0.1}, "gain"),
        ("posture", {"rest": [0.0, 1.0]}, "rest"),
        ("weighted", {"limits": [[1.0, 0.0]] * 3}, "limits"),
        ("damped", {"gain": 1.0}, "gain"),
        ("nonsense", {}, "algorithm"),
    ],
)
def test_bad_parameters_name_their_field(name, params, field):
    with pytest.raises(InvalidInputError, match=field):
        make_inverse(KIN, name, algorithm_parameters=params)


@pytest.mark.parametrize("name", ["pseudoinverse", "damped", "weighted", "posture"])
def test_an_augmenting_map_is_the_extended_inverses_alone(name):
    """A map given to another algorithm is refused, not dropped (the caller meant one)."""
    with pytest.raises(InvalidInputError, match="takes no augmenting map") as refused:
        make_inverse(KIN, name, "paper_cubic")
    assert refused.value.field == "augmentation"
    with pytest.raises(InvalidInputError, match=r"takes no augmenting map .*got \{'a': 1.0\}"):
        make_inverse(KIN, name, None, {"a": 1.0})


def test_reproduction_table_has_every_algorithm():
    """`jik reproduce algorithms`, shortened to 2 cycles: one row per algorithm, in order."""
    from jik.engine.reproductions import algorithms as repro

    result = repro.run(cycles=2, loops=("manipulator2",))
    assert [r["name"] for r in result["algorithms"]] == list(ALGORITHMS)
    drift = {r["name"]: r["drift"]["1"] for r in result["algorithms"]}
    assert drift["extended"] < 1e-12 < drift["posture"] < 0.2 < drift["pseudoinverse"]
    text = repro.format_text(result)
    assert text.count("\n| ") == 6 and "| posture | gain = 1.0, rest = x0 |" in text


@pytest.mark.slow  # (~5 s: the Panda's map is synthesized; the default run has Table 1's)
def test_reproduction_table_of_the_panda_pose_loop():
    """The Panda's pose loop, one cycle: every algorithm succeeds, the extended inverse (its
    synthesized map) comes back to x0, the pseudoinverse does not."""
    from jik.engine.reproductions import algorithms as repro

    result = repro.run(cycles=1, loops=("panda",))
    rows = {r["name"]: r for r in result["panda"]["algorithms"]}
    assert list(rows) == list(ALGORITHMS) and all(r["success"] for r in rows.values())
    assert rows["extended"]["drift"]["1"] < 1e-12 < rows["pseudoinverse"]["drift"]["1"]
    text = repro.format_text(result)
    assert (
        "Panda's pose loop" in text and "| weighted | limits = the Panda's joint limits |" in text
    )


def test_cli_algorithm_and_robot_names_are_the_catalogue():
    from jik.cli.algorithm_options import ALGORITHM_NAMES
    from jik.cli.robot_commands import BUILT_IN_ROBOTS, CATALOGUE_ARMS
    from jik.engine.arms import ARMS
    from jik.engine.registry import ROBOTS

    assert list(ALGORITHM_NAMES) == list(ALGORITHMS)
    assert list(BUILT_IN_ROBOTS) == list(ROBOTS) and list(CATALOGUE_ARMS) == list(ARMS)


def test_weighted_refuses_a_start_past_a_limit_naming_the_joint():
    inv = WeightedInverse(KIN, [[-1.0, 1.0], [-1.0, 1.0], [2.0, 3.0]])
    with pytest.raises(
        KinematicSingularityError, match=r"joint 3 is at or past its limits \[2, 3\]"
    ):
        solve(inv, X0, (1.0, 1.0))


def test_limits_given_to_make_inverse_serve_a_robot_without_limits_of_its_own():
    """A planar chain built directly has no limits and no configuration box; the weighted
    inverse takes the limits given in algorithm_parameters (the default was computed, and
    refused, even when they were given)."""
    chain = PlanarChain(joints="RRR", lengths=[1.0, 0.8, 0.6])
    limits = [[-2.0, 2.0], [-1.5, 1.5], [-2.5, 2.5]]
    inv = make_inverse(chain, "weighted", algorithm_parameters={"limits": limits})
    np.testing.assert_allclose(inv.limits, limits)
    assert solve(inv, [0.3, 1.0, 1.0], [1.0, 1.3]).success


@pytest.mark.parametrize("width", [1e308, np.finfo(float).max, np.inf])
def test_a_joint_whose_limits_are_huge_or_infinite_has_weight_one(width):
    """Limits [-w, w] with w near the largest float: (hi - lo)^2 would overflow, yet the joint
    is as unlimited as with w = inf, so W = I and the weighted inverse is the pseudoinverse."""
    lim = np.array([[-width, width]] * 3)
    x = X0 + np.random.default_rng(3).normal(scale=0.3, size=(5, 3))
    np.testing.assert_array_equal(limit_gradient(x, lim), 0.0)
    plain = solve(_inverse("pseudoinverse"), X0, (1.0, 1.0))
    res = solve(WeightedInverse(KIN, lim), X0, (1.0, 1.0))
    assert res.success
    np.testing.assert_allclose(res.x, plain.x, atol=1e-12)


@pytest.fixture(scope="module")
def panda():
    pytest.importorskip("yourdfpy")
    from jik.engine.robot_spec import robot_from_dict

    return robot_from_dict({"name": "panda", "task": "pose"})


def test_a_rest_outside_an_arm_s_joint_limits_is_refused_naming_the_joint(panda):
    """The Panda's joint 4 lies in [-3.0718, -0.0698]: a rest with x4 = 0 is refused at rest.3,
    naming the joint, its value and the limit; its home is accepted, given or by default."""
    kin, home = panda.kinematics, list(panda.kinematics.home)
    bad = [*home[:3], 0.0, *home[4:]]
    for build in (
        lambda: PostureInverse(kin, bad),
        lambda: make_inverse(kin, "posture", algorithm_parameters={"rest": bad}),
        lambda: panda.inverse("posture", algorithm_parameters={"rest": bad}),
    ):
        with pytest.raises(InvalidInputError) as refused:
            build()
        assert refused.value.field == "rest.3"
        assert str(refused.value) == (
            "rest x4 (panda_joint4) must be in [-3.0718, -0.0698] (the joint limits of the "
            "panda), got 0"
        )
    np.testing.assert_array_equal(PostureInverse(kin, home).rest, home)
    default = make_inverse(kin, "posture", x0=bad)
    assert not default.rest_given and list(default.rest) == home


def test_a_default_rest_at_a_start_outside_the_limits_is_accepted():
    """A planar chain with limits and no home: a start outside its limits is allowed (the run
    reports leaving them), and so is the default rest there (the start); the same numbers given
    as the rest are refused."""
    from jik.engine.robot_spec import robot_from_dict

    robot = robot_from_dict(
        {"name": "planar_chain", "joints": "RRR", "lengths": [1, 0.8, 0.6], "limits": LIMITS_RRR}
    )
    x0 = [1.5, 0.2, 0.3]  # (x1 above its upper limit 1)
    inv = make_inverse(robot.kinematics, "posture", x0=x0)
    assert not inv.rest_given and list(inv.rest) == x0
    assert list(robot.inverse("posture", x0=x0).rest) == x0
    res = repeatability(inv, np.array(x0), [(1.2, 1.0), (1.0, 1.2)], cycles=1)
    assert np.isfinite(res.drift).all()
    with pytest.raises(InvalidInputError, match=r"rest x1 must be in \[-1, 1\]") as refused:
        make_inverse(robot.kinematics, "posture", algorithm_parameters={"rest": x0})
    assert refused.value.field == "rest.0"
    # A joint without a lower bound: only its upper one refuses.
    PostureInverse(robot.kinematics, [0.0, -50.0, 0.0])
    with pytest.raises(InvalidInputError, match=r"must be at most 1.2 .*, got 2"):
        PostureInverse(robot.kinematics, [0.0, 2.0, 0.0])


def test_a_home_outside_the_limits_is_the_default_rest_but_not_a_given_one(panda):
    """A URDF arm given a home outside its limits (its start by default, allowed and reported
    as leaving them): the posture inverse's default rest is that home; given, it is refused."""
    from jik.engine.robot_spec import robot_from_dict

    home = [*panda.kinematics.home[:3], 0.0, *panda.kinematics.home[4:]]
    robot = robot_from_dict({"name": "panda", "task": "pose", "home": home})
    assert list(robot.inverse("posture").rest) == home
    with pytest.raises(InvalidInputError) as refused:
        robot.inverse("posture", algorithm_parameters={"rest": home})
    assert refused.value.field == "rest.3"


def test_limited_box_narrows_a_box_to_the_limits_keeping_its_width_beyond_one():
    """Finite limits replace their side of the box; a side without a limit keeps the box's, or,
    where the box lies wholly beyond the other side's limit, the box's width from that limit."""
    from jik.engine.limits import limited_box

    box = [[-3.0, 3.0], [-3.0, 3.0], [5.0, 7.0], [-3.0, 3.0]]
    limits = [[-1.0, 1.0], [-np.inf, 1.2], [-np.inf, 4.0], [-np.inf, np.inf]]
    want = [[-1.0, 1.0], [-3.0, 1.2], [2.0, 4.0], [-3.0, 3.0]]
    np.testing.assert_array_equal(limited_box(box, limits), want)
    np.testing.assert_array_equal(limited_box(box, None), box)


def test_a_diverged_posture_run_names_its_gain_beside_gamma():
    """The posture inverse's null-space pull grows with k ||e||: a discrete run with a large
    gain that diverges says to lower gamma or the gain, naming k."""
    chain = PlanarChain("RRR", [1.0, 1.0, 1.0])
    posture = make_inverse(
        chain, "posture", algorithm_parameters={"gain": 20.0, "rest": [2, -2, 2]}
    )
    res = solve(posture, [0.3, 0.4, 0.5], [1.5, 1.0], mode="discrete", gamma=1.0)
    assert res.status == "diverged"
    assert res.message.endswith("; lower gamma or the posture gain k (20)")


@pytest.mark.parametrize("name", ["panda", "iiwa14", "gen3", "ur5e"])
def test_the_weighted_inverse_runs_from_each_catalogue_arm_s_default_start(name):
    """The weighted inverse's default limits of a URDF arm: its joint limits, none for a
    continuous joint (Gen3's joints 1, 3, 5 and 7, whose default start has x3 = pi: a limit
    there made the catalogue's own default run refuse its start)."""
    pytest.importorskip("yourdfpy")
    from jik.engine.robot_spec import robot_from_dict

    robot = robot_from_dict({"name": name})
    inv = robot.inverse("weighted")
    free = np.isinf(robot.kinematics.joint_limits).all(axis=1)
    assert np.isinf(inv.limits[free]).all() and np.isfinite(inv.limits[~free]).all()
    x0 = np.asarray(robot.spec.default_x0)
    target = robot.kinematics.forward(x0 + 0.05)
    res = solve(inv, x0, target)
    assert res.success, res.message
    assert name != "gen3" or (free.sum() == 4 and math.isclose(x0[2], math.pi))
