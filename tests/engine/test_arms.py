"""The catalogue arms: their URDFs against Pinocchio (pose and Jacobian to 1e-12), against the
makers' DH tables written out independently here, and the Panda against example-robot-data's."""

import math

import numpy as np
import pytest

from jik.engine.arms import ARMS
from jik.engine.robot_spec import robot_from_dict
from jik.engine.urdf import UrdfChain
from tests.engine.test_urdf_field import ROBOTS

pytest.importorskip("yourdfpy")
RNG = np.random.default_rng(372)
PI = math.pi


def _random_in_limits(kin, n):
    lo, hi = np.array(kin.limits).T
    return RNG.uniform(lo, hi, (n, kin.p))


def _standard_dh(rows, q):
    """prod_i Rz(q_i + offset_i) Tz(d_i) Tx(a_i) Rx(alpha_i), rows (d, a, alpha, offset)."""
    T = np.eye(4)
    for (d, a, alpha, offset), qi in zip(rows, q, strict=True):
        ct, st = math.cos(qi + offset), math.sin(qi + offset)
        ca, sa = math.cos(alpha), math.sin(alpha)
        T = T @ np.array(
            [
                [ct, -st * ca, st * sa, a * ct],
                [st, ct * ca, -ct * sa, a * st],
                [0, sa, ca, d],
                [0, 0, 0, 1],
            ]
        )
    return T


def _modified_dh(rows, q):
    """prod_i Rx(alpha_i) Tx(a_i) Rz(q_i) Tz(d_i) (Craig), rows (a, d, alpha); a last row
    without a joint (the flange) when rows is one longer than q."""
    T = np.eye(4)
    for i, (a, d, alpha) in enumerate(rows):
        qi = q[i] if i < len(q) else 0.0
        ct, st = math.cos(qi), math.sin(qi)
        ca, sa = math.cos(alpha), math.sin(alpha)
        T = T @ np.array(
            [
                [ct, -st, 0, a],
                [st * ca, ct * ca, -sa, -d * sa],
                [st * sa, ct * sa, ca, d * ca],
                [0, 0, 0, 1],
            ]
        )
    return T


#: The makers' tables (see each URDF's comment for the source).
PANDA_DH = [
    (0, 0.333, 0),
    (0, 0, -PI / 2),
    (0, 0.316, PI / 2),
    (0.0825, 0, PI / 2),
    (-0.0825, 0.384, -PI / 2),
    (0, 0, PI / 2),
    (0.088, 0, PI / 2),
    (0, 0.107, 0),
]
IIWA_DH = [
    (0.36, 0, -PI / 2, 0),
    (0, 0, PI / 2, 0),
    (0.42, 0, PI / 2, 0),
    (0, 0, -PI / 2, 0),
    (0.4, 0, -PI / 2, 0),
    (0, 0, PI / 2, 0),
    (0.126, 0, 0, 0),
]
UR5E_DH = [
    (0.1625, 0, PI / 2, 0),
    (0, -0.425, 0, 0),
    (0, -0.3922, 0, 0),
    (0.1333, 0, PI / 2, 0),
    (0.0997, 0, -PI / 2, 0),
    (0.0996, 0, 0, 0),
]
GEN3_DH = [
    (-(0.1564 + 0.1284), 0, PI / 2, 0),
    (-(0.0054 + 0.0064), 0, PI / 2, PI),
    (-(0.2104 + 0.2104), 0, PI / 2, PI),
    (-(0.0064 + 0.0064), 0, PI / 2, PI),
    (-(0.2084 + 0.1059), 0, PI / 2, PI),
    (0, 0, PI / 2, PI),
    (-(0.1059 + 0.0615), 0, PI, PI),
]  # after the base's Rx(pi)


def _kin(name, task="pose"):
    return robot_from_dict(
        {"name": name, "task": task if name != "ur5e" else "xyz rx ry"}
    ).kinematics


