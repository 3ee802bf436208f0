"""Input validation shared by every public engine function, and the bound on a call's memory.

Each check raises :class:`InvalidInputError` whose ``field`` names the argument: the ``field``
given, else ``name`` when it is an argument's name or a dotted path (``"x0"``, ``"region.x2"``);
a descriptive ``name`` ("target y_d") gives no field unless ``field`` is passed.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable
from typing import Any

import numpy as np

from .exceptions import InvalidInputError

FloatArray = np.ndarray

#: The most memory, in bytes, that one call of the engine may plan to hold (a batched solve, a
#: repeatability run, a gathered atlas, an atlas's chunk): a call whose estimate
#: (:func:`check_memory`) is larger is refused before it allocates anything. Read at each call,
#: so a caller with more memory may raise it: ``jik.engine.validation.MEMORY_LIMIT = 16 * 2**30``.
MEMORY_LIMIT = 4 * 2**30

_FIELD = re.compile(r"[A-Za-z_]\w*(\.\w+)*")


def field_for(name: str, field: str | None = None) -> str | None:
    """The error's field for a check of ``name``: ``field``, else ``name`` if it is an
    argument's name or a dotted path, else None."""
    if field is not None:
        return field
    return name if _FIELD.fullmatch(name) else None


def as_numbers(x, name: str, field: str | None = None) -> FloatArray:
    """``x`` as a float array (NaN and inf allowed), or an error naming ``name``: numbers,
    not text that reads as one (``"1"``) nor booleans, as :func:`finite` takes them."""
    try:
        a = np.asarray(x)
        if a.dtype.kind not in "iuf" and not _numbers(a):
            raise TypeError(f"{a.dtype} entries")
        # (numpy reads [True, 0, 1.5] as numbers: a JSON true, or YAML's yes, became 1.0)
        if isinstance(x, list | tuple) and _holds_bool(x):
            raise TypeError("boolean entries")
        return a.astype(float, copy=False)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidInputError(
            f"{name} must be numeric, got {x!r:.80}", field_for(name, field)
        ) from exc


def _numbers(a: np.ndarray) -> bool:
    """Whether an array that is not of integers or floats holds only numbers (an object
    array of Python numbers); text, booleans and bytes are not."""
    return a.dtype.kind == "O" and all(_is_number(v) for v in a.ravel())


def _is_number(v) -> bool:
    return not isinstance(v, str | bytes | bool | np.bool_)


def _holds_bool(x: list | tuple) -> bool:
    """Whether nested lists or tuples hold a boolean anywhere (plain floats and ints, most
    entries, are passed over first: as fast as numpy's own reading of the list)."""
    stack = [x]
    while stack:
        for v in stack.pop():
            kind = type(v)
            if kind is float or kind is int:
                continue
            if kind is list or kind is tuple or isinstance(v, list | tuple):
                stack.append(v)
            elif isinstance(v, bool | np.bool_):
                return True
    return False


def as_points(
    x, size: int, name: str, field: str | None = None, *, finite: bool = True
) -> FloatArray:
    """Check that ``x`` is a float array of shape (..., size), finite unless ``finite`` is
    False, and return it.

    Raises
    ------
    InvalidInputError
        On a wrong trailing dimension or (``finite``) a NaN/inf entry, naming ``name`` (field:
        :func:`field_for`).
    """
    try:
        a = as_numbers(x, name, field)
    except InvalidInputError:
        _check_point_sizes(x, size, name, field)  # (a ragged list: name its first odd point)
        raise
    if a.ndim == 0 or a.shape[-1] != size:
        raise InvalidInputError(
            f"{name} must have shape (..., {size}) (a vector of length {size}), got shape "
            f"{a.shape}",
            field_for(name, field),
        )
    if finite and not np.isfinite(a).all():
        raise InvalidInputError(
            f"{name} contains NaN or infinite values; give finite numbers", field_for(name, field)
        )
    return a


#: Most joint variables p of a robot (a planar chain's joints, a formula robot's variables, a
#: URDF chain's active joints), in Python, over REST (the most components of a vector) and in
#: the dashboard.
MAX_JOINTS = 16

#: Largest magnitude of a coordinate of a solve's start or target (rad, m or the robot's own
#: units): at 1e6 the spacing of doubles (1.2e-10) passes the default tolerance of 1e-10, and far
#: beyond it the task error's norm overflows (a target of 1e200 ran 20,000 steps at error inf).
MAX_COORDINATE = 1e6


