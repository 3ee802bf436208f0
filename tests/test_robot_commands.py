"""`jik solve` and `jik repeatability` with robots from files and by name."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from jik.cli import main
from jik.cli.robot_commands import parse_path, parse_vector
from jik.engine.reproductions.table1 import PRINTED
from tests.helpers import approx_tree

ARM4 = Path(__file__).resolve().parent / "data" / "arm4.urdf"
ARM3R = {
    "name": "planar_chain",
    "joints": "RRR",
    "lengths": [1.0, 0.8, 0.6],
    "augmentations": [{"name": "e2_synthesized", "region": {"x2": [0.4, 2], "x3": [0.4, 2]}}],
}


@pytest.fixture
def arm_file(tmp_path):
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(ARM3R))
    return str(path)


def run(capsys, *argv, code=0):
    assert main(list(argv)) == code
    out = capsys.readouterr()
    return out.out, out.err


def test_vectors_and_paths_are_constant_formulas():
    assert parse_vector("0, -1e-3, pi/2, atan2(1, 1)", "--x0") == pytest.approx(
        [0, -1e-3, np.pi / 2, np.pi / 4]
    )
    assert parse_path("1,1; 1,2;0 , 2;", "--path") == [[1, 1], [1, 2], [0, 2]]


def test_solve_a_planar_arm_from_a_json_file(capsys, arm_file):
    out, _ = run(
        capsys, "solve", "--robot", arm_file, "--x0", "0.3, 1, 1", "--target", "1, 1.5", "--json"
    )
    res = json.loads(out)
    assert res["success"] and res["algorithm"] == "pseudoinverse"
    np.testing.assert_allclose(res["y"], [1.0, 1.5], atol=1e-10)
    text, _ = run(capsys, "solve", "--robot", arm_file, "--x0", "0.3, 1, 1", "--target", "1, 1.5")
    assert "planar chain, pseudoinverse: converged" in text and "k(x) = (1, 1.5)" in text


def test_json_outputs_are_the_engine_results_dicts(capsys):
    """``jik solve --json`` and ``jik repeatability --json`` print the engine result's
    ``as_dict()`` (the target is ``y_d``, as in its ``y_d_k`` columns), with the robot, and its
    notes and limits."""
    from jik.engine.inverses import Pseudoinverse
    from jik.engine.kinematics import Manipulator2
    from jik.engine.repeatability import repeatability
    from jik.engine.solver import solve

    x0, inverse = [0.0, 0.0, np.pi / 2], Pseudoinverse(Manipulator2())
    out, _ = run(capsys, "solve", "--robot", "manipulator2", "--target", "1, 1", "--json")
    engine = json.loads(json.dumps(solve(inverse, x0, [1, 1]).as_dict()))
    printed = json.loads(out)
    assert "target" not in printed and printed["robot"] == "Manipulator 2"
    assert printed["units"]["x"] == ["m", "m", "rad"] and printed["units"]["y"] == ["m", "m"]
    assert {k: printed[k] for k in engine} == approx_tree(engine, abs=1e-12)
    out, _ = run(capsys, "repeatability", "--robot", "manipulator2", "--cycles", "2", "--json")
    path = [(1, 1), (1, 2), (0, 2), (0, 1)]
    engine = json.loads(json.dumps(repeatability(inverse, x0, path, cycles=2).as_dict()))
    printed = json.loads(out)
    assert list(printed)[1 : len(engine) + 1] == list(engine)
    np.testing.assert_allclose(printed["cycle_end"], engine["cycle_end"], rtol=0, atol=1e-12)


def test_a_failed_runs_json_is_json_with_null_for_its_missing_numbers(capsys):
    """A leg that fails leaves NaN in the engine's legs and drift; the printed JSON has null
    there (JSON has no NaN: a strict parser, as jq or a browser's, refuses it), as jik atlas's."""

    def refuse(constant):
        raise ValueError(f"not JSON: {constant}")

    argv = ["--robot", "manipulator2", "--x0", "0.2398, -0.6496, 0.8637", "--algorithm"]
    out, _ = run(capsys, "repeatability", *argv, "extended", "--json", code=1)
    printed = json.loads(out, parse_constant=refuse)
    assert printed["success"] is False and printed["drift"] == [None]
    assert printed["legs"][0] == [None, None, None] and printed["x0"][0] == 0.2398


def test_repeatability_of_the_synthesized_map_from_a_file(capsys, arm_file):
    path = "1,1.3; 1,1.7; 0.6,1.7"
    out, _ = run(
        capsys,
        "repeatability",
        "--robot",
        arm_file,
        "--x0",
        "0.3, 1, 1",
        "--path",
        path,
        "--cycles",
        "3",
        "--algorithm",
        "extended",
        "--json",
    )
    res = json.loads(out)
    assert res["success"] and res["algorithm"] == "extended"
    assert len(res["drift"]) == 3 and max(res["drift"]) < 1e-9
    assert np.shape(res["legs"]) == (12, 3)


def test_repeatability_of_a_builtin_robot_reproduces_table1(capsys):
    out, _ = run(
        capsys,
        "repeatability",
        "--robot",
        "manipulator2",
        "--x0",
        "0, 0, pi/2",
        "--path",
        "1,1; 1,2; 0,2; 0,1",
        "--json",
    )
    legs = json.loads(out)["legs"]
    np.testing.assert_allclose(legs, PRINTED["pseudoinverse"][1:], atol=5e-5)
    text, _ = run(
        capsys,
        "repeatability",
        "--robot",
        "manipulator2",
        "--x0",
        "0, 0, pi/2",
        "--path",
        "1,1; 1,2; 0,2; 0,1",
        "--cycles",
        "2",
    )
    assert "cycle 2:" in text and "|x - x0| = 4.612e-01" in text


def test_a_catalogue_arm_by_name_with_its_pose_task(capsys):
    """The Panda's default path is a pose loop from home: every leg reaches its pose, and the
    pseudoinverse does not come back."""
    pytest.importorskip("yourdfpy")
    out, _ = run(capsys, "repeatability", "--robot", "panda", "--cycles", "2", "--json")
    result = json.loads(out)
    assert result["robot"] == "Franka Panda" and result["success"]
    assert len(result["x0"]) == 7 and len(result["targets"][0]) == 6
    assert 1e-5 < result["drift"][-1] < 1e-2
    assert result["limits"] == {
        "within": True,
        "violation": None,
        "farthest": None,
        "ends_outside": False,
    }
    out, _ = run(capsys, "solve", "--robot", "panda", "--target", "-0.3, 0, 0.5, 0, 0, 0")
    assert "joint limits: left the joint limits on the way to the target: x2 (panda_joint2)" in out


def test_a_catalogue_arms_task_is_an_option(capsys, tmp_path, arm_file):
    """``--task xyz`` gives the Panda a position task (r = 3) without a robot file; on a robot
    file or a built-in robot the option is refused by its name."""
    pytest.importorskip("yourdfpy")
    out, _ = run(
        capsys, "solve", "--robot", "panda", "--task", "xyz", "--target", "0.4, 0.1, 0.5", "--json"
    )
    result = json.loads(out)
    assert result["success"] and len(result["y"]) == 3
    np.testing.assert_allclose(result["y"], [0.4, 0.1, 0.5], atol=1e-9)
    assert (result["units"]["x"], result["units"]["y"]) == (["rad"] * 7, ["m", "m", "m"])
    for robot in (arm_file, "manipulator2"):
        _, err = run(capsys, "repeatability", "--robot", robot, "--task", "xyz", code=2)
        assert "--task is for a catalogue arm" in err


def test_urdf_robot_from_a_yaml_file(capsys, tmp_path):
    yaml = pytest.importorskip("yaml")
    pytest.importorskip("yourdfpy")
    shutil.copy(ARM4, tmp_path / "arm4.urdf")
    robot = {
        "name": "urdf",
        "urdf_file": "arm4.urdf",
        "end_link": "tool",
        "x0": [0.3, 0.5, 0.8, 0.6],
    }
    (tmp_path / "arm.yaml").write_text(yaml.safe_dump(robot))
    out, _ = run(capsys, "solve", "--robot", str(tmp_path / "arm.yaml"), "--json")
    res = json.loads(out)
    assert res["success"]
    np.testing.assert_allclose(res["y"], res["y_d"], atol=1e-9)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--x0", "0.3, 1"], "x0 must have shape (..., 3)"),
        (["--x0", "__import__('os')"], "--x0[0]: unexpected character '_' at position 0"),
        (["--x0", "0, x1, 0"], "--x0[1]: unknown name 'x1'"),
        (["--target", "1, 2, 3"], "target y_d must have shape (..., 2)"),
        (["--algorithm", "extended", "--augmentation", "nope"], "unknown augmentation 'nope'"),
        (["--x0", ""], "--x0 is empty: give numbers"),
        (
            ["--damping", "1"],
            "--damping is a parameter of damped, not of pseudoinverse: choose it with "
            "--algorithm damped (option --damping)",
        ),
        (["--algorithm", "damped", "--gain", "2"], "--gain is a parameter of posture, not of"),
        (["--max-iterations", "0"], "max_iterations must be between 1 and"),
        (["--tol", "0"], "tol must be"),
        (["--target=1e300,1"], "in magnitude (option --target)"),
        (["--augmentation", "paper_cubic"], "--augmentation is a parameter of extended, not of"),
    ],
)
def test_bad_input_exits_2_with_the_message(capsys, arm_file, argv, message):
    _, err = run(capsys, "solve", "--robot", arm_file, *argv, code=2)
    assert err.startswith("jik solve: ") and message in err


@pytest.mark.parametrize(
    ("path", "message"), [("1,1;;1,2;0,2", "--path[1] is empty"), ("", "--path[0] is empty")]
)
def test_an_empty_path_point_is_refused_and_a_trailing_semicolon_ends_the_path(
    capsys, path, message
):
    _, err = run(capsys, "repeatability", "--robot", "manipulator2", "--path", path, code=2)
    assert message in err
    path = ["--path", "1,1; 1,2; 0,2; 0,1;"]
    out, _ = run(capsys, "repeatability", "--robot", "manipulator2", *path, "--json")
    assert json.loads(out)["targets"] == [[1, 1], [1, 2], [0, 2], [0, 1]]


def test_unknown_robot_exits_2(capsys):
    _, err = run(capsys, "repeatability", "--robot", "scara.json", code=2)
    assert "neither a file nor a built-in robot" in err and "(option --robot)" in err


@pytest.mark.parametrize(
    ("entry", "field"),
    [
        ({"task": ["x2 + os(x3)", "x1 + sin(x3)"]}, "task.0"),
        ({"limits": [[1, 0], [None, None], [None, None]]}, "limits"),
    ],
)
@pytest.mark.parametrize("command", ["solve", "repeatability", "atlas"])
def test_a_robot_files_refused_entry_is_named_as_the_files_not_an_options(
    capsys, tmp_path, entry, field, command
):
    """A formula robot file's task or limits share their names with --task and --limits,
    options the user did not give and that could not change the file: the message names the
    entry of the file."""
    robot = {"name": "formula", "variables": ["x1", "x2", "x3"]}
    robot |= {"task": ["x2 + cos(x3)", "x1 + sin(x3)"], **entry}
    path = tmp_path / "m2.json"
    path.write_text(json.dumps(robot))
    out = ["--out", str(tmp_path / "a.json")] if command == "atlas" else []
    _, err = run(capsys, command, "--robot", str(path), *out, code=2)
    assert err.startswith(f"jik {command}: {field}")
    assert err.endswith(f"(field {field} of the robot file {path})\n") and "option" not in err


def test_repeatability_says_what_it_found_and_why(capsys):
    """``jik repeatability`` ends its text with the run's findings (the engine's sentences, in
    the robot's unit) and gives them in --json as {text, role}: J^E# (11) on Table 1's path
    came back because h stayed at h(x0), eq. (12); J^P# (8) drifted, and why."""
    argv = ["repeatability", "--robot", "manipulator2", "--cycles", "2", "--algorithm"]
    text, _ = run(capsys, *argv, "extended")
    assert "\n  extended Jacobian J^E#: repeatable. After each of 2 cycles" in text
    assert "[m and rad mixed]" in text and "\n  Why: J^E# adds the equation h(x) = h(x0)" in text
    out, _ = run(capsys, *argv, "pseudoinverse", "--json")
    found, why = json.loads(out)["findings"]
    assert found["role"] == "finding" and why["role"] == "why" and set(found) == {"text", "role"}
    assert found["text"].startswith("pseudoinverse J^P#: not repeatable. After 2 cycles")
    assert "no memory of the start" in why["text"]


def test_the_step_cap_and_tolerance_are_options_the_advice_can_name(capsys):
    """A run out of steps says "raise max_iterations": --max-iterations is that option, and
    --tol the error at which a solve stops."""
    slow = ["solve", "--robot", "manipulator1", "--mode", "discrete", "--gamma", "0.1"]
    out, _ = run(capsys, *slow, "--max-iterations", "3", code=1)
    assert "did not converge within 3 iterations" in out and "raise max_iterations" in out
    out, _ = run(capsys, *slow, "--tol", "1e-3")
    assert "< 0.001 after" in out


def test_a_catalogue_arm_without_redundancy_for_its_task_names_the_task_option(capsys):
    """UR5e's 6 joints and --task pose's 6 coordinates: the option to change is --task (the
    arm's active_joints are the catalogue's, no option of the command)."""
    pytest.importorskip("yourdfpy")
    _, err = run(capsys, "solve", "--robot", "ur5e", "--task", "pose", code=2)
    assert "6 active joints for a task of 6 coordinates" in err and err.endswith(
        "(option --task)\n"
    )


@pytest.mark.parametrize("name", ["manipulator1", "manipulator2", "unicycle", "algorithms"])
def test_the_printed_gradient_option_is_refused_outside_table1(capsys, name):
    """--printed-gradient changes Table 1 alone; another reproduction ran without it and said
    nothing, as if the option had been used."""
    _, err = run(capsys, "reproduce", name, "--printed-gradient", code=2)
    assert err == (
        f"jik reproduce: --printed-gradient is for table1 (the printed j32, j33 of (39)), not "
        f"{name} (option --printed-gradient)\n"
    )
    out, _ = run(capsys, "reproduce", "table1", "--printed-gradient", "--json")
    assert json.loads(out)
