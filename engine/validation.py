"""Input validation shared by every public engine function."""

from __future__ import annotations

import numpy as np

from .exceptions import InvalidInputError

FloatArray = np.ndarray


def as_points(x, size: int, name: str) -> FloatArray:
    """Check that ``x`` is a finite float array of shape (..., size) and return it.

    Raises
    ------
    InvalidInputError
        On a wrong trailing dimension or a NaN/inf entry, naming ``name``.
    """
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidInputError(f"{name} must be numeric, got {x!r}") from exc
    if a.ndim == 0 or a.shape[-1] != size:
        raise InvalidInputError(
            f"{name} must have shape (..., {size}) (a vector of length {size}), got shape {a.shape}"
        )
    if not np.all(np.isfinite(a)):
        raise InvalidInputError(f"{name} contains NaN or infinite values; give finite numbers")
    return a


def as_vector(x, size: int, name: str) -> FloatArray:
    """Check that ``x`` is one finite vector of length ``size``."""
    a = as_points(x, size, name)
    if a.ndim != 1:
        raise InvalidInputError(f"{name} must be a single vector of length {size}, got {a.shape}")
    return a


def positive(value, name: str) -> float:
    """Check that ``value`` is a finite number > 0."""
    v = finite(value, name)
    if v <= 0:
        raise InvalidInputError(f"{name} must be > 0, got {v}")
    return v


def finite(value, name: str) -> float:
    """Check that ``value`` is a finite real number."""
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidInputError(f"{name} must be a number, got {value!r:.80}") from exc
    if not np.isfinite(v):
        raise InvalidInputError(f"{name} must be finite, got {v}")
    return v


def count(value, name: str, low: int, high: int, field: str | None = None) -> int:
    """Check that ``value`` is an integer in [low, high] (``field``: the error's field)."""
    try:
        integral = not isinstance(value, bool) and int(value) == value
    except (TypeError, ValueError, OverflowError):
        integral = False
    if not integral:
        raise InvalidInputError(f"{name} must be an integer, got {value!r}", field)
    v = int(value)
    if not low <= v <= high:
        raise InvalidInputError(f"{name} must be between {low} and {high}, got {v}", field)
    return v


def json_number(value, name: str, field: str | None = None) -> float:
    """A finite JSON number: an int or a float, not a boolean or a numeric string.

    The error carries ``field`` (default ``name``), for a client to mark the entry.
    """
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InvalidInputError(f"{name} must be a number, got {value!r:.80}", field or name)
    try:
        return finite(value, name)
    except InvalidInputError as exc:
        raise InvalidInputError(str(exc), field or name) from None
