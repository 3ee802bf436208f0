"""Shared test utilities: central finite differences, Picard sweep counts."""

from __future__ import annotations

import numpy as np


def central_difference(f, x: np.ndarray, eps: float = 1e-6) -> np.ndarray:
    """d f / d x by central differences; x (..., p), f(x) (..., *out) -> (..., *out, p)."""
    cols = []
    for i in range(x.shape[-1]):
        d = np.zeros(x.shape[-1])
        d[i] = eps
        cols.append((np.asarray(f(x + d)) - np.asarray(f(x - d))) / (2 * eps))
    return np.stack(cols, axis=-1)


def count_picard_sweeps(monkeypatch) -> list[int]:
    """Record the sweeps of the first member of every Picard call the solver makes from now on
    (``engine.solver.picard_path`` wrapped for the test)."""
    from jik.engine import solver as engine_solver

    sweeps: list[int] = []
    picard = engine_solver.picard_path

    def counted(*args, **kwargs):
        out = picard(*args, **kwargs)
        sweeps.append(int(out[3][0]))
        return out

    monkeypatch.setattr(engine_solver, "picard_path", counted)
    return sweeps
