"""The time budget of one step in a compute worker (:mod:`jik.app.compute.budget`)."""

from __future__ import annotations

import signal
import threading
import time

import pytest

from jik.app.compute.budget import time_budget
from jik.app.compute.exceptions import RequestError


def test_a_step_past_its_budget_is_stopped_naming_its_field():
    """A pure-Python loop is interrupted after its budget, even inside ``except Exception``;
    the alarm handler in force before is restored."""
    before = signal.getsignal(signal.SIGALRM)
    start = time.monotonic()
    with pytest.raises(RequestError, match=r"robot: building it took longer than 0\.2 s") as info:
        with time_budget(0.2, "robot", "building it"):
            while True:
                try:
                    sum(range(1000))
                except Exception:  # (library code that swallows errors)
                    pass
    assert info.value.field == "robot"
    assert time.monotonic() - start < 5.0
    assert signal.getsignal(signal.SIGALRM) is before


def test_a_step_within_its_budget_or_off_the_main_thread_runs_unbounded():
    with time_budget(5.0, "robot", "building it"):
        pass
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    done = []

    def other() -> None:
        with time_budget(0.01, "robot", "building it"):
            time.sleep(0.1)
        done.append(True)

    t = threading.Thread(target=other)
    t.start()
    t.join()
    assert done == [True]
