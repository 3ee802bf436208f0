"""The result of an E2 synthesis over all the joint variables of a box
(:func:`jik.engine.synthesis_nd.synthesize_e2_nd`): its maps, E2 and their convergence."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .exceptions import InvalidInputError
from .exports import Columns
from .total_degree import TotalDegreeMap
from .validation import FloatArray


@dataclass(frozen=True, repr=False)
class TotalDegreeSynthesis(Columns):
    """The E2-optimal map(s) on a box and what they achieve.

    Attributes
    ----------
    maps : tuple of TotalDegreeMap
        One per degree of redundancy (h_1, ..., h_(p-r)).
    e2 : float
        E2 of the maps on the fitting rule (the Ritz value).
    e2_check : float
        E2 of the maps on an independent scrambled Sobol rule of as many nodes: the value to
        trust; its distance to ``e2`` measures the quadrature error.
    convergence : list of dict
        ``{"degree", "nodes", "unknowns", "e2"}``: the Ritz value with the degree at all the nodes,
        then with the nodes (the leading 2^k nodes of the rule, 2^k >= 1024 and twice the
        unknowns) at the final degree.
    single_joint : dict name -> dict
        E2 of the common choice h = s x_j for each joint of the region, with the better sign s
        (one degree of redundancy only; empty otherwise).
    region, fixed : dict
    degree, nodes, seed : int
    frame_axes : tuple of int
        The 1-based joints whose axes fix the kernel frame (p - r >= 2), as the synthesis's
        ``frame_axes`` parameter takes them; empty for one degree of redundancy.
    """

    maps: tuple[TotalDegreeMap, ...]
    e2: float
    e2_check: float
    convergence: list[dict]
    single_joint: dict[str, dict]
    region: dict[str, tuple[float, float]]
    fixed: dict[str, float]
    degree: int
    nodes: int
    seed: int
    frame_axes: tuple[int, ...] = field(default=())

    @property
    def augmenting_map(self) -> TotalDegreeMap:
        """The map, for one degree of redundancy."""
        if len(self.maps) != 1:
            raise InvalidInputError(f"there are {len(self.maps)} maps; use .maps")
        return self.maps[0]

    def __repr__(self) -> str:
        return (
            f"TotalDegreeSynthesis(e2={self.e2:.6g}, e2_check={self.e2_check:.6g}, "
            f"maps={len(self.maps)}, variables={len(self.region)}, degree={self.degree}, "
            f"unknowns={len(self.maps[0].index)}, nodes={self.nodes}"
            f"{f', frame_axes={list(self.frame_axes)}' if self.frame_axes else ''})"
        )

    def columns(self) -> dict[str, FloatArray]:
        """A row per Ritz value computed (:attr:`convergence`), the last the result:
        ``degree``, ``nodes``, ``unknowns``, ``e2``."""
        return {
            key: np.array([row[key] for row in self.convergence])
            for key in ("degree", "nodes", "unknowns", "e2")
        }

    def as_dict(self) -> dict:
        """JSON-friendly summary (without the coefficients)."""
        return {
            "e2": self.e2,
            "e2_check": self.e2_check,
            "degree": self.degree,
            "nodes": self.nodes,
            "seed": self.seed,
            "unknowns": len(self.maps[0].index),
            "region": {k: list(v) for k, v in self.region.items()},
            "fixed": dict(self.fixed),
            "convergence": list(self.convergence),
            "single_joint": dict(self.single_joint),
            "frame_axes": list(self.frame_axes),
        }
