"""Plotly figures of a dashboard result: pure functions ``DashboardResult -> figure dict`` (a
plain dict, which :func:`~jik.app.dashboard.plotting.figure_json` serializes), each chosen
algorithm in its style (:data:`jik.app.dashboard.algorithms.STYLES`). They follow the paper:
task-space paths (Figs. 5, 6, of Manipulator 2), joint trajectories against theta (Figs. 7-9),
the repeatability drift per cycle, and for the unicycle the platform paths in the (q1, q2)
plane and the controls against the iteration (Figs. 11-14). An arm in space, whose task may hold
its end link's orientation (:mod:`jik.engine.pose_task`), which a plane would hide, has a row per
task coordinate against theta instead (:func:`pose_task_spec`).
"""

from __future__ import annotations

import numpy as np

from ...engine.reproductions.table1 import FIGS_5_9_TARGET, X0
from ...engine.reproductions.unicycle import figs_11_14
from .algorithms import COLORS, DASH, LABELS, STYLES
from .cspace import cspace_spec
from .map_figures import augmenting_spec, sensitivity_spec
from .plotting import (
    NO_LEGEND,
    RIGHT,
    corner_names,
    figure,
    is_unicycle,
    label,
    log_range,
    nice_range,
    norm_unit,
    note,
    side_by_side,
    stacked_axes,
    theta_axis,
    trace,
    units,
)
from .runs import AlgorithmRun, DashboardResult, spaced_iterations
from .table import table_spec

#: The coordinates of an arm's task in space (any of them).
POSE_NAMES = ("x", "y", "z", "rx", "ry", "rz")
#: Least half-span of a row's axis [m or rad]: a coordinate the path holds (rx, ry of a turn
#: about z) shows flat, not its rounding errors of 1e-16 blown up.
MIN_SPAN = 0.01


def is_pose_task(result: DashboardResult) -> bool:
    """Whether the task is an arm's in space beyond the plane: some of x y z rx ry rz, with z or
    an orientation coordinate among them."""
    names = set(result.task_names)
    return names <= set(POSE_NAMES) and bool(names & {"z", "rx", "ry", "rz"})


def algorithms_key(result: DashboardResult) -> str:
    """The line style of each algorithm, three to a line (a title fits its panel)."""
    keys = [f"{STYLES[a].line.split()[0]}: {STYLES[a].short}" for a in result.runs]
    return "</sup><br><sup>".join(", ".join(keys[i : i + 3]) for i in range(0, len(keys), 3))


def theta_line(a: str, run: AlgorithmRun, values, name: str, row: int, legs=False, **props):
    """Algorithm ``a``'s ``run``: the ``values`` of coordinate ``name`` against theta on the row
    ``row`` (from the top, 0) of stacked axes; ``legs``: its leg in the hover too."""
    if legs:
        props["customdata"] = run.leg + 1
    leg = "<br>leg %{customdata}" if legs else ""
    return trace(
        "scatter",
        x=run.theta,
        y=values,
        mode="lines",
        name=LABELS[a],
        line=dict(color=COLORS[a], width=1.8, dash=DASH[a]),
        xaxis="x",
        yaxis="y" if row == 0 else f"y{row + 1}",
        hovertemplate=f"{name} = %{{y:.5f}}<br>θ = %{{x:.4g}}{leg}<extra>{a}</extra>",
        **props,
    )


