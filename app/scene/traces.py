"""The scene's traces: polylines of the computed paths, simplified to what a pixel shows."""

from __future__ import annotations

import numpy as np

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
    """:data:`TRACE_TOLERANCE` of the task-plane box ``extent`` (see :func:`_extent`)."""
    (xlo, xhi), (ylo, yhi) = extent
    return TRACE_TOLERANCE * max(xhi - xlo, yhi - ylo)


def polyline(points: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """(n, 3) points -> segments (m - 1, 2, 3) of the polyline simplified to within ``tol``."""
    points = simplify(points, tol) if tol > 0 and len(points) > 2 else points
    return np.stack([points[:-1], points[1:]], axis=1)
