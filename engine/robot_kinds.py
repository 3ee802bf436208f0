"""What a robot definition may contain, kind by kind: one description for validation and editors.

:func:`jik.engine.robot_spec.robot_from_dict` accepts exactly these keys, and a client (the REST
API, the dashboard's robot editor) builds its form from :func:`robot_kinds` instead of writing
the fields again. Types: ``"string"``, ``"text"`` (long text), ``"boolean"``, ``"numbers"`` (a
list), ``"names"`` (a list of names), ``"formulas"`` (a list of formulas), ``"mapping"`` (names to
numbers), ``"points"`` (a list of lists of numbers), ``"integer"``, ``"augmentations"``.
"""

from __future__ import annotations

import re
from dataclasses import asdict, dataclass

from .exceptions import InvalidInputError

#: Longest ``title`` of a robot, and ``label`` of one of its maps [characters].
MAX_TITLE_CHARS = 100
#: What a text shown on one line (a title, a label: in the page, a command's output, a CSV
#: export's header) may not hold: control characters (line breaks, tabs, escapes), Unicode's
#: line and paragraph separators, its bidirectional controls (which reorder the rest of the
#: line it is printed on), and lone surrogates (which no UTF-8 file can hold).
_NOT_ONE_LINE = re.compile(
    "[\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028-\u202e\u2066-\u2069\ud800-\udfff]"
)


def one_line(value, field: str, most: int = MAX_TITLE_CHARS) -> str:
    """``value``, a text of 1 to ``most`` characters shown on one line; else an
    InvalidInputError with ``field`` that shows its first character not printable on one line
    as an escape (``'\\n'``)."""
    if not isinstance(value, str):
        raise InvalidInputError(f"{field} must be a text, got {value!r:.80}", field)
    if not 1 <= len(value) <= most:
        raise InvalidInputError(
            f"{field} must have 1 to {most} characters, got {len(value)}", field
        )
    if fault := one_line_fault(value):
        raise InvalidInputError(f"{field} must be one line of printable text, got {fault}", field)
    return value


def one_line_fault(value: str) -> str | None:
    """The first character of ``value`` that is not printable on one line, as an escape and its
    place (``"'\\n' at character 3"``); None when there is none."""
    bad = _NOT_ONE_LINE.search(value)
    return None if bad is None else f"{bad.group()!a} at character {bad.start()}"


@dataclass(frozen=True)
class DefinitionField:
    """One entry of a robot definition."""

    name: str
    type: str
    required: bool
    help: str
    example: object = None


#: Optional joint limits, a field of the planar chains and the formula robots (a URDF's are in
#: its joints).
LIMITS = DefinitionField(
    "limits",
    "points",
    False,
    "joint limits, one [lower, upper] per variable (a bound null: none, as [null, 1.5]); runs "
    "report whether they stayed within them",
)

PLANAR_CHAIN = (
    DefinitionField(
        "joints",
        "string",
        True,
        "joint types in order, base first: R revolute, P prismatic (p = their number)",
        "RRR",
    ),
    DefinitionField("lengths", "numbers", True, "link lengths > 0, one per joint", [1.0, 0.8, 0.6]),
    DefinitionField(
        "offsets",
        "numbers",
        False,
        "joint offsets added to x: angle [rad] for R, extension for P (default 0)",
    ),
    DefinitionField(
        "orientation",
        "boolean",
        False,
        "also the end's angle as a task component (r = 3, needs p >= 3; default false: the end "
        "point, r = 2)",
        False,
    ),
    LIMITS,
)

FORMULA = (
    DefinitionField(
        "variables",
        "names",
        True,
        "joint variable names, in order (p = their number)",
        ["x1", "x2", "x3"],
    ),
    DefinitionField(
        "task",
        "formulas",
        True,
        "task components (r = their number), formulas in the variables and "
        "parameters (sin cos tan exp log sqrt atan2 abs, + - * / **, numbers, pi)",
        ["x2 + l*cos(x3)", "x1 + l*sin(x3)"],
    ),
    DefinitionField("parameters", "mapping", False, "named constants of the formulas", {"l": 1.0}),
    LIMITS,
)

URDF = (
    DefinitionField("urdf", "text", True, "the URDF text (no DOCTYPE; meshes are not loaded)"),
    DefinitionField(
        "urdf_file",
        "string",
        False,
        "instead of urdf, in a robot file only: a path relative to the file's folder",
    ),
    DefinitionField("end_link", "string", True, "the link whose origin is the end point", "tool"),
    DefinitionField(
        "base_link",
        "string",
        False,
        "the link whose frame is the base frame, an ancestor of end_link (default: the URDF's "
        "root; name the link past a floating joint, e.g. a humanoid's torso)",
    ),
    DefinitionField(
        "active_joints",
        "names",
        False,
        "the joints that move, in order (default: every movable joint from the base to end_link)",
    ),
    DefinitionField(
        "task",
        "string",
        False,
        "coordinates of the end link: x y z (position in the base frame) "
        "and rx ry rz (rotation vector of R0^T R), pose for all six, or a subset "
        "such as xyz or 'x y z rz' (default xyz)",
        "xyz",
    ),
    DefinitionField(
        "locked", "mapping", False, "values of the chain's other movable joints (default 0)"
    ),
    DefinitionField(
        "home",
        "numbers",
        False,
        "a reference configuration, one value per active joint (default: zero, clipped "
        "into the joint limits): R0's default and the posture inverse's default rest; when "
        "given, also the default start (else 0.5 in each joint's range that holds it, the "
        "middle of the others)",
    ),
    DefinitionField(
        "reference",
        "numbers",
        False,
        "R0, the orientation with rotation "
        "coordinates 0: a rotation vector (3 numbers), a quaternion x y z w (4) or "
        "a matrix (3 rows of 3); default: the end link's orientation at home",
    ),
)

