"""Fuzz the API from its own OpenAPI document (schemathesis): no 5xx, responses match the schema.

Bounded: a few dozen examples per operation, no deadline, a 2 s compute limit so that generated
requests asking for huge work (1000 cycles over 100 path points) are cut short (HTTP 422 naming
the field). A body hook fits most generated x0 / target / path lengths to the generated robot's
p and r, so that real solves (and their response schema) are exercised, not only the length
check; vectors of length 1 are left alone to keep that check fuzzed too.
"""

from __future__ import annotations

import schemathesis
from hypothesis import HealthCheck, settings
from schemathesis.checks import not_a_server_error, response_schema_conformance

from app.main import create_app
from app.service import Settings
from engine.registry import ROBOTS

APP = create_app(Settings(workers=2, timeout=2.0))
# Only this module's operations: other routers (the dashboard) are tested by their owners.
schema = schemathesis.openapi.from_asgi("/openapi.json", APP).include(
    path_regex=r"^/(health|robots|solve|repeatability|synthesize)$"
)
STATUSES: list[int] = []


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
    if "target" in body:
        body["target"] = _fit(body["target"], spec.r)
    if isinstance(body.get("path"), list):
        body["path"] = [_fit(pt, spec.r) for pt in body["path"]]
    return body


@schema.parametrize()
@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
def test_api_fuzz(case):
    response = case.call_and_validate(checks=[not_a_server_error, response_schema_conformance])
    STATUSES.append(response.status_code)


def test_fuzz_reached_successful_computations():
    """The fuzzing above got real results, not only rejections (runs after it, same module)."""
    if not STATUSES:
        return  # run on its own
    assert STATUSES.count(200) >= 10, sorted(STATUSES)
    print(f"fuzz statuses: { {s: STATUSES.count(s) for s in sorted(set(STATUSES))} }")
