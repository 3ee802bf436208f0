"""The result of driving a closed path cycle after cycle (eq. (7) leg by leg): the legs' ends,
each cycle's end and its drift from the start, the quantity repeatability is judged by.

It prints on one line and exports its numbers as :mod:`jik.engine.results`' results do.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .exports import Columns, coordinate_columns, json_values, short_text, short_vector
from .results import SolveResult
from .run_settings import RunSettings
from .validation import FloatArray


def _plural(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


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
                f"{_plural(cycles, 'cycle')} of {len(self.targets)} legs, "
                f"x0={short_vector(self.x0)}, drift after the last cycle {last}, "
                f"message={short_text(str(self.message))})"
            )
        ok = int(np.count_nonzero(self.success))
        worst = float(np.nanmax(self.drift[:, -1])) if np.any(self.success) else float("nan")
        return (
            f"RepeatabilityResult({how}, {len(self.x0)} starts, {ok} completed, "
            f"{_plural(cycles, 'cycle')} of {self.targets.shape[1]} legs, largest drift after "
            f"the last cycle {worst:.3g})"
        )

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
        leg: :func:`~jik.engine.exports.json_values`), success, message."""
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
            }
        )
