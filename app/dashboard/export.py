"""A dashboard result exported as JSON or CSV: every point of every run, with the state that
produced it, the verdict, each run's drift and leg ends, the units of its columns, the jik
version and the time of the export (:func:`export_file`)."""

from __future__ import annotations

import json
import re
from datetime import UTC, datetime

import numpy as np

from jik import __version__

from ...engine.exports import csv_text
from ...engine.results import Trajectory
from ...engine.units import robot_units
from .algorithms import posture_rest
from .messages import h_change, to_json
from .robots import state_kinematics
from .runs import DashboardResult
from .verdict import verdict


def described(result: DashboardResult) -> dict:
    """What an export says of its columns (:func:`run_columns`): ``units``, the unit of every
    column by its name (:meth:`jik.engine.units.RobotUnits.trajectory_units`); ``length_unit``,
    what the robot's length unit m stands for (the paper states none); ``coordinates``, what
    each coordinate column is (``{"x_1": <the first joint's name>, ..., "y_1": <the first task
    coordinate's>, ...}``)."""
    units = robot_units(state_kinematics(result.state), result.task_names)
    columns = units.trajectory_units(result.state.mode)
    maps = h_shape(result)
    if maps:  # (a vector of maps: a column and a unit for each, as Trajectory.columns names them)
        said = columns.pop("h")
        columns |= {f"h_{k}": said for k in range(1, maps[0] + 1)}
    return {
        "units": columns,
        "length_unit": units.lengths,
        "coordinates": {k: c.name for k, c in units.columns().items()},
    }


def h_shape(result: DashboardResult) -> tuple[int, ...]:
    """The shape of h at one point of the result's runs: ``()`` for one map (or none),
    ``(p - r,)`` for a vector of maps."""
    shapes = [np.shape(run.h)[1:] for run in result.runs.values() if run.h is not None]
    return shapes[0] if shapes else ()


def run_columns(result: DashboardResult, algorithm: str) -> dict[str, np.ndarray]:
    """A run's table, a row per point: ``algorithm``, ``cycle`` and ``leg`` (both from 1, the
    leg within its cycle), then the engine's trajectory columns
    (:meth:`jik.engine.results.Trajectory.columns`: ``theta``, ``x_k``, ``y_k``, ``error``, ``h``;
    ``h``, or ``h_1``.. for a vector of maps; NaN for an inverse without a map)."""
    run = result.runs[algorithm]
    m, legs = len(run.theta), max(1, len(result.targets))
    h = run.h if run.h is not None else np.full((m, *h_shape(result)), np.nan)
    cycle, leg = np.divmod(np.asarray(run.leg, dtype=int), legs)
    return {
        "algorithm": np.full(m, algorithm),
        "cycle": cycle + 1,
        "leg": leg + 1,
        **Trajectory(run.theta, run.x, run.y, run.error, h).columns(),
    }


def provenance(when: datetime | None = None) -> dict:
    """The jik version and the time (UTC, ISO 8601) of an export."""
    when = when or datetime.now(UTC)
    return {"jik_version": __version__, "exported_at": when.isoformat(timespec="seconds")}


def export_filename(result: DashboardResult, extension: str, when: datetime) -> str:
    """``jik-<robot>-<map>-<mode>-g<generation>-<UTC time>.<extension>``: what the file holds
    and when, so that exports of several states do not overwrite each other."""
    state = result.state
    parts = [
        state.robot,
        state.augmentation,
        state.mode,
        f"g{result.generation}",
        when.strftime("%Y%m%dT%H%M%SZ"),
    ]
    slug = "-".join(re.sub(r"[^A-Za-z0-9_.]+", "_", p) for p in parts)
    return f"jik-{slug}.{extension}"


