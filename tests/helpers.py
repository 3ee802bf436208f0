"""Shared test utilities: central finite differences."""

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
