"""POST /synthesize and GET /synthesize: maps on a grid, coefficients, E1 and E2."""

from __future__ import annotations

import math

import numpy as np

from jik.engine.augmentations import E2Optimal, PaperCubic
from jik.engine.functionals import error_functional_e2
from jik.engine.kinematics import Manipulator1, Manipulator2

REGION = {"x2": [-1.0, 1.0], "x3": [0.0, math.pi]}


def test_methods_are_listed_with_notes(api):
    b = api.get("/synthesize").json()
    assert b["methods"] == ["evaluate", "e2_variational", "e2_total_degree"]
    assert "Ritz" in b["notes"]["e2_variational"]
    assert "Sobol" in b["notes"]["e2_total_degree"]


def test_evaluate_paper_cubic(api):
    body = {"robot": {"name": "manipulator2"}, "region": REGION, "nodes": 12, "grid": 11}
    r = api.post("/synthesize", json=body)
    assert r.status_code == 200, r.text
    b = r.json()
    assert b["method"] == "evaluate" and b["augmentation"]["name"] == "paper_cubic"
    assert b["coefficients"]["x2^1 x3^1"] == -0.7501
    assert b["fixed"] == {"x1": 0.0}
    axes = b["grid"]["axes"]
    assert list(axes) == ["x2", "x3"] and len(axes["x2"]) == 11
    h = np.array(b["grid"]["h"], dtype=float)
    x2, x3 = np.meshgrid(axes["x2"], axes["x3"], indexing="ij")
    x = np.stack([np.zeros_like(x2), x2, x3], axis=-1)
    np.testing.assert_allclose(h, PaperCubic().value(x), atol=1e-12)
    ref = error_functional_e2(Manipulator2(), PaperCubic(), REGION, nodes=12)
    assert math.isclose(b["functionals"]["e2"]["value"], ref.value, rel_tol=1e-12)
    assert b["functionals"]["e2"]["n_points"] == 144


def test_evaluate_manipulator1_map_picks_the_axes_where_h_varies(api):
    body = {
        "robot": {"name": "manipulator1"},
        "augmentation": {"name": "e2_optimal", "a": 0.5, "b": 1.0},
        "nodes": 6,
        "grid": 5,
    }
    b = api.post("/synthesize", json=body).json()
    assert b["augmentation"] == {"name": "e2_optimal", "parameters": {"a": 0.5, "b": 1.0}}
    assert set(b["region"]) == {"x1", "x2", "x3"}  # default: a box around the default start
    assert list(b["grid"]["axes"]) == ["x1", "x3"]  # h = x3 (a x1 + b) sqrt(1 + x1^2)
    x1, x3 = np.meshgrid(*b["grid"]["axes"].values(), indexing="ij")
    x = np.stack([x1, np.zeros_like(x1), x3], axis=-1)
    np.testing.assert_allclose(b["grid"]["h"], E2Optimal(0.5, 1.0).value(x), atol=1e-12)
    ref = error_functional_e2(Manipulator1(), E2Optimal(0.5, 1.0), b["region"], nodes=6)
    assert math.isclose(b["functionals"]["e2"]["value"], ref.value, rel_tol=1e-12)


def test_e2_variational_beats_the_printed_cubic(api):
    """The Ritz minimiser of E2 has lower E2 than (38) on the same box."""
    body = {
        "robot": {"name": "manipulator2"},
        "method": "e2_variational",
        "region": REGION,
        "degree": 8,
        "nodes": 12,
    }
    r = api.post("/synthesize", json=body)
    assert r.status_code == 200, r.text
    b = r.json()
    assert b["augmentation"]["name"] == "e2_synthesized"
    assert b["convergence"][-1]["degree"] == 8
    assert len(b["coefficients"]) == 10  # the least-squares cubic, like (38)
    cubic = api.post(
        "/synthesize", json={"robot": {"name": "manipulator2"}, "region": REGION, "nodes": 12}
    ).json()
    assert b["functionals"]["e2"]["value"] < cubic["functionals"]["e2"]["value"]


def test_synthesize_bad_input(api):
    def msg(body):
        r = api.post("/synthesize", json=body)
        assert r.status_code == 422, r.text
        return r.json()["detail"][0]["msg"]

    m2 = {"name": "manipulator2"}
    assert msg({"robot": m2, "region": {"x7": [0, 1], "x2": [0, 1]}}).startswith(
        "region.x7: Input should be 'x1', 'x2' or 'x3'"
    )
    assert msg({"robot": m2, "region": {"x2": [1, 0], "x3": [0, 1]}}).startswith(
        "region.x2: needs lo < hi"
    )
    assert msg({"robot": m2, "region": REGION, "fixed": {"x2": 0.0}}).startswith(
        "fixed.x2: is also a region variable"
    )
    assert msg({"robot": m2, "grid": 1000}).startswith("grid: Input should be less than")
    assert msg({"robot": m2, "method": "magic"}).startswith("method: Input should be")
