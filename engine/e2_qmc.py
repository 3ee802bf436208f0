"""E2, eq. (18), of a map over many joints by a quasi-Monte Carlo rule, beside single joints.

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
``TotalDegreeSynthesis.single_joint`` gives them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from .augmentations import AugmentingMap
from .exceptions import InvalidInputError, KinematicSingularityError
from .functionals import Region, check_region
from .inverses import require_kinematics
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
        ``{"E2": float or None (h undefined at some node), "undefined_points": int,
        "single_joint": {name: {"sign", "e2"}} (empty for p - r >= 2), "nodes", "seed",
        "frame_axes": 1-based list, or None for one degree of redundancy}``.
    """
    kinematics = require_kinematics(kinematics)
    maps = require_maps(kinematics, amap, "E2", "amap")
    box, fix = check_region(kinematics, region, fixed)
    progress = check_progress(progress)
    nodes = count(nodes, "nodes", 64, MAX_NODES)
    if nodes & (nodes - 1):
        raise InvalidInputError(f"nodes must be a power of two, got {nodes}", "nodes")
    axes = frame_axes_of(kinematics, box, fix, frame_axes)
    k_red = len(maps)
    names = kinematics.names
    idx = np.array([names.index(n) for n in box])
    lo, hi = np.array(list(box.values()), dtype=float).T
    t = sobol_nodes(len(box), nodes, seed)
    base = np.array([fix.get(n, 0.0) for n in names])
    total, undefined = 0.0, 0
    c0, diag, load = 0.0, np.zeros(len(idx)), np.zeros(len(idx))
    for start in range(0, nodes, CHUNK):
        check_cancelled(progress, "the E2 rule was cancelled")
        x = np.broadcast_to(base, (len(t[start : start + CHUNK]), base.size)).copy()
        x[:, idx] = 0.5 * (lo + hi) + 0.5 * (hi - lo) * t[start : start + CHUNK]
        m = kinematics.manipulability(x)
        if np.any(m < 1e-9):
            raise KinematicSingularityError(
                "the region contains a kinematic singularity", x[int(np.argmin(m))], "region"
            )
        K, Jp = kernel_frame(kinematics, x, axes)  # (n, p, p - r)
        P = Jp @ np.swapaxes(Jp, -1, -2) + K @ np.swapaxes(K, -1, -2)
        dh, bad = maps_gradient(maps, x)  # (n, p - r, p)
        undefined += int(np.count_nonzero(bad))
        quad = np.einsum("nik,nkl,nil->n", dh, P, dh)
        integrand = m * (quad - 2.0 * np.einsum("nik,nki->n", dh, K) + k_red)
        total += float(np.sum(integrand[~bad]))
        c0 += float(m.sum())
        diag += np.einsum("n,nk->k", m, P[:, idx, idx])
        load += np.einsum("n,nk->k", m, K[:, idx, 0])
        if progress is not None:
            progress.advance(min(start + CHUNK, nodes) / nodes, 1.0)
    w = float(np.prod(hi - lo)) / nodes
    sign = np.where(load >= 0, 1.0, -1.0)
    single = {
        name: {"sign": float(sign[j]), "e2": float(w * (c0 + diag[j] - 2.0 * sign[j] * load[j]))}
        for j, name in enumerate(box)
        if k_red == 1
    }
    e2 = None if undefined else float(w * total)
    return {
        "E2": e2,
        "undefined_points": undefined,
        "single_joint": single,
        "nodes": nodes,
        "seed": seed,
        "frame_axes": None if axes is None else [a + 1 for a in axes],
    }
