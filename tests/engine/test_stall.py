"""Why a continuous run stalled, said by the engine's own message (jik.engine.stall)."""

import numpy as np
import pytest

import jik.engine as e
from jik.engine.stall import reach, reach_note, stall_reason

ARM = e.PlanarChain("RRR", [1.0, 0.8, 0.6])
X0 = np.array([0.3, 0.4, 0.5])


def test_a_target_beyond_the_reach_of_a_planar_chain_is_named_with_its_distance():
    """Reach 1 + 0.8 + 0.6 = 2.4: a target at distance 5 stalls, and the message says why."""
    result = e.solve(e.Pseudoinverse(ARM), X0, [5.0, 0.0])
    assert not result.success
    assert result.message.startswith("stalled after ")
    assert (
        "the target is out of reach: it is 5 from the base, beyond the arm's reach 2.4"
        in result.message
    )
    assert "the target is unreachable" not in result.message


def test_the_inner_reach_of_a_chain_with_one_long_link():
    """Links 3, 1, 1: nothing closer to the base than 3 - 2 = 1 is reached."""
    inner, outer = reach(e.PlanarChain("RRR", [3.0, 1.0, 1.0]))
    assert (inner, outer) == pytest.approx((1.0, 5.0), abs=1e-15)
    message = stall_reason(e.Pseudoinverse(e.PlanarChain("RRR", [3.0, 1.0, 1.0])), [0.5, 0], X0)
    assert message.startswith("the target is out of reach: it is 0.5 from the base, inside")


def test_the_extended_jacobian_stalling_within_reach_is_an_algorithmic_singularity():
    """h = x3 from X0 toward (0.05, 0): J stays regular, [J; dh] (10) becomes singular."""
    inverse = e.ExtendedInverse(ARM, e.FormulaMap("x3", ["x1", "x2", "x3"]))
    result = e.solve(inverse, X0, [0.05, 0.0])
    assert not result.success
    assert "the target is within reach (0.05 from the base, reach 2.4)" in result.message
    assert "J is regular there" in result.message
    assert "an algorithmic singularity" in result.message


def test_a_stretched_chain_is_a_kinematic_singularity():
    """At x = 0 the chain is stretched along its first axis: J has rank 1."""
    message = stall_reason(e.Pseudoinverse(ARM), [2.0, 1.0], np.zeros(3))
    assert "the run stalled at a kinematic singularity: J loses rank there" in message


def test_a_regular_stop_of_the_pseudoinverse_is_its_steps_collapsing():
    """J regular and the pseudoinverse well defined: the error still falls there (eq. (5)), so
    the stall is the integrator's, not a local minimum of the task error."""
    message = stall_reason(e.Pseudoinverse(ARM), [1.0, 1.0], X0)
    assert message.startswith("the target is within reach")
    assert "the integrator's steps collapsed" in message and "local minimum" not in message


def test_other_robots_are_judged_by_their_jacobians_only():
    """Manipulator 2 has no closed-form reach: no distance is claimed."""
    assert reach(e.Manipulator2()) is None
    message = stall_reason(e.Pseudoinverse(e.Manipulator2()), [1.0, 1.0], [0.1, 0.2, 0.3])
    assert "reach" not in message and "the integrator's steps collapsed" in message


def test_a_discrete_run_out_of_reach_says_so_not_raise_gamma():
    """Discrete mode toward a target beyond the reach runs out of iterations: the message says
    why (the target's distance and the reach), not "raise max_iterations or gamma"."""
    result = e.solve(e.Pseudoinverse(ARM), X0, [3.0, 1.0], mode="discrete", max_iterations=50)
    assert not result.success and "did not converge within 50 iterations" in result.message
    assert "the target is out of reach: it is 3.16 from the base" in result.message
    assert "gamma" not in result.message


def test_out_of_iterations_advice_follows_the_mode_and_gamma():
    """Discrete: near a solution the error shrinks by |1 - gamma| per iteration (eq. (5)), so
    gamma nearer 1 helps and a larger gamma (refused at 2) does not; at gamma = 1 only more
    iterations. Continuous: gamma only rescales theta, so it is never the advice."""
    inverse = e.Pseudoinverse(e.Manipulator2())
    x0, target = [0.0, 0.0, 1.5707963267948966], [1.0, 1.0]
    slow = e.solve(inverse, x0, target, mode="discrete", gamma=1.99, max_iterations=5)
    assert slow.message.endswith("; raise max_iterations, or take gamma nearer 1"), slow.message
    plain = e.solve(inverse, x0, target, mode="discrete", gamma=1.0, max_iterations=1)
    assert plain.message.endswith("; raise max_iterations"), plain.message
    continuous = e.solve(inverse, x0, target, max_iterations=2)
    assert continuous.message.endswith("; raise max_iterations"), continuous.message


