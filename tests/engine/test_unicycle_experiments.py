"""Section 6.2 reproduction: runs from A and B with both inverses (one run() for the module)."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from jik.engine.reproductions import unicycle as repro
from jik.engine.unicycle import Unicycle


@pytest.fixture(scope="module")
def result():
    fractions = []
    out = repro.run(progress=fractions.append)
    assert fractions[-1] == pytest.approx(1.0)
    assert all(b > a for a, b in itertools.pairwise(fractions))
    return out


def test_json_serialisable_without_nan(result):
    """run() is plain JSON (NaN would be invalid JSON: undefined values are None)."""
    text = json.dumps(result, allow_nan=False)
    assert json.loads(text)["parameters"]["gamma"] == 0.1


def test_start_a_both_inverses_converge(result):
    """From A both inverses reach ||k - y_d|| < 1e-10; the final lambda solves the task."""
    for name in ("pseudoinverse", "extended"):
        r = result["A"][name]
        assert r["success"], r["message"]
        assert r["error"] < repro.TOL
        assert len(r["lambda_history"]) == r["iterations"] + 1 == len(r["error_history"])
        assert 150 < r["iterations"] < 400  # error shrinks by 0.9 per iteration near the end
        kin = Unicycle(q0=repro.STARTS["A"])
        assert np.linalg.norm(kin.forward(r["lambda"]) - np.array(repro.Y_D)) < 1e-9
        assert r["lambda_history"][0] == list(repro.LAMBDA0)


def test_discrete_steps_do_not_conserve_h_but_continuous_does(result):
    """Finite steps change h (sec. 6.2); the continuous algorithm (7) conserves it, eq. (12)."""
    disc = result["A"]["extended"]
    assert disc["h_drift"] > 1e-3
    for start in ("A", "B"):
        cont = result["continuous"][start]["extended"]
        assert cont["success"], cont["message"]
        assert cont["h_drift"] < 1e-9
        assert cont["h_final"] == pytest.approx(cont["h_start"], abs=1e-9)


def test_start_b_extended_discrete_stops_with_a_message(result):
    """From B the extended discrete run leaves lambda10 > 0 (h breaks down): stopped, explained."""
    r = result["B"]["extended"]
    assert not r["success"]
    assert "lambda10 crossed 0" in r["message"]
    reasons = ("diverged", "undefined", "could not be resolved", "singular")
    assert any(reason in r["message"] for reason in reasons)
    # A run stopped where h is undefined notes the map's own reason (the raising twin's), not
    # only the inverse's "undefined".
    assert r["solver_message"].startswith("the augmenting map 'characteristics' is undefined")
    assert "its characteristic (28) could not be resolved" in r["notes"][-1]
    assert all(v is None or np.isfinite(v) for v in r["lambda"])
    assert result["B"]["pseudoinverse"]["success"]


def test_paths_similar_from_a_not_from_b(result):
    """The paper's remark: the results of the two inverses are very similar from A, not from B."""
    a = result["comparison"]["A"]["discrete"]["platform_path_max_distance"]
    b = result["comparison"]["B"]["continuous"]["platform_path_max_distance"]
    assert a < 0.5
    assert b > 2.0
    # (from B the extended discrete run stopped: its controls are compared with nothing)
    assert result["comparison"]["B"]["discrete"]["platform_path_max_distance"] is None


def test_format_text_mentions_every_run(result):
    text = repro.format_text(result)
    assert text.count("pseudoinverse") >= 4 and text.count("extended") >= 4
    assert "lambda10 crossed 0" in text
