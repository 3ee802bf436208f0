"""Robots defined by data: each kind from a dict or a file, their augmentations, their errors."""

import importlib.util
import json
import pickle
import shutil
from pathlib import Path

import numpy as np
import pytest

from jik.engine.exceptions import FormulaError, InvalidInputError
from jik.engine.extended_vector import VectorExtendedInverse
from jik.engine.formula_kinematics import FormulaKinematics
from jik.engine.kinematics import Manipulator2
from jik.engine.planar_chain import PlanarChain
from jik.engine.registry import ROBOTS
from jik.engine.repeatability import repeatability
from jik.engine.robot_spec import load_robot, robot_from_dict
from jik.engine.solver import solve

ARM4 = Path(__file__).resolve().parents[1] / "data" / "arm4.urdf"
#: A home of the iiwa14 other than its catalogue's (within its joint limits).
HOME_IIWA = [0.1, 0.5, 0.0, -1.5, 0.0, 1.0, 0.2]
ARM3R = {
    "name": "planar_chain",
    "joints": "RRR",
    "lengths": [1.0, 0.8, 0.6],
    "x0": [0.3, 1.0, 1.0],
    "path": [[1.0, 1.3], [1.0, 1.7], [0.6, 1.7]],
    "augmentations": [
        {"name": "e2_synthesized", "region": {"x2": [0.4, 2.0], "x3": [0.4, 2.0]}, "degree": 8},
        {"name": "formula", "h": "x3"},
    ],
}
M2_FORMULA = {
    "name": "formula",
    "variables": ["x1", "x2", "x3"],
    "task": ["x2 + l*cos(x3)", "x1 + l*sin(x3)"],
    "parameters": {"l": 1.0},
    "augmentations": [{"name": "formula", "label": "cubic_like", "h": "x3 - x2*x3/4"}],
}


def _run(robot, algorithm, augmentation=None, cycles=3):
    spec = robot.spec
    inverse = robot.inverse(algorithm, augmentation)
    return repeatability(inverse, spec.default_x0, spec.default_path, cycles=cycles)


def test_planar_chain_robot_runs_both_inverses():
    robot = robot_from_dict(ARM3R)
    assert isinstance(robot.kinematics, PlanarChain)
    spec = robot.spec
    assert (spec.p, spec.r, spec.task_names) == (3, 2, ("x", "y"))
    assert [a.name for a in spec.augmentations] == ["e2_synthesized", "formula"]
    assert spec.default_augmentation == "e2_synthesized"
    assert spec.functional_region == {"x2": (0.4, 2.0), "x3": (0.4, 2.0)}
    assert spec.as_dict()["default_x0"] == [0.3, 1.0, 1.0]
    assert _run(robot, "pseudoinverse").drift[-1] > 1e-3
    for name in ("e2_synthesized", "formula"):
        rep = _run(robot, "extended", name)
        assert rep.success and np.max(rep.drift) < 1e-9


def test_formula_robot_is_manipulator2():
    robot = robot_from_dict(M2_FORMULA)
    assert isinstance(robot.kinematics, FormulaKinematics)
    x = np.random.default_rng(1).uniform(-2, 2, (20, 3))
    np.testing.assert_allclose(robot.kinematics.forward(x), Manipulator2().forward(x), atol=1e-15)
    assert robot.spec.task_names == ("y1", "y2")
    rep = _run(robot, "extended", "cubic_like")
    assert rep.success and np.max(rep.drift) < 1e-9