def test_a_chain_with_an_orientation_task_claims_no_reach():
    """Links 1, 1, 1 with the end's angle as a task (r = 3): (2.9, 0) at angle pi puts the
    wrist at (3.9, 0), beyond the first two links; the end point's annulus says nothing."""
    chain = e.PlanarChain("RRR", [1.0, 1.0, 1.0], orientation=True)
    assert reach(chain) is None
    message = stall_reason(e.Pseudoinverse(chain), [2.9, 0.0, np.pi], [0.3, 0.2, 0.1])
    assert "within reach" not in message and "out of reach" not in message


def test_a_rotation_vector_longer_than_a_half_turn_is_refused():
    """A pose task's rotation coordinates are the principal log (|r| <= pi): a target, or a
    path point, whose rotation vector is longer is never reached, so it is refused before a run
    (field y_d or path), with the same orientation within a half turn; one within it runs."""
    pytest.importorskip("yourdfpy")
    panda = e.robot_from_dict({"name": "panda", "task": "pose"})
    home = np.array(panda.spec.default_x0)
    target = panda.kinematics.forward(home) + [0, 0, 0, 3.0, 0, 1.0]  # |r| = sqrt(10)
    with pytest.raises(e.InvalidInputError) as err:
        e.solve(panda.inverse(), home, target, mode="discrete", gamma=0.5, max_iterations=50)
    assert err.value.field == "y_d"
    assert str(err.value) == (
        "target y_d is out of reach: its rotation coordinates (rx, ry, rz) have length 3.16228 "
        "> pi, and the rotation coordinates (the principal log of R0^T R) never exceed pi; "
        "the same orientation is (-2.96075, 0, -0.986918)"
    )
    with pytest.raises(e.InvalidInputError, match=r"^path\[1\] is out of reach") as err:
        e.repeatability(panda.inverse(), home, [target - [0, 0, 0, 0.1, 0, 0.1], target])
    assert err.value.field == "path.1"
    turns = panda.kinematics.forward(home) + [0, 0, 0, 0, 0, 10.0]  # (1.59 turns about z)
    with pytest.raises(e.InvalidInputError, match=r"the same orientation is \(0, 0, -2\.56637\)$"):
        panda.kinematics.check_target(turns, "target")
    ok = e.solve(panda.inverse(), home, target - [0, 0, 0, 0.1, 0, 0.1], max_iterations=50)
    assert np.linalg.norm(ok.y_d[3:]) < np.pi
    assert reach_note(panda.kinematics, target) == (None, "")


@pytest.mark.parametrize("rz", [np.pi, -np.pi, -3.1415926536, -np.pi - 1e-10])
def test_a_target_on_the_rotation_coordinates_cut_is_refused(rz):
    """At a half turn from R0 the rotation coordinates jump to the opposite vector: a discrete
    run toward such a target 'converged' with joints turned by hundreds of radians, a
    continuous one crossed the cut with a turn of the wrist. Refused, naming the reference."""
    pytest.importorskip("yourdfpy")
    panda = e.robot_from_dict({"name": "panda", "task": "pose"})
    home = np.array(panda.spec.default_x0)
    target = np.r_[panda.kinematics.forward(home)[:5], rz]
    with pytest.raises(e.InvalidInputError, match="a half turn from the reference") as err:
        e.solve(panda.inverse(), home, target, mode="discrete", gamma=0.5, max_iterations=50)
    assert err.value.field == "y_d" and "`reference`" in str(err.value)


def test_a_start_on_the_rotation_coordinates_cut_is_refused():
    """R0 = the base frame puts the Panda's home (flange down) a half turn away: a start there
    is refused, and the same start with the default R0 (its home's orientation) runs."""
    pytest.importorskip("yourdfpy")
    base = e.robot_from_dict({"name": "panda", "task": "pose", "reference": [0, 0, 0]})
    home = np.array(base.spec.default_x0)
    target = base.kinematics.forward(home) + [0.05, 0, 0, 0, 0, 0]
    with pytest.raises(e.InvalidInputError, match=r"^x0 puts the end link a half turn") as err:
        e.solve(base.inverse(), home, target, mode="discrete", gamma=0.5)
    assert err.value.field == "x0"
    with pytest.raises(e.InvalidInputError, match=r"^x0\[1\] puts the end link"):
        e.solve_batch(base.inverse(), [home + 0.5, home], target)
    panda = e.robot_from_dict({"name": "panda", "task": "pose"})
    moved = panda.kinematics.forward(home) + [0.05, 0, 0, 0, 0, 0]
    assert e.solve(panda.inverse(), home, moved, mode="discrete", gamma=0.5).status == "converged"


