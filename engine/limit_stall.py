"""Why a run of the weighted least-norm inverse stalled where J is regular: a joint pressed
against its limit.

The weighted inverse W^(-1) J^T (J W^(-1) J^T)^(-1) of Chan and Dubey
(:class:`~jik.engine.practical_inverses.WeightedInverse`) is a right inverse, so while it is
defined the task error falls as exp(-tau) along eq. (7), eq. (5): it has no local minimum to
settle in. Its weight 1 + |dH/dx_i| grows without bound as joint i nears a limit. Where the
target needs that joint to go on and the other joints cannot move the task that way, the
weighted Jacobian J W^(-1/2) loses rank at the limit, though J does not; the flow reaches that
point in a finite tau, with ever shorter steps, and stalls there
(:data:`jik.engine.dop853.PACE_WINDOWS`). More steps do not help: the start, the target or the
limits must change.
"""

from __future__ import annotations

import numpy as np

from .exceptions import JikError
from .inverses import Inverse
from .limits import limit_names
from .practical_inverses import WeightedInverse
from .stall import SINGULAR_RATIO, reach_note


def _ratio(A) -> float:
    """sigma_min / sigma_max of A (r, p); 0 for A = 0."""
    s = np.linalg.svd(A, compute_uv=False)
    return float(s[-1] / s[0]) if s[0] > 0 else 0.0


def pressed_joint(inverse: Inverse, target, x) -> str | None:
    """Why a run of the weighted inverse stopped at ``x`` (p,) short of ``target`` (r,): the
    joint pressed against its limit, named with its value and the limit; None for another
    inverse, a target out of reach, J singular at ``x`` (:func:`jik.engine.stall.stall_reason`
    says why) or J W^(-1/2) regular there.

    Notes
    -----
    J W^(-1/2) near singular where J is not (sigma_min / sigma_max below
    :data:`~jik.engine.stall.SINGULAR_RATIO` for the one, not for the other) is the weights'
    doing, that is the limits'; the joint named has the largest weight, the one nearest its
    limit for its range.
    """
    if not isinstance(inverse, WeightedInverse):
        return None
    kin = inverse.kinematics
    out, within = reach_note(kin, target)
    if out is not None:
        return None
    x = np.asarray(x, dtype=float)
    try:
        with np.errstate(all="ignore"):
            J = np.asarray(kin.jacobian_unchecked(x), dtype=float)
            winv = inverse.weights_inverse(x)
            ratio, weighted = _ratio(J), _ratio(J * np.sqrt(winv))
    except (JikError, ValueError, np.linalg.LinAlgError):
        return None
    if not (ratio >= SINGULAR_RATIO and weighted < SINGULAR_RATIO):
        return None
    i = int(np.argmin(winv))
    lo, hi = inverse.limits[i]
    side, limit = ("upper", hi) if hi - x[i] < x[i] - lo else ("lower", lo)
    return (
        f"{within}J is regular there (σ_min/σ_max = {ratio:.3g}) but the run is blocked at a "
        f"joint limit: joint {i + 1}, {limit_names(kin)[i]} = {x[i]:.9g}, is pressed against its "
        f"{side} limit {limit:g} ({abs(limit - x[i]):.3g} from it), where the weighted inverse "
        "stops it, and the other joints cannot move the task toward the target (J W^-1/2 "
        f"loses rank: σ_min/σ_max = {weighted:.3g}); more steps will not help: move the start "
        "or the target, or widen the limits"
    )
