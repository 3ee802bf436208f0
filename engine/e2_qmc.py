"""E1 (13) and E2 (18) of a map over many joints by a quasi-Monte Carlo rule, E2 beside single
joints.

A tensor Gauss rule over d variables has n^d nodes (12^7 = 3.6e7 for a 7-joint arm): jik's
:mod:`jik.engine.functionals` stops at three. E2 is the integral over the region of
(docs/e2-vector.md, eq. (19); for one degree of redundancy dh is a row and K a column)

    m(x) tr(dh P dh^T - 2 dh K + I),    P = J^# J^#T + K K^T,

which :func:`e2_qmc` takes as the mean over a scrambled Sobol rule (``scipy.stats.qmc``) of N
nodes times the region's volume: the rule and the nodes of
:func:`jik.engine.synthesis_nd.synthesize_e2_nd` (seed 1 is its independent check rule,
``e2_check``), in the same kernel frame K (:mod:`jik.engine.kernel_frame`) for p - r >= 2. For
one degree of redundancy, with it, E2 of the common choice h = s x_j (one joint held, s = +-1 the
better sign: the one of the integral of m K_j) for each joint of the region, as
``TotalDegreeSynthesis.single_joint`` gives them. :func:`e1_qmc` takes E1 on the same nodes.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from .augmentations import AugmentingMap
from .exceptions import InvalidInputError, KinematicSingularityError
from .functionals import Region, check_region, e1_integrand
from .inverses import extended_determinant, require_kinematics
from .kernel_frame import frame_axes_of, kernel_frame, maps_gradient, require_maps
from .kinematics import Kinematics
from .progress import Progress, check_cancelled, check_progress
from .synthesis_nd import CHUNK, MAX_NODES
from .total_degree import sobol_nodes
from .validation import count


def e2_qmc(
    kinematics: Kinematics,
    amap: AugmentingMap | Sequence[AugmentingMap],
    region: Region,
    *,
    fixed: Mapping[str, float] | None = None,
    nodes: int = 2**13,
    seed: int = 1,
    frame_axes: Sequence[int] | None = None,
    progress: Progress | None = None,
) -> dict:
    """E2 (18) of ``amap`` on ``region`` by a scrambled Sobol rule, and for one degree of
    redundancy E2 of each h = s x_j.

    Parameters
    ----------
    kinematics : Kinematics
        With p > r.
    amap : AugmentingMap, or a sequence of p - r of them
        The map h, a vector of maps for p - r >= 2 (their gradients,
        :meth:`~jik.engine.augmentations.AugmentingMap.gradient_masked`).
    region : mapping name -> (lo, hi)
        The joint variables integrated over; the others are held at ``fixed`` (default
        :func:`jik.engine.kinematics.held_values`: the robot's home).
    nodes : int
        A power of two (a Sobol rule's balance needs it).
    seed : int
        Seed of the scrambling (the result is a deterministic function of it).
    frame_axes : sequence of int, optional
        For p - r >= 2, the joints (1-based) that fix the kernel frame
        (:func:`~jik.engine.kernel_frame.frame_axes_of`; default the best conditioned).
    progress : Progress, optional
        Told the fraction of the nodes done (``advance``); polled between chunks of nodes
        (``cancelled``: :class:`~jik.engine.exceptions.RunCancelled`).

    Returns
    -------
    dict
        ``{"E2": float or None (h undefined at some node), "E2_half": the same rule's value on
        its first half of the nodes (a Sobol rule of nodes / 2; :func:`error_estimate`),
        "undefined_points": int, "single_joint": {name: {"sign", "e2"}} (empty for
        p - r >= 2), "nodes", "seed", "frame_axes": 1-based list, or None for one degree of
        redundancy}``.
    """
    kinematics = require_kinematics(kinematics)
    maps = require_maps(kinematics, amap, "E2", "amap")
    rule = _Rule(kinematics, region, fixed, nodes, seed, "E2")
    axes = frame_axes_of(kinematics, rule.box, rule.fix, frame_axes)
    k_red = len(maps)
    total, half, undefined = 0.0, 0.0, 0
    c0, diag, load = 0.0, np.zeros(len(rule.idx)), np.zeros(len(rule.idx))
    for first, x, m in rule.chunks(progress):
        K, Jp = kernel_frame(kinematics, x, axes)  # (n, p, p - r)
        P = Jp @ np.swapaxes(Jp, -1, -2) + K @ np.swapaxes(K, -1, -2)
        dh, bad = maps_gradient(maps, x)  # (n, p - r, p)
        undefined += int(np.count_nonzero(bad))
        quad = np.einsum("nik,nkl,nil->n", dh, P, dh)
        integrand = m * (quad - 2.0 * np.einsum("nik,nki->n", dh, K) + k_red)
        total += float(np.sum(integrand[~bad]))
        half += float(np.sum(integrand[~bad & first]))
        c0 += float(m.sum())
        diag += np.einsum("n,nk->k", m, P[:, rule.idx, rule.idx])
        load += np.einsum("n,nk->k", m, K[:, rule.idx, 0])
    w = rule.weight
    sign = np.where(load >= 0, 1.0, -1.0)
    single = {
        name: {"sign": float(sign[j]), "e2": float(w * (c0 + diag[j] - 2.0 * sign[j] * load[j]))}
        for j, name in enumerate(rule.box)
        if k_red == 1
    }
    e2 = None if undefined else float(w * total)
    return {
        "E2": e2,
        "E2_half": None if undefined else float(2.0 * w * half),
        "undefined_points": undefined,
        "single_joint": single,
        "nodes": rule.nodes,
        "seed": seed,
        "frame_axes": None if axes is None else [a + 1 for a in axes],
    }


def e1_qmc(
    kinematics: Kinematics,
    amap: AugmentingMap | Sequence[AugmentingMap],
    region: Region,
    *,
    fixed: Mapping[str, float] | None = None,
    nodes: int = 2**13,
    seed: int = 1,
    progress: Progress | None = None,
) -> dict:
    """E1 (13) of ``amap`` on ``region`` by the scrambled Sobol rule of :func:`e2_qmc` (the
    same parameters, no frame: E1 does not depend on it).

    The integrand ||J^P# - J^E#||_F^2 = tr(W W^T), W = (dh K)^(-1) dh J^P# (eq. (14)), blows up
    where det [J; dh] = +-det(dh K) sqrt(det J J^T) vanishes; E1 is infinite (``divergent``)
    when that determinant is zero at a node (:func:`~jik.engine.inverses.extended_determinant`)
    or of both signs among them (a zero between), as the Gauss rule of
    :func:`~jik.engine.functionals.error_functional_e1` decides at its points (without the
    box's faces: a zero there between nodes is found by the sign change).

    Returns
    -------
    dict
        ``{"E1": float, inf when divergent, or None (h undefined at some node; then not
        "divergent" either), "E1_half": the same on the rule's first half of the nodes
        (:func:`error_estimate`), "divergent", "undefined_points", "min_abs_dh_k":
        min |det(dh K)| over the nodes, "nodes", "seed"}``.
    """
    kinematics = require_kinematics(kinematics)
    maps = require_maps(kinematics, amap, "E1", "amap")
    rule = _Rule(kinematics, region, fixed, nodes, seed, "E1")
    total, half, undefined, singular = 0.0, 0.0, 0, False
    lo_det, hi_det, least = np.inf, -np.inf, np.inf
    for first, x, m in rule.chunks(progress):
        J = kinematics.jacobian(x)
        dh, bad = maps_gradient(maps, x)
        undefined += int(np.count_nonzero(bad))
        det, rank_loss = extended_determinant(J, dh)
        singular |= bool(np.any(rank_loss & ~bad))
        if np.any(~bad):  # (|det(dh K)| = |det [J; dh]| / m, whatever the frame)
            lo_det, hi_det = min(lo_det, np.min(det[~bad])), max(hi_det, np.max(det[~bad]))
            least = min(least, float(np.min(np.abs(det[~bad]) / m[~bad])))
        ok = ~bad & ~rank_loss
        integrand = e1_integrand(J[ok], dh[ok])
        total += float(np.sum(integrand))
        half += float(np.sum(integrand[first[ok]]))
    divergent = not undefined and (singular or bool(lo_det < 0.0 < hi_det))
    e1 = None if undefined else (np.inf if divergent else float(rule.weight * total))
    return {
        "E1": e1,
        "E1_half": e1 if e1 is None or divergent else float(2.0 * rule.weight * half),
        "divergent": divergent,
        "undefined_points": undefined,
        "min_abs_dh_k": float(least),
        "nodes": rule.nodes,
        "seed": seed,
    }


class _Rule:
    """The scrambled Sobol rule of ``nodes`` (a power of two) on ``region``, the others held at
    ``fixed``: its configurations and manipulability by chunks of nodes (:meth:`chunks`), the
    weight of a node (the region's volume / nodes); ``what`` names the functional."""

    def __init__(self, kinematics, region, fixed, nodes, seed, what: str) -> None:
        self.kin, self.what = kinematics, what
        self.box, self.fix = check_region(kinematics, region, fixed)
        self.nodes = count(nodes, "nodes", 64, MAX_NODES)
        if self.nodes & (self.nodes - 1):
            raise InvalidInputError(f"nodes must be a power of two, got {self.nodes}", "nodes")
        names = kinematics.names
        self.idx = np.array([names.index(n) for n in self.box])
        self.lo, self.hi = np.array(list(self.box.values()), dtype=float).T
        self.t = sobol_nodes(len(self.box), self.nodes, seed)
        self.base = np.array([self.fix.get(n, 0.0) for n in names])
        self.weight = float(np.prod(self.hi - self.lo)) / self.nodes

    def chunks(self, progress: Progress | None):
        """(first, x, m) per chunk of nodes, ``first`` marking the nodes of the rule's first
        half (their own Sobol rule of nodes / 2); told ``progress`` the fraction done, polled
        for a cancel (:class:`~jik.engine.exceptions.RunCancelled`); a kinematic singularity in
        the region (m < 1e-9 at a node) is a KinematicSingularityError."""
        progress = check_progress(progress)
        for start in range(0, self.nodes, CHUNK):
            check_cancelled(progress, f"the {self.what} rule was cancelled")
            t = self.t[start : start + CHUNK]
            x = np.broadcast_to(self.base, (len(t), self.base.size)).copy()
            x[:, self.idx] = 0.5 * (self.lo + self.hi) + 0.5 * (self.hi - self.lo) * t
            m = self.kin.manipulability(x)
            if np.any(m < 1e-9):
                raise KinematicSingularityError(
                    "the region contains a kinematic singularity", x[int(np.argmin(m))], "region"
                )
            yield start + np.arange(len(t)) < self.nodes // 2, x, m
            if progress is not None:
                progress.advance(min(start + CHUNK, self.nodes) / self.nodes, 1.0)


def error_estimate(value: float | None, half: float | None) -> float | None:
    """An estimate of the size of the quadrature error of a Sobol rule's ``value``: its
    difference from the same rule on its first half of the nodes, ``half`` (:func:`e1_qmc`,
    :func:`e2_qmc`). Where the rule converges (its error shrinks as the nodes double) this is
    about the half rule's error, mostly more than the whole rule's; an estimate, not a bound
    (``docs/e2-vector.md`` compares it with the error against a rule of 16 times the nodes).
    None where either value is not finite."""
    if value is None or half is None or not (np.isfinite(value) and np.isfinite(half)):
        return None
    return abs(value - half)
