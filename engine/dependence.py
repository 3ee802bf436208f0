"""Which joint variables a robot's Jacobian and an augmenting map ignore.

E1 (13) and E2 (18) integrate functions of J(x), h(x) and dh(x) over a region; a variable x_k
that none of them depends on changes neither the integrands nor a slice of h, so a region need
not span it and a value held fixed there says nothing (Manipulator 2's x1: J(x3), and its cubic
(38) is h(x2, x3)).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .exceptions import JikError
from .inverses import require_kinematics, require_map
from .kinematics import Kinematics
from .validation import as_box

#: Seeded points of the box probed, and the shift of each variable (a fraction of its width).
SAMPLES, SHIFT = 8, 0.371


def inert_variables(kinematics: Kinematics, amap, box: Sequence[Sequence[float]]) -> frozenset[int]:
    """The joint variables x_k (indices from 0) that neither J nor h nor dh depends on.

    Parameters
    ----------
    kinematics : Kinematics
    amap : AugmentingMap or None
        The map h (eq. (9)); None (a vector of maps, p - r > 1) probes nothing.
    box : sequence of p (low, high)
        Where to probe.

    Returns
    -------
    frozenset of int
        Shifting x_k by :data:`SHIFT` of its width at :data:`SAMPLES` seeded points of ``box``
        leaves J, h and dh bitwise unchanged (NaN where undefined included): an expression
        without x_k evaluates the same, one that merely cancels it would not and counts as
        dependent. Empty for a map that solves a problem per point
        (:attr:`~jik.engine.augmentations.AugmentingMap.solves_per_point`), for None, and for
        a map that cannot be evaluated at the probes (every variable then counts).

    Raises
    ------
    InvalidInputError
        ``box`` is not p finite pairs (low, high).
    """
    kinematics = require_kinematics(kinematics)
    amap = None if amap is None else require_map(amap, kinematics, "amap")
    lo, hi = as_box(box, kinematics.p).T
    if amap is None or getattr(amap, "solves_per_point", False):
        return frozenset()
    X = np.random.default_rng(0).uniform(lo, hi, (SAMPLES, len(lo)))

    def probe(x):
        with np.errstate(all="ignore"):
            return (kinematics.jacobian(x), amap.value_masked(x)[0], amap.gradient_masked(x)[0])

    inert = set()
    try:
        at = probe(X)
        for k in range(len(lo)):
            shifted = X.copy()
            shifted[:, k] += SHIFT * (hi[k] - lo[k])
            again = probe(shifted)
            if all(np.array_equal(a, b, equal_nan=True) for a, b in zip(at, again, strict=True)):
                inert.add(k)
    except (JikError, ValueError, ArithmeticError):  # a map that cannot be probed: all matter
        return frozenset()
    return frozenset(inert)
