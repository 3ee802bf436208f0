"""Results of the continuation algorithm (7): a solve, a batch, a trajectory, a repeatability run.

They borrow SciPy's vocabulary (``x``, ``success``, ``message``, ``nit``), print on one line
(``print(result)``) and export their numbers: :meth:`as_dict` gives JSON-friendly values, and
``to_dataframe()`` a pandas DataFrame (pandas is optional: ``columns()`` gives the same columns
as plain arrays).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from .exceptions import InvalidInputError
from .inverses import Inverse
from .validation import FloatArray


def short_vector(v, digits: int = 4) -> str:
    """A vector on one line, ``[0.1235, -1, 1.571]``; a long one elided in the middle."""
    a = np.asarray(v, dtype=float).ravel()
    items = [f"{t:.{digits}g}" for t in a]
    if len(items) > 8:
        items = [*items[:3], "...", *items[-3:]]
    return "[" + ", ".join(items) + "]"


def short_text(text: str, width: int = 60) -> str:
    """``text`` cut to ``width`` characters, quoted."""
    return repr(text if len(text) <= width else text[: width - 3] + "...")


def _plural(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def dataframe(columns: dict[str, Any]):
    """A pandas DataFrame of ``columns`` (pandas is imported here, and only here)."""
    try:
        import pandas as pd
    except ImportError:
        raise ImportError(
            "to_dataframe() needs pandas (pip install pandas); columns() gives the same "
            "columns as numpy arrays"
        ) from None
    return pd.DataFrame(columns)


def coordinate_columns(name: str, values: FloatArray) -> dict[str, FloatArray]:
    """``{name1: values[:, 0], name2: ...}``: one column per coordinate, numbered from 1."""
    values = np.asarray(values, dtype=float)
    return {f"{name}{k + 1}": values[:, k] for k in range(values.shape[1])}


@dataclass(frozen=True)
class Trajectory:
    """One run of eq. (7), point by point (accepted steps or iterations).

    Attributes
    ----------
    theta : ndarray, shape (m,)
        Continuation parameter theta (continuous) or iteration number (discrete).
    x : ndarray, shape (m, p)
    y : ndarray, shape (m, r)
        k(x).
    error : ndarray, shape (m,)
        ||k(x) - y_d||.
    h : ndarray, shape (m,) or None
        h(x) for the extended inverse (constant along the continuous flow, eq. (12)); NaN at a
        point where h is undefined (a run stopped there).
    """

    theta: FloatArray
    x: FloatArray
    y: FloatArray
    error: FloatArray
    h: FloatArray | None

    def __len__(self) -> int:
        return len(self.theta)

    def __repr__(self) -> str:
        return (
            f"Trajectory({len(self)} points, theta {self.theta[0]:.4g} to {self.theta[-1]:.4g}, "
            f"x {short_vector(self.x[0])} to {short_vector(self.x[-1])}, "
            f"error {self.error[0]:.3g} to {self.error[-1]:.3g})"
        )

    def columns(self) -> dict[str, FloatArray]:
        """One array per column: ``theta``, ``x1``..``xp``, ``y1``..``yr``, ``error``, ``h``."""
        out = {"theta": np.asarray(self.theta, dtype=float)}
        out |= coordinate_columns("x", self.x) | coordinate_columns("y", self.y)
        out["error"] = np.asarray(self.error, dtype=float)
        if self.h is not None:
            out["h"] = np.asarray(self.h, dtype=float)
        return out

    def to_dataframe(self):
        """The trajectory as a pandas DataFrame, a row per point (:meth:`columns`)."""
        return dataframe(self.columns())

    def as_dict(self) -> dict[str, Any]:
        """JSON-friendly: ``theta``, ``x`` (m lists of p), ``y``, ``error``, ``h`` (or None)."""
        return {
            "theta": np.asarray(self.theta).tolist(),
            "x": np.asarray(self.x).tolist(),
            "y": np.asarray(self.y).tolist(),
            "error": np.asarray(self.error).tolist(),
            "h": None if self.h is None else np.asarray(self.h).tolist(),
        }


@dataclass(frozen=True)
class SolveResult:
    """Result of one solve, in SciPy's vocabulary (``x``, ``success``, ``message``, ``nit``)."""

    x: FloatArray
    y: FloatArray
    error: float
    success: bool
    message: str
    nit: int
    trajectory: Trajectory | None
    mode: str
    gamma: float
    algorithm: str

    def __repr__(self) -> str:
        points = "none" if self.trajectory is None else f"{len(self.trajectory)} points"
        return (
            f"SolveResult({self.algorithm}, {self.mode}, success={self.success}, "
            f"x={short_vector(self.x)}, error={self.error:.3g}, nit={self.nit}, "
            f"trajectory={points}, message={short_text(self.message)})"
        )

    def as_dict(self, trajectory: bool = False) -> dict[str, Any]:
        """JSON-friendly fields; with ``trajectory``, also :meth:`Trajectory.as_dict`."""
        out: dict[str, Any] = {
            "algorithm": self.algorithm,
            "mode": self.mode,
            "gamma": self.gamma,
            "x": self.x.tolist(),
            "y": self.y.tolist(),
            "error": self.error,
            "success": self.success,
            "nit": self.nit,
            "message": self.message,
        }
        if trajectory:
            out["trajectory"] = None if self.trajectory is None else self.trajectory.as_dict()
        return out


