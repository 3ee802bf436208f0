"""The words of a field's refusal by its type (pydantic's error), the same for a REST request and
a dashboard change: an unknown field, too few or too many entries, else pydantic's own."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any


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
