"""The posture inverse with each run's own start as its rest, for a batch of runs at once.

An atlas (:mod:`jik.engine.atlas_run`) drives many starts x0 around one closed path. With the
posture inverse's rest fixed (the robot's home), each run is pulled toward that one posture and
the atlas measures the pull, not the drift of sec. 5.2.1; with rest = x0 of each run (as a
single run's default) the pull keeps each run near its own start.

The solvers pass subsets of a batch's members to :meth:`Inverse.apply_masked`, so a rest per
member rides along in the state: a run's configuration is (x, x_rest) in R^(2p), with the
kinematics k(x) of the first half (:class:`RestCarrying`, J = [J(x) 0]) and the velocity
(v, 0) of :class:`PostureAtStart`, v the posture inverse's (Liegeois 1977) with that member's
x_rest. The second half never changes (its velocity is exactly 0), so every batched solve of
eq. (7) keeps each member's rest, and ||(x, x_rest) - (x0, x0)|| = ||x - x0||.
"""

from __future__ import annotations

import numpy as np

from .exceptions import SingularConfigurationError
from .inverses import Inverse
from .kinematics import Kinematics
from .practical_inverses import PostureInverse
from .validation import FloatArray


class RestCarrying(Kinematics):
    """k(x, x_rest) = k(x) on R^(2p): the configuration carries its rest posture."""

    def __init__(self, inner: Kinematics) -> None:
        self.inner = inner
        self.name = inner.name  # type: ignore[misc]
        self.p, self.r = 2 * inner.p, inner.r

    def __repr__(self) -> str:
        return f"RestCarrying({self.inner!r})"

    def forward(self, x: FloatArray) -> FloatArray:
        return self.inner.forward_unchecked(x[..., : self.inner.p])

    def jacobian(self, x: FloatArray) -> FloatArray:
        J = self.inner.jacobian_unchecked(x[..., : self.inner.p])
        return np.concatenate([J, np.zeros_like(J)], axis=-1)


class PostureAtStart(Inverse):
    """The posture inverse ``posture`` on :class:`RestCarrying` states: (x, x_rest) moves by
    (v, 0), v = J# e - k ||e|| (I - J# J)(x_rest - x) of :class:`PostureInverse`."""

    def __init__(self, posture: PostureInverse) -> None:
        self.posture = posture
        self.name = posture.name
        self.kinematics = RestCarrying(posture.kinematics)

    def __repr__(self) -> str:
        return f"PostureAtStart({self.posture!r})"

    @property
    def parameters(self) -> dict[str, object]:
        return self.posture.parameters

    def apply_masked(self, x: FloatArray, e: FloatArray) -> tuple[FloatArray, FloatArray]:
        p = self.posture.kinematics.p
        v, bad = self.posture.pull(x[..., :p], e, x[..., p:])
        return np.concatenate([v, np.zeros_like(v)], axis=-1), bad

    def matrix(self, x: FloatArray) -> FloatArray:
        J = self.posture.matrix(x[..., : self.posture.kinematics.p])
        return np.concatenate([J, np.zeros_like(J)], axis=-2)

    def singular_error(self, x: FloatArray) -> SingularConfigurationError:
        return self.posture.singular_error(np.asarray(x)[..., : self.posture.kinematics.p])

    @staticmethod
    def carry(x0: FloatArray) -> FloatArray:
        """(x0, x0): each start with itself as its rest."""
        return np.concatenate([x0, x0], axis=-1)
