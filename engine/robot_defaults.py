"""The defaults of a robot defined by data (:func:`jik.engine.robot_spec.robot_from_dict`):
its start x0, a target, and a closed path the pseudoinverse drifts on, each checked when given.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .exceptions import InvalidInputError
from .kinematics import Kinematics
from .registry import RobotSpec
from .repeatability import MAX_PATH_POINTS
from .validation import as_points


def points(value, size: int, name: str):
    """``as_points`` with the error's field set to ``name``."""
    try:
        return as_points(value, size, name)
    except InvalidInputError as exc:
        raise InvalidInputError(str(exc), name) from None


def loop_joints(kin: Kinematics, x0: np.ndarray, step: np.ndarray) -> tuple[int, int]:
    """The two joints whose moves by ``step`` make the default closed path: the first and the
    last, unless the task moves they make span less than a tenth of the largest parallelogram of any
    pair (a last joint that only turns the flange about its axis moves no position and, near
    home, no rx, ry); then that largest pair. Task moves are forward differences, all p at once.
    """
    with np.errstate(all="ignore"):  # (a task that overflows: the build refuses it after)
        d = kin.forward(x0 + np.diag(step)) - kin.forward(x0)
        gram = d @ d.T
        norms = np.diag(gram)
        area = np.sqrt(np.maximum(np.outer(norms, norms) - gram**2, 0.0))
    area = np.where(np.isfinite(area), area, 0.0)
    last = kin.p - 1
    if area[0, last] >= 0.1 * area.max():
        return 0, last
    i, j = np.unravel_index(int(np.argmax(area)), area.shape)
    return int(min(i, j)), int(max(i, j))


def defaults(kin: Kinematics, d: Mapping, box, base: RobotSpec | None = None) -> tuple:
    """x0 (given, else a URDF arm's home if given, else 0.5 in each range), a target and a
    closed path reachable from it; a built-in robot's (``base``) where its definition has none."""
    lo, hi = np.array(box).T
    if "x0" in d:
        x0 = points(d["x0"], kin.p, "x0")
        if x0.ndim != 1:
            raise InvalidInputError(f"x0 must be one configuration of {kin.p} numbers", "x0")
    elif base is not None:
        x0 = np.array(base.default_x0, dtype=float)
    elif "home" in d:
        x0 = np.array(kin.parameters["home"], dtype=float)
    else:
        x0 = np.clip(0.5, lo, hi)
    if base is not None:
        target, path = d.get("target", base.default_target), d.get("path", base.default_path)
    else:
        with np.errstate(all="ignore"):
            y0 = kin.forward(x0)
        if not np.isfinite(y0).all() and not ("target" in d and "path" in d):
            k = int(np.flatnonzero(~np.isfinite(y0))[0])
            raise InvalidInputError(
                f"the task k(x0) is undefined at x0 = ({', '.join(f'{v:g}' for v in x0)}) "
                f"(k{k + 1} = {y0[k]:g}): give an x0 where it is defined",
                "x0",
            )
        step = 0.15 * np.minimum(1.0, hi - lo)
        i, j = loop_joints(kin, x0, step)
        moves = np.zeros((3, kin.p))
        moves[0, i] = moves[1, i] = step[i]
        moves[1, j] = moves[2, j] = step[j]
        target = d.get("target", kin.forward(x0 + moves[1]))
        path = d.get("path", kin.forward(x0 + moves))
    target, path = points(target, kin.r, "target"), points(path, kin.r, "path")
    if target.ndim != 1:
        raise InvalidInputError(f"target must be one task point ({kin.r} numbers)", "target")
    if path.ndim != 2 or not 1 <= len(path) <= MAX_PATH_POINTS:
        raise InvalidInputError(
            f"path must be a list of 1 to {MAX_PATH_POINTS} task points", "path"
        )
    return tuple(x0.tolist()), tuple(target.tolist()), tuple(map(tuple, path.tolist()))
