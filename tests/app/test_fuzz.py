"""Fuzz the API from its own OpenAPI document (schemathesis): no 5xx, responses match the schema.

Bounded: 30 generated examples per operation, no deadline. A body hook fits most generated
x0 / target / path lengths to the generated robot's p and r, so that real solves (and their
response schema) are exercised, not only the length check (vectors of length 1 are left alone to
keep that check fuzzed too); it clamps the start into the robot's x_range and caps the work
(cycles, path points, iterations, synthesis sizes) so the run stays short. The size limits and
the time limit are tested in test_errors.py and test_limits.py.
"""

from __future__ import annotations

import schemathesis
from hypothesis import HealthCheck, settings
from schemathesis.checks import not_a_server_error, response_schema_conformance

from jik.app.api.factory import create_app
from jik.app.compute.settings import Settings
from jik.engine.registry import ROBOTS

APP = create_app(Settings(workers=2, timeout=3.0))
# Only this module's operations: other routers (the dashboard) are tested by their owners.
schema = schemathesis.openapi.from_asgi("/openapi.json", APP).include(
    path_regex=r"^/(health|robots|solve|repeatability|synthesize)$"
)
# The coverage phase alone sends ~1000 boundary cases (mostly 422s): too slow for CI here; the
# generated phases below still produce positive and negative bodies (bad input is tested case by
# case in test_errors.py).
schema.config.phases.coverage.enabled = False
STATUSES: list[int] = []
WORK_CAPS = {"cycles": 2, "max_iterations": 300, "degree": 6, "nodes": 3, "grid": 5}


def _fit(v, n: int):
    if not isinstance(v, list) or len(v) <= 1:
        return v
    return (v * n)[:n]


@schema.hook
def map_body(context, body):
    if not isinstance(body, dict) or not isinstance(body.get("robot"), dict):
        return body
    name = body["robot"].get("name")
    spec = ROBOTS.get(name) if isinstance(name, str) else None
    if spec is None:
        return body
    body = dict(body)
    if "x0" in body:
        body["x0"] = _fit(body["x0"], spec.p)
        if isinstance(body["x0"], list) and len(body["x0"]) == spec.p:
            body["x0"] = [
                min(max(v, lo), hi) if isinstance(v, float | int) else v
                for v, (lo, hi) in zip(body["x0"], spec.x_range, strict=True)
            ]
    if "target" in body:
        body["target"] = _fit(body["target"], spec.r)
    if isinstance(body.get("path"), list):
        body["path"] = [_fit(pt, spec.r) for pt in body["path"][:4]]
    # Keep the work small: the limits themselves are tested in test_errors.py / test_limits.py.
    for name, cap in WORK_CAPS.items():
        if isinstance(body.get(name), int) and not isinstance(body[name], bool):
            body[name] = min(body[name], cap)
    return body


@schema.parametrize()
@settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck))
def test_api_fuzz(case):
    response = case.call_and_validate(
        checks=[not_a_server_error, response_schema_conformance], timeout=60
    )
    STATUSES.append(response.status_code)


def test_fuzz_reached_successful_computations():
    """The fuzzing above got real results, not only rejections (runs after it, same module)."""
    if not STATUSES:
        return  # run on its own
    assert STATUSES.count(200) >= 10, sorted(STATUSES)
    print(f"fuzz statuses: { {s: STATUSES.count(s) for s in sorted(set(STATUSES))} }")
