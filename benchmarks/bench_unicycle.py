"""Unicycle characteristics synthesis: jik vs a straightforward implementation, in the same run.

Straightforward: for every evaluation of h, ``scipy.integrate.solve_ivp`` (RK45, rtol 1e-10,
atol 1e-12) integrates the characteristic (28) from s = 1 to 0, with omega from the generic
determinant cofactors of the Jacobian at each right-hand-side call; dh is central differences of
h (8 more integrations, step 1e-6). jik: Chebyshev collocation of (28) solved by Newton for the
whole batch, exact gradient from the variational equations (engine/characteristics.py).

The straightforward extended run from A takes tens of seconds; it is timed on its first
PREFIX_ITERATIONS iterations and extrapolated per iteration to the length of jik's run (stated in
the output). Times are wall-clock medians (``time.perf_counter``); CPU-time medians
(``time.process_time``) are reported too, because the machine is shared.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import TypeVar, cast

import numpy as np
from scipy.integrate import solve_ivp

from ..engine.augmentations import AugmentingMap
from ..engine.characteristics import UnicycleCharacteristics
from ..engine.inverses import ExtendedInverse
from ..engine.kinematics import kernel_cofactors
from ..engine.reproductions import unicycle as repro
from ..engine.solver import solve
from ..engine.unicycle import Unicycle

PREFIX_ITERATIONS = 8
TARGETS = {"h_and_gradient_ms": 5.0, "extended_run_a_s": 1.0, "reproduction_s": 10.0}


class StraightforwardCharacteristics(AugmentingMap):
    """h of section 6.1 by solve_ivp per point and dh by central differences (the baseline)."""

    name = "characteristics_straightforward"
    p = 4

    def __init__(self, kinematics: Unicycle, a: float = 1.0, step: float = 1e-6) -> None:
        self.kinematics, self.a, self.step = kinematics, a, step

    def _h(self, lam: np.ndarray) -> float:
        y = np.array([lam[0] - self.a, lam[2], lam[3]])

        def rhs(s, z):
            x = np.array([self.a + s * y[0], z[0], s * y[1], s * y[2]])
            c = kernel_cofactors(self.kinematics.jacobian(x))
            w = c / c[1]
            return [-(w[0] * y[0] + w[2] * y[1] + w[3] * y[2])]

        sol = solve_ivp(rhs, (1.0, 0.0), [lam[1]], rtol=1e-10, atol=1e-12)
        return float(sol.y[0, -1])

    def value(self, x):
        x = np.asarray(x, dtype=float)
        flat = x.reshape(-1, 4)
        return np.array([self._h(v) for v in flat]).reshape(x.shape[:-1])

    def gradient(self, x):
        x = np.asarray(x, dtype=float)
        flat = x.reshape(-1, 4)
        out = np.empty_like(flat)
        for n, v in enumerate(flat):
            for k, e in enumerate(np.eye(4) * self.step):
                out[n, k] = (self._h(v + e) - self._h(v - e)) / (2 * self.step)
        return out.reshape(x.shape)


_T = TypeVar("_T")


def _timed(fn: Callable[[], _T], repeats: int) -> tuple[float, float, _T]:
    """Median wall and CPU seconds of ``fn()`` over ``repeats`` calls, and its last result."""
    wall: list[float] = []
    cpu: list[float] = []
    out: _T | None = None
    for _ in range(repeats):
        w0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    # median() raises on repeats < 1, so out is fn()'s result when this returns.
    return statistics.median(wall), statistics.median(cpu), cast(_T, out)


def run(quick: bool = False) -> dict:
    """Medians (seconds) and ratios straightforward / jik; see the module docstring."""
    kin = Unicycle(q0=repro.STARTS["A"])
    lam0 = np.array(repro.LAMBDA0)
    fast = UnicycleCharacteristics(kin, a=repro.A_PARAMETER)
    slow = StraightforwardCharacteristics(kin, a=repro.A_PARAMETER)
    points = lam0 + np.random.default_rng(0).uniform(-0.3, 0.3, (5, 4))
    reps = 3 if quick else 15

    def fast_cold():
        fast._cache = None  # no reuse of the previous characteristic: a cold Newton start
        return [fast.value(p) for p in points], [fast.gradient(p) for p in points]

    def slow_eval():
        return [slow.value(p) for p in points], [slow.gradient(p) for p in points]

    fw, fc, (fh, fg) = _timed(fast_cold, reps)
    sw, sc, (sh, sg) = _timed(slow_eval, 1 if quick else 3)
    n = len(points)
    out: dict = {
        "h_and_gradient": {
            "jik_ms": 1e3 * fw / n,
            "jik_cpu_ms": 1e3 * fc / n,
            "straightforward_ms": 1e3 * sw / n,
            "straightforward_cpu_ms": 1e3 * sc / n,
            "ratio": sw / fw,
            "max_h_difference": float(np.max(np.abs(np.subtract(fh, sh)))),
            "max_gradient_difference": float(np.max(np.abs(np.subtract(fg, sg)))),
        },
    }

    def fast_run():
        inv = ExtendedInverse(kin, UnicycleCharacteristics(kin, a=repro.A_PARAMETER))
        return solve(inv, lam0, repro.Y_D, gamma=repro.GAMMA, mode="discrete", tol=repro.TOL)

    rw, rc, res = _timed(fast_run, 1 if quick else 3)
    inv_slow = ExtendedInverse(kin, slow)
    pw, _pc, _ = _timed(
        lambda: solve(
            inv_slow,
            lam0,
            repro.Y_D,
            gamma=repro.GAMMA,
            mode="discrete",
            tol=repro.TOL,
            max_iterations=PREFIX_ITERATIONS,
            record=False,
        ),
        1,
    )
    per_iteration = pw / (PREFIX_ITERATIONS + 1)  # the solver also checks the start point
    out["extended_run_a"] = {
        "iterations": int(res.nit),
        "jik_s": rw,
        "jik_cpu_s": rc,
        "straightforward_s_extrapolated": per_iteration * (res.nit + 1),
        "straightforward_prefix_iterations": PREFIX_ITERATIONS,
        "ratio": per_iteration * (res.nit + 1) / rw,
    }
    qw, qc, _ = _timed(repro.run, 1)
    out["reproduction"] = {"jik_s": qw, "jik_cpu_s": qc}
    out["targets"] = TARGETS
    out["meets_targets"] = {
        "h_and_gradient_ms": out["h_and_gradient"]["jik_ms"] <= TARGETS["h_and_gradient_ms"],
        "extended_run_a_s": rw <= TARGETS["extended_run_a_s"],
        "reproduction_s": qw < TARGETS["reproduction_s"],
    }
    return out


def main(quick: bool = False) -> None:
    r = run(quick=quick)
    hg, ra, rp = r["h_and_gradient"], r["extended_run_a"], r["reproduction"]
    rows = [
        (
            "h + dh, one point (ms)",
            hg["jik_ms"],
            hg["jik_cpu_ms"],
            hg["straightforward_ms"],
            hg["ratio"],
            TARGETS["h_and_gradient_ms"],
        ),
        (
            f"extended run from A, {ra['iterations']} it. (s)",
            ra["jik_s"],
            ra["jik_cpu_s"],
            ra["straightforward_s_extrapolated"],
            ra["ratio"],
            TARGETS["extended_run_a_s"],
        ),
        (
            "whole reproduction (s)",
            rp["jik_s"],
            rp["jik_cpu_s"],
            float("nan"),
            float("nan"),
            TARGETS["reproduction_s"],
        ),
    ]
    print(f"{'':36}{'jik':>10}{'jik cpu':>10}{'straightfwd':>13}{'ratio':>9}{'target':>9}")
    for label, a, b, c, d, t in rows:
        print(f"{label:36}{a:10.3g}{b:10.3g}{c:13.3g}{d:9.1f}{t:9.3g}")
    print(
        f"straightforward extended run extrapolated from its first {PREFIX_ITERATIONS} "
        f"iterations; h agrees to {hg['max_h_difference']:.1e}, dh to "
        f"{hg['max_gradient_difference']:.1e}"
    )
    print(f"meets targets: {r['meets_targets']}")


if __name__ == "__main__":
    main()