def test_urdf_robot_from_a_file_next_to_its_urdf(tmp_path):
    pytest.importorskip("yourdfpy")
    shutil.copy(ARM4, tmp_path / "arm4.urdf")
    (tmp_path / "arm.json").write_text(
        json.dumps(
            {
                "name": "urdf",
                "urdf_file": "arm4.urdf",
                "end_link": "tool",
                "x0": [0.3, 0.5, 0.8, 0.6],
                "augmentations": [{"name": "formula", "h": "x4 - x3"}],
            }
        )
    )
    robot = load_robot(tmp_path / "arm.json")
    assert (robot.spec.p, robot.spec.r, robot.spec.task_names) == (4, 3, ("x", "y", "z"))
    assert robot.spec.x_range[0] == (-3.0, 3.0)  # the URDF's limits
    res = solve(robot.inverse(), robot.spec.default_x0, robot.spec.default_target)
    assert res.success
    rep = _run(robot, "extended")
    assert rep.success and np.max(rep.drift) < 1e-9


def test_urdf_text_in_the_definition():
    pytest.importorskip("yourdfpy")
    robot = robot_from_dict(
        {
            "name": "urdf",
            "urdf": ARM4.read_text(),
            "end_link": "tool",
            "active_joints": ["shoulder", "elbow", "wrist_pitch"],
            "task": "xz",
            "x0": [0.5, 0.8, 0.6],
        }
    )
    assert (robot.spec.p, robot.spec.r) == (3, 2)
    assert _run(robot, "pseudoinverse", cycles=1).success


def test_urdf_file_must_stay_in_the_robot_files_folder(tmp_path):
    pytest.importorskip("yourdfpy")
    (tmp_path / "sub").mkdir()
    shutil.copy(ARM4, tmp_path / "arm4.urdf")
    (tmp_path / "sub" / "arm.json").write_text(
        json.dumps({"name": "urdf", "urdf_file": "../arm4.urdf", "end_link": "tool"})
    )
    with pytest.raises(InvalidInputError, match="not a file inside") as err:
        load_robot(tmp_path / "sub" / "arm.json")
    assert err.value.field == "urdf_file"
    with pytest.raises(
        InvalidInputError,
        match="which robot_from_dict takes as base_dir",
    ):
        robot_from_dict({"name": "urdf", "urdf_file": "arm4.urdf", "end_link": "tool"})


def test_yaml_robot_file(tmp_path):
    yaml = pytest.importorskip("yaml")
    (tmp_path / "arm.yaml").write_text(yaml.safe_dump(ARM3R))
    robot = load_robot(tmp_path / "arm.yaml")
    assert robot.kinematics.parameters["lengths"] == [1.0, 0.8, 0.6]


def test_builtin_robots_by_name_with_parameters_and_extra_maps():
    assert set(ROBOTS) == {"manipulator1", "manipulator2", "unicycle"}  # the catalogue stays
    robot = robot_from_dict(
        {
            "name": "manipulator2",
            "parameters": {"l": 1.5},
            "augmentations": [{"name": "formula", "h": "x3"}],
        }
    )
    assert robot.kinematics.parameters == {"l": 1.5}
    assert [a.name for a in robot.spec.augmentations][-1] == "formula"
    assert [a.name for a in ROBOTS["manipulator2"].augmentations] == [
        "paper_cubic",
        "e2_synthesized",
    ]
    assert robot.inverse("extended", "paper_cubic").augmenting_map.name == "paper_cubic"
    assert load_robot("manipulator1").spec is ROBOTS["manipulator1"]


def test_a_builtin_robots_defaults_given_in_its_definition_are_used_and_checked():
    """x0, target, path, x_range and title of a built-in robot's definition replace the
    built-in's (what `jik repeatability --robot file` runs without --x0 or --path); a bad one
    is refused naming its field, not silently dropped; what is not given stays the built-in's."""
    mine = {"x0": [0.1, 0.0, 1.5], "path": [[1, 1], [1, 1.5]], "title": "M2", "target": [1, 1]}
    spec = robot_from_dict({"name": "manipulator2", **mine}).spec
    assert (spec.default_x0, spec.default_path) == ((0.1, 0.0, 1.5), ((1.0, 1.0), (1.0, 1.5)))
    assert (spec.title, spec.default_target) == ("M2", (1.0, 1.0))
    assert spec.x_range == ROBOTS["manipulator2"].x_range
    unicycle = robot_from_dict({"name": "unicycle", "x_range": [[-1, 1]] * 4}).spec
    assert unicycle.x_range == ((-1.0, 1.0),) * 4
    assert unicycle.default_x0 == ROBOTS["unicycle"].default_x0
    assert unicycle.default_path == ROBOTS["unicycle"].default_path
    for key, value in {"x0": [0, 0], "path": [[1, 1, 1]], "target": "abc", "title": 3}.items():
        with pytest.raises(InvalidInputError) as err:
            robot_from_dict({"name": "manipulator2", key: value})
        assert err.value.field == key


