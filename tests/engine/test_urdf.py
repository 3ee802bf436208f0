"""URDF arms: forward kinematics against yourdfpy's, the analytic Jacobian, solve, repeatability."""

from pathlib import Path

import numpy as np
import pytest

from jik.engine.exceptions import InvalidInputError
from jik.engine.formula_kinematics import FormulaMap
from jik.engine.inverses import ExtendedInverse, Pseudoinverse
from jik.engine.repeatability import repeatability
from jik.engine.solver import solve
from jik.engine.urdf import MAX_URDF_BYTES, UrdfChain
from tests.helpers import central_difference

yourdfpy = pytest.importorskip("yourdfpy")

ARM4 = Path(__file__).resolve().parents[1] / "data" / "arm4.urdf"
TEXT = ARM4.read_text(encoding="utf-8")
RNG = np.random.default_rng(4)
X0 = np.array([0.3, 0.5, 0.8, 0.6])


@pytest.fixture(scope="module")
def arm():
    return UrdfChain(TEXT, "tool")


@pytest.fixture(scope="module")
def reference():
    return yourdfpy.URDF.load(str(ARM4), load_meshes=False)


def _yourdfpy_position(model, cfg: dict, link: str) -> np.ndarray:
    model.update_cfg(cfg)
    return model.get_transform(link, "base_link")[:3, 3]


def test_the_chain_is_read_from_the_urdf(arm):
    assert arm.joint_names == ("base_yaw", "shoulder", "elbow", "wrist_pitch")
    assert (arm.p, arm.r, arm.base_link) == (4, 3, "base_link")
    assert arm.limits[:3] == ((-3.0, 3.0), (-2.0, 2.0), (-2.5, 2.5))
    assert arm.limits[3] == pytest.approx((-np.pi, np.pi))  # continuous


def test_forward_kinematics_matches_yourdfpy(arm, reference):
    x = RNG.uniform(-2, 2, (10, 4))
    ours = arm.forward(x)
    for xi, yi in zip(x, ours, strict=True):
        theirs = _yourdfpy_position(reference, dict(zip(arm.joint_names, xi, strict=True)), "tool")
        np.testing.assert_allclose(yi, theirs, atol=1e-12)


def test_locked_joints_and_a_task_subset_match_yourdfpy(reference):
    kin = UrdfChain(TEXT, "tool", ["shoulder", "elbow", "wrist_pitch"], "xz", {"base_yaw": 0.3})
    assert (kin.p, kin.r) == (3, 2)
    x = RNG.uniform(-2, 2, (5, 3))
    for xi, yi in zip(x, kin.forward(x), strict=True):
        cfg = {"base_yaw": 0.3, **dict(zip(kin.joint_names, xi, strict=True))}
        np.testing.assert_allclose(
            yi, _yourdfpy_position(reference, cfg, "tool")[[0, 2]], atol=1e-12
        )


@pytest.mark.parametrize(
    ("end", "active", "task"),
    [
        ("tool", None, "xyz"),
        ("tool", ["wrist_pitch", "shoulder", "elbow"], "yz"),
        ("finger", None, "xyz"),
        ("finger", ["finger_slide", "elbow", "shoulder"], "zx"),
    ],
)
def test_jacobian_matches_finite_differences(end, active, task):
    kin = UrdfChain(TEXT, end, active, task)
    x = RNG.uniform(-2, 2, (30, kin.p))
    np.testing.assert_allclose(kin.jacobian(x), central_difference(kin.forward, x), atol=1e-8)
    assert kin.jacobian(x[0]).shape == (kin.r, kin.p)


def test_points_run_from_the_base_to_the_end(arm):
    pts = arm.points(RNG.uniform(-1, 1, (6, 4)))
    assert pts.shape == (6, 6, 3)  # 5 joints on the chain (one fixed) and the end point
    np.testing.assert_allclose(pts[:, 0], [[0, 0, 0.05]] * 6)


def test_solve_reaches_a_position(arm):
    target = arm.forward(X0) + np.array([0.05, -0.08, 0.04])
    res = solve(Pseudoinverse(arm), X0, target)
    assert res.success
    np.testing.assert_allclose(arm.forward(res.x), target, atol=1e-9)


def test_repeatability_pseudoinverse_drifts_extended_returns(arm):
    """A closed path around k(x0): the pseudoinverse drifts; h = x4 - x3 (the wrist's pitch
    against the elbow's) makes it repeatable: h is conserved along eq. (7), eq. (12). (h = x4
    alone meets an algorithmic singularity on this path: the arm stretches.)"""
    home = arm.forward(X0)
    path = home + np.array([[0.1, 0, 0], [0.1, 0.1, 0.05], [0, 0.1, 0.05]])
    pinv = repeatability(Pseudoinverse(arm), X0, path, cycles=3)
    ext = repeatability(
        ExtendedInverse(arm, FormulaMap("x4 - x3", arm.variable_names)), X0, path, cycles=3
    )
    assert pinv.success and ext.success
    assert pinv.drift[-1] > 1e-4
    assert np.max(ext.drift) < 1e-9


