"""What the h panel shows beside the runs: the state's augmenting map h, built from the registry
(a synthesized map, eq. (19), made on first use by :func:`built_map`, in a compute worker when
the server runs its pool), and h on a grid over the two joint variables it depends on most (its
box following the runs)."""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from ...engine.exceptions import JikError, RunCancelled
from ...engine.map_grid import axes_along, slice_values
from ...engine.progress import ProgressCallbacks
from ...engine.robot_synthesis import (
    SynthesisElsewhere,
    recorded_syntheses,
    synthesis_progress,
    synthesized_elsewhere,
)
from ..compute.worker import task
from .model import DashboardState
from .robots import state_kinematics, state_robot, state_spec
from .runs import AlgorithmRun, Cancelled


def kinematics_and_map(state: DashboardState, kin=None):
    """The state's kinematics (``kin`` when the caller has built it) and its augmenting map h,
    built from the registry; h is None for a robot with p - r > 1, whose map is a vector of
    p - r maps (the extended inverse of :mod:`jik.engine.extended_vector` runs with it; the
    panels of one scalar h, E1 (13) and E2 (18) do not apply)."""
    spec = state_spec(state)
    kin = state_kinematics(state) if kin is None else kin
    if spec.p - spec.r > 1:
        return kin, None
    return kin, spec.augmentation(state.augmentation).build(kin, **state.augmentation_parameters)


#: What the progress of a synthesis says on the page.
SYNTHESIZING = "synthesizing h (E2, eq. (19))"


def vector_maps(state: DashboardState) -> tuple | None:
    """For p - r > 1, the state's vector of p - r maps (h_1, ..., h_(p-r)), built (a synthesis
    on its first use); None for one map."""
    spec = state_spec(state)
    maps = state_robot(state).map_vectors.get(state.augmentation) if spec.p > spec.r + 1 else None
    return None if maps is None else tuple(maps() if callable(maps) else maps)


def state_maps(state: DashboardState) -> tuple:
    """:func:`kinematics_and_map` of ``state``, its vector of maps built too (p - r > 1)."""
    kin, amap = kinematics_and_map(state)
    if amap is None:
        vector_maps(state)
    return kin, amap


@task("augmentation", "a lower degree or a smaller region of the map's E2 synthesis")
def synthesized_maps(state: DashboardState) -> dict:
    """The E2 syntheses that the state's map needs, made in a compute worker (within its memory
    and time limits) for :func:`~jik.engine.robot_synthesis.keep_syntheses` in the server."""
    with recorded_syntheses() as made:
        state_maps(state)
    return made


def built_map(
    state,
    progress: Callable[..., None],
    cancelled: Callable[[], bool],
    elsewhere: Callable[[DashboardState, Callable[[], bool]], bool] | None = None,
) -> tuple:
    """:func:`state_maps` of ``state``, a synthesis on the way reporting
    ``progress(fraction, SYNTHESIZING)`` and stopped by ``cancelled()`` (then
    :class:`Cancelled`, nothing kept). With ``elsewhere``
    (:meth:`~jik.app.dashboard.offload.OffloadLane.synthesize`) a synthesis is made there, its
    progress not known (``progress(None, ...)``), unless that returns False (no pool running)."""
    report = ProgressCallbacks(
        on_advance=lambda done, total: progress(min(done / total, 1.0), SYNTHESIZING),
        is_cancelled=cancelled,
    )
    try:
        with synthesis_progress(report):
            if elsewhere is not None:
                try:
                    with synthesized_elsewhere():
                        return state_maps(state)
                except SynthesisElsewhere:

                    def waiting() -> bool:  # (polled while the worker synthesizes)
                        progress(None, f"{SYNTHESIZING} in a compute worker")
                        return cancelled()

                    elsewhere(state, waiting)
            return state_maps(state)
    except RunCancelled:
        raise Cancelled from None


def vector_note(state: DashboardState) -> str | None:
    """What the h panel, drawn for one scalar h, says for a robot with p - r > 1 (None for
    p = r + 1)."""
    spec = state_spec(state)
    if spec.p - spec.r <= 1:
        return None
    h = spec.augmentation(state.augmentation).description
    return (
        f"{h}: a vector of p − r = {spec.p - spec.r} maps, each kept constant by the "
        "extended inverse (eq. (12)); the h panel draws one map (p = r + 1), the E1/E2 "
        "panel scores the vector"
    )


