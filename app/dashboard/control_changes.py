"""A change of the dashboard's controls as a change of its state (:func:`expand`), and the one
text format of a closed path, in the page's and the scene's path box (:func:`path_text`,
:func:`parse_path_text`, :func:`path_format`): a point per line.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from typing import Any

from ...engine.algorithm_registry import default_rest
from ...engine.exceptions import InvalidInputError
from ..compute.schemas.wording import refused
from .algorithms import editable_rest
from .robots import state_kinematics, state_spec

#: Between two points of a path's text: the separator, and a new line (a box shows a point per
#: line, as many lines as points).
POINT_SEPARATOR = ";\n"
#: Decimals of a number as a user types it: the path's text, the page's vector boxes and the
#: scene's vector boxes (which take no more decimals than they show).
DECIMALS = 4
#: Switching to discrete mode takes gamma down to this when it is above (the full Newton step).
DISCRETE_GAMMA_ON_SWITCH = 1.0


def expand(state, patch: Mapping[str, object]) -> dict[str, object]:
    """A patch of control keys as a patch of the state's fields (which
    :func:`jik.app.dashboard.model.updated_state` applies): ``{"x0.1": v}`` sets one coordinate
    of x0, ``{"robot_parameters.l": v}`` one parameter, ``{"path": "1, 1; 1, 2"}`` the path from
    its text, ``{"algorithm_parameters.rest.1": v}`` one coordinate of the posture inverse's rest
    in force (:func:`~jik.app.dashboard.algorithms.editable_rest`),
    ``{"algorithm_parameters.rest": "x0"}`` the rest at the start x0 (None, the default that
    follows x0, on a robot without a home), ``{"target": "0.3, 0, 0.6, 0, 0, 0"}`` a vector from
    its text (:func:`parse_vector_text`). Switching to discrete mode without a gamma takes gamma
    down to :data:`DISCRETE_GAMMA_ON_SWITCH` when it is above."""
    out: dict[str, Any] = {}
    for key, value in patch.items():
        head, _, rest = key.partition(".")
        if isinstance(value, str) and (key == "target" or head == "robot_parameters"):
            current = _in_force(state, key)
            value = value if current is None else parse_vector_text(value, current, key)
        if head == "algorithm_parameters" and rest.startswith("rest."):
            params = out.setdefault(head, {})
            if not isinstance(params.get("rest"), list | tuple):
                params["rest"] = editable_rest(state, state_spec(state), state_kinematics(state))
            params["rest"] = list(params["rest"])
            index = rest.removeprefix("rest.")
            if not index.isdigit() or int(index) >= len(params["rest"]):
                n = len(params["rest"])
                raise refused(key, f"rest has {n} coordinates")
            params["rest"][int(index)] = value
        elif key == "path" and isinstance(value, str):  # (the text shown: the path in force)
            size = len(state.target) if "robot" not in patch else None
            out[key] = parse_path_text(value, size, state.path)
        elif not rest:
            out[key] = value
        elif head in ("robot_parameters", "augmentation_parameters", "algorithm_parameters"):
            out.setdefault(head, {})[rest] = value
        elif head in ("x0", "target") and rest.isdigit():
            vector = out[head] = list(out.get(head, getattr(state, head)))
            if int(rest) >= len(vector):
                raise refused(key, f"{head} has {len(vector)} coordinates")
            vector[int(rest)] = value
        else:
            raise InvalidInputError(f"unknown dashboard control {key!r}", key)
    if out.get("algorithm_parameters", {}).get("rest") == "x0":
        x0 = list(out.get("x0", state.x0))
        follows = default_rest(state_kinematics(state), x0)[1] == "x0"
        out["algorithm_parameters"]["rest"] = None if follows else x0
    if out.get("mode") == "discrete" and "gamma" not in out and state.mode != "discrete":
        out["gamma"] = min(state.gamma, DISCRETE_GAMMA_ON_SWITCH)
    return out


def lookup(state: Mapping[str, Any], key: str) -> Any:
    """The value at a dotted key of a state's dict."""
    value: Any = state
    for part in key.split("."):
        value = value[int(part)] if isinstance(value, list) else value[part]
    return value


