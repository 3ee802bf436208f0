"""The dashboard's 3D scene (viser), one per session: :func:`start_scene`."""

from .lifecycle import DashboardScene, start_scene

__all__ = ["DashboardScene", "start_scene"]
