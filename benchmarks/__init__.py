"""Benchmarks run by ``jik bench``: every ``benchmarks/bench_NAME.py`` with a ``main()``.

Each benchmark times jik against a straightforward implementation in the same run and prints
medians and the ratio; results are recorded in docs/benchmarks.md.
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path


def available() -> list[str]:
    """Names of the benchmarks (``bench_NAME.py`` files beside this one)."""
    return sorted(p.stem.removeprefix("bench_") for p in Path(__file__).parent.glob("bench_*.py"))


def run_benchmarks(names: list[str] | None = None, quick: bool = False) -> int:
    """Run the named benchmarks (all when empty); returns a process exit code."""
    names = names or available()
    unknown = sorted(set(names) - set(available()))
    if unknown:
        print(f"unknown benchmark(s) {unknown}; available: {available()}")
        return 2
    for name in names:
        module = importlib.import_module(f"jik.benchmarks.bench_{name}")
        print(f"== {name} ==", flush=True)
        if "quick" in inspect.signature(module.main).parameters:
            module.main(quick=quick)
        else:
            module.main()
    return 0
