"""The variables a default augmenting map keeps (robot_defaults.kept_variables): the last p - r,
unless the columns J leaves to the others are singular at the start."""

from __future__ import annotations

import numpy as np

from jik.engine.planar_chain import PlanarChain
from jik.engine.robot_defaults import kept_variables
from jik.engine.robot_spec import robot_from_dict


def test_a_regular_chain_keeps_its_last_variables():
    """A three-link chain in a generic pose: h = x3, the last variable (p - r = 1)."""
    kin = PlanarChain("RRR", [1.0, 0.8, 0.6])
    assert kept_variables(kin, [0.3, 0.7, -0.4]) == [2]


def test_a_pandas_position_task_at_home_keeps_joints_that_leave_a_regular_jacobian():
    """The Panda's xyz task at home: joints 1 and 3 move the point alike, so J's columns of
    joints 1-3 are singular and the last four cannot be h; the ones kept leave three columns
    of J whose smallest singular value is not round-off, and [J; dh] (10) is regular."""
    robot = robot_from_dict({"name": "panda", "task": "xyz"})
    kin, x0 = robot.kinematics, np.asarray(robot.spec.default_x0)
    kept = kept_variables(kin, x0)
    assert len(kept) == kin.p - kin.r and kept != [3, 4, 5, 6]
    J = kin.jacobian(x0)
    free = [i for i in range(kin.p) if i not in kept]
    assert np.linalg.svd(J[:, free], compute_uv=False)[-1] > 1e-3
    dh = np.eye(kin.p)[kept]  # (p - r, p): h = (x_i for i kept)
    assert abs(np.linalg.det(np.vstack([J, dh]))) > 1e-6
