"""Synthesis over a box (section 3): a catalogue map evaluated, or an E2-optimal one synthesized
(:mod:`jik.engine.functionals`, :mod:`jik.engine.variational`): h on a grid of the box, its
coefficients, E1 and E2 (:func:`synthesize_request`). With ``'e2_total_degree'``, E2-optimal
maps over any number of joint variables (:func:`jik.engine.synthesis_nd.synthesize_e2_nd`, eq.
(19) on a total-degree Legendre basis with a scrambled Sobol rule; for p - r >= 2 the maps h_1
... h_(p-r) of the functional generalised in ``docs/e2-vector.md``).
"""

from __future__ import annotations

from typing import Any, get_args

from ...engine.augmentations import Polynomial2
from ...engine.exceptions import JikError
from ...engine.functional_report import functional_info
from ...engine.functionals import check_region
from ...engine.kinematics import Kinematics
from ...engine.map_grid import map_grid
from ...engine.map_singularities import map_singularities
from ...engine.registry import RobotSpec
from ...engine.robot_synthesis import TOTAL_DEGREE, default_box
from ...engine.synthesis_nd import synthesize_e2_nd
from ...engine.variational import DEFAULT_DEGREE, synthesize_e2
from . import schemas as S
from .documents import nullable
from .exceptions import RequestError
from .robot_requests import request_robot
from .schemas.wording import without_field


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
    if len(region) > 3 and req.method == "e2_variational":
        raise RequestError(
            "region",
            f"'e2_variational' takes 2 or 3 variables, got {len(region)}; 'e2_total_degree' "
            "synthesizes h of any number",
        )
    region, fixed = check_region(kin, region, req.fixed)
    return list(spec.variable_names), region, fixed


def _functionals(
    kin, amap, region, fixed, nodes, frame_axes=None, labels=("e1", "e2")
) -> tuple[dict, list[str]]:
    """E1 (13) and E2 (18) (those of ``labels``) of ``amap`` (a map, or a tuple of p - r maps:
    E2 in the kernel frame of ``frame_axes``, default the best conditioned) by the rule the
    region's size calls for (:func:`~jik.engine.functional_report.functional_info`), and what
    the message says."""
    notes: list[str] = []
    out: dict[str, S.FunctionalInfo | None] = {}
    for label in labels:
        try:
            info = functional_info(label.upper(), kin, amap, region, fixed, nodes, frame_axes)
            out[label] = S.FunctionalInfo.model_validate(info)
            if info["divergent"]:
                notes.append(f"{label.upper()} diverges: det(dh K) vanishes inside the region")
            if info["frame_axes"]:
                notes.append(f"E2 in the kernel frame of joints {info['frame_axes']}")
            if info["value"] is None and not info["divergent"]:
                notes.append(f"{label.upper()} undefined: h is not defined on all of the region")
        except JikError as exc:
            if getattr(exc, "field", None) == "frame_axes":
                raise RequestError("frame_axes", without_field(str(exc), "frame_axes")) from None
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
            f"(p = r + 1); this {spec.name} robot has p = {spec.p}, r = {spec.r}: "
            + (
                "its Jacobian is square, so it has no room for a map"
                if spec.p == spec.r
                else f"give its extended inverse {spec.p - spec.r} formula maps instead "
                "({'name': 'formula', 'h': [...]})"
            ),
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
            top = req.degree or DEFAULT_DEGREE.get(len(region), 1)  # (even degrees below it)
            steps = range(2, top, 2)
            result = synthesize_e2(kin, region, degree=top, fixed=fixed, convergence_degrees=steps)
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
    own = (getattr(aug_used, "definition", None) or {}).get("frame_axes")  # (its synthesis's)
    own = own if isinstance(amap, tuple) else None  # (a vector's; one map has none)
    functionals, more = _functionals(kin, amap, region, fixed, nodes, req.frame_axes or own)
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


#: The engine's fields of a total-degree synthesis, as the request names them (others: region).
_FIELDS = {"degree": "degree", "nodes": "qmc_nodes", "frame_axes": "frame_axes"}


def grid(amap, names, region, fixed, n: int) -> S.SynthesisGrid | None:
    """h on the response's grid (:func:`jik.engine.map_grid.map_grid`); None for one variable."""
    found = map_grid(amap, names, region, fixed, n)
    if found is None:
        return None
    return S.SynthesisGrid(axes={k: v.tolist() for k, v in found.axes.items()}, h=nullable(found.h))


