"""Fair turns for the sessions' computations: at most ``n`` run at once, in the order they
asked (a session that changes its state again waits behind the others, not before them)."""

from __future__ import annotations

import collections
import contextlib
import threading
from collections.abc import Iterator


class FairSlots:
    """``n`` slots handed out first come, first served."""

    def __init__(self, n: int) -> None:
        if n < 1:
            raise ValueError(f"n must be >= 1, got {n}")
        self.n = n
        self._cond = threading.Condition()
        self._queue: collections.deque[object] = collections.deque()
        self._busy = 0

    @contextlib.contextmanager
    def slot(self) -> Iterator[None]:
        """Hold a slot for the block (waiting for the turn of this thread's request)."""
        me = object()
        with self._cond:
            self._queue.append(me)
            self._cond.wait_for(lambda: self._queue[0] is me and self._busy < self.n)
            self._queue.popleft()
            self._busy += 1
            self._cond.notify_all()
        try:
            yield
        finally:
            with self._cond:
                self._busy -= 1
                self._cond.notify_all()
