"""``POST /synthesize`` and ``GET /synthesize``: synthesis of augmenting maps on a box."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from ....engine.registry import RobotSpec
from ....engine.robot_synthesis import TOTAL_DEGREE, TOTAL_NODES
from ....engine.variational import DEFAULT_DEGREE, MAX_DEGREE
from .fields import INTEGRAL, MAX_DIMENSION, Bound, Coordinate, FrameAxes, MaybeFloat, Seed
from .robots import AnyAugmentation, AnyRobot, AugmentationUsed, RobotUsed
from .variants import narrowed, per_robot

SynthesisMethod = Literal["evaluate", "e2_variational", "e2_total_degree"]
#: What each method does: the ``method`` field's description and ``GET /synthesize``'s notes.
METHODS = {
    "evaluate": "any map of the catalogue (GET /robots; analytic or already synthesized): h on "
    "a grid of the box, polynomial coefficients, E1 and E2 on the box",
    "e2_variational": "minimise E2 (eq. (19)) over h of the box variables by the Ritz method on "
    "a tensor Legendre basis of 2 or 3 variables (engine.variational.synthesize_e2)",
    "e2_total_degree": "minimise E2 over h of any number of box variables, and h_1 ... h_(p-r) "
    "for p - r >= 2, on a total-degree Legendre basis with a scrambled Sobol rule "
    "(engine.synthesis_nd.synthesize_e2_nd): E2 on the fitting and on an independent rule, its "
    "convergence with the degree and the nodes",
}
#: Sobol nodes of a total-degree synthesis (a power of two): bounds (default: the engine's).
MIN_QMC_NODES, MAX_QMC_NODES = 64, 2**17


class SynthesizeRequest(BaseModel):
    """Synthesize or evaluate an augmenting map h over a box of the joint space."""

    model_config = ConfigDict(extra="forbid")

    robot: AnyRobot
    method: SynthesisMethod = Field(
        "evaluate", description="; ".join(f"'{k}': {v}" for k, v in METHODS.items())
    )
    augmentation: AnyAugmentation | None = Field(
        None, description="for 'evaluate': the map and its parameters (default: the robot's)"
    )
    region: dict[str, tuple[Bound, Bound]] | None = Field(
        None,
        max_length=MAX_DIMENSION,
        description="box {variable: [lo, hi]} (2 or 3 variables for 'e2_variational'; any "
        "number for 'evaluate', E1 and E2 by a Sobol rule past three, and 'e2_total_degree'); "
        "default: the last 3 (2 for 'e2_variational', all for "
        "'e2_total_degree') variables: the robot's design region (functional_region of "
        "/robots) when it has that many, else each over a tenth of its x_range either side "
        "of the robot's default start",
    )
    fixed: dict[str, Coordinate] | None = Field(
        None,
        max_length=MAX_DIMENSION,
        description="values of the variables not in the box (default: the default start)",
    )
    nodes: Annotated[int, Field(strict=True, ge=2, le=24), INTEGRAL] = Field(
        8,
        description="Gauss-Legendre nodes per variable for E1 and E2 (of a map 'e2_variational' "
        "synthesizes, at least its degree + 8: the rule it was synthesized on, on which its E2 "
        "is the convergence's last), and grid points per variable of the search for h's "
        "singularities (singularities)",
    )
    degree: Annotated[int, Field(strict=True, ge=1, le=24), INTEGRAL] | None = Field(
        None,
        description="'e2_variational': Legendre degree per variable (default: "
        f"{DEFAULT_DEGREE[2]} over two variables, {DEFAULT_DEGREE[3]} over three, "
        f"engine.variational.DEFAULT_DEGREE; at most {MAX_DEGREE[3]} over three); "
        f"'e2_total_degree': total degree of the basis (default {TOTAL_DEGREE})",
    )
    qmc_nodes: Annotated[int, Field(strict=True, ge=MIN_QMC_NODES, le=MAX_QMC_NODES), INTEGRAL] = (
        Field(
            TOTAL_NODES,
            description="'e2_total_degree': nodes of the scrambled Sobol rule, a power of two, at "
            "least twice the basis' unknowns",
        )
    )
    seed: Seed = Field(0, description="'e2_total_degree': seed of the Sobol rule's scrambling")
    frame_axes: FrameAxes | None = Field(
        None,
        description="p - r >= 2, 'e2_total_degree' and 'evaluate': the p - r joints (1-based) "
        "whose axes fix the kernel frame of E2 (default: a synthesized vector's own, else those "
        "best conditioned at the box's centre, engine.kernel_frame.best_frame_axes; "
        "functionals.e2.frame_axes and total_degree.frame_axes say which); refused for p - r = "
        "1, whose frame is its kernel vector",
    )
    grid: Annotated[int, Field(strict=True, ge=3, le=61), INTEGRAL] = Field(
        21, description="grid points per axis for h"
    )


def _synthesis_fields(spec: RobotSpec) -> dict[str, Any]:
    names = tuple(spec.variable_names)
    variable = Literal[names]  # type: ignore[valid-type]
    return {
        "region": (
            Annotated[
                dict[variable, tuple[Bound, Bound]], Field(min_length=1, max_length=len(names))
            ]
            | None,
            Field(
                None,
                description=f"box {{variable: [lo, hi]}}, lo < hi, of {list(names)} (2 or "
                "more draw a grid of h; 'e2_variational' needs 2 or 3; 'evaluate' and "
                "'e2_total_degree' take any number), none of them fixed; default: the last 3 "
                "(2 for 'e2_variational', all for 'e2_total_degree') not fixed: the robot's "
                "design region when it has that many, else each over a tenth of its range "
                "either side of the default start",
            ),
        ),
        "fixed": narrowed(SynthesizeRequest, "fixed", dict[variable, Coordinate] | None),
    }


#: ``POST /synthesize``'s body: a :class:`SynthesizeRequest` with its robot's variables.
SynthesizeBody = per_robot(SynthesizeRequest, _synthesis_fields)


class FunctionalInfo(BaseModel):
    value: MaybeFloat = Field(description="the integral; null where it is not finite")
    n_points: int
    n_singular: int = Field(
        description="quadrature points where [J; dh] is singular (of the Sobol rule: where h is "
        "undefined)"
    )
    min_abs_dh_k: MaybeFloat
    rule: Literal["gauss", "sobol"] = Field(
        "gauss",
        description="the Gauss-Legendre rule of 'nodes' per variable over at most three "
        "variables, else a scrambled Sobol rule of n_points (engine.functional_report)",
    )
    divergent: bool = Field(
        default=False,
        description="E1 diverges: det(dh K) vanishes inside the region (eq. (14)); value is null",
    )
    frame_axes: list[int] | None = Field(
        None,
        description="E2 of a vector of p - r >= 2 maps: the joints (1-based) whose axes fix the "
        "kernel frame E2 depends on (engine.kernel_frame); null otherwise",
    )
    error_estimate: MaybeFloat = Field(
        None,
        description="of the Sobol rule: |value - the same rule on its first half of the nodes|, "
        "an estimate of the quadrature error (engine.e2_qmc.error_estimate); null for the Gauss "
        "rule, where value is null, and for a total-degree synthesis's E2 (total_degree's e2 "
        "and e2_check, on two independent rules, say how far apart they are)",
    )


class MapSingularitiesInfo(BaseModel):
    """Where h is singular on a grid of the box (engine.map_singularities.MapSingularities)."""

    where: dict[str, list[float]] = Field(
        description="per box variable, [lo, hi] of the grid points where h is singular"
    )
    fraction: float = Field(
        description="the fraction of the grid's points where h is singular (of the grid, not "
        "of the box: a rank loss or a pole is found at the points beside it, fewer of them on "
        "a finer grid)"
    )
    reasons: list[str] = Field(
        description="what is singular there: 'h or its gradient is not finite', 'the gradient "
        "of h blows up', 'the extended Jacobian (10) loses rank' (at a point, or det [J; dh] "
        "changes sign between neighbours: dh K = 0, where E1 diverges), 'h jumps through "
        "infinity'"
    )
    nodes: int = Field(description="grid points per box variable, ends included")


class SynthesisGrid(BaseModel):
    axes: dict[str, list[float]] = Field(description="the two grid variables and their values")
    h: list[list[MaybeFloat]] = Field(description="h[i][j] at (axis 1 [i], axis 2 [j])")


class TotalDegreeInfo(BaseModel):
    """A total-degree synthesis (engine.synthesis_nd_result.TotalDegreeSynthesis)."""

    e2: float = Field(description="E2 of the maps on the fitting rule (the Ritz value)")
    e2_check: float = Field(
        description="E2 on an independent scrambled Sobol rule of as many nodes: the value to "
        "trust; its distance to e2 measures the quadrature error"
    )
    degree: int
    nodes: int
    seed: int
    unknowns: int = Field(description="basis polynomials per map")
    single_joint: dict[str, dict[str, float]] = Field(
        description="p - r = 1: E2 of h = sign * x_j for each region variable, the better sign"
    )
    frame_axes: list[int] = Field(description="p - r >= 2: the kernel frame's joints (1-based)")
    basis: list[list[int]] = Field(
        description="(unknowns, d): multi-indices a of the basis prod_k sqrt(2 a_k + 1) "
        "P_(a_k)(t_k), t the region's variables mapped onto [-1, 1]"
    )
    coefficients: list[list[float]] = Field(description="(p - r, unknowns): each map's")


class SynthesizeResponse(BaseModel):
    robot: RobotUsed
    method: SynthesisMethod
    augmentation: AugmentationUsed
    region: dict[str, list[float]]
    fixed: dict[str, float]
    grid: SynthesisGrid | None
    coefficients: dict[str, float] = Field(
        description="polynomial coefficients, when there are any"
    )
    functionals: dict[str, FunctionalInfo | None] = Field(
        description="E1 (13) and E2 (18) of the map on the box; null where undefined (see message)"
    )
    convergence: list[dict[str, float]] = Field(
        description="'e2_variational': {degree, unknowns, e2}, E2 against the Legendre degree; "
        "'e2_total_degree': {degree, nodes, unknowns, e2}, the Ritz value with the degree at all "
        "the nodes, then with the nodes (leading 2^k of the rule) at the final degree"
    )
    singularities: MapSingularitiesInfo | None = Field(
        description="where h, or the extended Jacobian [J; dh] (10), is singular in the box "
        "(the fixed variables held), on a uniform grid: null when h is regular there, or when "
        "it was not searched (singularities_searched)"
    )
    singularities_searched: bool = Field(
        description="whether h was searched for singularities: not for a map that solves a "
        "problem per point (the characteristics'), a vector of maps, or too large a grid "
        "(message says which)"
    )
    total_degree: TotalDegreeInfo | None = Field(
        None, description="'e2_total_degree': the synthesis' numbers and its maps"
    )
    message: str


class SynthesisMethodsResponse(BaseModel):
    methods: list[SynthesisMethod]
    notes: dict[str, str]
