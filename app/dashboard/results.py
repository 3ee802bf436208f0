"""A dashboard state solved: its chosen algorithms through its task (cached runs reused, more cycles
going on from fewer), with h on a grid for the h panel.

Continuous mode integrates in tau = gamma theta (see :mod:`jik.engine.solver`): x(theta) does not
depend on gamma, so the runs are solved at gamma = 1 and theta divided by gamma, and a gamma
change in continuous mode only rescales the theta axis without a new integration.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import replace

from .algorithms import cache_key
from .analysis import augmenting_grid
from .controls import MAX_DASHBOARD_CYCLES
from .model import DashboardState
from .offload import OffloadLane
from .robots import state_kinematics, state_spec
from .runs import (
    AlgorithmRun,
    DashboardResult,
    algorithm_run,
    first_cycles,
    leg_targets,
    platform_time,
)


def other_cycles(cache: dict, state: DashboardState, algorithm: str, legs: int):
    """A cached successful run of the same closed path with another number of cycles: the
    closest with more cycles, else the longest with fewer; None if there is none."""
    if state.task != "path" or legs < 2:
        return None
    found = {}
    for c in range(1, MAX_DASHBOARD_CYCLES + 1):
        run = cache.get(cache_key(state.model_copy(update={"cycles": c}), algorithm))
        if c != state.cycles and run is not None and run.success and run.platform is None:
            found[c] = run
    more = [c for c in found if c > state.cycles]
    return found[min(more) if more else max(found)] if found else None


def compute(
    state: DashboardState,
    generation: int = 0,
    *,
    progress: Callable[[float], None] = lambda fraction: None,
    cancelled: Callable[[], bool] = lambda: False,
    cache: dict | None = None,
    with_augmenting: bool = True,
    offload: OffloadLane | None = None,
    grid_before: dict | None = None,
) -> DashboardResult:
    """Solve the state's task with each of its chosen algorithms (``state.algorithms``).

    Parameters
    ----------
    progress : callable, optional
        Called with the fraction of legs done, in [0, 1].
    cancelled : callable
        Polled between legs; when it returns True the computation raises :class:`Cancelled`.
    cache : dict, optional
        Runs keyed by everything they depend on (gamma excluded in continuous mode); reused
        and filled.
    with_augmenting : bool
        Evaluate h on a grid for the h panel now (see :func:`augmenting_grid`).
    offload : OffloadLane, optional
        A lane of the shared compute processes: the first algorithm to solve runs there,
        concurrently with the others here (same results).
    grid_before : dict, optional
        The h grid on screen, whose box the new grid keeps when it fits (see
        :func:`augmenting_grid`).

    Raises
    ------
    Cancelled, JikError
        A singular start configuration raises the engine's typed error.
    """
    t0 = time.perf_counter()
    spec = state_spec(state)
    kin = state_kinematics(state)
    targets = leg_targets(kin, state)
    cycles = state.cycles if state.task == "path" else 1
    algorithms = state.algorithms
    total = len(algorithms) * cycles * len(targets)
    cache = {} if cache is None else cache
    keys = {a: cache_key(state, a) for a in algorithms}
    todo = [a for a in algorithms if keys[a] not in cache]
    # Another number of cycles of the same legs: its first cycles are this run's, or this run
    # goes on from its end (cycles slider: only the new legs are solved).
    other = {a: other_cycles(cache, state, a, len(targets)) for a in todo}
    for a in [a for a in todo if other[a] is not None and len(other[a].drift) >= cycles]:
        cache[keys[a]] = first_cycles(other[a], cycles, len(targets))
        todo.remove(a)
    # (legs done: those of the cached runs and of the runs the others go on from)
    done = [float((len(algorithms) - len(todo)) * cycles * len(targets))]
    done[0] += sum(len(other[a].leg_end) for a in todo if other[a] is not None)

    # With a lane of the compute pool, the first algorithm runs in a worker while this thread
    # runs the others (they are independent); each local leg then stands for n / (n - 1) legs
    # of the n in the progress.
    remote: Future | None = None
    away = todo[0] if len(todo) >= 2 else None
    if offload is not None and away is not None:
        remote = offload.submit(state, away, targets, cycles, generation, other[away])
    weight = 1.0 if remote is None else len(todo) / (len(todo) - 1)

    def step() -> None:
        done[0] += weight
        progress(min(done[0] / total, 1.0))

    def partial(fraction: float) -> None:
        progress(min((done[0] + weight * float(fraction)) / total, 1.0))

    for algorithm in todo:
        if remote is None or algorithm != away:
            cache[keys[algorithm]] = algorithm_run(
                state,
                algorithm,
                targets,
                cycles,
                step,
                cancelled,
                partial,
                kin,
                resume=other[algorithm],
            )
    if remote is not None and offload is not None and away is not None:
        cache[keys[away]] = offload.result(
            remote,
            lambda: algorithm_run(
                state, away, targets, cycles, cancelled=cancelled, kin=kin, resume=other[away]
            ),
        )
    runs: dict[str, AlgorithmRun] = {a: cache[keys[a]] for a in algorithms}
    if state.mode == "continuous":
        runs = {a: replace(run, theta=run.theta / state.gamma) for a, run in runs.items()}
    for k in list(cache)[:-64]:  # (the 64 newest kept)
        del cache[k]
    return DashboardResult(
        state=state,
        generation=generation,
        title=spec.title,
        variable_names=tuple(spec.variable_names),
        task_names=tuple(spec.task_names),
        targets=targets,
        runs=runs,
        time=platform_time(kin),
        augmenting=augmenting_grid(kin, state, runs, before=grid_before)
        if with_augmenting
        else None,
        seconds=time.perf_counter() - t0,
        cached={a: a not in todo for a in algorithms},
    )
