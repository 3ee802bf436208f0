"""The compute pool against a maintained process pool (pebble) under the /solve load, no HTTP.

16 asyncio clients post Manipulator 2 solves (as ``jik bench load``) for 10 s (``quick``: 3 s)
to two worker processes, in the same run:

- ``jik pool, batched``: :class:`jik.app.compute.pool.ComputePool` as the server runs it
  (concurrent compatible solves micro-batched into one engine call);
- ``jik pool, one per task``: the same pool with batching off (one engine call per request);
- ``pebble, one per task``: ``pebble.ProcessPool.schedule`` of the same worker function with the
  same time limit, awaited through ``asyncio.wrap_future`` (each result comes back through
  pebble's result thread, then the event loop);
- ``pebble, batched``: pebble with the same micro-batching in front of it (requests that arrive
  while both workers are busy wait and go as one batch).

It prints throughput and p50 / p99 latency of each, and the ratios to the jik pool.
"""

from __future__ import annotations

import asyncio
import multiprocessing
import time
from typing import Any

from jik import install_hint

from .bench_load import CLIENTS, _bodies, _summary

DURATION = 10.0
QUICK_DURATION = 3.0


async def _drive(send, duration: float, clients: int) -> dict:
    """``clients`` loops of ``await send(body_bytes)`` for ``duration`` seconds."""
    lat: list[float] = []
    errs: list[str] = []

    async def client(k: int, stop: float) -> None:
        from ..app.compute.schemas import SolveRequest

        reqs = [SolveRequest.model_validate(b) for b in _bodies(64, seed=k)]
        i = 0
        while time.perf_counter() < stop:
            t0 = time.perf_counter()
            try:
                await send(reqs[i % len(reqs)])
                lat.append(time.perf_counter() - t0)
            except Exception as exc:  # counted, not raised: the run goes on
                errs.append(repr(exc))
            i += 1

    t0 = time.perf_counter()
    await asyncio.gather(*(client(k, t0 + duration) for k in range(clients)))
    return _summary(lat, errs, time.perf_counter() - t0)


async def _jik(duration: float, clients: int, batching: bool) -> dict:
    from ..app.compute.pool import ComputePool
    from ..app.compute.settings import Settings

    pool = ComputePool(Settings(workers=2, batching=batching))
    try:
        await pool.warm_up()
        return await _drive(pool.solve, duration, clients)
    finally:
        pool.close()


async def _pebble(duration: float, clients: int, batching: bool) -> dict:
    try:
        import pebble
    except ImportError:  # (the comparison's library only: the bench extra)
        return {
            "throughput_rps": float("nan"),
            "p50_ms": float("nan"),
            "p99_ms": float("nan"),
            "errors": f"pebble is not installed: {install_hint('bench')}",
        }

    from ..app.compute.worker import solve_batch
    from ..engine.atlas_backends import limit_memory

    pool = pebble.ProcessPool(
        max_workers=2,
        initializer=limit_memory,
        initargs=(1024,),
        context=multiprocessing.get_context("spawn"),
    )
    try:
        await asyncio.wrap_future(pool.schedule(solve_batch, args=([],)))  # (workers up)
        slots = asyncio.Semaphore(2)
        waiting: list[tuple[bytes, asyncio.Future]] = []
        flushes: set[asyncio.Task] = set()

        def spawn_flush() -> None:
            task = asyncio.ensure_future(flush())
            flushes.add(task)
            task.add_done_callback(flushes.discard)

        async def run(items: list[bytes]) -> list[Any]:
            async with slots:
                return await asyncio.wrap_future(
                    pool.schedule(solve_batch, args=(items,), timeout=20.0)
                )

        async def flush() -> None:
            async with slots:  # (a worker is free: everything waiting goes as one batch)
                batch = waiting[:64]
                del waiting[:64]
                if waiting:
                    spawn_flush()
                if batch:
                    items = [b for b, _ in batch]
                    results = await asyncio.wrap_future(
                        pool.schedule(solve_batch, args=(items,), timeout=20.0)
                    )
                    for (_, fut), res in zip(batch, results, strict=True):
                        fut.set_result(res)

        async def send(req) -> Any:
            payload = req.model_dump_json().encode()
            if not batching:
                return (await run([payload]))[0]
            fut = asyncio.get_running_loop().create_future()
            waiting.append((payload, fut))
            if len(waiting) == 1:  # (the first of a batch opens its window)
                await asyncio.sleep(0.002)
                spawn_flush()
            return await fut

        return await _drive(send, duration, clients)
    finally:
        pool.stop()
        pool.join()


def main(quick: bool = False) -> dict:
    duration = QUICK_DURATION if quick else DURATION
    runs = {
        "jik pool, batched": lambda: _jik(duration, CLIENTS, True),
        "pebble, batched": lambda: _pebble(duration, CLIENTS, True),
        "jik pool, one per task": lambda: _jik(duration, CLIENTS, False),
        "pebble, one per task": lambda: _pebble(duration, CLIENTS, False),
    }
    results = {}
    for label, make in runs.items():
        r = results[label] = asyncio.run(make())
        print(
            f"{label:24s} {r['throughput_rps']:7.0f} req/s  p50 {r['p50_ms']:6.1f} ms  "
            f"p99 {r['p99_ms']:6.1f} ms  errors {r['errors']}",
            flush=True,
        )
    for kind in ("batched", "one per task"):
        j, p = results[f"jik pool, {kind}"], results[f"pebble, {kind}"]
        print(
            f"  {kind}: pebble / jik throughput {p['throughput_rps'] / j['throughput_rps']:.2f}, "
            f"p50 {p['p50_ms'] / j['p50_ms']:.2f}"
        )
    return results


if __name__ == "__main__":
    main()
