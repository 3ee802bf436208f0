"""The units of a robot's joint variables and task coordinates (jik.engine.units)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import jik.engine as jik
from jik.engine.arms import ARMS
from jik.engine.kinematics import Manipulator1
from jik.engine.units import norm_unit, robot_units

ARM4 = Path(__file__).resolve().parents[1] / "data" / "arm4.urdf"


def test_the_papers_robots_have_the_dashboards_units():
    """Manipulator 1's x3 is dimensionless (it multiplies the length x1, eq. (30)); Manipulator
    2's gantry and task are lengths in the unit of l, its arm angle x3 in rad (37); the
    unicycle's controls (41) are velocities, its pose (40) positions and an angle."""
    m1 = jik.robot_from_dict({"name": "manipulator1"}).units
    assert (m1.x, m1.y) == (("m", "m", "1"), ("m", "m"))
    m2 = jik.robot_from_dict({"name": "manipulator2", "parameters": {"l": 2.0}}).units
    assert (m2.x, m2.y) == (("m", "m", "rad"), ("m", "m"))
    assert "arm length l" in m2.lengths
    assert [c.name for c in m2.variables] == ["x1", "x2", "x3"]
    assert [c.name for c in m2.task] == ["y1", "y2"]
    assert all(c.joint is None and c.limits is None and c.home is None for c in m2.variables)
    unicycle = jik.robot_from_dict({"name": "unicycle"}).units
    assert unicycle.x == ("m/s", "m/s", "rad/s", "rad/s")
    assert unicycle.y == ("m", "m", "rad") and [c.name for c in unicycle.task] == ["q1", "q2", "q3"]


def test_a_planar_chains_prismatic_joint_is_a_length_and_its_end_angle_in_rad():
    robot = jik.robot_from_dict(
        {
            "name": "planar_chain",
            "joints": "RPRR",
            "lengths": [1.0, 0.8, 0.6, 0.4],
            "orientation": True,
            "limits": [[-1, 1], [0, None], [None, None], [-2, 2]],
        }
    )
    units = robot.units
    assert units.x == ("rad", "m", "rad", "rad")
    assert units.y == ("m", "m", "rad") and [c.name for c in units.task] == ["x", "y", "phi"]
    assert [c.limits for c in units.variables] == [(-1, 1), (0, None), (None, None), (-2, 2)]
    assert "link lengths" in units.lengths
    assert units.as_dict()["variables"][1] == {"name": "x2", "unit": "m", "limits": [0.0, None]}


def test_the_pandas_pose_task_is_in_m_and_rad_with_its_joints_limits_and_home():
    """Joint names, kinds and limits as Pinocchio reads the same URDF."""
    pin = pytest.importorskip("pinocchio")
    robot = jik.robot_from_dict({"name": "panda", "task": "pose"})
    units = robot.units
    assert units.x == ("rad",) * 7
    assert units.y == ("m", "m", "m", "rad", "rad", "rad")
    assert [c.name for c in units.task] == ["x", "y", "z", "rx", "ry", "rz"]
    assert units.lengths.startswith("m")
    model = pin.buildModelFromXML(ARMS["panda"].urdf)
    for i, c in enumerate(units.variables):
        assert (c.name, c.joint) == (f"x{i + 1}", f"panda_joint{i + 1}")
        jm = model.joints[model.getJointId(c.joint)]
        assert jm.shortname().startswith("JointModelR")  # revolute: rad
        lo, hi = model.lowerPositionLimit[jm.idx_q], model.upperPositionLimit[jm.idx_q]
        np.testing.assert_allclose(c.limits, (lo, hi), atol=1e-12)
        assert math.isclose(c.home, ARMS["panda"].home[i], abs_tol=1e-15)
    position = jik.robot_from_dict({"name": "panda", "task": "xz rz"}).units
    assert position.y == ("m", "m", "rad")


def test_a_urdf_arms_prismatic_joint_is_in_m_and_a_continuous_one_unbounded():
    robot = jik.robot_from_dict(
        {"name": "urdf", "urdf": ARM4.read_text(encoding="utf-8"), "end_link": "finger"}
    )
    units = robot.units
    assert [c.joint for c in units.variables] == [
        "base_yaw",
        "shoulder",
        "elbow",
        "wrist_pitch",
        "finger_slide",
    ]
    assert units.x == ("rad", "rad", "rad", "rad", "m") and units.y == ("m", "m", "m")
    assert units.variables[3].limits == (None, None)
    assert units.variables[4].limits == (0.0, 0.03)


