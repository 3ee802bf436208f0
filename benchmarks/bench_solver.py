"""Solver speed: jik's continuous mode against straightforward ``solve_ivp`` code, same tolerance.

1. One continuous leg of Manipulator 2 (Table 1's first leg, pseudoinverse): ``engine.solver.solve``
   against ``solve_ivp`` (default RK45, and DOP853 for reference) with rtol = atol = 1e-12 and a
   terminal event at task error 1e-10.
2. 4096 start configurations through Table 1's four-leg path: one batched
   ``engine.repeatability.repeatability`` call against the straightforward code run leg by leg
   (a subset of starts, timed per leg).
3. Three cycles of Table 1's path for one start with the extended inverse (paper_cubic), leg by
   leg as the dashboard runs them: each leg from a cold start against each leg after the first
   cycle guessed by the same leg of the cycle before (``solve(..., guess=)``).
4. The same with the pseudoinverse, whose legs do not repeat: each leg cold, guessed by the
   cycle before, and guessed by a chain of its cycle's legs swept together
   (``engine.solver.chain_guesses``, what the dashboard does for it).
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np
from scipy.integrate import solve_ivp

from ..engine.augmentations import PaperCubic
from ..engine.dop853 import ATOL, RTOL
from ..engine.inverses import ExtendedInverse, Pseudoinverse
from ..engine.kinematics import Manipulator2
from ..engine.picard_guesses import chain_guesses
from ..engine.repeatability import closed_path, repeatability
from ..engine.solver import solve

X0 = np.array([0.0, 0.0, math.pi / 2])
PATH = np.array([(1.0, 1.0), (1.0, 2.0), (0.0, 2.0), (0.0, 1.0)])
TOL = 1e-10


def straightforward_leg(kin, x0, y_d, method="RK45"):
    """The textbook implementation: solve_ivp on (7) until ||e|| < TOL, gamma = 1. It calls
    the robot's unchecked k and J, as jik's solver does: the ratio is of the integration, not
    of the public methods' input checks."""

    def f(_t, x):
        J = kin.jacobian_unchecked(x)
        return -J.T @ np.linalg.solve(J @ J.T, kin.forward_unchecked(x) - y_d)

    def reached(_t, x):
        return np.linalg.norm(kin.forward_unchecked(x) - y_d) - TOL

    reached.terminal = True  # type: ignore[attr-defined]  # solve_ivp reads event attributes off the function
    sol = solve_ivp(f, (0, 200), x0, method=method, rtol=RTOL, atol=ATOL, events=reached)
    return sol.y[:, -1]


