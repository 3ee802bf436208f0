"""The verdict's warning when the augmenting map is singular in its robot's design region (the
box of sec. 5 over which E1 (13) and E2 (18) are taken), saying where, so that a large E1 or E2
is not read as a bad fit: :func:`jik.engine.map_singularities.map_singularities` on that box,
the other variables at x0.
"""

from __future__ import annotations

import json

from ...engine.exceptions import JikError
from ...engine.map_singularities import MapSingularities, map_singularities
from .analysis import expensive_map, kinematics_and_map
from .model import DashboardState, robot_and_map
from .robots import state_spec


def singular_points(state: DashboardState) -> MapSingularities | None:
    """Where h or the extended Jacobian (10) is singular in the robot's design region; None
    when it has none, the map is expensive to evaluate (it solves a problem per point), the
    region's grid is too large (a 7-joint arm's) or h is regular there. Cached by what it
    depends on: the robot, its map and their parameters, and x0."""
    key = (json.dumps(robot_and_map(state), sort_keys=True), tuple(state.x0))
    if key not in _CACHE:
        if len(_CACHE) > 64:
            _CACHE.clear()
        _CACHE[key] = _find(state)
    return _CACHE[key]


_CACHE: dict[tuple[str, tuple[float, ...]], MapSingularities | None] = {}


def _find(state: DashboardState) -> MapSingularities | None:
    spec = state_spec(state)
    region = dict(spec.functional_region)
    if not region:
        return None
    try:
        kin, amap = kinematics_and_map(state)
        if amap is None or expensive_map(amap):
            return None
        fixed = {
            n: v for n, v in zip(spec.variable_names, state.x0, strict=True) if n not in region
        }
        return map_singularities(kin, amap, region, fixed=fixed)
    except (JikError, ValueError):
        return None


def singular_sentence(state: DashboardState) -> str | None:
    """The warning the verdict shows when h is singular in the design region, saying where
    (:meth:`jik.engine.map_singularities.MapSingularities.warning`)."""
    found = singular_points(state)
    return (
        None if found is None else found.warning(state.augmentation, state.augmentation_parameters)
    )