def pose_task_spec(result: DashboardResult) -> dict:
    """Each task coordinate against theta for each algorithm, one row per coordinate; the
    targets (× at the end of each leg, their letters above the top row) and the start k(x0) (○)."""
    _, tu = units(result)
    names = list(result.task_names)
    order = sorted(range(len(names)), key=lambda k: POSE_NAMES.index(names[k]))
    runs = list(result.runs.values())
    first = runs[0]
    ends = np.flatnonzero(np.diff(first.leg, append=first.leg[-1] + 1))  # (last point of a leg)
    legs = first.leg[ends]
    targets = np.asarray(result.targets, dtype=float)
    letters = np.asarray(corner_names(result), dtype=object)[legs % len(targets)]
    data = []
    axes = stacked_axes(len(names))
    for row, k in enumerate(order):
        yaxis = "y" if row == 0 else f"y{row + 1}"
        name = names[k]
        # (each entry once in a legend, the saved panel's: the top row's)
        once = dict(showlegend=row == 0)
        data += [
            theta_line(a, r, r.y[:, k], name, row, legs=True, legendgroup=a, **once)
            for a, r in result.runs.items()
        ]
        data.append(
            trace(
                "scatter",
                x=first.theta[ends],
                y=targets[legs % len(targets), k],
                name="targets",
                mode="markers",
                xaxis="x",
                yaxis=yaxis,
                text=letters.tolist(),
                marker=dict(color="black", size=8, symbol="x"),
                hovertemplate=f"%{{text}}: {name} = %{{y:.4f}}<extra></extra>",
                legendgroup="targets",
                **once,
            )
        )
        data.append(
            trace(
                "scatter",
                x=[first.theta[0]],
                y=[first.y[0, k]],
                mode="markers",
                name="start k(x0)",
                xaxis="x",
                yaxis=yaxis,
                marker=dict(color="#2ca02c", size=10, symbol="circle-open", line=dict(width=2)),
                hovertemplate=f"start {name} = %{{y:.4f}}<extra></extra>",
                legendgroup="start",
                **once,
            )
        )
        values = np.concatenate([r.y[:, k] for r in runs] + [targets[:, k]])
        mid = float(np.nanmean(values))  # (a coordinate constant up to rounding: +-MIN_SPAN)
        values = np.append(values, [mid - MIN_SPAN, mid + MIN_SPAN])
        axes["yaxis" if row == 0 else f"yaxis{row + 1}"].update(
            title=label(name, tu[k]), range=nice_range(values)
        )
    # The targets' letters above the top row, at the end of their legs (never over a line).
    axes["annotations"] = [
        note(str(t), float(x), 1.0, "x", "y domain", yanchor="bottom")
        for t, x in zip(letters, first.theta[ends], strict=True)
    ]
    axes["xaxis"].update(theta_axis(result))
    lead = next(iter(result.runs))  # (the targets are marked at its legs' ends)
    title = (
        "Task coordinates against θ: position, then rotation vector<br><sup>"
        + algorithms_key(result)
        + f"</sup><br><sup>× target at the end of each leg of {STYLES[lead].short}"
        " · ○ start k(x0)</sup>"
    )
    return figure(data, title, height=110 * len(names) + 140, **NO_LEGEND, **axes)


def _task_space(result: DashboardResult) -> dict:
    """End-effector paths of the algorithms in the task plane (paper, Figs. 5 and 6)."""
    _, tu = units(result)
    n1, n2 = result.task_names[:2]
    data = []
    for a, run in result.runs.items():
        data.append(
            trace(
                "scatter",
                x=run.y[:, 0],
                y=run.y[:, 1],
                mode="lines",
                name=LABELS[a],
                line=dict(color=COLORS[a], width=STYLES[a].width, dash=DASH[a]),
                customdata=run.leg + 1,  # (theta stays out: this panel does not depend on gamma)
                hovertemplate=f"{n1} = %{{x:.4f}}<br>{n2} = %{{y:.4f}}"
                "<br>leg %{customdata}<extra>" + a + "</extra>",
            )
        )
    tg = result.targets
    x0y = next(iter(result.runs.values())).y[0]
    data.append(
        trace(
            "scatter",
            x=tg[:, 0],
            y=tg[:, 1],
            mode="markers+text",
            name="targets",
            text=corner_names(result),
            textposition="top right",
            marker=dict(color="black", size=9, symbol="x"),
            hovertemplate=f"%{{text}}: ({n1}, {n2}) = (%{{x:.3f}}, %{{y:.3f}})<extra></extra>",
        )
    )
    data.append(
        trace(
            "scatter",
            x=[x0y[0]],
            y=[x0y[1]],
            mode="markers",
            name="start k(x0)",
            marker=dict(color="#2ca02c", size=12, symbol="circle-open", line=dict(width=2)),
            hovertemplate="start (%{x:.3f}, %{y:.3f})<extra></extra>",
        )
    )
    points = np.vstack([r.y[:, :2] for r in result.runs.values()] + [tg[:, :2]])
    return figure(
        data,
        f"Task-space paths{_cited(result, 'Figs. 5, 6')}<br><sup>"
        + algorithms_key(result)
        + (" · " if len(result.runs) <= 2 else "</sup><br><sup>")
        + "× targets of the legs · ○ start k(x0)</sup>",
        **NO_LEGEND,
        xaxis=dict(title=label(n1, tu[0]), range=nice_range(points[:, 0])),
        yaxis=dict(
            title=label(n2, tu[1]), range=nice_range(points[:, 1]), scaleanchor="x", scaleratio=1
        ),
    )


