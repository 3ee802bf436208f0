"""Engine results as JSON-ready documents: arrays to lists (null where not finite), a run's
trajectory downsampled, one solve's response and its joint-limit report (the fields of
``S.SolveResponse``), built without validating the model on the workers' hot path."""

from __future__ import annotations

from typing import Any

import numpy as np
import pydantic_core

from ...engine.exports import json_values
from ...engine.limits import run_report
from . import schemas as S


def nullable(a) -> Any:
    """Numbers -> nested lists with None where not finite (:func:`json_values`)."""
    return json_values(np.asarray(a, dtype=float))


def trajectory_document(traj) -> dict[str, Any]:
    """A run's trajectory as JSON-ready data, downsampled to at most ``MAX_TRAJECTORY_POINTS``
    evenly spread, first and last kept (the fields of
    :class:`~jik.app.compute.schemas.runs.Trajectory`)."""
    m, limit = len(traj.theta), S.MAX_TRAJECTORY_POINTS
    idx = np.arange(m)
    if m > limit:
        idx = np.unique(np.linspace(0, m - 1, limit).round().astype(int))
    return {
        "theta": nullable(traj.theta[idx]),
        "x": nullable(traj.x[idx]),
        "y": nullable(traj.y[idx]),
        "error": nullable(traj.error[idx]),
        "h": None if traj.h is None else nullable(np.asarray(traj.h)[idx]),
        "points": m,
        "downsampled": bool(len(idx) < m),
    }


def solve_response_json(setup, res) -> bytes:
    """One solve's response (``S.SolveResponse``) as JSON, built without validating the model
    (the workers' hot path: validation costs about as much as a small solve).
    ``tests/app/test_solve.py`` checks that the model reads it back as the same document."""
    return pydantic_core.to_json(
        {
            **setup.head,
            "tolerance": float(setup.run["tol"]),
            "x0": res.x0.tolist(),
            "target": res.y_d.tolist(),
            "x": nullable(res.x),
            "y": nullable(res.y),
            "error": nullable(res.error),
            "converged": bool(res.success),
            "message": str(res.message),
            "status": res.status,
            "iterations": int(res.nit),
            "trajectory": trajectory_document(res.trajectory),
            **limits_document(setup.kinematics, res),
        }
    )


def limits_document(kinematics, result) -> dict[str, Any]:
    """``{"limits": ...}`` of a run (:func:`jik.engine.limits.run_report`), empty when the
    robot has none."""
    report = run_report(kinematics, result)
    return {} if report is None else {"limits": report.as_dict()}
