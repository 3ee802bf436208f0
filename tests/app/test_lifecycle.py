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


def _nested_38() -> str:
    """exp(x1/exp(x2/exp(x3/...))) 38 deep (306 bytes): 8 s of sympy on the event loop once."""
    inner = "x3"
    for i in range(38, 0, -1):
        inner = f"exp(x{i % 3 + 1}/{inner})"
    return inner


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
    """Six nested-exponential formula robots posted at once to a session's state (three 38
    deep, three products of 8-deep ones): each is a 422 naming the formula's field; /health
    answers within a second or two all along (the machine's load aside, the session's own
    computation shares the event loop's process). A new session with such a robot in its
    link's state is refused the same way."""
    definitions = [
        {"name": "formula", "variables": ["x1", "x2", "x3"], "task": ["x1 + x2", text]}
        for text in (_nested_38(), _nested_exponentials(5))
    ]
    definition = definitions[1]
    with jik_serve(JIK_WORKERS="1") as served:
        with httpx.Client(timeout=120) as client:
            created = client.post(f"{served.url}/api/sessions", json={"state": {}})
            assert created.status_code == 201, created.text
            url = f"{served.url}/api/sessions/{created.json()['id']}/state"
        answers: list[httpx.Response] = []

        def post(definition: dict) -> None:
            with httpx.Client(timeout=120) as client:
                body = {"robot": "formula", "robot_definition": definition}
                answers.append(client.post(url, json=body))

        posts = [threading.Thread(target=post, args=(definitions[k % 2],)) for k in range(6)]
        for t in posts:
            t.start()
        waiter = threading.Thread(target=lambda: [t.join() for t in posts])
        waiter.start()
        stall = _health_stall(served.url, waiter)
        with httpx.Client(timeout=120) as client:  # (a link's state: the same check)
            state = {"robot": "formula", "robot_definition": definition}
            linked = client.post(f"{served.url}/api/sessions", json={"state": state})
    assert linked.status_code == 422, linked.text
    assert linked.json()["detail"][0]["loc"][:3] == ["body", "state", "robot_definition"]
    assert len(answers) == 6
    for r in answers:
        assert r.status_code == 422, r.text
        (detail,) = r.json()["detail"]
        assert detail["loc"] in (
            ["body", "robot_definition", "task", 1],
            ["body", "robot_definition"],
        ), detail
        assert any(
            why in detail["msg"]
            for why in ("derivatives are too large", "took longer", "nested too deeply")
        ), detail
    assert stall < 2.0, f"/health took {stall:.2f} s while the formulas were refused"


def test_sigterm_during_an_atlas_job_stops_the_server_within_seconds():
    """An atlas job computing in its worker processes: SIGTERM ends the server (and its
    workers) within 5 s, with no leaked semaphore."""
    long = {
        "robot": {"name": "manipulator2"},
        "starts": 20000,
        "cycles": 5,
        "path": [[0.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]],
    }
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
