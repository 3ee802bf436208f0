"""Drift of the five algorithms on Table 1's loop of Manipulator 2 and on the Panda's pose loop
(docs/algorithms.md).

Each algorithm, with the catalogue's default parameters, drives Manipulator 2 around Table 1's
closed path (1,1), (1,2), (0,2), (0,1) from x0 = (0, 0, pi/2), and the Panda (``{"name":
"panda", "task": "pose"}``, p = 7, r = 6: position and rotation coordinates) around its default
closed pose loop from its home, for 100 cycles in continuous mode (eq. (7)); the tables give
||x - x0|| after 1, 10 and 100 cycles and the last cycle's own drift ||x_100 - x_99||. The
Panda's extended inverse uses its synthesized E2-optimal map (:mod:`jik.engine.robot_synthesis`),
its weighted inverse its joint limits, its posture inverse its home as rest. Regenerate with
``jik reproduce algorithms``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial

import numpy as np

from ..kinematics import Manipulator2
from ..registry import ALGORITHMS, make_inverse
from ..repeatability import repeatability

X0 = (0.0, 0.0, math.pi / 2)
PATH = ((1.0, 1.0), (1.0, 2.0), (0.0, 2.0), (0.0, 1.0))
CYCLES = 100
REPORTED = (1, 10, 100)
#: The loops of the tables: Table 1's, and the Panda's pose loop.
LOOPS = ("manipulator2", "panda")
PANDA = {"name": "panda", "task": "pose"}


#: What the tables print for the parameters the catalogue leaves to the robot, per loop.
SHOWN = {
    "manipulator2": {
        "extended": {"augmentation": "paper_cubic (38)"},
        "weighted": {"limits": "x_range of the catalogue: [-3, 3], [-3, 3], [-pi, 2 pi]"},
        "posture": {"rest": "x0"},
    },
    "panda": {
        "extended": {"augmentation": "e2_synthesized (19)"},
        "weighted": {"limits": "the Panda's joint limits"},
        "posture": {"rest": "home"},
    },
}


def _parameters(name: str, loop: str = "manipulator2") -> dict:
    out: dict = {p.name: p.default for p in ALGORITHMS[name].parameters}
    return {**out, **SHOWN[loop].get(name, {})}


def _rows(inverse, x0, path, cycles: int, loop: str, progress) -> list[dict]:
    """One row per algorithm: ``inverse(name)`` driven ``cycles`` times around ``path``."""
    rows = []
    names = list(ALGORITHMS)
    for i, name in enumerate(names):
        rep = repeatability(inverse(name), x0, path, cycles=cycles)
        drift = np.asarray(rep.drift)
        ends = np.asarray(rep.cycle_end)
        last = float(np.linalg.norm(ends[-1] - ends[-2])) if cycles > 1 else float(drift[0])
        rows.append(
            {
                "name": name,
                "parameters": _parameters(name, loop),
                "drift": {str(c): float(drift[c - 1]) for c in REPORTED if c <= cycles},
                "last_cycle": last,
                "success": bool(rep.success),
                "message": str(rep.message),
            }
        )
        if progress is not None:
            progress(i + 1, len(names))
    return rows


def run(
    progress: Callable[[float], None] | None = None,
    cycles: int = CYCLES,
    loops: tuple[str, ...] = LOOPS,
) -> dict:
    """{"algorithms": [{"name", "parameters", "drift" (after REPORTED cycles), "last_cycle",
    "success", "message"}] on Table 1's loop, "cycles", "x0", "path", and with "panda" in
    ``loops`` "panda": the same on the Panda's pose loop, with its "x0" and "path"}."""
    out: dict = {"cycles": cycles, "x0": list(X0), "path": [list(p) for p in PATH]}
    unknown = sorted(set(loops) - set(LOOPS))
    if unknown:
        raise ValueError(f"unknown loop {unknown[0]!r}; known: {LOOPS}")
    if "panda" in loops:  # (built first: without the urdf extra, refused before any run)
        from ..robot_spec import robot_from_dict

        panda = robot_from_dict(PANDA)
    for k, loop in enumerate(loops):
        step = None if progress is None else _part(progress, k, len(loops))
        if loop == "manipulator2":
            kin = Manipulator2()
            out["algorithms"] = _rows(partial(make_inverse, kin), X0, PATH, cycles, loop, step)
        else:
            x0, path = panda.spec.default_x0, panda.spec.default_path
            rows = _rows(panda.inverse, x0, path, cycles, loop, step)
            out["panda"] = {"algorithms": rows, "x0": list(x0), "path": [list(p) for p in path]}
    return out


def _part(progress: Callable[[float], None], k: int, n: int) -> Callable[[int, int], None]:
    """Progress of loop ``k`` of ``n``: its i of m algorithms done as a fraction of all."""
    return lambda i, m: progress((k + i / m) / n)


def _table(title: str, rows: list[dict], cycles: int) -> list[str]:
    shown = [c for c in REPORTED if c <= cycles]
    head = " | ".join(f"after {c}" for c in shown)
    out = [
        title,
        "",
        f"| algorithm | parameters | {head} | cycle {cycles} alone |",
        "|---|---|" + "---|" * len(shown) + "---|",
    ]
    for row in rows:
        params = ", ".join(f"{k} = {v}" for k, v in row["parameters"].items()) or "-"
        cells = " | ".join(f"{row['drift'][str(c)]:.3e}" for c in shown)
        flag = "" if row["success"] else f" (failed: {row['message']})"
        out.append(f"| {row['name']}{flag} | {params} | {cells} | {row['last_cycle']:.3e} |")
    return out


def format_text(result: dict) -> str:
    """Markdown tables: one row per algorithm, per loop."""
    n = result["cycles"]
    out = []
    if "algorithms" in result:
        out += _table(
            f"Drift ||x - x0|| on Table 1's loop of Manipulator 2 (continuous, {n} cycles)",
            result["algorithms"],
            n,
        )
    if "panda" in result:
        out += [""] if out else []
        out += _table(
            f"Drift ||x - x0|| [rad] on the Panda's pose loop from its home "
            f"(continuous, {n} cycles)",
            result["panda"]["algorithms"],
            n,
        )
    return "\n".join(out)
