"""A real ``jik serve`` under hostile work: a formula whose derivatives explode is refused off the
event loop (the server answers others meanwhile), and SIGTERM stops the server within seconds
whatever it computes (an atlas job's worker processes included)."""

from __future__ import annotations

import signal
import threading
import time

import httpx

from jik.benchmarks.serving import jik_serve


def _nested_exponentials(factors: int) -> str:
    """A product of ``factors`` nested exponentials exp(x1/exp(x2/exp(x3/...))), 8 deep: about
    70 bytes each, and second derivatives of tens of thousands of terms."""
    product = []
    for k in range(factors):
        inner = "x3"
        for i in range(8, 0, -1):
            inner = f"exp(x{(i + k) % 3 + 1}/{inner})"
        product.append(inner)
    return "*".join(product)


def _health_stall(url: str, busy: threading.Thread) -> float:
    """The longest /health answer while ``busy`` runs [s]."""
    worst = 0.0
    with httpx.Client(timeout=60) as client:
        while busy.is_alive():
            start = time.monotonic()
            assert client.get(f"{url}/health").status_code == 200
            worst = max(worst, time.monotonic() - start)
            time.sleep(0.05)
    return worst


def test_an_exploding_formula_is_refused_and_the_server_answers_meanwhile():
    """Six nested-exponential formula robots posted at once to a session's state: each is a
    422 naming the formula's field; /health answers within a second all along."""
    definition = {"name": "formula", "variables": ["x1", "x2", "x3"],
                  "task": ["x1 + x2", _nested_exponentials(5)]}  # fmt: skip
    with jik_serve(JIK_WORKERS="1") as served:
        with httpx.Client(timeout=120) as client:
            created = client.post(f"{served.url}/api/sessions", json={"state": {}})
            assert created.status_code == 201, created.text
            url = f"{served.url}/api/sessions/{created.json()['id']}/state"
        answers: list[httpx.Response] = []

        def post() -> None:
            with httpx.Client(timeout=120) as client:
                body = {"robot": "formula", "robot_definition": definition}
                answers.append(client.post(url, json=body))

        posts = [threading.Thread(target=post) for _ in range(6)]
        for t in posts:
            t.start()
        waiter = threading.Thread(target=lambda: [t.join() for t in posts])
        waiter.start()
        stall = _health_stall(served.url, waiter)
    assert len(answers) == 6
    for r in answers:
        assert r.status_code == 422, r.text
        (detail,) = r.json()["detail"]
        assert detail["loc"] in (["body", "robot_definition", "task", "1"],
                                 ["body", "robot_definition"]), detail  # fmt: skip
        assert "derivatives are too large" in detail["msg"] or "took longer" in detail["msg"]
    assert stall < 1.0, f"/health took {stall:.2f} s while the formulas were refused"


def test_sigterm_during_an_atlas_job_stops_the_server_within_seconds():
    """An atlas job computing in its worker processes: SIGTERM ends the server (and its
    workers) within 5 s, with no leaked semaphore."""
    long = {"robot": {"name": "manipulator2"}, "starts": 20000, "cycles": 5,
            "path": [[0.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]]}  # fmt: skip
    with jik_serve(JIK_WORKERS="1") as served:
        with httpx.Client(timeout=60) as client:
            job = client.post(f"{served.url}/atlas", json=long)
            assert job.status_code == 202, job.text
            status = f"{served.url}/atlas/{job.json()['id']}"
            deadline = time.monotonic() + 60
            while client.get(status).json()["runs_done"] == 0:  # its workers are computing
                assert time.monotonic() < deadline, "the atlas never started"
                time.sleep(0.2)
        start = time.monotonic()
        served.process.send_signal(signal.SIGTERM)
        served.process.wait(timeout=30)
        took = time.monotonic() - start
    log = served.log[0]
    assert took < 5.0, f"the server took {took:.1f} s to stop:\n{log[-2000:]}"
    assert "leaked semaphore" not in log, log[-2000:]
    assert "Traceback" not in log, log[-2000:]
