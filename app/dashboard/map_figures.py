"""The panels of the augmenting map: h on a grid with both runs over it (its title carries E1
and E2 of section 5), and E1, E2 against the map's parameters or against the robot's other
maps."""

from __future__ import annotations

import textwrap
from typing import Any

import numpy as np

from ...engine.functional_report import plus_minus, region_words, report_words
from .algorithms import COLORS, DASH, LABELS
from .analysis import vector_note
from .functionals import state_inert_variables
from .plotting import (
    COLORBAR,
    NO_LEGEND_MARGIN,
    RIGHT,
    figure,
    label,
    note,
    side_by_side,
    trace,
    units,
)
from .robots import state_spec
from .runs import DashboardResult


def augmenting_spec(
    result: DashboardResult, functionals: dict | None = None, cancelled: str | None = None
) -> dict:
    """Contours of the augmenting map h over two joint variables with the runs on top (the
    extended Jacobian's follows a level curve, eq. (12)); the title carries E1 (13) and E2 (18).

    The runs and the start x0 are layout shapes over the contour trace, not traces: a change
    that keeps h on its box then moves them by a relayout, and the contours stay (plotly's
    animation of traces would drop a contour's layer). ``cancelled``: the second phase was
    cancelled (how), so E1, E2 (and h, without its grid) were not computed.
    """
    ju, _ = units(result)
    grid = result.augmenting
    if grid is None and cancelled:
        return message_figure(
            augmenting_title(result, None, cancelled), f"not computed: {cancelled}"
        )
    vector = vector_note(result.state) if grid is None else None
    if vector:
        return message_figure(f"Augmenting map h: {map_name(result)}", vector)
    if grid is None:
        return figure([], augmenting_title(result))
    i, j = grid["axes"]
    ni, nj = result.variable_names[i], result.variable_names[j]
    H = grid["h"]
    finite = H[np.isfinite(H)]
    zmin, zmax = np.percentile(finite, [2, 98]) if finite.size else (0.0, 1.0)
    data = [
        trace(
            "contour",
            x=grid["u"],
            y=grid["v"],
            z=H,
            zmin=zmin,
            zmax=zmax,
            # A neutral scale, so that the red and blue runs on top stay the algorithms' colours.
            colorscale=[[0.0, "#fdfdfd"], [1.0, "#9a9a9a"]],
            # No labels on the level curves: placing them costs the page 100-250 ms per redraw;
            # the colour bar and the hover give the levels.
            ncontours=24,
            contours=dict(showlabels=False),
            colorbar=dict(
                title=dict(text="h", side="right"), thickness=12, ticklabeloverflow="allow"
            ),
            hovertemplate=f"{ni} = %{{x:.3f}}<br>{nj} = %{{y:.3f}}<br>h = %{{z:.4f}}"
            "<extra></extra>",
            name="h",
            showlegend=False,
        )
    ]
    shapes: list[dict[str, Any]] = [
        dict(
            type="path",
            path=_svg_path(result.runs[a].x[:, i], result.runs[a].x[:, j]),
            line=dict(color=COLORS[a], width=2.5, dash=DASH[a]),
            name=LABELS[a],
        )
        for a in result.runs
    ]
    x0 = result.state.x0
    shapes.append(  # (a circle of 10 px at x0, whatever the axes' scales)
        dict(
            type="circle",
            xsizemode="pixel",
            ysizemode="pixel",
            xanchor=float(x0[i]),
            yanchor=float(x0[j]),
            x0=-5,
            x1=5,
            y0=-5,
            y1=5,
            fillcolor="white",
            line=dict(color="black", width=2),
            name="x0",
        )
    )
    return figure(
        data,
        augmenting_title(result, functionals, cancelled),
        showlegend=False,
        margin={**NO_LEGEND_MARGIN, "r": RIGHT + COLORBAR},  # (the colour bar beside h)
        shapes=shapes,
        xaxis=dict(title=label(ni, ju[i])),
        yaxis=dict(title=label(nj, ju[j])),
    )


