"""The dashboard's atlas panel: the REST API's repeatability atlas
(:mod:`jik.app.compute.atlas_jobs`) of the session's current state (:func:`atlas_request`), and
its heatmap (:func:`atlas_figure`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ...engine.arms import ARMS
from ...engine.exceptions import InvalidInputError
from ...engine.redundant_starts import manifold_starts
from ..compute.atlas_schemas import AtlasRequest
from ..compute.schemas import RobotUsed
from .algorithms import STYLES
from .model import DashboardState
from .plotting import COLORBAR, RIGHT, figure, norm_unit, note
from .robots import state_kinematics, state_spec, user_robot

#: Drift below this is drawn as this (the extended Jacobian's drift is round-off, ~1e-13).
DRIFT_FLOOR = 1e-14


def atlas_request(
    state: DashboardState,
    starts: int,
    cycles: int | None = None,
    scales: Sequence[float] | None = None,
) -> AtlasRequest:
    """The atlas of ``state`` (its closed path, robot, map, gamma, mode, tolerance and cap on
    steps per leg), with ``starts`` starts and ``cycles`` cycles (default: the state's);
    InvalidInputError naming the field when the state has no closed path or the request is
    refused."""
    if state.task != "path" or not state.path:
        raise InvalidInputError(
            "task: the atlas drives a closed path; choose the closed-path task first", "task"
        )
    kin = state_kinematics(state)  # (its map is the atlas workers' to build, not this)
    home = np.asarray(kin.forward(np.asarray(state.x0, dtype=float)), dtype=float)
    # The atlas's posture inverse, without rest, pulls each run toward its own start (the
    # state's rest is for the runs from x0; the heatmap's title says so).
    params = {k: v for k, v in state.algorithm_parameters.items() if k != "rest"}
    points = None
    if kin.p - kin.r > 1:  # (its self-motion manifolds are not curves: starts given)
        box = state_spec(state).x_range
        points = manifold_starts(kin, state.x0, starts, box).tolist()
    robot, augmentation = request_robot(state)
    return AtlasRequest.model_validate(
        {
            "robot": robot,
            "algorithms": list(state.algorithms),
            "algorithm_parameters": params or None,
            "augmentation": augmentation if "extended" in state.algorithms else None,
            "path": [home.tolist(), *[list(p) for p in state.path]],
            "starts": starts,
            "cycles": cycles or state.cycles,
            "reference": list(state.x0),
            "start_points": points,
            "scales": list(scales) if scales else None,
            "gamma": state.gamma,
            "mode": state.mode,
            "tolerance": state.tolerance,
            "max_iterations": state.max_iterations,
        }
    )


def request_robot(state: DashboardState) -> tuple[dict, dict | None]:
    """A state's robot and map as a request gives them: a catalogue robot with its parameters
    and its map by name; a robot given by a definition (a user's, a catalogue arm) by that
    definition, with its chosen map as the definition's entry (None: the robot's default map,
    such as a catalogue arm's synthesized one)."""
    if state.robot_definition is None:
        return (
            {"name": state.robot, **state.robot_parameters},
            {"name": state.augmentation, **state.augmentation_parameters},
        )
    definition = dict(state.robot_definition)
    # (the map the dashboard adds, if it added one; a catalogue arm's is its own default)
    if not definition.get("augmentations") and definition.get("name") not in ARMS:
        built = user_robot(definition).definition
        if built.get("augmentations"):
            definition["augmentations"] = built["augmentations"]
    entries = definition.pop("augmentations", None) or []
    if state.augmentation == state_spec(state).default_augmentation:
        chosen = entries[0] if entries else None
    else:
        chosen = next(e for e in entries if e.get("label", e.get("name")) == state.augmentation)
    return definition, None if chosen is None else {k: v for k, v in chosen.items() if k != "label"}


def atlas_figure(result: dict[str, Any], request: AtlasRequest, robot: RobotUsed) -> dict:
    """The heatmap of a finished atlas of :func:`atlas_request`'s ``request`` (the ``result``
    of ``GET /atlas/{id}``): for each algorithm, log10 of the drift ||x after cycle c - x0||
    over the starts' arc length s (columns) and the cycles (rows; per path scale when
    several), one colour scale for both.
    A cell's ``customdata`` is its run, path * N + start (for a click); ``robot``, the robot
    the job used, gives the title its name and the arc length its unit."""
    algorithms = result["algorithms"]
    s = np.asarray(result["parameter"], dtype=float)  # (N,)
    scales = request.scales or [1.0]
    unit = norm_unit(robot.units.x)
    x_title, hover, at_x0 = f"arc length s of the start {unit}", "s = %{x:.3f}", 0.0
    if result.get("period") is not None:  # (a closed curve: the starts cover one turn)
        x_title = f"arc length s of the start {unit}, one turn of {result['period']:.4g}"
    # (p - r > 1: starts by number, the first x0, see the engine's manifold_starts)
    if request.start_points:
        s = np.arange(1.0, len(request.start_points) + 1)
        x_title, hover, at_x0 = "start, farther from x0 to the right", "start %{x}", 1.0
    P, N = len(result["paths"]), len(s)
    rows = [(j, c) for j in range(P) for c in range(request.cycles)]
    labels = [f"×{scales[j]:g}, cycle {c + 1}" if P > 1 else f"cycle {c + 1}" for j, c in rows]
    runs = np.array([[j * N + i for i in range(N)] for j, _ in rows])
    data: list[dict] = []
    layout: dict[str, Any] = {"shapes": [], "annotations": []}
    gap = 0.06
    width = (1.0 - gap * (len(algorithms) - 1)) / len(algorithms)
    outside = result.get("outside_limits") or {}  # (runs that left the joint limits)
    for k, a in enumerate(algorithms):
        d = np.array(result["drift"][a], dtype=float)  # (P, N, C), NaN after a failure
        z = np.array([d[j, :, c] for j, c in rows])  # (rows, N)
        failed = int(np.isnan(d).any(axis=2).sum())
        axis = "" if k == 0 else str(k + 1)
        data.append(
            {
                "type": "heatmap",
                "x": s,
                "y": labels,
                "z": np.log10(np.maximum(z, DRIFT_FLOOR)),
                "customdata": runs.tolist(),
                "coloraxis": "coloraxis",
                "xaxis": f"x{axis}",
                "yaxis": f"y{axis}",
                "hovertemplate": f"{hover}<br>%{{y}}<br>log10 drift = %{{z:.2f}}<extra>{a}</extra>",
                "hoverongaps": False,
                "xgap": 0,
                "ygap": 1,
            }
        )
        lo = k * (width + gap)
        layout[f"xaxis{axis}"] = dict(domain=[lo, lo + width], anchor=f"y{axis}", title=x_title)
        # s = 0 is x0, the start of the state the atlas was asked for
        layout["shapes"].append(
            {
                "type": "line",
                "xref": f"x{axis}",
                "yref": f"y{axis} domain",
                "x0": at_x0,
                "x1": at_x0,
                "y0": 0,
                "y1": 1,
                "line": {"color": "#fff", "width": 1.5, "dash": "dot"},
            }
        )
        ticks = dict(showticklabels=k == 0, type="category")
        layout[f"yaxis{axis}"] = dict(anchor=f"x{axis}", autorange="reversed", **ticks)
        name = STYLES[a].label
        if a == "extended" and request.augmentation is not None:
            name += f"<br>h = {request.augmentation.name}"
        name += f"<br>{_rest_used(request)}" if a == "posture" else ""
        what = "run" if P > 1 else "start"  # (with scales: a start on one scaled path)
        name += f", {failed} {what}{'' if failed == 1 else 's'} failed (blank)" if failed else ""
        if a in outside:
            name += f"<br>{outside[a]} of {P * N} runs left the joint limits"
        where = dict(xanchor="center", yanchor="bottom")
        layout["annotations"].append(
            note(name, lo + width / 2, 1.0, color=STYLES[a].color, **where)
        )
    # (a session's atlas, whose request atlas_request made: gamma and mode the state's)
    assert request.gamma is not None and request.mode is not None
    title = (
        f"Drift after each cycle from {N} starts on k(x) = k(x0) (dotted: x0), "
        f"{robot.title}, γ = {request.gamma:g}, {request.mode} mode"
    )
    logs = np.concatenate([np.ravel(t["z"]) for t in data])
    logs = logs[np.isfinite(logs)]
    cmin, cmax = (np.floor(logs.min()), np.ceil(logs.max())) if logs.size else (-14.0, 0.0)
    layout["coloraxis"] = {
        "colorscale": "Viridis",
        "cmin": float(cmin),
        "cmax": float(max(cmax, cmin + 1)),
        "colorbar": {
            "title": {"text": f"log10 ‖x − x0‖<br>{unit}", "side": "right"},
            "len": 0.9,
            "x": 1.0,  # (beside the plots, as thin as h's: COLORBAR holds it)
            "thickness": 12,
        },
    }
    height = max(280, 120 + 22 * len(rows))  # (room for the toolbar beside the plots)
    return figure(
        data,
        title,
        height=height,
        showlegend=False,
        margin=dict(l=110, r=RIGHT + COLORBAR, t=84, b=56),  # (the colour bar beside them)
        **layout,
    )


def _rest_used(request: AtlasRequest) -> str:
    """The posture inverse's rest in an atlas: the request's, else each run's own start."""
    rest = request.algorithm_parameters.rest if request.algorithm_parameters else None
    if rest is None:
        return "x_rest = each run's start"
    return "x_rest = (" + ", ".join(f"{v:.4g}" for v in rest) + ")"


__all__ = ["atlas_figure", "atlas_request"]
