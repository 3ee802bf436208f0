"""What the front door's objects say about themselves: a Resume refuses another run, atlas
labels stay apart, reprs and exports name what was computed, and names mean one thing."""

import csv
import io
import json
import math
import pydoc

import numpy as np
import pytest

import jik.engine as jik
import jik.engine.exports as jik_exports
from jik.engine.legendre_map import SynthesizedMap

ARM = jik.Manipulator2()
X0 = np.array([0.0, 0.0, math.pi / 2])
PATH = [(1, 1), (1, 2), (0, 2)]


def _pinv_run(**kwargs):
    return jik.repeatability(jik.Pseudoinverse(ARM), X0, PATH, cycles=2, **kwargs)


@pytest.mark.parametrize(
    ("inverse", "path", "kwargs", "field"),
    [
        (jik.ExtendedInverse(ARM, jik.PaperCubic()), PATH, {}, "algorithm"),
        (jik.Pseudoinverse(jik.Manipulator2(l=2.0)), PATH, {}, "inverse"),
        (jik.Pseudoinverse(ARM), [(1, 1), (1, 1.5), (0, 2)], {}, "targets"),
        (jik.Pseudoinverse(ARM), PATH, {"mode": "discrete", "gamma": 0.5}, "mode"),
        (jik.Pseudoinverse(ARM), PATH, {"gamma": 0.5}, "gamma"),
        (jik.Pseudoinverse(ARM), PATH, {"tol": 1e-8}, "tol"),
        (jik.Pseudoinverse(ARM), PATH, {"max_iterations": 500}, "max_iterations"),
    ],
)
def test_a_resume_of_another_run_is_refused_naming_what_differs(inverse, path, kwargs, field):
    """Going on from a pseudoinverse run with the extended inverse reported the
    pseudoinverse's drift as the extended inverse's; with another path, the old legs."""
    resume = jik.Resume.of(_pinv_run())
    with pytest.raises(jik.InvalidInputError, match=rf"another run, {field}: ") as info:
        jik.repeatability(inverse, resume, path, cycles=4, **kwargs)
    assert info.value.field == "x0"


def test_a_resume_goes_on_with_an_equal_inverse_built_again():
    """A fresh Pseudoinverse of an equal arm is the same run: its numbers are a run from x0."""
    resumed = jik.repeatability(
        jik.Pseudoinverse(jik.Manipulator2()), jik.Resume.of(_pinv_run()), PATH, cycles=4
    )
    whole = jik.repeatability(jik.Pseudoinverse(ARM), X0, PATH, cycles=4)
    np.testing.assert_allclose(resumed.drift, whole.drift, rtol=0, atol=1e-12)
    # Built by hand (no settings), a Resume is checked for its shape alone.
    legs = _pinv_run().legs
    assert jik.repeatability(jik.Pseudoinverse(ARM), jik.Resume(X0, legs), PATH, 3).success


def test_maps_that_print_alike_but_differ_are_different_runs():
    """Two synthesized maps of one degree print alike; their coefficients tell them apart."""
    box = {"x2": (0.0, 1.0), "x3": (1.0, 1.6)}
    c = np.zeros((3, 3))
    c[0, 1], c[1, 0] = 1.0, 0.1
    one, two = SynthesizedMap(c, box, (1, 2), 3), SynthesizedMap(2 * c, box, (1, 2), 3)
    assert repr(one) == repr(two) == "SynthesizedMap(degree_x2=2, degree_x3=2)"
    first = jik.repeatability(jik.ExtendedInverse(ARM, one), X0, PATH, cycles=1)
    with pytest.raises(jik.InvalidInputError, match="another run, fingerprint: "):
        jik.repeatability(jik.ExtendedInverse(ARM, two), jik.Resume.of(first), PATH, cycles=2)
    again = SynthesizedMap(c.copy(), dict(box), (1, 2), 3)
    ok = jik.repeatability(jik.ExtendedInverse(ARM, again), jik.Resume.of(first), PATH, 2)
    assert ok.success