def test_a_task_undefined_at_the_box_centre_starts_where_it_is_defined():
    """log(a - 1) is undefined at a = 0.5: the default start is the first point of a Halton
    sequence over x_range where the task and its default path are (it was refused, asking for
    an x0 the REST API's robot has no place for); a given x0 there is still refused."""
    d = {"name": "formula", "variables": ["a", "b"], "task": ["log(a - 1)"]}
    spec = robot_from_dict(d).spec
    assert spec.default_x0[0] > 1 and np.isfinite(spec.default_path).all()
    assert spec.default_x0 == robot_from_dict(d).spec.default_x0  # (deterministic)
    with pytest.raises(InvalidInputError, match=r"undefined at x0 = \(0, 0\) \(k1 = nan\): "):
        robot_from_dict({**d, "x0": [0, 0]})


def test_a_chain_without_redundancy_runs_but_its_extended_inverse_says_why_not():
    """p = r (a 2R chain in the plane): the pseudoinverse is J^-1 and runs; the extended inverse
    has no room for a map, and says so instead of asking for 'p - r = 0' maps."""
    robot = robot_from_dict({"name": "planar_chain", "joints": "RR", "lengths": [1, 1]})
    x0 = np.array([0.3, 0.5])
    assert solve(robot.inverse("pseudoinverse"), x0, robot.kinematics.forward(x0 + 0.1)).success
    with pytest.raises(
        InvalidInputError,
        match=r"needs redundancy \(p > r\), and this "
        r"planar_chain has p = r = 2",
    ) as err:
        robot.inverse("extended")
    assert err.value.field == "augmentation" and "0 augmenting maps" not in str(err.value)
    with pytest.raises(InvalidInputError, match=r"one degree of redundancy \(p = r \+ 1\); planar"):
        robot.kinematics.kernel(x0)  # (K(x), of E1 and E2, has no meaning here either)


@pytest.mark.parametrize(
    "augmentation",
    [
        {"name": "formula", "h": "x1"},
        {"name": "formula", "h": []},
        {"name": "e2_synthesized", "region": {"x1": [0, 1], "x2": [0, 1]}},
    ],
)
def test_a_chain_without_redundancy_refuses_an_augmenting_map(augmentation):
    """p = r: a map of the definition is refused as Robot.inverse('extended') is, not taken as
    'a list of 0 formulas' (h = [] built an 'extended' inverse that was J^-1 under its name)."""
    chain = {"name": "planar_chain", "joints": "RR", "lengths": [1, 1]}
    with pytest.raises(InvalidInputError, match=r"needs redundancy \(p > r\).*p = r = 2") as err:
        robot_from_dict({**chain, "augmentations": [augmentation]})
    assert err.value.field == "augmentations.0"


