"""Benchmark: the default Manipulator 2 E2 synthesis vs a straightforward implementation.

jik: :func:`jik.engine.variational.synthesize_manipulator2` (tensor Legendre degree 16, 288
unknowns, batched quadrature data, Ritz system assembled once by matrix products, plus the
lower-degree convergence solves, the cubic fit and its E2).
Straightforward: the same Ritz problem at the same degree and quadrature, assembled point by
point in a Python loop (kinematics, P and the outer products of the basis gradients per
quadrature point), then one dense solve. Both must give the same E2.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import TypeVar, cast

import numpy as np
from numpy.polynomial import legendre as L

from ..engine.inverses import pseudoinverse
from ..engine.kinematics import Manipulator2
from ..engine.variational import (
    EXTRA_NODES,
    MANIPULATOR2_DEGREE,
    MANIPULATOR2_REGION,
    synthesize_manipulator2,
)

#: Target of the issue: the default synthesis takes at most this long [s].
BUDGET_SECONDS = 2.0


def naive_synthesis(degree: int = MANIPULATOR2_DEGREE) -> float:
    """E2 minimum by a per-quadrature-point loop assembly of the same Ritz system."""
    kin = Manipulator2()
    (lo2, hi2), (lo3, hi3) = MANIPULATOR2_REGION["x2"], MANIPULATOR2_REGION["x3"]
    t, w = L.leggauss(degree + EXTRA_NODES)
    s2, s3 = 2.0 / (hi2 - lo2), 2.0 / (hi3 - lo3)
    D = np.zeros((degree + 1, degree + 1))
    D[:degree, :] = L.legder(np.eye(degree + 1), axis=0)
    nb = (degree + 1) ** 2
    A, b, const = np.zeros((nb, nb)), np.zeros(nb), 0.0
    for i, ti in enumerate(t):
        for j, tj in enumerate(t):
            x = np.array([0.0, (lo2 + hi2) / 2 + ti / s2, (lo3 + hi3) / 2 + tj / s3])
            J, K, m = kin.jacobian(x), kin.kernel(x), float(kin.manipulability(x))
            Jp = pseudoinverse(J)
            R = m * (Jp @ Jp.T + np.outer(K, K))[1:, 1:]
            vi, vj = L.legvander(ti, degree)[0], L.legvander(tj, degree)[0]
            g = np.stack([np.kron(vi @ D * s2, vj), np.kron(vi, vj @ D * s3)])  # (2, nb)
            wij = w[i] * w[j] / (s2 * s3)
            A += wij * g.T @ R @ g
            b += wij * g.T @ (m * K[1:])
            const += wij * m
    c = np.linalg.solve(A[1:, 1:], b[1:])
    return const - float(c @ b[1:])


_T = TypeVar("_T")


def _median_time(fn: Callable[[], _T], repeats: int) -> tuple[float, float, _T]:
    """Median wall-clock and CPU (process) time of ``repeats`` calls, and the last result."""
    wall: list[float] = []
    cpu: list[float] = []
    out: _T | None = None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    # median() raises on repeats < 1, so out is fn()'s result when this returns.
    return statistics.median(wall), statistics.median(cpu), cast(_T, out)


def run(repeats: int = 5) -> dict:
    """Medians [s] of both implementations (wall clock and CPU), their ratio and E2 values."""
    jik_s, jik_cpu, res = _median_time(synthesize_manipulator2, repeats)
    naive_s, naive_cpu, naive_e2 = _median_time(naive_synthesis, max(1, repeats // 3))
    return {
        "degree": MANIPULATOR2_DEGREE,
        "unknowns": (MANIPULATOR2_DEGREE + 1) ** 2 - 1,
        "jik_median_s": jik_s,
        "jik_median_cpu_s": jik_cpu,
        "naive_median_s": naive_s,
        "naive_median_cpu_s": naive_cpu,
        "speedup": naive_s / jik_s,
        "jik_e2": res.e2,
        "naive_e2": naive_e2,
        "e2_relative_difference": abs(res.e2 - naive_e2) / abs(naive_e2),
        "within_budget": jik_s <= BUDGET_SECONDS,
        "budget_s": BUDGET_SECONDS,
    }


def main(quick: bool = False) -> dict:
    """Print the table (see docs/benchmarks.md)."""
    r = run(repeats=3 if quick else 7)
    print(f"Manipulator 2 E2 synthesis, degree {r['degree']} ({r['unknowns']} unknowns)")
    print(f"{'implementation':<34} {'wall [s]':>9} {'CPU [s]':>9} {'E2':>16}")
    rows = [
        ("jik synthesize_manipulator2", r["jik_median_s"], r["jik_median_cpu_s"], r["jik_e2"]),
        (
            "loop assembly + dense solve",
            r["naive_median_s"],
            r["naive_median_cpu_s"],
            r["naive_e2"],
        ),
    ]
    for name, wall, cpu, e2 in rows:
        print(f"{name:<34} {wall:>9.3f} {cpu:>9.3f} {e2:>16.12f}")
    met = "met" if r["within_budget"] else "NOT met"
    print(
        f"speedup {r['speedup']:.1f}x (wall); E2 relative difference "
        f"{r['e2_relative_difference']:.1e}; budget {r['budget_s']:g} s {met}"
    )
    return r


if __name__ == "__main__":
    main()