def _in_force(state, key: str) -> list | None:
    """The vector in force at ``key`` (``target``, ``robot_parameters.<name>``), None for a
    key that holds none (a scalar parameter)."""
    try:
        value = lookup(state.as_dict(), key)
    except (KeyError, IndexError, TypeError, ValueError):
        return None
    return list(value) if isinstance(value, list | tuple) else None


def parse_vector_text(text: str, current, key: str) -> list[float]:
    """A vector written as text, its numbers separated by ',' (as a point of
    :func:`path_format`), of the size of ``current``, the vector in force at ``key``; the text
    the box shows (:func:`path_text` of it) gives ``current`` itself, exact."""
    if text.split() == path_text([current]).split():
        return list(current)
    try:
        vector = [float(v) for v in text.split(",")]
    except ValueError:
        raise refused(key, f"'{text.strip()}' is not numbers separated by ','") from None
    if len(vector) != len(current) or not all(math.isfinite(v) for v in vector):
        raise refused(key, f"write {len(current)} finite numbers separated by ','")
    return vector


def path_text(path) -> str:
    """A path as text, :func:`path_format` with a point per line, each coordinate to
    :data:`DECIMALS` as the page's number boxes show them (a computed 1.29e-17 as 0). Sent back
    unchanged, or spaced otherwise, it leaves the path in force exact (:func:`expand`)."""
    return POINT_SEPARATOR.join(", ".join(_number(v) for v in p) for p in path)


def _number(v: float) -> str:
    text = f"{float(v):.{DECIMALS}f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def path_format(size: int | None = None) -> str:
    """How a closed path of points with ``size`` coordinates (2 when not known) is written in a
    text box: points separated by ';' (or a new line), coordinates by ','."""
    n = size or 2
    point = ", ".join(f"y{i}" for i in range(1, n + 1)) if n <= 3 else f"y1, ..., y{n}"
    return f"{point}; {point}; ..."


#: Characters of a user's text a refusal quotes (a longer text is cut, with "...").
QUOTED = 60


def _quoted(text: str) -> str:
    return text if len(text) <= QUOTED else f"{text[: QUOTED - 3]}..."


def parse_path_text(text: str, size: int | None = None, current=()) -> list[list[float]]:
    """The points of a path written as :func:`path_format`, a new line separating points as a
    ';' does; ``size``: the task's dimension, which every point must have. A point written as
    :func:`path_text` shows a point of ``current`` (the path in force) is that point, exact: a
    point added or edited leaves the others as they were, not rounded to the decimals shown. A
    refusal quotes the point as the user wrote it (its first :data:`QUOTED` characters)."""
    points = []
    parts = [p for p in re.split(r"[;\n]", text) if p.strip()]
    written = path_format(size)
    shown = {"".join(path_text([p]).split()): list(p) for p in current}
    for k, part in enumerate(parts, start=1):
        if (exact := shown.get("".join(part.split()))) is not None:
            points.append(exact)
            continue
        where = f"point {k} of {len(parts)}, '{_quoted(part.strip())}',"
        try:
            point = [float(v) for v in part.split(",")]
        except ValueError:
            raise InvalidInputError(
                f"path: {where} is not numbers separated by ',' (write '{written}')", "path"
            ) from None
        if not all(math.isfinite(v) for v in point):
            raise InvalidInputError(f"path: {where} has a coordinate that is not finite", "path")
        if size is not None and len(point) != size:
            raise InvalidInputError(
                f"path: {where} has {len(point)} coordinate{'s' if len(point) > 1 else ''}; "
                f"each point needs {size} (write '{written}')",
                "path",
            )
        points.append(point)
    return points
