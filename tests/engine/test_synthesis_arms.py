"""A repeatable inverse synthesized for a 7-joint arm: the Panda with its pose task (p - r = 1)."""

import numpy as np
import pytest

from jik.engine.arms import ARMS
from jik.engine.exceptions import InvalidInputError
from jik.engine.repeatability import repeatability
from jik.engine.robot_spec import SYNTHESIZED as SYNTH
from jik.engine.robot_spec import robot_from_dict
from jik.engine.synthesis_nd import synthesize_e2_nd

#: A closed pose loop from home: 8 cm squares in x and y with turns about x and y (rad).
STEPS = [(0.08, 0, 0, 0, 0, 0), (0.08, 0.08, 0, 0.1, 0, 0), (0, 0.08, 0.05, 0, 0.1, 0), (0,) * 6]


@pytest.fixture(scope="module")
def panda():
    return robot_from_dict({"name": "panda", "task": "pose"})


def _loop(robot):
    home = np.array(robot.spec.default_x0)
    y0 = robot.kinematics.forward(home)
    return home, [y0 + np.array(step) for step in STEPS]


def test_the_panda_pose_task_has_a_synthesized_map_by_default(panda):
    """Its map is E2-optimal over all seven joints, +-0.3 rad around home."""
    assert panda.kinematics.p - panda.kinematics.r == 1
    assert panda.spec.default_augmentation == "e2_synthesized"
    assert "total-degree" in panda.spec.augmentation("e2_synthesized").description


def test_the_synthesized_inverse_is_repeatable_and_close_to_the_pseudoinverse(panda):
    """Ten cycles of a closed pose loop: the extended inverse returns to x0 (drift < 1e-9) while
    the pseudoinverse drifts; the leg ends of the first cycle stay near the pseudoinverse's."""
    home, path = _loop(panda)
    ext = repeatability(panda.inverse("extended"), home, path, cycles=10)
    pin = repeatability(panda.inverse("pseudoinverse"), home, path, cycles=10)
    assert ext.success and pin.success
    assert np.max(ext.drift) < 1e-9
    assert pin.drift[-1] > 1e-2
    ends = np.linalg.norm(ext.legs[:4] - pin.legs[:4], axis=-1)
    assert np.max(ends) < 0.05  # [rad]: the first cycle's leg ends, joint space


def test_e2_beats_every_single_joint_map(panda):
    """E2 of the synthesized map against h = +-x_j, the usual choice, on the same box."""
    home = np.array(panda.spec.default_x0)
    region = {
        n: (home[i] - 0.3, home[i] + 0.3) for i, n in enumerate(panda.kinematics.variable_names)
    }
    res = synthesize_e2_nd(panda.kinematics, region, degree=3, nodes=2**12)
    assert res.e2 < 0.5 * min(v["e2"] for v in res.single_joint.values())
    assert abs(res.e2_check - res.e2) < 0.01 * res.e2


def test_a_definitions_vector_map_is_synthesized_and_repeatable():
    """p - r = 2 (a planar 4R chain, the end point): an ``e2_synthesized`` map of a definition is
    the vector h = (h_1, h_2) of the total-degree synthesis, built on first use; its extended
    inverse comes back to x0 while the pseudoinverse drifts. A frame that is not p - r joints is
    refused naming the field."""

    box = {"x1": [0.1, 0.5], "x2": [0.4, 0.8], "x3": [0.4, 0.8], "x4": [0.4, 0.8]}
    d = {
        "name": "planar_chain",
        "joints": "RRRR",
        "lengths": [1, 1, 1, 1],
        "x0": [0.3, 0.6, 0.6, 0.6],
        "augmentations": [{"name": "e2_synthesized", "region": box}],
    }
    robot = robot_from_dict(d)
    spec = robot.spec
    drift = {
        a: repeatability(robot.inverse(a), spec.default_x0, spec.default_path, 3).drift[-1]
        for a in ("extended", "pseudoinverse")
    }
    assert drift["extended"] < 1e-12 < 1e-4 < drift["pseudoinverse"]
    bad = {**d, "augmentations": [{"name": "e2_synthesized", "region": box, "frame_axes": [1]}]}
    with pytest.raises(InvalidInputError) as err:
        robot_from_dict(bad)
    assert err.value.field == "augmentations.0.frame_axes"


def test_the_default_frame_of_a_vector_synthesis_is_the_best_conditioned():
    """The Panda with a position task (p - r = 4): the last four joints' frame is degenerate at
    home (the kernel has no component along them), the default frame is not."""
    from jik.engine.kernel_frame import best_frame_axes

    robot = robot_from_dict({"name": "panda", "task": "xyz"})
    kin, x = robot.kinematics, np.array(robot.spec.default_x0)
    box = {n: [v - 0.3, v + 0.3] for n, v in zip(kin.variable_names, x, strict=True)}
    axes = best_frame_axes(kin, box, {})
    J = kin.jacobian(x)
    N = np.eye(7) - np.linalg.pinv(J) @ J

    def least(ax):
        ix = [a - 1 for a in ax]
        return np.linalg.eigvalsh(N[np.ix_(ix, ix)])[0]

    assert least([4, 5, 6, 7]) < 1e-12 < 0.5 < least(axes)


def test_an_arm_gives_its_synthesized_map_by_name_as_its_definition_does():
    """``inverse("extended", "e2_synthesized")`` of the Panda with a position task (p - r = 4,
    no map by default) is the extended inverse of the maps that
    ``{"augmentations": [{"name": "e2_synthesized"}]}`` in its definition gives; a robot
    without a home still needs its region."""
    from jik.engine.extended_vector import VectorExtendedInverse

    by_name = robot_from_dict({"name": "panda", "task": "xyz"}).inverse("extended", SYNTH)
    defined = robot_from_dict(
        {"name": "panda", "task": "xyz", "augmentations": [{"name": SYNTH}]}
    ).inverse("extended", SYNTH)
    assert isinstance(by_name, VectorExtendedInverse)
    x = np.array(ARMS["panda"].home) + 0.1
    np.testing.assert_array_equal(by_name.augmenting_value(x), defined.augmenting_value(x))
    chain = robot_from_dict({"name": "planar_chain", "joints": "RRRR", "lengths": [1] * 4})
    with pytest.raises(InvalidInputError, match="'region'"):
        chain.inverse("extended", SYNTH)


def test_a_synthesis_without_a_degree_takes_the_basis_its_box_and_redundancy_call_for():
    """A tensor basis of degree 12 for one map of two or three variables, eq. (20); a total
    degree of 4 for more variables or p - r > 1; a definition's map says which in its text."""
    from jik.engine.robot_synthesis import default_degree

    assert [default_degree(2, 1), default_degree(3, 1)] == [12, 12]
    assert [default_degree(4, 1), default_degree(2, 2), default_degree(7, 1)] == [4, 4, 4]
    chain = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}
    box = {"x2": [0.4, 2.0], "x3": [0.4, 2.0]}
    robot = robot_from_dict({**chain, "augmentations": [{"name": "e2_synthesized", "region": box}]})
    assert robot.spec.augmentations[0].description.endswith("degree 12")
