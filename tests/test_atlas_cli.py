"""`jik atlas` writes its inputs, starts, per algorithm drift and leg ends,
a CSV for large atlases, a figure, and errors that name the input."""

import csv
import json
import math

import numpy as np
import pytest

from jik.cli import atlas as atlas_cli
from jik.cli import main
from jik.engine.augmentations import PaperCubic
from jik.engine.inverses import ExtendedInverse, Pseudoinverse
from jik.engine.kinematics import Manipulator2
from jik.engine.repeatability import repeatability

TABLE1 = "1,1; 1,2; 0,2; 0,1"


def run(tmp_path, *extra, out="atlas.json"):
    argv = [
        "atlas",
        "--robot",
        "manipulator2",
        "--path",
        TABLE1,
        "--starts",
        "12",
        "--cycles",
        "2",
        "--quiet",
        "--out",
        str(tmp_path / out),
        *extra,
    ]
    assert main(argv) == 0
    return json.loads((tmp_path / out).read_text())


def test_json_holds_inputs_starts_drift_and_leg_ends(tmp_path):
    """Both algorithms on Table 1's loop from (1, 1): every run is repeatability() from its
    start (to 1e-10), and the starts lie on k(x) = (1, 1)."""
    doc = run(tmp_path, "--algorithm", "pseudoinverse", "--algorithm", "extended", "--csv")
    assert doc["inputs"]["robot"] == "manipulator2" and doc["inputs"]["cycles"] == 2
    assert doc["inputs"]["algorithms"] == ["pseudoinverse", "extended"]
    assert doc["legs_per_cycle"] == 4
    starts = np.array(doc["starts"])
    assert starts.shape == (12, 3) and len(doc["parameter"]) == 12
    kin = Manipulator2()
    np.testing.assert_allclose(kin.forward(starts), np.ones((12, 2)), rtol=0, atol=1e-13)
    path = [(1.0, 2.0), (0.0, 2.0), (0.0, 1.0)]
    for alg, inverse in (
        ("pseudoinverse", Pseudoinverse(kin)),
        ("extended", ExtendedInverse(kin, PaperCubic())),
    ):
        res = doc["results"][alg]
        assert np.shape(res["drift"]) == (12, 2) and np.shape(res["leg_ends"]) == (12, 8, 3)
        for i in (0, 7):
            one = repeatability(inverse, starts[i], path, cycles=2)
            assert res["success"][i] == one.success
            if one.success:
                np.testing.assert_allclose(res["drift"][i], one.drift, rtol=0, atol=1e-10)
                np.testing.assert_allclose(res["leg_ends"][i], one.legs, rtol=0, atol=1e-10)
    rows = list(csv.DictReader((tmp_path / doc["csv"]).open()))
    assert len(rows) == 12 * 2 * 2 * 4  # (starts, algorithms, cycles, legs)
    row = rows[7 * 16 + 7]  # (start 7, pseudoinverse, cycle 2, leg 4)
    assert (row["start"], row["algorithm"], row["cycle"], row["leg"]) == (
        "7",
        "pseudoinverse",
        "2",
        "4",
    )
    assert float(row["drift"]) == doc["results"]["pseudoinverse"]["drift"][7][1]
    assert float(row["x0_3"]) == starts[7, 2]
    assert float(row["x_1"]) == doc["results"]["pseudoinverse"]["leg_ends"][7][7][0]
    assert doc["variable_names"] == ["x1", "x2", "x3"]  # (x0_k and x_k: the variable k)
    assert (tmp_path / doc["figure"]).read_text().count("Repeatability atlas") >= 1


