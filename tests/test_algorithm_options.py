"""`jik solve`, `jik repeatability` and `jik atlas` with the damped, weighted and posture
algorithms and their options."""

import json

from jik.cli import main


def run(capsys, *argv, code=0):
    assert main(list(argv)) == code
    out = capsys.readouterr()
    return out.out, out.err


def test_solve_with_damping_and_a_user_robot_with_limits(capsys, tmp_path):
    out, _ = run(
        capsys,
        "solve",
        "--robot",
        "manipulator2",
        "--algorithm",
        "damped",
        "--damping",
        "0.5",
        "--target",
        "1, 1",
        "--json",
    )
    got = json.loads(out)
    assert got["algorithm"] == "damped" and got["success"] and got["error"] < 1e-10
    arm = tmp_path / "arm.json"
    arm.write_text(json.dumps({"name": "planar_chain", "joints": "RRR", "lengths": [1, 1, 1]}))
    out, _ = run(
        capsys,
        "solve",
        "--robot",
        str(arm),
        "--x0",
        "0.3, 0.6, 0.6",
        "--target",
        "1.5, 1.2",
        "--algorithm",
        "weighted",
        "--limits",
        "-3,3; -3,3; -3,3",
        "--json",
    )
    assert json.loads(out)["algorithm"] == "weighted" and json.loads(out)["success"]


def test_repeatability_posture_gain_changes_the_drift(capsys):
    def drift(*extra):
        out, _ = run(
            capsys,
            "repeatability",
            "--robot",
            "manipulator2",
            "--path",
            "1,1; 1,2; 0,2",
            "--cycles",
            "3",
            "--json",
            *extra,
        )
        return json.loads(out)["drift"][-1]

    assert drift("--algorithm", "posture", "--gain", "1") < 0.1 * drift()
    assert drift("--algorithm", "posture", "--gain", "0") == drift()


def test_a_bad_parameter_names_itself(capsys):
    _, err = run(
        capsys, "solve", "--robot", "manipulator2", "--algorithm", "posture", "--gain", "-1", code=2
    )
    assert "gain must be in [0, 100], got -1" in err
    _, err = run(
        capsys,
        "solve",
        "--robot",
        "manipulator2",
        "--algorithm",
        "posture",
        "--rest",
        "0, 1",
        code=2,
    )
    assert "rest must have shape" in err


def test_atlas_compares_algorithms(capsys, tmp_path):
    out_file = tmp_path / "atlas.json"
    run(
        capsys,
        "atlas",
        "--path",
        "0,1; 1,1; 1,2; 0,2",
        "--starts",
        "4",
        "--cycles",
        "2",
        "--arc=-1,1",
        "--algorithm",
        "pseudoinverse",
        "--algorithm",
        "damped",
        "--algorithm",
        "posture",
        "--damping",
        "0.5",
        "--out",
        str(out_file),
    )
    got = json.loads(out_file.read_text())
    assert got["inputs"]["algorithms"] == ["pseudoinverse", "damped", "posture"]
    assert got["inputs"]["algorithm_parameters"]["damped"] == {"damping": 0.5}