#: A second joint onto the tool: the tool link then has two parents.
SECOND_PARENT = (
    '<joint name="tool_too" type="fixed"><parent link="forearm"/><child link="tool"/></joint>'
)


@pytest.mark.parametrize(
    ("urdf", "text"),
    [
        (
            TEXT.replace("<robot name", "<robt name").replace("</robot>", "</robt>"),
            "urdf: the root element is <robt>, not <robot>",
        ),
        (
            TEXT.replace('<joint name="elbow"', '<joint name="shoulder"'),
            "two joints are named 'shoulder'",
        ),
        (
            TEXT.replace('<link name="finger">', '<link name="wrist">'),
            "two links are named 'wrist'",
        ),
        (
            TEXT.replace("</robot>", SECOND_PARENT + "</robot>"),
            "link 'tool' is the child of two joints, 'tool_mount' and 'tool_too'",
        ),
        (
            TEXT.replace('<child link="forearm"/>', ""),
            "joint 'elbow' has no <child link=\"...\"/>",
        ),
        (
            TEXT.replace('xyz="0 0 0.2" rpy="0 0 0"', 'xyz="0 0" rpy="0 0 0"'),
            "joint 'shoulder' has origin xyz='0 0', not 3 numbers",
        ),
        (
            TEXT.replace('xyz="0 0 0.2" rpy="0 0 0"', 'xyz="0 0 0.2 1" rpy="0 0 0"'),
            "joint 'shoulder' has origin xyz='0 0 0.2 1', not 3 numbers",
        ),
        (
            TEXT.replace('xyz="0 0 0.2" rpy="0 0 0"', 'xyz="0 0 0.2" rpy="0 0"'),
            "joint 'shoulder' has origin rpy='0 0', not 3 numbers",
        ),
        (
            TEXT.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 1 x"/>'),
            "joint 'shoulder' has axis xyz='0 1 x', not 3 numbers",
        ),
        (
            TEXT.replace('lower="', 'lower="zz', 1),
            "joint 'base_yaw' has limit lower='zz-3.0', not a number",
        ),
    ],
)
def test_a_urdf_that_is_not_a_tree_of_unique_names_is_refused_naming_what(urdf, text):
    """What yourdfpy reads without a word (a fourth origin number, a second parent, a second
    joint of one name: the chain then takes one of them) or with a message about its own code
    (a joint without its child) is refused, saying what is wrong."""
    with pytest.raises(InvalidInputError) as err:
        UrdfChain(urdf, "tool")
    assert err.value.field == "urdf"
    assert text in str(err.value)


