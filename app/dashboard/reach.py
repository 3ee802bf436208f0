"""Why a run stalled, in the dashboard's words: the target beyond the robot's reach, or a
kinematic singularity (J loses rank), or an algorithmic one of the extended Jacobian (10) (J
regular, [J; dh] singular), decided from the robot's reach and the Jacobians where it stopped.

The engine's solver says only that the step size collapsed "near a singularity or the target is
unreachable" (it knows neither the robot's workspace nor which matrix is near singular); a
planar chain of revolute joints reaches the annulus between max(0, 2 max l - sum l) and sum l
around its base, and the rank of J and of the inverse at the stall point tell the rest.
"""

from __future__ import annotations

import numpy as np

from ...engine.exceptions import JikError
from ...engine.planar_chain import PlanarChain

#: sigma_min / sigma_max of J below this: the arm is at a kinematic singularity.
SINGULAR_RATIO = 1e-3
#: ||J^E#|| / ||J^P#|| above this (J regular): the extended Jacobian is near singular.
ALGORITHMIC_RATIO = 1e2


def reach(kin) -> tuple[float, float] | None:
    """(inner, outer) distances from the base a planar chain of revolute joints reaches with
    its end point; None for other robots (prismatic joints, formulas, URDF arms, the paper's)."""
    if not isinstance(kin, PlanarChain) or not bool(np.all(kin.revolute)):
        return None
    lengths = np.abs(kin.lengths)
    outer = float(lengths.sum())
    return max(0.0, 2 * float(lengths.max()) - outer), outer


def stall_note(inverse, target, x) -> str:
    """Which it is, for a run of ``inverse`` stalled at ``x`` (p,) on its way to ``target``."""
    kin = inverse.kinematics
    g = lambda v: f"{v:.3g}"  # noqa: E731
    bounds = reach(kin)
    within = ""
    if bounds is not None:
        inner, outer = bounds
        d = float(np.linalg.norm(np.asarray(target, dtype=float)[:2]))
        tol = 1e-9 * max(1.0, outer)
        if d > outer + tol:
            return (
                f"the target is out of reach: it is {g(d)} from the base, beyond the arm's "
                f"reach {g(outer)} (the sum of its link lengths)"
            )
        if d < inner - tol:
            return (
                f"the target is out of reach: it is {g(d)} from the base, inside the "
                f"arm's inner reach {g(inner)} (2 max l − sum l)"
            )
        within = f"the target is within reach ({g(d)} from the base, reach {g(outer)}); "
    x = np.asarray(x, dtype=float)
    try:
        with np.errstate(all="ignore"):
            s = np.linalg.svd(np.asarray(kin.jacobian(x), dtype=float), compute_uv=False)
    except (JikError, ValueError, np.linalg.LinAlgError):
        return f"{within}the step size collapsed near a singularity"
    ratio = float(s[-1] / s[0]) if s[0] > 0 else 0.0
    if ratio < SINGULAR_RATIO:
        return (
            f"{within}the arm stalled at a kinematic singularity: J loses rank there "
            f"(σ_min/σ_max = {g(ratio)})"
        )
    try:  # (an inverse singular there raises: that is the algorithmic singularity)
        with np.errstate(all="ignore"):
            grow = float(np.linalg.norm(inverse.matrix(x), 2) * s[-1])
    except (JikError, ValueError, np.linalg.LinAlgError):
        grow = float("inf")
    if inverse.name == "extended" and (not np.isfinite(grow) or grow > ALGORITHMIC_RATIO):
        return (
            f"{within}J is regular there (σ_min/σ_max = {g(ratio)}) but the extended "
            "Jacobian [J; dh] (10) is near singular (an algorithmic singularity): the level "
            "set h = h(x0) does not lead to the target from this start"
        )
    return (
        f"{within}J is regular there (σ_min/σ_max = {g(ratio)}): the error stopped at a "
        "local minimum; move the start or the target"
    )