@dataclass(frozen=True)
class BatchSolveResult:
    """Results of a batch of solves; index it for a :class:`SolveResult` with its trajectory."""

    x: FloatArray  # (n, p)
    y: FloatArray  # (n, r)
    error: FloatArray  # (n,)
    success: FloatArray  # (n,) bool
    message: tuple[str, ...]
    nit: FloatArray  # (n,) int
    mode: str
    gamma: float
    algorithm: str
    _inverse: Inverse = field(repr=False)
    _y_d: FloatArray = field(repr=False)
    # Recorded points: member index, theta, x of every accepted step, in order.
    _rec_member: FloatArray | None = field(repr=False, default=None)
    _rec_theta: FloatArray | None = field(repr=False, default=None)
    _rec_x: FloatArray | None = field(repr=False, default=None)
    # Each member's outcome (solve_rules.Status): solve_in_chunks words its message.
    _status: FloatArray | None = field(repr=False, default=None)

    def __len__(self) -> int:
        return len(self.x)

    def __repr__(self) -> str:
        return (
            f"BatchSolveResult({self.algorithm}, {self.mode}, {len(self)} solves, "
            f"{int(np.count_nonzero(self.success))} converged, "
            f"max error {float(np.max(self.error)) if len(self) else float('nan'):.3g})"
        )

    def columns(self) -> dict[str, Any]:
        """One array per column, a row per member: ``x1``..``xp``, ``y1``..``yr``, ``error``,
        ``success``, ``nit``, ``message``."""
        out: dict[str, Any] = coordinate_columns("x", self.x) | coordinate_columns("y", self.y)
        out["error"] = np.asarray(self.error)
        out["success"] = np.asarray(self.success, dtype=bool)
        out["nit"] = np.asarray(self.nit, dtype=int)
        out["message"] = np.array(self.message)
        return out

    def to_dataframe(self):
        """The batch as a pandas DataFrame, a row per member (:meth:`columns`)."""
        return dataframe(self.columns())

    def as_dict(self) -> dict[str, Any]:
        """JSON-friendly: the settings and, per member, x, y, error, success, nit, message."""
        return {
            "algorithm": self.algorithm,
            "mode": self.mode,
            "gamma": self.gamma,
            "x": self.x.tolist(),
            "y": self.y.tolist(),
            "error": self.error.tolist(),
            "success": np.asarray(self.success, dtype=bool).tolist(),
            "nit": np.asarray(self.nit, dtype=int).tolist(),
            "message": list(self.message),
        }

    def trajectory(self, i: int) -> Trajectory:
        """The trajectory of member ``i`` (requires ``record=True``)."""
        # The three recordings are set together (all or none).
        if self._rec_member is None or self._rec_theta is None or self._rec_x is None:
            raise InvalidInputError("trajectories were not recorded; solve with record=True")
        ys, h, err, bounds = self._recorded
        sel = slice(bounds[i], bounds[i + 1])
        return Trajectory(
            theta=self._rec_theta[sel],
            x=self._rec_x[sel],
            y=ys[sel],
            error=err[sel],
            h=None if h is None else h[sel],
        )

    @cached_property
    def _recorded(self):
        """k(x), h(x), ||k(x) - y_d|| of every recorded point at once, and each member's slice."""
        assert self._rec_member is not None and self._rec_x is not None
        ys = self._inverse.kinematics.forward_unchecked(self._rec_x)
        h = self._inverse.augmenting_value(self._rec_x)
        err = np.linalg.norm(ys - self._y_d[self._rec_member], axis=-1)
        bounds = np.searchsorted(self._rec_member, np.arange(len(self.x) + 1))  # sorted members
        return ys, None if h is None else np.asarray(h), err, bounds

    def __getitem__(self, i: int) -> SolveResult:
        return SolveResult(
            x=self.x[i],
            y=self.y[i],
            error=float(self.error[i]),
            success=bool(self.success[i]),
            message=self.message[i],
            nit=int(self.nit[i]),
            trajectory=self.trajectory(i) if self._rec_member is not None else None,
            mode=self.mode,
            gamma=self.gamma,
            algorithm=self.algorithm,
        )


