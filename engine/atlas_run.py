"""Running an atlas (:mod:`jik.engine.atlas`): chunks of starts, each through every inverse.

A chunk is a few batched :func:`jik.engine.repeatability.repeatability` calls per inverse: every
leg of every start of a batch is one vectorized solve of eq. (7). :func:`run_chunk` is a plain
module-level function of picklable data, so a process pool or a Dask worker runs it as it is;
:func:`iter_atlas` hands chunks to a backend (:mod:`jik.engine.atlas_backends`) and yields
their results as they come, holding at most a few chunks at a time; :func:`run_atlas` gathers
them into one :class:`AtlasResult`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass
from time import perf_counter

import numpy as np

from .atlas import AtlasPlan
from .atlas_backends import Backend, backend_for
from .atlas_table import AtlasResult
from .exceptions import SingularConfigurationError
from .exports import plural
from .inverses import Inverse
from .limits import robot_limits, starts_outside
from .posture_at_start import PostureAtStart
from .practical_inverses import PostureInverse
from .progress import Progress, check_cancelled, check_progress
from .repeatability import repeatability
from .validation import FloatArray, check_memory, flag, of_type

#: Starts per batched repeatability() call within a chunk: the working set of the Picard sweeps
#: then stays in cache (``jik bench atlas``, docs/benchmarks.md: 512 is faster than 2048),
#: while a chunk, the unit of work a backend hands out, may be larger.
BATCH = 512


@dataclass(frozen=True)
class ChunkTask:
    """Runs ``lo`` to ``hi`` - 1 of an atlas: their starts (n, p) and legs' targets (n, L, r)."""

    lo: int
    hi: int
    inverses: tuple[Inverse, ...]
    starts: FloatArray
    targets: FloatArray
    cycles: int
    settings: dict


@dataclass(frozen=True)
class AtlasChunk:
    """What one chunk gives, per inverse a (leading axis A).

    Attributes
    ----------
    lo, hi : int
        The chunk's runs (run = path * N + start).
    drift : ndarray, shape (A, n, cycles)
        ||x after cycle c - x0||, sec. 5.2.1; NaN after a failed leg.
    leg_ends : ndarray, shape (A, n, cycles * L, p)
    success : ndarray of bool, shape (A, n)
    failures : tuple of (a, run, message)
        The runs whose legs did not all converge, and why.
    outside_limits : ndarray of bool, shape (A, n), or None
        The runs whose start or some leg end is outside the robot's joint limits (None: the
        robot has none).
    """

    lo: int
    hi: int
    drift: FloatArray
    leg_ends: FloatArray
    success: FloatArray
    failures: tuple[tuple[int, int, str], ...]
    outside_limits: FloatArray | None = None


def chunk_task(plan: AtlasPlan, lo: int, hi: int) -> ChunkTask:
    """The task of runs lo to hi - 1 (its starts computed here, by the caller)."""
    starts = plan.starts(lo, hi)
    return ChunkTask(
        lo, hi, plan.inverses, starts, plan.targets(lo, hi, starts), plan.cycles, plan.settings
    )


def run_chunk(task: ChunkTask) -> AtlasChunk:
    """Every inverse's repeatability run of the chunk's starts, in batches of :data:`BATCH`."""
    n, L = task.targets.shape[:2]
    A, p = len(task.inverses), task.starts.shape[1]
    drift = np.full((A, n, task.cycles), np.nan)
    legs = np.full((A, n, task.cycles * L, p), np.nan)
    success = np.zeros((A, n), dtype=bool)
    failures: list[tuple[int, int, str]] = []
    batches = [np.arange(b, min(b + BATCH, n)) for b in range(0, n, BATCH)]
    for a, inverse in enumerate(task.inverses):
        for ids, res, why in (r for batch in batches for r in _runs(inverse, task, batch)):
            if res is None:
                failures.extend((a, task.lo + int(i), why) for i in ids)
                continue
            drift[a, ids], success[a, ids] = res.drift, res.success
            legs[a, ids] = res.legs[..., :p]
            failures.extend(
                (a, task.lo + int(ids[k]), res.message[k]) for k in np.flatnonzero(~res.success)
            )
    limits = robot_limits(task.inverses[0].kinematics)
    outside = None if limits is None else starts_outside(limits, task.starts, legs)
    return AtlasChunk(task.lo, task.hi, drift, legs, success, tuple(failures), outside)


