"""Where an augmenting map is singular in its robot's design region (the box of sec. 5 over which
E1 (13) and E2 (18) are taken): h blows up or jumps there (the E1-optimal map (32) with a C2
that makes g(x1) vanish), or the extended Jacobian [J; dh] of eq. (10) loses rank (eq. (11) is
then undefined). The verdict says where, so that a large E1 or E2 is not read as a bad fit.
"""

from __future__ import annotations

import json

import numpy as np

from ...engine.exceptions import JikError
from .analysis import expensive_map, kinematics_and_map
from .model import DashboardState
from .robots import state_spec

#: Grid points per region variable.
NODES = 25
#: Regions of more variables are not searched (a 7-joint arm's box: 25^7 points).
MAX_GRID_VARIABLES = 3
#: A point is singular where |dh| exceeds this many times its median over the region, where h
#: jumps by this many times its median step between neighbours with opposite signs, or where
#: the extended Jacobian's rows are this close to dependent (|det| / product of row norms).
BLOW_UP, JUMP, DEPENDENT = 30.0, 30.0, 1e-6


def _grid(state: DashboardState, names, region) -> tuple[np.ndarray, list[int]]:
    """The region's grid, other variables at x0: (NODES, ..., p) and the region's axes."""
    axes = [names.index(n) for n in region]
    lines = [
        np.linspace(float(region[names[k]][0]), float(region[names[k]][1]), NODES) for k in axes
    ]
    mesh = np.meshgrid(*lines, indexing="ij")
    X = np.broadcast_to(np.asarray(state.x0, dtype=float), (*mesh[0].shape, len(names))).copy()
    for k, m in zip(axes, mesh, strict=True):
        X[..., k] = m
    return X, axes


def singular_points(state: DashboardState) -> dict | None:
    """Where h or the extended Jacobian is singular in the robot's design region (cached by
    what it depends on: the robot, its map and their parameters, and x0)."""
    key = (
        state.robot,
        json.dumps(state.robot_parameters, sort_keys=True),
        json.dumps(state.robot_definition, sort_keys=True),
        state.augmentation,
        json.dumps(state.augmentation_parameters, sort_keys=True),
        tuple(state.x0),
    )
    if key not in _CACHE:
        if len(_CACHE) > 64:
            _CACHE.clear()
        _CACHE[key] = _find(state)
    return _CACHE[key]


_CACHE: dict[tuple, dict | None] = {}


def _find(state: DashboardState) -> dict | None:
    """Where h or the extended Jacobian is singular in the robot's design region.

    Returns
    -------
    dict or None
        ``{"region": {name: [lo, hi]}, "where": {name: [lo, hi]}, "fraction": float,
        "reason": str}``: the bounds of the singular grid points per region variable; None
        when there is no design region, the map is expensive to evaluate, or h is regular
        there.
    """
    spec = state_spec(state)
    region = dict(spec.functional_region)
    if not region or len(region) > MAX_GRID_VARIABLES:
        return None  # (none, or a grid of NODES^n points too large to search)
    try:
        kin, amap = kinematics_and_map(state)
    except (JikError, ValueError):
        return None
    if amap is None or expensive_map(amap):
        return None
    names = list(spec.variable_names)
    X, axes = _grid(state, names, region)
    flat = X.reshape(-1, X.shape[-1])
    with np.errstate(all="ignore"):
        h = np.asarray(amap.value(flat), dtype=float).reshape(X.shape[:-1])
        dh = np.asarray(amap.gradient(flat), dtype=float)  # (n, p)
        J = np.asarray(kin.jacobian(flat), dtype=float)  # (n, r, p)
        E = np.concatenate([J, dh[:, None, :]], axis=1)  # (n, p, p): eq. (10)
        ratio = np.abs(np.linalg.det(E)) / np.prod(np.linalg.norm(E, axis=2), axis=1)
        g = np.linalg.norm(dh, axis=1)
    bad = ~np.isfinite(g) | ~np.isfinite(ratio) | ~np.isfinite(h.reshape(-1))
    reasons = []
    if bad.any():
        reasons.append("h or its gradient is not finite")
    finite_g = g[np.isfinite(g)]
    if finite_g.size and np.median(finite_g) > 0:
        big = np.isfinite(g) & (g > BLOW_UP * np.median(finite_g))
        if big.any():
            reasons.append("the gradient of h blows up")
        bad |= big
    dependent = np.isfinite(ratio) & (ratio < DEPENDENT)
    if dependent.any():
        reasons.append("the extended Jacobian (10) loses rank")
    bad |= dependent
    bad = bad.reshape(h.shape)
    for ax in range(h.ndim):  # h jumps through infinity between neighbours (a pole)
        with np.errstate(all="ignore"):
            step = np.abs(np.diff(h, axis=ax))
        finite_step = step[np.isfinite(step)]
        scale = float(np.median(finite_step)) if finite_step.size else 0.0
        flip = np.diff(np.sign(h), axis=ax) != 0
        jump = flip & (step > JUMP * max(scale, 1e-12))
        if jump.any():
            reasons.append("h jumps through infinity")
            lo = [slice(None)] * h.ndim
            hi = [slice(None)] * h.ndim
            lo[ax], hi[ax] = slice(0, -1), slice(1, None)
            bad[tuple(lo)] |= jump
            bad[tuple(hi)] |= jump
    if not bad.any():
        return None
    pts = X[bad]
    where = {names[k]: [float(pts[:, k].min()), float(pts[:, k].max())] for k in axes}
    return {
        "region": {k: list(v) for k, v in region.items()},
        "where": where,
        "fraction": float(bad.mean()),
        "reason": "; ".join(dict.fromkeys(reasons)),
    }


def singular_sentence(state: DashboardState) -> str | None:
    """The warning the verdict shows when h is singular in the design region, saying where."""
    found = singular_points(state)
    if found is None:
        return None
    spans = []
    for name, (lo, hi) in found["where"].items():
        r_lo, r_hi = found["region"][name]
        if lo <= r_lo and hi >= r_hi:
            spans.append(f"any {name}")
        elif hi - lo < 1e-12:
            spans.append(f"{name} ≈ {lo:.3g}")
        else:
            spans.append(f"{name} ∈ [{lo:.3g}, {hi:.3g}]")
    box = ", ".join(f"{k} ∈ [{lo:.3g}, {hi:.3g}]" for k, (lo, hi) in found["region"].items())
    params = ", ".join(f"{k} = {v:.3g}" for k, v in state.augmentation_parameters.items())
    return (
        f"Warning: the augmenting map {state.augmentation}"
        + (f" ({params})" if params else "")
        + f" is singular in the design region {box}: {found['reason']} at "
        + ", ".join(spans)
        + f" ({100 * found['fraction']:.2g}% of the region's grid). E1 and E2 there are not a "
        "measure of fit, and the extended Jacobian is undefined where a run crosses it."
    )