@pytest.mark.parametrize(
    ("name", "table", "atol"),
    [
        ("panda", None, 1e-15),
        ("iiwa14", IIWA_DH, 1e-15),
        ("ur5e", UR5E_DH, 1e-15),
        ("gen3", GEN3_DH, 1e-3),
    ],
)
def test_each_arm_equals_its_makers_dh_table(name, table, atol):
    """Gen3: the guide's table rounds the kortex frames to 0.1 mm."""
    kin = _kin(name)
    for x in _random_in_limits(kin, 10):
        R, t = kin.end_pose(x)
        if name == "panda":
            T = _modified_dh(PANDA_DH, x)
        elif name == "gen3":
            T = np.diag([1.0, -1.0, -1.0, 1.0]) @ _standard_dh(table, x)
        else:
            T = _standard_dh(table, x)
        np.testing.assert_allclose(t, T[:3, 3], atol=atol)
        np.testing.assert_allclose(R, T[:3, :3], atol=atol)


@pytest.mark.parametrize("name", sorted(ARMS))
def test_each_arm_equals_pinocchio_to_1e_12(name):
    """Pose coordinates and Jacobian at random configurations within the limits, from the
    batched call and from the one-configuration path."""
    pin = pytest.importorskip("pinocchio")
    a = ARMS[name]
    kin = _kin(name)
    model = pin.buildModelFromXML(a.urdf)
    data, frame = model.createData(), model.getFrameId(a.end_link)
    assert model.nv == kin.p
    x = _random_in_limits(kin, 30)
    k, J = kin.forward_jacobian(x)
    for xi, ki, Ji in zip(x, k, J, strict=True):
        q = pin.neutral(model)
        for name_j, value in zip(kin.joint_names, xi, strict=True):
            jm = model.joints[model.getJointId(name_j)]
            if jm.nq == 2:  # a continuous joint: (cos, sin)
                q[jm.idx_q : jm.idx_q + 2] = math.cos(value), math.sin(value)
            else:
                q[jm.idx_q] = value
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        M = data.oMf[frame]
        Rrel = kin.reference.T @ M.rotation
        world = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
        local = pin.getFrameJacobian(model, data, frame, pin.LOCAL)
        full_k = np.r_[M.translation, pin.log3(Rrel)]
        full_J = np.vstack([world[:3], pin.Jlog3(Rrel) @ local[3:]])
        rows = [("x", "y", "z", "rx", "ry", "rz").index(n) for n in kin.task_names]
        np.testing.assert_allclose(ki, full_k[rows], atol=1e-12)
        np.testing.assert_allclose(Ji, full_J[rows], atol=1e-12)
        k1, J1 = kin.forward_jacobian(xi)
        np.testing.assert_allclose(k1, full_k[rows], atol=1e-12)
        np.testing.assert_allclose(J1, full_J[rows], atol=1e-12)


@pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
def test_the_panda_equals_example_robot_datas():
    theirs = UrdfChain(
        (ROBOTS / "panda_description/urdf/panda.urdf").read_text(),
        "panda_link8",
        [f"panda_joint{i}" for i in range(1, 8)],
        "pose",
    )
    ours = _kin("panda")
    x = _random_in_limits(ours, 20)
    for a, b in zip(ours.end_pose(x), theirs.end_pose(x), strict=True):
        np.testing.assert_allclose(a, b, atol=1e-15)


@pytest.mark.parametrize("name", sorted(ARMS))
def test_home_is_within_the_limits_regular_and_has_zero_rotation(name):
    kin = _kin(name)
    home = np.array(ARMS[name].home)
    lo, hi = np.array(kin.limits).T
    assert np.all((lo <= home) & (home <= hi))
    assert kin.manipulability(home) > 0.01
    np.testing.assert_allclose(kin.forward(home)[3:], 0.0, atol=1e-15)


def test_known_home_positions():
    """Franka's 'ready' flange at (0.307, 0, 0.590); Kinova's Home tool at (0.457, 0.001,
    0.434), as their documentation gives them."""
    np.testing.assert_allclose(
        _kin("panda", "xyz").forward(ARMS["panda"].home), [0.3069, 0.0, 0.5903], atol=1e-4
    )
    np.testing.assert_allclose(
        _kin("gen3", "xyz").forward(ARMS["gen3"].home), [0.457, 0.001, 0.434], atol=1e-3
    )