def export_json(
    result: DashboardResult, functionals: dict | None = None, when: datetime | None = None
) -> dict:
    """The current result as plain JSON: the state, both runs point by point (``x``, ``y`` the
    vectors whose coordinates the CSV's ``x_k``, ``y_k`` are; ``cycle``, ``leg`` from 1), the
    columns' units and what each coordinate is, the jik version and the export's time."""
    runs = {}
    for a, run in result.runs.items():
        table = run_columns(result, a)
        runs[a] = {
            "success": run.success,
            "message": run.message,
            "theta": run.theta,
            "x": run.x,
            "y": run.y,
            "error": run.error,
            "h": run.h,
            "cycle": table["cycle"],
            "leg": table["leg"],
            "legs": run.leg_end,  # (x after each leg, as RepeatabilityResult.as_dict names it)
            "drift": run.drift,
            "h_change": h_change(run.h),
        }
        if run.platform is not None:
            runs[a]["platform_final"] = run.platform[-1]
        if a == "posture":
            rest, source = posture_rest(result.state, state_kinematics(result.state))
            runs[a].update(rest=rest, rest_from=source)
    return json.loads(
        to_json(
            {
                **provenance(when),
                "robot": result.title,
                "state": result.state.as_dict(),
                "generation": result.generation,
                **described(result),
                "variable_names": result.variable_names,
                "task_names": result.task_names,
                "targets": result.targets,
                "runs": runs,
                "functionals": functionals,
                "verdict": [v["text"] for v in verdict(result)],
            }
        )
    )


def csv_context(result: DashboardResult, when: datetime | None = None) -> list[str]:
    """The lines at the top of the CSV, each starting with '#' (``pandas.read_csv(...,
    comment="#")`` skips them): the jik version and the export's time, the generation and
    state, the columns' units, what each coordinate column is (``x_1 x1``: a joint's name), the
    verdict, and per algorithm its message, drift after each cycle, h's change and leg ends (the
    posture inverse's rest x_rest in force too)."""
    made, columns = provenance(when), described(result)
    lines = [
        f"# jik export of generation {result.generation}: {result.title}",
        f"# jik {made['jik_version']}, exported {made['exported_at']}",
        f"# state: {to_json(result.state.as_dict())}",
        "# units: " + "; ".join(f"{k} [{v}]" for k, v in columns["units"].items()),
        "# coordinates: " + "; ".join(f"{k} {v}" for k, v in columns["coordinates"].items()),
        f"# lengths: {columns['length_unit']}",
    ]
    lines += [f"# verdict: {v['text']}" for v in verdict(result)]
    kin = state_kinematics(result.state)
    for a, run in result.runs.items():
        ends = "; ".join(", ".join(f"{v:.6g}" for v in e) for e in run.leg_end)
        lines.append(f"# {a}: success {str(run.success).lower()}; {run.message}")
        drift = ", ".join(f"{d:.6g}" for d in run.drift) or "none (no closed path was driven)"
        lines.append(f"# {a} drift after each cycle: {drift}")
        dh = h_change(run.h)
        change = "not recorded (this run has no h)" if dh is None else f"{dh:.6g}"
        lines.append(f"# {a} h changed by: {change}")
        lines.append(f"# {a} leg ends (x after each leg): {ends}")
        if a == "posture":
            rest, source = posture_rest(result.state, kin)
            lines.append(f"# {a} rest x_rest ({source}): {', '.join(repr(v) for v in rest)}")
    return lines


def export_csv(result: DashboardResult, when: datetime | None = None) -> str:
    """The context (:func:`csv_context`, '#' lines), then one row per trajectory point of each
    run: the columns of :func:`run_columns` (``algorithm, cycle, leg, theta, x_1.., y_1..,
    error, h``)."""
    context = "".join(f"{line}\n" for line in csv_context(result, when))
    return context + "".join(csv_text((run_columns(result, a) for a in result.runs), "\n"))


def export_file(
    result: DashboardResult, kind: str, functionals: dict | None = None
) -> tuple[dict | str, str]:
    """The export of ``kind`` ("json": a dict, "csv": text) and its file name, made now."""
    when = datetime.now(UTC)
    body = export_json(result, functionals, when) if kind == "json" else export_csv(result, when)
    return body, export_filename(result, kind, when)
