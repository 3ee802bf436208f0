"""Joint limits: whether a run stayed within a robot's limits; if not, its first violation, its
farthest excursion and whether it ends outside them.

A robot's limits are a (p, 2) array of [lower, upper] per joint variable, -inf/+inf where a
joint has none (a continuous joint). A URDF arm reads them from its file; a planar chain or a
formula robot takes them from its definition (``"limits"``); the paper's robots have none. A start
outside the limits is accepted (the run is the paper's algorithm, eq. (7), which knows nothing
of limits) and reported as the first violation, at cycle 0, leg 0.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from .exceptions import InvalidInputError
from .validation import FloatArray


def robot_limits(kinematics) -> FloatArray | None:
    """The kinematics' joint limits (p, 2), or None when it has none."""
    limits = getattr(kinematics, "joint_limits", None)
    return None if limits is None else np.asarray(limits, dtype=float)


def limited_box(box, limits) -> FloatArray:
    """A finite box (p, 2) of configurations within the robot's limits (p, 2), or the box itself
    when ``limits`` is None: each finite limit replaces its side of the box, a side without one
    (+-inf) keeps the box's; where the box lies wholly beyond a finite limit, the free side
    keeps the box's width from that limit. The weighted inverse's default limits and the range
    of the posture rest's sliders."""
    box = np.asarray(box, dtype=float)
    if limits is None:
        return box.copy()
    limits = np.asarray(limits, dtype=float)
    free = ~np.isfinite(limits)
    lo, hi = np.where(free, box, limits).T
    empty, width = lo >= hi, box[:, 1] - box[:, 0]
    lo = np.where(empty & free[:, 0], hi - width, lo)
    hi = np.where(empty & free[:, 1], lo + width, hi)
    return np.stack([lo, hi], axis=-1)


def limit_names(kinematics) -> tuple[str, ...]:
    """Each variable's name for a report: ``x4 (panda_joint4)`` for a URDF arm."""
    joints = getattr(kinematics, "joint_names", None)
    names = tuple(kinematics.variable_names)
    if joints is None:
        return names
    return tuple(f"{v} ({j})" for v, j in zip(names, joints, strict=True))


@dataclass(frozen=True)
class LimitViolation:
    """Where a run first left the limits.

    ``cycle`` and ``leg`` count from 1 (0, 0: the start x0); ``joint`` indexes x (0-based),
    ``name`` is its variable's name, ``value`` the joint's value there and ``limit`` the bound
    it passed (``bound``: ``"lower"`` or ``"upper"``); ``single``: the run was one leg (a solve
    toward one target), which :attr:`where` says instead of "cycle 1, leg 1".
    """

    cycle: int
    leg: int
    joint: int
    name: str
    value: float
    limit: float
    bound: str
    single: bool = False

    @property
    def where(self) -> str:
        """ "at the start x0", "on the way to the target" or "at cycle 2, leg 3"."""
        if self.cycle == 0:
            return "at the start x0"
        return (
            "on the way to the target" if self.single else f"at cycle {self.cycle}, leg {self.leg}"
        )

    @property
    def side(self) -> str:
        """ "below its lower" or "above its upper": the limit it passed, in words."""
        return "below its lower" if self.bound == "lower" else "above its upper"

    def __str__(self) -> str:
        return f"{self.where}: {self.name} = {self.value:.6g}, {self.side} limit {self.limit:.6g}"

    def as_dict(self) -> dict:
        return {
            "cycle": self.cycle,
            "leg": self.leg,
            "joint": self.joint,
            "name": self.name,
            "value": self.value,
            "limit": self.limit,
            "bound": self.bound,
        }


#: What a report of a run that was not recorded checked.
_ENDS = "at its start and its legs' ends (the steps between were not recorded: record=True)"