def singularities(
    kin, amap, region, fixed, nodes: int
) -> tuple[S.MapSingularitiesInfo | None, list[str], bool]:
    """Where h is singular in the box (:func:`jik.engine.map_singularities.map_singularities`
    on a grid of ``nodes`` points per variable, as many as E1's and E2's Gauss rule: a
    polynomial map costs as much there), what the response's message says of it, and whether
    it was searched: not for a map that solves a problem per point (a characteristic's, eq.
    (28): seconds for a grid), as the dashboard does not either, nor where the search does
    not apply (a vector of maps, too large a grid)."""
    if isinstance(amap, tuple):
        return None, ["singularities of h not searched: h is a vector of maps"], False
    if amap.solves_per_point:
        return None, ["singularities of h not searched: each value of h solves a problem"], False
    try:
        found = map_singularities(kin, amap, region, fixed=fixed, nodes=nodes)
    except JikError as exc:
        return None, [f"singularities of h not searched: {exc}"], False
    if found is None:
        return None, [], True
    info = S.MapSingularitiesInfo.model_validate(found.as_dict())
    return info, [f"h is singular in the box: {found}"], True


def map_response(
    req, robot_used, kin, amap, box, notes: list[str], **fields
) -> S.SynthesizeResponse:
    """The response of a synthesis whose map h is ``amap`` on ``box`` (the variables' names,
    the region, the values of the others: :func:`jik.engine.functionals.check_region`'s): h
    on the grid and where it is singular, the message ``notes`` and what the search says, with
    the method's own ``fields``. A tuple of p - r maps shows h_1 on the grid, unsearched."""
    names, region, fixed = box
    all_fixed = {n: float(fixed[n]) for n in names if n not in region}
    found, said, searched = singularities(kin, amap, region, all_fixed, req.nodes)
    if isinstance(amap, tuple):  # (p - r >= 2: a vector of maps)
        notes = [*notes, f"{len(amap)} maps h_1 ... h_{len(amap)}; the grid shows h_1"]
        amap = amap[0]
    return S.SynthesizeResponse(
        robot=robot_used,
        method=req.method,
        region={k: [float(lo), float(hi)] for k, (lo, hi) in region.items()},
        fixed=all_fixed,
        grid=grid(amap, names, region, all_fixed, req.grid),
        singularities=found,
        singularities_searched=searched,
        message="; ".join(notes + said) or "ok",
        **fields,
    )


def total_degree_response(
    req: S.SynthesizeRequest, kin, robot_used: S.RobotUsed, box: tuple[list[str], dict, dict]
) -> S.SynthesizeResponse:
    """The E2-optimal map(s) of ``req`` on its box (names, region, fixed values): E1 (by the rule
    the box's size calls for) and E2 on the fitting rule and on an independent one, its
    convergence with the degree and the nodes, h_1 on a grid, the basis and coefficients."""
    names, region, fixed = box
    degree = TOTAL_DEGREE if req.degree is None else req.degree
    try:
        res = synthesize_e2_nd(
            kin,
            region,
            degree=degree,
            nodes=req.qmc_nodes,
            fixed=fixed,
            seed=req.seed,
            frame_axes=req.frame_axes,
            convergence_degrees=range(1, degree),
        )
    except JikError as exc:
        field = getattr(exc, "field", None) or ""
        raise RequestError(_FIELDS.get(field, "region"), without_field(str(exc), field)) from None
    info: dict[str, Any] = {
        k: v for k, v in res.as_dict().items() if k not in ("region", "fixed", "convergence")
    }
    info["basis"] = res.maps[0].index.tolist()
    info["coefficients"] = [m.coefficients.tolist() for m in res.maps]
    notes = [
        f"E2 {res.e2:.6g} on the fitting rule, {res.e2_check:.6g} on an independent rule "
        f"of {res.nodes} nodes ({len(info['coefficients'][0])} unknowns per map)"
    ]
    if res.single_joint:
        j, best = min(res.single_joint.items(), key=lambda item: item[1]["e2"])
        notes.append(
            f"the best single joint, h = {'-' if best['sign'] < 0 else ''}{j}, has "
            f"E2 {best['e2']:.6g}"
        )
    amap = res.maps if len(res.maps) > 1 else res.maps[0]
    e1, more = _functionals(kin, amap, res.region, res.fixed, req.nodes, labels=("e1",))
    return map_response(
        req,
        robot_used,
        kin,
        amap,
        (names, res.region, {**fixed, **res.fixed}),
        notes + more,
        augmentation=S.AugmentationUsed(
            name=res.maps[0].name,
            parameters={
                "degree": float(degree),
                "unknowns": float(len(res.maps[0].index)),
                "maps": float(len(res.maps)),
            },
        ),
        coefficients={},
        functionals={
            "e1": e1["e1"],
            "e2": S.FunctionalInfo(
                value=nullable(res.e2_check),
                n_points=res.nodes,
                n_singular=0,
                min_abs_dh_k=None,
                rule="sobol",
                frame_axes=list(res.frame_axes) or None,
                error_estimate=None,  # (total_degree's e2 and e2_check, two rules, say it)
            ),
        },
        convergence=[{k: float(v) for k, v in row.items()} for row in res.convergence],
        total_degree=S.TotalDegreeInfo(**info),
    )