def test_a_formula_robots_units_are_not_stated():
    """A formula robot's definition gives no units: each is "", and ``lengths`` says why."""
    robot = jik.robot_from_dict(
        {
            "name": "formula",
            "variables": ["a", "b", "c"],
            "task": ["a + l*cos(c)", "b + l*sin(c)"],
            "parameters": {"l": 1.0},
            "limits": [[-1, 1], [-1, 1], [None, 3]],
        }
    )
    units = robot.units
    assert units.x == ("", "", "") and units.y == ("", "")
    assert [c.name for c in units.variables] == ["a", "b", "c"]
    assert [c.name for c in units.task] == ["y1", "y2"]
    assert units.variables[2].limits == (None, 3.0)
    assert "not stated" in units.lengths


def test_robot_units_of_bare_kinematics_name_the_task_itself():
    """Without a spec: a URDF arm's task names are its own, another's y1 .. yr."""
    units = robot_units(jik.Manipulator2())
    assert [c.name for c in units.task] == ["y1", "y2"] and units.y == ("m", "m")
    chain = robot_units(jik.PlanarChain("PRR", [1.0, 1.0, 1.0]))
    assert chain.x == ("m", "rad", "rad") and chain.y == ("m", "m")


def test_a_runs_summary_says_the_units_of_x_and_y():
    summary = jik.robot_from_dict({"name": "manipulator1"}).units.summary()
    assert summary["x"] == ["m", "m", "1"] and summary["y"] == ["m", "m"]
    assert summary["lengths"].startswith("the paper states no unit")


def test_the_columns_name_each_coordinate_as_the_engines_tables_do():
    """x_1..x_p, then y_1..y_r, in order, keyed to the coordinates with their names and units:
    the columns of a trajectory's table (Trajectory.columns) between theta and error."""
    m1 = jik.robot_from_dict({"name": "manipulator1"})
    columns = m1.units.columns()
    assert {k: (c.name, c.unit) for k, c in columns.items()} == {
        "x_1": ("x1", "m"),
        "x_2": ("x2", "m"),
        "x_3": ("x3", "1"),
        "y_1": ("y1", "m"),
        "y_2": ("y2", "m"),
    }
    inverse = m1.inverse("pseudoinverse")
    trajectory = jik.solve(inverse, (0.5, 0.25, 1.0), (0.5, 0.5), record=True).trajectory
    assert list(trajectory.columns())[1:-1] == list(columns)


def test_a_norm_has_one_unit_or_says_which_it_mixes():
    assert norm_unit(("rad", "rad")) == "[rad]"
    assert norm_unit(("m", "m", "1")) == "[m and dimensionless mixed]"
    assert norm_unit(("", "")) == ""


def test_a_trajectory_s_columns_have_their_units_spelled_out():
    """Manipulator 1: theta, x_1..x_3 (m, m, dimensionless), y_1, y_2 in m, the error a norm
    of y in m, h in the map's unit; in discrete mode theta counts iterations."""
    units = robot_units(Manipulator1())
    said = units.trajectory_units("continuous")
    assert list(said) == ["theta", "x_1", "x_2", "x_3", "y_1", "y_2", "error", "h"]
    assert said["x_3"] == "dimensionless" and said["y_1"] == "m" and said["error"] == "m"
    assert said["theta"] == "dimensionless"
    assert units.trajectory_units("discrete")["theta"] == "iterations"


def test_robot_units_print_on_one_short_line_with_every_coordinate_and_unit():
    """A notebook cell showing a Panda's units printed 1,200 characters of Coordinate(...) fields;
    the repr is one line with each coordinate and its unit, a joint's name, and which limits
    and home it has."""
    panda = robot_units(jik.robot_from_dict({"name": "panda", "task": "pose"}).kinematics)
    text = repr(panda)
    assert "\n" not in text and len(text) < 400, text
    assert text.startswith("RobotUnits(x=(x1 [rad] panda_joint1, x2 [rad] panda_joint2,")
    assert "y=(x [m], y [m], z [m], rx [rad], ry [rad], rz [rad])" in text
    assert text.endswith("limits=True, home=True)")
    m2 = repr(robot_units(jik.Manipulator2()))
    assert (
        m2
        == "RobotUnits(x=(x1 [m], x2 [m], x3 [rad]), y=(y1 [m], y2 [m]), limits=False, home=False)"
    )
