"""Plotly figures of a dashboard result: pure functions ``DashboardResult -> go.Figure``.

Each figure is built as a plain figure dict first (its "spec"): the dashboard serializes those
directly (:func:`figure_specs`, :func:`figure_json`), 5x faster than through ``go.Figure``
and ``to_json``, on every change of a control.

Colours are fixed per algorithm (:data:`jik.app.dashboard.model.COLORS`), the same as in the
3D scene.
The figures follow the paper: task-space paths (Figs. 5, 6), joint trajectories against theta
(Figs. 7-9), the repeatability drift per cycle with the Table 1 numbers, and for the unicycle the
platform paths in the (q1, q2) plane and the controls against the iteration (Figs. 11-14).
"""

from __future__ import annotations

import base64
import json
import math
from typing import Any

import numpy as np
import plotly.graph_objects as go

from jik.app.dashboard.analysis import state_inert_variables
from jik.app.dashboard.model import ALGORITHMS, COLORS, LABELS
from jik.app.dashboard.runs import DashboardResult
from jik.engine.reproductions.table1 import cell

#: Units of the joint and task variables, by robot (the registry does not carry units).
UNITS = {
    "manipulator1": (("m", "m", "1"), ("m", "m")),
    "manipulator2": (("m", "m", "rad"), ("m", "m")),
    "unicycle": (("m/s", "m/s", "rad/s", "rad/s"), ("m", "m", "rad")),
}
PANEL_HEIGHT = 380
#: Panel ids, in the page's order, with their size on the page's grid ("wide": a whole row,
#: "tall": two rows).
PANEL_SIZES = {"task": "wide", "drift": "", "joints": "tall", "augmenting": "",
               "sensitivity": "", "table": "wide"}  # fmt: skip
PANELS = tuple(PANEL_SIZES)
_AXIS = dict(
    gridcolor="#e6e6e6", zerolinecolor="#b0b0b0", linecolor="#888", showline=True, mirror=True,
    ticks="outside", automargin=True,
    # plotly's default on linear axes, "hide past div", measures every tick label's box
    # (a forced layout each) on every redraw: ~10 ms per panel here.
    ticklabeloverflow="allow",
)  # fmt: skip
# A small explicit template: the named ones ("plotly_white") cost ~25 ms per figure to apply.
_TEMPLATE = dict(
    layout=dict(paper_bgcolor="white", plot_bgcolor="white", xaxis=_AXIS, yaxis=_AXIS,
                colorway=["#d62728", "#1f77b4", "#2ca02c", "#9467bd"])
)  # fmt: skip
_LAYOUT = dict(
    template=_TEMPLATE,
    height=PANEL_HEIGHT,
    margin=dict(l=64, r=20, t=40, b=100),
    legend=dict(orientation="h", yanchor="top", y=-0.2, xanchor="left", x=0, font=dict(size=10)),
    font=dict(size=11),
    hovermode="closest",
    uirevision="keep",  # keep the user's zoom across updates of the same robot
)
_SYMBOLS = {"pseudoinverse": "circle", "extended": "diamond"}


def _units(result: DashboardResult) -> tuple[tuple[str, ...], tuple[str, ...]]:
    joint, task = UNITS.get(result.state.robot, ((), ()))
    p, r = len(result.variable_names), len(result.task_names)
    return (joint or ("",) * p), (task or ("",) * r)


def _label(name: str, unit: str) -> str:
    return f"{name} [{unit}]" if unit else name


def is_unicycle(result: DashboardResult) -> bool:
    """Results with platform paths (the unicycle) get the platform figures."""
    return any(r.platform is not None for r in result.runs.values())


def _theta_label(result: DashboardResult) -> str:
    if result.state.mode == "discrete":
        return "iteration"
    return f"θ (continuation parameter, γ = {result.state.gamma:g})"


def _leg_names(n: int) -> list[str]:
    return [chr(ord("A") + i) if i < 26 else f"P{i + 1}" for i in range(n)]


def _trace(kind: str, **props) -> dict:
    return {"type": kind, **props}


#: Layout of the panels whose traces are the two algorithms: no legend (the page's header
#: names the colours; a legend costs a fifth of a panel's redraw in the browser test), the
#: other marks named in the title, and the bottom margin the legend took given back.
_NO_LEGEND = dict(showlegend=False, margin=dict(l=64, r=20, t=48, b=48))


