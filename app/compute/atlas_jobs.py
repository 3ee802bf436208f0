"""Atlas jobs of the REST API: started by a request, run in the background, read back later.

An atlas (:mod:`jik.engine.atlas`) takes longer than a request may wait, so ``POST /atlas`` only
checks and plans it (:func:`~jik.app.compute.atlas_plan.planned`, in a compute worker), then
:class:`AtlasJobs` runs it in a thread of its own that hands its chunks to the server's compute
pool (:class:`PoolBackend`: the API's workers and their time and memory limits, first come first
served with its requests; they stop with the server). A job runs on when its client goes away,
and is dropped ``keep_for`` seconds after it ends (or when cancelled, or sooner when a new job
needs its room: the job that ended first goes, once kept ``min_keep`` seconds).

Limits (:class:`~jik.app.compute.atlas_plan.AtlasLimits`): at most ``max_running`` atlases
compute at once (the others wait, queued), ``max_jobs`` are kept in all (queued, running or
ended), ``per_client`` queued or running for one client (an address's REST requests, or one
dashboard session) and ``per_address`` for one address in all, and a job computes for at most
``max_seconds`` (then it fails and says so). A done job keeps its result document and the
engine's atlas it was made from (its table's source,
:meth:`~jik.engine.atlas_table.AtlasResult.csv_text`).
"""

from __future__ import annotations

import contextlib
import re
import secrets
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

from ...engine.atlas import AtlasPlan
from ...engine.atlas_backends import IN_FLIGHT, bounded_imap
from ...engine.atlas_run import run_atlas
from ...engine.atlas_table import AtlasResult
from ...engine.exceptions import RunCancelled
from ...engine.progress import ProgressCallbacks
from .atlas_plan import AtlasLimits, Used, result_document
from .atlas_schemas import AtlasJobResponse, AtlasRequest, Status
from .worker import task


@task("starts", "fewer starts or cycles")
def atlas_chunk(fn: Callable[[Any], Any], chunk: Any) -> Any:
    """``fn(chunk)``: one chunk of an atlas in a compute worker."""
    return fn(chunk)


class PoolBackend:
    """An atlas backend (:class:`jik.engine.atlas_backends.Backend`) on the server's compute
    pool (a :class:`~jik.app.compute.pool.ComputePool`): at most ``IN_FLIGHT`` chunks per worker
    submitted at once, results in the order they finish; leaving gives up the chunks in flight."""

    def __init__(self, pool: Any) -> None:
        self.pool = pool
        self.workers = pool.settings.workers

    def __enter__(self) -> PoolBackend:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def imap_unordered(self, fn: Callable[[Any], Any], tasks: Iterable[Any]) -> Iterator[Any]:
        submit = lambda chunk: self.pool.submit(atlas_chunk, fn, chunk)  # noqa: E731
        yield from bounded_imap(submit, tasks, IN_FLIGHT * self.workers)


class AtlasJobNotFound(LookupError):
    """No job with that id: HTTP 404; ``args``: the id and why it is not there."""


class AtlasJobsFull(RuntimeError):
    """Too many jobs in all or for this client: HTTP 429 with Retry-After."""


@dataclass
class AtlasJob:
    id: str
    client: str
    #: The request it was started from (the dashboard draws the result with it).
    request: AtlasRequest
    plan: AtlasPlan
    #: The robot and the map the plan used (:func:`~jik.app.compute.atlas_plan.planned`).
    used: Used
    status: Status = "queued"
    runs_done: int = 0
    started: float = field(default_factory=time.monotonic)
    ended: float | None = None
    error: str | None = None
    result: dict[str, Any] | None = None
    cancel: threading.Event = field(default_factory=threading.Event)
    #: The engine's atlas once done: its table (``GET /atlas/{id}/table.csv``) is made from it.
    atlas: AtlasResult | None = None
    #: The dashboard session that started it (None: a REST client): only that session's
    #: routes give its table.
    session: str | None = None
    #: Whether it holds one of the ``max_running`` slots (given back once, at its end or its
    #: cancel, whichever comes first).
    holds_slot: bool = False

    def response(self, ahead: int, running: int) -> AtlasJobResponse:
        """The job's state; ``ahead``: the jobs before it in the queue, of which ``running``
        are computing (:meth:`AtlasJobs.response` counts them)."""
        end = self.ended if self.ended is not None else time.monotonic()
        message: str = "computing" if self.status == "running" else self.status
        if self.status == "queued":
            message = (
                f"queued behind {ahead} atlas job{'s' * (ahead != 1)} ({running} computing, "
                f"the rest waiting); it starts when they end"
                if ahead
                else "starting"
            )
        return AtlasJobResponse(
            id=self.id,
            status=self.status,
            runs=self.plan.size,
            runs_done=self.runs_done,
            progress=self.runs_done / self.plan.size,
            elapsed_s=end - self.started,
            queue_position=ahead if self.status == "queued" else None,
            message=message,
            robot=self.used[0],
            augmentation=self.used[1],
            error=self.error,
            result=self.result,  # type: ignore[arg-type]  # (validated)
        )

    @property
    def active(self) -> bool:
        return self.status in ("queued", "running")