def median_time(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def cycles_leg_by_leg(inverse, x0, cycles: int, guessed: bool, chained: bool = False):
    """``cycles`` cycles of Table 1's path (closed), one solve per leg; returns the leg ends
    and the Picard sweeps. ``guessed``: each leg after the first cycle guessed by the same leg
    of the cycle before; ``chained``: each cycle's legs guessed by a chain from its start."""
    targets = closed_path(inverse.kinematics, x0[None], PATH)[0]
    guides: list = [None] * len(targets)
    cur, ends, sweeps = x0, [], 0
    for _ in range(cycles):
        chain = chain_guesses(inverse, cur, targets) if chained else None
        for j, y in enumerate(targets):
            guess = chain[j] if chain is not None else guides[j] if guessed else None
            res = solve(inverse, cur, y, guess=guess)
            guides[j], cur = res.trajectory, res.x
            ends.append(cur)
            sweeps += res.nit
    return np.array(ends), sweeps


def run(quick: bool = False) -> dict:
    kin = Manipulator2()
    inv = Pseudoinverse(kin)
    rep = 5 if quick else 21
    y_d = PATH[0]
    ours = median_time(lambda: solve(inv, X0, y_d, record=False), rep)
    rk45 = median_time(lambda: straightforward_leg(kin, X0, y_d), max(3, rep // 4))
    dop = median_time(lambda: straightforward_leg(kin, X0, y_d, "DOP853"), max(3, rep // 4))
    gap = np.linalg.norm(solve(inv, X0, y_d).x - straightforward_leg(kin, X0, y_d, "DOP853"))

    n = 512 if quick else 4096
    rng = np.random.default_rng(0)
    # Starts on the self-motion manifold k(x0) = (0, 1) of Table 1's x0, so that every start
    # runs exactly the four legs (1,1), (1,2), (0,2), (0,1).
    x3 = rng.uniform(1.0, 2.1, n)
    starts = np.column_stack([1.0 - np.sin(x3), -np.cos(x3), x3])
    t = time.perf_counter()
    res = repeatability(inv, starts, PATH, cycles=1)
    batch_total = time.perf_counter() - t
    legs = len(res.targets[0])
    batch_per_leg = batch_total / (n * legs)
    sub = 4 if quick else 16
    per_leg = []
    for x in starts[:sub]:
        cur = x
        for y in res.targets[0]:
            t = time.perf_counter()
            cur = straightforward_leg(kin, cur, y)
            per_leg.append(time.perf_counter() - t)
    straight_leg = statistics.median(per_leg)
    ref = np.array(
        [straightforward_leg(kin, starts[0], y) for y in res.targets[0][:1]]
    )  # same first leg
    ext = ExtendedInverse(kin, PaperCubic())
    cold_ends, cold_sweeps = cycles_leg_by_leg(ext, X0, 3, guessed=False)
    warm_ends, warm_sweeps = cycles_leg_by_leg(ext, X0, 3, guessed=True)
    cold_t = median_time(lambda: cycles_leg_by_leg(ext, X0, 3, guessed=False), rep)
    warm_t = median_time(lambda: cycles_leg_by_leg(ext, X0, 3, guessed=True), rep)
    pinv = {
        how: (
            cycles_leg_by_leg(inv, X0, 3, guessed=how == "cycle", chained=how == "chain"),
            median_time(
                lambda h=how: cycles_leg_by_leg(
                    inv, X0, 3, guessed=h == "cycle", chained=h == "chain"
                ),
                rep,
            ),
        )
        for how in ("cold", "cycle", "chain")
    }
    return {
        "pinv_cycles": {
            "legs": len(pinv["cold"][0][0]),
            **{f"{how}_ms": 1e3 * t for how, (_, t) in pinv.items()},
            **{f"{how}_sweeps": int(sw) for how, ((_, sw), _) in pinv.items()},
            "ratio": pinv["cold"][1] / pinv["chain"][1],
            "leg_end_difference": float(
                max(np.max(np.abs(pinv["cold"][0][0] - e)) for (e, _), _ in pinv.values())
            ),
        },
        "cycles": {
            "legs": len(cold_ends),
            "cold_ms": 1e3 * cold_t,
            "guessed_ms": 1e3 * warm_t,
            "ratio": cold_t / warm_t,
            "cold_sweeps": int(cold_sweeps),
            "guessed_sweeps": int(warm_sweeps),
            "leg_end_difference": float(np.max(np.abs(cold_ends - warm_ends))),
        },
        "single_leg": {
            "jik_ms": 1e3 * ours,
            "solve_ivp_rk45_ms": 1e3 * rk45,
            "solve_ivp_dop853_ms": 1e3 * dop,
            "ratio_rk45": rk45 / ours,
            "ratio_dop853": dop / ours,
            "end_point_difference": float(gap),
        },
        "batch": {
            "starts": n,
            "legs": legs,
            "succeeded": int(np.sum(res.success)),
            "jik_total_s": batch_total,
            "jik_per_leg_ms": 1e3 * batch_per_leg,
            "straightforward_per_leg_ms": 1e3 * straight_leg,
            "straightforward_sample": sub * legs,
            "ratio": straight_leg / batch_per_leg,
            "first_leg_difference": float(np.linalg.norm(res.legs[0, 0] - ref[0])),
        },
    }


def main(quick: bool = False) -> dict:
    r = run(quick)
    s, b = r["single_leg"], r["batch"]
    print("One continuous leg of Manipulator 2 (tol 1e-10, rtol = atol = 1e-12), medians:")
    print(f"  jik solve               {s['jik_ms']:9.2f} ms")
    for name, key in (("RK45", "rk45"), ("DOP853", "dop853")):
        ms, ratio = s[f"solve_ivp_{key}_ms"], s[f"ratio_{key}"]
        print(f"  solve_ivp {name:<14}{ms:9.2f} ms   ratio {ratio:6.1f}x")
    print(f"  |x_jik - x_dop853|      {s['end_point_difference']:.2e}")
    print(f"{b['starts']} starts through Table 1's {b['legs']}-leg path (pseudoinverse):")
    print(
        f"  jik batched             {b['jik_total_s']:9.2f} s total, "
        f"{b['jik_per_leg_ms']:.4f} ms per start per leg ({b['succeeded']} succeeded)"
    )
    print(
        f"  straightforward         {b['straightforward_per_leg_ms']:9.2f} ms per leg "
        f"(median of {b['straightforward_sample']} legs)   ratio {b['ratio']:7.0f}x"
    )
    print(f"  |first leg jik - solve_ivp| {b['first_leg_difference']:.2e}")
    c = r["cycles"]
    print(f"3 cycles of Table 1's path, extended inverse, {c['legs']} legs one by one:")
    print(f"  every leg cold          {c['cold_ms']:9.2f} ms ({c['cold_sweeps']} sweeps)")
    print(
        f"  guessed by cycle before {c['guessed_ms']:9.2f} ms ({c['guessed_sweeps']} sweeps)"
        f"   ratio {c['ratio']:6.2f}x"
    )
    print(f"  max |leg end difference| {c['leg_end_difference']:.2e}")
    c = r["pinv_cycles"]
    print(f"3 cycles of Table 1's path, pseudoinverse, {c['legs']} legs one by one:")
    print(f"  every leg cold          {c['cold_ms']:9.2f} ms ({c['cold_sweeps']} sweeps)")
    print(f"  guessed by cycle before {c['cycle_ms']:9.2f} ms ({c['cycle_sweeps']} sweeps)")
    print(
        f"  chained per cycle       {c['chain_ms']:9.2f} ms ({c['chain_sweeps']} sweeps of the"
        " legs, after the chains')"
        f"   ratio {c['ratio']:6.2f}x (cold / chained)"
    )
    print(f"  max |leg end difference| {c['leg_end_difference']:.2e}")
    return r


if __name__ == "__main__":
    main()
