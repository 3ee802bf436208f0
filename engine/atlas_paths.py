"""An atlas's paths and the self-motion curves its starts lie on.

The family of paths (:func:`path_family`: every shift of a base path with every scale about its
first point) and, for starts on the self-motion manifold k(x) = path[0] of each path's first point
(sec. 2: one-dimensional, p - r = 1), those curves traced over one arc
(:func:`base_manifolds`, :mod:`jik.engine.self_motion`), s = 0 where eq. (7) with the
pseudoinverse (8) from a reference configuration reaches the point.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .exceptions import InvalidInputError, SingularConfigurationError, format_vector
from .inverses import Pseudoinverse
from .self_motion import SelfMotionManifold, periodic_joints, project, trace
from .solver import solve_batch
from .validation import MAX_COORDINATE, FloatArray, as_points, as_series, bounded

#: Largest number of paths in a family (shifts x scales).
MAX_PATHS = 10**4


class Family(NamedTuple):
    """Where each path of a family comes from: its ``scale`` (P,) about the base path's first
    point and its ``shift`` (P, r) of the whole path."""

    scale: FloatArray
    shift: FloatArray


def family(base_path: FloatArray, shifts: FloatArray, scales: FloatArray) -> FloatArray:
    """Paths (P, L0, r): every shift with every scale, shift-major; a scale acts about the path's
    first point (the starts' task point), a shift moves the whole path."""
    rel = base_path - base_path[0]
    first = base_path[0] + shifts  # (S, r)
    return (first[:, None, None, :] + scales[None, :, None, None] * rel).reshape(
        -1, *base_path.shape
    )


def path_family(
    kin, base_path: FloatArray, shifts, scales
) -> tuple[FloatArray, int | None, Family | None]:
    """The family of ``base_path`` (L0, r) by ``shifts`` (S, r) and ``scales`` (Q,), checked
    (None: no shift, scale 1), how many of its paths share each shift's first point (Q; None
    without shifts), and each path's scale and shift (None when neither was given).

    Raises
    ------
    InvalidInputError
        ``shifts`` or ``scales`` malformed, more than :data:`MAX_PATHS` paths, or a path
        moved beyond the task coordinates a solve takes.
    """
    shift = (
        np.zeros((1, kin.r))
        if shifts is None
        else checked(lambda: as_points(shifts, kin.r, "shifts"), "shifts")
    )
    scale = np.ones(1) if scales is None else as_series(scales, "scales")
    if shift.ndim != 2 or not len(shift):
        raise InvalidInputError(f"shifts must be one or more task points (S, {kin.r})", "shifts")
    if not len(scale) or not np.all(np.isfinite(scale) & (scale > 0)):
        raise InvalidInputError("scales must be finite and > 0, one or more of them", "scales")
    for name, values in (("shifts", shift.reshape(len(shift), -1)), ("scales", scale[:, None])):
        _, first = np.unique(values, axis=0, return_index=True)
        if len(first) < len(values):  # (a path twice: the same band drawn twice, twice the work)
            j = int(np.setdiff1d(np.arange(len(values)), first)[0])
            i = int(np.flatnonzero((values[:j] == values[j]).all(axis=1))[0])
            shown = format_vector(values[j]) if name == "shifts" else f"{values[j, 0]:g}"
            raise InvalidInputError(
                f"{name} must be distinct: {shown} is given twice (entries {i} and {j})",
                f"{name}.{j}",
            )
    if len(shift) * len(scale) > MAX_PATHS:
        raise InvalidInputError(f"at most {MAX_PATHS} paths (shifts x scales)", field="shifts")
    bounded(base_path, "path")
    paths = family(base_path, shift, scale)
    if not np.all(np.abs(paths) <= MAX_COORDINATE):  # (a solve's bound on task coordinates)
        raise InvalidInputError(
            f"shifts and scales move the path to task coordinates beyond {MAX_COORDINATE:g} in "
            "magnitude, which a solve does not take",
            field="shifts" if shifts is not None else "scales",
        )
    _check_reachable(kin, paths, base_path, scale, shifts is not None, scales is not None)
    placed = None
    if shifts is not None or scales is not None:  # (shift-major, as family() lays the paths)
        placed = Family(np.tile(scale, len(shift)), np.repeat(shift, len(scale), axis=0))
    return paths, None if shifts is None else len(scale), placed


def _check_reachable(kin, paths, base_path, scale, shifted: bool, scaled: bool) -> None:
    """Refuse a family whose shift or scale moves a point of the path out of the task's range
    where that is known without solving (a pose task's rotation coordinates beyond pi:
    :meth:`~jik.engine.kinematics.Kinematics.check_target`), naming ``shifts.s`` or
    ``scales.q`` (a scale when it alone moves the point out) and the point; the base path is
    checked as ``path``; ``paths``: the family (:func:`family`)."""
    if not _fails(kin, paths):
        return
    for j, path in enumerate(paths):
        try:
            kin.check_target(path, "path")
        except InvalidInputError as error:
            s, q = divmod(j, len(scale))
            alone = scaled and (
                not shifted
                or _fails(kin, family(base_path, np.zeros((1, kin.r)), scale[q : q + 1]))
            )
            field = f"scales.{q}" if alone else f"shifts.{s}"
            point = int((error.field or "path.0").rpartition(".")[2])
            why = str(error).partition(": ")[2] or str(error)
            raise InvalidInputError(
                f"{field.replace('.', '[')}] moves the path's point {point} to "
                f"{format_vector(path[point])}: {why}",
                field,
            ) from None


def _fails(kin, paths: FloatArray) -> bool:
    """Whether :meth:`~jik.engine.kinematics.Kinematics.check_target` refuses a point of
    ``paths`` (P, L0, r)."""
    try:
        kin.check_target(paths.reshape(-1, kin.r), "path")
    except InvalidInputError:
        return True
    return False


def base_manifolds(
    kin, paths, reference, arc, box, per_shift: int | None = None
) -> tuple[SelfMotionManifold, ...]:
    """Each path's self-motion curve over one arc: the base path's, cut by ``box``. With
    shifts, ``per_shift`` paths (one per scale) share each shift's first point: a first point
    out of reach is that shift's fault."""
    y0 = paths[:, 0]
    try:
        res = solve_batch(
            Pseudoinverse(kin),
            np.broadcast_to(reference, (len(y0), kin.p)),
            y0,
            tol=1e-12,
            record=False,
        )
    except SingularConfigurationError as error:
        raise InvalidInputError(str(error), field="reference") from None
    if not np.all(res.success):  # (the path's point is at fault, not the reference: a default)
        j = int(np.argmin(res.success))
        point, why = format_vector(y0[j]), res.message[j]
        if per_shift is None:
            raise InvalidInputError(
                f"path: its first point {point} is out of reach: {why}", field="path"
            )
        raise InvalidInputError(
            f"shifts[{j // per_shift}] moves the path's first point to {point}, out of reach: "
            f"{why}",
            field=f"shifts.{j // per_shift}",
        )
    bases = project(kin, res.x, y0)
    try:
        first = trace(kin, bases[0], arc, box)
    except InvalidInputError as error:
        if error.field != "base":
            raise
        where = str(error).partition(": ")[2]
        if _outside(kin, np.asarray(reference, dtype=float), box):
            raise InvalidInputError(
                f"the reference {format_vector(reference)} lies outside the box (x_range, joint "
                f"limits): eq. (7) from it reaches the path's first point {format_vector(y0[0])} "
                f"only where {where}",
                field="reference",
            ) from None
        raise InvalidInputError(
            f"the path's first point {format_vector(y0[0])} is out of reach in the box (x_range, "
            f"joint limits): eq. (7) from the reference reaches it only where {where}",
            field="path",
        ) from None
    return (first, *(trace(kin, b, first.arc) for b in bases[1:]))


def _outside(kin, x: FloatArray, box) -> bool:
    """Whether ``x`` lies outside ``box`` in a variable that is not a freely turning angle
    (:func:`~jik.engine.self_motion.periodic_joints`, which a box does not bound)."""
    if box is None:
        return False
    lo, hi = np.asarray(box, dtype=float).T
    return bool(np.any(((x < lo) | (x > hi)) & ~periodic_joints(kin)))


def checked(check, name: str):
    """Run ``check`` and tag an InvalidInputError it raises with the field ``name``."""
    try:
        return check()
    except InvalidInputError as error:
        if error.field is None:
            error.field = name
        raise
