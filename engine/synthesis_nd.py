"""E2 synthesis of h over all the joint variables of a box: total-degree basis, QMC rule.

The tensor Ritz method of :mod:`jik.engine.variational` needs (n + 1)^d unknowns and nodes, so it
stops at three variables; a 7-joint arm needs h of all seven. Here the same functional, eq. (19),

    E2(h) = integral over the box of tr(dh P dh^T - 2 dh K + I_(p-r)) m dx,
    P = J^# J^#T + K K^T,  m = sqrt(det J J^T),

is minimised over a total-degree Legendre basis {phi_a : 1 <= |a| <= n} (C(n + d, d) - 1 unknowns,
polynomial in d for a fixed degree) with a scrambled Sobol rule (``scipy.stats.qmc``) of N
equal-weight nodes, so the cost grows polynomially with the number of variables d.

More than one degree of redundancy (p - r >= 2): with K(x) a p x (p - r) orthonormal kernel frame,
E1^-1 E2 - I_p of eq. (18) is [[0, 0], [dh J^#, dh K - I]], so eq. (18) is
tr(dh P dh^T - 2 dh K + I) m: a sum over the components h_i of the scalar functional with the load
m K_i, each minimised independently (they share the stiffness matrix). Its Euler equations are the
p - r decoupled linear elliptic equations (20). The frame is not unique; the one used here is given
by :func:`~jik.engine.kernel_frame.kernel_frame` (``docs/e2-vector.md`` derives all of this).

The constant mode is left out (E2 depends on dh only): each h_i has zero mean over the rule's
nodes up to the quadrature error. Natural boundary conditions, as in :mod:`jik.engine.variational`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from scipy import linalg

from .exceptions import InvalidInputError, KinematicSingularityError
from .functionals import Region, check_region
from .inverses import require_kinematics
from .kernel_frame import frame_axes_of, kernel_frame
from .kinematics import Kinematics
from .progress import Progress, check_cancelled, check_progress
from .synthesis_nd_result import TotalDegreeSynthesis
from .total_degree import (
    TotalDegreeMap,
    basis_gradients,
    basis_size,
    sobol_nodes,
    total_degree_indices,
)
from .validation import FloatArray, check_seed, count

#: Largest basis the synthesis assembles (its stiffness matrix is dense, unknowns^2 floats).
MAX_UNKNOWNS = 4000
#: Largest number of quadrature nodes (a power of two, as the Sobol rule needs).
MAX_NODES = 2**17
#: Nodes assembled at once: bounds the memory of the basis' gradients to a few tens of MB.
CHUNK = 1024
#: Bytes of the basis gradients (nodes, unknowns, variables) held for one chunk of nodes.
CHUNK_BYTES = 2**24
#: Share of a synthesis's progress for assembling the Ritz system; the rest is the check of E2
#: on a second rule, about a quarter of the time.
MAIN_PASS = 0.75


def chunk_for(unknowns: int, variables: int) -> int:
    """Nodes per chunk: at most :data:`CHUNK`, a power of two (so that the leading 2^k nodes of
    the convergence table end on a chunk's end), with the chunk's basis gradients within
    :data:`CHUNK_BYTES` (at least 64 nodes)."""
    fits = CHUNK_BYTES // (8 * unknowns * variables)
    return max(64, min(CHUNK, 1 << max(0, int(fits).bit_length() - 1)))


class _Rule:
    """A scrambled Sobol rule on the box and the integrand's data at its nodes, by chunks."""

    def __init__(self, kinematics, box, fix, nodes, seed, axes, chunk=CHUNK):
        self.kin, self.box, self.axes, self.chunk = kinematics, box, axes, chunk
        names = kinematics.names
        self.variables = [names.index(n) for n in box]
        lo = np.array([v[0] for v in box.values()])
        hi = np.array([v[1] for v in box.values()])
        self.center, self.half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        self.volume = float(np.prod(hi - lo))
        self.t = sobol_nodes(len(box), nodes, seed)
        self.base = np.array([fix.get(n, 0.0) for n in names])

    def chunks(self):
        """(t, R, f, m) per chunk: R = m P and f = m K restricted to the box's variables."""
        idx = np.array(self.variables)
        for start in range(0, len(self.t), self.chunk):
            t = self.t[start : start + self.chunk]
            x = np.broadcast_to(self.base, (len(t), self.base.size)).copy()
            x[:, idx] = self.center + self.half * t
            m = self.kin.manipulability(x)
            if np.any(m < 1e-9):
                bad = x[int(np.argmin(m))]
                raise KinematicSingularityError(
                    "the synthesis region contains a kinematic singularity; choose a region "
                    "without one",
                    bad,
                    "region",
                )
            K, Jp = kernel_frame(self.kin, x, self.axes)
            P = Jp @ np.swapaxes(Jp, -1, -2) + K @ np.swapaxes(K, -1, -2)
            R = m[:, None, None] * P[:, idx][:, :, idx]
            f = m[:, None, None] * K[:, idx, :]
            # grad_x phi = grad_t phi / half: fold the scales into R and f.
            s = 1.0 / self.half
            yield t, R * s[:, None] * s[None, :], f * s[:, None], m


def synthesize_e2_nd(
    kinematics: Kinematics,
    region: Region,
    *,
    degree: int = 4,
    nodes: int = 2**13,
    fixed: Mapping[str, float] | None = None,
    seed: int = 0,
    frame_axes: Sequence[int] | None = None,
    convergence_degrees: Sequence[int] = (),
    progress: Progress | None = None,
) -> TotalDegreeSynthesis:
    """Minimise E2, eq. (19), over maps h of all the region's variables (see the module).

    Parameters
    ----------
    kinematics : Kinematics
        With p - r >= 1.
    region : mapping name -> (lo, hi)
        Any number of joint variables (h depends on these); the others are held at ``fixed``,
        by default the robot's home, else its start (:func:`~.kinematics.held_values`).
    degree : int
        Total degree of the polynomial basis.
    nodes : int
        Quadrature nodes: a power of two (a Sobol rule's balance needs it), at least twice the
        number of unknowns.
    seed : int
        Seed of the scrambling, 0 to 2^63 - 1 (the result is a deterministic function of it).
    frame_axes : sequence of int, optional
        1-based joints whose axes fix the kernel frame for p - r >= 2
        (:func:`~jik.engine.kernel_frame.kernel_frame`);
        default: the best conditioned at the box's centre
        (:func:`~jik.engine.kernel_frame.best_frame_axes`).
    convergence_degrees : sequence of int
        Lower total degrees whose Ritz values are reported too.
    progress : Progress, optional
        Told the fraction of the nodes assembled (``advance``); polled between chunks of nodes
        (``cancelled``: :class:`~jik.engine.exceptions.RunCancelled` stops the synthesis).

    Returns
    -------
    TotalDegreeSynthesis
    """
    kinematics = require_kinematics(kinematics)
    m_red = kinematics.p - kinematics.r
    if m_red < 1:
        raise InvalidInputError(
            f"{kinematics.name} has no redundancy (p = r): synthesize_e2_nd needs p - r >= 1",
            "kinematics",
        )
    (box, fix), progress = check_region(kinematics, region, fixed), check_progress(progress)
    d = len(box)
    degree, seed = count(degree, "degree", 1, 32), check_seed(seed)
    nodes = count(nodes, "nodes", 64, MAX_NODES)
    if nodes & (nodes - 1):
        raise InvalidInputError(f"nodes must be a power of two, got {nodes}", "nodes")
    nb = basis_size(d, degree)
    if nb > MAX_UNKNOWNS:
        raise InvalidInputError(
            f"degree {degree} in {d} variables has {nb} unknowns (at most {MAX_UNKNOWNS}); "
            "lower the degree",
            "degree",
        )
    if nodes < 2 * nb:
        raise InvalidInputError(
            f"nodes must be at least twice the {nb} unknowns of degree {degree} in {d} "
            f"variables, got {nodes}",
            "nodes",
        )
    axes = frame_axes_of(kinematics, box, fix, frame_axes)
    levels = sorted(
        {
            count(n, "convergence degree", 1, degree, "convergence_degrees")
            for n in convergence_degrees
        }
    )
    levels = [n for n in levels if n < degree] + [degree]

    index = total_degree_indices(d, degree)
    chunk = chunk_for(nb, d)
    rule = _Rule(kinematics, box, fix, nodes, seed, axes, chunk)
    A = np.zeros((nb, nb))
    B = np.zeros((nb, m_red))
    c0 = 0.0
    diag, load = np.zeros(d), np.zeros(d)
    snapshots: list[tuple[int, FloatArray, FloatArray, float]] = []
    done = 0
    for t, R, f, m in rule.chunks():
        check_cancelled(progress, "the E2 synthesis was cancelled")
        _, G = basis_gradients(t, index)  # (n, nb, d)
        H = np.einsum("nbk,nkl->nbl", G, R)
        A += np.tensordot(H, G, axes=([0, 2], [0, 2]))
        B += np.einsum("nbk,nkj->bj", G, f)
        c0 += float(m.sum()) * m_red
        diag += np.einsum("nkk->k", R)
        load += f[:, :, 0].sum(axis=0)
        done += len(t)
        if done < nodes and done >= max(2 * nb, CHUNK) and done & (done - 1) == 0:
            snapshots.append((done, A.copy(), B.copy(), c0))
        if progress is not None:
            progress.advance(MAIN_PASS * done / nodes, 1.0)
    w = rule.volume / nodes
    A, B, c0 = A * w, B * w, c0 * w
    A = 0.5 * (A + A.T)

    def ritz(A_, B_, c0_, k):
        n_k = basis_size(d, k)
        try:
            C = linalg.solve(A_[:n_k, :n_k], B_[:n_k], assume_a="pos")
        except linalg.LinAlgError as exc:
            raise InvalidInputError(
                f"the Ritz system of degree {k} is singular on {nodes} nodes; use more nodes",
                "nodes",
            ) from exc
        return C, c0_ - float(np.sum(B_[:n_k] * C))

    convergence = []
    for k in levels:
        C, e2 = ritz(A, B, c0, k)
        convergence.append({"degree": k, "nodes": nodes, "unknowns": basis_size(d, k), "e2": e2})
    for n_s, A_s, B_s, c_s in snapshots:
        ws = rule.volume / n_s
        _, e2_s = ritz(0.5 * (A_s + A_s.T) * ws, B_s * ws, c_s * ws, degree)
        convergence.append({"degree": degree, "nodes": n_s, "unknowns": nb, "e2": e2_s})
    convergence.append(dict(convergence[len(levels) - 1]))
    del convergence[len(levels) - 1]
    maps = tuple(
        TotalDegreeMap(index, C[:, i], box, rule.variables, kinematics.p) for i in range(m_red)
    )
    check = _Rule(kinematics, box, fix, nodes, seed + 1, axes, chunk)
    e2_check = e2_of_gradients(check, index, C, progress)
    single = _single_joint(rule, diag * w, load * w, c0) if m_red == 1 else {}
    if progress is not None:
        progress.advance(1.0, 1.0)
    return TotalDegreeSynthesis(
        maps=maps,
        e2=convergence[-1]["e2"],
        e2_check=e2_check,
        convergence=convergence,
        single_joint=single,
        region=box,
        fixed=fix,
        degree=degree,
        nodes=nodes,
        seed=seed,
        frame_axes=tuple(a + 1 for a in axes or ()),
    )


def e2_of_gradients(
    rule: _Rule, index: np.ndarray, C: FloatArray, progress: Progress | None = None
) -> float:
    """E2 of the maps with coefficients C (nb, p - r) on ``rule``: tr(dh R dh^T - 2 dh f) + m
    (the last 1 - MAIN_PASS of a synthesis's ``progress``, cancelled between chunks)."""
    total, done = 0.0, 0
    for t, R, f, m in rule.chunks():
        check_cancelled(progress, "the E2 synthesis was cancelled")
        done += len(t)
        if progress is not None:
            progress.advance(MAIN_PASS + (1.0 - MAIN_PASS) * done / len(rule.t), 1.0)
        _, G = basis_gradients(t, index)
        dh = np.einsum("nbk,bi->nik", G, C)  # (n, p - r, d), with respect to t
        quad = np.einsum("nik,nkl,nil->n", dh, R, dh)
        lin = np.einsum("nik,nki->n", dh, f)
        total += float(np.sum(quad - 2.0 * lin + m * C.shape[1]))
    return total * rule.volume / len(rule.t)


def _single_joint(rule: _Rule, diag: FloatArray, load: FloatArray, c0: float) -> dict[str, dict]:
    """E2 of h = s x_j, s = +-1 the better sign, for each joint j of the region (p - r = 1);
    ``diag``, ``load``, ``c0``: the integrals of R_jj, f_j, m per unit of t (dh/dt_j = half_j)."""
    out = {}
    for k, name in enumerate(rule.box):
        s = 1.0 if load[k] >= 0 else -1.0
        h = rule.half[k]
        out[name] = {"sign": s, "e2": float(c0 + h**2 * diag[k] - 2.0 * s * h * load[k])}
    return out