def _cited(result: DashboardResult, figures: str) -> str:
    """`` (Figs. ...)`` on the runs the paper draws: Manipulator 2 (l = 1) from x0 = (0, 0, pi/2)
    to the one target y_d = (0, 2) (Figs. 5-9, sec. 5.2.1), the unicycle's of Figs. 11-14
    (:func:`~jik.engine.reproductions.unicycle.figs_11_14`). Other runs cite none."""
    s, p = result.state, result.state.robot_parameters
    a = s.augmentation_parameters.get("a")
    shown = s.task == "target" and (
        figs_11_14(p["q0"], p["T"], a, s.x0, s.target, s.gamma, s.mode)
        if s.robot == "unicycle"
        else s.robot == "manipulator2"
        and p.get("l", 1.0) == 1.0
        and np.allclose(s.x0, X0, rtol=0, atol=1e-9)
        and np.allclose(s.target, FIGS_5_9_TARGET, rtol=0, atol=1e-9)
    )
    return f" ({figures})" if shown else ""


def _joints(result: DashboardResult) -> dict:
    """Every joint variable against theta for each algorithm (Figs. 7-9; Figs. 11-14 b, c)."""
    ju, _ = units(result)
    names = result.variable_names
    data = []
    for a, run in result.runs.items():
        for k, name in enumerate(names):
            data.append(theta_line(a, run, run.x[:, k], name, k, legendgroup=a, showlegend=k == 0))
    axes = stacked_axes(len(names))
    runs = list(result.runs.values())
    for k, name in enumerate(names):
        axis = axes["yaxis" if k == 0 else f"yaxis{k + 1}"]
        axis["title"] = label(name, ju[k])
        axis["range"] = nice_range(np.concatenate([r.x[:, k] for r in runs]))
    axes["xaxis"].update(theta_axis(result))
    title = (
        f"Controls λ against the iteration{_cited(result, 'Figs. 11-14 b, c')}"
        if is_unicycle(result)
        else f"Joint trajectories{_cited(result, 'Figs. 7-9')}"
    )
    return figure(data, title, height=120 * len(names) + 100, **NO_LEGEND, **axes)


def _drift(result: DashboardResult) -> dict:
    """Repeatability drift ||x(end of cycle c) - x0|| per cycle, log scale (Table 1's point).

    For a single-target task (and the unicycle) the task error against theta is shown instead.
    """
    closed = result.state.task == "path"
    data = []
    for a, run in result.runs.items():
        cycle = dict(
            x=np.arange(1, len(run.drift) + 1),
            y=np.maximum(run.drift, 1e-16),
            mode="lines+markers",
            marker=dict(symbol=STYLES[a].symbol, size=9),
            hovertemplate="cycle %{x}: drift %{y:.3e}<extra>" + a + "</extra>",
        )
        point = dict(
            x=run.theta,
            y=np.maximum(run.error, 1e-16),
            mode="lines",
            hovertemplate="‖k(x) − y_d‖ = %{y:.3e}<br>θ = %{x:.4g}<extra>" + a + "</extra>",
        )
        line = dict(color=COLORS[a], width=2, dash=DASH[a])
        data.append(trace("scatter", name=LABELS[a], line=line, **(cycle if closed else point)))
    ys = np.concatenate([np.asarray(t["y"], dtype=float) for t in data])
    if closed:
        cycles = max(len(r.drift) for r in result.runs.values())
        title, norm = "Repeatability: joint drift after each closed cycle", "‖x(end of cycle) − x0‖"
        xaxis = dict(title="cycle", dtick=1, range=[0.5, cycles + 0.5])
    else:
        title, norm, xaxis = "Convergence: task error", "‖k(x) − y_d‖", theta_axis(result)
    unit = norm_unit(units(result)[0 if closed else 1])
    title_words = " ".join(w for w in (norm, unit, "(log)") if w)  # (a formula robot: no unit)
    yaxis = dict(title=title_words, type="log", exponentformat="power")
    return figure(data, title, **NO_LEGEND, xaxis=xaxis, yaxis=yaxis | {"range": log_range(ys)})


#: Iterations of the unicycle's platform path drawn per algorithm (first and last included).
PLATFORM_PATHS = 12


