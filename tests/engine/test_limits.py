"""Joint limits: a run reports whether it stayed within them and its first violation."""

import numpy as np
import pytest

import jik.engine as jik
from jik.engine.exceptions import InvalidInputError
from jik.engine.limits import (
    LimitsReport,
    check_limits,
    legs_report,
    limit_names,
    repeatability_report,
    robot_limits,
    run_report,
    solve_report,
    starts_outside,
)
from jik.engine.repeatability import repeatability
from jik.engine.robot_spec import robot_from_dict
from jik.engine.solver import solve, solve_batch

LIMITS = np.array([[-1.0, 1.0], [-np.inf, np.inf], [0.0, 2.0]])
NAMES = ("x1", "x2", "x3")


def test_the_first_violation_is_found_in_order():
    legs = [
        np.array([[0, 5, 1], [0.5, -9, 1.5]]),
        np.array([[0.9, 0, 1], [0.2, 0, 2.5]]),
        np.array([[1.5, 0, 1]]),
    ]
    report = legs_report(LIMITS, [0, 0, 1], legs, 2, NAMES)
    assert not report.within
    v = report.violation
    assert (v.cycle, v.leg, v.joint, v.value, v.limit, v.bound) == (1, 2, 2, 2.5, 2.0, "upper")
    assert (
        str(report) == "left the joint limits at cycle 1, leg 2: x3 = 2.5, above its upper limit "
        "2; it ends outside them"
    )
    assert legs_report(LIMITS, [0, 0, 1], legs[:1], 2, NAMES) == LimitsReport(True)


def test_a_start_outside_is_reported_at_cycle_0():
    report = legs_report(LIMITS, [-1.2, 0, 1], [], 1, NAMES)
    expected = {
        "cycle": 0,
        "leg": 0,
        "joint": 0,
        "name": "x1",
        "value": -1.2,
        "limit": -1.0,
        "bound": "lower",
    }
    assert report.violation.as_dict() == expected
    assert "the start x0: x1 = -1.2, below its lower limit -1" in str(report)


def test_atlas_starts_that_leave_the_limits():
    x0 = np.array([[0, 0, 1], [0, 0, 1], [3, 0, 1]])
    legs = np.array([[[0, 0, 1], [0, 0, 1]], [[0, 0, 1], [0, 0, -1]], [[0, 0, 1], [0, 0, 1]]])
    np.testing.assert_array_equal(starts_outside(LIMITS, x0, legs), [False, True, True])


@pytest.mark.parametrize(
    "limits",
    [[[0, 1]], [[1, 0], [0, 1], [0, 1]], [[0, 1], [0, "a"], [0, 1]], [[0, 1], [None, None], 3]],
)
def test_bad_limits_name_the_field(limits):
    with pytest.raises(InvalidInputError, match="3 pairs") as err:
        check_limits(limits, 3)
    assert err.value.field == "limits"


def test_a_planar_chain_takes_optional_limits():
    arm = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}
    assert robot_limits(robot_from_dict(arm).kinematics) is None
    robot = robot_from_dict({**arm, "limits": [[-1, 1], [None, 1.2], [-3, 3]]})
    kin = robot.kinematics
    np.testing.assert_array_equal(robot_limits(kin), [[-1, 1], [-np.inf, 1.2], [-3, 3]])
    res = solve(robot.inverse(), [0.3, 1.0, 1.0], [0.2, 1.2])
    report = solve_report(robot_limits(kin), res, limit_names(kin))
    assert res.success and not report.within
    assert report.violation.name == "x2" and report.violation.bound == "upper"


def test_a_formula_robot_takes_optional_limits():
    robot = robot_from_dict(
        {
            "name": "formula",
            "variables": ["a", "b", "c"],
            "task": ["a + b", "b * c"],
            "limits": [[0, 1], [0, 1], [0, 1]],
        }
    )
    assert robot_limits(robot.kinematics).shape == (3, 2)


