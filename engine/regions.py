"""A design region (sec. 5): a box over some of a robot's joint variables, the others held at
fixed values; where E1 (13) and E2 (18) are taken, maps are synthesized and drawn on a grid."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from .exceptions import InvalidInputError
from .validation import finite, of_type

#: Largest |bound| of a box region (a synthesis's, E1's and E2's, a map's grid): no joint
#: ranges further, and on a box of 1e200 the Ritz solve's matrices overflow.
MAX_REGION_BOUND = 100.0


def check_box_region(
    names: Sequence[str],
    region,
    fixed: Mapping[str, float] | None = None,
    held: Sequence[float] | None = None,
) -> tuple[dict[str, tuple[float, float]], dict[str, float]]:
    """Validate a box region over some of the variables ``names`` (name -> (lo, hi), lo < hi,
    within :data:`MAX_REGION_BOUND`) and the fixed values of the others (name -> value;
    default ``held``, one value per name, else 0): the design region of sec. 5, where E1 (13)
    and E2 (18) are taken.

    Returns
    -------
    region : dict name -> (lo, hi), in the order of ``names``
    fixed : dict name -> value for every variable not in ``region``
    """
    names = tuple(names)
    if not isinstance(region, Mapping) or not region:
        raise InvalidInputError(
            f"region must be a non-empty mapping of {names} to (lo, hi)", "region"
        )
    wanted = f"a mapping of variables in {names} to values"
    fixed = dict(of_type(fixed or {}, Mapping, "fixed", wanted))
    for name in (*region, *fixed):
        if name not in names:
            raise InvalidInputError(
                f"unknown joint variable {name!r}; use one of {names}",
                f"{'region' if name in region else 'fixed'}.{name}",
            )
    if both := sorted(set(region) & set(fixed)):
        raise InvalidInputError(
            f"variables {both} are both integrated over and fixed", f"fixed.{both[0]}"
        )
    box: dict[str, tuple[float, float]] = {}
    for name in names:
        if name not in region:
            continue
        try:
            lo, hi = region[name]
        except (TypeError, ValueError) as exc:
            raise InvalidInputError(
                f"region[{name!r}] must be a pair (lo, hi)", f"region.{name}"
            ) from exc
        lo = finite(lo, f"lower bound of {name}", f"region.{name}")
        hi = finite(hi, f"upper bound of {name}", f"region.{name}")
        if not -MAX_REGION_BOUND <= lo < hi <= MAX_REGION_BOUND:
            raise InvalidInputError(
                f"region[{name!r}] must have lo < hi within +-{MAX_REGION_BOUND:g}, got "
                f"({lo}, {hi})",
                f"region.{name}",
            )
        box[name] = (lo, hi)
    rest = dict(zip(names, held, strict=True)) if held is not None else {}
    fix = {
        n: finite(fixed.get(n, rest.get(n, 0.0)), f"fixed {n}", f"fixed.{n}")
        for n in names
        if n not in box
    }
    return box, fix