def test_more_than_one_degree_of_redundancy_takes_a_vector_of_formula_maps():
    chain = {
        "name": "planar_chain",
        "joints": "RRRRR",
        "lengths": [0.6, 0.5, 0.4, 0.3, 0.2],
        "x0": [0.2, 0.5, 0.6, 0.4, 0.3],
    }
    robot = robot_from_dict(chain)
    assert _run(robot, "pseudoinverse", cycles=2).success
    with pytest.raises(InvalidInputError, match=r"needs p - r = 3 augmenting maps: give") as err:
        robot.inverse("extended")
    assert err.value.field == "augmentation"
    vector = {"name": "formula", "h": ["x3 - x2", "x4 - x3", "x5 - x4"]}
    robot = robot_from_dict({**chain, "augmentations": [vector]})
    assert isinstance(robot.inverse("extended"), VectorExtendedInverse)
    rep = _run(robot, "extended")
    assert rep.success and np.max(rep.drift) < 1e-9
    with pytest.raises(InvalidInputError, match="vector of maps"):
        robot.spec.augmentation("formula").build(robot.kinematics)
    cases = [
        (
            {
                "name": "e2_synthesized",
                "region": {"x2": [0, 1], "x3": [0, 1], "x4": [0, 1]},
                "frame_axes": [1, 1, 2],
            },
            "augmentations.0.frame_axes",
            "3 distinct joints",
        ),
        ({"name": "formula", "h": "x5"}, "augmentations.0.h", "a list of 3 formulas"),
        ({"name": "formula", "h": ["x5", "x4"]}, "augmentations.0.h", "a list of 3 formulas"),
        ({"name": "formula", "h": ["x5", "x4", "x9"]}, "augmentations.0.h.2", "unknown name"),
    ]
    for aug, field, text in cases:
        with pytest.raises(InvalidInputError) as err:
            robot_from_dict({**chain, "augmentations": [aug]})
        assert err.value.field == field
        assert text in str(err.value)


@pytest.mark.parametrize(
    ("definition", "field", "text"),
    [
        ({"name": "scara"}, "name", "name must be one of"),
        ({"joints": "RR"}, "name", "name must be one of"),
        ({**ARM3R, "lenghts": [1, 1, 1]}, "lenghts", "unknown key 'lenghts'"),
        ({"name": "planar_chain", "lengths": [1, 1]}, "joints", "joints is required"),
        ({**ARM3R, "lengths": [1, 1]}, "lengths", "one entry per joint"),
        ({**ARM3R, "x_range": [[0, 1]]}, "x_range", "3 pairs"),
        ({**ARM3R, "x0": [0, 1]}, "x0", "shape (..., 3)"),
        (
            {**ARM3R, "augmentations": [{"name": "formula", "h": "x3 + y"}]},
            "augmentations.0.h",
            "unknown name 'y'",
        ),
        (
            {**ARM3R, "augmentations": [{"name": "formula", "h": "x3", "hh": 1}]},
            "augmentations.0",
            "unknown key(s) ['hh']",
        ),
        (
            {**ARM3R, "augmentations": [{"name": "e2_synthesized", "region": {"x9": [0, 1]}}]},
            "augmentations.0.region.x9",
            "unknown joint variable 'x9'",
        ),
        (
            {**ARM3R, "augmentations": [{"name": "formula", "h": "x3"}] * 2},
            "augmentations.1.label",
            "must be a new name",
        ),
        ({**ARM3R, "augmentations": [{"name": "cubic"}]}, "augmentations.0", "must be"),
        ({**M2_FORMULA, "task": ["x2 +* x3"]}, "task.0", "expected a number"),
        (
            {"name": "manipulator2", "parameters": {"l": 99}},
            "parameters.l",
            "l must be in [0.1, 5]",
        ),
    ],
)
def test_bad_definitions_name_the_field(definition, field, text):
    with pytest.raises(InvalidInputError) as err:
        robot_from_dict(definition)
    assert err.value.field == field
    assert text in str(err.value)


def test_formula_errors_carry_their_position():
    with pytest.raises(FormulaError) as err:
        robot_from_dict({**M2_FORMULA, "task": ["x2 + l*cos(x3)", "x1 + l*sin(x3))"]})
    assert (err.value.field, err.value.position) == ("task.1", 14)


def test_bad_files(tmp_path):
    with pytest.raises(InvalidInputError, match="neither a file nor a built-in robot"):
        load_robot(tmp_path / "missing.json")
    (tmp_path / "bad.json").write_text("{")
    with pytest.raises(InvalidInputError, match="not valid JSON"):
        load_robot(tmp_path / "bad.json")


