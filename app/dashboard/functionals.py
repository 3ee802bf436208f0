"""The E1/E2 panel: the error functionals E1 (13) and E2 (18) of section 5 for the current
augmenting map h, on the robot's design region (else on the h panel's box,
:func:`jik.app.dashboard.analysis.augmenting_grid`), their sensitivity to the map's parameters
(or the other maps the robot offers), the key their cache is kept under, and the joint variables
that neither J nor h nor dh depends on (which the functionals therefore ignore)."""

from __future__ import annotations

import json
from collections.abc import Callable

from ...engine.dependence import inert_variables
from ...engine.exceptions import JikError, RunCancelled
from ...engine.functional_report import (
    MAX_TENSOR_VARIABLES,
    functionals_report,
    maps_report,
    parameters_report,
)
from ...engine.progress import ProgressCallbacks
from .algorithms import cache_key
from .analysis import expensive_map, kinematics_and_map, runs_box, vector_maps
from .model import DashboardState, robot_and_map
from .robots import state_kinematics, state_robot, state_spec
from .runs import Cancelled, DashboardResult

_inert_cache: dict[str, frozenset[int]] = {}


def state_inert_variables(state: DashboardState) -> frozenset[int]:
    """The joint variables that neither J nor h nor dh depends on
    (:func:`jik.engine.dependence.inert_variables`) over the robot's x_range, cached per robot,
    map and parameters."""
    key = json.dumps(robot_and_map(state), sort_keys=True)
    if key not in _inert_cache:
        kin, amap = kinematics_and_map(state)
        box = state_spec(state).x_range or ((-1.0, 1.0),) * kin.p
        if len(_inert_cache) >= 64:  # (slider values of l, a, b: keep the recent ones)
            del _inert_cache[next(iter(_inert_cache))]
        _inert_cache[key] = inert_variables(kin, amap, box)
    return _inert_cache[key]


def functionals_key(state: DashboardState) -> str:
    """Everything E1, E2 and their sensitivity depend on (see :func:`error_functionals`).

    On a robot's design region: the robot, the map and the start values of the variables
    outside the region (held fixed) that J, h or dh depends on
    (:func:`state_inert_variables`); the path, the cycles, gamma and the rest of x0 do not
    matter. Without a design region the box follows the runs: everything they depend on.
    """
    spec = state_spec(state)
    design = spec.functional_region
    if not design:
        return cache_key(state, "extended")
    inert = state_inert_variables(state)
    fixed = {
        n: state.x0[k]
        for k, n in enumerate(spec.variable_names)
        if n not in design and k not in inert
    }
    return json.dumps(robot_and_map(state) | {"fixed": fixed}, sort_keys=True)


#: E1 and E2 are taken by a tensor Gauss rule (over at most
#: :data:`~jik.engine.functional_report.MAX_TENSOR_VARIABLES` region variables) of this many
#: nodes per variable (fewer for a map that solves a problem per point).
NODES, EXPENSIVE_NODES = 12, 6


def error_functionals(
    result: DashboardResult,
    on_advance: Callable[[float, float], None] | None = None,
    cancelled: Callable[[], bool] = lambda: False,
) -> dict | None:
    """E1 (13) and E2 (18) of the current map, or None if unavailable: over the robot's design
    region from the registry (the boxes of sec. 5) where it has one, else over the heat-map box;
    a vector of p - r > 1 maps (E2 in the kernel frame the report names: the ``frame_axes`` of
    the robot's first e2_synthesized map, in which its E2 is minimal, else the best
    conditioned) over every joint, in the box of the runs
    (:func:`~jik.app.dashboard.analysis.runs_box`).
    ``on_advance(done, total)`` as the engine's
    :func:`~jik.engine.functional_report.functionals_report` advances (what it raises stops
    it), ``cancelled`` polled; over more than three variables, E1 and E2 by a Sobol rule.
    """
    grid, state, names = result.augmenting, result.state, result.variable_names
    vector = vector_maps(state)
    if grid is None and vector is None:
        return None
    if vector is not None:  # (p - r > 1: over every joint, the Sobol rule past three)
        kin, amap, nodes = state_kinematics(state), vector, NODES
        low, high = runs_box(state, result.runs)
        box = {n: (float(low[k]), float(high[k])) for k, n in enumerate(names)}
    elif grid is not None:
        kin, amap = grid["kinematics"], grid["map"]
        nodes = EXPENSIVE_NODES if expensive_map(amap) else NODES
        i, j = grid["axes"]
        box = {names[i]: tuple(grid["box"][0]), names[j]: tuple(grid["box"][1])}
    design = state_spec(state).functional_region
    region = dict(design) or box
    fixed = {n: float(state.x0[k]) for k, n in enumerate(names) if n not in region}
    items = (state_robot(state).definition.get("augmentations") or []) if vector else []
    synthesized = [a for a in items if isinstance(a, dict) and a.get("name") == "e2_synthesized"]
    frame = synthesized[0].get("frame_axes") if synthesized else None
    out = {
        "region": {k: list(v) for k, v in region.items()},
        "fixed": fixed,
        "nodes": nodes,
        "design_region": bool(design),
    }
    report = ProgressCallbacks(on_advance=on_advance, is_cancelled=cancelled)
    try:
        return out | functionals_report(kin, amap, region, fixed, nodes, report, frame)
    except RunCancelled:
        raise Cancelled from None


