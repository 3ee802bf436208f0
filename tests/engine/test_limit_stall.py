"""A run that can no longer reach its target within its budget stalls and says why: the
weighted inverse blocked at a joint limit, named with its value and the limit."""

from __future__ import annotations

import numpy as np
import pytest

import jik.engine as e
from jik.engine.dop853 import _pace_stall
from jik.engine.solve_rules import Status


def _panda_pressed_against_joint_6():
    """A Panda (xyz) start and target from which the weighted inverse drives x6 into its upper
    limit 3.7525 while x1..x3, x5 cannot carry the task on."""
    pytest.importorskip("yourdfpy")
    panda = e.robot_from_dict({"name": "panda", "task": "xyz"})
    x0 = [-0.5078, 0.84032, -0.55408, -0.0898, 0.5216, 3.19756, 2.27926]
    return panda, np.array(x0), panda.kinematics.forward(np.array(x0)) + [-0.1924, 0.145, -0.0541]


def test_the_weighted_inverse_blocked_at_a_joint_limit_stalls_and_names_it():
    """Continuous: its error stays at 0.166 while x6 creeps to the limit with ever shorter
    steps; the run stalls within a tenth or so of its 20,000 steps (its pace fell from one
    window to the next and could not bring the error below tol in the steps left) and names
    the joint, not 'raise max_iterations'. Discrete: a step crosses the limit, and the run
    stops there naming the joint."""
    panda, x0, target = _panda_pressed_against_joint_6()
    res = e.solve(panda.inverse("weighted"), x0, target)
    assert res.status == "stalled" and res.nit < 3000
    assert res.error == pytest.approx(0.1659, abs=1e-3)
    assert res.x[5] == pytest.approx(3.7525, abs=1e-4)
    assert "blocked at a joint limit: joint 6, x6 (panda_joint6) = 3.7524" in res.message
    assert "pressed against its upper limit 3.7525" in res.message
    assert "raise max_iterations" not in res.message
    disc = e.solve(panda.inverse("weighted"), x0, target, mode="discrete", gamma=0.5)
    assert disc.status == "singular" and "joint 6 is at or past its limits" in disc.message


def test_a_pace_stalls_only_if_it_fell_and_cannot_reach_tol_in_the_steps_left():
    """Four runs at the end of a window of 100 steps, 1,000 left, ln(err / tol) = 10: a pace
    of 0.5 that fell from 1 (0.5 * 1000 / 100 = 5 < 10) stalls; one of 2 that fell from 3
    reaches tol (20 >= 10); one of 0.5 that rose from 0.4 may be recovering; a first window
    (no pace before) is only measured."""
    n, tol = 4, 1e-10
    status = np.full(n, Status.RUNNING)
    err = np.full(n, tol * np.exp(10.0))
    pace_err = err * np.exp([0.5, 2.0, 0.5, 0.5])
    pace = np.array([1.0, 3.0, 0.4, np.nan])
    nsteps, cap, window = np.full(n, 1000), np.full(n, 2000), np.full(n, 100)
    pace_step = nsteps.copy()
    _pace_stall(status, np.arange(n), nsteps, cap, window, err, tol, pace_step, pace_err, pace)
    assert list(status) == [Status.STALLED, Status.RUNNING, Status.RUNNING, Status.RUNNING]
    np.testing.assert_allclose(pace, [0.5, 2.0, 0.5, 0.5], rtol=1e-12)
    assert list(pace_step) == [1100] * n


def test_the_weighted_inverse_singular_at_its_limits_where_j_is_regular_says_so():
    """The Panda (pose) where a continuous weighted run around a loop stopped: x1 and x7 within
    2e-7 of their upper limit 2.8973, J regular (sigma_min / sigma_max 0.07) but J W^-1 J^T
    singular. Its error names the joint and the limit, not 'J J^T is singular ... add damping'
    (damping does not apply to the weighted inverse, and J is regular)."""
    pytest.importorskip("yourdfpy")
    panda = e.robot_from_dict({"name": "panda", "task": "pose"})
    x = np.array([2.8973 - 1.2e-7, -0.5741, -1.8763, -2.1827, -0.7175, 2.2345, 2.8973 - 1.6e-7])
    with pytest.raises(e.SingularConfigurationError) as info:
        e.solve(panda.inverse("weighted"), x, panda.kinematics.forward(x) + 0.01)
    message = str(info.value)
    assert not isinstance(info.value, e.KinematicSingularityError)
    assert "J J^T is singular" not in message and "damping" not in message
    assert "J is regular but J W^-1 J^T is singular: joint 1, x1 (panda_joint1)" in message
    assert "1.2e-07 from its upper limit 2.8973" in message
