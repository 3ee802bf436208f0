"""A time budget for one step of a computation in a compute worker: building a robot's formulas.

A worker's whole computation is bounded by the pool's time limit (the worker is killed when it
overruns); that limit cannot say which step overran. :func:`time_budget` bounds one step within
it, in the worker's main thread, by an interval timer (SIGALRM): the step is interrupted between
two Python bytecodes (sympy is pure Python) and the request refused naming the step's field.
Where there is no such timer (a thread other than the main one, a platform without SIGALRM) the
step runs bounded by the pool's limit alone.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

from .exceptions import RequestError
from .settings import settings

#: The build budget of this process [s], set by a compute worker's entry from its pool's
#: settings (None: the environment's, ``Settings.build_budget``).
BUILD_SECONDS: float | None = None


def build_seconds() -> float:
    """Seconds a robot's formulas may take to build here (:data:`BUILD_SECONDS`)."""
    return settings().build_budget if BUILD_SECONDS is None else BUILD_SECONDS


class _Expired(BaseException):
    """The budget ran out (a BaseException: library code's ``except Exception`` lets it pass)."""


def _expired(signum: int, frame: object) -> None:
    raise _Expired


@contextlib.contextmanager
def time_budget(seconds: float, field: str, what: str) -> Iterator[None]:
    """Run the block within ``seconds`` (0 or less: no budget); past them, :class:`RequestError`
    naming ``field`` (the request's field the block works on, ``"robot"``) and saying that
    ``what`` ("building the robot's formulas") took too long."""
    timer = getattr(signal, "setitimer", None)
    if seconds <= 0 or timer is None or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGALRM, _expired)
    try:
        try:
            signal.setitimer(signal.ITIMER_REAL, seconds)
            yield
        finally:  # (a timer that fires in here has fired once: it is caught below)
            signal.setitimer(signal.ITIMER_REAL, 0)
    except _Expired:
        raise RequestError(
            field,
            f"{what} took longer than {seconds:g} s and was stopped; give shorter formulas "
            "or fewer nested functions",
        ) from None
    finally:
        signal.signal(signal.SIGALRM, previous)