def test_a_subset_of_the_rotation_coordinates_longer_than_pi_is_refused():
    """Any subset of the rotation coordinates is no longer than the whole rotation vector, so
    rz alone beyond pi is refused too; the message then gives no 'same orientation' (the
    coordinates left free decide it). A planar chain's targets have no such rule."""
    pytest.importorskip("yourdfpy")
    arm = e.robot_from_dict({"name": "panda", "task": "x y z rz"})
    with pytest.raises(e.InvalidInputError) as err:
        arm.kinematics.check_target([0.3, 0, 0.5, -3.5], "target")
    assert str(err.value).endswith("never exceed pi") and err.value.field == "target"
    arm.kinematics.check_target([0.3, 0, 0.5, -3.14], "target")
    with pytest.raises(e.InvalidInputError, match="a half turn from the reference"):
        arm.kinematics.check_target([0.3, 0, 0.5, -np.pi], "target")
    e.PlanarChain("RRR", [1, 1, 1]).check_target([0, 9], "target")


def test_damped_least_squares_stops_once_its_error_settles_at_the_nearest_point():
    """Damped least squares toward a target out of reach settles at the point of the reach
    nearest it (task error 5 - 2.4 = 2.6), where its flow is stiff and its steps short: the run
    stops when neither its error nor x moves any more (dop853.PLATEAU_DECREASE and PLATEAU_MOVE
    over PLATEAU_TAU), in 718 steps rather than the 1,743 that the bound on tau alone allowed,
    stretched toward the target to 1e-12."""
    result = e.solve(e.DampedInverse(ARM, damping=0.1), X0, [5.0, 0.0])
    assert result.status == "stalled"
    assert result.error == pytest.approx(2.6, abs=1e-12)
    assert result.nit < 1000
    np.testing.assert_allclose(result.x, 0.0, atol=1e-12)
    assert "beyond the arm's reach 2.4" in result.message


@pytest.mark.parametrize("method", ["auto", "dop853"])
@pytest.mark.parametrize(
    ("task", "x0", "target"),
    [(["x1**16", "x3"], [1.1, 0, 0], [1000, 0]), (["tan(x1)", "x3"], [0, 0, 0], [900, 0])],
    ids=["x1^16", "tan"],
)
def test_a_task_of_large_jacobian_converges_and_is_not_called_singular(method, task, x0, target):
    """J = diag-like with ||J|| up to 8e5 and full rank: the task error falls along (7) as
    exp(-theta) (eq. (5)), so DOP853 refuses a step that raises it; a step whose error in x
    was within tolerance had thrown the error from 3e-10 back to 1e-8 near the end, and the
    run stopped there as stalled "at a kinematic singularity"."""
    robot = e.robot_from_dict({"name": "formula", "variables": ["x1", "x2", "x3"], "task": task})
    res = e.solve(e.Pseudoinverse(robot.kinematics), x0, target, method=method)
    assert res.success and res.error < 1e-10, res.message


def test_a_leg_the_long_way_round_the_rotation_coordinates_is_a_note():
    """rz -3.1 then +3.1: orientations 0.083 rad apart that the coordinates join by 6.2 rad;
    the run's findings say so, naming the leg and `reference`; a path that stays clear of the
    cut gets no such note."""
    pytest.importorskip("yourdfpy")
    panda = e.robot_from_dict({"name": "panda", "task": "pose"})
    x0 = np.array(panda.spec.default_x0)
    x0[6] -= 2.9
    y0 = panda.kinematics.forward(x0)
    run = e.repeatability(panda.inverse(), x0, [np.r_[y0[:5], -3.1], np.r_[y0[:5], 3.1]])
    notes = [f.text for f in run.findings() if f.role == "note"]
    assert notes[0].startswith("Leg 2 moves the rotation coordinates by 6.2 rad between ")
    assert "0.0832 rad apart" in notes[0] and "`reference`" in notes[0]
    home = np.array(panda.spec.default_x0)
    calm = e.repeatability(panda.inverse(), home, panda.spec.default_loop())
    assert not [f for f in calm.findings() if f.text.startswith("Leg ")]


@pytest.mark.parametrize("task", ["pose", "xyz", "x z"])
def test_an_arm_target_beyond_the_sum_of_its_links_is_out_of_reach(task):
    """The Panda's end lies within 0.986 m of its first joint (0.333 m above the base): the sum
    of its links' lengths, joint to joint and to the flange. A target 2 m away in x is out of
    reach for any orientation: a discrete run out of iterations says so, not "raise
    max_iterations, or take gamma nearer 1", and so does a stall; a target within that distance
    claims nothing (the sum bounds the reach, it does not give it)."""
    pytest.importorskip("yourdfpy")
    panda = e.robot_from_dict({"name": "panda", "task": task})
    home = np.array(panda.spec.default_x0)
    y = panda.kinematics.forward(home)
    far = y + np.eye(len(y))[0] * 2.0  # (x is the first coordinate of each task)
    inverse = panda.inverse("pseudoinverse")
    res = e.solve(inverse, home, far, mode="discrete", gamma=0.5, max_iterations=50)
    assert not res.success and "the target is out of reach" in res.message, res.message
    assert "beyond the arm's reach 0.986 (the sum of its links' lengths)" in res.message
    assert "gamma" not in res.message and "raise max_iterations" not in res.message
    assert "the target is out of reach" in stall_reason(inverse, far, home)
    assert reach_note(panda.kinematics, y) == (None, "")
