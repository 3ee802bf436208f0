"""The defaults of a robot defined by data (:func:`jik.engine.robot_spec.robot_from_dict`):
its start x0, a target, and a closed path the pseudoinverse drifts on, each checked when given;
and, for a robot without an augmenting map, the variables a default map h keeps
(:func:`kept_variables`).
"""

from __future__ import annotations

import itertools
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


#: sigma_min / sigma_max of J's columns of the joints h leaves free, at x0, above which the
#: default map keeps the last p - r variables.
REGULAR = 1e-6


def kept_variables(kin: Kinematics, x0) -> list[int]:
    """The p - r variables a default augmenting map h = (x_i, ...) keeps, for a robot defined
    without a map: the last ones, unless the columns of J(x0) of the others are singular at
    ``x0`` (then the extended Jacobian [J; dh] of eq. (10) is, as for a Panda's xyz task at
    home, whose joints 1 and 3 move the point alike); then those whose others' columns are best
    conditioned (largest sigma_min / sigma_max).

    Parameters
    ----------
    kin : Kinematics
    x0 : array_like, shape (p,)
        The robot's default start.

    Returns
    -------
    list of int
        p - r indices of variables, ascending.
    """
    p, r = kin.p, kin.r
    with np.errstate(all="ignore"):
        J = np.asarray(kin.jacobian(np.asarray(x0, dtype=float)), float)  # (r, p)
    driven = np.array(list(itertools.combinations(range(p), r)))  # (n, r): joints J drives
    s = np.linalg.svd(np.nan_to_num(J[:, driven].transpose(1, 0, 2)), compute_uv=False)
    ratio = s[:, -1] / np.maximum(s[:, 0], 1e-300)  # (n,)
    first = int(np.flatnonzero((driven == np.arange(r)).all(axis=1))[0])
    best = first if ratio[first] > REGULAR else int(np.argmax(ratio))
    return [i for i in range(p) if i not in driven[best]]