def bounded(a: FloatArray, name: str, field: str | None = None) -> FloatArray:
    """``a`` (finite) if no entry exceeds :data:`MAX_COORDINATE` in magnitude; else an
    InvalidInputError naming ``name``."""
    hi, lo = (a.max(), a.min()) if a.size else (0.0, 0.0)  # (no copy of a, as abs would make)
    if max(hi, -lo) > MAX_COORDINATE:
        raise InvalidInputError(
            f"{name} has a coordinate of {hi if hi > -lo else lo:.3g}; a solve takes "
            f"coordinates up to {MAX_COORDINATE:g} in magnitude",
            field_for(name, field),
        )
    return a


def checked_points(core: Callable[..., Any], finite: bool = True) -> Callable[..., Any]:
    """The method ``core(self, x, ...)`` behind ``self.check(x, "x")``, the check of ``x``
    against the shape (..., ``self.p``) (a kinematics' or an augmenting map's).

    The common case costs about a microsecond: a float64 array of the right width (whose sum
    is finite, when ``finite``: then it is finite) goes straight to ``core``; anything else (a
    list, a wrong shape, NaN) takes the full check, which raises or returns the array.
    """

    @functools.wraps(core)
    def evaluation(self, x, *args, **kwargs):
        if not (
            type(x) is np.ndarray
            and x.dtype == np.float64
            and x.ndim
            and x.shape[-1] == self.p
            and (not finite or math.isfinite(np.add.reduce(x, axis=None)))
        ):
            x = self.check(x, "x")
        return core(self, x, *args, **kwargs)

    return evaluation


def _check_point_sizes(x, size: int, name: str, field: str | None) -> None:
    """A list of points whose sizes differ, which :func:`as_numbers` refused: the first point
    of another size than ``size``, named (``path[1] must have 2 numbers``) rather than the list
    called not numeric."""
    if not isinstance(x, list | tuple) or not all(isinstance(p, list | tuple) for p in x):
        return
    if len({len(p) for p in x}) < 2:  # (one size for all: the shape's own message)
        return
    for i, point in enumerate(x):
        if len(point) != size:
            base = field_for(name, field)
            raise InvalidInputError(
                f"{name}[{i}] must have {size} numbers, got {len(point)}",
                None if base is None else f"{base}.{i}",
            )


def as_vector(x, size: int, name: str, field: str | None = None) -> FloatArray:
    """Check that ``x`` is one finite vector of length ``size``."""
    a = as_points(x, size, name, field)
    if a.ndim != 1:
        raise InvalidInputError(
            f"{name} must be a single vector of length {size}, got {a.shape}",
            field_for(name, field),
        )
    return a


def as_box(box, p: int, name: str = "box", *, finite: bool = True) -> FloatArray:
    """Check that ``box`` is ``p`` pairs (low, high) with low < high, no NaN, and finite unless
    ``finite`` is False (then an infinite end leaves its variable unbounded); return it (p, 2)."""
    try:
        b = as_numbers(box, name).copy()
    except InvalidInputError:
        b = np.empty(0)
    bad = b.shape != (p, 2) or np.isnan(b).any() or (finite and not np.isfinite(b).all())
    if bad or np.any(b[..., 0] >= b[..., 1]):
        kind = "finite pairs" if finite else "pairs"
        raise InvalidInputError(
            f"{name} must be {p} {kind} (low, high) with low < high, got {box!r:.80}",
            field_for(name),
        )
    return b


def within(x, bounds, name: str, names, where: str, field: str | None = None) -> None:
    """Check that each coordinate of the vector ``x`` (p,) lies in its [lo, hi] of ``bounds``
    (p, 2; +-inf: no bound on that side).

    Raises
    ------
    InvalidInputError
        At the first coordinate i outside, with field ``{field}.{i}`` (``field`` default
        ``name``): "rest x4 (panda_joint4) must be in [-3.0718, -0.0698] (the joint limits of
        the panda), got 0", ``names[i]`` naming the coordinate and ``where`` what the bounds
        are.
    """
    x, box = np.asarray(x, dtype=float), np.asarray(bounds, dtype=float)
    out = np.flatnonzero((x < box[:, 0]) | (x > box[:, 1]))
    if out.size:
        i = int(out[0])
        lo, hi = box[i]
        bound = (
            f"be in [{lo:g}, {hi:g}]"
            if np.isfinite(lo) and np.isfinite(hi)
            else f"be at most {hi:g}"
            if np.isfinite(hi)
            else f"be at least {lo:g}"
        )
        raise InvalidInputError(
            f"{name} {names[i]} must {bound} ({where}), got {x[i]:g}", f"{field or name}.{i}"
        )


