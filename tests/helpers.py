"""Shared test utilities: central finite differences, Picard sweep counts, approximate JSON,
coroutines run to the end."""

from __future__ import annotations

import asyncio
import concurrent.futures

import numpy as np
import pytest


def central_difference(f, x: np.ndarray, eps: float = 1e-6) -> np.ndarray:
    """d f / d x by central differences; x (..., p), f(x) (..., *out) -> (..., *out, p)."""
    cols = []
    for i in range(x.shape[-1]):
        d = np.zeros(x.shape[-1])
        d[i] = eps
        cols.append((np.asarray(f(x + d)) - np.asarray(f(x - d))) / (2 * eps))
    return np.stack(cols, axis=-1)


def run_async(coro, new_loop=asyncio.new_event_loop):
    """``asyncio.run(coro)`` on a loop made by ``new_loop``, in a thread of its own: in a worker
    that ran the browser tests, Playwright's loop is running in the main thread, where
    ``asyncio.run`` refuses to start another."""

    def run():
        with asyncio.Runner(loop_factory=new_loop) as runner:
            return runner.run(coro)

    with concurrent.futures.ThreadPoolExecutor(1) as thread:
        return thread.submit(run).result()


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


def approx_tree(expected, **tolerance):
    """``pytest.approx`` through a JSON-like tree: every number of ``expected`` (dicts and lists
    nested to any depth) compared within ``tolerance``, everything else exactly. pytest's own
    approx compares one level and refuses a dict whose values are lists."""
    if isinstance(expected, dict):
        return {k: approx_tree(v, **tolerance) for k, v in expected.items()}
    if isinstance(expected, list | tuple):
        return [approx_tree(v, **tolerance) for v in expected]
    if isinstance(expected, int | float) and not isinstance(expected, bool):
        return pytest.approx(expected, **tolerance)
    return expected
