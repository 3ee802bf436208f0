"""``GET /robots``: the catalogue of robots, catalogue arms and algorithms, and the API's limits."""

from __future__ import annotations

import functools

from ...engine.arms import ARMS
from ...engine.registry import ALGORITHMS, ROBOTS
from ...engine.repeatability import MAX_CYCLES, MAX_PATH_POINTS
from ...engine.robot_spec import Robot, robot_from_dict
from ...engine.solve_rules import MODES
from . import schemas as S


@functools.cache
def _robots() -> tuple[Robot, ...]:
    """The paper's robots with their default parameters, then the catalogue arms with their
    default tasks (each built once: a URDF parse)."""
    return tuple(robot_from_dict({"name": name}) for name in (*ROBOTS, *ARMS))


def robots_response(timeout: float) -> S.RobotsResponse:
    """The catalogue: every robot with p, r, parameters, defaults, augmentations, its variables
    and task coordinates with their units (:mod:`jik.engine.units`), then the catalogue arms
    (``{"name": "panda"}``; ``task`` and ``reference`` change their r); ``timeout``: the
    server's time limit of a request [s]."""
    robots = [
        S.RobotInfo(
            **robot.spec.as_dict(),
            **robot.units.as_dict(),
            algorithms=list(S.Algorithm.__args__),  # type: ignore[attr-defined]
            modes=list(MODES),
        )
        for robot in _robots()
    ]
    limits = S.Limits(
        max_cycles=MAX_CYCLES,
        max_path_points=MAX_PATH_POINTS,
        max_iterations=S.MAX_ITERATIONS_CAP,
        max_trajectory_points=S.MAX_TRAJECTORY_POINTS,
        request_timeout_s=float(timeout),
    )
    algorithms = [S.AlgorithmInfo(**a.as_dict()) for a in ALGORITHMS.values()]
    return S.RobotsResponse(robots=robots, limits=limits, algorithms=algorithms)
