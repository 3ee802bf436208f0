"""An atlas as one long table (:mod:`jik.engine.atlas_run`): the columns of
:meth:`AtlasResult.columns <jik.engine.atlas_run.AtlasResult.columns>` and of ``jik atlas``'s
CSV, which writes the same rows chunk by chunk as they come.

Rows are in run order, path by path and start by start (run = path * N + start, as the plan
numbers runs), then algorithm, then cycle (and, for every leg's end, leg): a block of runs gives
the rows of those runs alone, so a streamed atlas writes each chunk's rows and the whole file is
the gathered result's table. Column names are those of :mod:`jik.engine.exports`: ``x0_k`` a
start, ``x_k`` the configuration the row is about (the end of its cycle, or of its leg).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .exceptions import InvalidInputError
from .exports import coordinate_columns
from .validation import FloatArray


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

    Returns
    -------
    dict of str to ndarray
        ``algorithm``, ``path``, ``start``, ``s``, ``cycle`` (from 1), [``leg``], ``drift``,
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
        "start": np.asarray(start)[run],
        "s": s[run],
        "cycle": cycle + 1,
    }
    if every_leg:
        out["leg"] = k % per_cycle + 1
    out["drift"] = np.asarray(drift)[a, run, cycle]
    out["success"] = np.asarray(success, dtype=bool)[a, run]
    out |= coordinate_columns("x0", np.asarray(starts)[run])
    if leg_ends is not None:
        leg = k if every_leg else (cycle + 1) * L - 1
        out |= coordinate_columns("x", np.asarray(leg_ends)[a, run, leg])
    return out
