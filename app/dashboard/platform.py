"""The unicycle's platform paths q(t) of a run, computed for the iterations that are drawn."""

from __future__ import annotations

import operator

import numpy as np

#: Paths kept per run: the task panel and the scene draw a few spaced iterations.
KEPT = 256


class PlatformPaths:
    """q(t) on the time grid ``t`` for the controls of each iteration ``x`` (m, 4) of a run,
    indexed like an array of shape (m, T, 3): ``P[i]``, ``P[i, :, 0]``, ``P[-1]``, ``len(P)``.
    A path is computed (:meth:`jik.engine.unicycle.Unicycle.path`) when its iteration is first
    asked for, and kept: every path of a long discrete run (10^5 iterations) had taken
    gigabytes of the server's memory and minutes, for a dozen drawn."""

    def __init__(self, kinematics, x: np.ndarray, t: np.ndarray) -> None:
        self._kinematics, self._x, self._t = kinematics, np.asarray(x), np.asarray(t)
        self._kept: dict[int, np.ndarray] = {}

    def __len__(self) -> int:
        return len(self._x)

    @property
    def shape(self) -> tuple[int, int, int]:
        return len(self._x), len(self._t), 3

    def __getitem__(self, key):
        i, rest = (key[0], key[1:]) if isinstance(key, tuple) else (key, ())
        i = operator.index(i)
        i += len(self) if i < 0 else 0
        if not 0 <= i < len(self):
            raise IndexError(f"iteration {i} of a run of {len(self)}")
        path = self._kept.get(i)
        if path is None:
            path = self._kinematics.path(self._x[i], self._t)
            if len(self._kept) < KEPT:
                self._kept[i] = path
        return path[rest] if rest else path