def expensive_map(amap) -> bool:
    """Maps evaluated by solving a problem per point (the engine's
    :attr:`~jik.engine.augmentations.AugmentingMap.solves_per_point`): h is computed after the
    runs have been shown, on a coarser grid."""
    return bool(getattr(amap, "solves_per_point", False))


#: The h panel keeps its box while the trajectories fill at least this fraction of it.
BOX_FILL = 0.5
#: Points of an expensive map evaluated at once (each solves a collocation problem): the steps
#: in which its grid reports progress and can be cancelled (docs/benchmarks.md).
GRID_BATCH = 45
#: Grid points per axis of h (fewer for an expensive map).
GRID_POINTS, EXPENSIVE_GRID_POINTS = 41, 15


def grid_batches(runs: Mapping[str, AlgorithmRun], amap) -> int:
    """The steps of :func:`augmenting_grid` for ``runs``: the batches of the gradient along the
    runs and of h on the grid (an expensive map), else 1."""
    if not expensive_map(amap):
        return 1
    points = sum(len(r.x) for r in runs.values())
    return -(-points // GRID_BATCH) + -(-(EXPENSIVE_GRID_POINTS**2) // GRID_BATCH)


def runs_box(state: DashboardState, runs: Mapping[str, AlgorithmRun]):
    """Lower and upper corners (p,) around the runs' configurations, with a margin of a quarter
    of their span plus 0.25, within the robot's x_range: the box the h panel's grid and the
    configuration-space panel's curves are drawn in."""
    xs = np.concatenate([r.x for r in runs.values()])
    xs = xs[np.isfinite(xs).all(axis=1)]
    lo, hi = xs.min(axis=0), xs.max(axis=0)
    pad = 0.25 * (hi - lo) + 0.25
    lo, hi = lo - pad, hi + pad
    x_range = state_spec(state).x_range
    if x_range:
        r = np.asarray(x_range, dtype=float)
        lo, hi = np.maximum(lo, r[:, 0]), np.minimum(hi, r[:, 1])
    return lo, hi


def augmenting_grid(
    kin,
    state: DashboardState,
    runs: Mapping[str, AlgorithmRun],
    before: dict | None = None,
    progress: Callable[[int, int], None] = lambda done, total: None,
):
    """h on a grid over the two variables it depends on most, other variables at x0; None when
    h cannot be evaluated on the grid.

    The box is :func:`runs_box`'s; the box of ``before`` (the grid on screen) is kept while the
    trajectories lie inside it and span at least :data:`BOX_FILL` of it, like the other panels'
    axes (:func:`jik.app.dashboard.plotting.keep_ranges`). ``progress(done, total)``: after each
    of the :func:`grid_batches` steps; what it raises (:class:`Cancelled`) stops the grid there.
    """
    try:
        _, amap = kinematics_and_map(state, kin)
        if amap is None:
            return None
        xs = np.concatenate([r.x for r in runs.values()])
        total, along = grid_batches(runs, amap), -(-len(xs) // GRID_BATCH)

        def step(offset: int):
            return lambda done, _: progress(offset + done, total)

        i, j = axes_along(amap, xs, GRID_BATCH, step(0))
        low, high = runs_box(state, runs)
        box = [(float(low[k]), float(high[k])) for k in (i, j)]
        n = EXPENSIVE_GRID_POINTS if expensive_map(amap) else GRID_POINTS
        if before is not None and tuple(before["axes"]) == (i, j) and before["n"] == n:
            inside = all(
                b_lo <= np.min(xs[:, k])
                and np.max(xs[:, k]) <= b_hi
                and hi - lo >= BOX_FILL * (b_hi - b_lo)
                for k, (lo, hi), (b_lo, b_hi) in zip((i, j), box, before["box"], strict=True)
            )
            if inside:
                box = [tuple(b) for b in before["box"]]
        u, v, H = slice_values(amap, state.x0, (i, j), box, n, GRID_BATCH, step(along))
        if not expensive_map(amap):
            progress(total, total)
    except (JikError, ValueError, ArithmeticError):
        return None
    return {
        "axes": (i, j),
        "u": u,
        "v": v,
        "h": H,
        "box": box,
        "n": n,
        "map": amap,
        "kinematics": kin,
    }
