"""Pose tasks of URDF arms: SO(3) log and its derivative, the task's Jacobian against finite
differences and against Pinocchio's frame Jacobian mapped through the log's derivative."""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from jik.engine import so3
from jik.engine.arms import ARMS
from jik.engine.exceptions import InvalidInputError
from jik.engine.inverses import Pseudoinverse
from jik.engine.pose_task import COORDINATES, parse_task, reference_rotation
from jik.engine.repeatability import repeatability
from jik.engine.urdf import UrdfChain
from tests.engine.test_urdf_field import ROBOTS
from tests.helpers import central_difference

pytest.importorskip("yourdfpy")
RNG = np.random.default_rng(371)
ARM4 = (Path(__file__).resolve().parents[1] / "data" / "arm4.urdf").read_text(encoding="utf-8")
PANDA = ROBOTS / "panda_description" / "urdf" / "panda.urdf" if ROBOTS else None
PANDA_JOINTS = [f"panda_joint{i}" for i in range(1, 8)]


@pytest.mark.parametrize(
    "scale", [1e-7, 1e-3, 0.5, 2.0, 3.0, np.pi - 2e-3, np.pi - 1e-5, np.pi - 1e-8]
)
def test_log_inverts_exp_and_matches_scipy(scale):
    """To rounding up to a half turn: the angle from atan2(sin, cos), not arccos(cos), which
    lost half the digits near pi (errors 6e-10 at pi - 2e-3, 3e-8 at pi - 1e-8)."""
    w = RNG.normal(size=(20, 3))
    w *= scale / np.linalg.norm(w, axis=-1, keepdims=True)
    R = so3.exp(w)
    np.testing.assert_allclose(R, Rotation.from_rotvec(w).as_matrix(), atol=1e-15)
    np.testing.assert_allclose(so3.log(R), w, rtol=0, atol=5e-13 if scale > 3 else 1e-14)
    for Ri in R[:3]:
        phi, L = so3.log_and_jacobian(Ri)
        np.testing.assert_allclose(phi, so3.log(Ri), atol=1e-15)
        np.testing.assert_allclose(L, so3.left_jacobian_inverse(phi), atol=1e-12)


@pytest.mark.parametrize("scale", [1e-6, 0.3, 2.5])
def test_left_jacobian_inverse_is_the_logs_derivative(scale):
    """d/ds log(exp(s w) R) at s = 0 is Jl^-1(log R) w (the base-frame angular velocity w)."""
    phi = RNG.normal(size=3)
    phi *= scale / np.linalg.norm(phi)
    R = so3.exp(phi)
    for w in RNG.normal(size=(5, 3)):
        eps = 1e-6
        fd = (so3.log(so3.exp(eps * w) @ R) - so3.log(so3.exp(-eps * w) @ R)) / (2 * eps)
        np.testing.assert_allclose(so3.left_jacobian_inverse(phi) @ w, fd, atol=1e-8)


@pytest.mark.parametrize(
    ("task", "names"),
    [
        ("pose", COORDINATES),
        ("xyz", ("x", "y", "z")),
        ("zx", ("z", "x")),
        ("xyzrz", ("x", "y", "z", "rz")),
        ("x y rz", ("x", "y", "rz")),
        ("rx, z", ("rx", "z")),
        (["ry", "x"], ("ry", "x")),
    ],
)
def test_task_names(task, names):
    assert parse_task(task) == names


@pytest.mark.parametrize("task", ["", "xw", "xx", "posee", "x rw", "r", ["x", "x"], 3])
def test_bad_tasks_name_the_field(task):
    with pytest.raises(InvalidInputError, match="among x y z rx ry rz") as err:
        parse_task(task)
    assert err.value.field == "task"


@pytest.mark.parametrize(
    ("end", "task"),
    [
        ("tool", "rz ry x"),
        ("tool", "rx ry rz"),
        ("tool", "xz"),
        ("finger", "x rx ry rz"),
        ("finger", "rz y"),
    ],
)
def test_jacobian_matches_finite_differences(end, task):
    """At seeded configurations whose rotation from R0 is below 0.9 pi: away from the rotation
    coordinates' singularity at pi, where central differences lose their accuracy (a turn of
    0.99 pi gave a difference of 2e-7)."""
    kin = UrdfChain(ARM4, end, task=task)
    x = RNG.uniform(-1.5, 1.5, (60, kin.p))
    turn = np.linalg.norm(UrdfChain(ARM4, end, task="rx ry rz").forward(x), axis=-1)
    x = x[turn < 0.9 * np.pi][:25]
    assert len(x) == 25
    J = kin.jacobian(x)
    np.testing.assert_allclose(J, central_difference(kin.forward, x), atol=1e-8)
    k = kin.forward(x)
    for xi, ki, Ji in zip(x[:4], k[:4], J[:4], strict=True):  # one configuration: the scalar path
        np.testing.assert_allclose(kin.jacobian(xi), Ji, atol=1e-14)
        np.testing.assert_allclose(kin.forward(xi), ki, atol=1e-15)


def test_reference_forms_agree_and_home_has_zero_rotation():
    R0 = Rotation.from_rotvec([0.3, -0.2, 0.5])
    forms = [R0.as_rotvec(), R0.as_quat(), R0.as_matrix()]
    kins = [UrdfChain(ARM4, "tool", task="rx ry rz", reference=f) for f in forms]
    x = RNG.uniform(-1, 1, (6, 4))
    for kin in kins[1:]:
        np.testing.assert_allclose(kin.forward(x), kins[0].forward(x), atol=1e-14)
    home = [0.2, 0.4, -0.3, 0.1]
    kin = UrdfChain(ARM4, "tool", task="x rx ry", home=home)
    np.testing.assert_allclose(kin.forward(np.array(home))[1:], 0.0, atol=1e-15)


