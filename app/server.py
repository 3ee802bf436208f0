"""``jik serve``: the REST API under uvicorn (and the dashboard's viser scene)."""

from __future__ import annotations

import uvicorn

from app.main import create_app


def run_server(host: str = "127.0.0.1", port: int = 8000, scene_port: int = 8080) -> None:
    """Serve the API on ``host:port`` until interrupted.

    Parameters
    ----------
    host : str
        Address to bind; 127.0.0.1 by default (use 0.0.0.0 in a container).
    port : int
        HTTP port of the API (OpenAPI docs at /docs).
    scene_port : int
        Port of the viser 3D scene.
    """
    app = create_app()
    from app.dashboard import Dashboard
    from app.scene import start_scene
    from app.service import env_flag

    # The dashboard runs one algorithm in a second process (JIK_DASHBOARD_OFFLOAD=0: not).
    app.state.dashboard = Dashboard(offload=env_flag("JIK_DASHBOARD_OFFLOAD"))
    app.state.scene_port = start_scene(app.state.dashboard, host, scene_port).port
    try:
        uvicorn.run(app, host=host, port=port, log_level="info", access_log=False)
    finally:
        app.state.dashboard.stop()
