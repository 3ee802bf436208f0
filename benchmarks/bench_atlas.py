"""Atlas speed and memory: 100,000 starts x Table 1's path x 3 cycles, pseudoinverse.

1. The atlas (``engine.atlas_run.run_atlas``) in-process, with 2 local processes and with a
   2-worker Dask LocalCluster (where the ``atlas`` extra installed Dask), against the
   straightforward code: single-start ``engine.repeatability.repeatability`` in a loop, timed on
   a sample of starts and extrapolated. The backends' numbers are compared (max |difference| of
   drift), and the sample's drift with the atlas's.
2. Memory: streaming (``iter_atlas``, the way ``jik atlas`` writes a large CSV) 10^5 and 10^6
   starts with 2 local processes, one cycle, in a fresh interpreter each: the peak of Python's
   allocations in the parent (tracemalloc) and the peak resident size of the parent and of the
   workers (getrusage).

The starts lie on the self-motion curve k(x) = (0, 1) of Table 1's x0, one turn of the arm
(s in [-pi m, pi m], m = sqrt(2)), on a grid; the path is Table 1's loop from (0, 1).
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import time

import numpy as np

from jik import install_hint

from ..engine.atlas import plan_atlas
from ..engine.atlas_run import iter_atlas, run_atlas
from ..engine.inverses import Pseudoinverse
from ..engine.kinematics import Manipulator2
from ..engine.repeatability import repeatability

X0 = (0.0, 0.0, math.pi / 2)
LOOP = [(0.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)]
TURN = math.pi * math.sqrt(2.0)


def plan(n: int, cycles: int = 3):
    return plan_atlas(
        Pseudoinverse(Manipulator2()),
        LOOP,
        cycles=cycles,
        n_starts=n,
        arc=(-TURN, TURN),
        reference=X0,
    )


def timed(fn):
    t = time.perf_counter()
    out = fn()
    return time.perf_counter() - t, out


def cpu_seconds() -> float:
    """User + system time of this process and of its finished children (pool workers, and a
    LocalCluster's nannies with their workers), which other processes' load does not inflate."""
    return sum(
        u.ru_utime + u.ru_stime
        for u in (
            resource.getrusage(resource.RUSAGE_SELF),
            resource.getrusage(resource.RUSAGE_CHILDREN),
        )
    )


def loop_reference(p, sample: int):
    """Single-start repeatability() at ``sample`` starts spread over the atlas: seconds each."""
    idx = np.linspace(0, p.n_starts - 1, sample).astype(int)
    starts = np.concatenate([p.starts(i, i + 1) for i in idx])
    times, drift = [], []
    for x in starts:
        t, res = timed(lambda x=x: repeatability(p.inverses[0], x, p.paths[0, 1:], p.cycles))
        times.append(t)
        drift.append(res.drift)
    return idx, np.array(times), np.array(drift)


def memory(n: int, backend: str) -> dict:
    """Stream an atlas of n starts (one cycle) and report its peaks (run in a fresh process)."""
    import tracemalloc

    p = plan(n, cycles=1)
    tracemalloc.start()
    t0 = time.perf_counter()
    runs = 0
    for _task, chunk in iter_atlas(p, backend):
        runs += chunk.hi - chunk.lo
    elapsed = time.perf_counter() - t0
    traced = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    kb = 1024  # (ru_maxrss is in kB on Linux)
    return {
        "starts": n,
        "runs": runs,
        "chunk": p.chunk,
        "seconds": elapsed,
        "traced_peak_mb": traced / 1e6,
        "parent_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * kb / 1e6,
        "worker_rss_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * kb / 1e6,
    }


def memory_in_fresh_process(n: int, backend: str) -> dict:
    code = (
        "import json, sys; from jik.benchmarks.bench_atlas import memory; "
        f"print(json.dumps(memory({n}, {backend!r})))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def backends() -> tuple[str, ...]:
    """The atlas backends timed: the Dask cluster only where the ``atlas`` extra installed it."""
    local = ("inprocess", "processes:2")
    return (*local, "dask:local:2") if importlib.util.find_spec("distributed") else local


def run(quick: bool = False) -> dict:
    n = 2000 if quick else 100_000
    p = plan(n)
    results, cpu, drift = {}, {}, {}
    for backend in backends():
        c0 = cpu_seconds()
        t, res = timed(lambda b=backend: run_atlas(p, b, keep_leg_ends=False))
        results[backend], cpu[backend] = t, cpu_seconds() - c0
        drift[backend] = res.drift[0, 0]
    idx, times, sample_drift = loop_reference(p, 8 if quick else 40)
    per_start = statistics.median(times)
    loop_total = per_start * n
    mem = [
        memory_in_fresh_process(m, "processes:2")
        for m in ((2000, 20000) if quick else (10**5, 10**6))
    ]
    return {
        "starts": n,
        "legs": p.legs * p.cycles,
        "seconds": results,
        "cpu_seconds": cpu,
        "load_average": list(os.getloadavg()),
        "loop_per_start_ms": 1e3 * per_start,
        "loop_sample": len(times),
        "loop_extrapolated_s": loop_total,
        "ratio": {b: loop_total / t for b, t in results.items()},
        "backend_difference": {
            b: float(np.nanmax(np.abs(drift[b] - drift["inprocess"]))) for b in drift
        },
        "sample_difference": float(np.max(np.abs(sample_drift - drift["inprocess"][idx]))),
        "failed": int(np.sum(~np.isfinite(drift["inprocess"][:, -1]))),
        "median_drift": [float(v) for v in np.nanmedian(drift["inprocess"], axis=0)],
        "memory": mem,
    }


def main(quick: bool = False) -> dict:
    r = run(quick)
    n = r["starts"]
    print(f"{n} starts x Table 1's loop x 3 cycles ({r['legs']} legs each), pseudoinverse:")
    for b, t in r["seconds"].items():
        print(
            f"  atlas {b:<14} {t:8.1f} s wall, {r['cpu_seconds'][b]:6.1f} s CPU   "
            f"{1e3 * t / (n * r['legs']):.4f} ms per start and leg   ratio to the loop "
            f"{r['ratio'][b]:5.0f}x   max |drift - in-process| "
            f"{r['backend_difference'][b]:.1e}"
        )
    if "dask:local:2" not in r["seconds"]:
        print(f"  atlas dask:local:2 not timed: it needs dask.distributed, {install_hint('atlas')}")
    print(
        f"  repeatability() loop   {r['loop_per_start_ms']:8.2f} ms per start (median of "
        f"{r['loop_sample']}), {r['loop_extrapolated_s']:.0f} s extrapolated to {n}; "
        f"max |drift - atlas| {r['sample_difference']:.1e}"
    )
    print(f"  failed runs {r['failed']}; median drift per cycle {r['median_drift']}")
    print(f"  load average during the run (1, 5, 15 min): {r['load_average']}")
    print("Memory, streaming with 2 local processes, one cycle (fresh interpreter each):")
    for m in r["memory"]:
        print(
            f"  {m['starts']:>8} starts (chunk {m['chunk']}): {m['seconds']:6.1f} s, traced "
            f"peak {m['traced_peak_mb']:.2f} MB, parent RSS {m['parent_rss_mb']:.0f} MB, "
            f"largest worker RSS {m['worker_rss_mb']:.0f} MB"
        )
    return r


if __name__ == "__main__":
    main()