def _figure(data: list, title: str, **layout) -> dict:
    """A figure dict (a spec) with the panels' common layout, not validated by plotly (the
    server builds every panel on each change); tests/app/test_figures.py validates every one."""
    base = {**_LAYOUT, "title": dict(text=title, font=dict(size=13), x=0.01, xanchor="left")}
    for key, axis in layout.items():  # an axis title given as text (validation did this)
        if key.startswith(("xaxis", "yaxis")) and isinstance(axis.get("title"), str):
            layout[key] = {**axis, "title": {"text": axis["title"]}}
    return {"data": data, "layout": {**base, **layout}}


def _go(spec: dict) -> go.Figure:
    return go.Figure(data=spec["data"], layout=spec["layout"], _validate=False)


#: numpy dtypes plotly.js takes as typed arrays (base64), by their plotly.js names.
_TYPED = {"float64": "f8", "float32": "f4", "int32": "i4", "uint32": "u4", "int16": "i2",
          "uint16": "u2", "int8": "i1", "uint8": "u1"}  # fmt: skip


def _typed_array(v: np.ndarray):
    """``v`` as plotly.js's typed-array spec (base64 of the bytes, as plotly.py >= 6 sends it);
    64-bit integers narrowed to 32 bits, anything else as a list."""
    if v.dtype.kind in "iu" and v.size and v.dtype.itemsize == 8:
        if np.iinfo(np.int32).min <= v.min() and v.max() <= np.iinfo(np.int32).max:
            v = v.astype(np.int32)
    name = _TYPED.get(str(v.dtype))
    if name is None or not v.size:
        return _plain(v.tolist())
    out = {"dtype": name, "bdata": base64.b64encode(v.tobytes()).decode("ascii")}
    if v.ndim > 1:
        out["shape"] = ", ".join(str(n) for n in v.shape)
    return out


def _plain(v):
    """``v`` with numpy values made JSON's (arrays typed) and non-finite numbers null."""
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, list | tuple):
        return [_plain(x) for x in v]
    if isinstance(v, np.ndarray):
        return _typed_array(v)
    if isinstance(v, float | np.floating):
        return float(v) if math.isfinite(v) else None
    if isinstance(v, np.integer | np.bool_):
        return v.item()
    return v


def figure_json(spec: dict) -> str:
    """The JSON plotly.js reads for a figure dict (what ``go.Figure(spec).to_json()`` gives,
    about 5x faster: no property objects, no deep copies)."""
    return json.dumps(_plain(spec), separators=(",", ":"), allow_nan=False)


def nice_range(values, pad: float = 0.05, from_zero: bool = False) -> list[float] | None:
    """An axis range around ``values``: padded by ``pad`` of their span, then widened to
    multiples of a 1-2-5 step near a tenth of the span (``from_zero``: from 0, unpadded).

    Nearby data give the same range, so a small change of a control leaves the figure's layout
    unchanged and the page moves only the traces (``Plotly.animate`` in static/panels.js, a third
    of a full redraw). None when there is nothing finite to show (plotly then autoranges).
    """
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if not v.size:
        return None
    lo, hi = float(v.min()), float(v.max())
    span = hi - lo
    if span <= 1e-9 * max(abs(lo), abs(hi)):  # constant up to rounding: a tenth around
        span = max(abs(hi), 1.0) * 0.1
    raw = span / 10
    step = 10.0 ** np.floor(np.log10(raw))
    step *= next(m for m in (1, 2, 5, 10) if m * step >= raw)

    def tidy(x: float) -> float:  # (0.30000000000000004 -> 0.3)
        return float(f"{x:.12g}")

    if from_zero:  # (an axis like theta: the data start at its left edge)
        return [0.0, tidy(np.ceil(hi / step) * step)]
    return [tidy(np.floor((lo - pad * span) / step) * step),
            tidy(np.ceil((hi + pad * span) / step) * step)]  # fmt: skip