def _svg_path(x: np.ndarray, y: np.ndarray) -> str:
    """A polyline through (x, y) in data coordinates, as a plotly path shape takes it (six
    significant digits: under a pixel at a hundredfold zoom of a panel)."""
    points = "L".join(f"{u:.6g},{v:.6g}" for u, v in zip(x.tolist(), y.tolist(), strict=True))
    return "M" + points


def map_name(result: DashboardResult) -> str:
    """The map's name, and for a user's formula map its formula ("formula: h = x3")."""
    name = result.state.augmentation
    text = state_spec(result.state).augmentation(name).description
    return f"{name}: {text}" if text.startswith("h = ") else name


def augmenting_title(
    result: DashboardResult, functionals: dict | None = None, cancelled: str | None = None
) -> str:
    """Title of the h panel: the map, E1 and E2 on the plotted box, the fixed variables; while
    they are computed, or when that was ``cancelled``, it says so."""
    title = f"Augmenting map h: {map_name(result)}"
    grid = result.augmenting
    if grid is None:
        # (on a line of its own: the title fits a half-width panel at 1280 px)
        note = "h on a grid: cancelled" if cancelled else "computing h on a grid…"
        return f"{title}<br><sup>{note}</sup>"
    i, j = grid["axes"]
    x0 = result.state.x0
    # (a line now: the title keeps its height)
    waiting = "E1, E2: not computed (cancelled)" if cancelled else "E1, E2: computing…"
    sub = [] if functionals else [waiting]
    if functionals:
        design = functionals.get("design_region")
        where = region_words(functionals["region"]) if design else "the plotted box"
        sub.append(report_words(functionals, where))
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
    return title + "".join(f"<br><sup>{line}</sup>" for line in wrap(sub))


#: Characters of a subtitle line that fit a half-width panel at 1280 px.
SUBTITLE_CHARS = 70
#: Characters of a line of a panel's message (12 px, larger than a subtitle's).
MESSAGE_CHARS = 50


def wrap(parts: list[str]) -> list[str]:
    """The subtitle's parts joined by " · " into lines of about :data:`SUBTITLE_CHARS`
    characters (a long part on its own line), so that no panel cuts its subtitle off."""
    lines: list[str] = []
    for part in parts:
        if lines and len(lines[-1]) + 3 + len(part) <= SUBTITLE_CHARS:
            lines[-1] += " · " + part
        else:
            lines.append(part)
    return lines


def message_figure(title: str, message: str) -> dict:
    """A panel with nothing to plot: its title, and ``message`` where the plot would be (no
    empty axes), in lines of :data:`MESSAGE_CHARS` characters that fit a half-width panel."""
    hidden = dict(visible=False)
    lines = [
        line for piece in message.split("<br>") for line in textwrap.wrap(piece, MESSAGE_CHARS)
    ]
    return figure(
        [],
        title,
        xaxis=hidden,
        yaxis=hidden,
        annotations=[note("<br>".join(lines), 0.5, 0.5, size=12, color="#555")],
    )


#: Colours of the functionals (the algorithms keep red and blue).
E_COLORS = {"E1": "#2ca02c", "E2": "#9467bd"}


def log_ticks(values) -> dict:
    """Ticks of a log axis over ``values`` that do not crowd: each decade when they span more
    than one and a half, else 1, 2 and 5 per decade (plotly's default labels 2..9 overlap)."""
    v = np.asarray([x for x in values if x is not None], dtype=float)
    v = v[np.isfinite(v) & (v > 0)]
    if v.size and np.log10(v.max() / v.min()) > 1.5:
        return dict(dtick=1)
    return dict(dtick="D2")


