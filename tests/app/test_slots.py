"""Fair turns for the sessions' computations (jik.app.dashboard.offload)."""

from __future__ import annotations

import threading

import pytest

from jik.app.dashboard.offload import FairSlots


def test_at_most_n_hold_a_slot_and_turns_go_in_the_order_asked():
    slots = FairSlots(2)
    held, order, peak, busy = threading.Semaphore(0), [], [0], [0]
    release = threading.Event()
    lock = threading.Lock()

    def work(k: int) -> None:
        with slots.slot():
            with lock:
                order.append(k)
                busy[0] += 1
                peak[0] = max(peak[0], busy[0])
            held.release()
            release.wait(10)
            with lock:
                busy[0] -= 1

    first = [threading.Thread(target=work, args=(k,)) for k in (0, 1)]
    for t in first:
        t.start()
    assert held.acquire(timeout=10) and held.acquire(timeout=10)  # both slots taken
    waiting = []
    for k in (2, 3, 4):  # asked one after the other while both slots are held
        t = threading.Thread(target=work, args=(k,))
        t.start()
        waiting.append(t)
        while len(slots._queue) < k - 1:  # (its request is queued before the next one's)
            threading.Event().wait(0.001)
    release.set()
    for t in first + waiting:
        t.join(10)
    assert sorted(order[:2]) == [0, 1] and order[2:] == [2, 3, 4]
    assert peak[0] == 2


def test_slots_need_at_least_one():
    with pytest.raises(ValueError, match="n must be >= 1"):
        FairSlots(0)
