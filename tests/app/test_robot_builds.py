"""A robot's formulas are built within a budget of their own in the compute worker: a build that
overruns it is refused naming the robot, never blamed on the computation's field."""

from __future__ import annotations

from fastapi.testclient import TestClient

from jik.app.api.factory import create_app
from jik.app.compute.settings import Settings


def _slow_formula() -> str:
    """Five nested exponentials multiplied: accepted by the parser, seconds of sympy to build."""
    product = []
    for k in range(5):
        inner = "x3"
        for i in range(8, 0, -1):
            inner = f"exp(x{(i + k) % 3 + 1}/{inner})"
        product.append(inner)
    return "*".join(product)


def test_a_slow_formula_build_is_refused_naming_the_robot():
    """With a build budget of 0.02 s (a build of this formula and its derivatives takes far
    longer on any machine), /solve of a slow formula robot is a 422 naming ``robot`` and the
    build (not ``max_iterations``, the field that sizes a solve)."""
    body = {
        "robot": {
            "name": "formula",
            "variables": ["x1", "x2", "x3"],
            "task": ["x1 + x2", _slow_formula()],
        },
        "algorithm": "pseudoinverse",
        "x0": [0.1, 0.2, 0.3],
        "target": [0.3, 1.0],
    }
    with TestClient(create_app(Settings(workers=1, timeout=1.5, build_seconds=0.02))) as client:
        r = client.post("/solve", json=body)
    assert r.status_code == 422, r.text
    (err,) = r.json()["detail"]
    assert err["loc"] == ["body", "robot"], err
    assert err["msg"].startswith("robot: building the robot's formulas took longer than 0.02 s")
