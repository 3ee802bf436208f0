"""What the page writes above the plots, computed from the result in the engine's sentences
(:mod:`jik.engine.findings`): for each algorithm whether it was repeatable on the closed path
and by how much, how much h changed along the extended Jacobian's run, and why, and a warning
when h is singular in the robot's design region (:func:`singular_points`), so that a large E1 or
E2 is not read as a bad fit.
"""

from __future__ import annotations

import json

from ...engine.exceptions import JikError
from ...engine.findings import NAMES, Finding
from ...engine.findings import verdict as run_verdict
from ...engine.map_singularities import MapSingularities, map_singularities
from ...engine.pose_task import cut_notes
from ...engine.practical_findings import PRACTICAL, practical_findings
from ...engine.reproductions.unicycle import undefined_why
from .algorithms import rest_words
from .analysis import expensive_map, kinematics_and_map
from .joint_limits import state_limits
from .model import DashboardState, robot_and_map
from .plotting import norm_unit, units
from .robots import state_inverse, state_kinematics, state_spec
from .runs import AlgorithmRun, DashboardResult


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


def _undefined_why(result: DashboardResult, run: AlgorithmRun) -> list[Finding]:
    """Why the unicycle's map of characteristics (29) became undefined along the extended run
    (:func:`jik.engine.reproductions.unicycle.undefined_why`)."""
    state = result.state
    if (
        state.robot != "unicycle"
        or state.augmentation != "characteristics"
        or run.status != "undefined"
        or len(run.x) < 2
    ):
        return []
    a = float(state.augmentation_parameters.get("a", 1.0))
    discrete = state.mode == "discrete"
    step = f"iteration {len(run.x) - 1}" if discrete else "the run's last step"
    q0 = state.robot_parameters.get("q0", ())
    lam10 = (float(run.x[-2][0]), float(run.x[-1][0]))
    texts = undefined_why(q0, a, lam10, step, discrete)
    return [Finding(t, r, "extended") for t, r in zip(texts, ("why", "note"), strict=False)]


def _practical(result: DashboardResult, unit: str) -> list[Finding]:
    """What the practical inverses' parameters did
    (:func:`jik.engine.practical_findings.practical_findings`); the weighted inverse's only for
    a robot without joint limits (one with some has its sentence from
    :attr:`~jik.app.dashboard.runs.DashboardResult.limits`)."""
    state, out = result.state, []
    for a in (a for a in result.runs if a in PRACTICAL):
        if a == "weighted" and state_limits(state) is not None:
            continue
        inverse, run = state_inverse(state, a), result.runs[a]
        rest = rest_words(state, state_spec(state), inverse) if a == "posture" else None
        tol, legs = state.tolerance, len(result.targets)
        found = practical_findings(inverse, run, unit, tol, result.runs, rest, legs=legs)
        out += [Finding(text, role, a) for text, role in found]
    return out


def verdict(result: DashboardResult) -> list[dict]:
    """The sentences the page shows above the plots for ``result`` (:class:`Finding` dicts):
    each chosen algorithm's finding, then why (:func:`jik.engine.findings.verdict`); failures
    with the engine's message."""
    runs, state = result.runs, result.state
    path = state.task == "path"
    unit = norm_unit(units(result)[0])
    e = runs.get("extended")
    undefined = [] if e is None else _undefined_why(result, e)
    out = run_verdict(runs, path, state.mode, state.gamma, unit, undefined)
    out += _practical(result, unit)
    if path:  # (a leg the long way round a pose task's rotation coordinates)
        kin = state_kinematics(state)
        out += [Finding(t, "note") for t in cut_notes(kin, state.x0, result.targets)]
    robot = state_spec(state).title
    for a, report in result.limits.items():
        role = "note" if report.within else "warning"
        out.append(Finding(report.sentence(NAMES[a], robot), role, a))
    if e is not None and (found := singular_points(state)):
        warning = found.warning(state.augmentation, state.augmentation_parameters)
        out.append(Finding(warning, "warning", "extended"))
    return [s._asdict() for s in out]