#: Runs timed together by :func:`sized_chunks`.
PROBE = 8


def sized_chunks(plan: AtlasPlan, seconds: float = 1.0) -> AtlasPlan:
    """``plan`` with chunks of about ``seconds`` of work, from the time of its first runs (a
    unicycle's run costs hundreds of times a Manipulator 2's); at most the plan's own chunk.
    The first run (with its one-time costs) is timed alone: when it takes ``seconds`` or more,
    a chunk is one run and nothing more is probed (an arm's runs far out of reach take seconds
    each); else up to :data:`PROBE` runs, as many as fit in ``seconds`` at the first one's
    pace, are timed together. The atlas's numbers do not depend on its chunks."""
    start = perf_counter()
    run_chunk(chunk_task(plan, 0, 1))
    first = perf_counter() - start
    if first >= seconds:
        return dataclasses.replace(plan, chunk=1)
    n = int(min(PROBE, plan.size, max(1.0, seconds / max(first, 1e-9))))
    probe = chunk_task(plan, 0, n)
    start = perf_counter()
    run_chunk(probe)
    per_run = (perf_counter() - start) / (probe.hi - probe.lo)
    chunk = int(min(max(seconds / max(per_run, 1e-9), 1), plan.chunk))
    return dataclasses.replace(plan, chunk=chunk)


def _runs(inverse: Inverse, task: ChunkTask, ids: np.ndarray):
    """Batched runs of the members ``ids``: (ids, result, "") pairs, or (ids, None, why) for a
    member whose start or leg start is singular for ``inverse`` (a batched solve raises there
    for the whole batch: the batch is halved until that member runs alone; every other member's
    numbers are those of any batch). A posture inverse whose rest was not given pulls each run
    toward its own start (:mod:`jik.engine.posture_at_start`)."""
    starts, run_inverse = task.starts[ids], inverse
    if isinstance(inverse, PostureInverse) and not inverse.rest_given:
        starts, run_inverse = PostureAtStart.carry(starts), PostureAtStart(inverse)
    try:
        res = repeatability(
            run_inverse, starts, task.targets[ids], task.cycles, close=False, **task.settings
        )
    except SingularConfigurationError as error:
        if len(ids) == 1:
            yield ids, None, str(error)
            return
        half = len(ids) // 2
        yield from _runs(inverse, task, ids[:half])
        yield from _runs(inverse, task, ids[half:])
        return
    yield ids, res, ""


def iter_atlas(
    plan: AtlasPlan,
    backend: str | Backend | None = None,
    progress: Progress | None = None,
) -> Iterator[tuple[ChunkTask, AtlasChunk]]:
    """The atlas's chunks, each with its task, in the order they finish.

    The tasks are made as the backend asks for them and a finished chunk is handed on at once,
    so memory holds a few chunks (the backend's in-flight bound), whatever ``plan.size``.

    Raises
    ------
    RunCancelled
        ``progress.cancelled()`` returned True (polled after every chunk); work not yet done is
        dropped.
    """
    plan = of_type(plan, AtlasPlan, "plan", "an AtlasPlan (plan_atlas)")
    progress = check_progress(progress)
    tasks = (
        chunk_task(plan, lo, min(lo + plan.chunk, plan.size))
        for lo in range(0, plan.size, plan.chunk)
    )
    by_lo: dict[int, ChunkTask] = {}

    def kept(items):
        for task in items:
            by_lo[task.lo] = task
            yield task

    with backend_for(backend) as runner:
        for chunk in runner.imap_unordered(run_chunk, kept(tasks)):
            yield by_lo.pop(chunk.lo), chunk
            check_cancelled(progress, f"atlas cancelled after run {chunk.hi} of {plan.size}")