def _damped_atlas(*dampings):
    inverses = [jik.DampedInverse(ARM, damping=d) for d in dampings]
    plan = jik.plan_atlas(
        inverses, [(0, 1), *PATH], cycles=1, n_starts=2, arc=(-0.2, 0.2), reference=X0
    )
    return plan, jik.run_atlas(plan)


def test_atlas_labels_tell_inverses_of_one_algorithm_apart():
    """Two damped inverses were both ``damped``: the long table merged them."""
    plan, atlas = _damped_atlas(0.01, 0.5)
    assert plan.algorithms == atlas.algorithms == ("damped(damping=0.01)", "damped(damping=0.5)")
    assert "AtlasResult(damped(damping=0.01)/damped(damping=0.5)" in repr(atlas)
    column = atlas.columns()["algorithm"]
    assert sorted(set(column.tolist())) == sorted(atlas.algorithms)
    assert np.count_nonzero(column == "damped(damping=0.5)") == atlas.drift[1].size
    _, same = _damped_atlas(0.1, 0.1)
    assert same.algorithms == ("damped #1", "damped #2")
    plan = jik.plan_atlas(
        [jik.Pseudoinverse(ARM), jik.ExtendedInverse(ARM, jik.PaperCubic())],
        [(0, 1), *PATH],
        cycles=1,
        starts=[X0],
    )
    assert plan.algorithms == ("pseudoinverse", "extended")  # (unique names stay as they are)


def _kinematics():
    chain = jik.PlanarChain("RRRR", [1.0, 0.8, 0.6, 0.4])
    formula = jik.FormulaKinematics(["a", "b", "c"], ["a + l*cos(c)", "b + sin(c)"], {"l": 1.0})
    return [jik.Manipulator1(), ARM, jik.Unicycle(), chain, formula]


def test_robots_and_inverses_print_what_they_compute():
    for kin in _kinematics():
        text = repr(kin)
        assert " object at 0x" not in text and "\n" not in text and len(text) < 200, text
        assert text.startswith(f"{type(kin).__name__}(p={kin.p}, r={kin.r}"), text
    assert repr(ARM) == "Manipulator2(p=3, r=2, l=1)"
    chain = _kinematics()[3]
    assert (
        repr(chain)
        == "PlanarChain(p=4, r=2, joints='RRRR', lengths=[1, 0.8, 0.6, 0.4], task='x y')"
    )
    inverses = {
        "Pseudoinverse(Manipulator2(p=3, r=2, l=1))": jik.Pseudoinverse(ARM),
        "ExtendedInverse(Manipulator2(p=3, r=2, l=1), map=PaperCubic())": jik.ExtendedInverse(
            ARM, jik.PaperCubic()
        ),
        "DampedInverse(Manipulator2(p=3, r=2, l=1), damping=0.01, damping_threshold=0)": (
            jik.DampedInverse(ARM, damping=0.01)
        ),
        "PostureInverse(Manipulator2(p=3, r=2, l=1), rest=[0, 0, 1.5], gain=2)": (
            jik.PostureInverse(ARM, [0, 0, 1.5], gain=2.0)
        ),
        "WeightedInverse(PlanarChain(p=4, r=2, joints='RRRR', lengths=[1, 0.8, 0.6, 0.4], "
        "task='x y'), limits=[[-1, 1], [-1, 1], [-1, 1], [-1, 1]])": jik.WeightedInverse(
            chain, [[-1, 1]] * 4
        ),
    }
    for text, inverse in inverses.items():
        assert repr(inverse) == text
    kin = jik.FormulaKinematics(["a", "b", "c", "d"], ["a + b", "c + d"])
    vector = jik.VectorExtendedInverse(kin, [jik.FormulaMap("a", kin.variable_names)] * 2)
    assert "maps=[FormulaMap('a'), FormulaMap('a')]" in repr(vector)


