"""A dashboard result exported: every point of both runs, as JSON or CSV, with the state that
produced it, what the page says about it (the verdict) and each run's drift and leg ends."""

from __future__ import annotations

import json

import numpy as np

from jik.app.dashboard.messages import h_change, to_json
from jik.app.dashboard.runs import DashboardResult
from jik.app.dashboard.verdict import verdict


def export_json(result: DashboardResult, functionals: dict | None = None) -> dict:
    """The current result as plain JSON: the state, and both runs point by point."""
    runs = {}
    for a, run in result.runs.items():
        runs[a] = {
            "success": run.success,
            "message": run.message,
            "theta": run.theta,
            "x": run.x,
            "y": run.y,
            "error": run.error,
            "h": run.h,
            "leg": run.leg,
            "leg_end": run.leg_end,
            "drift": run.drift,
            "h_change": h_change(run.h),
        }
        if run.platform is not None:
            runs[a]["platform_final"] = run.platform[-1]
    return json.loads(to_json({
        "robot": result.title, "state": result.state.as_dict(), "generation": result.generation,
        "variable_names": result.variable_names, "task_names": result.task_names,
        "targets": result.targets, "runs": runs, "functionals": functionals,
        "verdict": [v["text"] for v in verdict(result)],
    }))  # fmt: skip


def csv_context(result: DashboardResult) -> list[str]:
    """The lines at the top of the CSV, each starting with '#' (``pandas.read_csv(...,
    comment="#")`` skips them): the generation and state, the verdict, and per algorithm its
    message, drift after each cycle, h's change and leg ends."""
    lines = [f"# jik export of generation {result.generation}: {result.title}",
             f"# state: {to_json(result.state.as_dict())}"]  # fmt: skip
    lines += [f"# verdict: {v['text']}" for v in verdict(result)]
    for a, run in result.runs.items():
        ends = "; ".join(", ".join(f"{v:.6g}" for v in e) for e in run.leg_end)
        lines.append(f"# {a}: success {str(run.success).lower()}; {run.message}")
        lines.append(f"# {a} drift after each cycle: {', '.join(f'{d:.6g}' for d in run.drift)}")
        dh = h_change(run.h)
        lines.append(f"# {a} h changed by: {'' if dh is None else f'{dh:.6g}'}")
        lines.append(f"# {a} leg ends (x after each leg): {ends}")
    return lines


def export_csv(result: DashboardResult) -> str:
    """The context (:func:`csv_context`, '#' lines), then one row per trajectory point:
    algorithm, leg, theta, x..., y..., error, h."""
    names, tasks = result.variable_names, result.task_names
    header = ["algorithm", "leg", "theta", *names, *tasks, "error", "h"]
    lines = [*csv_context(result), ",".join(header)]
    for a, run in result.runs.items():
        h = run.h if run.h is not None else np.full(len(run.theta), np.nan)
        for k in range(len(run.theta)):
            vals = [a, str(int(run.leg[k]) + 1), repr(float(run.theta[k]))]
            vals += [repr(float(v)) for v in run.x[k]] + [repr(float(v)) for v in run.y[k]]
            vals += [repr(float(run.error[k])), "" if np.isnan(h[k]) else repr(float(h[k]))]
            lines.append(",".join(vals))
    return "\n".join(lines) + "\n"
