"""Benchmarks run by ``jik bench``: every ``benchmarks/bench_NAME.py`` with a ``main()``.

Each benchmark times jik against a straightforward implementation in the same run and prints
medians and the ratio; results are recorded in docs/benchmarks.md. Those that drive a server
with the test tools (schemathesis, Playwright) live in ``benchmarks/harness/``, which a source
checkout has and the wheel leaves out.
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path

HERE = Path(__file__).parent
#: What a user of the wheel is told when asking for a benchmark of the source checkout.
CHECKOUT_HINT = (
    "the fuzzing and the browser's measurements run from a source checkout, with the test "
    "extra: pip install -e '.[test]'"
)


def _modules() -> dict[str, str]:
    """Benchmark name -> its module (``bench_NAME.py`` here and in harness/)."""
    return {
        path.stem.removeprefix("bench_"): f"jik.benchmarks.{prefix}{path.stem}"
        for prefix, folder in (("", HERE), ("harness.", HERE / "harness"))
        for path in sorted(folder.glob("bench_*.py"))
    }


def available() -> list[str]:
    """Names of the benchmarks."""
    return sorted(_modules())


def has_harness() -> bool:
    """Whether the harnesses of the source checkout are here (not in an installed wheel)."""
    return (HERE / "harness" / "__init__.py").is_file()


def run_benchmarks(names: list[str] | None = None, quick: bool = False) -> int:
    """Run the named benchmarks (all when empty); returns a process exit code."""
    modules = _modules()
    names = names or available()
    unknown = sorted(set(names) - set(modules))
    if unknown:
        hint = "" if has_harness() else f" ({CHECKOUT_HINT})"
        print(f"unknown benchmark(s) {unknown}; available: {available()}{hint}")
        return 2
    for name in names:
        module = importlib.import_module(modules[name])
        print(f"== {name} ==", flush=True)
        if "quick" in inspect.signature(module.main).parameters:
            module.main(quick=quick)
        else:
            module.main()
    return 0
