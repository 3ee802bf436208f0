"""An atlas's gathered result (:class:`AtlasResult`, what :func:`jik.engine.atlas_run.run_atlas`
returns) and the atlas as one long table: the columns of :meth:`AtlasResult.columns` and of
``jik atlas``'s CSV, which writes the same rows chunk by chunk as they come.

Rows are in run order, path by path and start by start (run = path * N + start, as the plan
numbers runs), then algorithm, then cycle (and, for every leg's end, leg): a block of runs gives
the rows of those runs alone, so a streamed atlas writes each chunk's rows and the whole file is
the gathered result's table. Column names are those of :mod:`jik.engine.exports`: ``x0_k`` a
start, ``x_k`` the configuration the row is about (the end of its cycle, or of its leg); a
family of paths adds each path's ``scale`` and ``shift_k``.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from .atlas_paths import Family
from .exceptions import InvalidInputError
from .exports import Columns, coordinate_columns, csv_text, dataframe, json_values, plural
from .validation import FloatArray, of_type


def atlas_columns(
    algorithms: tuple[str, ...],
    path: FloatArray,
    start: FloatArray,
    s: FloatArray | None,
    starts: FloatArray,
    drift: FloatArray,
    success: FloatArray,
    leg_ends: FloatArray | None = None,
    every_leg: bool = False,
    family: Family | None = None,
) -> dict[str, Any]:
    """The table of n runs of an atlas of A inverses, C cycles of L legs.

    Parameters
    ----------
    algorithms : tuple of str, length A
        The inverses' labels (:attr:`AtlasPlan.algorithms <jik.engine.atlas.AtlasPlan>`).
    path, start : ndarray of int, shape (n,)
        Each run's path and start (both from 0).
    s : ndarray, shape (n,), or None
        Each run's arc length on its path's self-motion curve (None: explicit starts, NaN).
    starts : ndarray, shape (n, p)
        Each run's start x0.
    drift : ndarray, shape (A, n, C)
        ||x after cycle c - x0|| (sec. 5.2.1), NaN after a failed leg.
    success : ndarray of bool, shape (A, n)
    leg_ends : ndarray, shape (A, n, C * L, p), or None
        Every leg's end; None leaves the ``x_k`` columns out.
    every_leg : bool
        A row per leg's end (with ``leg``, from 1 within its cycle, and the cycle's drift on each
        of its legs' rows) instead of a row per cycle (``x_k`` the cycle's end). Needs
        ``leg_ends``.
    family : Family or None
        Each path's scale (P,) and shift (P, r) in a family of paths (indexed by ``path``); None
        leaves the ``scale`` and ``shift_k`` columns out.

    Returns
    -------
    dict of str to ndarray
        ``algorithm``, ``path``, [``scale``, ``shift_1``..``shift_r``], ``start``, ``s``,
        ``cycle`` (from 1), [``leg``], ``drift``,
        ``success`` (the run's), ``x0_1``..``x0_p`` and, with ``leg_ends``, ``x_1``..``x_p``.
    """
    A, n, C = np.shape(drift)
    if every_leg and leg_ends is None:
        raise InvalidInputError(
            "a row per leg needs the leg ends (keep_leg_ends=True)", "every_leg"
        )
    L = 1 if leg_ends is None else np.shape(leg_ends)[2] // C
    per_cycle = L if every_leg else 1
    run, a, k = (g.ravel() for g in np.indices((n, A, C * per_cycle)))
    cycle = k // per_cycle
    s = np.full(n, np.nan) if s is None else np.asarray(s, dtype=float)
    out: dict[str, Any] = {
        "algorithm": np.asarray(algorithms)[a],
        "path": np.asarray(path)[run],
    }
    if family is not None:
        on = np.asarray(path)[run]
        out["scale"] = np.asarray(family.scale, dtype=float)[on]
        out |= coordinate_columns("shift", np.asarray(family.shift, dtype=float)[on])
    out |= {"start": np.asarray(start)[run], "s": s[run], "cycle": cycle + 1}
    if every_leg:
        out["leg"] = k % per_cycle + 1
    out["drift"] = np.asarray(drift)[a, run, cycle]
    out["success"] = np.asarray(success, dtype=bool)[a, run]
    out |= coordinate_columns("x0", np.asarray(starts)[run])
    if leg_ends is not None:
        leg = k if every_leg else (cycle + 1) * L - 1
        out |= coordinate_columns("x", np.asarray(leg_ends)[a, run, leg])
    return out


@dataclass(frozen=True)
class AtlasResult(Columns):
    """An atlas: for every inverse a, path j and start i, the drift after each cycle.

    Attributes
    ----------
    algorithms : tuple of str, length A
        A distinct label per inverse: its name, with the parameters that tell it apart from
        another of the same name (``damped(damping=0.01)``; :func:`jik.engine.inverses.
        algorithm_labels`).
    paths : ndarray, shape (P, L0, r)
    parameter : ndarray, shape (N,) or None
        Arc length s of each start on its path's self-motion curve (None: explicit starts).
    starts : ndarray, shape (P, N, p)
    drift : ndarray, shape (A, P, N, cycles)
    leg_ends : ndarray, shape (A, P, N, cycles * L, p), or None when not kept
    success : ndarray of bool, shape (A, P, N)
    failures : dict
        (a, j, i) -> why that run failed.
    outside_limits : ndarray of bool, shape (A, P, N), or None
        The runs whose start or some leg end left the joint limits (None: the robot has none).
    family : Family or None
        Each path's scale (P,) and shift (P, r) in a family of shifts and scales (None: the
        base path as given).
    """

    algorithms: tuple[str, ...]
    paths: FloatArray
    parameter: FloatArray | None
    starts: FloatArray
    drift: FloatArray
    leg_ends: FloatArray | None
    success: FloatArray
    failures: dict[tuple[int, int, int], str]
    outside_limits: FloatArray | None = None
    family: Family | None = None

    def __repr__(self) -> str:
        _, P, N, cycles = self.drift.shape
        last = self.drift[..., -1]
        worst = np.max(np.where(np.isfinite(last), last, -np.inf), axis=(1, 2))
        drifts = ", ".join(
            f"{a} {w:.3g}" for a, w in zip(self.algorithms, worst, strict=True) if np.isfinite(w)
        )
        drifts = f", largest drift after the last cycle: {drifts}" if drifts else ""
        return (
            f"AtlasResult({'/'.join(self.algorithms)}, {plural(P, 'path')} x "
            f"{plural(N, 'start')} x {plural(cycles, 'cycle')}, "
            f"{int(np.count_nonzero(self.success))} of {self.success.size} runs completed"
            f"{drifts})"
        )

    def columns(self, every_leg: bool = False, runs: slice | None = None) -> dict[str, FloatArray]:
        """A row per path, start, algorithm and cycle (long format, run order:
        :func:`jik.engine.atlas_table.atlas_columns`, the table ``jik atlas`` streams to its
        CSV): ``algorithm`` (its label), ``path`` (from 0; of a family, its ``scale`` and
        ``shift_1``..``shift_r`` too), ``start`` (from 0), ``s`` (arc length, NaN
        for given starts), ``cycle`` (from 1), ``drift``, ``success`` (the run's), the start
        ``x0_1``..``x0_p`` and, when the leg ends were kept, the configuration at the cycle's end
        ``x_1``..``x_p``. ``every_leg``: a row per leg instead, with ``leg`` (from 1 within its
        cycle) and ``x_k`` the leg's end. ``runs``: the rows of those runs alone (run = path *
        N + start), a block of the table."""
        A, P, N, C = self.drift.shape
        runs = slice(None) if runs is None else of_type(runs, slice, "runs", "a slice of runs")
        path, start = np.divmod(np.arange(P * N)[runs], N)
        legs = self.leg_ends
        return atlas_columns(
            self.algorithms,
            path,
            start,
            None if self.parameter is None else np.asarray(self.parameter)[start],
            self.starts.reshape(P * N, -1)[runs],
            self.drift.reshape(A, P * N, C)[:, runs],
            self.success.reshape(A, P * N)[:, runs],
            None if legs is None else legs.reshape(A, P * N, *legs.shape[3:])[:, runs],
            every_leg,
            self.family,
        )

    def csv_text(self, every_leg: bool = False, rows: int = 8192) -> Iterator[str]:
        """:meth:`columns` as CSV text (:func:`jik.engine.exports.csv_text`: the header, then
        the rows), made a block of about ``rows`` rows (whole runs) at a time: the memory a
        download takes is a block's, never the whole table's text.

        Raises
        ------
        InvalidInputError
            At the call, with field ``every_leg``, when a row per leg is asked for and the leg
            ends were not kept.
        """
        A, P, N, C = self.drift.shape
        if every_leg and self.leg_ends is None:
            raise InvalidInputError(
                "a row per leg needs the leg ends, and this atlas did not keep them",
                "every_leg",
            )
        legs = self.leg_ends.shape[3] // C if every_leg and self.leg_ends is not None else 1
        block = max(1, rows // (A * C * legs))
        return csv_text(
            self.columns(every_leg, slice(lo, lo + block)) for lo in range(0, P * N, block)
        )

    def to_dataframe(self, every_leg: bool = False):
        """:meth:`columns` as a pandas DataFrame (needs pandas: the ``dataframes`` extra)."""
        return dataframe(self.columns(every_leg))

    def as_dict(self, leg_ends: bool = False) -> dict:
        """JSON-friendly: the labels, paths, arc lengths, starts, drift, success, the failures
        (a list of ``{"algorithm", "path", "start", "message"}``), outside_limits and, with
        ``leg_ends``, every leg's end (A P N cycles L p numbers); None for NaN (a failed leg's
        drift: :func:`~jik.engine.exports.json_values`)."""
        return json_values(
            {
                "algorithms": list(self.algorithms),
                "paths": self.paths.tolist(),
                "parameter": None if self.parameter is None else self.parameter.tolist(),
                "starts": self.starts.tolist(),
                "drift": self.drift.tolist(),
                "success": self.success.tolist(),
                "failures": [
                    {"algorithm": self.algorithms[a], "path": j, "start": i, "message": why}
                    for (a, j, i), why in sorted(self.failures.items())
                ],
                "outside_limits": None
                if self.outside_limits is None
                else self.outside_limits.tolist(),
                **(
                    {"leg_ends": None if self.leg_ends is None else self.leg_ends.tolist()}
                    if leg_ends
                    else {}
                ),
            }
        )
