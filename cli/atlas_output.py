"""What ``jik atlas`` writes (:mod:`jik.cli.atlas`): the chunks gathered for the JSON, the CSV
(the engine's atlas table, streamed in run order) and the HTML figure of the drift map."""

from __future__ import annotations

import csv
import sys
from pathlib import Path
from typing import Any

from jik import install_hint

from ..engine.exports import json_values


class Gathered:
    """What the JSON and the figure need: everything for a small atlas; for a large one the
    last cycle's drift of every ``every``-th run, a summary and the failures."""

    def __init__(self, plan, keep: bool, every: int, legs: bool) -> None:
        import numpy as np

        A, P, N, C = len(plan.inverses), len(plan.paths), plan.n_starts, plan.cycles
        p = plan.inverses[0].kinematics.p
        self.plan, self.keep, self.every, self.done = plan, keep, every, 0
        self.failures: dict[tuple[int, int], str] = {}
        self.sampled = np.arange(0, P * N, every)
        self.last = np.full((A, len(self.sampled)), np.nan)
        self.count = np.zeros((A, C))
        self.total = np.zeros((A, C))
        self.worst = np.zeros((A, C))
        self.outside: Any = None  # (A,) runs that left the joint limits; None: no limits
        if keep:
            self.starts = np.empty((P, N, p))
            self.drift = np.empty((A, P, N, C))
            self.success = np.empty((A, P, N), dtype=bool)
        self.legs = np.empty((A, P, N, C * plan.legs, p)) if keep and legs else None

    def add(self, task, chunk) -> None:
        import numpy as np

        lo, hi = chunk.lo, chunk.hi
        self.done += hi - lo
        finite = np.isfinite(chunk.drift)
        self.count += finite.sum(axis=1)
        self.total += np.where(finite, chunk.drift, 0).sum(axis=1)
        self.worst = np.fmax(self.worst, np.nanmax(np.where(finite, chunk.drift, 0), axis=1))
        pick = (self.sampled >= lo) & (self.sampled < hi)
        self.last[:, pick] = chunk.drift[:, self.sampled[pick] - lo, -1]
        self.failures.update({(a, run): why for a, run, why in chunk.failures})
        if chunk.outside_limits is not None:
            self.outside = chunk.outside_limits.sum(axis=1) + (
                0 if self.outside is None else self.outside
            )
        if self.keep:
            for name, values in (
                ("drift", chunk.drift),
                ("success", chunk.success),
                ("legs", chunk.leg_ends),
            ):
                if getattr(self, name) is not None:
                    flat = getattr(self, name).reshape(len(values), -1, *values.shape[2:])
                    flat[:, lo:hi] = values
            self.starts.reshape(-1, self.starts.shape[-1])[lo:hi] = task.starts

    def summary(self) -> dict:
        import numpy as np

        with np.errstate(invalid="ignore", divide="ignore"):
            mean = self.total / self.count
        return {
            alg: {
                "converged_runs": int(self.count[a, 0]),
                "failed_runs": sum(1 for (b, _) in self.failures if b == a),
                "mean_drift": json_values(mean[a]),
                "max_drift": json_values(self.worst[a]),
                **({} if self.outside is None else {"outside_limits": int(self.outside[a])}),
            }
            for a, alg in enumerate(self.plan.algorithms)
        }


#: Rows of the CSV's table made at a time (the atlas result's csv_text makes its blocks alike).
ROWS = 8192


class CsvWriter:
    """The CSV: the atlas's long table (:func:`jik.engine.atlas_table.atlas_columns`, the
    columns of ``AtlasResult.columns(every_leg=legs)``, named there), a chunk's rows at a time in
    run order (chunks that finish early wait in a small buffer)."""

    def __init__(self, path: Path | None, plan, legs: bool) -> None:
        self.path, self.plan, self.next, self.legs = path, plan, 0, legs
        self.waiting: dict[int, tuple[Any, Any]] = {}

    def __enter__(self) -> CsvWriter:
        if self.path is not None:
            self.file = self.path.open("w", newline="", encoding="utf-8")
            self.writer = csv.writer(self.file)
        return self

    def __exit__(self, *exc: object) -> None:
        if self.path is not None:
            self.file.close()

    def add(self, task, chunk) -> None:
        if self.path is None:
            return
        self.waiting[chunk.lo] = (task, chunk)
        while self.next in self.waiting:
            task, chunk = self.waiting.pop(self.next)
            self._write(task, chunk)
            self.next = chunk.hi

    def _write(self, task, chunk) -> None:
        """The chunk's rows, a block of about ROWS rows (whole runs) at a time: a chunk's long
        table is several times its arrays, and only a block of it is held."""
        import numpy as np

        from ..engine.atlas_table import atlas_columns
        from ..engine.exports import csv_rows

        A, n, C = np.shape(chunk.drift)
        L = np.shape(chunk.leg_ends)[2] // C if self.legs else 1
        block = max(1, ROWS // (A * C * L))
        for lo in range(0, n, block):
            runs = slice(lo, lo + block)
            path, start = np.divmod(np.arange(chunk.lo, chunk.hi)[runs], self.plan.n_starts)
            table = atlas_columns(
                self.plan.algorithms,
                path,
                start,
                self.plan.parameter(start),
                task.starts[runs],
                chunk.drift[:, runs],
                chunk.success[:, runs],
                chunk.leg_ends[:, runs] if self.legs else None,
                self.legs,
                self.plan.family,
            )
            if chunk.lo == 0 and lo == 0:  # (the first rows: the header, the column names)
                self.writer.writerow(list(table))
            self.writer.writerows(csv_rows(table))


def atlas_figure(s, drift_last, algorithms, cycles: int, paths: int, n: int, label: str):
    """The drift map, a plotly Figure (None without plotly): drift after the last cycle against
    the start's arc length s (or run), a marker series per algorithm, log scale.
    ``drift_last`` is (A, runs) at the sampled runs' ``s``."""
    try:
        import plotly.graph_objects as go
    except ImportError:
        return None

    fig = go.Figure()
    for a, alg in enumerate(algorithms):
        fig.add_trace(
            go.Scattergl(x=s, y=drift_last[a], mode="markers", name=alg, marker={"size": 4})
        )
    fig.update_layout(
        title=f"Repeatability atlas: drift after cycle {cycles} ({paths} path(s), {n} starts each)",
        xaxis_title=label,
        yaxis_title=f"||x after cycle {cycles} - x0||",
        yaxis_type="log",
        template="plotly_white",
    )
    return fig


def write_figure(arrays: Gathered, plan, path: Path) -> Path | None:
    """Write the HTML figure; None (and a note) when plotly is not installed."""
    import numpy as np

    N = plan.n_starts
    s = plan.parameter(arrays.sampled % N)
    label = "arc length s on the self-motion curve"
    if s is None:
        s, label = arrays.sampled % N, "start"
    if len(plan.paths) > 1:
        s, label = arrays.sampled.astype(float), "run (path x starts + start)"
    fig = atlas_figure(
        np.asarray(s), arrays.last, plan.algorithms, plan.cycles, len(plan.paths), N, label
    )
    if fig is None:
        hint = install_hint("app")
        sys.stderr.write(f"jik atlas: plotly is not installed: no figure ({hint})\n")
        return None
    fig.write_html(path, include_plotlyjs=True, full_html=True)  # (offline: no CDN)
    return path