def test_a_large_atlas_streams_to_csv_and_the_json_keeps_a_summary(tmp_path, monkeypatch):
    """Past JSON_RUNS the arrays go to the CSV, in run order, whatever order chunks finish in;
    each row names its path's scale and shift."""
    monkeypatch.setattr(atlas_cli, "JSON_RUNS", 10)
    doc = run(
        tmp_path,
        "--chunk",
        "5",
        "--shift",
        "0,0",
        "--shift",
        "0.2,0",
        "--no-figure",
        "--no-leg-ends",
    )
    assert "results" not in doc and doc["figure"] is None
    assert doc["summary"]["pseudoinverse"]["converged_runs"] == 24
    assert len(doc["paths"]) == 2
    rows = list(csv.DictReader((tmp_path / doc["csv"]).open()))
    assert "leg" not in rows[0] and "x_1" not in rows[0]
    assert [(int(r["path"]), int(r["start"])) for r in rows[::2]] == [
        (j, i) for j in range(2) for i in range(12)
    ]  # (run order; a run's rows: its 2 cycles)
    assert {(r["path"], r["scale"], r["shift_1"], r["shift_2"]) for r in rows} == {
        ("0", "1.0", "0.0", "0.0"),
        ("1", "1.0", "0.2", "0.0"),
    }
    drift = [float(r["drift"] or "nan") for r in rows if r["algorithm"] == "pseudoinverse"]
    assert np.nanmax(drift) == pytest.approx(max(doc["summary"]["pseudoinverse"]["max_drift"]))


@pytest.mark.parametrize(
    ("extra", "rows"), [((), 8192), (("--no-leg-ends", "--chunk", "5"), 8192), ((), 5)]
)
def test_the_csv_is_the_engine_atlas_table(tmp_path, monkeypatch, extra, rows):
    """The CSV is the engine's table of the same atlas, ``AtlasResult.columns()`` (a row per
    leg with the leg ends, per cycle without), written chunk by chunk and, within a chunk, a
    block of about ``ROWS`` rows at a time (5: a block of one run)."""
    from jik.cli import atlas_output
    from jik.engine import atlas_run

    monkeypatch.setattr(atlas_output, "ROWS", rows)

    plans = []

    def recorded(plan, *args, **kwargs):
        plans.append(plan)
        return iter_atlas(plan, *args, **kwargs)

    iter_atlas = atlas_run.iter_atlas
    monkeypatch.setattr(atlas_run, "iter_atlas", recorded)
    doc = run(
        tmp_path,
        "--algorithm",
        "pseudoinverse",
        "--algorithm",
        "extended",
        "--csv",
        "--no-figure",
        *extra,
    )
    legs = "--no-leg-ends" not in extra
    table = atlas_run.run_atlas(plans[0], keep_leg_ends=legs).columns(every_leg=legs)
    with (tmp_path / doc["csv"]).open() as f:
        header, *rows = list(csv.reader(f))
    assert header == list(table)
    assert len(rows) == len(table["drift"])
    for k, name in enumerate(header):
        column = table[name]
        if column.dtype.kind == "f":
            cells = np.array([float(r[k] or "nan") for r in rows])
            np.testing.assert_array_equal(cells, column)
        else:
            assert [r[k] for r in rows] == [str(v) for v in column.tolist()]


def test_processes_give_the_in_process_numbers(tmp_path):
    here = run(tmp_path, "--no-figure", out="a.json")
    there = run(tmp_path, "--no-figure", "--processes", "2", "--chunk", "4", out="b.json")
    assert there["inputs"]["backend"] == "processes:2"
    np.testing.assert_allclose(
        there["results"]["pseudoinverse"]["drift"],
        here["results"]["pseudoinverse"]["drift"],
        rtol=0,
        atol=1e-12,
    )


def test_arc_and_sampling_set_the_starts(tmp_path):
    """--arc lo,hi on a grid: s from lo to hi; on Manipulator 2, s = sqrt(2) (x3 - x3_base)."""
    doc = run(tmp_path, "--arc=-1,1", "--no-figure")
    np.testing.assert_allclose(doc["parameter"], np.linspace(-1, 1, 12), atol=1e-15)
    x3 = np.array(doc["starts"])[:, 2]
    np.testing.assert_allclose(np.diff(x3), np.diff(doc["parameter"]) / math.sqrt(2), atol=1e-10)


