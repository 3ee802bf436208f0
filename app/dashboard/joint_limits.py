"""Whether each run of a dashboard result stayed within its robot's joint limits, and where it
first left them (:mod:`jik.engine.limits`), for the verdict, the summary and the 3D scene (the
paper's algorithms, eq. (7), know nothing of joint limits).
"""

from __future__ import annotations

import numpy as np

from ...engine.limits import LimitsReport, legs_report, limit_names, robot_limits
from .robots import state_kinematics


def state_limits(state) -> np.ndarray | None:
    """The joint limits (p, 2) of a state's robot; None when it declares none (every bound
    infinite, or the paper's robots)."""
    limits = robot_limits(state_kinematics(state))
    if limits is None or not np.isfinite(limits).any():
        return None
    return limits


def run_limits(result, algorithm: str) -> LimitsReport | None:
    """The limits report of ``result``'s run of ``algorithm``: its start x0, then its legs in
    order (leg k of cycle k // L + 1, L the legs of one cycle); None for a robot without
    limits."""
    state = result.state
    limits = state_limits(state)
    if limits is None:
        return None
    run = result.runs[algorithm]
    legs = [run.x[run.leg == k] for k in np.unique(run.leg)]
    names = limit_names(state_kinematics(state))
    L = max(1, len(result.targets))
    return legs_report(limits, np.asarray(state.x0, dtype=float), legs, L, names)


def outside_joints(limits: np.ndarray | None, x) -> np.ndarray:
    """The indices of the joint variables of ``x`` (p,) outside ``limits`` (none without)."""
    if limits is None:
        return np.zeros(0, dtype=int)
    x = np.asarray(x, dtype=float)
    return np.flatnonzero((x < limits[:, 0]) | (x > limits[:, 1]))