@dataclass(frozen=True)
class RepeatabilityResult:
    """Configurations along a closed path driven ``cycles`` times.

    Attributes
    ----------
    targets : ndarray, shape (L, r) or (n, L, r)
        The task point of every leg of one cycle (the given path, closed by k(x0) if needed).
    legs : ndarray, shape (cycles * L, p) or (n, cycles * L, p)
        Configuration after each leg.
    cycle_end : ndarray, shape (cycles, p) or (n, cycles, p)
    drift : ndarray, shape (cycles,) or (n, cycles)
        ||cycle_end[c] - x0||.
    success : bool or ndarray of bool, shape (n,)
    message : str or tuple of str
    leg_results : list of SolveResult
        Every leg with its trajectory (single start with ``record=True`` only).
    """

    x0: FloatArray
    targets: FloatArray
    legs: FloatArray
    cycle_end: FloatArray
    drift: FloatArray
    success: bool | FloatArray
    message: str | tuple[str, ...]
    leg_results: list[SolveResult]

    def __repr__(self) -> str:
        cycles = self.drift.shape[-1]
        if np.ndim(self.success) == 0:
            last = f"{self.drift[-1]:.3g}" if cycles else "none"
            return (
                f"RepeatabilityResult(success={self.success}, {_plural(cycles, 'cycle')} of "
                f"{len(self.targets)} legs, x0={short_vector(self.x0)}, drift after the last "
                f"cycle {last}, message={short_text(str(self.message))})"
            )
        ok = int(np.count_nonzero(self.success))
        worst = float(np.nanmax(self.drift[:, -1])) if np.any(self.success) else float("nan")
        return (
            f"RepeatabilityResult({len(self.x0)} starts, {ok} completed, "
            f"{_plural(cycles, 'cycle')} of {self.targets.shape[1]} legs, largest drift after "
            f"the last cycle {worst:.3g})"
        )

    def columns(self) -> dict[str, Any]:
        """One array per column, a row per cycle (and start): ``start`` (a batch), ``cycle``
        (from 1), ``drift``, and the configuration at the cycle's end, ``x1``..``xp``."""
        drift = np.atleast_2d(self.drift)  # (n, cycles)
        ends = self.cycle_end.reshape(-1, self.cycle_end.shape[-1])
        n, cycles = drift.shape
        out: dict[str, Any] = (
            {} if np.ndim(self.success) == 0 else {"start": np.repeat(np.arange(n), cycles)}
        )
        out["cycle"] = np.tile(np.arange(1, cycles + 1), n)
        out["drift"] = drift.ravel()
        return out | coordinate_columns("x", ends)

    def to_dataframe(self):
        """The drift per cycle as a pandas DataFrame (:meth:`columns`)."""
        return dataframe(self.columns())

    def as_dict(self) -> dict[str, Any]:
        """JSON-friendly: x0, the legs' targets, leg ends, cycle ends, drift, success, message."""
        return {
            "x0": self.x0.tolist(),
            "targets": self.targets.tolist(),
            "legs": self.legs.tolist(),
            "cycle_end": self.cycle_end.tolist(),
            "drift": self.drift.tolist(),
            "success": np.asarray(self.success).tolist(),
            "message": self.message if isinstance(self.message, str) else list(self.message),
        }
