"""schemathesis against a running ``jik serve``: every check, positive and negative data, at
least 2,000 cases: no failure of any kind and no traceback in the server's log (issue 26).

The rules the OpenAPI document cannot state are in :mod:`jik.benchmarks.fuzz_hooks`;
``jik bench fuzz`` runs the same with 10,000 and more cases.
"""

from __future__ import annotations

from jik.benchmarks.bench_fuzz import run_fuzz

#: Examples per operation: about 2,100 cases in all (~2 minutes on 2 cores).
EXAMPLES = 150


def test_schemathesis_finds_nothing():
    run = run_fuzz(EXAMPLES)
    assert run.cases >= 2000, run.output[-3000:]
    assert run.failures == 0, run.output[-8000:]
    assert "Traceback" not in run.server_log, run.server_log[-8000:]
