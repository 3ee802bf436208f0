"""Why a continuous run of eq. (7) stalled: the target beyond the robot's reach, a kinematic
singularity (J loses rank), an algorithmic one of the extended Jacobian (10) (J regular,
[J; dh] singular), or, J regular, steps collapsing where the error still falls; and whether a
target is out of reach, which a run that diverged or ran out of steps says too.

The integrator only sees its step size collapse; the robot's workspace and the Jacobians where
the run stopped tell which. A planar chain of revolute joints reaches the annulus between
max(0, 2 max l - sum l) and sum l around its base (l its link lengths). A URDF arm of revolute
joints keeps its end within the sum of its links' lengths (joint to joint, then to the end) of
its first joint: a target's position farther than that is out of reach, though one nearer may be
too. For other robots the reach is not known in closed form (a pose task's rotation coordinates
longer than pi are refused as input, :meth:`jik.engine.pose_task.PoseTask.check_reachable`) and
only the Jacobians speak.
"""

from __future__ import annotations

import numpy as np

from .exceptions import JikError
from .inverses import Inverse
from .planar_chain import PlanarChain
from .urdf import UrdfChain

#: sigma_min / sigma_max of J below this: the robot is at a kinematic singularity.
SINGULAR_RATIO = 1e-3
#: ||J#|| sigma_min(J) above this (J regular): the extended Jacobian is near singular.
ALGORITHMIC_RATIO = 1e2


def reach(kinematics) -> tuple[float, float] | None:
    """(inner, outer) distances from the base that a planar chain of revolute joints reaches
    with its end point; None for other robots (prismatic joints, formulas, URDF arms, the
    paper's) and for a chain whose task includes the end's orientation (r = 3: whether a
    target is reached then depends on its angle too)."""
    if (
        not isinstance(kinematics, PlanarChain)
        or not bool(np.all(kinematics.revolute))
        or kinematics.r != 2
    ):
        return None
    lengths = np.abs(kinematics.lengths)
    outer = float(lengths.sum())
    return max(0.0, 2 * float(lengths.max()) - outer), outer


def _g(v: float) -> str:
    return f"{v:.3g}"


def reach_note(kinematics, target) -> tuple[str | None, str]:
    """(why ``target`` is out of the robot's reach, or None; a clause saying it is within
    reach, or "" when the reach is not known)."""
    if isinstance(kinematics, UrdfChain):
        return _arm_reach_note(kinematics, target), ""
    bounds = reach(kinematics)
    if bounds is None:
        return None, ""
    inner, outer = bounds
    d = float(np.linalg.norm(np.asarray(target, dtype=float)[:2]))
    tol = 1e-9 * max(1.0, outer)
    if d > outer + tol:
        return (
            f"the target is out of reach: it is {_g(d)} from the base, beyond the arm's "
            f"reach {_g(outer)} (the sum of its link lengths)"
        ), ""
    if d < inner - tol:
        return (
            f"the target is out of reach: it is {_g(d)} from the base, inside the arm's "
            f"inner reach {_g(inner)} (2 max l − sum l)"
        ), ""
    return None, f"the target is within reach ({_g(d)} from the base, reach {_g(outer)}); "


def _arm_reach_note(arm: UrdfChain, target) -> str | None:
    """Why ``target`` is out of the reach of a URDF arm of revolute joints, or None: its
    position coordinates (those of the task, a subset of x y z) farther from the first joint's
    than the sum of the distances from joint to joint and from the last joint to the end link,
    which no configuration exceeds (the triangle inequality). None for an arm with a prismatic
    joint or a task without a position coordinate."""
    chain = arm.compiled
    rows = [(i, "xyz".index(n)) for i, n in enumerate(arm.task_names) if n in ("x", "y", "z")]
    if chain.prismatic.any() or not rows:
        return None
    links = np.linalg.norm(chain.origins[1:, :3, 3], axis=-1).sum()
    outer = float(links + np.linalg.norm(chain.tip[:3, 3]))
    y, first = np.asarray(target, dtype=float), chain.origins[0, :3, 3]
    d = float(np.linalg.norm([y[i] - first[k] for i, k in rows]))
    if d <= outer + 1e-9 * max(1.0, outer):
        return None
    least = "" if len(rows) == 3 else "at least "
    return (
        f"the target is out of reach: its position is {least}{_g(d)} from the first joint, "
        f"beyond the arm's reach {_g(outer)} (the sum of its links' lengths)"
    )


def stall_reason(inverse: Inverse, target, x) -> str:
    """Why a run of ``inverse`` stalled at ``x`` (p,) on its way to ``target`` (r,), in words.

    Notes
    -----
    Out of reach when the chain's reach says so; else a kinematic singularity when
    sigma_min(J) / sigma_max(J) < :data:`SINGULAR_RATIO`; else, for the extended Jacobian
    (11), an algorithmic singularity when ||J^E#(x)|| sigma_min(J(x)) exceeds
    :data:`ALGORITHMIC_RATIO` (a right inverse of J has ||J#|| >= 1 / sigma_min(J), with
    equality for the pseudoinverse (8)) or J^E# is undefined there; else the integrator's steps
    collapsed: where J has full rank the task error has no local minimum to stop at (a right
    inverse's falls as exp(-theta), eq. (5); damped least squares' as fast as
    sigma_min^2 / (sigma_min^2 + lambda^2) at least).
    """
    out, within = reach_note(inverse.kinematics, target)
    if out is not None:
        return out
    x = np.asarray(x, dtype=float)
    try:
        with np.errstate(all="ignore"):
            J = np.asarray(inverse.kinematics.jacobian_unchecked(x), dtype=float)
            s = np.linalg.svd(J, compute_uv=False)
    except (JikError, ValueError, np.linalg.LinAlgError):
        return f"{within}the step size collapsed near a singularity"
    ratio = float(s[-1] / s[0]) if s[0] > 0 else 0.0
    if not ratio >= SINGULAR_RATIO:
        return (
            f"{within}the run stalled at a kinematic singularity: J loses rank there "
            f"(σ_min/σ_max = {_g(ratio)})"
        )
    try:  # (an inverse singular there raises: that is the algorithmic singularity)
        with np.errstate(all="ignore"):
            grow = float(np.linalg.norm(inverse.matrix(x), 2) * s[-1])
    except (JikError, ValueError, np.linalg.LinAlgError):
        grow = float("inf")
    if inverse.name == "extended" and not grow <= ALGORITHMIC_RATIO:
        return (
            f"{within}J is regular there (σ_min/σ_max = {_g(ratio)}) but the extended "
            "Jacobian [J; dh] (10) is near singular (an algorithmic singularity): the level "
            "set h = h(x0) does not lead to the target from this start"
        )
    return (
        f"{within}J is regular there (σ_min/σ_max = {_g(ratio)}), so the task error still "
        "falls there (eq. (5)): the integrator's steps collapsed, as near a singularity of J#; "
        "move the start or the target"
    )