def run_atlas(
    plan: AtlasPlan,
    backend: str | Backend | None = None,
    *,
    progress: Progress | None = None,
    keep_leg_ends: bool = True,
) -> AtlasResult:
    """Run an atlas and gather it (memory: the result's arrays and a few chunks).

    Parameters
    ----------
    plan : AtlasPlan
        From :func:`jik.engine.atlas.plan_atlas`.
    backend : str or Backend, optional
        Where chunks run: None or "inprocess" (here), "processes:N" (a local process pool),
        "dask:ADDRESS" or "dask:local:N" (a Dask cluster); see
        :func:`jik.engine.atlas_backends.backend_for`. The numbers are the same on each.
    progress : Progress, optional
        Told ``advance(runs_done, runs_total)`` after every chunk, and asked then whether to go
        on (:meth:`Progress.cancelled`: True stops the atlas with ``RunCancelled``).
    keep_leg_ends : bool
        Keep every leg's end (A P N cycles L p numbers); False keeps the drift alone.

    Raises
    ------
    InvalidInputError
        Before any work, with field ``n_starts`` (``starts`` for explicit starts), when the
        gathered arrays would exceed :data:`jik.engine.validation.MEMORY_LIMIT`: stream such an
        atlas with :func:`iter_atlas`, or keep the drift alone.
    """
    progress, keep_leg_ends = check_progress(progress), flag(keep_leg_ends, "keep_leg_ends")
    plan = of_type(plan, AtlasPlan, "plan", "an AtlasPlan (plan_atlas)")
    A, P, N = len(plan.inverses), len(plan.paths), plan.n_starts
    p = plan.inverses[0].kinematics.p
    leg_ends = A * plan.cycles * plan.legs * p if keep_leg_ends else 0
    check_memory(
        P * N,
        8.0 * (p + A * plan.cycles + leg_ends + 1) + 2 * A,
        "n_starts" if plan.explicit is None else "starts",
        f"runs of a gathered atlas ({plural(P, 'path')} x {plural(N, 'start')})",
        "stream it chunk by chunk with iter_atlas"
        + (", keep the drift alone (keep_leg_ends=False)" if keep_leg_ends else "")
        + ", or ask for fewer starts, paths or cycles",
    )
    starts = np.empty((P * N, p))
    drift = np.empty((A, P * N, plan.cycles))
    legs = np.empty((A, P * N, plan.cycles * plan.legs, p)) if keep_leg_ends else None
    success = np.empty((A, P * N), dtype=bool)
    limited = robot_limits(plan.inverses[0].kinematics) is not None
    outside = np.zeros((A, P * N), dtype=bool) if limited else None
    failures: dict[tuple[int, int, int], str] = {}
    done = 0
    for task, chunk in iter_atlas(plan, backend, progress):
        sl = slice(chunk.lo, chunk.hi)
        starts[sl], drift[:, sl], success[:, sl] = task.starts, chunk.drift, chunk.success
        if legs is not None:
            legs[:, sl] = chunk.leg_ends
        if outside is not None and chunk.outside_limits is not None:
            outside[:, sl] = chunk.outside_limits
        for a, run, why in chunk.failures:
            failures[(a, *divmod(run, N))] = why
        done += chunk.hi - chunk.lo
        if progress is not None:
            progress.advance(done, plan.size)
    return AtlasResult(
        plan.algorithms,
        plan.paths,
        plan.parameter(np.arange(N)),
        starts.reshape(P, N, p),
        drift.reshape(A, P, N, plan.cycles),
        None if legs is None else legs.reshape(A, P, N, *legs.shape[2:]),
        success.reshape(A, P, N),
        failures,
        None if outside is None else outside.reshape(A, P, N),
        plan.family,
    )
