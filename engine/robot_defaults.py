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


#: Points of a Halton sequence over the box tried as the default start of a robot whose task is
#: undefined at the box's centre (``log(x1 - 1)`` at x1 = 0.5).
START_CANDIDATES = 256


def defaults(kin: Kinematics, d: Mapping, box, base: RobotSpec | None = None) -> tuple:
    """x0 (given, else a URDF arm's home if given, else 0.5 in each range that holds it and the
    range's middle in the others, or where the task is undefined there or along the default
    path, the first point of a Halton sequence over the box where it is defined), a target and a
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
    else:  # (0.5, or the middle of a range without it: a start on a limit leaves it at once)
        x0 = np.where((lo < 0.5) & (0.5 < hi), 0.5, (lo + hi) / 2)
    if base is not None:
        target, path = d.get("target", base.default_target), d.get("path", base.default_path)
    else:
        step = 0.15 * np.minimum(1.0, hi - lo)
        task = _default_task(kin, x0, step)
        if task is None and "x0" not in d and "home" not in d:
            x0, task = _defined_start(kin, lo, hi, step, x0)
        if task is None and not ("target" in d and "path" in d):
            with np.errstate(all="ignore"):
                y0 = kin.forward(x0)
            bad = np.flatnonzero(~np.isfinite(y0))
            where = f" (k{bad[0] + 1} = {y0[bad[0]]:g})" if bad.size else " or near it"
            searched = (
                "" if "x0" in d or "home" in d else f" or at {START_CANDIDATES} points of x_range"
            )
            raise InvalidInputError(
                f"the task k(x) is undefined at x0 = ({', '.join(f'{v:g}' for v in x0)})"
                f"{where}{searched}: give an x0 where it is defined",
                "x0",
            )
        _check_rank(kin, lo, hi, "joints" if d.get("name") == "planar_chain" else "task")
        target = d.get("target", task[1] if task is not None else None)
        path = d.get("path", task if task is not None else None)
    target, path = points(target, kin.r, "target"), points(path, kin.r, "path")
    if target.ndim != 1:
        raise InvalidInputError(f"target must be one task point ({kin.r} numbers)", "target")
    if path.ndim != 2 or not 1 <= len(path) <= MAX_PATH_POINTS:
        raise InvalidInputError(
            f"path must be a list of 1 to {MAX_PATH_POINTS} task points", "path"
        )
    return tuple(x0.tolist()), tuple(target.tolist()), tuple(map(tuple, path.tolist()))


def _default_task(kin: Kinematics, x0: np.ndarray, step: np.ndarray) -> np.ndarray | None:
    """The default closed path from ``x0`` (shape (3, r): the moves of two joints by ``step``,
    :func:`loop_joints`; its second point is the default target), or None where the task is
    undefined at x0 or on the path."""
    with np.errstate(all="ignore"):
        if not np.isfinite(kin.forward(x0)).all():
            return None
        i, j = loop_joints(kin, x0, step)
        moves = np.zeros((3, kin.p))
        moves[0, i] = moves[1, i] = step[i]
        moves[1, j] = moves[2, j] = step[j]
        path = kin.forward(x0 + moves)
    return path if np.isfinite(path).all() else None


def _defined_start(kin, lo, hi, step, centre) -> tuple[np.ndarray, np.ndarray | None]:
    """The first of :data:`START_CANDIDATES` Halton points over the box [lo, hi] where the task
    and its default path are defined, with that path; ``centre`` and None where none is."""
    from scipy.stats import qmc

    candidates = lo + (hi - lo) * qmc.Halton(kin.p, scramble=False).random(START_CANDIDATES)
    with np.errstate(all="ignore"):
        defined = np.isfinite(kin.forward(candidates)).all(axis=-1)
    for x0 in candidates[defined]:  # (the first usually is; only a robot the centre failed)
        task = _default_task(kin, x0, step)
        if task is not None:
            return x0, task
    return centre, None


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


#: Configurations of a Halton sequence over the box at which a robot defined by data must have
#: a Jacobian of full rank r at least once (:func:`_check_rank`), and the ratio
#: sigma_min / sigma_max of J, each row scaled by its largest entry, below which it has not.
RANK_POINTS, RANK_RATIO = 32, 1e-10


def _check_rank(kin: Kinematics, lo, hi, field: str) -> None:
    """Refuse a robot whose Jacobian J (r, p) has rank < r at each of :data:`RANK_POINTS`
    configurations spread over its box [lo, hi]: its task cannot move in every direction
    anywhere (a planar chain of prismatic joints only, which moves along one line; a formula
    task whose coordinates depend on each other), so no inverse can follow it and every start is
    singular. A robot singular on a set of measure zero passes."""
    from scipy.stats import qmc

    x = lo + (hi - lo) * qmc.Halton(kin.p, scramble=False).random(RANK_POINTS + 1)[1:]
    with np.errstate(all="ignore"):
        J = np.asarray(kin.jacobian(x), dtype=float)
    J = J[np.isfinite(J).all(axis=(1, 2))]
    if not len(J):
        return
    rows = np.max(np.abs(J), axis=2, keepdims=True)  # (each coordinate in its own unit)
    s = np.linalg.svd(J / np.where(rows > 0, rows, 1.0), compute_uv=False)  # (n, r), descending
    full = s[:, -1] > RANK_RATIO * np.maximum(s[:, 0], 1e-300)
    if np.any(full):
        return
    rank = int(np.max(np.sum(s > RANK_RATIO * np.maximum(s[:, :1], 1e-300), axis=1)))
    raise InvalidInputError(
        f"the task cannot move in every direction: J has rank {rank} < r = {kin.r} at each of "
        f"{len(J)} configurations spread over x_range, so no inverse can follow it and every "
        "start is singular (its coordinates depend on each other, or the joints move it along "
        f"fewer directions, as prismatic joints alone do); give a task of {rank} "
        f"coordinate{'s' if rank != 1 else ''} or other joints",
        field,
    )
