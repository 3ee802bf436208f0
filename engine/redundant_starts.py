"""Starts for an atlas of a robot with more than one degree of redundancy (p - r > 1), whose
self-motion manifold k(x) = k(x0) is not a curve that :mod:`jik.engine.self_motion` can trace:
x0 and points reached from it along random directions of the null space of J(x0), eq. (4),
projected back onto the manifold."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .exceptions import InvalidInputError
from .inverses import require_kinematics
from .kinematics import Kinematics
from .self_motion import project
from .validation import FloatArray, as_box, check_seed, positive, within

#: Starts on a self-motion manifold lie within this fraction of the box's width around x0.
START_SPREAD = 0.15


def manifold_starts(
    kinematics: Kinematics,
    x0,
    n: int,
    box: Sequence[Sequence[float]],
    spread: float = START_SPREAD,
    seed: int = 0,
) -> FloatArray:
    """Starts for an atlas on the self-motion manifold k(x) = k(x0) of a robot with p - r > 1,
    where it is not a curve (:func:`jik.engine.atlas.plan_atlas` then takes explicit
    ``starts``): x0 first, then farther and farther.

    Parameters
    ----------
    kinematics : Kinematics
    x0 : array_like, shape (p,)
        The first start, within ``box``.
    n : int
        Starts asked for (1 to 10^5), x0 among them.
    box : sequence of p (low, high)
        The configurations allowed (the robot's ``x_range``); starts outside are left out.
    spread : float
        The farthest step, as a fraction (0, 1] of the box's narrowest finite width.
    seed : int
        The random directions' seed, 0 to 2^63 - 1: the same starts for the same arguments.

    Returns
    -------
    ndarray, shape (m, p), m <= n
        x0 plus a step along a random direction of the null space of J(x0), the step growing
        from 0 to ``spread`` of the box, projected back onto k(x) = k(x0) by Newton steps with
        the pseudoinverse (8) (:func:`project`); those that leave the box or do not reach the
        manifold (task error 1e-10) are left out.
    """
    x0 = require_kinematics(kinematics).check(x0, "x0")
    if x0.shape != (kinematics.p,):
        raise InvalidInputError(f"x0 must be one configuration of {kinematics.p} numbers", "x0")
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= 10**5:
        raise InvalidInputError(f"n must be an integer from 1 to 100000, got {n!r}", "n")
    lim = as_box(box, kinematics.p, finite=False)
    # (x0 is the first start: outside the box, every start would be left out)
    within(x0, lim, "x0", kinematics.variable_names, "the box, where the starts lie", "x0")
    spread, seed = positive(spread, "spread"), check_seed(seed)
    if spread > 1:
        raise InvalidInputError(
            f"spread must be a fraction of the box, in (0, 1], got {spread:g}", "spread"
        )
    y0 = kinematics.forward(x0)
    J = np.asarray(kinematics.jacobian(x0), dtype=float)
    null = np.eye(kinematics.p) - np.linalg.pinv(J) @ J
    d = np.random.default_rng(seed).standard_normal((n, kinematics.p)) @ null
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)
    widths = lim[:, 1] - lim[:, 0]
    width = float(np.min(widths[np.isfinite(widths)], initial=2 * np.pi))
    step = spread * width * np.linspace(0.0, 1.0, n)
    X = project(kinematics, x0 + step[:, None] * d, y0)
    X[0] = x0
    ok = (np.linalg.norm(kinematics.forward(X) - y0, axis=1) < 1e-10) & np.all(
        (X >= lim[:, 0]) & (X <= lim[:, 1]), axis=1
    )
    return X[ok]
