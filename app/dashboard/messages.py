"""What a dashboard sends its listeners: events with JSON data, and a result's summary."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from jik.app.dashboard.runs import DashboardResult


@dataclass(frozen=True)
class Event:
    """A message to the subscribers: ``data`` is the JSON sent to the page."""

    kind: str  # "state" | "progress" | "result" | "functionals" | "error" | "ahead"
    generation: int
    data: str
    result: DashboardResult | None = None


def digest(text: str) -> str:
    return hashlib.md5(text.encode()).hexdigest()[:16]


def to_json(obj) -> str:
    return json.dumps(obj, separators=(",", ":"), allow_nan=False, default=jsonable)


def with_figures(message: dict, figures: Mapping[str, str]) -> str:
    """The JSON of ``message`` with a "figures" object of already serialized figures."""
    body = ",".join(f'"{k}":{t}' for k, t in figures.items())
    return to_json(message)[:-1] + ',"figures":{' + body + "}}"


def jsonable(v):
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, np.generic):
        return v.item()
    raise TypeError(f"not JSON serialisable: {type(v).__name__}")


def summary(result: DashboardResult) -> dict:
    """Numbers shown beside the plots: per algorithm success, message, drift, final x."""
    out = {}
    for a, run in result.runs.items():
        out[a] = {
            "success": run.success,
            "message": run.message,
            "drift": [float(d) for d in run.drift],
            "x_final": [float(v) for v in run.x[-1]],
            "h_change": None if run.h is None else float(np.max(run.h) - np.min(run.h)),
            "points": len(run.theta),
            "seconds": round(run.seconds, 4),
            "cached": bool(result.cached.get(a, False)),
        }
    return out