def _ended(job: AtlasJob) -> float:
    return job.ended or 0.0


class AtlasJobs:
    """The API's atlas jobs (see the module docstring)."""

    def __init__(self, limits: AtlasLimits | None = None, pool: Any = None) -> None:
        """``pool``: the compute pool whose workers run the chunks (:class:`PoolBackend`;
        None: each job's own thread runs them)."""
        self.limits = limits or AtlasLimits()
        self._pool = pool
        self._jobs: dict[str, AtlasJob] = {}
        self._lock = threading.Lock()
        self._slots = threading.Semaphore(self.limits.max_running)
        #: The first characters of this server's job ids: an id with others is a job of an
        #: earlier server process, lost when it stopped (jobs live in memory).
        self.run = secrets.token_hex(3)

    def check_room(self, client: str, session: str | None = None) -> None:
        """Raise :class:`AtlasJobsFull` if no job of ``client`` (an address; ``session``: of
        that dashboard session's) can start now."""
        self.sweep()
        with self._lock:
            self._room(client, session)

    def start(
        self,
        client: str,
        req: AtlasRequest,
        plan: tuple[AtlasPlan, Used],
        session: str | None = None,
    ) -> AtlasJob:
        """Start the request's atlas as a job: ``plan`` is its plan and what it used
        (:func:`~jik.app.compute.atlas_plan.planned`); raises before anything is kept when
        there is no room; ``session``: the dashboard session that asks for it."""
        self.check_room(client, session)
        job = AtlasJob(self.run + secrets.token_urlsafe(12), client, req, *plan, session=session)
        with self._lock:
            ended = self._room(client, session)
            if len(self._jobs) >= self.limits.max_jobs:  # (the job that ended first makes room)
                del self._jobs[ended[0].id]
            self._jobs[job.id] = job
        threading.Thread(
            target=self._run, args=(job,), name=f"jik-atlas-{job.id}", daemon=True
        ).start()
        return job

    def _room(self, client: str, session: str | None) -> list[AtlasJob]:
        """Raise :class:`AtlasJobsFull` if no job of ``client`` and ``session`` can start now;
        else the ended jobs that may make room (kept ``min_keep`` s), the first ended first.
        Under the lock."""
        jobs, limits = self._jobs.values(), self.limits
        mine = [j for j in jobs if j.active and j.client == client]
        if sum(j.session == session for j in mine) >= limits.per_client:
            raise AtlasJobsFull(
                f"at most {limits.per_client} atlas jobs per client run at "
                "once; wait for one to end or cancel it"
            )
        if len(mine) >= limits.per_address:
            raise AtlasJobsFull(
                f"at most {limits.per_address} atlas jobs of one address (its tabs together) "
                "run at once; wait for one to end"
            )
        kept = time.monotonic() - limits.min_keep
        ended = sorted((j for j in jobs if j.ended is not None and j.ended <= kept), key=_ended)
        if len(self._jobs) >= self.limits.max_jobs and not ended:
            raise AtlasJobsFull(
                f"the server has at most {self.limits.max_jobs} atlas jobs queued or running; "
                "retry when one has ended"
            )
        return ended

    def response(self, job: AtlasJob) -> AtlasJobResponse:
        """``job``'s state, with the jobs queued or running before it when it waits."""
        with self._lock:
            before = self._before(job)
        return job.response(len(before), sum(j.status == "running" for j in before))

    def _before(self, job: AtlasJob) -> list[AtlasJob]:
        """The active jobs ahead of ``job``: the running ones and those queued before it (the
        queue is served in the order the jobs were started). Under the lock."""
        ahead, earlier = [], True
        for other in self._jobs.values():
            earlier = earlier and other is not job
            if other is not job and (other.status == "running" or (earlier and other.active)):
                ahead.append(other)
        return ahead

    def get(self, job_id: str) -> AtlasJob:
        self.sweep()
        with self._lock:
            job = self._jobs.get(job_id)
        if job is None:
            raise AtlasJobNotFound(job_id, self._missing(job_id))
        return job

    def _missing(self, job_id: str) -> str:
        """Why no job has the id ``job_id``."""
        if job_id.startswith(self.run):
            return (
                f"it was cancelled, or it ended and was dropped ({self.limits.keep_for:g} s "
                f"after, or sooner to make room: the server keeps {self.limits.max_jobs} jobs)"
            )
        if re.fullmatch(r"[0-9a-f]{6}[A-Za-z0-9_-]{16}", job_id):
            return (
                "the server restarted since it was started, and atlas jobs live in the "
                "server's memory: start it again"
            )
        return "no job of this server has had this id"

    def cancel(self, job_id: str) -> None:
        """Stop the job (after the chunk it is on) and drop it; its slot goes at once to the
        next queued job (the chunks in flight end in the workers meanwhile, their results
        dropped), not after those chunks."""
        job = self.get(job_id)
        job.cancel.set()
        with self._lock:
            self._jobs.pop(job_id, None)
        self._release(job)

    def cancel_session(self, session: str) -> None:
        """Cancel the jobs a dashboard session started (it ended: nobody follows them)."""
        with self._lock:
            ids = [j.id for j in self._jobs.values() if j.session == session]
        for job_id in ids:
            with contextlib.suppress(AtlasJobNotFound):  # (ended meanwhile)
                self.cancel(job_id)

    def _release(self, job: AtlasJob) -> None:
        """Give back ``job``'s slot if it still holds it."""
        with self._lock:
            held, job.holds_slot = job.holds_slot, False
        if held:
            self._slots.release()

    def sweep(self) -> None:
        """Drop the jobs that ended more than ``keep_for`` seconds ago."""
        now = time.monotonic()
        with self._lock:
            for job in [j for j in self._jobs.values() if j.ended is not None]:
                if now - job.ended > self.limits.keep_for:  # type: ignore[operator]
                    del self._jobs[job.id]

    def close(self) -> None:
        """Cancel every job."""
        with self._lock:
            for job in self._jobs.values():
                job.cancel.set()
            self._jobs.clear()

    def _run(self, job: AtlasJob) -> None:
        while True:  # first come, first served
            if job.cancel.is_set():
                return self._end(job, "cancelled")
            with self._lock:
                first = not any(j.status == "queued" for j in self._before(job))
            if first and self._slots.acquire(timeout=0.2):
                break
            if not first:
                job.cancel.wait(0.2)
        job.holds_slot = True
        try:
            job.status = "running"
            job.started = time.monotonic()
            deadline = job.started + self.limits.max_seconds
            stop = lambda: job.cancel.is_set() or time.monotonic() > deadline  # noqa: E731

            def progress(done: float, _total: float) -> None:
                job.runs_done = int(done)

            backend = None if self._pool is None else PoolBackend(self._pool)
            res = run_atlas(
                job.plan,
                backend,
                progress=ProgressCallbacks(on_advance=progress, is_cancelled=stop),
                keep_leg_ends=job.request.leg_ends,
            )
            curve = job.plan.manifolds[0] if job.plan.manifolds else None  # (explicit starts)
            arc, period = ((), None) if curve is None else (curve.arc, curve.period)
            job.atlas, job.result = res, result_document(res, arc, job.request.leg_ends, period)
            self._end(job, "done")
        except RunCancelled:
            if job.cancel.is_set():
                self._end(job, "cancelled")
            else:
                job.error = (
                    f"starts: the atlas reached the server's time limit of "
                    f"{self.limits.max_seconds:g} s after {job.runs_done} of {job.plan.size} "
                    "runs; ask for fewer starts or cycles or a lower max_iterations (or run "
                    "`jik atlas` for larger atlases)"
                )
                self._end(job, "failed")
        except Exception as error:  # (a job's failure is its result, read by GET)
            job.error = f"{type(error).__name__}: {error}"
            self._end(job, "failed")
        finally:
            self._release(job)

    @staticmethod
    def _end(job: AtlasJob, status: Status) -> None:
        job.status = status
        job.ended = time.monotonic()


__all__ = ["AtlasJobNotFound", "AtlasJobs", "AtlasJobsFull"]