def test_a_robot_prints_on_one_line():
    """Robot printed a dataclass dump (1,167 characters for a planar chain, with the URDF
    text for an arm)."""
    robot = jik.robot_from_dict(
        {
            "name": "planar_chain",
            "joints": "RRR",
            "lengths": [1, 1, 1],
            "augmentations": [{"name": "formula", "h": "x3"}],
        }
    )
    assert repr(robot) == (
        "Robot('planar_chain', title='planar chain', p=3, r=2, task='x y', maps=['formula'])"
    )
    vectors = jik.robot_from_dict(
        {
            "name": "planar_chain",
            "joints": "RRRR",
            "lengths": [1, 0.8, 0.6, 0.4],
            "augmentations": [
                {"name": "formula", "h": ["x3", "x4"]},
                {"name": "formula", "label": "other", "h": ["x1", "x4"]},
            ],
        }
    )
    assert repr(vectors).endswith("maps=['formula', 'other'])"), repr(vectors)
    panda = jik.robot_from_dict({"name": "panda", "task": "pose"})
    text = repr(panda)
    assert len(text) < 200 and "<?xml" not in text and "\n" not in text, text
    assert text.startswith("Robot('panda'") and "p=7, r=6" in text, text
    assert "robot='panda'" in repr(panda.kinematics) and "task='pose'" in repr(panda.kinematics)
    extended = repr(panda.inverse("extended"))
    assert "map=TotalDegreeMap(degree=4, unknowns=329)" in extended, extended


def test_runs_export_their_algorithm_settings_start_and_target():
    """RepeatabilityResult omitted the algorithm, mode and gamma; SolveResult.as_dict x0 and
    the target: two algorithms' JSON looked alike."""
    a = jik.repeatability(jik.DampedInverse(ARM, damping=0.01), X0, PATH, cycles=1)
    b = jik.repeatability(jik.DampedInverse(ARM, damping=0.5), X0, PATH, cycles=1, gamma=2.0)
    da, db = (json.loads(json.dumps(r.as_dict())) for r in (a, b))
    assert da["algorithm"] == db["algorithm"] == "damped" and da["inverse"] != db["inverse"]
    assert (da["mode"], da["gamma"], db["gamma"]) == ("continuous", 1.0, 2.0)
    assert "damping=0.5" in db["inverse"] and da["tol"] == 1e-10
    assert repr(b).startswith("RepeatabilityResult(damped, continuous, gamma=2, success=True")
    one = jik.solve(jik.Pseudoinverse(ARM), X0, [1, 1])
    d = json.loads(json.dumps(one.as_dict()))
    assert d["x0"] == X0.tolist() and d["y_d"] == [1.0, 1.0] and d["algorithm"] == "pseudoinverse"
    batch = jik.solve_batch(jik.Pseudoinverse(ARM), [X0, X0 + 0.1], [[1, 1], [1, 2]])
    assert batch.as_dict()["y_d"] == [[1.0, 1.0], [1.0, 2.0]] and batch[1].y_d.tolist() == [1, 2]
    np.testing.assert_array_equal(batch[1].x0, X0 + 0.1)
    chunked = jik.repeatability(
        jik.Pseudoinverse(ARM),
        X0,
        PATH,
        mode="discrete",
        gamma=0.5,
        record=True,
        progress=jik.ProgressCallbacks(),
    )
    np.testing.assert_array_equal(chunked.leg_results[1].x0, chunked.legs[0])


def test_a_solve_exports_why_it_stopped():
    """as_dict() and columns() dropped SolveResult.status: a notebook's export or
    `jik solve --json` could not tell why a run stopped without parsing the message."""
    one = jik.solve(jik.Pseudoinverse(ARM), X0, [1, 1])
    assert one.as_dict()["status"] == "converged" and one.columns()["status"].tolist() == [
        "converged"
    ]
    batch = jik.solve_batch(
        jik.Pseudoinverse(ARM),
        [X0, X0],
        [[1, 1], [50, -40]],
        mode="discrete",
        gamma=0.5,
        max_iterations=40,
    )
    assert batch.status == (batch[0].status, batch[1].status) == ("converged", "max_steps")
    assert json.loads(json.dumps(batch.as_dict()))["status"] == ["converged", "max_steps"]
    assert batch.columns()["status"].tolist() == ["converged", "max_steps"]