#: A catalogue arm (:mod:`jik.engine.arms`): its URDF, end link and home are the catalogue's.
ARM = tuple(f for f in URDF if f.name in ("task", "reference", "home", "locked", "active_joints"))

COMMON = (
    DefinitionField(
        "name",
        "string",
        True,
        "the kind: planar_chain, formula, urdf, a "
        "catalogue arm (panda, iiwa14, gen3, ur5e) or a built-in robot's name",
    ),
    DefinitionField(
        "title", "string", False, f"a name to show: one line, 1 to {MAX_TITLE_CHARS} characters"
    ),
    DefinitionField(
        "x_range",
        "points",
        False,
        "one [lo, hi] per variable, the range of x0's sliders (default: a URDF's joint limits, "
        "[-pi, pi] for a continuous or revolute joint, +-length for a prismatic one; a planar "
        "chain's or formula robot's limits do not narrow it: a start outside them is reported)",
    ),
    DefinitionField(
        "x0",
        "numbers",
        False,
        "start configuration (default 0.5, or the middle of a range without it; where the "
        "task is undefined or overflows there, the first point of the ranges' Halton sequence "
        "where it is defined)",
    ),
    DefinitionField("target", "numbers", False, "default target of a solve"),
    DefinitionField("path", "points", False, "default closed path (task points)"),
    DefinitionField(
        "augmentations",
        "augmentations",
        False,
        "augmenting maps of the extended "
        "inverse: {name: formula, h: ...} (h a list of p - r formulas when "
        "p - r > 1) or {name: e2_synthesized, region: {...}} (p = r + 1); a second map of "
        "one kind needs a label of its own (label: ...), its name in the page",
    ),
)

#: The entries of an augmentation, by its name.
AUGMENTATIONS: dict[str, tuple[DefinitionField, ...]] = {
    "formula": (
        DefinitionField(
            "h",
            "formulas",
            True,
            "h as a formula in the variables (p - r = 1), or a list of p - r formulas",
            "x3",
        ),
        DefinitionField("parameters", "mapping", False, "named constants of h"),
        DefinitionField(
            "label",
            "string",
            False,
            "its name among the robot's maps (default formula): one line, 1 to "
            f"{MAX_TITLE_CHARS} characters",
        ),
    ),
    "e2_synthesized": (
        DefinitionField(
            "region",
            "mapping",
            True,
            "two or more variables to [lo, hi], lo < hi: the box "
            "of the Ritz synthesis of E2, eq. (20) (over more than three, in a "
            "total-degree basis); an arm's maps default to a box around its home",
            {"x2": [0.4, 2], "x3": [0.4, 2]},
        ),
        DefinitionField(
            "degree",
            "integer",
            False,
            "Legendre degree per variable, 1-24 "
            "(default 12); over more than three variables the total degree, 1-6 "
            "(default 4)",
            12,
        ),
        DefinitionField(
            "fixed",
            "mapping",
            False,
            "values of the variables outside the region (default: the home, else 0 within the "
            "joint limits)",
        ),
        DefinitionField(
            "frame_axes",
            "numbers",
            False,
            "p - r > 1: the p - r joints (1-based) whose axes fix the kernel frame of the maps "
            "h_1..h_(p-r), docs/e2-vector.md (default: the best-conditioned at the box's centre)",
        ),
        DefinitionField(
            "label",
            "string",
            False,
            "its name among the robot's maps (default e2_synthesized): one line, 1 to "
            f"{MAX_TITLE_CHARS} characters",
        ),
    ),
}

KINDS: dict[str, tuple[DefinitionField, ...]] = {
    "planar_chain": PLANAR_CHAIN,
    "formula": FORMULA,
    "urdf": URDF,
}


def keys(kind: str) -> set[str]:
    """The keys a definition of ``kind`` may have (its own and the common ones); a catalogue
    arm's are :data:`ARM`'s."""
    from .arms import ARMS

    own = ARM if kind in ARMS else KINDS.get(kind, ())
    return {f.name for f in (*own, *COMMON)}


def augmentation_keys(name: str) -> set[str]:
    """The keys an augmentation named ``name`` may have."""
    return {"name", *(f.name for f in AUGMENTATIONS.get(name, ()))}


def robot_kinds() -> dict:
    """``{"kinds": {kind: [field, ...]}, "common": [...], "augmentations": {name: [...]}}``,
    JSON-friendly."""
    return {
        "kinds": {k: [asdict(f) for f in fields] for k, fields in KINDS.items()},
        "common": [asdict(f) for f in COMMON],
        "augmentations": {k: [asdict(f) for f in fields] for k, fields in AUGMENTATIONS.items()},
    }
