"""A dashboard result exported: every point of both runs, as JSON or CSV."""

from __future__ import annotations

import json

import numpy as np

from jik.app.dashboard.messages import to_json
from jik.app.dashboard.runs import DashboardResult


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
        }
        if run.platform is not None:
            runs[a]["platform_final"] = run.platform[-1]
    return json.loads(to_json({
        "robot": result.title, "state": result.state.as_dict(), "generation": result.generation,
        "variable_names": result.variable_names, "task_names": result.task_names,
        "targets": result.targets, "runs": runs, "functionals": functionals,
    }))  # fmt: skip


def export_csv(result: DashboardResult) -> str:
    """One row per trajectory point: algorithm, leg, theta, x..., y..., error, h."""
    names, tasks = result.variable_names, result.task_names
    header = ["algorithm", "leg", "theta", *names, *tasks, "error", "h"]
    lines = [",".join(header)]
    for a, run in result.runs.items():
        h = run.h if run.h is not None else np.full(len(run.theta), np.nan)
        for k in range(len(run.theta)):
            vals = [a, str(int(run.leg[k]) + 1), repr(float(run.theta[k]))]
            vals += [repr(float(v)) for v in run.x[k]] + [repr(float(v)) for v in run.y[k]]
            vals += [repr(float(run.error[k])), "" if np.isnan(h[k]) else repr(float(h[k]))]
            lines.append(",".join(vals))
    return "\n".join(lines) + "\n"
