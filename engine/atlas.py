"""Repeatability atlas: drift after every cycle of a closed path, over many starts and paths.

The repeatability test of sec. 5.2.1 (Table 1) drives the robot around a closed task path from one
start x0; the pseudoinverse (8) drifts, the extended inverse (11) does not. The drift depends on
where on the self-motion manifold of the path's first point the robot starts, and on the path's
size and place. An atlas runs the test of :func:`jik.engine.repeatability.repeatability` for
every start of a set (points of the traced manifold at arc lengths s, :mod:`jik.engine.self_motion`,
or explicit configurations) and every path of a family (translations and scales of a base path),
for one or several inverses.

The path is a loop through its points in order, from the first: a start x lies on k(x) = path[0]
and the legs of a cycle go to path[1], ..., path[-1] and back to k(x) (as ``repeatability``
closes them). The work is cut into chunks of starts, each run as batched ``repeatability`` calls per
inverse (:mod:`jik.engine.atlas_run`); a chunk's numbers depend only on its starts (each member's
arithmetic in the batched solver is its own), so the atlas is the same whatever the chunking and
wherever the chunks run (:mod:`jik.engine.atlas_backends`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .atlas_paths import Family, base_manifolds, checked, path_family
from .exceptions import InvalidInputError
from .exports import plural
from .inverses import Inverse, algorithm_labels
from .repeatability import MAX_CYCLES, MAX_PATH_POINTS, open_loop
from .self_motion import SelfMotionManifold
from .solve_rules import check_settings, chunk_limit
from .validation import FloatArray, as_points, bounded, check_seed, count

#: Largest number of starts per path and of starts in a chunk (of paths in a family:
#: :data:`~jik.engine.atlas_paths.MAX_PATHS`). A chunk must also fit in the memory bound
#: (:func:`~jik.engine.solve_rules.chunk_limit`); the starts need not, when the atlas is
#: streamed (``iter_atlas``).
MAX_STARTS = 10**9
MAX_CHUNK = 65536
#: Largest number of starts in a chunk by default, the unit of work handed to a backend: about a
#: second of work for the paper's robots, few tasks for a scheduler.
DEFAULT_CHUNK = 2048
#: A default chunking cuts an atlas into at least this many chunks (of at least MIN_AUTO_CHUNK
#: starts): progress moves and a cancellation is heard within a small atlas of a slow robot.
AUTO_CHUNKS, MIN_AUTO_CHUNK = 16, 16


def auto_chunk(size: int) -> int:
    """The default starts per chunk of an atlas of ``size`` runs per inverse: at most
    :data:`DEFAULT_CHUNK`, at least :data:`AUTO_CHUNKS` chunks of :data:`MIN_AUTO_CHUNK` or
    more (an atlas's numbers do not depend on its chunking)."""
    return max(MIN_AUTO_CHUNK, min(DEFAULT_CHUNK, -(-size // AUTO_CHUNKS)))


#: Sampled arc lengths are drawn in blocks of this many indices, each from its own seeded stream,
#: so the s of a start depends only on its index and the seed.
SAMPLE_BLOCK = 1024
#: An explicit start must lie this close to k(x) = path[0].
ON_MANIFOLD_TOL = 1e-9


@dataclass(frozen=True)
class AtlasPlan:
    """Validated inputs of an atlas (made by :func:`plan_atlas`).

    Attributes
    ----------
    inverses : tuple of Inverse
        One or several right inverses of the same kinematics.
    paths : ndarray, shape (P, L0, r)
        The family's paths; each is a loop from its first point.
    cycles : int
    n_starts : int
        N, starts per path.
    sampling : (str, int) or None
        How the arc lengths s of the starts are laid on their curves' common arc: ("grid", 0) or
        ("sample", seed) (:func:`arc_lengths`); None for explicit starts.
    manifolds : tuple of SelfMotionManifold (one per path) or ()
        The first path's curve sets the arc: one turn when it is closed. Each other path's curve
        is traced over that arc; when it closes within it, its starts' s are taken modulo its
        own period (:meth:`SelfMotionManifold.points`).
    explicit : ndarray, shape (N, p) or None
    chunk : int
    settings : dict
        gamma, mode, tol and max_iterations of every leg (:func:`jik.engine.solver.solve`).
    family : Family or None
        Each path's scale (P,) and shift (P, r) when the paths are a family of shifts and
        scales (:func:`~jik.engine.atlas_paths.path_family`); None for the base path as given.
    """

    inverses: tuple[Inverse, ...]
    paths: FloatArray
    cycles: int
    n_starts: int
    sampling: tuple[str, int] | None
    manifolds: tuple[SelfMotionManifold, ...]
    explicit: FloatArray | None
    chunk: int
    settings: dict = field(default_factory=dict)
    family: Family | None = None

    def __repr__(self) -> str:
        return (
            f"AtlasPlan({'/'.join(self.algorithms)}, {plural(len(self.paths), 'path')} x "
            f"{plural(self.n_starts, 'start')} x {plural(self.cycles, 'cycle')} of "
            f"{plural(self.legs, 'leg')}, {self.size} runs in chunks of {self.chunk})"
        )

    @property
    def size(self) -> int:
        """Number of runs per inverse: paths x starts."""
        return len(self.paths) * self.n_starts

    @property
    def legs(self) -> int:
        """Legs of one cycle: path[1:] and the return to k(x)."""
        return self.paths.shape[1]

    @property
    def algorithms(self) -> tuple[str, ...]:
        return algorithm_labels(self.inverses)

    def starts(self, lo: int, hi: int) -> FloatArray:
        """The starts of runs lo to hi - 1 (runs are path-major: run = path * N + start)."""
        runs = np.arange(lo, hi)
        path, index = np.divmod(runs, self.n_starts)
        if self.explicit is not None:
            return self.explicit[index]
        s = self.parameter(index)
        assert s is not None  # (not explicit: the starts are on traced curves)
        x = np.empty((len(runs), self.inverses[0].kinematics.p))
        for j in np.unique(path):
            x[path == j] = self.manifolds[j].points(s[path == j])
        return x

    def parameter(self, index) -> FloatArray | None:
        """Arc lengths s of starts ``index`` (an int array) on their curves; None when the
        starts are explicit. Computed on demand: a plan holds nothing of size N."""
        if self.sampling is None:
            return None
        curve = self.manifolds[0]
        return arc_lengths(
            np.asarray(index), self.n_starts, curve.arc, *self.sampling, closed=curve.closed
        )

    def targets(self, lo: int, hi: int, starts: FloatArray) -> FloatArray:
        """The legs' targets (n, L, r) of runs lo to hi - 1: path[1:] and k(start)."""
        path = np.arange(lo, hi) // self.n_starts
        home = self.inverses[0].kinematics.forward(starts)[:, None, :]
        return np.concatenate([self.paths[path, 1:], home], axis=1)


def arc_lengths(
    index: FloatArray,
    n: int,
    arc: tuple[float, float],
    sampling: str,
    seed: int,
    closed: bool = False,
) -> FloatArray:
    """Arc lengths of starts ``index`` (ints in [0, n)) of n on [lo, hi]: evenly spaced, ends
    included ("grid"), or uniform random ("sample"): drawn from ``seed`` block by block, so
    each index's value is fixed by the index and the seed, not by what else is asked for.

    On a ``closed`` curve, whose arc is one turn (s = hi is s = lo again), the grid is n even
    steps from lo, the end hi left out; samples are drawn as on an open arc, over the turn."""
    lo, hi = arc
    if sampling == "grid" and closed:
        u = index / n
    elif sampling == "grid":
        u = index / (n - 1) if n > 1 else np.zeros(len(index))
    else:
        u = np.empty(len(index))
        block = index // SAMPLE_BLOCK
        for b in np.unique(block):
            u[block == b] = np.random.default_rng([seed, int(b)]).random(SAMPLE_BLOCK)[
                index[block == b] % SAMPLE_BLOCK
            ]
    return np.clip(lo + (hi - lo) * u, lo, hi)


def plan_atlas(
    inverses: Inverse | Sequence[Inverse],
    path,
    *,
    cycles: int = 1,
    starts=None,
    n_starts: int | None = None,
    arc: Sequence[float] | None = None,
    sampling: str = "grid",
    seed: int = 0,
    reference=None,
    box=None,
    shifts=None,
    scales=None,
    chunk: int | None = None,
    gamma: float = 1.0,
    mode: str = "continuous",
    tol: float = 1e-10,
    max_iterations: int | None = None,
) -> AtlasPlan:
    """Check an atlas's inputs once, here, and trace the manifolds of its starts.

    Parameters
    ----------
    inverses : Inverse or sequence of Inverse
        Of one kinematics k; each gives its own drift.
    path : array_like, shape (L0, r)
        The base path, a loop from its first point (2 to 100 points; a last point equal to the
        first is dropped: the return leg to k(x) closes every loop).
    cycles : int
        1 to 1000.
    starts : array_like, shape (N, p), optional
        Explicit starts, each on k(x) = path[0] (to 1e-9). Otherwise:
    n_starts, arc, sampling, seed, reference, box
        N starts at arc lengths s in ``arc`` = (lo, hi) on the self-motion curve of each path's
        first point (:func:`jik.engine.self_motion.trace`), on a grid (ends included) or sampled
        uniformly with ``seed``. s = 0 is where eq. (7) with the pseudoinverse from ``reference``
        (a configuration, p) reaches the path's first point; with ``box`` ((low, high) per
        coordinate) the arc is cut where the base path's curve leaves the box, and the same
        arc is used for every path of the family. A base curve that closes on itself within the
        arc (:func:`jik.engine.self_motion.trace`) gives one turn as the arc, and the starts
        cover it once: a grid leaves out its end, the start again.
    shifts : array_like, shape (S, r), optional
        Translations of the base path (default: none).
    scales : array_like, shape (Q,), optional
        Scales of the base path about its first point, > 0 (default 1). The family is every
        shift with every scale, P = S Q paths.
    chunk : int, optional
        Starts per chunk: the batch size and the unit of work, 1 to 65536; by default
        :func:`auto_chunk` of the atlas's size (progress is told, and cancellation asked,
        after every chunk), lowered to what fits in :data:`jik.engine.validation.MEMORY_LIMIT`
        (:func:`~jik.engine.solve_rules.chunk_limit`).
    gamma, mode, tol, max_iterations
        Of every leg, as in :func:`jik.engine.solver.solve`.

    Raises
    ------
    InvalidInputError
        Naming the field (``error.field``): path, cycles, starts, n_starts, arc, sampling, seed,
        reference, box, shifts, scales, chunk, gamma, mode, tol, max_iterations, inverses; a
        chunk whose runs would exceed :data:`jik.engine.validation.MEMORY_LIMIT` names
        ``chunk`` (``cycles``, when one run is too large).
    """
    invs = (inverses,) if isinstance(inverses, Inverse) else tuple(inverses)
    if not invs or not all(isinstance(i, Inverse) for i in invs):
        raise InvalidInputError("give one or more Inverse objects", field="inverses")
    kin = invs[0].kinematics
    if any(i.kinematics is not kin for i in invs):
        raise InvalidInputError("all inverses must share one kinematics", field="inverses")
    base_path = checked(lambda: as_points(path, kin.r, "path"), "path")
    if base_path.ndim != 2:
        raise InvalidInputError(f"path must be a list of task points (L, {kin.r})", field="path")
    base_path = open_loop(base_path)
    if not 2 <= len(base_path) <= MAX_PATH_POINTS:
        raise InvalidInputError(
            f"path must have 2 to {MAX_PATH_POINTS} points (a loop from the first), got "
            f"{len(base_path)}",
            field="path",
        )
    cycles = checked(lambda: count(cycles, "cycles", 1, MAX_CYCLES), "cycles")
    chunk = None if chunk is None else checked(lambda: count(chunk, "chunk", 1, MAX_CHUNK), "chunk")
    mode, gamma, tol, cap = check_settings(mode, gamma, tol, max_iterations)
    settings = {
        "gamma": gamma,
        "mode": mode,
        "tol": tol,
        "max_iterations": None if max_iterations is None else cap,
    }
    paths, per_shift, placed = path_family(kin, base_path, shifts, scales)

    fits = chunk_limit(kin, len(invs), cycles, paths.shape[1], settings, chunk)

    def make(**starts_: Any) -> AtlasPlan:
        plan = AtlasPlan(
            inverses=invs,
            paths=paths,
            cycles=cycles,
            chunk=1,
            settings=settings,
            family=placed,
            **starts_,
        )
        return replace(plan, chunk=min(auto_chunk(plan.size), fits) if chunk is None else chunk)

    if starts is not None:
        x = checked(lambda: as_points(starts, kin.p, "starts"), "starts")
        if x.ndim != 2 or not 1 <= len(x) <= MAX_STARTS:
            raise InvalidInputError(f"starts must be a list (N, {kin.p}), N >= 1", "starts")
        off = np.linalg.norm(kin.forward(x)[None] - paths[:, None, 0], axis=-1).max(axis=0)
        if np.any(off > ON_MANIFOLD_TOL):
            i = int(np.argmax(off))
            raise InvalidInputError(
                f"starts[{i}] is not on the self-motion manifold of every path's first point: "
                f"|k(x) - path[0]| = {off[i]:.3g} > {ON_MANIFOLD_TOL:g}",
                field=f"starts.{i}",
            )
        return make(n_starts=len(x), sampling=None, manifolds=(), explicit=x)
    if n_starts is None:
        raise InvalidInputError(
            "give explicit starts, or n_starts with arc and reference (starts on the "
            "self-motion curve of the path's first point)",
            "starts",
        )
    missing = [name for name, value in (("arc", arc), ("reference", reference)) if value is None]
    if missing:
        raise InvalidInputError(
            f"n_starts needs {' and '.join(missing)}: arc = (lo, hi), the arc lengths s of the "
            "starts on the self-motion curve (lo <= 0 <= hi), and reference, a configuration "
            f"({kin.p} numbers, such as the robot's home) that eq. (7) moves onto the path's "
            "first point, where s = 0",
            missing[0],
        )
    n = checked(lambda: count(n_starts, "n_starts", 1, MAX_STARTS), "n_starts")
    if sampling not in ("grid", "sample"):
        raise InvalidInputError(
            f"sampling must be 'grid' or 'sample', got {sampling!r}", "sampling"
        )
    seed = check_seed(seed)
    ref = checked(lambda: bounded(kin.check(reference, "reference"), "reference"), "reference")
    if ref.ndim != 1:
        raise InvalidInputError(f"reference must be one configuration ({kin.p},)", "reference")
    if box is not None:
        box = checked(lambda: as_points(box, 2, "box"), "box")
        if box.shape != (kin.p, 2) or np.any(box[:, 0] >= box[:, 1]):
            raise InvalidInputError(f"box must be {kin.p} pairs (low, high), low < high", "box")
    pair = isinstance(arc, Sequence) and len(arc) == 2
    if not (arc.shape == (2,) if isinstance(arc, np.ndarray) else pair):
        raise InvalidInputError("arc must be a pair (lo, hi) with lo <= 0 <= hi", field="arc")
    manifolds = checked(lambda: base_manifolds(kin, paths, ref, arc, box, per_shift), "reference")
    return make(n_starts=n, sampling=(sampling, seed), manifolds=manifolds, explicit=None)
