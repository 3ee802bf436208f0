"""What every panel shares: units and labels, the style of the axes and traces, figure dicts
serialized without ``go.Figure`` (typed arrays as base64), and axis ranges that stay put while
the data fill them (:func:`nice_range`, :func:`keep_ranges`)."""

from __future__ import annotations

import base64
import json

import numpy as np

from ...engine.exports import json_values
from ...engine.reproductions.table1 import corner_letters
from ...engine.units import norm_unit as norm_unit  # (the panels' and the atlas's)
from ...engine.units import robot_units
from .robots import state_kinematics
from .runs import DashboardResult

PANEL_HEIGHT = 380
#: Panel ids, in the page's order, with their size on the page's grid ("wide": a whole row,
#: "tall": two rows).
PANEL_SIZES = {
    "task": "wide",
    "drift": "",
    "joints": "tall",
    "augmenting": "",
    "sensitivity": "",
    "cspace": "full",
    "table": "wide",
}
PANELS = tuple(PANEL_SIZES)
AXIS = dict(
    gridcolor="#e6e6e6",
    zerolinecolor="#b0b0b0",
    linecolor="#888",
    showline=True,
    mirror=True,
    ticks="outside",
    automargin=True,
    # plotly's default on linear axes, "hide past div", measures every tick label's box
    # (a forced layout each) on every redraw, milliseconds per panel.
    ticklabeloverflow="allow",
)
# A small explicit template: the named ones ("plotly_white") cost ~25 ms per figure to apply.
TEMPLATE = dict(
    layout=dict(
        paper_bgcolor="white",
        plot_bgcolor="white",
        xaxis=AXIS,
        yaxis=AXIS,
        colorway=["#d62728", "#1f77b4", "#2ca02c", "#9467bd"],
    )
)
#: A panel's right margin: room for plotly's toolbar, drawn upright beside the plots (below;
#: the page starts it at the plots' top) so that it covers neither the title nor the plots.
RIGHT = 30
#: The right margin's room for a colour bar beside the plots (its bar, ticks and title), left of
#: the toolbar's.
COLORBAR = 96

LAYOUT = dict(
    template=TEMPLATE,
    height=PANEL_HEIGHT,
    margin=dict(l=64, r=RIGHT, t=40, b=100),
    legend=dict(orientation="h", yanchor="top", y=-0.2, xanchor="left", x=0, font=dict(size=10)),
    font=dict(size=11),
    hovermode="closest",
    uirevision="keep",  # keep the user's zoom across updates of the same robot
    modebar=dict(orientation="v"),
)


