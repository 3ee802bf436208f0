"""How every refusal is worded, the same for a REST request and a dashboard change: a field's
path written one way (:func:`field_text`: ``x0[1]``, ``algorithm_parameters.rest[3]``; its
``loc`` as FastAPI's, :func:`field_loc`), once, as the message's prefix (:func:`refused`,
:func:`without_field`); the words of pydantic's errors (:func:`refusal`): an unknown field, too
few or too many entries, else pydantic's own."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ....engine.exceptions import InvalidInputError


def refusal(error: Mapping[str, Any]) -> str:
    """The message of one of pydantic's errors (``{"type", "msg", "ctx"}``), without its field."""
    kind = error.get("type")
    ctx = error.get("ctx") or {}
    if kind == "extra_forbidden":
        return "unknown field; remove it"
    bound = ctx.get("min_length") if kind == "too_short" else ctx.get("max_length")
    if kind in ("too_short", "too_long") and bound is not None:
        entries = "entry" if bound == 1 else "entries"
        most = "at least" if kind == "too_short" else "at most"
        return f"give {most} {bound} {entries}, got {ctx.get('actual_length')}"
    return str(error.get("msg", "invalid"))


def _parts(field: str) -> list[str]:
    """The names and indices of a field's path, in either notation (``rest.3``, ``x0[1]``)."""
    return [p for p in field.replace("[", ".").replace("]", "").split(".") if p]


def field_text(field: str) -> str:
    """A field's path as every message writes it: names joined by dots, indices in brackets
    (``algorithm_parameters.rest.3`` -> ``algorithm_parameters.rest[3]``)."""
    out: list[str] = []
    for part in _parts(field):
        if part.isdigit() and out:
            out[-1] += f"[{part}]"
        else:
            out.append(part)
    return ".".join(out)


def field_loc(field: str) -> list[str | int]:
    """A field's path as FastAPI's ``loc`` of a body field: ``["body", "rest", 3]``; ``body``
    is the body itself (``["body"]``: a body that is not an object)."""
    parts = [] if field == "body" else _parts(field)
    return ["body", *(int(p) if p.isdigit() else p for p in parts)]


def without_field(text: str, field: str | None) -> str:
    """An engine message without its leading mention of ``field`` (``lengths[1] must be ...``
    -> ``must be ...``): the error's prefix names the field, in the request's words."""
    if field:
        head, *rest = _parts(field)  # (and as Python subscripts it: ``region['x2']``)
        python = head + "".join(f"[{int(p)}]" if p.isdigit() else f"[{p!r}]" for p in rest)
        for name in dict.fromkeys((field, field_text(field), python)):
            if text.startswith(name) and text[len(name) : len(name) + 1] in (":", " "):
                return text[len(name) :].lstrip(":").lstrip()
    return text


def refused(field: str, problem: str) -> InvalidInputError:
    """The error of a value refused at ``field`` (its path as data, dotted: ``x0.1``), its
    message ``<field>: <problem>`` naming it as every message does (:func:`field_text`)."""
    return InvalidInputError(f"{field_text(field)}: {problem}", field)