def test_a_panda_run_below_joint_2s_limit_is_reported():
    """From Franka's ready pose to a point behind the base, the pseudoinverse takes joint 2
    below -1.7628 rad; the run converges and says where it left the limits."""
    pytest.importorskip("yourdfpy")
    robot = robot_from_dict({"name": "panda", "task": "xyz"})
    kin = robot.kinematics
    res = solve(robot.inverse(), robot.spec.default_x0, [-0.3, 0.0, 0.5])
    report = solve_report(robot_limits(kin), res, limit_names(kin))
    assert res.success and not report.within
    v = report.violation
    assert (v.cycle, v.leg, v.joint, v.name, v.bound) == (1, 1, 1, "x2 (panda_joint2)", "lower")
    assert v.value < v.limit == -1.7628


def test_a_panda_start_outside_the_limits_is_accepted_and_reported():
    """Joint 4 at +0.2 (limits -3.0718, -0.0698): the run goes ahead and reports the start."""
    pytest.importorskip("yourdfpy")
    robot = robot_from_dict({"name": "panda", "task": "xyz"})
    kin = robot.kinematics
    x0 = np.array(robot.spec.default_x0)
    x0[3] = 0.2
    y0 = kin.forward(x0)
    path = y0 + np.array([[0.05, 0, 0], [0.05, 0.05, 0]])
    res = repeatability(robot.inverse(), x0, path, cycles=1, record=True)
    report = repeatability_report(robot_limits(kin), res, limit_names(kin))
    assert res.success and not report.within
    assert report.violation.as_dict() == {
        "cycle": 0,
        "leg": 0,
        "joint": 3,
        "name": "x4 (panda_joint4)",
        "value": 0.2,
        "limit": -0.0698,
        "bound": "upper",
    }


def test_continuous_joints_have_no_limits():
    pytest.importorskip("yourdfpy")
    kin = robot_from_dict({"name": "gen3"}).kinematics
    limits = robot_limits(kin)
    assert np.all(np.isinf(limits[[0, 2, 4, 6]])) and np.all(np.isfinite(limits[[1, 3, 5]]))


def test_a_robot_reports_its_runs_limits():
    """Robot.limits_report: a solve's and a repeatability run's; None without limits."""
    pytest.importorskip("yourdfpy")
    panda = robot_from_dict({"name": "panda", "task": "xyz"})
    res = solve(panda.inverse(), panda.spec.default_x0, [-0.3, 0.0, 0.5])
    assert panda.limits_report(res).violation.name == "x2 (panda_joint2)"
    home = np.array(panda.spec.default_x0)
    run = repeatability(
        panda.inverse(), home, panda.kinematics.forward(home) + [[0.05, 0, 0]], record=True
    )
    assert panda.limits_report(run) == LimitsReport(True)
    m2 = robot_from_dict({"name": "manipulator2"})
    assert m2.limits_report(solve(m2.inverse(), [0, 0, 1.5708], [1, 1])) is None
    assert run_report(panda.kinematics, run) == LimitsReport(True)
    assert run_report(panda.kinematics, res) == panda.limits_report(res)


