"""GET /api/sessions/{id}/events against a real ``jik serve``: the event stream as the page's
EventSource reads it (framed by sse-starlette)."""

from __future__ import annotations

import json

import httpx

from jik.benchmarks.serving import jik_serve


def test_the_event_stream_gives_retry_then_the_sessions_events_and_ends_with_it():
    with jik_serve(JIK_WORKERS="1") as served, httpx.Client(base_url=served.url) as c:
        session = c.post("/api/sessions", json={"state": {}}).json()["id"]
        with c.stream("GET", f"/api/sessions/{session}/events", timeout=30) as r:
            assert r.status_code == 200
            assert r.headers["content-type"].startswith("text/event-stream")
            assert r.headers["cache-control"] == "no-store"
            lines = r.iter_lines()
            assert next(lines) == "retry: 1000"
            assert next(lines) == ""
            seen: dict[str, dict] = {}
            event: dict[str, str] = {}
            for line in lines:
                if line:
                    key, _, value = line.partition(": ")
                    event[key] = value
                    continue
                if "event" in event:
                    seen[event["event"]] = event
                    if event["event"] == "result":
                        break
                event = {}
            result = seen["result"]
            assert int(result["id"]) >= 1
            assert json.loads(result["data"])["generation"] == int(result["id"])
            # Deleting the session ends its stream.
            assert c.delete(f"/api/sessions/{session}").status_code == 204
            rest = list(lines)
            assert all(not line.startswith("event: result") for line in rest)
    assert "Traceback" not in served.log[0], served.log[0]
