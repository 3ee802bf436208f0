"""The field types and size limits every request model shares (JSON, snake_case).

Pydantic checks types, ranges, finiteness (``allow_inf_nan=False``: NaN and inf are rejected) and
size bounds. The dashboard's state (:mod:`jik.app.dashboard.model`) uses the same types.
"""

from __future__ import annotations

from typing import Annotated, Any, Union

from pydantic import AfterValidator, BeforeValidator, Discriminator, Field, Tag
from pydantic_core import PydanticCustomError

from ....engine.regions import MAX_REGION_BOUND
from ....engine.solve_rules import GAMMA_MAX, GAMMA_MIN, TOL_MAX, TOL_MIN
from ....engine.validation import MAX_JOINTS

#: Largest configuration / task dimension accepted before the registry check.
MAX_DIMENSION = MAX_JOINTS
#: Largest cap on a leg's integrator steps or iterations that a request, the dashboard's state
#: and its page may ask for (a far target at a small gamma needs many; a run's time limit stops
#: it sooner).
MAX_ITERATIONS_CAP = 200_000
#: Trajectories longer than this are downsampled (first and last points kept).
MAX_TRAJECTORY_POINTS = 2000

FiniteFloat = Annotated[float, Field(strict=True, allow_inf_nan=False)]


def _integral(value: Any) -> Any:
    """A float with no fraction is the integer it equals (JSON Schema's "integer": 49.0 is one)."""
    return int(value) if isinstance(value, float) and value.is_integer() else value


#: The API's one integer rule, on every route and the session state: what JSON Schema (and so
#: the OpenAPI document's ``integer``) calls an integer, 49 or 49.0, never 49.5, a boolean or a
#: string. Written ``Annotated[int, Field(strict=True, ...), INTEGRAL]`` (after the Field, or
#: the schema loses its bounds); ``tests/app/test_integers.py`` holds every route to it.
INTEGRAL = BeforeValidator(_integral)

#: A cap on a leg's integrator steps (continuous) or iterations (discrete).
IterationCap = Annotated[int, Field(strict=True, ge=1, le=MAX_ITERATIONS_CAP), INTEGRAL]


#: A float that is null where the engine produced NaN or inf (a failed or diverged run).
MaybeFloat = float | None

#: Largest |coordinate| of a configuration or task point (radians, lengths, control amplitudes):
#: beyond it the kinematics only overflow, and the unicycle's quadrature would need huge grids.
COORDINATE_BOUND = 1000.0
Coordinate = Annotated[
    float, Field(strict=True, ge=-COORDINATE_BOUND, le=COORDINATE_BOUND, allow_inf_nan=False)
]
Vector = Annotated[list[Coordinate], Field(min_length=1, max_length=MAX_DIMENSION)]


def coordinates(n: int) -> Any:
    """A vector of exactly ``n`` coordinates: a configuration (n = p) or a task point (n = r)
    of a robot whose request model knows them."""
    return Annotated[list[Coordinate], Field(min_length=n, max_length=n)]


def points(n: int, least: int, most: int) -> Any:
    """A list of ``least`` to ``most`` vectors of ``n`` coordinates (a path's task points)."""
    return Annotated[list[coordinates(n)], Field(min_length=least, max_length=most)]  # type: ignore[misc]


#: The seed of a random rule (a Sobol rule's scrambling, an atlas's sampled starts).
Seed = Annotated[int, Field(strict=True, ge=0, le=2**31 - 1), INTEGRAL]
#: The p - r joints (1-based) whose axes fix the kernel frame of maps h_1..h_(p-r).
FrameAxes = Annotated[
    list[Annotated[int, Field(strict=True, ge=1, le=MAX_DIMENSION), INTEGRAL]],
    Field(min_length=1, max_length=MAX_DIMENSION),
]
#: The decay rate of eq. (5) (discrete mode: the step; its bound there is checked with the mode,
#: engine.solve_rules.gamma_problem).
Gamma = Annotated[float, Field(strict=True, ge=GAMMA_MIN, le=GAMMA_MAX, allow_inf_nan=False)]
#: The task error at which a solve stops.
Tolerance = Annotated[float, Field(strict=True, ge=TOL_MIN, le=TOL_MAX, allow_inf_nan=False)]
#: A bound of a synthesis box (the engine's bound on a box region).
Bound = Annotated[
    float,
    Field(strict=True, ge=-MAX_REGION_BOUND, le=MAX_REGION_BOUND, allow_inf_nan=False),
]


#: The labels of a one-or-many union's members in pydantic's error locations: written as type
#: labels (they hold "["), which the API's field names leave out, as they do a plain union's.
ONE, MANY = "list[number]", "list[list[number]]"


def _shape(value: Any) -> str:
    """Which member of :func:`one_or_many` a value evidently means: a list whose first entry is a
    list is many, anything else one."""
    return MANY if isinstance(value, list) and value and isinstance(value[0], list) else ONE


def one_or_many(one: Any, many: Any) -> Any:
    """``one`` (a list of numbers) or ``many`` (a list of such lists), told apart by the value's
    shape before either is checked: a refusal is the one of the shape the request gave, once
    per field (a plain union reports both members' refusals)."""
    return Annotated[
        Union[Annotated[one, Tag(ONE)], Annotated[many, Tag(MANY)]],  # noqa: UP007
        Discriminator(_shape),
    ]


#: How deep a JSON object of free form (a dashboard's robot definition) may nest: a definition's
#: deepest part, a URDF arm's limits or a map's list of formulas, is 3 deep.
MAX_OBJECT_DEPTH = 12


def _shallow(value: dict) -> dict:
    """``value`` if it nests at most :data:`MAX_OBJECT_DEPTH` deep (deeper, it could not even be
    passed to a compute worker: pickling it ran out of stack)."""
    level: list[dict | list] = [value]
    depth = 1
    while level:
        if depth > MAX_OBJECT_DEPTH:
            raise PydanticCustomError(
                "too_deep", f"nests deeper than {MAX_OBJECT_DEPTH} levels of lists and objects"
            )
        inner = [v for item in level for v in (item.values() if isinstance(item, dict) else item)]
        level, depth = [v for v in inner if isinstance(v, dict | list)], depth + 1
    return value


#: A JSON object of free form (checked by the engine, as a robot definition is), of at most 32
#: keys and :data:`MAX_OBJECT_DEPTH` levels.
FreeObject = Annotated[dict[str, Any], Field(max_length=32), AfterValidator(_shallow)]