@pytest.mark.parametrize(
    ("extra", "text"),
    [
        (["--dask", "local:0"], "local Dask cluster is 'local:N'"),
        (["--dask", "foo bar"], "a Dask scheduler's address is 'HOST:PORT'"),
        (["--dask", ""], "got 'dask:' (option --dask)"),
        (["--processes", "0"], "got 'processes:0' (option --processes)"),
        (["--starts", "0"], "n_starts must be between 1 and 1000000000, got 0 (option --starts)"),
        (["--cycles", "0"], "cycles must be between 1 and 1000, got 0 (option --cycles)"),
        (["--arc", "1,2"], "lo <= 0 <= hi"),
        (["--param", "l"], "--param must be NAME=VALUE, got 'l' (option --param)"),
        (["--arc", "1,a"], "--arc must be comma-separated numbers, got '1,a' (option --arc)"),
    ],
)
def test_bad_input_exits_2_and_names_it(tmp_path, capsys, extra, text):
    argv = ["atlas", "--path", TABLE1, "--quiet", "--out", str(tmp_path / "x.json"), *extra]
    assert main(argv) == 2
    assert text in capsys.readouterr().err
    assert not (tmp_path / "x.json").exists()


@pytest.mark.parametrize(
    ("out", "text"),
    [
        ("missing/atlas.json", "there is no folder"),
        (".", "is a folder; give a file name"),
    ],
)
def test_an_out_that_cannot_be_written_is_refused_before_computing(
    tmp_path, capsys, monkeypatch, out, text
):
    """A folder that does not exist (or a folder given as the file) is named at once, in one
    line, before the curves are traced and the runs computed."""
    from jik.engine import atlas

    def computed(*args, **kwargs):
        raise AssertionError("the atlas was planned before --out was checked")

    monkeypatch.setattr(atlas, "plan_atlas", computed)
    argv = ["atlas", "--path", TABLE1, "--quiet", "--out", str(tmp_path / out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"jik atlas: --out {tmp_path / out}") and text in err, err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_a_path_that_is_not_numbers_is_refused(tmp_path, capsys):
    assert main(["atlas", "--path", "1,a; 2,2", "--out", str(tmp_path / "x.json")]) == 2
    assert "--path must be comma-separated numbers" in capsys.readouterr().err


@pytest.mark.parametrize("terminal", [True, False], ids=["terminal", "log"])
def test_a_refusal_after_the_progress_bar_starts_on_a_line_of_its_own(
    tmp_path, capsys, monkeypatch, terminal
):
    """The bar is drawn before the backend starts; its refusal ends the bar's line. On a
    terminal the bar is redrawn in place, in a log it is a line each time."""
    import sys

    monkeypatch.setattr(sys.stderr, "isatty", lambda: terminal)
    argv = [
        "atlas",
        "--robot",
        "manipulator2",
        "--dask",
        "foo bar",
        "--out",
        str(tmp_path / "x.json"),
    ]
    assert main(argv) == 2
    bar, said = capsys.readouterr().err.split("\n")[:2]
    assert bar.startswith("\r  atlas [" if terminal else "  atlas [")
    assert said.startswith("jik atlas: a Dask scheduler's")


@pytest.mark.parametrize("chunk", ["0", "-3"])
def test_a_chunk_below_one_is_refused_as_the_engine_says(tmp_path, capsys, chunk):
    """--chunk 0 is refused like any chunk outside 1 to 65536, not taken as the default."""
    assert (
        main(["atlas", "--path", TABLE1, "--chunk", chunk, "--out", str(tmp_path / "x.json")]) == 2
    )
    err = capsys.readouterr().err
    assert err == f"jik atlas: chunk must be between 1 and 65536, got {chunk} (option --chunk)\n"


def test_a_dask_scheduler_out_of_reach_is_one_line_and_exit_2(tmp_path, capsys, monkeypatch):
    """A scheduler that does not answer (Dask's connect timeout, an OSError) is said in one
    line, not a traceback."""
    from jik.engine import atlas_backends

    def unreachable(*args, **kwargs):
        raise OSError("Timed out trying to connect to tcp://nosuchhost:1 after 30 s")

    monkeypatch.setattr(atlas_backends.Dask, "__enter__", unreachable)
    argv = ["atlas", "--path", TABLE1, "--quiet", "--dask", "nosuchhost:1"]
    assert main([*argv, "--out", str(tmp_path / "x.json")]) == 2
    err = capsys.readouterr().err
    assert err == "jik atlas: Timed out trying to connect to tcp://nosuchhost:1 after 30 s\n"


ARM = {
    "name": "planar_chain",
    "joints": "RRR",
    "lengths": [1.0, 0.8, 0.6],
    "augmentations": [{"name": "formula", "h": "x1 + x3"}],
}


def test_a_robot_file_runs_as_the_engine_builds_it(tmp_path):
    """--robot FILE: a user's robot (robot_spec.load_robot); each run is repeatability() of
    the robot's own inverses from its start (to 1e-10), the starts on k(x) = path[0]."""
    from jik.engine.robot_spec import load_robot

    (tmp_path / "arm.json").write_text(json.dumps(ARM))
    path = "1.2,1.2; 1.2,1.6; 0.8,1.6"
    argv = [
        "atlas",
        "--robot",
        str(tmp_path / "arm.json"),
        "--path",
        path,
        "--reference",
        "0.3, 1, 1",
        "--arc=-0.5,0.5",
        "--starts",
        "5",
        "--cycles",
        "2",
        "--algorithm",
        "pseudoinverse",
        "--algorithm",
        "extended",
        "--quiet",
        "--no-figure",
        "--out",
        str(tmp_path / "a.json"),
    ]
    assert main(argv) == 0
    doc = json.loads((tmp_path / "a.json").read_text())
    assert doc["inputs"]["robot"] == "planar_chain"
    assert doc["inputs"]["robot_file"] == str(tmp_path / "arm.json")
    robot = load_robot(tmp_path / "arm.json")
    starts = np.array(doc["starts"])
    np.testing.assert_allclose(robot.kinematics.forward(starts), np.full((5, 2), 1.2), atol=1e-9)
    legs = [(1.2, 1.6), (0.8, 1.6), (1.2, 1.2)]
    for alg in ("pseudoinverse", "extended"):
        inverse = robot.inverse(alg)
        for i in (0, 4):
            rep = repeatability(inverse, starts[i], legs, cycles=2)
            np.testing.assert_allclose(
                doc["results"][alg]["drift"][i], rep.drift, rtol=0, atol=1e-10
            )
    assert max(doc["results"]["extended"]["drift"][0]) < 1e-9
    assert min(doc["results"]["pseudoinverse"]["drift"][0]) > 1e-4


def test_a_robot_file_takes_no_param(tmp_path, capsys):
    (tmp_path / "arm.json").write_text(json.dumps(ARM))
    argv = [
        "atlas",
        "--robot",
        str(tmp_path / "arm.json"),
        "--param",
        "l=2",
        "--path",
        "1.2,1.2; 1.2,1.6",
        "--quiet",
        "--out",
        str(tmp_path / "x.json"),
    ]
    assert main(argv) == 2
    assert "--param is for a built-in robot" in capsys.readouterr().err


def test_a_catalogue_arm_counts_the_starts_that_leave_its_limits(tmp_path, capsys):
    """The Panda's pose loop from its home pose: the runs whose start or a leg end is outside
    the joint limits are counted, agree with the leg ends of the JSON, and are said on the
    command's output."""
    pytest.importorskip("yourdfpy")
    from jik.engine.limits import robot_limits, starts_outside
    from jik.engine.robot_spec import robot_from_dict

    path = "0.3069,0,0.5903,0,0,0; 0.38,0,0.59,0,0,0.2; 0.38,0.08,0.59,0.15,0,0.2"
    assert (
        main(
            [
                "atlas",
                "--robot",
                "panda",
                "--path",
                path,
                "--starts",
                "16",
                "--cycles",
                "1",
                "--out",
                str(tmp_path / "a.json"),
                "--no-figure",
                "--quiet",
            ]
        )
        == 0
    )
    doc = json.loads((tmp_path / "a.json").read_text())
    count = doc["summary"]["pseudoinverse"]["outside_limits"]
    limits = robot_limits(robot_from_dict({"name": "panda"}).kinematics)
    legs = np.array(doc["results"]["pseudoinverse"]["leg_ends"], dtype=float)
    expected = starts_outside(limits, np.array(doc["starts"], dtype=float), legs)
    assert count == int(expected.sum()) and 0 < count < 16
    err = capsys.readouterr().err
    assert f"outside the joint limits, of 16 each: pseudoinverse {count}\n" in err


def test_a_catalogue_arm_takes_a_task(tmp_path, capsys):
    """``--task "x y z rx ry"`` on the 6-joint UR5e (p - r = 1): a loop around its home pose in
    those five coordinates; ``--task`` on a built-in robot names the option."""
    pytest.importorskip("yourdfpy")
    from jik.engine.arms import ARMS
    from jik.engine.robot_spec import robot_from_dict

    kin = robot_from_dict({"name": "ur5e", "task": "x y z rx ry"}).kinematics
    y0 = kin.forward(np.array(ARMS["ur5e"].home))
    loop = [y0, y0 + [0.04, 0, 0, 0, 0], y0 + [0.04, 0.04, 0, 0.1, 0]]
    path = "; ".join(",".join(f"{v:.6f}" for v in y) for y in loop)
    out = tmp_path / "ur5e.json"
    argv = [
        "atlas",
        "--robot",
        "ur5e",
        "--task",
        "x y z rx ry",
        "--path",
        path,
        "--starts",
        "4",
        "--cycles",
        "1",
        "--arc=-0.2,0.2",
        "--out",
        str(out),
        "--no-figure",
        "--quiet",
    ]
    assert main(argv) == 0, capsys.readouterr().err
    doc = json.loads(out.read_text())
    assert doc["inputs"]["task"] == ["x", "y", "z", "rx", "ry"] and len(doc["starts"][0]) == 6
    assert doc["summary"]["pseudoinverse"]["outside_limits"] == 0
    argv = [
        "atlas",
        "--robot",
        "manipulator2",
        "--task",
        "xyz",
        "--path",
        "1,1; 1,2",
        "--quiet",
        "--out",
        str(tmp_path / "m.json"),
    ]
    assert main(argv) == 2
    assert "--task is for a catalogue arm" in capsys.readouterr().err


def test_a_urdf_arm_in_a_robot_file_equals_the_catalogue_arm(tmp_path):
    """The Panda's URDF text given inline in a robot file (with its end link and home) gives the
    atlas of ``--robot panda``: the same starts, drift and count of runs outside the limits."""
    pytest.importorskip("yourdfpy")
    from jik.engine.arms import ARMS

    arm = ARMS["panda"]
    definition = {
        "name": "urdf",
        "urdf": arm.urdf,
        "end_link": arm.end_link,
        "home": list(arm.home),
        "task": "pose",
    }
    (tmp_path / "panda.json").write_text(json.dumps(definition))
    path = "0.3069,0,0.5903,0,0,0; 0.38,0,0.59,0,0,0.2; 0.38,0.08,0.59,0.15,0,0.2"
    docs = []
    for robot in ("panda", str(tmp_path / "panda.json")):
        out = tmp_path / f"{len(docs)}.json"
        assert (
            main(
                [
                    "atlas",
                    "--robot",
                    robot,
                    "--path",
                    path,
                    "--starts",
                    "6",
                    "--cycles",
                    "1",
                    "--out",
                    str(out),
                    "--no-figure",
                    "--quiet",
                ]
            )
            == 0
        )
        docs.append(json.loads(out.read_text()))
    by_name, by_file = docs
    np.testing.assert_allclose(by_name["starts"], by_file["starts"], atol=1e-12)
    np.testing.assert_allclose(
        np.array(by_name["results"]["pseudoinverse"]["drift"], float),
        np.array(by_file["results"]["pseudoinverse"]["drift"], float),
        atol=1e-12,
    )
    assert by_name["summary"] == by_file["summary"]


def test_without_path_the_robot_s_closed_path_is_the_loop(tmp_path, capsys):
    """``jik atlas --robot panda --task "x y z rx ry rz"`` (the README's command) and a
    built-in robot without --path run the robot's default closed path; the unicycle, whose
    default path is not a loop, is told to give --path."""
    pytest.importorskip("yourdfpy")
    from jik.engine.registry import ROBOTS
    from jik.engine.robot_spec import robot_from_dict

    out = tmp_path / "panda.json"
    argv = [
        "atlas",
        "--robot",
        "panda",
        "--task",
        "x y z rx ry rz",
        "--starts",
        "2",
        "--cycles",
        "1",
        "--out",
        str(out),
        "--no-figure",
        "--quiet",
    ]
    assert main(argv) == 0, capsys.readouterr().err
    spec = robot_from_dict({"name": "panda", "task": "pose"}).spec
    assert json.loads(out.read_text())["inputs"]["path"] == [list(p) for p in spec.default_path]
    doc = run(tmp_path, out="m2.json")  # (with Table 1's loop, the default path of manipulator2)
    argv = [
        "atlas",
        "--robot",
        "manipulator2",
        "--starts",
        "12",
        "--cycles",
        "2",
        "--quiet",
        "--out",
        str(tmp_path / "m2_default.json"),
    ]
    assert main(argv) == 0
    default = json.loads((tmp_path / "m2_default.json").read_text())
    assert default["inputs"]["path"] == [list(p) for p in ROBOTS["manipulator2"].default_path]
    assert default["results"]["pseudoinverse"]["drift"] == doc["results"]["pseudoinverse"]["drift"]
    argv = ["atlas", "--robot", "unicycle", "--quiet", "--out", str(tmp_path / "u.json")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "unicycle has no default closed path: its default path" in err
    assert "not a loop: give --path (option --path)" in err


def test_the_progress_bar_counts_the_runs_of_every_algorithm(tmp_path, capsys):
    """8 starts, three algorithms: the bar ends at 24 runs, each start run by each algorithm."""
    argv = [
        "atlas",
        "--robot",
        "manipulator2",
        "--path",
        TABLE1,
        "--starts",
        "8",
        "--cycles",
        "1",
        "--algorithm",
        "pseudoinverse",
        "--algorithm",
        "posture",
        "--algorithm",
        "damped",
        "--no-figure",
        "--out",
        str(tmp_path / "a.json"),
    ]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "24/24 runs (8 starts x 3 algorithms)" in err and "8/8 runs" not in err


def test_the_progress_bar_says_the_atlas_s_size_before_its_first_chunk(
    tmp_path, monkeypatch, capsys
):
    """An atlas whose first chunk takes minutes is not silent until then: the bar starts at 0
    runs of its whole size, its time left not yet known ("?", not "nan")."""
    shown = []

    def first_chunk(plan, backend=None, progress=None):
        shown.append(capsys.readouterr().err)
        raise KeyboardInterrupt  # (stop before any work)
        yield

    monkeypatch.setattr("jik.engine.atlas_run.iter_atlas", first_chunk)
    argv = ["atlas", "--robot", "manipulator2", "--starts", "300", "--no-figure"]
    out = ["--out", str(tmp_path / "a.json")]
    with pytest.raises(KeyboardInterrupt):
        main([*argv, *out, "--algorithm", "pseudoinverse", "--algorithm", "extended"])
    assert "atlas [" in shown[0] and "] 0/600 runs (300 starts x 2 algorithms)" in shown[0]
    assert "? s left" in shown[0] and "nan" not in shown[0]


def test_the_run_options_are_a_solve_s(tmp_path):
    """--mode, --gamma, --tol and --max-iterations run every leg as they run jik solve's, and
    the inputs record them: discrete legs at gamma 0.5 given 3 iterations fail, saying so."""
    doc = run(tmp_path, "--mode", "discrete", "--gamma", "0.5", "--max-iterations", "3")
    inputs = doc["inputs"]
    assert (inputs["mode"], inputs["gamma"], inputs["max_iterations"]) == ("discrete", 0.5, 3)
    failures = doc["results"]["pseudoinverse"]["failures"]
    assert len(failures) == 12
    assert all("did not converge within 3 iterations" in why for why in failures.values())
    assert run(tmp_path, "--tol", "1e-6")["inputs"]["tol"] == 1e-6
