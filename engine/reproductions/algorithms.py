"""Drift of the five algorithms on Table 1's loop of Manipulator 2 (docs/algorithms.md).

Each algorithm, with the catalogue's default parameters, drives Manipulator 2 around Table 1's
closed path (1,1), (1,2), (0,2), (0,1) from x0 = (0, 0, pi/2) for 100 cycles in continuous mode
(eq. (7)); the table gives ||x - x0|| after 1, 10 and 100 cycles and the last cycle's own drift
||x_100 - x_99||. Regenerate with ``jik reproduce algorithms``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from jik.engine.kinematics import Manipulator2
from jik.engine.registry import ALGORITHMS, make_inverse
from jik.engine.repeatability import repeatability

X0 = (0.0, 0.0, math.pi / 2)
PATH = ((1.0, 1.0), (1.0, 2.0), (0.0, 2.0), (0.0, 1.0))
CYCLES = 100
REPORTED = (1, 10, 100)


def _parameters(name: str) -> dict:
    out: dict = {p.name: p.default for p in ALGORITHMS[name].parameters}
    if name == "extended":
        out["augmentation"] = "paper_cubic (38)"
    if name == "weighted":
        out["limits"] = "x_range of the catalogue: [-3, 3], [-3, 3], [-pi, 2 pi]"
    if name == "posture":
        out["rest"] = "x0"
    return out


def run(progress: Callable[[float], None] | None = None, cycles: int = CYCLES) -> dict:
    """{"algorithms": [{"name", "parameters", "drift" (after REPORTED cycles), "last_cycle",
    "success", "message"}], "cycles", "x0", "path"}."""
    kin = Manipulator2()
    rows = []
    names = list(ALGORITHMS)
    for i, name in enumerate(names):
        rep = repeatability(make_inverse(kin, name), X0, PATH, cycles=cycles)
        drift = np.asarray(rep.drift)
        ends = np.asarray(rep.cycle_end)
        last = float(np.linalg.norm(ends[-1] - ends[-2])) if cycles > 1 else float(drift[0])
        rows.append(
            {
                "name": name,
                "parameters": _parameters(name),
                "drift": {str(c): float(drift[c - 1]) for c in REPORTED if c <= cycles},
                "last_cycle": last,
                "success": bool(rep.success),
                "message": str(rep.message),
            }
        )
        if progress is not None:
            progress((i + 1) / len(names))
    return {"algorithms": rows, "cycles": cycles, "x0": list(X0), "path": [list(p) for p in PATH]}


def format_text(result: dict) -> str:
    """A Markdown table: one row per algorithm."""
    shown = [c for c in REPORTED if c <= result["cycles"]]
    head = " | ".join(f"after {c}" for c in shown)
    n = result["cycles"]
    out = [
        f"Drift ||x - x0|| on Table 1's loop of Manipulator 2 (continuous, {n} cycles)",
        "",
        f"| algorithm | parameters | {head} | cycle {n} alone |",
        "|---|---|" + "---|" * len(shown) + "---|",
    ]
    for row in result["algorithms"]:
        params = ", ".join(f"{k} = {v}" for k, v in row["parameters"].items()) or "-"
        cells = " | ".join(f"{row['drift'][str(c)]:.3e}" for c in shown)
        flag = "" if row["success"] else f" (failed: {row['message']})"
        out.append(f"| {row['name']}{flag} | {params} | {cells} | {row['last_cycle']:.3e} |")
    return "\n".join(out)