GOOD = {
    "planar_chain": {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]},
    "formula": {k: v for k, v in M2_FORMULA.items() if k != "augmentations"},
    "manipulator2": {"name": "manipulator2"},
}
if importlib.util.find_spec("yourdfpy"):
    GOOD["urdf"] = {"name": "urdf", "urdf": ARM4.read_text(), "end_link": "tool"}
#: The keys each kind reads, and one key of another kind (unknown to it).
KEYS = {
    "planar_chain": ["joints", "lengths", "offsets", "orientation", "variables"],
    "formula": ["variables", "task", "parameters", "lengths"],
    "manipulator2": ["parameters", "joints"],
    "urdf": ["urdf", "end_link", "active_joints", "task", "locked", "urdf_file"],
}
COMMON = ["x_range", "x0", "target", "path", "title", "name", "augmentations"]
HOSTILE = [
    None,
    True,
    0,
    7,
    -1.5,
    float("nan"),
    float("inf"),
    "",
    "x",
    "R" * 300,
    [],
    [1],
    ["a", "b"],
    [None],
    [[1, 2], [3]],
    {},
    {"a": 1},
    {"x1": [0, 1]},
    [{}],
    [{"name": "formula"}],
    [{"name": "e2_synthesized", "region": {"x2": [0, 1], "x3": [0, 1]}, "degree": "a"}],
    [{"name": "formula", "h": ["x1"]}],
    10**400,
    [10**400, 1.0, 1.0],
    {"l": 10**400},
    {"base_yaw": 10**400},
]


@pytest.mark.parametrize("kind", sorted(GOOD))
def test_hostile_values_in_any_entry_fail_only_with_invalid_input(kind):
    """Each entry of a valid definition replaced by each of many wrong values: a robot, or an
    InvalidInputError naming a field, never another exception."""
    crashes = []
    for key in KEYS[kind] + COMMON:
        for value in HOSTILE:
            try:
                robot_from_dict({**GOOD[kind], key: value})
            except InvalidInputError as exc:
                assert exc.field is None or isinstance(exc.field, str)
            except Exception as exc:  # collected, to report every crash at once
                crashes.append(f"{key}={value!r:.40}: {type(exc).__name__}: {exc}")
    assert crashes == []


@pytest.mark.parametrize(
    "definition",
    [
        {"name": "manipulator2", "parameters": {"l": 1.5}},
        {"name": "unicycle"},
        {"name": "planar_chain", "joints": "RRR", "lengths": [1, 0.8, 0.6]},
        {"name": "panda", "task": "xyz"},
    ],
    ids=lambda d: d["name"],
)
def test_a_robot_pickles_as_its_definition_and_runs_the_same(definition):
    """A notebook sends a robot to multiprocessing or joblib workers, or saves it: it pickles,
    and the copy is the same robot (name, defaults, maps) with bit-identical runs."""
    robot = robot_from_dict(definition)
    copy = pickle.loads(pickle.dumps(robot))
    assert repr(copy) == repr(robot) and copy.kinematics.name == robot.kinematics.name
    spec = robot.spec
    path = spec.default_path if spec.default_path_loops else spec.default_path[:1]
    runs = [
        repeatability(r.inverse("pseudoinverse"), spec.default_x0, path, 1, mode=spec.default_mode)
        for r in (robot, copy)
    ]
    assert np.array_equal(runs[0].legs, runs[1].legs)


def test_a_robot_whose_urdf_came_from_a_file_pickles_with_its_text(tmp_path):
    """``urdf_file`` is relative to the robot file's folder, unknown where the copy is built:
    the pickle carries the URDF's text."""
    (tmp_path / "arm.urdf").write_text(ARM4.read_text())
    (tmp_path / "arm.json").write_text(
        json.dumps({"name": "urdf", "urdf_file": "arm.urdf", "end_link": "tool"})
    )
    robot = load_robot(tmp_path / "arm.json")
    copy = pickle.loads(pickle.dumps(robot))
    assert copy.kinematics.joint_names == robot.kinematics.joint_names
    x = np.array([0.3, 0.5, 0.8, 0.6])
    assert np.array_equal(copy.kinematics.forward(x), robot.kinematics.forward(x))


