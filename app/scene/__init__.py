"""The dashboard's 3D scene (viser), one per session: :class:`DashboardScene`."""

from .lifecycle import DashboardScene

__all__ = ["DashboardScene"]