def test_the_ur5e_has_no_redundancy_for_a_full_pose():
    from jik.engine.exceptions import InvalidInputError

    with pytest.raises(InvalidInputError, match="6 active joints for a task of 6 coordinates") as e:
        robot_from_dict({"name": "ur5e", "task": "pose"})
    assert e.value.field == "task"  # (the active joints are the chain's: the task is too long)
    few = {"name": "panda", "task": "pose", "active_joints": ["panda_joint1", "panda_joint2"]}
    with pytest.raises(InvalidInputError, match="2 active joints for a task of 6") as e:
        robot_from_dict(few)
    assert e.value.field == "active_joints"


def test_an_arm_equals_its_urdf_definition():
    a = ARMS["panda"]
    by_name = robot_from_dict({"name": "panda", "task": "pose"})
    by_text = robot_from_dict(
        {
            "name": "urdf",
            "urdf": a.urdf,
            "end_link": a.end_link,
            "home": list(a.home),
            "task": "pose",
        }
    )
    x = _random_in_limits(by_name.kinematics, 5)
    np.testing.assert_array_equal(by_name.kinematics.forward(x), by_text.kinematics.forward(x))
    assert by_name.spec.default_x0 == by_text.spec.default_x0 == a.home
    assert by_name.spec.default_path == by_text.spec.default_path


# (the UR5e's six joints are not redundant for a pose: its build refuses that task)
@pytest.mark.parametrize(
    ("name", "task"),
    [(n, t) for n in sorted(ARMS) for t in (None, "xyz", "pose") if (n, t) != ("ur5e", "pose")],
)
def test_the_default_path_is_a_loop_the_pseudoinverse_drifts_on(name, task):
    """The default closed path goes around: its corners differ and the pseudoinverse does not
    come back to x0 (a path made by the last joint alone, which turns the flange about its
    axis, would move no position: a task without rz would stand still)."""
    from jik.engine.registry import make_inverse
    from jik.engine.repeatability import repeatability

    robot = robot_from_dict({"name": name, **({"task": task} if task else {})})
    spec = robot.spec
    corners = np.array([spec.default_path[0], *spec.default_path])
    corners[0] = robot.kinematics.forward(np.array(spec.default_x0))
    gaps = np.linalg.norm(np.diff(corners, axis=0, append=corners[:1]), axis=1)
    assert gaps.min() > 1e-3
    inverse = make_inverse(robot.kinematics, "pseudoinverse")
    run = repeatability(inverse, spec.default_x0, spec.default_path, 1, mode="continuous")
    assert run.drift[-1] > 1e-6


@pytest.mark.parametrize(
    ("home1", "box1"),
    [
        (0.0, [-0.3, 0.3]),  # (+-ARM_BOX around home)
        (2.8, [2.5, 2.8973]),  # (cut at the limit 2.8973)
        (2.9, [2.6, 2.8973]),  # (home beyond the limit by less than ARM_BOX / 2)
        (10.0, [2.7473, 2.8973]),  # (far beyond: ARM_BOX / 2 inside the limit)
        (-10.0, [-2.8973, -2.7473]),
    ],
)
def test_an_arm_s_synthesis_box_lies_within_its_limits_wherever_its_home(home1, box1):
    """An arm's default map is synthesized on +-ARM_BOX around its home within the joint
    limits; a home beyond a limit (accepted) keeps ARM_BOX / 2 inside it: a home 10 rad past
    the Panda's first limit was refused as an empty region of its map ('augmentation.region')."""
    from jik.engine.robot_synthesis import arm_augmentations

    home = [home1, 0, 0, -1, 0, 1, 0]
    kin = robot_from_dict(
        {"name": "panda", "home": home, "augmentations": [{"name": "formula", "h": "x1"}]}
    ).kinematics
    (item,) = arm_augmentations(kin, {"home": home})
    np.testing.assert_allclose(item["region"]["x1"], box1, atol=1e-12)
    assert item["region"]["x2"] == pytest.approx([-0.3, 0.3])
    assert robot_from_dict({"name": "panda", "home": home}).kinematics.home[0] == home1