def test_every_result_exports_a_table_with_one_meaning_per_column_name():
    """x1..xp were cycle ends in a repeatability table but starts in an atlas's."""
    rep = jik.repeatability(jik.Pseudoinverse(ARM), X0, PATH, cycles=2)
    rc = rep.columns()
    np.testing.assert_array_equal(rc["x_3"], rep.cycle_end[:, 2])
    np.testing.assert_array_equal(rc["x0_3"], [X0[2]] * 2)
    _, atlas = _damped_atlas(0.01)
    ac = atlas.columns()
    np.testing.assert_array_equal(ac["x0_3"], atlas.starts[0, :, 2])
    np.testing.assert_array_equal(ac["x_3"], atlas.leg_ends[0, 0, :, 3, 2])  # (cycle 1's end)
    d = json.loads(json.dumps(atlas.as_dict()))
    assert d["algorithms"] == ["damped"] and np.allclose(d["drift"], atlas.drift)
    one = jik.solve(jik.Pseudoinverse(ARM), X0, [1, 1])
    sc = one.columns()
    assert list(sc)[:5] == ["x0_1", "x0_2", "x0_3", "y_d_1", "y_d_2"]
    assert sc["x_1"].tolist() == [one.x[0]] and sc["nit"].tolist() == [one.nit]
    synthesis = jik.synthesize_e2(
        ARM, {"x2": (0, 1), "x3": (1, 1.6)}, degree=4, convergence_degrees=(2,)
    )
    assert synthesis.columns()["degree"].tolist() == [2, 4]
    # (one name for the number of unknowns in both syntheses)
    assert list(synthesis.columns()) == ["degree", "unknowns", "e2"]
    assert synthesis.columns()["unknowns"].tolist() == [9, 25]
    sd = json.loads(json.dumps(synthesis.as_dict()))
    assert sd["e2"] == synthesis.e2 and sd["degree"] == 4
    assert repr(synthesis.augmenting_map) == "SynthesizedMap(degree_x2=4, degree_x3=4)"
    for result in (rep, atlas, one, synthesis):
        assert callable(result.to_dataframe) and callable(result.as_dict)


def test_names_are_one_and_exported():
    assert jik.FormulaError is jik.exceptions.FormulaError
    assert issubclass(jik.FormulaError, jik.InvalidInputError)
    with pytest.raises(jik.FormulaError):
        jik.FormulaMap("x3 +", ARM.variable_names)
    assert jik.ProgressCallbacks(stop_at_error=True).stop_at_error
    assert jik.Progress().stop_at_error is False


def test_help_on_progress_shows_its_methods_not_typing_internals():
    text = pydoc.render_doc(jik.ProgressCallbacks, renderer=pydoc.plaintext)
    assert "typing" not in text and "_proto_hook" not in text
    for method in ("leg(", "advance(", "cancelled(", "stop_at_error"):
        assert method in text
    assert "an atlas's runs" in jik.Progress.__doc__ and "total`` is 1.0" in jik.Progress.__doc__