@dataclass(frozen=True)
class LimitsReport:
    """Whether a run stayed within the limits, and if not its first violation, its farthest
    excursion (the joint furthest beyond a limit, and where) and whether it ends outside them;
    ``every_step``: whether every step of the run was checked (it was recorded), else only its
    start and its legs' ends."""

    within: bool
    violation: LimitViolation | None = None
    every_step: bool = True
    farthest: LimitViolation | None = None
    ends_outside: bool = False

    def __str__(self) -> str:
        if not self.within:
            return f"left the joint limits {self.violation}{self._farthest(6)}{self._end()}"
        return "within the joint limits" + ("" if self.every_step else f" {_ENDS}")

    def _farthest(self, digits: int) -> str:
        """ "; farthest <where>: ..." when the farthest excursion is not the first violation."""
        f, v = self.farthest, self.violation
        if f is None or v is None or (f.joint, f.value) == (v.joint, v.value):
            return ""
        beyond = abs(f.value - f.limit)
        return (
            f"; farthest {f.where}: {f.name} = {f.value:.{digits}g}, {beyond:.{digits}g} "
            f"{f.side} limit {f.limit:.{digits}g}"
        )

    def _end(self) -> str:
        return "; it ends outside them" if self.ends_outside else "; it ends within them"

    def sentence(self, run: str, robot: str) -> str:
        """The report as a sentence on the run named ``run`` of ``robot`` (values to four
        digits): it "stayed within the joint limits of the <robot> all along its run" (or, not
        recorded, at its start and its legs' ends), or "left the joint limits of the <robot>"
        and where first (its start, or a cycle and leg), where farthest, and whether it ends
        outside them."""
        v = self.violation
        if v is None:
            along = "all along its run" if self.every_step else _ENDS
            return f"{run}: stayed within the joint limits of the {robot} {along}."
        where = "its start x0 is already outside them" if v.cycle == 0 else f"first {v.where}"
        return (
            f"{run}: left the joint limits of the {robot}: {where}, joint {v.name} = "
            f"{v.value:.4g}, {v.side} limit {v.limit:.4g}{self._farthest(4)}{self._end()}."
        )

    def as_dict(self) -> dict:
        first = None if self.violation is None else self.violation.as_dict()
        farthest = None if self.farthest is None else self.farthest.as_dict()
        return {
            "within": self.within,
            "violation": first,
            "farthest": farthest,
            "ends_outside": self.ends_outside,
        }


def check_limits(limits, p: int, field: str = "limits") -> FloatArray:
    """Validate limits: p pairs [lower, upper], lower < upper, None (or +-inf) for no bound."""
    try:
        raw = [[-np.inf if lo is None else lo, np.inf if hi is None else hi] for lo, hi in limits]
        box = np.array(raw, dtype=float)
    except (TypeError, ValueError):
        box = np.zeros((0, 2))
    if box.shape != (p, 2) or np.isnan(box).any() or not np.all(box[:, 0] < box[:, 1]):
        raise InvalidInputError(
            f"{field} must be {p} pairs [lower, upper] with lower < upper (a bound null: none)",
            field,
        )
    return box


def outside(limits: FloatArray, x: FloatArray) -> FloatArray:
    """Mask (...,) of the configurations x (..., p) outside the limits (p, 2)."""
    x = np.asarray(x, dtype=float)
    return np.any((x < limits[:, 0]) | (x > limits[:, 1]), axis=-1)


def _first(limits: FloatArray, X: FloatArray) -> tuple[int, int] | None:
    """(row, joint) of the first configuration of X (m, p) outside the limits."""
    low, high = X < limits[:, 0], X > limits[:, 1]
    rows = np.flatnonzero(np.any(low | high, axis=-1))
    if rows.size == 0:
        return None
    i = int(rows[0])
    return i, int(np.flatnonzero(low[i] | high[i])[0])


def _violation(limits, x, joint, cycle, leg, names) -> LimitViolation:
    lower = x[joint] < limits[joint, 0]
    bound = limits[joint, 0 if lower else 1]
    side = "lower" if lower else "upper"
    return LimitViolation(cycle, leg, joint, names[joint], float(x[joint]), float(bound), side)


