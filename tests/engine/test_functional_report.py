"""E1 and E2 of a map on a region as plain data: a tensor rule over at most three variables,
else E2 by the Sobol rule beside single joints (jik.engine.functional_report)."""

import numpy as np
import pytest

from jik.engine.augmentations import PaperCubic
from jik.engine.e2_qmc import e2_qmc
from jik.engine.exceptions import RunCancelled
from jik.engine.functional_report import (
    QMC_NODES,
    QMC_SEED,
    functionals_report,
    region_words,
    report_words,
)
from jik.engine.functionals import error_functional_e1, error_functional_e2
from jik.engine.kinematics import Manipulator2
from jik.engine.progress import ProgressCallbacks
from jik.engine.synthesis_nd import synthesize_e2_nd
from tests.engine.test_e2_qmc import CHAIN, REGION


def test_a_small_region_gets_both_functionals_by_the_tensor_rule():
    """Manipulator 2's cubic (38) on a box of two variables: E1 and E2 are the engine's
    functionals there, with their singular points counted; ``on_step`` after each."""
    kin, h = Manipulator2(), PaperCubic()
    region, fixed = {"x2": (-0.5, 0.5), "x3": (1.0, 2.0)}, {"x1": 0.0}
    steps = []
    out = functionals_report(kin, h, region, fixed, 8, lambda: steps.append(1))
    e1 = error_functional_e1(kin, h, region, nodes=8, fixed=fixed)
    e2 = error_functional_e2(kin, h, region, nodes=8, fixed=fixed)
    assert out["E1"] == pytest.approx(float(e1.value)) and out["E2"] == pytest.approx(e2.value)
    assert out["E1_singular_points"] == e1.singular_points.shape[0]
    assert len(steps) == 2 and "note" not in out
    bad = functionals_report(kin, h, {"x2": (1.0, 0.0), "x3": (1.0, 2.0)}, fixed, 8)
    assert bad["E1"] is None and "E1_error" in bad


def test_a_region_of_four_joints_gets_e2_by_the_sobol_rule_and_no_e1():
    h = synthesize_e2_nd(CHAIN, REGION, degree=2, nodes=2**10).maps[0]
    out = functionals_report(CHAIN, h, REGION, {}, 12)
    rule = e2_qmc(CHAIN, h, REGION, nodes=QMC_NODES, seed=QMC_SEED)
    assert out["E1"] is None and out["E2"] == pytest.approx(rule["E2"], rel=1e-12)
    assert out["E2_single_joint"] == rule["single_joint"]
    assert out["note"].endswith("nodes); E1 not computed over 4 joints")
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
    assert report_words({"E2": 1.0, "note": "by a Sobol rule"}, "B") == "by a Sobol rule"