def test_a_report_says_where_its_run_went_farthest_and_whether_it_ends_outside():
    """The first violation can be a small one: the report also names the farthest excursion
    (when it is another) and whether the run ends outside the limits. A Panda run in discrete
    mode at gamma = 1 toward a half turn of rz first passes joint 7's upper limit by 0.55 rad,
    then goes tens of radians beyond a limit (which joint, and where it converges, depends on
    the round-off of numpy's versions: Newton steps of radians near the rotation cut) and ends
    there."""
    legs = [np.array([[0.0, 0, 1.1], [-3.0, 0, 1.0], [0.5, 0, 1.0]])]
    back = legs_report(LIMITS, [0, 0, 1], legs, 1, NAMES)
    assert (back.violation.name, back.farthest.name, back.ends_outside) == ("x1", "x1", False)
    assert str(back) == (
        "left the joint limits on the way to the target: x1 = -3, below its lower limit -1; it "
        "ends within them"
    )
    panda = robot_from_dict({"name": "panda"})
    x0 = np.asarray(panda.spec.default_x0)
    target = panda.kinematics.forward(x0[None])[0]
    target[5] = 3.14
    run = solve(panda.inverse("pseudoinverse"), x0, target, mode="discrete", gamma=1.0)
    report = panda.limits_report(run)
    assert run.success and run.trajectory is not None
    X, (lo, hi) = run.trajectory.x, panda.kinematics.joint_limits.T
    excess = np.maximum(np.maximum(lo - X, X - hi), 0.0)
    i, j = np.unravel_index(int(np.argmax(excess)), excess.shape)
    far = report.farthest
    assert (far.joint, far.value) == (j, X[i, j]) and excess[i, j] > 10
    assert report.ends_outside == bool(np.any((X[-1] < lo) | (X[-1] > hi)))
    assert report.ends_outside
    first = report.violation
    assert (first.name, first.bound) == ("x7 (panda_joint7)", "upper")
    assert first.value == pytest.approx(3.444, abs=1e-3)
    beyond = abs(far.value - far.limit)
    assert report.sentence("J^P#", "Franka Panda").endswith(
        f"farthest on the way to the target: {far.name} = {far.value:.4g}, {beyond:.4g} "
        f"{far.side} limit {far.limit:.4g}; it ends outside them."
    )
    assert report.as_dict()["farthest"]["joint"] == j


CHAIN = {"name": "planar_chain", "joints": "RRR", "lengths": [1, 0.8, 0.6]}


def test_a_report_is_of_one_run_of_this_robot():
    """A batch of solves, a repeatability run of several starts and another robot's run are
    refused (field ``result``), not misread as one run: the second start of a batch that
    begins outside the limits is no violation of the first's run."""
    chain = robot_from_dict({**CHAIN, "limits": [[-1, 1], [None, 1.2], [-2, 2]]})
    inside, outside = [0.3, 1.0, 1.0], [0.3, 1.5, 1.0]
    loop = [(1, 1.3), (1, 1.7), (0.6, 1.7)]
    calls = {
        "a batch of solves": lambda: solve_batch(chain.inverse(), [inside, outside], [0.2, 1.6]),
        "a run of two starts": lambda: repeatability(chain.inverse(), [inside, outside], loop),
        "a run of the other order": lambda: repeatability(chain.inverse(), [outside, inside], loop),
        "a run of another robot": lambda: solve(
            jik.Pseudoinverse(jik.PlanarChain("RRRR", [1] * 4)), [0.1, 0.2, 0.3, 0.4], [1, 1]
        ),
    }
    for what, run in calls.items():
        with pytest.raises(InvalidInputError, match="result is a") as info:
            chain.limits_report(run())
        assert info.value.field == "result", what
    batch = solve_batch(chain.inverse(), [inside, outside], [0.2, 1.6])
    assert chain.limits_report(batch[0]).within
    assert chain.limits_report(batch[1]).violation.where == "at the start x0"


def test_a_one_leg_run_says_on_the_way_to_the_target():
    """A solve is one leg: its violation is "on the way to the target", not "cycle 1, leg 1";
    the start and the legs of a loop keep their words, and as_dict stays the API's."""
    limits = np.array([[-1.0, 1.0], [-1.0, 1.0]])
    x0 = np.zeros(2)
    leg = np.array([[0.0, 0.5], [0.0, 1.5]])
    one = legs_report(limits, x0, [leg], 1, ["x1", "x2"])
    assert (
        str(one)
        == "left the joint limits on the way to the target: x2 = 1.5, above its upper limit 1; "
        "it ends outside them"
    )
    assert one.violation.as_dict()["cycle"] == 1 and "single" not in one.violation.as_dict()
    two = legs_report(limits, x0, [leg[:1], leg], 2, ["x1", "x2"])
    assert str(two).startswith("left the joint limits at cycle 1, leg 2: x2 = 1.5")
    start = legs_report(limits, np.array([2.0, 0.0]), [leg], 1, ["x1", "x2"])
    assert str(start).startswith("left the joint limits at the start x0: x1 = 2")


