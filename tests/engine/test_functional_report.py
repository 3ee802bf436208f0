"""E1 and E2 of a map on a region as plain data: a tensor rule over at most three variables,
else E2 by the Sobol rule beside single joints (jik.engine.functional_report)."""

import numpy as np
import pytest

from jik.engine.augmentations import E2Optimal, PaperCubic
from jik.engine.e2_qmc import e1_qmc, e2_qmc
from jik.engine.exceptions import InvalidInputError, RunCancelled
from jik.engine.functional_report import (
    QMC_NODES,
    QMC_SEED,
    functionals_report,
    maps_report,
    parameter_sensitivity,
    parameters_report,
    region_words,
    report_words,
)
from jik.engine.functionals import error_functional_e1, error_functional_e2
from jik.engine.kinematics import Manipulator1, Manipulator2
from jik.engine.progress import ProgressCallbacks
from jik.engine.synthesis_nd import synthesize_e2_nd
from tests.engine.test_e2_qmc import CHAIN, REGION


def test_a_small_region_gets_both_functionals_by_the_tensor_rule():
    """Manipulator 2's cubic (38) on a box of two variables: E1 and E2 are the engine's
    functionals there, with their singular points counted; the progress advances after each.
    A box of its variables that is not one is refused, naming the field, as a bad ``nodes``, a
    robot that is not a Kinematics or a map that is not an AugmentingMap (not a traceback, and
    not an ``E1_error`` in the returned data)."""
    kin, h = Manipulator2(), PaperCubic()
    region, fixed = {"x2": (-0.5, 0.5), "x3": (1.0, 2.0)}, {"x1": 0.0}
    steps = []
    told = ProgressCallbacks(on_advance=lambda done, total: steps.append((done, total)))
    out = functionals_report(kin, h, region, fixed, 8, told)
    e1 = error_functional_e1(kin, h, region, nodes=8, fixed=fixed)
    e2 = error_functional_e2(kin, h, region, nodes=8, fixed=fixed)
    assert out["E1"] == pytest.approx(float(e1.value)) and out["E2"] == pytest.approx(e2.value)
    assert out["E1_singular_points"] == e1.singular_points.shape[0]
    assert steps == [(1, 2), (2, 2)] and "note" not in out
    assert functionals_report(kin, h, region) == functionals_report(kin, h, region, None, 12)
    for bad, field in (
        (lambda: functionals_report(kin, h, {"x2": (1.0, 0.0), "x3": (1.0, 2.0)}, fixed), "region"),
        (lambda: functionals_report(kin, h, region, fixed, 0), "nodes"),
        (lambda: functionals_report(kin, h, region, fixed, 8, print), "progress"),
        (lambda: functionals_report("manipulator2", h, region), "kinematics"),
        (lambda: functionals_report(kin, None, region), "amap"),
        (lambda: functionals_report(kin, "x3", region), "amap"),
    ):
        with pytest.raises(InvalidInputError) as refused:
            bad()
        assert refused.value.field.startswith(field), refused.value.field


def test_a_region_of_four_joints_gets_both_by_the_sobol_rule():
    h = synthesize_e2_nd(CHAIN, REGION, degree=2, nodes=2**10).maps[0]
    out = functionals_report(CHAIN, h, REGION, {}, 12)
    rule = e2_qmc(CHAIN, h, REGION, nodes=QMC_NODES, seed=QMC_SEED)
    e1 = e1_qmc(CHAIN, h, REGION, nodes=QMC_NODES, seed=QMC_SEED)
    assert out["E2"] == pytest.approx(rule["E2"], rel=1e-12) and out["E1"] == e1["E1"]
    assert out["E2_single_joint"] == rule["single_joint"]
    errors = [abs(e1["E1"] - e1["E1_half"]), abs(rule["E2"] - rule["E2_half"])]
    assert [out["E1_error_estimate"], out["E2_error_estimate"]] == errors
    assert out["note"] == (
        f"E1 = {e1['E1']:.4g} ± {errors[0]:.1g}, E2 = {rule['E2']:.4g} ± {errors[1]:.1g} on the "
        f"region (Sobol rule, {QMC_NODES} nodes)"
    )
    with pytest.raises(RunCancelled):
        functionals_report(
            CHAIN, h, REGION, {}, 12, progress=ProgressCallbacks(is_cancelled=lambda: True)
        )
    assert np.isfinite(out["E2"])


def test_a_report_in_words_gives_its_note_or_each_value_on_the_box():
    box = region_words({"x2": (-1.0, 1.0), "x3": (0.0, 3.14159)})
    assert box == "x2 ∈ [-1, 1], x3 ∈ [0, 3.14]"
    assert report_words({"E1": 0.5, "E2": 0.25}, box) == f"E1 = 0.5, E2 = 0.25 on {box}"
    diverges = {"E1": None, "E1_divergent": True, "E2": None}
    assert report_words(diverges, "B") == "E1, E2 undefined: h is not defined on all of B"
    diverges["E2"] = 1.0
    assert report_words(diverges, "B") == "E1 = ∞ (dh K = 0 inside), E2 = 1 on B"
    assert report_words({"E1": None, "E2": 1.0}, "B") == "E1 undefined, E2 = 1 on B"
    sobol = {"E1": 0.5, "E1_error_estimate": 0.0123, "E2": 0.25}
    assert report_words(sobol, "B") == "E1 = 0.5 ± 0.01, E2 = 0.25 on B"
    assert report_words({"E2": 1.0, "note": "by a Sobol rule"}, "B") == "by a Sobol rule"


def test_the_parameters_report_sweeps_both_functionals_and_counts_every_evaluation():
    """E2-optimal maps (36) of Manipulator 1 over (a, b): each functional's sweep is the
    engine's parameter_sensitivity; the progress runs over both functionals' evaluations."""
    kin, region, params = Manipulator1(), {"x1": (0.0, 1.0), "x2": (0.0, 1.0)}, {"a": 1.0, "b": 0.5}
    told = []
    progress = ProgressCallbacks(on_advance=lambda *d: told.append(d))
    out = parameters_report(kin, E2Optimal, params, region, 6, {"x3": 1.0}, 3, progress)
    e1 = parameter_sensitivity(
        kin, E2Optimal, params, region, functional="e1", samples=3, nodes=6, fixed={"x3": 1.0}
    )
    assert out["kind"] == "parameters" and out["parameters"] == params and out["E1"] == e1
    n = 1 + 2 * (2 + 3)
    assert told[-1] == (2 * n, 2 * n) and len(told) == 2 * n


def test_the_maps_report_gives_each_map_its_functionals_and_marks_the_current_one():
    kin, region = Manipulator2(), {"x2": (-0.5, 0.5), "x3": (1.0, 2.0)}
    told = []
    maps = [("cubic", PaperCubic), ("again", PaperCubic)]
    progress = ProgressCallbacks(on_advance=lambda *d: told.append(d))
    out = maps_report(kin, maps, "again", region, 6, {"x1": 0.0}, progress)
    e2 = error_functional_e2(kin, PaperCubic(), region, nodes=6, fixed={"x1": 0.0}).value
    assert [(m["name"], m["current"]) for m in out["maps"]] == [("cubic", False), ("again", True)]
    assert out["maps"][0]["E2"] == pytest.approx(e2) and told == [(2, 4), (4, 4)]
    cancel = ProgressCallbacks(on_advance=lambda *d: told.append(d), is_cancelled=lambda: True)
    with pytest.raises(RunCancelled, match="maps"):
        maps_report(kin, maps, "again", region, 6, {"x1": 0.0}, cancel)
