"""What ``jik serve`` writes to its log: never a session's id, the one key to a session (who
holds it reads and changes the session), though each opening of a session's scene names it in
its path."""

from __future__ import annotations

import asyncio

import httpx
import websockets

from jik.benchmarks.serving import jik_serve


async def _open_scene(port: int, session_id: str, origin: str) -> None:
    url = f"ws://127.0.0.1:{port}/api/sessions/{session_id}/scene"
    async with websockets.connect(url, origin=origin, open_timeout=10) as ws:  # type: ignore[arg-type]
        await asyncio.wait_for(ws.wait_closed(), 10)


def test_the_server_log_never_names_a_session_id():
    with jik_serve(JIK_WORKERS="1") as served:
        session_id = httpx.post(f"{served.url}/api/sessions", json={}, timeout=60).json()["id"]
        for origin in (served.url, "http://evil.example"):  # (the scene's page; a refused one)
            asyncio.run(_open_scene(served.port, session_id, origin))
        httpx.delete(f"{served.url}/api/sessions/{session_id}", timeout=60)
    log = served.log[0]
    assert "/scene" not in log and session_id not in log, log