def _platform(result: DashboardResult) -> dict:
    """Unicycle platform paths q(t) in the (q1, q2) plane, per iteration (Figs. 11-14 a)."""
    _, tu = units(result)
    data, annotations = [], []
    axes: dict[str, dict] = {}
    domains = side_by_side(len(result.runs), 0.04)
    for col, (a, domain) in enumerate(zip(result.runs, domains, strict=True)):
        k = str(col + 1) if col else ""
        xa, ya = f"x{k}", f"y{k}"
        axes[f"xaxis{k}"] = dict(
            domain=domain, title=label("q1", tu[0]), **({"matches": "x"} if k else {})
        )
        axes[f"yaxis{k}"] = (
            dict(anchor=xa, matches="y", showticklabels=False)
            if k
            else dict(title=label("q2", tu[1]), scaleanchor="x", scaleratio=1)
        )
        P = result.runs[a].platform
        assert P is not None  # drawn only for the unicycle, whose runs all carry platform paths
        m = len(P)
        show = spaced_iterations(m, PLATFORM_PATHS)
        for n, i in enumerate(show):
            last = bool(i == m - 1)
            data.append(
                trace(
                    "scatter",
                    x=P[i, :, 0],
                    y=P[i, :, 1],
                    mode="lines",
                    xaxis=xa,
                    yaxis=ya,
                    name=LABELS[a] if last else f"{a} iteration {i}",
                    legendgroup=a,
                    showlegend=last,
                    line=dict(color=COLORS[a], width=3 if last else 1, dash=DASH[a]),
                    opacity=1.0 if last else 0.2 + 0.5 * n / max(len(show), 1),
                    customdata=result.time,
                    hovertemplate=f"iteration {i}<br>q1 = %{{x:.3f}}<br>q2 = %{{y:.3f}}"
                    "<br>t = %{customdata:.2f}<extra>" + a + "</extra>",
                )
            )
        q0 = result.state.robot_parameters.get("q0", P[0, 0])
        target = result.state.target
        data.append(
            trace(
                "scatter",
                x=[q0[0], target[0]],
                y=[q0[1], target[1]],
                xaxis=xa,
                yaxis=ya,
                mode="markers+text",
                text=["q0", "target"],
                textposition="top center",
                marker=dict(color=["#2ca02c", "black"], size=10, symbol=["circle", "x"]),
                showlegend=False,
                hovertemplate="%{text}: (%{x:.3f}, %{y:.3f})<extra></extra>",
            )
        )
        where = f"{xa} domain", f"{ya} domain"
        annotations.append(
            note(STYLES[a].short, 0.5, 1.0, *where, color=COLORS[a], yanchor="bottom")
        )
    return figure(
        data,
        f"Platform paths q(t) per iteration{_cited(result, 'Figs. 11-14 a')}",
        **axes,
        annotations=annotations,
        showlegend=False,  # (each plot is named above it)
        margin=dict(l=64, r=RIGHT, t=64, b=48),
    )


def gamma_free_panels(result: DashboardResult) -> set[str]:
    """Panels that do not change with gamma in continuous mode (theta is not on their axes)."""
    if result.state.mode != "continuous":
        return set()
    flat = not is_unicycle(result) and not is_pose_task(result)  # (a plane, theta not on it)
    panels = {"table", "augmenting", "cspace"} | ({"task"} if flat else set())
    return panels | ({"drift"} if result.state.task == "path" else set())


def figure_specs(
    result: DashboardResult,
    functionals: dict | None = None,
    only: set[str] | None = None,
    sensitivity: dict | None = None,
    cancelled: str | None = None,
) -> dict[str, dict]:
    """The panels of the dashboard for ``result`` (all, or those in ``only``) as figure dicts,
    keyed by id: what the dashboard serializes with :func:`figure_json`. ``cancelled``: how the
    second phase was cancelled (:mod:`jik.app.dashboard.second_phase`), which the h and E1/E2
    panels then say in place of what it did not compute."""
    builders = {
        "task": _platform
        if is_unicycle(result)
        else (pose_task_spec if is_pose_task(result) else _task_space),
        "joints": _joints,
        "drift": _drift,
        "table": table_spec,
        "cspace": cspace_spec,
        "augmenting": lambda r: augmenting_spec(r, functionals, cancelled),
        "sensitivity": lambda r: sensitivity_spec(r, sensitivity, cancelled),
    }
    return {k: f(result) for k, f in builders.items() if only is None or k in only}
