"""The task-space panel of an arm in space, whose task may hold its end link's position ``x y z``
and orientation ``rx ry rz`` (:mod:`jik.engine.pose_task`), which a plane (x, y) would hide: one
row per task coordinate against theta, positions above rotations, like the paper's joint
trajectories (Figs. 7-9).
"""

from __future__ import annotations

import numpy as np

from .algorithms import COLORS, DASH, LABELS, STYLES
from .plotting import (
    NO_LEGEND,
    corner_names,
    figure,
    label,
    nice_range,
    note,
    stacked_axes,
    theta_axis,
    trace,
    units,
)
from .runs import AlgorithmRun, DashboardResult

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
