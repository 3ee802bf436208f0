"""An augmenting map h on a plane of a box of the joint space: the slice that shows h over the
design region of sec. 5 (where E1 (13) and E2 (18) are taken), along the two variables of the
box that h varies most with, the others held at the box's centre, at given values or where E1,
E2 and their syntheses hold them (:func:`jik.engine.kinematics.held_values`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .augmentations import AugmentingMap
from .exceptions import InvalidInputError, JikError
from .inverses import require_map
from .kinematics import Kinematics, held_values
from .progress import ProgressCallbacks
from .regions import check_box_region
from .validation import FloatArray, count

#: Seeded samples of the box on which :func:`grid_axes` compares h's partial derivatives.
AXIS_SAMPLES = 64
#: The most grid points per axis (a map that raises where it is undefined is evaluated point
#: by point).
MAX_N = 201


@dataclass(frozen=True)
class MapGrid:
    """h on an n x n grid of two variables (:func:`map_grid`).

    Attributes
    ----------
    axes : dict name -> ndarray, shape (n,)
        The two variables, in the robot's order, and their grid values.
    h : ndarray, shape (n, n)
        h at (first axis value i, second axis value j); NaN where h is undefined.
    """

    axes: dict[str, FloatArray]
    h: FloatArray

    def __repr__(self) -> str:
        box = " x ".join(f"{k} in [{v[0]:.4g}, {v[-1]:.4g}]" for k, v in self.axes.items())
        defined = self.h[np.isfinite(self.h)]
        span = f"h in [{defined.min():.4g}, {defined.max():.4g}]" if defined.size else "h undefined"
        undefined = self.h.size - defined.size
        return (
            f"MapGrid({box}, {' x '.join(str(n) for n in self.h.shape)} points, {span}"
            f"{f', undefined at {undefined}' if undefined and defined.size else ''})"
        )


def varying_most(dh: FloatArray, spread: FloatArray | None = None) -> tuple[int, int]:
    """The two variables h varies most with at some configurations: the largest mean |dh/dx_i|
    (the gradient of eq. (9)'s map) over the rows of ``dh`` (n, k), rows where h is undefined
    (NaN) left out, each times ``spread_i + 1`` when ``spread`` (k,) is given (how far the
    configurations extend along x_i, e.g. a run's: a variable they move along counts more). A
    variable whose gradient is never defined comes last. Ascending indices; ties keep the
    variables' order."""
    g = np.abs(np.asarray(dh, dtype=float))
    defined = np.isfinite(g)
    rows = defined.sum(axis=0)  # (the rows where each partial derivative is defined)
    score = np.where(rows > 0, np.where(defined, g, 0.0).sum(axis=0) / np.maximum(rows, 1), -1.0)
    if spread is not None:
        score = score * (np.asarray(spread, dtype=float) + 1.0)
    i, j = sorted(np.argsort(-score, kind="stable")[:2])
    return int(i), int(j)


def grid_axes(
    amap: AugmentingMap,
    variable_names: Sequence[str],
    region: Mapping[str, tuple[float, float]],
    base: FloatArray,
) -> list[str]:
    """The two variables of ``region`` along which h varies most (:func:`varying_most`) on
    :data:`AXIS_SAMPLES` seeded uniform samples of the box, the other variables at ``base``
    (p,). All of them for a box of at most two variables, the first two when the gradient
    cannot be evaluated. Returned in the box's order."""
    if len(region) <= 2:
        return list(region)
    names = list(variable_names)
    rng = np.random.default_rng(0)
    x = np.broadcast_to(base, (AXIS_SAMPLES, len(base))).copy()
    for k, (lo, hi) in region.items():
        x[:, names.index(k)] = rng.uniform(lo, hi, AXIS_SAMPLES)
    with np.errstate(all="ignore"):
        try:
            g = np.asarray(amap.gradient(x), dtype=float)
        except JikError:
            return list(region)[:2]
    keys = list(region)
    i, j = varying_most(g[:, [names.index(k) for k in keys]])
    return [keys[i], keys[j]]


def map_grid(
    amap: AugmentingMap,
    kinematics: Kinematics | Sequence[str],
    region: Mapping[str, tuple[float, float]],
    fixed: Mapping[str, float] | None = None,
    n: int = 21,
) -> MapGrid | None:
    """h on an ``n`` x ``n`` grid over the two variables of ``region`` it varies most with
    (:func:`grid_axes`), ends included.

    Parameters
    ----------
    amap : AugmentingMap
        The map h of eq. (9), of the configurations x (..., p).
    kinematics : Kinematics or sequence of str, length p
        The robot (its variables' names, in x's order), or the names alone.
    region : dict name -> (lo, hi)
        The box; its variables other than the two axes are held at their centre.
    fixed : dict name -> value, optional
        The values of variables outside the box; by default a robot's
        :func:`~jik.engine.kinematics.held_values` (those of E1 (13), E2 (18) and their
        syntheses over the same box), 0 for names alone.
    n : int
        Grid points per axis, 2 to :data:`MAX_N`.

    Returns
    -------
    MapGrid or None
        None for a box of fewer than two variables. A map that raises where it is undefined
        is evaluated point by point, NaN at the points where it raises.

    Raises
    ------
    InvalidInputError
        A region or fixed value that is not one of the variables' (field ``region.<name>``,
        ``fixed``), an empty or reversed interval, ``n`` out of range, or ``kinematics`` not a
        robot nor names, or of another number of variables than the map's p.
    """
    if isinstance(kinematics, Kinematics):
        names, default = list(kinematics.names), list(held_values(kinematics))
    else:
        names, default = _names(kinematics), None
    amap = require_map(amap, names, "amap")
    if len(names) != amap.p:
        raise InvalidInputError(
            f"kinematics must have the map's p = {amap.p} variables, got {len(names)}: {names}",
            "kinematics",
        )
    region, held = check_box_region(names, region, fixed, default)
    n = count(n, "n", 2, MAX_N)
    if len(region) < 2:
        return None
    p = len(names)
    base = np.zeros(p)
    for k, v in held.items():
        base[names.index(k)] = v
    for k, (lo, hi) in region.items():
        base[names.index(k)] = 0.5 * (lo + hi)
    axes = grid_axes(amap, names, region, base)
    a, b = (np.linspace(region[k][0], region[k][1], n) for k in axes)
    x = np.broadcast_to(base, (n, n, p)).copy()
    x[..., names.index(axes[0])] = a[:, None]
    x[..., names.index(axes[1])] = b[None, :]
    with np.errstate(all="ignore"):
        try:
            h = np.asarray(amap.value(x), dtype=float)
        except JikError:
            h = np.full((n, n), np.nan)
            for i, j in np.ndindex(n, n):
                try:
                    h[i, j] = float(amap.value(x[i, j]))
                except JikError:
                    pass
    return MapGrid({axes[0]: a, axes[1]: b}, h)


def _names(kinematics) -> list[str]:
    """The variables' names given instead of a robot: a list of strings, else an
    InvalidInputError naming ``kinematics``."""
    if isinstance(kinematics, Sequence) and not isinstance(kinematics, str):
        if all(isinstance(n, str) for n in kinematics):
            return list(kinematics)
    raise InvalidInputError(
        "kinematics must be a Kinematics or its variables' names (a list of strings), got "
        f"{type(kinematics).__name__} {kinematics!r:.60}",
        "kinematics",
    )


def _batched(amap: AugmentingMap, x: FloatArray, batch: int, on_batch) -> tuple:
    """(h, dh) at ``x`` (n, p) of a map that solves a problem per point, ``batch`` points at a
    time (its ``evaluate_batches``), ``on_batch(done, total)`` after each batch."""
    return amap.evaluate_batches(x, batch, ProgressCallbacks(on_advance=on_batch))  # type: ignore[attr-defined]


def axes_along(
    amap: AugmentingMap, x: FloatArray, batch: int = 45, on_batch=None
) -> tuple[int, int]:
    """The two joint variables h depends on most along the configurations ``x`` (n, p), their
    spread counted (:func:`varying_most`). A map that solves a problem per point
    (:attr:`~jik.engine.augmentations.AugmentingMap.solves_per_point`) is evaluated ``batch``
    points at a time, ``on_batch(done, total)`` after each batch."""
    with np.errstate(all="ignore"):
        if amap.solves_per_point:
            dh = _batched(amap, x, batch, on_batch)[1]
        else:
            dh = amap.gradient(x)
    return varying_most(dh, np.ptp(x, axis=0))


def slice_values(
    amap: AugmentingMap, base, axes, box, n: int, batch: int = 45, on_batch=None
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """h on an ``n`` x ``n`` grid over the variables ``axes`` = (i, j) of x on ``box`` =
    ((lo_i, hi_i), (lo_j, hi_j)), ends included, the others at ``base`` (p,): (u, v, H), H[b,
    a] at x_i = u[a], x_j = v[b]; NaN where h is not finite. A map that solves a problem per
    point is evaluated as in :func:`axes_along`."""
    (i, j), p = axes, len(base)
    (lo_u, hi_u), (lo_v, hi_v) = box
    u, v = np.linspace(lo_u, hi_u, n), np.linspace(lo_v, hi_v, n)
    x = np.broadcast_to(np.asarray(base, dtype=float), (n, n, p)).copy()
    x[..., i] = u[None, :]
    x[..., j] = v[:, None]
    with np.errstate(all="ignore"):
        if amap.solves_per_point:  # (maps that can be undefined at some points)
            h = _batched(amap, x.reshape(-1, p), batch, on_batch)[0]
        else:
            h = amap.value(x.reshape(-1, p))
    h = np.asarray(h, dtype=float).reshape(n, n)
    return u, v, np.where(np.isfinite(h), h, np.nan)
