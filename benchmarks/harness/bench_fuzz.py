"""``jik bench fuzz``: schemathesis against a running ``jik serve``, every check, positive and
negative data.

:func:`run_fuzz` starts the server on a free loopback port, runs the schemathesis command
with :mod:`jik.benchmarks.harness.fuzz_hooks` (what the OpenAPI document cannot say) and reads
its summary: cases generated, failures, and whether the server logged a traceback. The CI test
(tests/app/test_fuzz.py) runs it with ~2,000 cases; this benchmark with 10,000 and more.
"""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass

from ..serving import jik_serve

#: The phases run with every check. Not the stateful phase: on this document schemathesis's
#: grows past the memory of a developer's machine within a minute and a half. Not the
#: coverage phase with positive_data_acceptance: its boundary cases bypass the hooks
#: (:func:`main` runs it with every other check).
PHASES = "examples,fuzzing"

#: schemathesis's settings file: a session's event stream (``GET /api/sessions/{id}/events``)
#: never ends, so its first event is the answer (schemathesis otherwise reads 20 events or until
#: its request timeout, a minute of heartbeats for an idle session). A response may take the
#: server's own bound, twice JIK_TIMEOUT (a wait for a worker, then the computation: a catalogue
#: arm's atlas synthesizes its map while it plans), not schemathesis's default 10 s.
#: A request the schema refuses may also be answered 413 (its body over the server's limit,
#: before it is read), which schemathesis's default list for refused data leaves out.
CONFIG = (
    "max-stream-events = 1\n\n[checks]\nmax_response_time = 40.0\n\n"
    "[checks.negative_data_rejection]\n"
    'expected-statuses = ["400", "401", "403", "404", "405", "406", "409", "413", "415", "422", '
    '"428", "429", "5xx"]\n'
)


@dataclass
class FuzzRun:
    cases: int
    failures: int
    seconds: float
    output: str
    server_log: str

    @property
    def clean(self) -> bool:
        return self.failures == 0 and "Traceback" not in self.server_log and self.cases > 0


def run_fuzz(
    max_examples: int,
    seed: int = 26,
    timeout: float = 1500.0,
    phases: str = PHASES,
    exclude_checks: str = "",
    deterministic: bool = False,
) -> FuzzRun:
    """schemathesis with ``max_examples`` per operation and phase against a fresh server.

    ``deterministic``: the same cases on every run (hypothesis derandomized, ``seed`` unused):
    the test suite's regression check. Otherwise a random search from ``seed``.
    """
    # A request waits at most JIK_TIMEOUT for a worker and as long again to compute, an export
    # at most a minute for its session's result: all within schemathesis's request timeout.
    with jik_serve(JIK_WORKERS="2", JIK_TIMEOUT="20", JIK_SESSION_IDLE_SECONDS="30") as server:
        scratch = tempfile.mkdtemp()  # (schemathesis writes its cache there)
        config = os.path.join(scratch, "schemathesis.toml")
        with open(config, "w") as f:
            f.write(CONFIG)
        started = time.perf_counter()
        out = subprocess.run(
            [
                sys.executable,
                "-m",
                "schemathesis.cli",
                "--config-file",
                config,
                "run",
                f"{server.url}/openapi.json",
                "--checks",
                "all",
                "--phases",
                phases,
                "--max-examples",
                str(max_examples),
                *(["--exclude-checks", exclude_checks] if exclude_checks else []),
                *(["--generation-deterministic"] if deterministic else ["--seed", str(seed)]),
                "--workers",
                "1",
                "--suppress-health-check",
                "all",
                "--continue-on-failure",
                "--request-timeout",
                "120",
                "--no-color",
            ],
            env=dict(
                os.environ,
                SCHEMATHESIS_HOOKS="jik.benchmarks.harness.fuzz_hooks",
                JIK_FUZZ_SERVER=server.url,
            ),
            capture_output=True,
            text=True,
            timeout=timeout,
            cwd=scratch,
        )
        seconds = time.perf_counter() - started
    log = server.log[0]
    text = out.stdout + out.stderr
    generated = re.search(r"(\d+) generated", text)
    found = re.search(r"found (\d+) unique failures", text)
    errors = re.search(r"(\d+) errors?", text.split("SUMMARY")[-1]) if "SUMMARY" in text else None
    failures = int(found.group(1)) if found else 0
    failures += int(errors.group(1)) if errors else 0
    if out.returncode != 0 and failures == 0:
        failures = 1  # (a run that ended in an error of its own)
    return FuzzRun(int(generated.group(1)) if generated else 0, failures, seconds, text, log)


def _report(title: str, run: FuzzRun) -> None:
    print(title)
    print(
        f"  cases {run.cases}, failures {run.failures}, {run.seconds:.0f} s "
        f"({1000 * run.seconds / max(run.cases, 1):.1f} ms per case), server tracebacks: "
        f"{run.server_log.count('Traceback')}"
    )
    if not run.clean:  # (schemathesis's failures, each with its curl command)
        failures = run.output.split("FAILURES")[-1].split("SUMMARY")[0]
        print(failures[-12000:] if "FAILURES" in run.output else run.output[-6000:])


def main(quick: bool = False) -> None:
    if importlib.util.find_spec("schemathesis") is None:
        print("jik bench fuzz needs schemathesis, of the test extra: pip install -e '.[test]'")
        return
    examples = 20 if quick else 850
    _report(
        f"schemathesis, every check, phases {PHASES}, {examples} examples per operation",
        run_fuzz(examples),
    )
    # The coverage phase's boundary cases do not pass through the hooks, so its positive cases
    # include what the document cannot rule out (a box [0, 0], 1000 cycles): every other check.
    coverage = run_fuzz(examples, phases="coverage", exclude_checks="positive_data_acceptance")
    _report("coverage phase (boundary values), every check but positive_data_acceptance", coverage)