def _log_range(values) -> list[float] | None:
    """A log axis's range (decades, as plotly takes it) to the half decade around the
    positive ``values``, with a half decade of margin: stable like :func:`nice_range`."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v) & (v > 0)]
    if not v.size:
        return None
    lo, hi = np.log10(v.min()), np.log10(v.max())
    return [float(np.floor(2 * lo) / 2 - 0.5), float(np.ceil(2 * hi) / 2 + 0.5)]


#: An axis keeps its range while the data span at least this fraction of it (:func:`keep_ranges`).
KEEP_FILL = 0.5


def _axis_data(spec: dict) -> dict[str, list]:
    """The values plotted along each axis of a figure dict (layout name -> sequences)."""
    out: dict[str, list] = {}
    for t in spec["data"]:
        for axis in ("x", "y"):
            values = t.get(axis)
            if values is not None:
                ref = t.get(f"{axis}axis") or axis
                out.setdefault(f"{axis}axis{ref[1:]}", []).append(values)
    return out


def keep_ranges(spec: dict, before: dict | None) -> dict:
    """Sticky axes: an axis of the figure dict ``spec`` takes the range it had in ``before``
    (the layout of the panel on screen) when the new data lie inside it and span at least
    :data:`KEEP_FILL` of it. Dragging a slider then does not make the axes jump, and the page
    moves the lines without redrawing the panel (static/panels.js). Axes with a fixed tick step
    (the cycles of the drift panel), without a range or with categories are left alone."""
    if not before:
        return spec
    layout = spec["layout"]
    for name, arrays in _axis_data(spec).items():
        axis, old = layout.get(name) or {}, (before.get(name) or {}).get("range")
        if axis.get("range") is None or old is None or axis.get("dtick") is not None:
            continue
        try:
            v = np.concatenate([np.asarray(a, dtype=float).ravel() for a in arrays])
        except ValueError:  # (categories: not a numeric axis)
            continue
        if axis.get("type") == "log":
            v = np.log10(v[v > 0])
        v = v[np.isfinite(v)]
        lo, hi = float(old[0]), float(old[1])
        if v.size and lo <= v.min() and v.max() <= hi and np.ptp(v) >= KEEP_FILL * (hi - lo):
            layout[name] = {**axis, "range": [lo, hi]}
    return spec


def _stacked_axes(n: int, gap: float = 0.04) -> dict:
    """Layout of n y-axes stacked over one shared x-axis (instead of make_subplots)."""
    h = (1.0 - gap * (n - 1)) / n
    out = {}
    for k in range(n):
        top = 1.0 - k * (h + gap)
        lo, hi = max(0.0, round(top - h, 6)), min(1.0, round(top, 6))
        out["yaxis" if k == 0 else f"yaxis{k + 1}"] = dict(domain=[lo, hi], anchor="x")
    out["xaxis"] = dict(anchor=f"y{n}" if n > 1 else "y")
    return out


def _task_space(result: DashboardResult) -> dict:
    """End-effector paths of both algorithms in the task plane (paper, Figs. 5 and 6)."""
    _, tu = _units(result)
    n1, n2 = result.task_names[:2]
    data = []
    for a in ALGORITHMS:
        run = result.runs[a]
        data.append(
            _trace("scatter",
                x=run.y[:, 0], y=run.y[:, 1], mode="lines", name=LABELS[a],
                line=dict(color=COLORS[a], width=4 if a == "pseudoinverse" else 1.8,
                          dash="solid" if a == "pseudoinverse" else "dash"),
                customdata=run.leg + 1,  # (theta stays out: this panel does not depend on gamma)
                hovertemplate=f"{n1} = %{{x:.4f}}<br>{n2} = %{{y:.4f}}"
                "<br>leg %{customdata}<extra>" + a + "</extra>",
            )
        )  # fmt: skip
    tg = result.targets
    x0y = result.runs["pseudoinverse"].y[0]
    data.append(
        _trace("scatter",
            x=tg[:, 0], y=tg[:, 1], mode="markers+text", name="targets",
            text=_leg_names(len(tg)), textposition="top right",
            marker=dict(color="black", size=9, symbol="x"),
            hovertemplate=f"%{{text}}: ({n1}, {n2}) = (%{{x:.3f}}, %{{y:.3f}})<extra></extra>",
        )
    )  # fmt: skip
    data.append(
        _trace("scatter",
            x=[x0y[0]], y=[x0y[1]], mode="markers", name="start k(x0)",
            marker=dict(color="#2ca02c", size=12, symbol="circle-open", line=dict(width=2)),
            hovertemplate="start (%{x:.3f}, %{y:.3f})<extra></extra>",
        )
    )  # fmt: skip
    points = np.vstack([result.runs[a].y[:, :2] for a in ALGORITHMS] + [tg[:, :2]])
    return _figure(
        data,
        "Task-space paths (Figs. 5, 6)<br><sup>solid: J<sup>P#</sup>, dashed: J<sup>E#</sup>"
        " · × targets of the legs · ○ start k(x0)</sup>",
        **_NO_LEGEND,
        xaxis=dict(title=_label(n1, tu[0]), range=nice_range(points[:, 0])),
        yaxis=dict(title=_label(n2, tu[1]), range=nice_range(points[:, 1]), scaleanchor="x",
                   scaleratio=1),
    )  # fmt: skip


def _joints(result: DashboardResult) -> dict:
    """Every joint variable against theta for both algorithms (Figs. 7-9; Figs. 11-14 b, c)."""
    ju, _ = _units(result)
    names = result.variable_names
    data = []
    for a in ALGORITHMS:
        run = result.runs[a]
        for k, name in enumerate(names):
            data.append(
                _trace("scatter",
                    x=run.theta, y=run.x[:, k], mode="lines", name=LABELS[a],
                    legendgroup=a, showlegend=k == 0, line=dict(color=COLORS[a], width=1.8),
                    xaxis="x", yaxis="y" if k == 0 else f"y{k + 1}",
                    hovertemplate=f"{name} = %{{y:.5f}}<br>θ = %{{x:.4g}}<extra>{a}</extra>",
                )
            )  # fmt: skip
    axes = _stacked_axes(len(names))
    runs = [result.runs[a] for a in ALGORITHMS]
    for k, name in enumerate(names):
        axis = axes["yaxis" if k == 0 else f"yaxis{k + 1}"]
        axis["title"] = _label(name, ju[k])
        axis["range"] = nice_range(np.concatenate([r.x[:, k] for r in runs]))
    axes["xaxis"]["title"] = _theta_label(result)
    axes["xaxis"]["range"] = nice_range(np.concatenate([r.theta for r in runs]), from_zero=True)
    title = (
        "Controls λ against the iteration (Figs. 11-14 b, c)"
        if is_unicycle(result)
        else "Joint trajectories (Figs. 7-9)"
    )
    return _figure(data, title, height=120 * len(names) + 100, **_NO_LEGEND, **axes)


def _drift(result: DashboardResult) -> dict:
    """Repeatability drift ||x(end of cycle c) - x0|| per cycle, log scale (Table 1's point).

    For a single-target task (and the unicycle) the task error against theta is shown instead.
    """
    data = []
    closed = result.state.task == "path"
    for a in ALGORITHMS:
        run = result.runs[a]
        if closed:
            data.append(
                _trace("scatter",
                    x=np.arange(1, len(run.drift) + 1), y=np.maximum(run.drift, 1e-16),
                    mode="lines+markers", name=LABELS[a], line=dict(color=COLORS[a], width=2),
                    marker=dict(symbol=_SYMBOLS[a], size=9),
                    hovertemplate="cycle %{x}: drift %{y:.3e}<extra>" + a + "</extra>",
                )
            )  # fmt: skip
        else:
            data.append(
                _trace("scatter",
                    x=run.theta, y=np.maximum(run.error, 1e-16), mode="lines", name=LABELS[a],
                    line=dict(color=COLORS[a], width=2),
                    hovertemplate="‖k(x) − y_d‖ = %{y:.3e}<br>θ = %{x:.4g}<extra>" + a + "</extra>",
                )
            )  # fmt: skip
    ys = np.concatenate([np.asarray(t["y"], dtype=float) for t in data])
    if closed:
        cycles = max(len(result.runs[a].drift) for a in ALGORITHMS)
        return _figure(
            data,
            "Repeatability: joint drift after each closed cycle",
            **_NO_LEGEND,
            xaxis=dict(title="cycle", dtick=1, range=[0.5, cycles + 0.5]),
            yaxis=dict(title="‖x(end of cycle) − x0‖ (log)", type="log", exponentformat="power",
                       range=_log_range(ys)),
        )  # fmt: skip
    theta = np.concatenate([result.runs[a].theta for a in ALGORITHMS])
    return _figure(
        data,
        "Convergence: task error",
        **_NO_LEGEND,
        xaxis=dict(title=_theta_label(result), range=nice_range(theta, from_zero=True)),
        yaxis=dict(title="‖k(x) − y_d‖ (log)", type="log", exponentformat="power",
                   range=_log_range(ys)),
    )  # fmt: skip


def _table(result: DashboardResult) -> dict:
    """The configuration after every leg for both algorithms, as in Table 1 of the paper."""
    names = result.variable_names
    L = len(result.targets)
    legs = _leg_names(L)
    rows = max(len(result.runs[a].leg_end) for a in ALGORITHMS)
    point = ["start x0"] + [
        f"{c // L + 1}: {legs[c % L]} {_fmt_point(result.targets[c % L])}" for c in range(rows)
    ]
    cols: list[list[str]] = [point]
    header = ["cycle: point"]
    for a in ALGORITHMS:
        ends = np.vstack([np.asarray(result.state.x0)[None, :], result.runs[a].leg_end])
        for k, name in enumerate(names):
            header.append(f"{'J^P#' if a == 'pseudoinverse' else 'J^E#'} {name}")
            cols.append([cell(v, 0) for v in ends[:, k]] + [""] * (rows + 1 - len(ends)))
    fills = ["#f4f4f4"] + ["#fbe3e3" if h.startswith("J^P#") else "#e1ecf7" for h in header[1:]]
    table = _trace("table",
        # (fill=dict(color=...): plotly.py's "fill_color" shorthand is expanded only by its
        # validation, which the builders skip; the page reads fill.color)
        header=dict(values=header, fill=dict(color=fills), font=dict(size=11), align="center"),
        cells=dict(values=cols, font=dict(size=11, family="monospace"), align="right",
                   fill=dict(color=[["white", "#f7f7f7"] * (rows + 1)])),
    )  # fmt: skip
    return _figure(
        [table], "Configurations after each leg (Table 1)", margin=dict(l=10, r=10, t=40, b=10)
    )


def _fmt_point(p) -> str:
    return "(" + ", ".join(f"{v:.3g}" for v in p) + ")"


def _platform(result: DashboardResult, max_paths: int = 12) -> dict:
    """Unicycle platform paths q(t) in the (q1, q2) plane, per iteration (Figs. 11-14 a)."""
    _, tu = _units(result)
    data = []
    annotations = []
    for col, a in enumerate(ALGORITHMS, start=1):
        xa, ya = ("x", "y") if col == 1 else ("x2", "y2")
        P = result.runs[a].platform
        assert P is not None  # drawn only for the unicycle, whose runs all carry platform paths
        m = len(P)
        show = sorted(set(np.geomspace(1, m, num=max_paths).astype(int) - 1) | {0, m - 1})
        for n, i in enumerate(show):
            last = bool(i == m - 1)
            data.append(
                _trace("scatter",
                    x=P[i, :, 0], y=P[i, :, 1], mode="lines", xaxis=xa, yaxis=ya,
                    name=LABELS[a] if last else f"{a} iteration {i}", legendgroup=a,
                    showlegend=last, line=dict(color=COLORS[a], width=3 if last else 1),
                    opacity=1.0 if last else 0.2 + 0.5 * n / max(len(show), 1),
                    customdata=result.time,
                    hovertemplate=f"iteration {i}<br>q1 = %{{x:.3f}}<br>q2 = %{{y:.3f}}"
                    "<br>t = %{customdata:.2f}<extra>" + a + "</extra>",
                )
            )  # fmt: skip
        q0 = result.state.robot_parameters.get("q0", P[0, 0])
        target = result.state.target
        data.append(
            _trace("scatter",
                x=[q0[0], target[0]], y=[q0[1], target[1]], xaxis=xa, yaxis=ya,
                mode="markers+text", text=["q0", "target"], textposition="top center",
                marker=dict(color=["#2ca02c", "black"], size=10, symbol=["circle", "x"]),
                showlegend=False, hovertemplate="%{text}: (%{x:.3f}, %{y:.3f})<extra></extra>",
            )
        )  # fmt: skip
        annotations.append(
            dict(text=LABELS[a], xref=f"{xa} domain", yref=f"{ya} domain", x=0.5, y=1.0,
                 yanchor="bottom", showarrow=False, font=dict(size=11, color=COLORS[a]))
        )  # fmt: skip
    return _figure(
        data,
        "Platform paths q(t) per iteration (Figs. 11-14 a)",
        xaxis=dict(domain=[0, 0.48], title=_label("q1", tu[0])),
        xaxis2=dict(domain=[0.52, 1], title=_label("q1", tu[0]), matches="x"),
        yaxis=dict(title=_label("q2", tu[1]), scaleanchor="x", scaleratio=1),
        yaxis2=dict(anchor="x2", matches="y", showticklabels=False),
        annotations=annotations,
        showlegend=False,  # (each plot is named above it)
        margin=dict(l=64, r=20, t=64, b=48),
    )


def _augmenting(result: DashboardResult, functionals: dict | None = None) -> dict:
    """Contours of the augmenting map h over two joint variables with both trajectories on top.

    The extended Jacobian keeps h constant (eq. (12)), so its trajectory follows a level curve;
    the pseudoinverse crosses them. The title carries E1 (13) and E2 (18) over the plotted box.

    The trajectories and the start x0 are layout shapes over the contour trace, not traces: a
    change that keeps h on its box then moves them by a relayout of the shapes, a few ms in the
    page, and the contours stay (plotly's animation of traces would drop a contour's layer, and
    drawing the panel anew takes ten times as long). Hover gives h; the joint values along
    the runs are in the joint panel.
    """
    ju, _ = _units(result)
    grid = result.augmenting
    if grid is None:
        return _figure([], augmenting_title(result))
    i, j = grid["axes"]
    ni, nj = result.variable_names[i], result.variable_names[j]
    H = grid["h"]
    finite = H[np.isfinite(H)]
    zmin, zmax = np.percentile(finite, [2, 98]) if finite.size else (0.0, 1.0)
    data = [
        _trace("contour",
            x=grid["u"], y=grid["v"], z=H, zmin=zmin, zmax=zmax,
            # A neutral scale, so that the red and blue runs on top stay the algorithms' colours.
            colorscale=[[0.0, "#fdfdfd"], [1.0, "#9a9a9a"]],
            # No labels on the level curves: placing them costs the page 100-250 ms per redraw;
            # the colour bar and the hover give the levels.
            ncontours=24, contours=dict(showlabels=False),
            colorbar=dict(
                title=dict(text="h", side="right"), thickness=12, ticklabeloverflow="allow"
            ),
            hovertemplate=f"{ni} = %{{x:.3f}}<br>{nj} = %{{y:.3f}}<br>h = %{{z:.4f}}"
            "<extra></extra>",
            name="h", showlegend=False,
        )
    ]  # fmt: skip
    shapes: list[dict[str, Any]] = [
        dict(type="path", path=_svg_path(result.runs[a].x[:, i], result.runs[a].x[:, j]),
             line=dict(color=COLORS[a], width=2.5), name=LABELS[a])
        for a in ALGORITHMS
    ]  # fmt: skip
    x0 = result.state.x0
    shapes.append(  # (a circle of 10 px at x0, whatever the axes' scales)
        dict(type="circle", xsizemode="pixel", ysizemode="pixel", xanchor=float(x0[i]),
             yanchor=float(x0[j]), x0=-5, x1=5, y0=-5, y1=5, fillcolor="white",
             line=dict(color="black", width=2), name="x0")
    )  # fmt: skip
    return _figure(
        data,
        augmenting_title(result, functionals),
        **_NO_LEGEND,
        shapes=shapes,
        xaxis=dict(title=_label(ni, ju[i])),
        yaxis=dict(title=_label(nj, ju[j])),
    )


def _svg_path(x: np.ndarray, y: np.ndarray) -> str:
    """A polyline through (x, y) in data coordinates, as a plotly path shape takes it (six
    significant digits: under a pixel at a hundredfold zoom of a panel)."""
    points = "L".join(f"{u:.6g},{v:.6g}" for u, v in zip(x.tolist(), y.tolist(), strict=True))
    return "M" + points


def augmenting_title(result: DashboardResult, functionals: dict | None = None) -> str:
    """Title of the h panel: the map, E1 and E2 on the plotted box, the fixed variables."""
    title = f"Augmenting map h: {result.state.augmentation}"
    grid = result.augmenting
    if grid is None:
        return title + " (computing h on a grid…)"
    i, j = grid["axes"]
    x0 = result.state.x0
    sub = []
    if functionals:
        values = {k: functionals.get(k) for k in ("E1", "E2")}
        where = "the plotted box"
        if functionals.get("design_region"):
            where = ", ".join(f"{k} ∈ [{lo:.3g}, {hi:.3g}]" for k, (lo, hi)
                              in functionals["region"].items())  # fmt: skip
        if all(v is None for v in values.values()):
            sub.append(f"E1, E2 undefined: h is not defined on all of {where}")
        else:
            sub.append(", ".join(
                f"{k} = {v:.4g}" if v is not None else f"{k} undefined" for k, v in values.items()
            ) + f" on {where}")  # fmt: skip
    # The slice's other variables, unless neither h nor J depends on them (Manipulator 2's x1
    # for h(x2, x3)): their values would say nothing, and the title would change with them.
    inert = state_inert_variables(result.state)
    fixed = [
        f"{n} = {x0[k]:.3g}"
        for k, n in enumerate(result.variable_names)
        if k not in (i, j) and k not in inert
    ]
    if fixed:
        sub.append("at " + ", ".join(fixed))
    sub.append("○ x0")
    if sub:
        title += "<br><sup>" + " · ".join(sub) + "</sup>"
    return title


#: Colours of the functionals (the algorithms keep red and blue).
E_COLORS = {"E1": "#2ca02c", "E2": "#9467bd"}


def _sensitivity(result: DashboardResult, sens: dict | None = None) -> dict:
    """E1 (13) and E2 (18) of the current map and how they change (issue 5).

    With parameters: each functional against each parameter (swept around its current value,
    which is marked), on a log scale. Without: the functionals of the robot's other maps.
    ``sens`` comes from :func:`jik.app.dashboard.analysis.sensitivity` (the dashboard's second
    phase).
    """
    aug = result.state.augmentation
    if sens is None:
        return _figure([], f"E1, E2 of {aug}: computing…")
    if sens["kind"] == "unavailable":
        return _figure([], f"E1, E2 of {aug}<br><sup>{sens['reason']}</sup>")
    log = dict(type="log", exponentformat="power")
    if sens["kind"] == "alternatives":
        maps = sens["maps"]
        names = [m["name"] + (" (current)" if m["current"] else "") for m in maps]
        data = [
            _trace("bar", x=names, y=[m[k] for m in maps], name=k,
                   marker=dict(color=E_COLORS[k],
                               line=dict(color=["black" if m["current"] else E_COLORS[k]
                                                for m in maps], width=2)),
                   hovertemplate="%{x}: " + k + " = %{y:.4g}<extra></extra>")
            for k in ("E1", "E2")
        ]  # fmt: skip
        return _figure(
            data,
            f"E1 (13), E2 (18) of the maps of this robot<br><sup>{aug} has no parameters: "
            "the alternatives on the same box</sup>",
            barmode="group",
            yaxis=dict(title="E (log)", **log),
        )
    params = sens["parameters"]
    names = list(params)
    n = len(names)
    data, layout = [], {}
    gap = 0.08
    width = (1.0 - gap * (n - 1)) / n
    for c, name in enumerate(names):
        xa, ya = ("x", "y") if c == 0 else (f"x{c + 1}", f"y{c + 1}")
        for k in ("E1", "E2"):
            sweep = sens[k]["sweeps"][name]
            data.append(_trace("scatter", x=sweep["values"], y=sweep["functional"],
                               mode="lines", name=k, legendgroup=k, showlegend=c == 0,
                               line=dict(color=E_COLORS[k], width=2), xaxis=xa, yaxis=ya,
                               hovertemplate=f"{name} = %{{x:.3g}}<br>{k} = %{{y:.4g}}"
                               "<extra></extra>"))  # fmt: skip
            if sens[k]["value"] is not None:
                data.append(_trace("scatter", x=[params[name]], y=[sens[k]["value"]],
                                   mode="markers", name=f"current {k}", showlegend=False,
                                   marker=dict(color="white", size=9,
                                               line=dict(color=E_COLORS[k], width=2)),
                                   xaxis=xa, yaxis=ya,
                                   hovertemplate=f"current {name} = %{{x:.3g}}<br>{k} = "
                                   "%{y:.4g}<extra></extra>"))  # fmt: skip
        lo = c * (width + gap)
        layout["xaxis" if c == 0 else f"xaxis{c + 1}"] = dict(
            domain=[round(lo, 6), round(min(1.0, lo + width), 6)], title=name,
            anchor=ya,
        )  # fmt: skip
        layout["yaxis" if c == 0 else f"yaxis{c + 1}"] = dict(
            anchor=xa, **log, **({"title": "E (log)"} if c == 0 else {})
        )
    slopes = []
    for k in ("E1", "E2"):
        g = sens[k]["gradient"]
        slopes.append(", ".join(
            f"∂{k}/∂{p} = {g[p]:.3g}" if g.get(p) is not None else f"∂{k}/∂{p} undefined"
            for p in names
        ))  # fmt: skip
    at = ", ".join(f"{p} = {v:.3g}" for p, v in params.items())
    return _figure(
        data,
        f"E1 (13), E2 (18) as the parameters of {aug} move"
        f"<br><sup>at {at} (circles): {'; '.join(slopes)}</sup>",
        **layout,
    )


def gamma_free_panels(result: DashboardResult) -> set[str]:
    """Panels that do not change with gamma in continuous mode (theta is not on their axes)."""
    if result.state.mode != "continuous":
        return set()
    panels = {"table", "augmenting"} | ({"task"} if not is_unicycle(result) else set())
    return panels | ({"drift"} if result.state.task == "path" else set())


def figure_specs(
    result: DashboardResult,
    functionals: dict | None = None,
    only: set[str] | None = None,
    sensitivity: dict | None = None,
) -> dict[str, dict]:
    """The panels of the dashboard for ``result`` (all, or those in ``only``) as figure dicts,
    keyed by id: what the dashboard serializes with :func:`figure_json`."""
    builders = {
        "task": _platform if is_unicycle(result) else _task_space,
        "joints": _joints,
        "drift": _drift,
        "table": _table,
        "augmenting": lambda r: _augmenting(r, functionals),
        "sensitivity": lambda r: _sensitivity(r, sensitivity),
    }
    return {k: f(result) for k, f in builders.items() if only is None or k in only}


def figures_for(
    result: DashboardResult,
    functionals: dict | None = None,
    only: set[str] | None = None,
    sensitivity: dict | None = None,
) -> dict[str, go.Figure]:
    """The panels of the dashboard for ``result`` (all, or those in ``only``), keyed by id."""
    return {k: _go(v) for k, v in figure_specs(result, functionals, only, sensitivity).items()}


# The figures as plotly objects, for notebooks and tests.


def task_space_figure(result: DashboardResult) -> go.Figure:
    """End-effector paths of both algorithms in the task plane (paper, Figs. 5 and 6)."""
    return _go(_task_space(result))


def joint_figure(result: DashboardResult) -> go.Figure:
    """Every joint variable against theta for both algorithms (Figs. 7-9; Figs. 11-14 b, c)."""
    return _go(_joints(result))


def drift_figure(result: DashboardResult) -> go.Figure:
    """Repeatability drift per closed cycle, log scale (Table 1), or the task error against
    theta for a single target."""
    return _go(_drift(result))


def table_figure(result: DashboardResult) -> go.Figure:
    """The configuration after every leg for both algorithms, as in Table 1 of the paper."""
    return _go(_table(result))


def platform_figure(result: DashboardResult, max_paths: int = 12) -> go.Figure:
    """Unicycle platform paths q(t) in the (q1, q2) plane, per iteration (Figs. 11-14 a)."""
    return _go(_platform(result, max_paths))


def augmenting_figure(result: DashboardResult, functionals: dict | None = None) -> go.Figure:
    """Contours of h over two joint variables with both trajectories on top; E1 (13) and
    E2 (18) in the title."""
    return _go(_augmenting(result, functionals))


def sensitivity_figure(result: DashboardResult, sens: dict | None = None) -> go.Figure:
    """E1 (13) and E2 (18) of the current map and how they change with its parameters."""
    return _go(_sensitivity(result, sens))
