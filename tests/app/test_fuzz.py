"""schemathesis against a running ``jik serve``: every check, positive and negative data: no
failure of any kind and no traceback in the server's log.

The default run is deterministic: the same few hundred cases every time (hypothesis
derandomized), a regression check of the contract. The random search is the ``slow`` test (CI
runs it as a step of its own, ``pytest -m slow``) and, at length (10,000+ cases), ``jik bench
fuzz``. ``JIK_FUZZ_EXAMPLES`` sets the slow test's examples per operation (0 skips it). The
rules the OpenAPI document cannot state are in :mod:`jik.benchmarks.harness.fuzz_hooks`.
"""

from __future__ import annotations

import os

import jsonschema
import pytest

from jik.benchmarks.harness.bench_fuzz import run_fuzz

#: Examples per operation and phase of the deterministic run: a few, every operation reached
#: (more made it the suite's longest test).
DETERMINISTIC_EXAMPLES = 5
#: ... and of the random search (CI's slow step): over 2,000 cases.
EXAMPLES = int(os.environ.get("JIK_FUZZ_EXAMPLES", "150"))
MIN_CASES = 2000


def _clean(run) -> None:
    assert run.failures == 0, run.output[-8000:]
    assert "Traceback" not in run.server_log, run.server_log[-8000:]


def test_schemathesis_finds_nothing_in_its_deterministic_cases():
    """The fuzzing phase only: the document's examples (one per robot and route) are posted by
    tests/app/test_examples_api.py, and checked by every check in the slow random search."""
    run = run_fuzz(DETERMINISTIC_EXAMPLES, deterministic=True, phases="fuzzing")
    _clean(run)
    assert run.cases >= 10 * DETERMINISTIC_EXAMPLES, run.output[-3000:]


@pytest.mark.slow
@pytest.mark.skipif(not EXAMPLES, reason="JIK_FUZZ_EXAMPLES=0")
def test_schemathesis_random_search_finds_nothing():
    run = run_fuzz(EXAMPLES)
    _clean(run)
    floor = MIN_CASES if EXAMPLES >= 150 else 10 * EXAMPLES
    assert run.cases >= floor, run.output[-3000:]


def test_the_document_refuses_what_the_server_refuses_a_zero_reference_leaf():
    """The unicycle's map ``characteristics`` needs a != 0 (omega is undefined on lambda10 = 0):
    the document says so, so no client (nor the fuzzing) is told that a = 0 is valid."""
    from fastapi.testclient import TestClient

    from jik.app.api.factory import create_app

    with TestClient(create_app()) as client:
        document = client.get("/openapi.json").json()
        schema = document["components"]["schemas"]["CharacteristicsAugmentation"]
        jsonschema.validate({"name": "characteristics", "a": 0.5}, schema)
        with pytest.raises(jsonschema.ValidationError, match="should not be valid"):
            jsonschema.validate({"name": "characteristics", "a": 0.0}, schema)
        answer = client.post(
            "/synthesize",
            json={
                "robot": {"name": "unicycle"},
                "method": "evaluate",
                "augmentation": {"name": "characteristics", "a": 0.0},
            },
        )
        assert answer.status_code == 422 and "a must be nonzero" in answer.text, answer.text
