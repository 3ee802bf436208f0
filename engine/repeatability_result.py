"""The result of driving a closed path cycle after cycle (eq. (7) leg by leg): the legs' ends,
each cycle's end and its drift from the start, the quantity repeatability is judged by.

It prints on one line, exports its numbers as :mod:`jik.engine.results`' results do, and says
what it found, and why, in sentences (:meth:`RepeatabilityResult.findings`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .exceptions import InvalidInputError
from .exports import Columns, coordinate_columns, json_values, plural, short_text, short_vector
from .results import SolveResult
from .run_settings import RunSettings
from .validation import FloatArray, count

if TYPE_CHECKING:
    from .findings import Finding
    from .inverses import Inverse


@dataclass(frozen=True)
class RepeatabilityResult(Columns):
    """Configurations along a closed path driven ``cycles`` times.

    Attributes
    ----------
    x0 : ndarray, shape (p,) or (n, p)
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
    settings : RunSettings
        The inverse (``settings.algorithm``, ``settings.inverse``), mode, gamma, tol and
        max_iterations of every leg; also ``algorithm``, ``inverse``, ``mode`` and ``gamma``.
    h : ndarray, shape (1 + cycles * L,) or (n, 1 + cycles * L), or None
        The augmenting map h (9) at x0 and after each leg (a column per map when p - r > 1;
        NaN after a failed leg); None for an inverse without h.
    used : Inverse or None
        The inverse J# the legs ran with (whose parameters :meth:`findings` reads).
    stopped : ndarray, shape (p,) or (n, p), or None
        Where a failed leg stopped (its ``legs`` entry is NaN: it reached no leg end); NaN for
        a run that completed.
    """

    x0: FloatArray
    targets: FloatArray
    legs: FloatArray
    cycle_end: FloatArray
    drift: FloatArray
    success: bool | FloatArray
    message: str | tuple[str, ...]
    leg_results: list[SolveResult]
    settings: RunSettings
    h: FloatArray | None = None
    used: Inverse | None = None
    stopped: FloatArray | None = None

    @classmethod
    def of_run(
        cls, inverse: Inverse, x0, targets, legs, alive, messages, leg_results, settings, stopped
    ):
        """The result of :func:`jik.engine.repeatability.repeatability` from its batch arrays:
        ``x0`` (n, p), ``targets`` (n, L, r), ``legs`` (n, cycles * L, p), ``alive`` (n,),
        ``messages`` and ``stopped`` (n, p); one start's (shapes without n) when
        ``leg_results`` or n is 1 and ``targets`` of ``settings`` is (L, r)."""
        cycle_end = legs[:, targets.shape[1] - 1 :: targets.shape[1]]
        drift = np.linalg.norm(cycle_end - x0[:, None, :], axis=-1)  # (n, cycles)
        points = np.concatenate([x0[:, None, :], legs], axis=1)
        known = np.all(np.isfinite(points), axis=-1)
        h = inverse.augmenting_value(points[known])
        if h is not None:
            h = np.asarray(h, dtype=float)
            full = np.full(points.shape[:2] + h.shape[1:], np.nan)
            full[known], h = h, full
        if np.ndim(settings.targets) == 2:
            one = None if h is None else h[0]
            ends = (cycle_end[0], drift[0], bool(alive[0]), messages[0])
            return cls(
                x0[0], targets[0], legs[0], *ends, leg_results, settings, one, inverse, stopped[0]
            )
        ends = (cycle_end, drift, alive, tuple(messages))
        return cls(x0, targets, legs, *ends, [], settings, h, inverse, stopped)

    @property
    def algorithm(self) -> str:
        return self.settings.algorithm

    @property
    def inverse(self) -> str:
        return self.settings.inverse

    @property
    def mode(self) -> str:
        return self.settings.mode

    @property
    def gamma(self) -> float:
        return self.settings.gamma

    def __repr__(self) -> str:
        cycles = self.drift.shape[-1]
        how = f"{self.algorithm}, {self.mode}, gamma={self.gamma:g}"
        if np.ndim(self.success) == 0:
            last = f"{self.drift[-1]:.3g}" if cycles else "none"
            return (
                f"RepeatabilityResult({how}, success={self.success}, "
                f"{plural(cycles, 'cycle')} of {plural(len(self.targets), 'leg')}, "
                f"x0={short_vector(self.x0)}, drift after the last cycle {last}, "
                f"message={short_text(str(self.message))})"
            )
        ok = int(np.count_nonzero(self.success))
        worst = float(np.nanmax(self.drift[:, -1])) if np.any(self.success) else float("nan")
        return (
            f"RepeatabilityResult({how}, {len(self.x0)} starts, {ok} completed, "
            f"{plural(cycles, 'cycle')} of {plural(self.targets.shape[1], 'leg')}, largest "
            f"drift after the last cycle {worst:.3g})"
        )

    def findings(self, unit: str = "", start: int | None = None) -> list[Finding]:
        """What the run found and why, in sentences (the dashboard's verdict): whether the joints
        came back to x0 after every cycle (sec. 5.2.1, Table 1; ‖x − x0‖ below
        :data:`~jik.engine.repeatability.REPEATABLE_DRIFT`), where a failed leg stopped; for
        the pseudoinverse (8) why it drifts, for the extended Jacobian inverse (11) whether h
        stayed at h(x0) (eq. (12), from h at every point of legs recorded with ``record=True``,
        else from h after each leg, as its sentence says) and, in discrete mode, that the
        iteration keeps h only approximately and what a gamma near 2 does; for the practical
        inverses what their parameters did
        (:func:`jik.engine.practical_findings.practical_findings`:
        the posture inverse's drift, damped least squares' task error at the legs' ends, the
        weighted inverse's joints against its limits, at every recorded point, else at the legs'
        ends).

        Parameters
        ----------
        unit : str
            The drift's unit in the sentences, e.g. "[rad]" (a robot's:
            ``norm_unit(robot.units.x)``, :func:`jik.engine.units.norm_unit`); "" unstated.
        start : int, optional
            A batch's member (from 0); required for a batch.

        Returns
        -------
        list of Finding
            ``(text, role, algorithm)`` (:class:`jik.engine.findings.Finding`), ``role`` one of
            "finding", "why", "note" or "failure".

        Examples
        --------
        >>> import numpy as np, jik.engine as jik
        >>> arm, path = jik.Manipulator2(), [(1, 1), (1, 2), (0, 2)]
        >>> run = jik.repeatability(jik.Pseudoinverse(arm), [0, 0, np.pi / 2], path, 2)
        >>> for finding in run.findings("[m and rad mixed]"):
        ...     print(finding.role, "|", finding.text[:60])
        finding | pseudoinverse J^P#: not repeatable. After 2 cycles the joint
        why | Why: J^P# picks the minimum-norm joint velocity, which has n
        """
        from .findings import Finding, verdict
        from .pose_task import cut_notes
        from .practical_findings import practical_findings

        i: Any = ()
        if np.ndim(self.success) == 0 and start is not None:
            raise InvalidInputError("start: one start's result takes no start", "start")
        if np.ndim(self.success):
            if start is None:
                raise InvalidInputError(
                    f"start: a batch of {len(self.x0)} starts needs start", "start"
                )
            i = count(start, "start", 0, len(self.x0) - 1)
        drift = self.drift[i]
        done = drift[: np.cumprod(np.isfinite(drift)).sum()]  # (the cycles that ended)
        h = None if self.h is None else self.h[i]
        legs = [leg.trajectory for leg in self.leg_results if leg.trajectory is not None]
        ends = h is not None  # (h at the start and the legs' ends, unless recorded)
        if legs and len(legs) == len(self.leg_results):  # (every recorded point, as the page)
            x, error = np.concatenate([t.x for t in legs]), np.concatenate([t.error for t in legs])
            leg = np.concatenate([np.full(len(t.x), j) for j, t in enumerate(legs)])
            if h is not None and all(t.h is not None for t in legs):
                h, ends = np.concatenate([t.h for t in legs]), False
        else:  # (the leg ends reached)
            reached = self.legs[i][np.isfinite(self.legs[i]).all(axis=-1)]
            x, leg = np.vstack([self.x0[i], reached]), np.arange(len(reached))
            error = self._errors(reached, self.targets[i])
        success, message = bool(np.asarray(self.success)[i]), str(np.asarray(self.message)[i])
        run = _Member(done, success, message, h, x, error, leg, ends)
        out = verdict({self.algorithm: run}, True, self.mode, self.gamma, unit)
        if self.used is None:
            return out
        targets = self.targets if self.targets.ndim == 2 else self.targets[i]
        out += [Finding(t, "note") for t in cut_notes(self.used.kinematics, self.x0[i], targets)]
        per_cycle = self.targets.shape[-2]  # (the legs of a cycle)
        found = practical_findings(self.used, run, unit, self.settings.tol, legs=per_cycle)
        return out + [Finding(text, role, self.algorithm) for text, role in found]

    def _errors(self, ends: FloatArray, targets: FloatArray) -> FloatArray:
        """||k(x) - target|| at the leg ends reached, ``ends`` (m, p), for the legs' targets
        ``targets`` (L, r) cycle after cycle; empty without the inverse's robot."""
        if self.used is None or not len(ends):
            return np.zeros(len(ends))
        goals = np.resize(targets, (len(ends), targets.shape[-1]))
        return np.linalg.norm(self.used.kinematics.forward(ends) - goals, axis=-1)

    def columns(self) -> dict[str, Any]:
        """A row per cycle (and start): ``start`` (a batch's member, from 0), ``cycle`` (from
        1), ``drift``, the start ``x0_1``..``x0_p`` and the configuration at the cycle's end
        ``x_1``..``x_p``."""
        drift = np.atleast_2d(self.drift)  # (n, cycles)
        ends = self.cycle_end.reshape(-1, self.cycle_end.shape[-1])
        n, cycles = drift.shape
        out: dict[str, Any] = (
            {} if np.ndim(self.success) == 0 else {"start": np.repeat(np.arange(n), cycles)}
        )
        out["cycle"] = np.tile(np.arange(1, cycles + 1), n)
        out["drift"] = drift.ravel()
        starts = np.repeat(np.atleast_2d(self.x0), cycles, axis=0)
        return out | coordinate_columns("x0", starts) | coordinate_columns("x", ends)

    def as_dict(self) -> dict[str, Any]:
        """JSON-friendly: the algorithm, the inverse as printed, mode, gamma, tol,
        max_iterations, x0, the legs' targets, leg ends, cycle ends, drift (None after a failed
        leg: :func:`~jik.engine.exports.json_values`), success, message, where a failed leg
        stopped (``stopped_at``, None for a run that completed) and h at x0 and after each leg
        (``h``, eq. (12)'s evidence: None for an inverse without a map)."""
        s = self.settings
        return json_values(
            {
                "algorithm": s.algorithm,
                "inverse": s.inverse,
                "mode": s.mode,
                "gamma": s.gamma,
                "tol": s.tol,
                "max_iterations": s.max_iterations,
                "x0": self.x0.tolist(),
                "targets": self.targets.tolist(),
                "legs": self.legs.tolist(),
                "cycle_end": self.cycle_end.tolist(),
                "drift": self.drift.tolist(),
                "success": np.asarray(self.success).tolist(),
                "message": self.message if isinstance(self.message, str) else list(self.message),
                "stopped_at": None if self.stopped is None else self.stopped.tolist(),
                "h": None if self.h is None else self.h.tolist(),
            }
        )


@dataclass(frozen=True)
class _Member:
    """One start's run as :func:`jik.engine.findings.verdict` and
    :func:`~jik.engine.practical_findings.practical_findings` read it: the drift of the cycles that
    ended, h, and the configurations, task errors and legs of its recorded points (else its
    leg ends)."""

    drift: FloatArray
    success: bool
    message: str
    h: FloatArray | None
    x: FloatArray
    error: FloatArray
    leg: FloatArray
    #: h is h at the start and the legs' ends only (the legs were not recorded).
    h_at_ends: bool = False
