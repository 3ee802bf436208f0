"""GET /health, GET /robots and the OpenAPI document."""

from __future__ import annotations

import math

from jik.engine.registry import ROBOTS


def test_health(api):
    r = api.get("/health")
    assert r.status_code == 200
    assert r.json() == {"status": "ok"}


def test_docs_and_openapi(api):
    assert api.get("/docs").status_code == 200
    spec = api.get("/openapi.json").json()
    assert {"/health", "/robots", "/solve", "/repeatability", "/synthesize"} <= set(spec["paths"])


def test_robots_lists_the_whole_registry(api):
    """Every robot of the registry with p, r, ranges, defaults and augmentations; then the
    catalogue arms (tests/app/test_arms_api.py)."""
    from jik.engine.arms import ARMS

    body = api.get("/robots").json()
    names = [r["name"] for r in body["robots"]]
    assert names == [*ROBOTS, *ARMS]
    for info in body["robots"][: len(ROBOTS)]:
        spec = ROBOTS[info["name"]]
        assert (info["p"], info["r"]) == (spec.p, spec.r)
        assert len(info["default_x0"]) == spec.p
        assert len(info["default_target"]) == spec.r
        assert all(len(pt) == spec.r for pt in info["default_path"])
        assert info["default_augmentation"] in [a["name"] for a in info["augmentations"]]
        for p in info["parameters"]:
            assert "minimum" in p and "maximum" in p and "default" in p
        for aug in info["augmentations"]:
            for p in aug["parameters"]:
                assert p["minimum"] <= p["default"] <= p["maximum"]
    m2 = next(r for r in body["robots"] if r["name"] == "manipulator2")
    assert m2["parameters"][0]["name"] == "l"
    assert m2["parameters"][0]["minimum"] == 0.1
    assert m2["functional_region"] == {"x2": [-1.0, 1.0], "x3": [0.0, math.pi]}
    assert body["limits"]["max_cycles"] == 1000
    assert body["limits"]["max_path_points"] == 100


def test_openapi_robot_union_comes_from_the_registry(api):
    """The request schema names every registered robot (discriminated by name)."""
    spec = api.get("/openapi.json").json()
    text = str(spec["components"]["schemas"])
    for name in ROBOTS:
        assert f"'{name}'" in text
