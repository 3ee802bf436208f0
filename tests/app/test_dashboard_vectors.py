"""The E1/E2 panel of a robot with p - r = 2: E1 (13) and E2 (18) of its vector of maps, as the
engine computes them, with the kernel frame E2 was taken in; the h panel keeps its note."""

from __future__ import annotations

import json

import pytest

from jik.app.dashboard import compute, default_state, updated_state
from jik.app.dashboard.analysis import kinematics_and_map, runs_box, vector_maps
from jik.app.dashboard.functionals import error_functionals, sensitivity
from jik.app.dashboard.map_figures import sensitivity_spec
from jik.app.dashboard.second_phase import SecondPhase, cancelled_message, finished_message
from jik.engine.functional_report import functionals_report
from jik.engine.functionals import error_functional_e1, error_functional_e2

CHAIN = {"name": "planar_chain", "joints": "RRRR", "lengths": [1.0, 1.0, 1.0, 1.0]}
FORMULAS = {"name": "formula", "h": ["x3 + 0.1*x1**2", "x4 - 0.2*sin(x2)"]}
BOX = {"x2": [0.3, 1.2], "x3": [0.4, 1.3], "x4": [0.2, 1.0]}


def result_of(*maps):
    definition = dict(CHAIN, augmentations=list(maps))
    return compute(
        updated_state(default_state(), {"robot": CHAIN["name"], "robot_definition": definition})
    )


def phase_of(result, cancelled=False):
    kin, amap = kinematics_and_map(result.state)
    return SecondPhase(
        kin,
        amap,
        result,
        deferred=False,
        cached=None,
        grid_before=None,
        progress=lambda *_: None,
        cancelled=lambda: cancelled,
    )


def test_formula_maps_are_scored_over_the_box_of_the_runs():
    result = result_of(FORMULAS)
    f = error_functionals(result)
    low, high = runs_box(result.state, result.runs)
    box = {n: (lo, hi) for n, lo, hi in zip(result.variable_names, low, high, strict=True)}
    kin = kinematics_and_map(result.state)[0]
    want = functionals_report(kin, vector_maps(result.state), box, {}, 12)
    assert f["E2"] == want["E2"] and f["E2_frame_axes"] == want["E2_frame_axes"] == [2, 4]
    assert f["E1"] == want["E1"] and not f["design_region"]  # (four joints: the Sobol rule)
    spec = sensitivity_spec(result, sensitivity(result, f))
    title = spec["layout"]["title"]["text"]
    assert "E1, E2 of the vector formula: h = x3 + 0.1*x1**2, x4 - 0.2*sin(x2)" in title
    assert "on the box of the runs" in title and "kernel frame of joints [2, 4]" in title
    assert [d["y"] for d in spec["data"]] == [[f["E1"]], [f["E2"]]]
    assert spec["layout"]["annotations"] == []
    # The Sobol rule's error estimates: error bars, the hover and the title say them.
    errors = [want["E1_error_estimate"], want["E2_error_estimate"]]
    assert [d["error_y"]["array"] for d in spec["data"]] == [[e] for e in errors]
    assert f"E1 = {f['E1']:.4g} ± {errors[0]:.1g}" in title
    assert f"± {errors[1]:.1g}<extra>" in spec["data"][1]["hovertemplate"]


def test_a_synthesized_vector_on_its_design_box_has_both_and_beats_the_formulas():
    """The first e2_synthesized map's box is the robot's design region: three joints, so E1 and
    E2 by the Gauss rule (E2 in the synthesis's frame) for the synthesized vector and, on the
    same box, for the formulas, whose E2 is larger."""
    synthesized = {"name": "e2_synthesized", "region": BOX, "label": "E2-optimal"}
    result = result_of(synthesized, FORMULAS)
    f = error_functionals(result)
    maps = vector_maps(result.state)
    kin, fixed = kinematics_and_map(result.state)[0], f["fixed"]
    assert f["design_region"] and f["region"] == BOX
    e2 = error_functional_e2(kin, maps, BOX, nodes=12, fixed=fixed)
    assert f["E2"] == e2.value and f["E2_frame_axes"] == list(e2.frame_axes)
    assert f["E1"] == error_functional_e1(kin, maps, BOX, nodes=12, fixed=fixed).value
    other = error_functionals(
        compute(updated_state(result.state, {"augmentation": FORMULAS["name"]}))
    )
    assert other["region"] == BOX and other["E2_frame_axes"] == f["E2_frame_axes"]
    assert f["E2"] < other["E2"] and f["E1"] < other["E1"]


def test_a_vector_synthesized_in_a_chosen_frame_is_scored_in_it_and_so_are_the_formulas():
    """The design synthesis asks for the frame of joints 3, 4: its E2 (minimal in that frame) and
    the formulas' are taken in it, not in the best-conditioned (2, 4), where the synthesis
    scores 13.3, worse than the formulas' 9.6."""
    synthesized = {"name": "e2_synthesized", "region": BOX, "frame_axes": [3, 4]}
    result = result_of(synthesized, FORMULAS)
    f = error_functionals(result)
    kin, fixed = kinematics_and_map(result.state)[0], f["fixed"]
    e2 = error_functional_e2(
        kin, vector_maps(result.state), BOX, nodes=12, fixed=fixed, frame_axes=[3, 4]
    )
    assert f["E2_frame_axes"] == [3, 4] and f["E2"] == e2.value
    other = error_functionals(
        compute(updated_state(result.state, {"augmentation": FORMULAS["name"]}))
    )
    assert other["E2_frame_axes"] == [3, 4] and f["E2"] < other["E2"]


@pytest.mark.parametrize("cancelled", [False, True])
def test_the_h_panel_keeps_its_note_when_the_phase_ends(cancelled):
    """The h panel of a vector is a note, not h on a grid: the phase's end, done or cancelled,
    sends it no title about a grid."""
    result = result_of(FORMULAS)
    phase = phase_of(result, cancelled)
    if cancelled:
        message = json.loads(cancelled_message(phase, 1))
    else:
        message = json.loads(finished_message(phase, 1, *phase.run()))
        assert message["functionals"]["E2_frame_axes"] == [2, 4]
    assert "augmenting" not in (message.get("titles") or {})