#: Values of each parameter in the E1/E2 sweep of the dashboard (over v - 1 .. v + 1).
SENSITIVITY_SAMPLES = 11


def sensitivity_evaluations(state: DashboardState, amap) -> int:
    """How many values of E1 or E2 :func:`sensitivity` computes for ``state`` and its map
    ``amap`` (its steps of progress): none for an expensive map or a design region over more
    variables than a tensor rule takes (E1 and E2 by a Sobol rule, no sweep); else both
    functionals at every point of the parameters' sweeps, or of each of the robot's maps."""
    if amap is None or expensive_map(amap):
        return 0
    spec = state_spec(state)
    if len(spec.functional_region) > MAX_TENSOR_VARIABLES:
        return 0
    params = spec.augmentation(state.augmentation).parameters
    if params:
        return 2 * (1 + len(params) * (2 + SENSITIVITY_SAMPLES))
    return 2 * len(spec.augmentations)


def sensitivity(
    result: DashboardResult,
    functionals: dict | None,
    cancelled: Callable[[], bool] = lambda: False,
    progress: Callable[[float, float], None] = lambda done, total: None,
) -> dict:
    """How E1 (13) and E2 (18) change with the parameters of the current map.

    Over the same box and fixed variables as ``functionals`` (see :func:`error_functionals`):

    * a map with parameters (C1, C2 or a, b): ``{"kind": "parameters", "parameters": {...},
      "E1": ..., "E2": ...}``, each from :func:`jik.engine.functional_report.parameter_sensitivity`
      (the value, the gradient and a sweep of every parameter over v - 1 .. v + 1);
    * a map without parameters: ``{"kind": "alternatives", "maps": [{"name", "E1", "E2",
      "current"}]}``, the functionals of every map the robot offers, at their defaults;
    * a vector of p - r > 1 maps: ``{"kind": "vector"}`` and ``functionals`` (no sweep: the
      robot's maps are vectors of formulas or a synthesis);
    * ``{"kind": "unavailable", "reason": ...}`` when they cannot be evaluated here.

    ``cancelled`` is polled before every evaluation of a functional (raises :class:`Cancelled`);
    ``progress(done, total)`` follows each of the :func:`sensitivity_evaluations`.
    """
    grid = result.augmenting
    if grid is None and functionals is None:
        return {"kind": "unavailable", "reason": "h could not be evaluated on a grid"}
    if functionals is None:
        return {"kind": "unavailable", "reason": "E1, E2 could not be evaluated"}
    if grid is None:  # (a vector of maps)
        return {"kind": "vector"} | functionals
    if functionals.get("E2_single_joint") is not None:  # (E2 by a Sobol rule, many joints)
        return single_joint_sensitivity(functionals)
    state = result.state
    if expensive_map(grid["map"]):
        return {
            "kind": "unavailable",
            "reason": "each value of E1, E2 of this map solves a "
            "collocation problem per node: no sweep in the dashboard",
        }
    if functionals.get("E1") is None and functionals.get("E2") is None:
        return {"kind": "unavailable", "reason": "E1, E2 are undefined on this box"}
    spec = state_spec(state)
    kin, nodes, fixed = grid["kinematics"], functionals["nodes"], functionals["fixed"]
    region = {k: tuple(v) for k, v in functionals["region"].items()}
    aug = spec.augmentation(state.augmentation)

    told = ProgressCallbacks(on_advance=progress, is_cancelled=cancelled)
    try:
        if aug.parameters:
            factory, samples = (lambda **p: aug.build(kin, **p)), SENSITIVITY_SAMPLES
            params = state.augmentation_parameters
            return parameters_report(kin, factory, params, region, nodes, fixed, samples, told)
        maps = [(m.name, lambda m=m: m.build(kin)) for m in spec.augmentations]  # (defaults)
        return maps_report(kin, maps, aug.name, region, nodes, fixed, told)
    except RunCancelled:
        raise Cancelled from None
    except (JikError, ValueError, ArithmeticError) as exc:
        return {"kind": "unavailable", "reason": str(exc)}


def single_joint_sensitivity(functionals: dict) -> dict:
    """The E1/E2 panel's data for a map whose E2 came from a Sobol rule
    (:func:`~jik.engine.functional_report.functionals_report`): E2 of the map and of h = s x_j
    for each joint, E1 of the map, ``{"kind": "single_joint", "E1", "E1_divergent", "E2",
    "maps": [{"name", "E2", "current"}], "nodes"}`` and the rule's error estimates of E1 and E2
    (``E1_error_estimate``, ``E2_error_estimate``; None where not finite)."""
    maps = [{"name": "h (current)", "E2": functionals["E2"], "current": True}]
    for name, row in functionals["E2_single_joint"].items():
        sign = "+" if row["sign"] > 0 else "−"
        maps.append({"name": f"h = {sign}{name}", "E2": row["e2"], "current": False})
    return {
        "kind": "single_joint",
        "E1": functionals["E1"],
        "E1_divergent": bool(functionals.get("E1_divergent")),
        "E2": functionals["E2"],
        **{f"{k}_error_estimate": functionals.get(f"{k}_error_estimate") for k in ("E1", "E2")},
        "maps": maps,
        "nodes": functionals["E2_rule"]["nodes"],
    }