@pytest.mark.parametrize(
    ("kwargs", "field", "text"),
    [
        ({"end_link": "hand"}, "end_link", "'hand' is not a link"),
        ({"end_link": None}, "end_link", "is required (the name of the end link); links: ['base"),
        (
            {"end_link": "tool", "active_joints": ["shoulder", "finger_slide"]},
            "active_joints.1",
            "not a movable joint on the chain",
        ),
        (
            {"end_link": "tool", "active_joints": ["shoulder", "shoulder", "elbow"]},
            "active_joints",
            "repeats",
        ),
        ({"end_link": "tool", "task": "xw"}, "task", "coordinates among x y z rx ry rz"),
        (
            {"end_link": "tool", "active_joints": ["shoulder", "elbow"], "task": "xz"},
            "active_joints",
            "more joints than task coordinates",
        ),
        ({"end_link": "tool", "locked": {"nope": 1.0}}, "locked.nope", "not a joint"),
        ({"end_link": "tool", "urdf": "<robot"}, "urdf", "not a valid URDF"),
        ({"end_link": "tool", "urdf": 3}, "urdf", "text of a URDF"),
        (
            {"end_link": "tool", "urdf": "<robot>" + " " * MAX_URDF_BYTES + "</robot>"},
            "urdf",
            "too large",
        ),
        (
            {
                "end_link": "tool",
                "urdf": '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>' + TEXT,
            },
            "urdf",
            "DOCTYPE",
        ),
        (
            {
                "end_link": "tool",
                "urdf": TEXT.replace(
                    '<limit lower="-2.0" upper="2.0"', '<limit lower="2.0" upper="-2.0"'
                ),
            },
            "urdf",
            "joint 'shoulder' has its lower limit 2 above its upper limit -2",
        ),
        (
            {
                "end_link": "tool",
                "urdf": TEXT.replace('<limit lower="-2.0"', '<limit lower="nan"'),
            },
            "urdf",
            "joint 'shoulder' has a NaN limit",
        ),
        (
            {"end_link": "tool", "urdf": TEXT.replace('xyz="0 0 0.2" rpy', 'xyz="0 inf 0.2" rpy')},
            "urdf",
            "joint 'shoulder' has a NaN or infinite origin",
        ),
        (
            {"end_link": "tool", "urdf": TEXT.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 1"/>')},
            "urdf",
            "joint 'shoulder' has axis xyz='0 1', not 3 numbers",
        ),
        (
            {
                "end_link": "tool",
                "urdf": TEXT.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 1 0 0"/>'),
            },
            "urdf",
            "joint 'shoulder' has axis xyz='0 1 0 0', not 3 numbers",
        ),
        (
            {"end_link": "tool", "urdf": TEXT.replace('<robot name="arm4">', "<robot>")},
            "urdf",
            "an element lacks its 'name' attribute",
        ),
    ],
)
@pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")  # (yourdfpy's NaN)
def test_bad_definitions_name_the_field(kwargs, field, text):
    with pytest.raises(InvalidInputError) as err:
        UrdfChain(**{"urdf": TEXT, **kwargs})
    assert err.value.field == field
    assert text in str(err.value)


def test_a_bad_urdf_is_reported_once_and_not_logged_as_an_error(caplog, capfd):
    """The refusal names the field; yourdfpy's own ERROR lines ("Using different parsing
    approach.") no longer reach a server's log for each bad URDF a user sends."""
    from jik.engine.urdf import parse_urdf

    with pytest.raises(InvalidInputError, match="urdf: not a valid URDF"):
        parse_urdf("0")
    assert not [r for r in caplog.records if r.name.startswith("yourdfpy")]
    assert "parsing approach" not in capfd.readouterr().err


def test_the_drawn_arm_starts_at_its_base_and_places_each_joint(arm):
    """arm4's first joint stands 0.05 m above its base frame's origin: the drawn polyline starts
    at the origin (that offset is a link), then the joint origins and the end; each joint
    variable's point is its joint's origin. An arm whose first joint is at the origin and a
    planar chain are drawn from their first joint."""
    from jik.engine.planar_chain import PlanarChain

    x = RNG.uniform(-1.0, 1.0, (5, 4))
    drawn, (origins, _, _) = arm.drawn_points(x), arm.frames(x)
    assert arm.base_offset and drawn.shape == (5, len(arm.chain) + 2, 3)
    np.testing.assert_allclose(drawn[:, 0], 0.0, atol=1e-15)
    np.testing.assert_allclose(drawn[:, 1:], arm.points(x), atol=1e-15)
    for index, point in arm.joint_points.items():
        k = next(k for k, j in enumerate(arm.chain) if j.index == index)
        np.testing.assert_allclose(drawn[:, point], origins[:, k], atol=1e-15)
    assert sorted(arm.joint_points) == [0, 1, 2, 3]
    at_origin = UrdfChain(TEXT.replace('<origin xyz="0 0 0.05"/>', "<origin/>", 1), "tool")
    assert not at_origin.base_offset and at_origin.joint_points[0] == 0
    np.testing.assert_allclose(at_origin.drawn_points(x), at_origin.points(x), atol=0)
    planar = PlanarChain("RRR", [1.0, 0.8, 0.6])
    np.testing.assert_allclose(planar.drawn_points(x[:, :3]), planar.points(x[:, :3]), atol=0)
    assert planar.joint_points == {0: 0, 1: 1, 2: 2}


def test_the_default_start_is_inside_every_joints_range():
    """Without x0 or home, a URDF arm starts at 0.5 in each joint's range that holds it and in
    the middle of the others: not on a limit, which the default path's first leg would leave."""
    from jik.engine.robot_spec import robot_from_dict

    text = TEXT.replace('<limit lower="-2.0" upper="2.0"', '<limit lower="-2.0" upper="0.0"')
    robot = robot_from_dict({"name": "urdf", "urdf": text, "end_link": "tool"})
    assert robot.spec.default_x0 == (0.5, -1.0, 0.5, 0.5)
    run = repeatability(
        robot.inverse("pseudoinverse"), robot.spec.default_x0, robot.spec.default_path
    )
    report = robot.limits_report(run)
    assert run.success and report is not None and report.within, report


def test_limits_declared_infinite_give_a_finite_range():
    """A joint whose URDF limits are -inf and inf (as exporters write "no limits") ranges over a
    turn like a continuous one, and one infinite side lies a turn from the other: the range
    (sliders, default start, an atlas's box) stays finite; the limits checked stay as declared."""
    from jik.engine.robot_spec import robot_from_dict

    text = TEXT.replace('<limit lower="-2.0" upper="2.0"', '<limit lower="-inf" upper="inf"')
    text = text.replace('<limit lower="-2.5" upper="2.5"', '<limit lower="-inf" upper="1.0"')
    robot = robot_from_dict({"name": "urdf", "urdf": text, "end_link": "tool"})
    pi = np.pi
    np.testing.assert_allclose(
        robot.spec.x_range, [(-3, 3), (-pi, pi), (1 - 2 * pi, 1), (-pi, pi)], rtol=0, atol=0
    )
    assert np.all(np.isfinite(robot.spec.default_x0))
    np.testing.assert_array_equal(robot.kinematics.joint_limits[1:3, 0], [-np.inf, -np.inf])
    assert list(robot.kinematics.joint_limits[1:3, 1]) == [np.inf, 1.0]


def _long_chain(n: int) -> str:
    joints = "".join(
        f'<link name="l{i}"/><joint name="j{i}" type="revolute"><parent link="l{i - 1}"/>'
        f'<child link="l{i}"/><origin xyz="0 0 0.01"/><axis xyz="0 {i % 2} {1 - i % 2}"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for i in range(1, n + 1)
    )
    return f'<robot name="snake"><link name="l0"/>{joints}</robot>'


def test_a_chain_of_more_joints_than_a_robot_may_have_is_refused_at_once():
    """A 3000-joint chain (a 640 kB URDF) is refused before anything is built for it (the
    dashboard's validation of a state holding it grew past 24 GB); 4 of its joints may be active."""
    urdf = _long_chain(3000)
    with pytest.raises(InvalidInputError, match="3000 of the 3000 movable joints") as info:
        UrdfChain(urdf, "l3000")
    assert info.value.field == "active_joints"
    assert UrdfChain(urdf, "l3000", active_joints=["j1", "j2", "j3", "j4"]).p == 4


def test_too_many_active_joints_named_are_counted_as_named():
    """17 joints named in active_joints of a 20-joint chain were answered "the chain has 17
    movable joints ... (list them in active_joints)": both the counts are now right."""
    names = [f"j{i}" for i in range(1, 18)]
    with pytest.raises(InvalidInputError) as info:
        UrdfChain(_long_chain(20), "l20", active_joints=names)
    assert info.value.field == "active_joints"
    assert "17 of the 20 movable joints on the chain from 'l0' to 'l20'" in str(info.value)


_FLOATING = """<robot name="humanoid"><link name="world"/><link name="torso"/>
<joint name="root" type="floating"><parent link="world"/><child link="torso"/></joint>
<link name="l1"/><link name="l2"/><link name="l3"/><link name="hand"/>
<joint name="j1" type="revolute"><parent link="torso"/><child link="l1"/>
<origin xyz="0 0.2 0.3"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/>
</joint>
<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
<origin xyz="0.3 0 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/>
</joint>
<joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
<origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/>
</joint>
<joint name="j4" type="fixed"><parent link="l3"/><child link="hand"/><origin xyz="0.1 0 0"/></joint>
</robot>"""


def test_base_link_starts_the_chain_past_a_floating_joint():
    """A humanoid's arm below its floating root: refused from the root, naming base_link; from
    base_link "torso" its positions are in the torso's frame, as of the URDF rooted there."""
    with pytest.raises(InvalidInputError, match="joint 'root' on the chain is floating") as info:
        UrdfChain(_FLOATING, "hand", task="xy")
    assert "base_link 'torso'" in str(info.value)
    arm = UrdfChain(_FLOATING, "hand", task="xy", base_link="torso")
    assert arm.joint_names == ("j1", "j2", "j3") and arm.base_link == "torso"
    rooted = _FLOATING.replace('<link name="world"/>', "").split("</joint>", 1)[1]
    alone = UrdfChain('<robot name="arm"><link name="torso"/>' + rooted, "hand", task="xy")
    x = np.array([[0.3, -0.4, 0.5], [1.0, 0.2, -0.7]])
    np.testing.assert_allclose(arm.forward(x), alone.forward(x), rtol=0, atol=1e-15)
    np.testing.assert_allclose(arm.jacobian(x), central_difference(arm.forward, x), atol=1e-8)
    head = _FLOATING.replace(
        "</robot>",
        '<link name="head"/><joint name="neck" type="fixed"><parent link="torso"/>'
        '<child link="head"/></joint></robot>',
    )
    for base, said in (("l9", "is not a link of the URDF"), ("head", "is not on the chain")):
        with pytest.raises(InvalidInputError, match=said) as info:
            UrdfChain(head, "hand", task="xy", base_link=base)
        assert info.value.field == "base_link"