def test_a_catalogue_arm_with_a_numpy_home_pickles():
    """A Panda given its home as an ndarray (robot_from_dict takes it) met "The truth value of
    an array ... is ambiguous" when pickled; the copy has that home."""
    pytest.importorskip("yourdfpy")
    home = np.array(robot_from_dict({"name": "panda"}).spec.default_x0) + 0.01
    robot = robot_from_dict({"name": "panda", "home": home})
    copy = pickle.loads(pickle.dumps(robot))
    assert np.array_equal(copy.spec.default_x0, robot.spec.default_x0)


@pytest.mark.parametrize(
    "given",
    [{"name": "panda"}, {"name": "iiwa14", "task": "xyz", "title": "arm", "home": HOME_IIWA}],
)
def test_a_catalogue_arm_s_definition_rebuilds_the_same_arm(given):
    """Robot.definition is documented as what robot_from_dict rebuilds: a catalogue arm's was
    the expanded URDF definition (name 'urdf', its kinematics named 'urdf'); it names the arm,
    keeps what was given and the default map, and rebuilds (and pickles) the same arm."""
    pytest.importorskip("yourdfpy")
    robot = robot_from_dict(given)
    assert robot.definition["name"] == given["name"] and "urdf" not in robot.definition
    assert {k: robot.definition[k] for k in given} == given
    one = robot.spec.p - robot.spec.r == 1  # (an arm's default map: one degree of redundancy)
    maps = [a["name"] for a in robot.definition.get("augmentations", [])]
    assert maps == (["e2_synthesized"] if one else [])
    for copy in (robot_from_dict(robot.definition), pickle.loads(pickle.dumps(robot))):
        assert copy.definition == robot.definition
        assert copy.spec.name == copy.kinematics.name == given["name"]
        assert (copy.spec.title, copy.spec.task_names) == (robot.spec.title, robot.spec.task_names)
        assert copy.spec.default_x0 == robot.spec.default_x0
        x = np.array(robot.spec.default_x0) + 0.1
        assert np.array_equal(copy.kinematics.forward(x), robot.kinematics.forward(x))


@pytest.mark.parametrize(
    ("definition", "field", "rank"),
    [
        ({"name": "planar_chain", "joints": "PPP", "lengths": [1, 1, 1]}, "joints", 1),
        (
            {"name": "planar_chain", "joints": "RPP", "lengths": [1, 1, 1], "orientation": True},
            "joints",
            2,
        ),
        (
            {"name": "formula", "variables": ["a", "b", "c"], "task": ["a + b", "2*a + 2*b"]},
            "task",
            1,
        ),
    ],
)
def test_a_robot_whose_task_cannot_move_in_every_direction_is_refused(definition, field, rank):
    """J of rank < r at every configuration (prismatic joints alone move a planar chain along one
    line; a formula task whose coordinates depend on each other): refused when defined, naming
    the field, instead of every start being called singular."""
    with pytest.raises(InvalidInputError, match=f"J has rank {rank} < r") as err:
        robot_from_dict(definition)
    assert err.value.field == field


def test_a_badly_scaled_task_of_full_rank_is_kept():
    """Rank is judged on J with each row scaled by its largest entry: a coordinate 1e300 times
    another's is no dependence; a chain singular on a set of measure zero passes."""
    scaled = {"name": "formula", "variables": ["x1", "x2", "x3"], "task": ["x1 * a", "x2"]}
    assert robot_from_dict({**scaled, "parameters": {"a": 1e300}}).spec.r == 2
    chain = {"name": "planar_chain", "joints": "PRP", "lengths": [1, 1, 1], "orientation": True}
    assert robot_from_dict(chain).spec.p == 3