def test_an_atlas_table_runs_in_run_order_and_can_hold_every_leg():
    """Rows run by run (then algorithm, cycle), so that a CSV streamed chunk by chunk writes
    a block of the table at a time; ``every_leg`` gives each leg's end its row."""
    plan, atlas = _damped_atlas(0.01, 0.5)
    A, _, N, C = atlas.drift.shape
    L = plan.legs
    cols = atlas.columns()
    assert cols["start"].tolist() == [0, 0, 1, 1] and cols["algorithm"].tolist() == [
        *atlas.algorithms,
        *atlas.algorithms,
    ]
    np.testing.assert_array_equal(cols["drift"], atlas.drift[:, 0].T.ravel())
    legs = atlas.columns(every_leg=True)
    assert list(legs) == [
        "algorithm",
        "path",
        "start",
        "s",
        "cycle",
        "leg",
        "drift",
        "success",
        "x0_1",
        "x0_2",
        "x0_3",
        "x_1",
        "x_2",
        "x_3",
    ]
    assert len(legs["drift"]) == N * A * C * L and legs["leg"].tolist()[:L] == [1, 2, 3, 4]
    np.testing.assert_array_equal(legs["x_2"][L : 2 * L], atlas.leg_ends[1, 0, 0, :, 1])
    np.testing.assert_array_equal(legs["drift"][:L], [atlas.drift[0, 0, 0, 0]] * L)
    drift_only = jik.run_atlas(plan, keep_leg_ends=False)
    assert "x_1" not in drift_only.columns()
    with pytest.raises(jik.InvalidInputError, match="a row per leg needs the leg ends"):
        drift_only.columns(every_leg=True)


@pytest.mark.parametrize("every_leg", [False, True])
def test_an_atlas_csv_made_in_blocks_is_its_whole_table(every_leg):
    """The CSV text a download streams, made a few rows at a time (here a run per block), is
    the header and the rows of the whole table by csv_rows; a row per leg without the leg
    ends is refused at the call, naming every_leg."""
    plan, atlas = _damped_atlas(0.01, 0.5)
    table = atlas.columns(every_leg)
    blocks = list(atlas.csv_text(every_leg, rows=1))
    assert len(blocks) == atlas.starts.shape[1] > 1
    rows = list(csv.reader(io.StringIO("".join(blocks))))
    assert rows[0] == list(table)
    assert rows[1:] == [list(r) for r in jik_exports.csv_rows(table)]
    drift_only = jik.run_atlas(plan, keep_leg_ends=False)
    with pytest.raises(jik.InvalidInputError, match="needs the leg ends") as refused:
        drift_only.csv_text(every_leg=True)
    assert refused.value.field == "every_leg"


def test_a_functional_value_prints_in_one_line():
    """E1 (13) and E2 (18) of the cubic (38) on its region: the value, the box, what is held,
    the points, and E1's divergence (docs/paper-errata.md), not the array of singular points."""
    region = {"x2": (-1.0, 1.0), "x3": (0.0, 3.0)}
    e2 = repr(jik.error_functional_e2(ARM, jik.PaperCubic(), region))
    assert e2.startswith("FunctionalValue(") and "\n" not in e2 and len(e2) < 200, e2
    assert "x2 in [-1, 1], x3 in [0, 3], held x1=0, 256 points, 0 singular" in e2
    e1 = repr(jik.error_functional_e1(ARM, jik.PaperCubic(), region))
    assert e1.startswith("FunctionalValue(inf (divergent), "), e1


def test_as_dict_gives_none_for_a_missing_number_as_the_cli_prints_null():
    """A failed leg leaves NaN in the drift and the leg ends: ``as_dict()`` (the values for
    JSON, ``json.dumps`` strict) has None there, ``jik repeatability --json`` prints the
    same dict, and the table keeps NaN (a DataFrame's missing value)."""
    x0 = [0.2398, -0.6496, 0.8637]  # the extended inverse stops at once here
    run = jik.repeatability(jik.ExtendedInverse(ARM, jik.PaperCubic()), x0, PATH, cycles=1)
    d = run.as_dict()
    json.dumps(d, allow_nan=False)
    assert d["drift"] == [None] and d["legs"][0] == [None, None, None]
    assert math.isnan(run.columns()["drift"][0])
    trajectory = jik.solve(jik.ExtendedInverse(ARM, jik.PaperCubic()), X0, (1, 1)).trajectory
    assert trajectory is not None
    nan_h = jik.Trajectory(**{**vars(trajectory), "h": np.full(len(trajectory), np.nan)})
    assert set(nan_h.as_dict()["h"]) == {None}
    assert set(jik_exports.json_values([np.nan, np.float64("inf"), (1.5,)])[:2]) == {None}