def legs_report(
    limits: FloatArray,
    x0: FloatArray,
    legs: Sequence[FloatArray],
    legs_per_cycle: int,
    names: Sequence[str],
) -> LimitsReport:
    """The first violation of a run, its farthest excursion and whether it ends outside the
    limits: the start x0 (p,), then each leg's configurations in order (a leg's trajectory
    (m, p), or its end (1, p)), leg k of cycle k // L + 1; the run ends at its last finite
    configuration."""
    single = len(legs) == 1
    rows = [(0, 0, np.asarray(x0, dtype=float)[None])]
    rows += [
        (k // legs_per_cycle + 1, k % legs_per_cycle + 1, np.atleast_2d(np.asarray(X, float)))
        for k, X in enumerate(legs)
    ]
    first: LimitViolation | None = None
    farthest, beyond = None, 0.0
    for cycle, leg, X in rows:
        found = _first(limits, X) if first is None else None
        if found is not None:
            first = _violation(limits, X[found[0]], found[1], cycle, leg, names)
        # (fmax: a failed leg's NaN end is no excursion)
        excess = np.fmax(np.fmax(limits[:, 0] - X, X - limits[:, 1]), 0.0)
        if excess.size and excess.max() > beyond:
            i, j = np.unravel_index(int(np.argmax(excess)), excess.shape)
            farthest = _violation(limits, X[i], int(j), cycle, leg, names)
            beyond = float(excess[i, j])
    if first is None:
        return LimitsReport(True)
    ends = np.concatenate([X for _, _, X in rows])
    ends = ends[np.all(np.isfinite(ends), axis=-1)]
    return LimitsReport(
        False,
        replace(first, single=single),
        farthest=None if farthest is None else replace(farthest, single=single),
        ends_outside=bool(outside(limits, ends[-1])),
    )


def solve_report(limits: FloatArray, result, names: Sequence[str]) -> LimitsReport:
    """A solve (one leg, cycle 1): its recorded trajectory from its start, else its start and
    end."""
    traj = getattr(result, "trajectory", None)
    if traj is None:
        X = np.stack([np.asarray(result.x0, dtype=float), np.asarray(result.x, dtype=float)])
        return replace(legs_report(limits, X[0], [X[1:]], 1, names), every_step=False)
    return legs_report(limits, traj.x[0], [traj.x], 1, names)


def repeatability_report(limits: FloatArray, result, names: Sequence[str]) -> LimitsReport:
    """A single start's repeatability run: every leg's trajectory when recorded, else its start
    and legs' ends. A resumed run's legs (``leg_results``, the new cycles only) are numbered
    from the first new cycle; the earlier cycles are checked at their legs' ends."""
    L = len(result.targets)
    recorded = [r.trajectory.x for r in result.leg_results if r.trajectory is not None]
    ends = np.asarray(result.legs, dtype=float)
    if not recorded or len(recorded) != len(result.leg_results):
        return replace(legs_report(limits, result.x0, list(ends), L, names), every_step=False)
    # The legs run: those with an end, and a failed one (recorded; its end is NaN).
    finite = np.all(np.isfinite(ends), axis=-1)
    run = (len(ends) if finite.all() else int(np.argmin(finite))) + (not result.success)
    before = list(ends[: max(0, run - len(recorded))])  # (the cycles a resumed run took over)
    report = legs_report(limits, result.x0, [*before, *recorded], L, names)
    return replace(report, every_step=not before) if report.within else report


def run_report(kinematics, result) -> LimitsReport | None:
    """Whether a run of ``kinematics`` (a solve's result, or a single start's repeatability
    result) stayed within its joint limits, and its first violation; None for a robot
    without limits. A batch is refused (a :class:`~jik.engine.results.BatchSolveResult`'s
    member ``result[i]`` is a solve's result), and so is a run of a robot with another p."""
    from .repeatability_result import RepeatabilityResult
    from .results import BatchSolveResult, SolveResult

    if isinstance(result, BatchSolveResult):
        raise InvalidInputError(
            f"result is a batch of {len(result)} solves; report each member, result[i]", "result"
        )
    if not isinstance(result, SolveResult | RepeatabilityResult):
        raise InvalidInputError(
            "result must be a SolveResult or a single start's RepeatabilityResult, got "
            f"{type(result).__name__}",
            "result",
        )
    x0 = np.asarray(result.x0)
    if x0.ndim != 1:
        raise InvalidInputError(
            f"result is a repeatability run of {len(x0)} starts; the report is of one start's "
            "run (an atlas counts the runs of many that leave the limits)",
            "result",
        )
    if x0.shape[-1] != kinematics.p:
        raise InvalidInputError(
            f"result is a run of a robot with {x0.shape[-1]} joint variables; this robot has "
            f"p = {kinematics.p}",
            "result",
        )
    limits = robot_limits(kinematics)
    if limits is None:
        return None
    names = limit_names(kinematics)
    if isinstance(result, RepeatabilityResult):
        return repeatability_report(limits, result, names)
    return solve_report(limits, result, names)


def starts_outside(limits: FloatArray, x0: FloatArray, legs: FloatArray) -> FloatArray:
    """Mask (n,) of the runs of an atlas (starts x0 (n, p), leg ends (n, C * L, p)) whose start
    or some leg end is outside the limits."""
    return outside(limits, x0) | np.any(outside(limits, legs), axis=-1)
