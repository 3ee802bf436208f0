"""Why a continuous run stalled, said by the engine's own message (jik.engine.stall)."""

import numpy as np
import pytest

import jik.engine as e
from jik.engine.stall import reach, stall_reason

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


def test_a_regular_stop_of_the_pseudoinverse_is_a_local_minimum():
    """J regular and the pseudoinverse well defined: nothing singular explains the stall."""
    message = stall_reason(e.Pseudoinverse(ARM), [1.0, 1.0], X0)
    assert message.startswith("the target is within reach")
    assert "local minimum" in message


def test_other_robots_are_judged_by_their_jacobians_only():
    """Manipulator 2 has no closed-form reach: no distance is claimed."""
    assert reach(e.Manipulator2()) is None
    message = stall_reason(e.Pseudoinverse(e.Manipulator2()), [1.0, 1.0], [0.1, 0.2, 0.3])
    assert "reach" not in message and "local minimum" in message