def positive(value, name: str, field: str | None = None) -> float:
    """Check that ``value`` is a finite number > 0."""
    v = finite(value, name, field)
    if v <= 0:
        raise InvalidInputError(f"{name} must be > 0, got {v}", field_for(name, field))
    return v


def finite(value, name: str, field: str | None = None) -> float:
    """Check that ``value`` is a finite real number (a number, not text that reads as one,
    ``"1"``, nor a boolean)."""
    try:
        if not _is_number(value):
            raise TypeError(type(value).__name__)
        v = float(value)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidInputError(
            f"{name} must be a number, got {value!r:.80}", field_for(name, field)
        ) from exc
    if not np.isfinite(v):
        raise InvalidInputError(f"{name} must be finite, got {v}", field_for(name, field))
    return v


def count(value, name: str, low: int, high: int, field: str | None = None) -> int:
    """Check that ``value`` is an integer in [low, high]."""
    try:
        integral = not isinstance(value, bool) and int(value) == value
    except (TypeError, ValueError, OverflowError):
        integral = False
    if not integral:
        raise InvalidInputError(f"{name} must be an integer, got {value!r}", field_for(name, field))
    v = int(value)
    if not low <= v <= high:
        raise InvalidInputError(
            f"{name} must be between {low} and {high}, got {v}", field_for(name, field)
        )
    return v


def check_seed(value, name: str = "seed") -> int:
    """A random generator's seed: an integer from 0 to 2^63 - 1 (not a boolean), as numpy's
    and scipy's generators take it; else an InvalidInputError naming ``name``."""
    return count(value, name, 0, 2**63 - 1)


def as_series(x, name: str) -> FloatArray:
    """``x`` as one float per entry, shape (n,) (NaN and inf allowed: a value per cycle of a
    run that may have stopped), else an InvalidInputError naming ``name``."""
    a = as_numbers(x, name)
    if a.ndim != 1:
        raise InvalidInputError(
            f"{name} must be a list of numbers, shape (n,), got shape {a.shape}", name
        )
    return a


def flag(value, name: str) -> bool:
    """``value``, True or False (numpy's too), as a bool; else an InvalidInputError naming
    ``name`` (a text such as "no" is not read as True)."""
    if isinstance(value, bool | np.bool_):
        return bool(value)
    raise InvalidInputError(f"{name} must be True or False, got {value!r:.40}", name)


def of_type(value, kind, name: str, wanted: str):
    """``value`` if it is a ``kind`` (a type or a tuple of types), else an InvalidInputError
    naming ``name`` that says what is ``wanted`` and what was given."""
    if isinstance(value, kind):
        return value
    got = f"{type(value).__name__} {value!r:.60}"
    raise InvalidInputError(f"{name} must be {wanted}, got {got}", name)


def check_memory(n: int, each: float, field: str, what: str, instead: str) -> None:
    """Refuse a call of ``n`` items of ``each`` bytes (its estimated peak memory) when they
    exceed :data:`MEMORY_LIMIT`.

    Parameters
    ----------
    n : int
        The number of items the call holds at once (starts, runs).
    each : float
        The estimated bytes per item.
    field : str
        The argument that gives ``n`` (``"x0"``, ``"n_starts"``).
    what : str
        What the items are, for the message: "starts of a batched solve".
    instead : str
        What to do instead: "solve them in smaller batches".

    Raises
    ------
    InvalidInputError
        With ``field``: "x0: 1000000 starts of a batched solve would hold about 10.1 GiB, more
        than ... ; at most 425000 fit: solve them in smaller batches".
    """
    limit = MEMORY_LIMIT
    if n * each > limit:
        raise InvalidInputError(
            f"{field}: {n} {what} would hold about {_size(n * each)}, more than the engine's "
            f"bound of {_size(limit)} (jik.engine.validation.MEMORY_LIMIT); at most "
            f"{int(limit // each)} fit: {instead}",
            field,
        )


def _size(n: float) -> str:
    """Bytes in readable units: '1.5 GiB'."""
    for unit, scale in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n / 2**10:.3g} KiB"


def json_number(value, name: str, field: str | None = None) -> float:
    """A finite JSON number: an int or a float (numpy's too, from Python), not a boolean or a
    numeric string.

    The error carries ``field`` (default ``name``), for a client to mark the entry.
    """
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InvalidInputError(f"{name} must be a number, got {value!r:.80}", field or name)
    try:
        return finite(value, name)
    except InvalidInputError as exc:
        raise InvalidInputError(str(exc), field or name) from None