def sensitivity_spec(
    result: DashboardResult, sens: dict | None = None, cancelled: str | None = None
) -> dict:
    """E1 (13) and E2 (18) of the current map and how they change.

    With parameters: each functional against each parameter (swept around its current value,
    which is marked), on a log scale. Without: the functionals of the robot's other maps.
    ``sens`` comes from :func:`jik.app.dashboard.functionals.sensitivity` (the dashboard's second
    phase); ``cancelled`` says how that phase was cancelled, when it was.
    """
    aug = result.state.augmentation
    if sens is None and cancelled:
        return message_figure(f"E1, E2 of {aug}: not computed", f"E1, E2 not computed: {cancelled}")
    if sens is None:
        return message_figure(f"E1, E2 of {aug}: computing…", "computing E1 and E2…")
    if sens["kind"] == "unavailable":
        return message_figure(f"E1, E2 of {aug}", sens["reason"])
    log = dict(type="log", exponentformat="power")
    if sens["kind"] == "single_joint":
        return single_joint_spec(sens, aug, log)
    if sens["kind"] == "vector":
        return vector_spec(sens, map_name(result), log)
    if sens["kind"] == "alternatives":
        maps = sens["maps"]
        names = [m["name"] + (" (current)" if m["current"] else "") for m in maps]
        data = [_bars(maps, k, names) for k in ("E1", "E2")]
        # (a functional without a bar says why at its map's foot: ∞, or undefined; in the
        # notes' grey, which small text can be read in, unlike the bars' green and purple)
        missing = [
            note(
                f"{k} {'= ∞' if m.get(f'{k}_divergent') else 'undefined'}",
                n,
                0,
                color="#555",
                xref="x",
                yanchor="bottom",
            )
            for m, n in zip(maps, names, strict=True)
            for k in ("E1", "E2")
            if m[k] is None
        ]
        return figure(
            data,
            f"E1 (13), E2 (18) of the maps of this robot<br><sup>{aug} has no parameters: "
            "the alternatives on the same box</sup>",
            barmode="group",
            annotations=missing,
            yaxis=dict(
                title="E (log)", **log, **log_ticks([m[k] for m in maps for k in ("E1", "E2")])
            ),
        )
    params = sens["parameters"]
    names = list(params)
    n = len(names)
    data, layout = [], {}
    # (0.2 of the width between the plots: room for the next one's y tick labels)
    for c, (name, domain) in enumerate(zip(names, side_by_side(n, 0.2), strict=True)):
        xa, ya = ("x", "y") if c == 0 else (f"x{c + 1}", f"y{c + 1}")
        for k in ("E1", "E2"):
            sweep = sens[k]["sweeps"][name]
            data.append(
                trace(
                    "scatter",
                    x=sweep["values"],
                    y=sweep["functional"],
                    mode="lines",
                    name=k,
                    legendgroup=k,
                    showlegend=c == 0,
                    line=dict(color=E_COLORS[k], width=2),
                    xaxis=xa,
                    yaxis=ya,
                    hovertemplate=f"{name} = %{{x:.3g}}<br>{k} = %{{y:.4g}}<extra></extra>",
                )
            )
            if sens[k]["value"] is not None:
                data.append(
                    trace(
                        "scatter",
                        x=[params[name]],
                        y=[sens[k]["value"]],
                        mode="markers",
                        name=f"current {k}",
                        showlegend=False,
                        marker=dict(color="white", size=9, line=dict(color=E_COLORS[k], width=2)),
                        xaxis=xa,
                        yaxis=ya,
                        hovertemplate=f"current {name} = %{{x:.3g}}<br>{k} = "
                        "%{y:.4g}<extra></extra>",
                    )
                )
        layout["xaxis" if c == 0 else f"xaxis{c + 1}"] = dict(
            domain=domain, title=name, anchor=ya, nticks=5
        )
        ys = [y for k in ("E1", "E2") for y in sens[k]["sweeps"][name]["functional"]]
        layout["yaxis" if c == 0 else f"yaxis{c + 1}"] = dict(
            anchor=xa, **log, **log_ticks(ys), **({"title": "E (log)"} if c == 0 else {})
        )

    def slope(k: str, p: str) -> str:
        g = sens[k]["gradient"].get(p)
        return f"∂{k}/∂{p} undefined" if g is None else f"∂{k}/∂{p} = {g:.3g}"

    slopes = [", ".join(slope(k, p) for p in names) for k in ("E1", "E2")]
    at = ", ".join(f"{p} = {v:.3g}" for p, v in params.items())
    sub = "".join(f"<br><sup>{line}</sup>" for line in wrap([f"at {at} (circles)", *slopes]))
    return figure(data, f"E1 (13), E2 (18) as the parameters of {aug} move{sub}", **layout)


