"""Results of the continuation algorithm (7): a solve, a batch of solves, a trajectory.

They borrow SciPy's vocabulary (``x``, ``success``, ``message``, ``nit``), print on one line
(``print(result)``) and export their numbers: :meth:`as_dict` gives JSON-friendly values (None
where a number is missing, NaN in the arrays), and ``to_dataframe()`` a pandas DataFrame, with
NaN there (pandas is optional: ``columns()`` gives the same columns as plain arrays). Column
names follow :mod:`jik.engine.exports`: ``x0_k`` a start, ``x_k`` the row's configuration,
``y_k`` its task point, ``y_d_k`` a target. A repeatability run's result is
:class:`jik.engine.repeatability_result.RepeatabilityResult`.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any, overload

import numpy as np

from .exceptions import InvalidInputError
from .exports import Columns, coordinate_columns, json_values, short_text, short_vector
from .inverses import Inverse
from .solve_rules import Status
from .validation import FloatArray


@dataclass(frozen=True)
class Trajectory(Columns):
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
    h : ndarray, shape (m,), (m, p - r) or None
        h(x) for the extended inverse (constant along the continuous flow, eq. (12)), one
        column per map of a vector of p - r maps; NaN at a point where h is undefined (a run
        stopped there).
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
        """A row per point: ``theta``, the point ``x_1``..``x_p``, its task point
        ``y_1``..``y_r``, ``error`` and, for an extended inverse, ``h`` (a vector of p - r
        maps: ``h_1``..``h_(p-r)``, one column each)."""
        out = {"theta": np.asarray(self.theta, dtype=float)}
        out |= coordinate_columns("x", self.x) | coordinate_columns("y", self.y)
        out["error"] = np.asarray(self.error, dtype=float)
        if self.h is not None:
            h = np.asarray(self.h, dtype=float)
            out |= {"h": h} if h.ndim == 1 else coordinate_columns("h", h)
        return out

    def as_dict(self) -> dict[str, Any]:
        """JSON-friendly (:func:`~jik.engine.exports.json_values`: NaN as None): ``theta``,
        ``x`` (m lists of p), ``y``, ``error``, ``h`` (None without a map, or where h is
        undefined)."""
        return json_values(
            {
                "theta": np.asarray(self.theta),
                "x": np.asarray(self.x),
                "y": np.asarray(self.y),
                "error": np.asarray(self.error),
                "h": None if self.h is None else np.asarray(self.h),
            }
        )


#: The fields of a solve's ``as_dict()``, in order; a batch's hold one value per member.
AS_DICT = tuple("algorithm inverse mode gamma x0 y_d x y error success nit message status".split())


@dataclass(frozen=True)
class SolveResult(Columns):
    """Result of one solve, in SciPy's vocabulary (``x``, ``success``, ``message``, ``nit``).

    Attributes
    ----------
    x, y : ndarray, shapes (p,) and (r,)
        Where the run ended and k(x) there.
    error : float
        ||k(x) - y_d||.
    success : bool
    message : str
    nit : int
        The solver's iterations: in discrete mode the iterations of eq. (7); in continuous mode
        its work, Chebyshev-Picard sweeps plus DOP853 steps (:mod:`jik.engine.solver`). A
        sweep integrates the whole leg, so a good initial guess (``solve``'s ``guess``) takes
        one or two where a cold start takes about ten: a leg of :func:`repeatability` (whose
        legs are guessed from the cycle before or swept together) reports fewer than the same
        leg solved alone, at the same x to the sweep tolerance.
    trajectory : Trajectory or None
        Every point (``record=True``).
    mode, gamma, algorithm
        The settings of eq. (7) and the inverse's name (``Inverse.name``).
    x0, y_d : ndarray, shapes (p,) and (r,)
        The start and the target.
    inverse : str
        The inverse as printed: its algorithm, parameters, map and robot.
    status : str
        Why the run stopped, for a caller that words its own message: "converged",
        "max_steps" (out of iterations or integrator steps), "diverged", "stalled", "singular"
        (the inverse singular where it stopped), "undefined" (the inverse undefined there
        because its augmenting map h is, not [J; dh] singular) or "raised" (a typed error
        stopped it where it is: :func:`jik.engine.solve_chunks.solve_in_chunks`, a leg of
        :func:`jik.engine.repeatability.repeatability` whose progress stops at errors).
    """

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
    x0: FloatArray
    y_d: FloatArray
    _inverse: Inverse | None = field(default=None, repr=False, compare=False)
    status: str = field(default="", repr=False)

    @property
    def inverse(self) -> str:
        """The inverse as printed (made when asked: the API's workers never ask)."""
        return "" if self._inverse is None else repr(self._inverse)

    def __repr__(self) -> str:
        points = "none" if self.trajectory is None else f"{len(self.trajectory)} points"
        return (
            f"SolveResult({self.algorithm}, {self.mode}, success={self.success}, "
            f"x={short_vector(self.x)}, error={self.error:.3g}, nit={self.nit}, "
            f"trajectory={points}, message={short_text(self.message)})"
        )

    def columns(self) -> dict[str, Any]:
        """One row (a solve; :meth:`Trajectory.columns` has a row per point): the start
        ``x0_1``..``x0_p``, the target ``y_d_1``..``y_d_r``, the end ``x_1``..``x_p``, its task
        point ``y_1``..``y_r``, ``error``, ``success``, ``nit``, ``message``, ``status``."""
        out: dict[str, Any] = coordinate_columns("x0", np.atleast_2d(self.x0))
        out |= coordinate_columns("y_d", np.atleast_2d(self.y_d))
        out |= coordinate_columns("x", np.atleast_2d(self.x))
        out |= coordinate_columns("y", np.atleast_2d(self.y))
        out["error"] = np.array([self.error])
        out["success"] = np.array([self.success])
        out["nit"] = np.array([self.nit])
        out["message"] = np.array([self.message])
        out["status"] = np.array([self.status])
        return out

    def as_dict(self, trajectory: bool = False) -> dict[str, Any]:
        """JSON-friendly fields (:func:`~jik.engine.exports.json_values`: NaN as None); with
        ``trajectory``, also :meth:`Trajectory.as_dict`."""
        out = {key: getattr(self, key) for key in AS_DICT}
        if trajectory:
            out["trajectory"] = None if self.trajectory is None else self.trajectory.as_dict()
        return json_values(out)


@dataclass(frozen=True)
class BatchSolveResult(Columns):
    """Results of a batch of solves; index it for a :class:`SolveResult` with its trajectory
    (slice it for a batch of those members).

    ``x0`` (n, p) and ``y_d`` (n, r) are each member's start and target; the other fields are
    those of :class:`SolveResult`, one per member.
    """

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
    y_d: FloatArray = field(repr=False)  # (n, r)
    x0: FloatArray = field(repr=False)  # (n, p)
    # Each member's outcome (solve_rules.Status), named by its SolveResult's ``status``.
    _status: FloatArray = field(repr=False)
    # Recorded points: member index, theta, x of every accepted step, in order.
    _rec_member: FloatArray | None = field(repr=False, default=None)
    _rec_theta: FloatArray | None = field(repr=False, default=None)
    _rec_x: FloatArray | None = field(repr=False, default=None)

    def __len__(self) -> int:
        return len(self.x)

    @property
    def inverse(self) -> str:
        """The inverse as printed, as :attr:`SolveResult.inverse`."""
        return repr(self._inverse)

    def __repr__(self) -> str:
        return (
            f"BatchSolveResult({self.algorithm}, {self.mode}, {len(self)} solves, "
            f"{int(np.count_nonzero(self.success))} converged, "
            f"max error {float(np.max(self.error)) if len(self) else float('nan'):.3g})"
        )

    def columns(self) -> dict[str, Any]:
        """A row per member: the start ``x0_1``..``x0_p``, the target ``y_d_1``..``y_d_r``, the
        end ``x_1``..``x_p``, its task point ``y_1``..``y_r``, ``error``, ``success``, ``nit``,
        ``message``, ``status``."""
        out: dict[str, Any] = coordinate_columns("x0", self.x0) | coordinate_columns(
            "y_d", self.y_d
        )
        out |= coordinate_columns("x", self.x) | coordinate_columns("y", self.y)
        out["error"] = np.asarray(self.error)
        out["success"] = np.asarray(self.success, dtype=bool)
        out["nit"] = np.asarray(self.nit, dtype=int)
        out["message"] = np.array(self.message)
        out["status"] = np.array(self.status)
        return out

    def as_dict(self) -> dict[str, Any]:
        """JSON-friendly (:func:`~jik.engine.exports.json_values`: NaN as None): the settings
        and, per member, x0, y_d, x, y, error, success, nit, message, status."""
        out = {key: getattr(self, key) for key in AS_DICT}
        out |= {"success": np.asarray(self.success, dtype=bool), "nit": np.asarray(self.nit, int)}
        return json_values(out)

    @property
    def status(self) -> tuple[str, ...]:
        """Each member's :attr:`SolveResult.status`."""
        return tuple(Status.NAMES[int(c)] for c in self._status)

    def _member(self, i) -> int:
        """``i`` as a member's index from 0 (a negative one counts from the end)."""
        n = len(self.x)
        k = operator.index(i)
        if not -n <= k < n:
            raise IndexError(f"member {k} of a batch of {n} solves")
        return k % n

    def trajectory(self, i: int) -> Trajectory:
        """The trajectory of member ``i`` (requires ``record=True``)."""
        i = self._member(i)
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
        err = np.linalg.norm(ys - self.y_d[self._rec_member], axis=-1)
        bounds = np.searchsorted(self._rec_member, np.arange(len(self.x) + 1))  # sorted members
        return ys, None if h is None else np.asarray(h), err, bounds

    def _members(self, key: slice) -> BatchSolveResult:
        """The members ``key`` selects, as a batch numbered from 0 (their steps kept)."""
        idx = np.arange(len(self))[key]
        arrays = ("x", "y", "error", "success", "nit", "y_d", "x0", "_status")
        kept: dict[str, Any] = {k: getattr(self, k)[idx] for k in arrays}
        kept["message"] = tuple(self.message[i] for i in idx)
        if self._rec_member is not None and self._rec_theta is not None and self._rec_x is not None:
            new = np.full(len(self), len(idx))  # (a member left out: past the new ones)
            new[idx] = np.arange(len(idx))
            member = new[self._rec_member]
            order = np.argsort(member, kind="stable")
            order = order[member[order] < len(idx)]
            kept |= {"_rec_member": member[order], "_rec_theta": self._rec_theta[order]}
            kept["_rec_x"] = self._rec_x[order]
        return replace(self, **kept)

    @overload
    def __getitem__(self, i: int) -> SolveResult: ...
    @overload
    def __getitem__(self, i: slice) -> BatchSolveResult: ...
    def __getitem__(self, i):
        """Member ``i``'s :class:`SolveResult`; a slice gives the members it selects as a
        :class:`BatchSolveResult`."""
        if isinstance(i, slice):
            return self._members(i)
        i = self._member(i)
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
            x0=self.x0[i],
            y_d=self.y_d[i],
            _inverse=self._inverse,
            status=Status.NAMES[int(self._status[i])],
        )
