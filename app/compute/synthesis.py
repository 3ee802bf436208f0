"""Synthesis over a box (section 3): a catalogue map evaluated, or an E2-optimal one synthesized
(:mod:`jik.engine.functionals`, :mod:`jik.engine.variational`): h on a grid of the box, its
coefficients, E1 and E2 (:func:`synthesize_request`).
"""

from __future__ import annotations

from typing import get_args

from ...engine.augmentations import Polynomial2
from ...engine.exceptions import JikError
from ...engine.functionals import check_region, error_functional_e1, error_functional_e2
from ...engine.kinematics import Kinematics
from ...engine.registry import RobotSpec
from ...engine.robot_synthesis import default_box
from ...engine.variational import synthesize_e2
from . import schemas as S
from .exceptions import RequestError
from .robot_requests import request_robot
from .synthesis_total import map_response, total_degree_response


def synthesis_methods() -> S.SynthesisMethodsResponse:
    return S.SynthesisMethodsResponse(
        methods=list(get_args(S.SynthesisMethod)),
        notes=S.METHODS
        | {"error_functionals": "E1 (13) and E2 (18) by Gauss quadrature (engine.functionals)"},
    )


def synthesis_region(spec: RobotSpec, kin: Kinematics, req: S.SynthesizeRequest):
    """The variable names, the box and the fixed values of a synthesis request, checked by the
    engine (:func:`jik.engine.functionals.check_region`: the variables outside the box held
    at the robot's default start, :func:`jik.engine.kinematics.held_values`)."""
    size = {"e2_variational": 2, "e2_total_degree": spec.p}.get(req.method, 3)
    if req.region is None:
        region = default_box(spec, size, req.fixed or {})
    else:
        region = {k: (float(lo), float(hi)) for k, (lo, hi) in req.region.items()}
    if len(region) > 3 and req.method != "e2_total_degree":
        raise RequestError(
            "region",
            f"'{req.method}' takes 1 to 3 variables (2 or 3 for 'e2_variational'), got "
            f"{len(region)}; 'e2_total_degree' synthesizes h of any number",
        )
    region, fixed = check_region(kin, region, req.fixed)
    return list(spec.variable_names), region, fixed


def _functionals(kin, amap, region, fixed, nodes) -> tuple[dict, list[str]]:
    notes: list[str] = []
    out: dict[str, S.FunctionalInfo | None] = {}
    for label, fn in (("e1", error_functional_e1), ("e2", error_functional_e2)):
        try:
            value = fn(kin, amap, region, nodes=nodes, fixed=fixed)
            out[label] = S.FunctionalInfo.model_validate(value.as_dict())
            if value.divergent:
                notes.append(f"{label.upper()} diverges: dh K vanishes inside the region")
        except JikError as exc:
            out[label] = None
            notes.append(f"{label.upper()} not evaluated: {exc}")
    return out, notes


def synthesize_request(req: S.SynthesizeRequest) -> S.SynthesizeResponse:
    """Evaluate a catalogue map, or synthesize an E2-optimal one, over a box (section 3)."""
    robot = request_robot(req.robot, req.augmentation, with_map=req.method == "evaluate")
    spec, kin, robot_used = robot.spec, robot.kinematics, robot.robot
    if req.method == "e2_variational" and spec.p != spec.r + 1:  # (a user robot's)
        raise RequestError(
            "method",
            f"'e2_variational' synthesizes one map h, which needs one degree of redundancy "
            f"(p = r + 1); this {spec.name} robot has p = {spec.p}, r = {spec.r}: give its "
            f"extended inverse {spec.p - spec.r} formula maps instead ({{'name': 'formula', "
            "'h': [...]}})",
        )
    if req.method != "evaluate" and req.augmentation is not None:
        raise RequestError("augmentation", f"'{req.method}' synthesizes h; give no map")
    names, region, fixed = synthesis_region(spec, kin, req)
    if req.method == "e2_total_degree":
        return total_degree_response(req, kin, robot_used, (names, region, fixed))
    convergence: list[dict[str, float]] = []
    coefficients: dict[str, float] = {}
    notes: list[str] = []
    if req.method == "e2_variational":
        try:
            result = synthesize_e2(kin, region, degree=req.degree, fixed=fixed)
        except JikError as exc:  # (the degree's bound depends on the region's variables)
            field = "degree" if getattr(exc, "field", None) == "degree" else "region"
            raise RequestError(field, str(exc)) from None
        amap = result.augmenting_map
        aug_used = S.AugmentationUsed(name=getattr(amap, "name", "e2_synthesized"), parameters={})
        convergence = [
            {k: float(v) for k, v in row.items() if isinstance(v, int | float)}
            for row in result.convergence
        ]
        if result.polynomial is not None:
            coefficients = result.polynomial_coefficients()
            notes.append(
                f"E2 of the synthesized map {result.e2:.6g}; of its cubic fit "
                f"{result.polynomial_e2:.6g}"
            )
        region, fixed = dict(result.region) or region, dict(result.fixed) or fixed
        nodes = max(req.nodes, result.nodes)  # (the rule it was minimised on, or a finer one)
    else:
        amap, aug_used = robot.augmenting_map()  # (the request's map, else the robot's default)
        coefficients = amap.monomials() if isinstance(amap, Polynomial2) else {}
        nodes = req.nodes
    functionals, more = _functionals(kin, amap, region, fixed, nodes)
    return map_response(
        req,
        robot_used,
        kin,
        amap,
        (names, region, fixed),
        notes + more,
        augmentation=aug_used,
        coefficients=coefficients,
        functionals=functionals,
        convergence=convergence,
        total_degree=None,
    )
