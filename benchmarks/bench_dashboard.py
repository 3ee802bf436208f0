"""Dashboard computation: both algorithms in one thread vs the pseudoinverse offloaded.

What a control change costs the server before the page and the scene can redraw:
:func:`jik.app.dashboard.compute` of the registry's default state (both algorithms through the
closed path, h on a grid), with a fresh cache each time (a new start point). Straightforward:
the two algorithms one after the other in the calling thread. jik serve: the pseudoinverse in a
worker of the server's compute pool (:class:`jik.app.dashboard.OffloadLane`, the pool the REST API
uses, here with one worker) while the thread runs the extended inverse.
Wall-clock medians; each offloaded run is checked to give the same configurations.

Algorithms chosen: the default view's update (the runs, every panel's JSON and the verdict) of
Manipulator 2's default state with the paper's two algorithms against the same with a third
(the posture inverse), in one thread and offloaded as ``jik serve`` does, alternating in the
same run. A third algorithm adds about half of the two's work, so the target is a ratio of at
most 1.5.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from ..app.compute.pool import pool_in_thread
from ..app.compute.settings import Settings
from ..app.dashboard import OffloadLane, compute, default_state, updated_state
from ..app.dashboard.figures import figure_specs
from ..app.dashboard.messages import summary
from ..app.dashboard.plotting import figure_json
from ..app.dashboard.verdict import verdict

ROBOTS = ("manipulator2", "manipulator1", "unicycle")


def _timed(robot: str, repeats: int, offload: OffloadLane | None) -> float:
    state = default_state(robot)
    walls = []
    for k in range(repeats):
        if robot != "unicycle":  # a new start point each time (no cached run)
            x0 = np.asarray(state.x0) + 0.01 * (k + 1)
            state = updated_state(default_state(robot), {"x0": x0.tolist()})
        t0 = time.perf_counter()
        result = compute(state, k + 1, offload=offload)
        walls.append(time.perf_counter() - t0)
        if offload is not None and k == 0:
            serial = compute(state)
            for a, run in serial.runs.items():
                assert np.array_equal(run.x, result.runs[a].x), f"{robot}: {a} differs"
    return statistics.median(walls)


#: The algorithms of the default view, and with a third.
TWO = ("pseudoinverse", "extended")
THREE = (*TWO, "posture")


def _update(algorithms, k: int, offload: OffloadLane | None) -> float:
    """Seconds of one update of the default view with ``algorithms`` from a new start point
    (nothing cached): the runs, every panel as JSON, the summary and the verdict."""
    state = default_state("manipulator2")
    x0 = np.asarray(state.x0) + 0.01 * (k + 1)
    state = updated_state(state, {"x0": x0.tolist(), "algorithms": list(algorithms)})
    t0 = time.perf_counter()
    result = compute(state, k + 1, offload=offload)
    texts = [figure_json(f) for f in figure_specs(result).values()]
    summary(result), verdict(result)
    assert list(result.runs) == list(algorithms) and len(texts) > 0
    return time.perf_counter() - t0


def algorithms_run(offload: OffloadLane | None, repeats: int) -> dict:
    """Median update with two and with three algorithms, measured alternately."""
    walls: dict[str, list[float]] = {"two": [], "three": []}
    for k in range(repeats):
        walls["two"].append(_update(TWO, k, offload))
        walls["three"].append(_update(THREE, k, offload))
    two, three = (statistics.median(walls[n]) for n in ("two", "three"))
    return {"two_ms": 1e3 * two, "three_ms": 1e3 * three, "ratio": three / two, "repeats": repeats}


def run(quick: bool = False) -> dict:
    with pool_in_thread(Settings(workers=1, timeout=120.0)) as pool:
        offload = OffloadLane(pool)
        compute(default_state("manipulator2"), offload=offload)  # the worker has run one
        out: dict = {}
        for robot in ROBOTS:
            repeats = (2 if quick else 5) if robot == "unicycle" else (5 if quick else 21)
            serial = _timed(robot, repeats, None)
            offloaded = _timed(robot, repeats, offload)
            out[robot] = {
                "serial_ms": 1e3 * serial,
                "offloaded_ms": 1e3 * offloaded,
                "ratio": serial / offloaded,
                "repeats": repeats,
            }
        repeats = 7 if quick else 21
        out["algorithms"] = {
            "one thread": algorithms_run(None, repeats),
            "offloaded": algorithms_run(offload, repeats),
        }
        return out


def main(quick: bool = False) -> None:
    r = run(quick=quick)
    print(f"{'default state':16}{'one thread':>12}{'offloaded':>12}{'ratio':>8}{'runs':>6}")
    chosen = r.pop("algorithms")
    for robot, v in r.items():
        print(
            f"{robot:16}{v['serial_ms']:10.1f}ms{v['offloaded_ms']:10.1f}ms"
            f"{v['ratio']:8.2f}{v['repeats']:6d}"
        )
    print(
        "\nManipulator 2, default view's update (runs, panels, verdict): two algorithms vs "
        "three (+ posture); target ratio <= 1.5"
    )
    print(f"{'':16}{'two':>12}{'three':>12}{'ratio':>8}{'runs':>6}")
    for how, v in chosen.items():
        print(
            f"{how:16}{v['two_ms']:10.1f}ms{v['three_ms']:10.1f}ms{v['ratio']:8.2f}"
            f"{v['repeats']:6d}"
        )


if __name__ == "__main__":
    main()