@pytest.mark.parametrize(
    ("value", "text"),
    [
        ([1, 2], "rotation vector"),
        ([0, 0, 0, 2], "norm 1"),
        (np.diag([1, 1, -1]), "rotation"),
        ([[1, 0, 0], [0, 1, 0], [0, 0, float("nan")]], "rotation vector"),
        ([1e308, 0, 0], "shorter than 1e154 rad"),  # (it was an arm whose task is undefined)
    ],
)
def test_bad_references_name_the_field(value, text):
    with pytest.raises(InvalidInputError, match=text) as err:
        reference_rotation(value)
    assert err.value.field == "reference"


@pytest.mark.skipif(PANDA is None, reason="example-robot-data is not installed")
def test_panda_pose_task_equals_pinocchio_through_jlog3():
    """k = (p, log3(R0^T R)), J = (Jv, Jlog3(R0^T R) J_local,angular): Pinocchio's frame
    Jacobian mapped through the SO(3) log's derivative."""
    pin = pytest.importorskip("pinocchio")
    text = PANDA.read_text(encoding="utf-8")
    kin = UrdfChain(text, "panda_link8", PANDA_JOINTS, task="pose")
    model = pin.buildModelFromXML(text)
    data, frame = model.createData(), model.getFrameId("panda_link8")
    x = RNG.uniform(-1.0, 1.0, (20, 7))
    k, J = kin.forward_jacobian(x)
    for xi, ki, Ji in zip(x, k, J, strict=True):
        q = pin.neutral(model)
        q[:7] = xi
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        M = data.oMf[frame]
        Rrel = kin.reference.T @ M.rotation
        local = pin.getFrameJacobian(model, data, frame, pin.LOCAL)[:, :7]
        world = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)[:, :7]
        np.testing.assert_allclose(ki, np.r_[M.translation, pin.log3(Rrel)], atol=1e-12)
        np.testing.assert_allclose(
            Ji, np.vstack([world[:3], pin.Jlog3(Rrel) @ local[3:]]), atol=1e-12
        )
        np.testing.assert_allclose(kin.jacobian(xi), Ji, atol=1e-12)


def test_a_target_nearly_a_half_turn_from_the_reference_is_reached():
    """The Panda's flange turned by pi - 1e-3 about z from its home: every algorithm converges.
    (At pi itself, the rotation coordinates' cut, a target is refused:
    tests/engine/test_stall.py.) With the log's rounding near pi (1e-8 in k) damped least
    squares had run out of its 20,000 steps at error 1.5e-8."""
    from jik.engine import robot_from_dict, solve

    panda = robot_from_dict({"name": "panda", "task": "pose"})
    home = np.array(panda.spec.default_x0)
    target = panda.kinematics.forward(home) + [0, 0, 0, 0, 0, np.pi - 1e-3]
    for algorithm in ("pseudoinverse", "damped", "weighted", "posture"):
        res = solve(panda.inverse(algorithm), home, target, max_iterations=2000)
        assert res.success, (algorithm, res.message)


@pytest.mark.skipif(PANDA is None, reason="example-robot-data is not installed")
def test_a_pose_loop_of_the_panda_drifts_under_the_pseudoinverse():
    """A closed loop in position and orientation: every leg reaches its pose target; the
    pseudoinverse's elbow does not come back (p - r = 1)."""
    kin = UrdfChain(
        PANDA.read_text(encoding="utf-8"),
        "panda_link8",
        PANDA_JOINTS,
        task="pose",
        home=[0, -0.785, 0, -2.356, 0, 1.571, 0.785],
    )
    x0 = np.array(kin.home)
    y0 = kin.forward(x0)
    np.testing.assert_allclose(y0[3:], 0.0, atol=1e-15)
    moves = np.array(
        [[0.1, 0, 0, 0, 0, 0.3], [0.1, 0.1, 0, 0.2, 0, 0.3], [0, 0.1, -0.05, 0.2, 0, 0]]
    )
    res = repeatability(Pseudoinverse(kin), x0, y0 + moves, cycles=2)
    assert res.success
    assert res.drift[-1] > 1e-4


@pytest.mark.parametrize(
    ("task", "has_t", "has_R"),
    [
        ("pose", True, True),
        ("rz x ry y rx z", True, True),
        ("xyz", True, False),
        ("rx ry rz", False, True),
        ("x z rx", False, False),
    ],
)
def test_pose_of_inverts_the_task_coordinates(task, has_t, has_R):
    """pose_of(k(x)) is the end link's pose at x where the task fixes it, for a batch and for one
    configuration; what the task leaves free is None."""
    panda = ARMS["panda"]
    kin = UrdfChain(panda.urdf, panda.end_link, task=task, reference=[0.3, -0.2, 0.5])
    x = RNG.uniform(-1.0, 1.0, size=(6, kin.p))
    R, t = kin.end_pose(x)
    for batch in (slice(None), 0):
        pos, rot = kin.pose_task.pose_of(kin.forward(x[batch]))
        assert (pos is not None, rot is not None) == (has_t, has_R)
        if has_t:
            np.testing.assert_allclose(pos, t[batch], atol=1e-12)
        if has_R:
            np.testing.assert_allclose(rot, R[batch], atol=1e-9)