def _bars(maps: list[dict], key: str, names: list[str]) -> dict:
    """The bars of E1 or E2 (``key``) of ``maps`` named ``names``, the current map's outlined."""
    edges = ["black" if m["current"] else E_COLORS[key] for m in maps]
    return trace(
        "bar",
        x=names,
        y=[m[key] for m in maps],
        name=key,
        marker=dict(color=E_COLORS[key], line=dict(color=edges, width=2)),
        hovertemplate="%{x}: " + key + " = %{y:.4g}<extra></extra>",
    )


def single_joint_spec(sens: dict, aug: str, log: dict) -> dict:
    """E2 (18) of the map (outlined) beside E2 of h = s x_j for each joint, on a log scale, E1
    (13) of the map in the title: a map over many joints, both by a Sobol rule
    (:func:`jik.engine.functional_report.functionals_report`)."""
    maps = sens["maps"]
    values = [m["E2"] for m in maps]
    data = [_bars(maps, "E2", [m["name"] for m in maps])]
    best = min((m for m in maps if not m["current"]), key=lambda m: m["E2"])
    ratio = ""
    if sens["E2"]:
        ratio = f": {best['E2'] / sens['E2']:.3g} × E2 of h"
    e1, e2 = sens["E1"], sens["E2"]
    e1 = f"{e1:.4g}" if e1 is not None else "∞" if sens["E1_divergent"] else "undefined"
    e1 += plus_minus(sens.get("E1_error_estimate"))
    e2 = "undefined" if e2 is None else f"{e2:.4g}{plus_minus(sens.get('E2_error_estimate'))}"
    title = (
        f"E2 (18) of {aug} and of a single joint held<br><sup>a scrambled Sobol rule of "
        f"{sens['nodes']} nodes on the design box; E1 (13) of h = {e1}, E2 = {e2}</sup>"
        f"<br><sup>the best single joint, {best['name']}{ratio}</sup>"
    )
    known = [v for v in values if v is not None and v > 0]
    # (a decade below the least: the map's bar, often the least, stands out of the axis)
    lo, hi = (np.log10(min(known)) - 1, np.log10(max(known)) + 0.2) if known else (-3, 0)
    yaxis = dict(title="E2 (log)", range=[float(lo), float(hi)], **log, **log_ticks(values))
    return figure(data, title, yaxis=yaxis)


def vector_spec(sens: dict, name: str, log: dict) -> dict:
    """E1 (13) and E2 (18) of a vector of p - r > 1 maps ``name`` as two bars on a log scale
    (a missing bar says why), the box and the kernel frame E2 was taken in."""
    values = {k: sens.get(k) for k in ("E1", "E2")}
    errors = {k: sens.get(f"{k}_error_estimate") for k in ("E1", "E2")}
    data = [
        trace(
            "bar",
            x=[f"{k} ({eq})"],
            y=[values[k]],
            name=k,
            marker=dict(color=E_COLORS[k]),
            hovertemplate=f"{k} = %{{y:.4g}}{plus_minus(errors[k])}<extra></extra>",
            **({} if errors[k] is None else {"error_y": dict(type="data", array=[errors[k]])}),
        )
        for k, eq in (("E1", 13), ("E2", 18))
    ]
    missing = {"E1": "undefined", "E2": "undefined"}
    if sens.get("E1_divergent"):
        missing["E1"] = "= ∞ (det(dh K) = 0 inside)"
    words = [
        note(f"{k} {missing[k]}", f"{k} ({eq})", 0, color="#555", xref="x", yanchor="bottom")
        for k, eq in (("E1", 13), ("E2", 18))
        if values[k] is None
    ]
    where = region_words(sens["region"]) if sens["design_region"] else "the box of the runs"
    frame = sens.get("E2_frame_axes")
    sub = [f"on {where}"] + ([f"E2 in the kernel frame of joints {frame}"] if frame else [])
    told = [f"{k} = {values[k]:.4g}{plus_minus(e)}" for k, e in errors.items() if e is not None]
    if told:
        sub.append("by a Sobol rule: " + ", ".join(told))
    title = f"E1, E2 of the vector {name}" + "".join(f"<br><sup>{x}</sup>" for x in wrap(sub))
    yaxis = dict(title="E (log)", **log, **log_ticks(values.values()))
    return figure(data, title, showlegend=False, annotations=words, yaxis=yaxis)
