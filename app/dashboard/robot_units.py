"""The units of a chain's joint and task variables, read from its kinematics: a revolute joint
in rad and a prismatic one in m; the task's position coordinates in m, its angles and rotation
coordinates in rad. A formula robot's variables have none (its definition gives no units)."""

from __future__ import annotations

from typing import Any

#: The unit of each kind of task coordinate (:mod:`jik.engine.pose_task`, a planar chain's).
TASK_UNITS = {"x": "m", "y": "m", "z": "m", "rx": "rad", "ry": "rad", "rz": "rad", "phi": "rad"}


def chain_units(kin: Any, task_names) -> tuple[tuple[str, ...], tuple[str, ...]] | None:
    """(joint units, task units) of a URDF or planar chain ``kin``; None for any other."""
    revolute = getattr(kin, "revolute", None)  # (a planar chain's, per joint)
    chain = getattr(kin, "chain", None)  # (a URDF chain's joints, fixed ones included)
    if revolute is not None:
        joints = tuple("rad" if r else "m" for r in revolute)
    elif chain is not None:
        kinds = {int(j.index): j.type for j in chain if getattr(j, "index", -1) >= 0}
        joints = tuple("m" if kinds.get(i) == "prismatic" else "rad" for i in range(kin.p))
    else:
        return None
    return joints, tuple(TASK_UNITS.get(n, "") for n in task_names)
