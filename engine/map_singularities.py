"""Where an augmenting map h is singular in a box of the joint space (the design region of
sec. 5, over which E1 (13) and E2 (18) are taken), found on one batch of a uniform grid.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .augmentations import AugmentingMap
from .exceptions import InvalidInputError
from .exports import number
from .functionals import Region, check_region
from .inverses import extended_determinant, require_compatible, require_kinematics, require_map
from .kinematics import Kinematics
from .validation import FloatArray, count

#: A point is singular where |dh| exceeds this many times its median over the grid, or where h
#: changes sign by this many times its median step between grid neighbours (a pole).
BLOW_UP, JUMP = 30.0, 30.0
#: Grid points at most (nodes ** number of region variables).
MAX_GRID_POINTS = 2**17
#: Grid points evaluated at once (:func:`_evaluated`).
BLOCK = 2048


@dataclass(frozen=True)
class MapSingularities:
    """Where h is singular on a grid of a box (:func:`map_singularities`).

    Attributes
    ----------
    where : dict name -> (lo, hi)
        Per region variable, the bounds of the singular grid points.
    fraction : float
        The fraction of the grid's points that are singular (of the grid, not of the box:
        :func:`map_singularities`' notes).
    reasons : tuple of str
        What is singular there, each once: "h or its gradient is not finite", "the gradient
        of h blows up", "the extended Jacobian (10) loses rank", "h jumps through infinity".
    region : dict name -> (lo, hi)
        The box searched.
    fixed : dict name -> value
        The variables held, at these values.
    nodes : int
        Grid points per region variable.
    """

    where: dict[str, tuple[float, float]]
    fraction: float
    reasons: tuple[str, ...]
    region: dict[str, tuple[float, float]]
    fixed: dict[str, float]
    nodes: int

    def __repr__(self) -> str:
        at = ", ".join(f"{k} in [{number(lo)}, {number(hi)}]" for k, (lo, hi) in self.where.items())
        return (
            f"MapSingularities({self.fraction:.2%} of a {self.nodes}^{len(self.region)} grid, "
            f"{at}: {'; '.join(self.reasons)})"
        )

    def __str__(self) -> str:
        """What and where, in words: ``the gradient of h blows up at x1 ∈ [0.458, 0.5], any
        x2, any x3 (1250 of the 25^3 grid points)``."""
        spans = []
        for name, (lo, hi) in self.where.items():
            r_lo, r_hi = self.region[name]
            if lo <= r_lo and hi >= r_hi:
                spans.append(f"any {name}")
            elif hi - lo < 1e-12:
                spans.append(f"{name} ≈ {lo:.3g}")
            else:
                spans.append(f"{name} ∈ [{lo:.3g}, {hi:.3g}]")
        return (
            f"{'; '.join(self.reasons)} at {', '.join(spans)} "
            f"({round(self.fraction * self.nodes ** len(self.region))} of the "
            f"{self.nodes}^{len(self.region)} grid points)"
        )

    def warning(self, map_name: str, parameters: Mapping[str, float]) -> str:
        """The warning that the map ``map_name`` (with its ``parameters``) is singular in the
        design region it was searched on, saying where (:meth:`__str__`), so that a large E1
        (13) or E2 (18) there is not read as a bad fit."""
        box = ", ".join(f"{k} ∈ [{lo:.3g}, {hi:.3g}]" for k, (lo, hi) in self.region.items())
        params = ", ".join(f"{k} = {v:.3g}" for k, v in parameters.items())
        return (
            f"Warning: the augmenting map {map_name}"
            + (f" ({params})" if params else "")
            + f" is singular in the design region {box}: {self}. E1 and E2 there are not a "
            "measure of fit, and the extended Jacobian is undefined where a run crosses it."
        )

    def as_dict(self) -> dict:
        """JSON-friendly form."""
        return {
            "where": {k: list(v) for k, v in self.where.items()},
            "fraction": self.fraction,
            "reasons": list(self.reasons),
            "region": {k: list(v) for k, v in self.region.items()},
            "fixed": dict(self.fixed),
            "nodes": self.nodes,
        }


def _neighbours(a: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """The grid array ``a`` without its last and without its first slice along ``axis``."""
    lo, hi = [slice(None)] * a.ndim, [slice(None)] * a.ndim
    lo[axis], hi[axis] = slice(0, -1), slice(1, None)
    return a[tuple(lo)], a[tuple(hi)]


def _between(
    h: np.ndarray, det: np.ndarray, slopes: list[np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """Grid points (h's shape) beside a step where h jumps through infinity, and beside a step
    where, without such a jump, det [J; dh] changes sign (a rank loss between the two points).

    h jumps through infinity between two neighbours where it changes sign against its slope:
    the step h1 - h0 has the opposite sign of dh/dx along that axis at both ends (``slopes``,
    one array per axis), as across a pole and never across a smooth zero; or, where the slopes
    do not say so, by more than JUMP times the median step."""
    pole, flip = np.zeros(h.shape, dtype=bool), np.zeros(h.shape, dtype=bool)
    with np.errstate(all="ignore"):
        for axis in range(h.ndim):
            (h0, h1), (d0, d1) = _neighbours(h, axis), _neighbours(det, axis)
            g0, g1 = _neighbours(slopes[axis], axis)
            step = h1 - h0
            steps = np.abs(step[np.isfinite(step)])
            median = float(np.median(steps)) if steps.size else 0.0
            against = (step * g0 < 0) & (step * g1 < 0)
            jump = (h0 * h1 < 0) & (against | (np.abs(step) > JUMP * max(median, 1e-12)))
            for mask, pair in ((pole, jump), (flip, (d0 * d1 < 0) & ~jump)):
                for side in _neighbours(mask, axis):
                    side |= pair  # (views of mask: both ends of each step)
    return pole, flip & ~pole


def _evaluated(kinematics, augmenting_map, x: FloatArray) -> tuple[FloatArray, ...]:
    """h (n,), dh (n, p), det [J; dh] (n,), where it is singular and where h or dh is
    undefined (n,) at the points x (n, p), :data:`BLOCK` points at a time: a map's gradient
    may hold far more per point than its value (a total-degree basis of seven variables, 64
    kB), and the grid's memory stays that of one block."""
    n = len(x)
    h, det = np.empty(n), np.empty(n)
    dh = np.empty((n, kinematics.p))
    singular, undefined = np.empty(n, dtype=bool), np.empty(n, dtype=bool)
    with np.errstate(all="ignore"):
        for at in range(0, n, BLOCK):
            part = slice(at, at + BLOCK)
            value, value_undefined = augmenting_map.value_masked(x[part])
            slope, slope_undefined = augmenting_map.gradient_masked(x[part])
            h[part] = np.asarray(value, dtype=float).reshape(-1)
            dh[part] = np.asarray(slope, dtype=float)
            det[part], singular[part] = extended_determinant(kinematics.jacobian(x[part]), dh[part])
            undefined[part] = np.asarray(value_undefined | slope_undefined).reshape(-1)
    return h, dh, det, singular, undefined


def map_singularities(
    kinematics: Kinematics,
    augmenting_map: AugmentingMap,
    region: Region,
    *,
    fixed: Mapping[str, float] | None = None,
    nodes: int = 25,
) -> MapSingularities | None:
    """Where h, eq. (9), or the extended Jacobian [J; dh], eq. (10), is singular in a box.

    Parameters
    ----------
    kinematics : Kinematics
        With one degree of redundancy.
    augmenting_map : AugmentingMap
        h; evaluated with ``value_masked``/``gradient_masked`` (NaN where undefined).
    region : mapping name -> (lo, hi)
        The box, e.g. a robot's design region ``{"x1": (0, 1), "x3": (0.5, 1.5)}``, as for
        :func:`~jik.engine.functionals.error_functional_e1`.
    fixed : mapping name -> value, optional
        Values of the variables not in the box, e.g. a start configuration x0's (default: the
        robot's held values, :func:`~jik.engine.kinematics.held_values`).
    nodes : int
        Grid points per region variable, ends included (at most ``MAX_GRID_POINTS`` in all).

    Returns
    -------
    MapSingularities or None
        None when h is regular on the grid.

    Notes
    -----
    Where h is singular, the extended Jacobian inverse (11) is undefined, the integrand of E1
    (13) blows up and E2 (18) does not measure fit. A point counts where h or dh is not
    finite, where |dh| > BLOW_UP times its median, where [J; dh] is singular
    (:func:`~jik.engine.inverses.extended_determinant`, the test E1's quadrature uses), and
    both neighbours of a grid step count where h changes sign against its slope (a pole,
    which a grid point rarely hits: :func:`_between`) or, elsewhere, where det [J; dh] =
    +-(dh K) sqrt(det J J^T) changes sign: dh K = 0 between them, where E1 diverges.
    ``fraction`` is that of the grid's points, not of the box: a rank loss or a pole is a
    set of lower dimension, found at the points beside it, whose share falls as the grid is
    refined; ``where`` is what a finer grid keeps.
    """
    kinematics = require_kinematics(kinematics)
    augmenting_map = require_map(augmenting_map, kinematics)
    require_compatible(kinematics, augmenting_map, "map_singularities")
    box, fix = check_region(kinematics, region, fixed)
    nodes = count(nodes, "nodes", 2, MAX_GRID_POINTS)
    if nodes ** len(box) > MAX_GRID_POINTS:
        raise InvalidInputError(
            f"a grid of {nodes}^{len(box)} points is more than {MAX_GRID_POINTS}; use fewer "
            "nodes or region variables",
            "nodes",
        )
    names = kinematics.names
    axes = [names.index(n) for n in box]
    mesh = np.meshgrid(*(np.linspace(lo, hi, nodes) for lo, hi in box.values()), indexing="ij")
    shape = mesh[0].shape
    x = np.empty((mesh[0].size, kinematics.p))  # (n, p)
    for name, value in fix.items():
        x[:, names.index(name)] = value
    for k, m in zip(axes, mesh, strict=True):
        x[:, k] = m.ravel()
    h, dh, det, singular, undefined = _evaluated(kinematics, augmenting_map, x)
    g = np.linalg.norm(dh, axis=-1)
    undefined |= ~np.isfinite(h) | ~np.isfinite(g)
    found = {"h or its gradient is not finite": undefined}
    scale = np.median(g[~undefined]) if np.any(~undefined) else 0.0
    found["the gradient of h blows up"] = ~undefined & (g > BLOW_UP * scale) & (scale > 0)
    found["the extended Jacobian (10) loses rank"] = singular & ~undefined
    slopes = [dh[:, k].reshape(shape) for k in axes]
    pole, flip = _between(h.reshape(shape), det.reshape(shape), slopes)
    found["the extended Jacobian (10) loses rank"] |= flip.reshape(-1)
    found["h jumps through infinity"] = pole.reshape(-1)
    bad = np.logical_or.reduce(list(found.values()))
    if not bad.any():
        return None
    lo, hi = x[bad].min(axis=0), x[bad].max(axis=0)
    return MapSingularities(
        where={n: (float(lo[k]), float(hi[k])) for n, k in zip(box, axes, strict=True)},
        fraction=float(bad.mean()),
        reasons=tuple(reason for reason, mask in found.items() if mask.any()),
        region=box,
        fixed=fix,
        nodes=nodes,
    )
