"""The extended Jacobian inverse for p - r > 1 degrees of redundancy, eqs. (9)-(12).

The paper treats one degree of redundancy; with p - r of them the augmenting map is a vector
h = (h_1, ..., h_(p-r)), the extended Jacobian is [J; dh_1; ...; dh_(p-r)] (p x p) and its inverse's
first r columns are the extended inverse J^E#: J J^E# = I_r and dh_i J^E# = 0 for every i, so
each h_i is constant along eq. (7) and the algorithm is repeatable, as for p - r = 1. E1 (13) and
E2 (18) of such a vector (:mod:`jik.engine.functionals`) and its E2 synthesis
(:mod:`jik.engine.synthesis_nd`) are derived in ``docs/e2-vector.md``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .augmentations import AugmentingMap
from .exceptions import AlgorithmicSingularityError, SingularConfigurationError
from .inverses import (
    SINGULAR_EXTENDED,
    Inverse,
    extended_singularity,
    require_kinematics,
    solve_extended,
)
from .kernel_frame import maps_gradient, require_maps
from .kinematics import Kinematics
from .validation import FloatArray


class VectorExtendedInverse(Inverse):
    """Extended Jacobian inverse (11) with a vector of p - r augmenting maps (see the module).

    Parameters
    ----------
    kinematics : Kinematics
        With p > r.
    augmenting_maps : sequence of AugmentingMap
        Exactly p - r maps on R^p; their gradients are the extra rows of the extended Jacobian.
    """

    name = "extended"

    def __init__(self, kinematics: Kinematics, augmenting_maps: Sequence[AugmentingMap]) -> None:
        kinematics = require_kinematics(kinematics)
        maps = require_maps(kinematics, augmenting_maps, "the extended inverse", "augmenting_maps")
        self.kinematics = kinematics
        self.augmenting_maps = maps

    @property
    def parameters(self) -> dict[str, object]:
        return {"maps": self.augmenting_maps}

    def augmenting_value(self, x: FloatArray) -> FloatArray:
        """h(x) = (h_1, ..., h_(p-r)), shape (..., p - r); NaN where a map is undefined."""
        return np.stack([m.value_masked(x)[0] for m in self.augmenting_maps], axis=-1)

    def _extended(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """[J; dh] (..., p, p) (undefined rows zeroed) and where some h_i is undefined."""
        dh, undefined = maps_gradient(self.augmenting_maps, x)  # (..., p - r, p)
        dh = np.where(undefined[..., None, None], 0.0, dh)
        return np.concatenate([self.kinematics.jacobian_unchecked(x), dh], axis=-2), undefined

    def map_undefined(self, x: FloatArray) -> FloatArray:
        return self._extended(x)[1]

    def apply_masked(self, x: FloatArray, e: FloatArray) -> tuple[FloatArray, FloatArray]:
        Jbar, undefined = self._extended(x)
        return solve_extended(Jbar, e, undefined)

    def matrix(self, x: FloatArray) -> FloatArray:
        """J^E#(x): the first r columns of [J; dh]^(-1), shape (..., p, r)."""
        x = self.kinematics.check(x)
        Jbar, undefined = self._extended(x)
        bad = undefined | (extended_singularity(Jbar) < SINGULAR_EXTENDED)
        self._raise_if(x, bad)
        r, p = self.kinematics.r, self.kinematics.p
        rhs = np.zeros((*Jbar.shape[:-2], p, r))
        rhs[..., :r, :] = np.eye(r)
        return np.linalg.solve(Jbar, rhs)

    def singular_error(self, x: FloatArray) -> SingularConfigurationError:
        at = np.asarray(x, dtype=float)[None]
        undefined = [
            f"h_{i + 1} = {m!r}"
            for i, m in enumerate(self.augmenting_maps)
            if m.gradient_masked(at)[1][0]
        ]
        if undefined:
            maps = ", ".join(undefined)
            which = f"map {maps} is" if len(undefined) == 1 else f"maps {maps} are"
            return AlgorithmicSingularityError(
                f"the augmenting {which} undefined (the gradient cannot be evaluated), so the "
                "extended Jacobian inverse (11) is undefined; choose another start or other maps",
                x,
            )
        return AlgorithmicSingularityError(
            f"the extended Jacobian [J; dh_1; ...; dh_{len(self.augmenting_maps)}] of "
            f"{self.kinematics.name} is singular (algorithmic singularity, eq. (11)); choose "
            "another start or other maps",
            x,
        )
