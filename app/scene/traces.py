"""The scene's traces: polylines of the computed paths, simplified to what a pixel shows, in
their algorithm's colour."""

from __future__ import annotations

import numpy as np
from plotly.colors import hex_to_rgb as rgb  # ((r, g, b) of "#rrggbb", as viser takes it)

from ..dashboard.algorithms import COLORS, STYLES
from .pose import shown_iterations

#: Largest distance of a drawn trace from the computed path, as a fraction of the scene's size
#: (about a third of a pixel at the dashboard's size).
TRACE_TOLERANCE = 1e-3


def simplify(points: np.ndarray, tol: float) -> np.ndarray:
    """The points of the polyline ``points`` (n, d) that keep it within ``tol`` of every
    original point (Ramer-Douglas-Peucker; the first and the last are always kept).

    A trace costs the viser client per segment, on every frame; the continuous task paths are
    straight between targets, eq. (5), so most of their recorded points lie on a line and add
    nothing a pixel shows.
    """
    n = len(points)
    keep = np.zeros(n, dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, n - 1)]
    while stack:
        i, j = stack.pop()
        if j <= i + 1:
            continue
        a, d = points[i], points[j] - points[i]
        rel = points[i + 1 : j] - a
        L2 = float(d @ d)
        t = np.clip(rel @ d / L2, 0.0, 1.0) if L2 > 0 else np.zeros(len(rel))
        dist = np.linalg.norm(rel - t[:, None] * d, axis=1)
        k = int(np.argmax(dist))
        if dist[k] > tol:
            m = i + 1 + k
            keep[m] = True
            stack += [(i, m), (m, j)]
    return points[keep]


def trace_tolerance(extent) -> float:
    """:data:`TRACE_TOLERANCE` of the task-plane box ``extent``
    (:func:`~jik.app.scene.mechanisms.extent_of`)."""
    (xlo, xhi), (ylo, yhi) = extent
    return TRACE_TOLERANCE * max(xhi - xlo, yhi - ylo)


def polyline(points: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """(n, 3) points -> segments (m - 1, 2, 3) of the polyline simplified to within ``tol``."""
    points = simplify(points, tol) if tol > 0 and len(points) > 2 else points
    return np.stack([points[:-1], points[1:]], axis=1)


def unicycle_traces(result, root: str, tol: float) -> dict[str, tuple[str, dict, dict]]:
    """The unicycle's paths at its shown iterations (:func:`~jik.app.scene.pose.shown_iterations`)
    as fixtures (:func:`~jik.app.scene.mechanisms.fixtures_of`): each algorithm's the paler the
    earlier, the last in its colour and thicker."""
    shown = shown_iterations(result)
    out: dict[str, tuple[str, dict, dict]] = {}
    for a, run in result.runs.items():
        base = np.asarray(rgb(COLORS[a]), dtype=float)
        for n, i in enumerate(shown):
            P = run.platform[min(int(i), len(run.platform) - 1)]
            last = n == len(shown) - 1
            mix = 1.0 if last else 0.3 + 0.5 * n / len(shown)
            pts = np.column_stack([P[:, 0], P[:, 1], np.full(len(P), 0.02 + STYLES[a].z * 0.2)])
            values = {
                "points": polyline(pts, tol),
                "colors": (255 - mix * (255 - base)).astype(np.uint8),
                "thickness": 3.5 if last else 1.5,
            }
            out[f"{root}/trace/{a}/{n}"] = ("line_segments", values, {"thickness_units": "screen"})
    return out