def test_a_report_says_in_a_sentence_where_its_run_left_the_limits():
    """The verdict's sentence: within all along, else where first (a leg, or the start already
    outside), the joint, its value and the limit it passed, to four digits."""
    legs = [np.array([[0.0, 0, 1]]), np.array([[0.2, 0, 2.123456]])]
    out = legs_report(LIMITS, [0, 0, 1], legs, 2, NAMES).sentence("J^P#", "planar chain")
    assert out == (
        "J^P#: left the joint limits of the planar chain: first at cycle 1, leg 2, joint x3 = "
        "2.123, above its upper limit 2; it ends outside them."
    )
    start = legs_report(LIMITS, [-1.2, 0, 1], [], 1, NAMES).sentence("J^E#", "arm")
    assert start == (
        "J^E#: left the joint limits of the arm: its start x0 is already outside them, joint "
        "x1 = -1.2, below its lower limit -1; it ends outside them."
    )
    within = legs_report(LIMITS, [0, 0, 1], legs[:1], 2, NAMES).sentence("J^P#", "arm")
    assert within == "J^P#: stayed within the joint limits of the arm all along its run."


CHAIN = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}


def test_a_run_not_recorded_says_it_was_checked_at_its_legs_ends():
    """x3 dips to -0.0017 on the way and ends at +0.018 (limits [0, 2.5]): a repeatability run
    without record=True has only its legs' ends to check, and its report says so instead of
    "within the joint limits" all along; recorded, the dip is found."""
    robot = robot_from_dict({**CHAIN, "limits": [[-3, 3], [-3, 3], [0.0, 2.5]]})
    inverse = robot.inverse("pseudoinverse")
    x0, target = [0.88341231, -0.95254394, 0.02701882], [[1.62633533, 1.37832725]]
    ends = robot.limits_report(repeatability(inverse, x0, target, cycles=1))
    assert ends.within and not ends.every_step
    assert str(ends) == (
        "within the joint limits at its start and its legs' ends (the steps between were not "
        "recorded: record=True)"
    )
    assert ends.sentence("J#", "arm").endswith(
        "arm at its start and its legs' ends (the steps between were not recorded: record=True)."
    )
    every = robot.limits_report(repeatability(inverse, x0, target, cycles=1, record=True))
    assert not every.within and every.violation.value < 0
    assert not robot.limits_report(solve(inverse, x0, target[0], record=True)).within
    assert not robot.limits_report(solve(inverse, x0, target[0], record=False)).every_step


def test_a_resumed_run_numbers_its_cycles_from_its_start():
    """A run resumed after 2 cycles to 4 (leg_results: the new legs) reports the violation in
    cycle 3, as the whole run does; the cycles it took over are checked at their legs' ends."""
    from jik.engine.run_settings import Resume

    robot = robot_from_dict({**CHAIN, "limits": [[-3, 3], [-3, 3], [-3, 1.085]]})
    inverse = robot.inverse("pseudoinverse")
    x0, path = [0.3, 1.0, 1.0], [[1.0, 1.3], [1.0, 1.7], [0.6, 1.7]]
    whole = robot.limits_report(repeatability(inverse, x0, path, cycles=4, record=True))
    two = repeatability(inverse, x0, path, cycles=2, record=True)
    resumed = robot.limits_report(repeatability(inverse, Resume.of(two), path, 4, record=True))
    assert (whole.violation.cycle, whole.violation.leg) == (3, 1)
    assert resumed == whole
