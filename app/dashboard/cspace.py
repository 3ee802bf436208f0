"""The configuration-space panel: for p = 3 (or three coordinates the user picks of the
unicycle's four), both algorithms' joint paths x(theta), the level surface h(x) = h(x0) that the
extended Jacobian keeps (eq. (12)), and the self-motion manifolds k(x) = y of the targets of the
legs (the path's corners): one-dimensional, since p - r = 1 (sec. 2).
"""

from __future__ import annotations

import numpy as np

from ...engine.exceptions import JikError
from ...engine.self_motion import drawn_curves
from .algorithms import COLORS, DASH, LABELS, STYLES
from .analysis import expensive_map, kinematics_and_map, runs_box
from .plotting import RIGHT, corner_names, figure, trace
from .runs import DashboardResult

#: Points per run drawn; level-surface grid.
MAX_POINTS, GRID = 1500, 16
CSPACE_HEIGHT = 520
#: The layout key of the panel's 3D axes (not "scene": see :func:`cspace_spec`).
SCENE = "scene2"


def _level_surface(result: DashboardResult, amap, axes, lo, hi) -> dict | str:
    """h (of p = 3 variables, a cheap map) on a grid of the box, as an isosurface at h(x0); or
    why there is none."""
    lines = [np.linspace(lo[k], hi[k], GRID) for k in axes]
    X = np.stack(np.meshgrid(*lines, indexing="ij"), axis=-1).reshape(-1, 3)
    # (float32 on the way: half the bytes of a panel sent on every change of its runs)
    with np.errstate(all="ignore"):
        H = np.asarray(amap.value(X), dtype=float)
        h0 = float(np.asarray(amap.value(np.asarray(result.state.x0, dtype=float)[None]))[0])
    if not np.isfinite(h0) or not np.isfinite(H).any():
        return "h is undefined at x0" if not np.isfinite(h0) else "h is undefined on the box"
    value = np.nan_to_num(H, nan=h0 + 1e9).astype(np.float32)  # (undefined h: far from h0)
    X = X.astype(np.float32)
    return trace(
        "isosurface",
        x=X[:, 0],
        y=X[:, 1],
        z=X[:, 2],
        value=value,
        isomin=h0,
        isomax=h0,
        surface=dict(count=1),
        caps=dict(x=dict(show=False), y=dict(show=False), z=dict(show=False)),
        colorscale=[[0, "#9aa5b1"], [1, "#9aa5b1"]],
        showscale=False,
        opacity=0.3,
        name=f"level surface h = h(x0) = {h0:.4g}",
        hoverinfo="skip",
        showlegend=True,
    )


def _thin(x: np.ndarray) -> np.ndarray:
    step = max(1, len(x) // MAX_POINTS)
    return np.vstack([x[::step], x[-1:]])


def cspace_spec(result: DashboardResult) -> dict:
    """The configuration-space panel (see the module's docstring)."""
    names = result.variable_names
    # (all three for p = 3, else the state's choice, hexadecimal digits: "013"; none: "012")
    axes = a, b, c = tuple(int(k, 16) for k in result.state.cspace_axes or "012")
    data = []
    notes = []
    try:
        kin, amap = kinematics_and_map(result.state)
    except (JikError, ValueError) as exc:
        return figure([], f"Configuration space: {exc}")
    lo, hi = runs_box(result.state, result.runs)
    if amap is None:
        notes.append(f"h is a vector of p − r = {kin.p - kin.r} maps: its level set not drawn")
    elif kin.p != 3:
        notes.append(f"the level surface of h lives in {kin.p} dimensions: not drawn")
    elif expensive_map(amap):
        notes.append("level surface not drawn: h is solved point by point for this map")
    elif isinstance(surface := _level_surface(result, amap, axes, lo, hi), str):
        notes.append(f"level surface not drawn: {surface}")
    else:
        data.append(surface)
    L = len(result.targets)
    # (the corners' configurations: the extended run's, else any run's that reached them)
    ends = [r.leg_end[:L] for a, r in sorted(result.runs.items(), key=lambda i: i[0] != "extended")]
    seeds = next((e for e in ends if len(e) >= L), ends[0])
    if kin.p - kin.r > 1:
        notes.append(f"self-motion manifolds {kin.p - kin.r}-dimensional: not drawn")
    elif len(seeds) == L:
        with np.errstate(all="ignore"):
            curves = drawn_curves(kin, seeds, lo, hi)
        for k, (curve, name) in enumerate(zip(curves, corner_names(result), strict=True)):
            data.append(
                trace(
                    "scatter3d",
                    x=curve[:, a],
                    y=curve[:, b],
                    z=curve[:, c],
                    mode="lines",
                    line=dict(color="#2ca02c", width=3),
                    name="self-motion manifolds k(x) = corner",
                    legendgroup="fibres",
                    showlegend=k == 0,
                    hovertemplate=f"k(x) = {name}<extra></extra>",
                )
            )
    for alg, run in result.runs.items():
        x = _thin(run.x)
        data.append(
            trace(
                "scatter3d",
                x=x[:, a],
                y=x[:, b],
                z=x[:, c],
                mode="lines",
                name=LABELS[alg],
                line=dict(color=COLORS[alg], dash=DASH[alg], width=1 + STYLES[alg].width),
                hovertemplate=f"{names[a]} = %{{x:.3f}}<br>{names[b]} = %{{y:.3f}}"
                f"<br>{names[c]} = %{{z:.3f}}<extra>{alg}</extra>",
            )
        )
    x0 = np.asarray(result.state.x0, dtype=float)
    data.append(
        trace(
            "scatter3d",
            x=[x0[a]],
            y=[x0[b]],
            z=[x0[c]],
            mode="markers",
            marker=dict(color="white", size=5, line=dict(color="black", width=2)),
            name="start x0",
        )
    )
    shown = ", ".join(names[k] for k in axes)
    if kin.p > 3:
        fixed = [n for k, n in enumerate(names) if k not in axes]
        notes.append(
            f"{', '.join(fixed)} not shown (the control “configuration-space axes” picks three)"
        )
    fibres = [] if kin.p - kin.r > 1 else ["green: self-motion manifolds of the corners"]
    sub = " · ".join([*fibres, *notes])
    scene = dict(
        xaxis=dict(title=dict(text=names[a])),
        yaxis=dict(title=dict(text=names[b])),
        zaxis=dict(title=dict(text=names[c])),
        aspectmode="cube",
    )
    # (plotly names a scene's element after its layout key: "scene" would be a second element
    # with the id of the page's 3D scene, #scene)
    for t in data:
        t["scene"] = SCENE
    return figure(
        data,
        f"Configuration space ({shown})<br><sup>{sub}</sup>",
        **{SCENE: scene},
        height=CSPACE_HEIGHT,
        showlegend=True,
        legend=dict(orientation="h", x=0, y=0, yanchor="top", font=dict(size=10)),
        margin=dict(l=0, r=RIGHT, t=40, b=40),  # (the toolbar beside the scene)
    )