def units(result: DashboardResult) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The units of x and of y (:func:`jik.engine.units.robot_units`; "": not stated)."""
    described = robot_units(state_kinematics(result.state), result.task_names)
    return described.x, described.y


def label(name: str, unit: str) -> str:
    return f"{name} [{unit}]" if unit else name


def is_unicycle(result: DashboardResult) -> bool:
    """Results with platform paths (the unicycle) get the platform figures."""
    return any(r.platform is not None for r in result.runs.values())


def theta_axis(result: DashboardResult) -> dict:
    """The axis of theta (the iteration in discrete mode), from 0 over every run."""
    theta = np.concatenate([r.theta for r in result.runs.values()])
    gamma = f"θ (continuation parameter, γ = {result.state.gamma:g})"
    title = "iteration" if result.state.mode == "discrete" else gamma
    return dict(title=title, range=nice_range(theta, from_zero=True))


def corner_names(result: DashboardResult) -> list[str]:
    """The letters of the task's corners
    (:func:`jik.engine.reproductions.table1.corner_letters`); a single target is "target" (a
    letter would clash with the paper's: its A is (1, 1) of Manipulator 2 and a start of the
    unicycle)."""
    if result.state.task == "target":
        return ["target"]
    start = next(iter(result.runs.values())).y[0]
    return corner_letters(result.targets, start, result.state.task == "path")


def trace(kind: str, **props) -> dict:
    return {"type": kind, **props}


def note(text: str, x, y, xref="paper", yref="paper", color=None, size=11, **more) -> dict:
    """A text without an arrow at (x, y) of ``xref``, ``yref`` (the figure's paper, an axis or
    its domain), in ``color`` (plotly's default: None); ``more``: its other properties."""
    font = dict(size=size) if color is None else dict(size=size, color=color)
    return dict(text=text, x=x, y=y, xref=xref, yref=yref, showarrow=False, font=font, **more)


#: Layout of the panels whose traces are the two algorithms: no legend (the page's header
#: names the colours; a legend costs a fifth of a panel's redraw in the browser test), the
#: other marks named in the title, and the bottom margin the legend took given back.
NO_LEGEND_MARGIN = dict(l=64, r=RIGHT, t=48, b=48)
NO_LEGEND = dict(showlegend=False, margin=NO_LEGEND_MARGIN)


def figure(data: list, title: str, **layout) -> dict:
    """A figure dict (a spec) with the panels' common layout, not validated by plotly (the
    server builds every panel on each change); tests/app/test_figures.py validates every one."""
    # The title hangs from the top; the top margin has room for each of its lines.
    base = {
        **LAYOUT,
        "title": dict(
            text=title,
            font=dict(size=13),
            x=0.01,
            xanchor="left",
            yref="container",
            y=1.0,
            yanchor="top",
            pad=dict(t=12),
        ),
    }
    margin = dict(layout.get("margin", LAYOUT["margin"]))
    margin["t"] = max(margin.get("t", 40), 40 + 16 * title.count("<br>"))
    layout["margin"] = margin
    for key, axis in layout.items():  # an axis title given as text (validation did this)
        if key.startswith(("xaxis", "yaxis")) and isinstance(axis.get("title"), str):
            layout[key] = {**axis, "title": {"text": axis["title"]}}
    return {"data": data, "layout": {**base, **layout}}


#: The typed arrays plotly.js takes (base64), by their names, which are numpy's type codes.
TYPED = {"f8", "f4", "i4", "u4", "i2", "u2", "i1", "u1"}


def typed_array(v: np.ndarray):
    """``v`` as plotly.js's typed-array spec (base64 of the bytes, as plotly.py >= 6 sends it);
    64-bit integers narrowed to 32 bits, anything else as a list."""
    if v.dtype.kind in "iu" and v.size and v.dtype.itemsize == 8:
        if np.iinfo(np.int32).min <= v.min() and v.max() <= np.iinfo(np.int32).max:
            v = v.astype(np.int32)
    name = v.dtype.str[1:]  # ("<f8": native little-endian float64 -> "f8")
    if name not in TYPED or v.dtype.byteorder == ">" or not v.size:
        return json_values(v)
    out = {"dtype": name, "bdata": base64.b64encode(v.tobytes()).decode("ascii")}
    if v.ndim > 1:
        out["shape"] = ", ".join(str(n) for n in v.shape)
    return out


def plain(v):
    """``v`` as JSON values by the engine's rule (:func:`jik.engine.exports.json_values`:
    non-finite numbers null), its arrays typed."""
    if isinstance(v, dict):
        return {k: plain(x) for k, x in v.items()}
    if isinstance(v, list | tuple):
        return [plain(x) for x in v]
    return typed_array(v) if isinstance(v, np.ndarray) else json_values(v)


def figure_json(spec: dict) -> str:
    """The JSON plotly.js reads for a figure dict (what ``go.Figure(spec).to_json()`` gives,
    about 5x faster: no property objects, no deep copies)."""
    return json.dumps(plain(spec), separators=(",", ":"), allow_nan=False)


def nice_range(values, pad: float = 0.05, from_zero: bool = False) -> list[float] | None:
    """An axis range around ``values``: padded by ``pad`` of their span, then widened to
    multiples of a 1-2-5 step near a tenth of the span (``from_zero``: from 0, unpadded), so
    that nearby data give the same range and the page only moves the traces. None when there is
    nothing finite to show (plotly then autoranges).
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
    return [
        tidy(np.floor((lo - pad * span) / step) * step),
        tidy(np.ceil((hi + pad * span) / step) * step),
    ]


def log_range(values) -> list[float] | None:
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


def axis_data(spec: dict) -> dict[str, list]:
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
    :data:`KEEP_FILL` of it. Axes with a fixed tick step (the cycles of the drift panel),
    without a range or with categories are left alone."""
    if not before:
        return spec
    layout = spec["layout"]
    for name, arrays in axis_data(spec).items():
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


def side_by_side(n: int, gap: float) -> list[list[float]]:
    """The x domains of n plots side by side, ``gap`` (of the width) between them."""
    width = (1.0 - gap * (n - 1)) / n
    lows = [c * (width + gap) for c in range(n)]
    return [[round(lo, 6), round(min(1.0, lo + width), 6)] for lo in lows]


def stacked_axes(n: int) -> dict:
    """Layout of n y-axes stacked over one shared x-axis (instead of make_subplots), 0.04 of
    the height between them (:func:`side_by_side`'s domains, top down)."""
    out = {}
    for k, domain in enumerate(reversed(side_by_side(n, 0.04))):
        out["yaxis" if k == 0 else f"yaxis{k + 1}"] = dict(domain=domain, anchor="x")
    out["xaxis"] = dict(anchor=f"y{n}" if n > 1 else "y")
    return out
