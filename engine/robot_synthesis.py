"""Synthesized augmenting maps of robots defined by data: their computation, cached per robot.

A definition's ``{"name": "e2_synthesized", "region": {...}}`` is the E2-optimal map on its box,
eq. (19): by the tensor Ritz solve for two or three variables (:mod:`jik.engine.variational`),
by the total-degree one over more (:mod:`jik.engine.synthesis_nd`). A catalogue arm with one
degree of redundancy (a 7-joint arm's pose task), or a URDF arm given with its home, gets such a
map by default, over all its joints.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import json
from collections.abc import Callable, Collection, Iterator, Mapping
from typing import TYPE_CHECKING

import numpy as np

from .augmentations import AugmentingMap
from .kinematics import Kinematics
from .progress import Progress
from .regions import MAX_REGION_BOUND
from .synthesis_nd import synthesize_e2_nd
from .variational import synthesize_e2

if TYPE_CHECKING:
    from .registry import RobotSpec


def synthesis(box: dict, fix: dict, degree: int, key: str | None) -> Callable[..., AugmentingMap]:
    """The E2-optimal map on ``box`` (one degree of redundancy): the tensor Ritz solve for two
    or three variables (:func:`~jik.engine.variational.synthesize_e2`), the total-degree one for
    more (:func:`~jik.engine.synthesis_nd.synthesize_e2_nd`)."""

    def synthesized(kin: Kinematics) -> AugmentingMap:
        return _maps(kin, box, fix, degree, key, None)[0]

    return functools.cache(synthesized)


def vector_synthesis(
    kin: Kinematics, box: dict, fix: dict, degree: int, key: str | None, axes: list | None
) -> Callable[[], tuple[AugmentingMap, ...]]:
    """The E2-optimal maps h_1, ..., h_(p-r) on ``box`` (p - r >= 2; docs/e2-vector.md), by the
    total-degree synthesis in the kernel frame of the 1-based joints ``axes`` (default: the
    best-conditioned at the box's centre,
    :func:`~jik.engine.kernel_frame.best_frame_axes`), computed on first call."""
    return functools.cache(lambda: _maps(kin, box, fix, degree, key, axes))


def _maps(kin, box, fix, degree, key, axes) -> tuple[AugmentingMap, ...]:
    """The synthesized maps, cached per robot definition ``key`` (None: not cached)."""
    cache_key = None if key is None else (key, json.dumps([box, fix, degree, axes], sort_keys=True))
    if cache_key is not None and cache_key in _SYNTHESIZED:
        return _SYNTHESIZED[cache_key]
    if cache_key is not None and _ELSEWHERE.get():  # (one without a key is made here)
        raise SynthesisElsewhere("this map is synthesized in another process")
    progress = _PROGRESS.get()  # (a RunCancelled it raises leaves nothing cached)
    maps: tuple[AugmentingMap, ...]
    if len(box) <= 3 and kin.p - kin.r == 1:
        maps = (
            synthesize_e2(kin, box, degree=degree, fixed=fix, progress=progress).augmenting_map,
        )
    else:
        maps = synthesize_e2_nd(
            kin,
            box,
            degree=degree,
            nodes=TOTAL_NODES,
            fixed=fix,
            frame_axes=axes,
            progress=progress,
        ).maps
    if cache_key is not None:
        keep_syntheses({cache_key: maps})
        made = _MADE.get()
        if made is not None:
            made[cache_key] = maps
    return maps


class SynthesisElsewhere(Exception):
    """A map not yet synthesized in this process was needed within
    :func:`synthesized_elsewhere`."""


@contextlib.contextmanager
def synthesized_elsewhere() -> Iterator[None]:
    """Within it, a robot's map not yet synthesized in this process is not computed here:
    :class:`SynthesisElsewhere` is raised where it would be. A server computes it in a worker
    process (within :func:`recorded_syntheses` there) and keeps it with :func:`keep_syntheses`,
    so that the worker's memory and time limits bound the synthesis."""
    token = _ELSEWHERE.set(True)
    try:
        yield
    finally:
        _ELSEWHERE.reset(token)


@contextlib.contextmanager
def recorded_syntheses() -> Iterator[dict]:
    """Within it, the robots' maps synthesized (not those found already made) are also put in
    the dict it gives: picklable, for :func:`keep_syntheses` in another process."""
    made: dict = {}
    token = _MADE.set(made)
    try:
        yield made
    finally:
        _MADE.reset(token)


def keep_syntheses(made: Mapping) -> None:
    """Keep maps synthesized elsewhere (a :func:`recorded_syntheses` dict) as if synthesized in
    this process: the robots whose definitions they belong to use them (a process keeps its
    16 most recent)."""
    for cache_key, maps in made.items():
        _SYNTHESIZED.pop(cache_key, None)
        while len(_SYNTHESIZED) >= 16:
            _SYNTHESIZED.pop(next(iter(_SYNTHESIZED)))
        _SYNTHESIZED[cache_key] = maps


@contextlib.contextmanager
def synthesis_progress(progress: Progress | None) -> Iterator[None]:
    """Within it, a map synthesized on first use (a robot's ``e2_synthesized``) reports to
    ``progress`` and stops with :class:`~jik.engine.exceptions.RunCancelled` when it is
    cancelled (:mod:`jik.engine.progress`); its maps are built on first use, deep inside an
    inverse's construction, where no argument reaches."""
    token = _PROGRESS.set(progress)
    try:
        yield
    finally:
        _PROGRESS.reset(token)


_PROGRESS: contextvars.ContextVar[Progress | None] = contextvars.ContextVar(
    "synthesis_progress", default=None
)
_ELSEWHERE: contextvars.ContextVar[bool] = contextvars.ContextVar(
    "synthesized_elsewhere", default=False
)
_MADE: contextvars.ContextVar[dict | None] = contextvars.ContextVar(
    "recorded_syntheses", default=None
)
#: Synthesized maps by the robot definition they belong to (a process's few most recent).
_SYNTHESIZED: dict[tuple[str, str], tuple[AugmentingMap, ...]] = {}
#: Total degree and nodes of a synthesis over more than three joints (docs/e2-vector.md).
TOTAL_DEGREE, TOTAL_NODES = 4, 2**13
#: Legendre degree per variable of the tensor synthesis (two or three variables).
TENSOR_DEGREE = 12
#: Largest degree a definition's E2 synthesis takes: per variable (tensor), and total.
MAX_TENSOR_DEGREE, MAX_TOTAL_DEGREE = 24, 6
#: Half-width [rad] of a catalogue arm's default synthesis box around its home.
ARM_BOX = 0.3


def default_box(
    spec: RobotSpec, size: int, fixed: Collection[str] = ()
) -> dict[str, tuple[float, float]]:
    """The box of a synthesis given none: the robot's design region (``functional_region``,
    the box of sec. 5 over which E1, eq. (13), and E2, eq. (18), are compared) when it has
    ``size`` variables, none of them ``fixed``; else the last ``size`` variables not ``fixed``,
    each over a tenth of its ``x_range`` (within :data:`~jik.engine.regions.MAX_REGION_BOUND`)
    either side of the default start, within that range.

    The variables outside the box are held at the default start, where the robot's maps are
    defined (not at 0): :func:`~jik.engine.kinematics.held_values`.
    """
    design = dict(spec.functional_region)
    if len(design) == size and not set(design) & set(fixed):
        return {n: (float(lo), float(hi)) for n, (lo, hi) in design.items()}
    names = list(spec.variable_names)
    box = {}
    for n in [n for n in names if n not in fixed][-size:]:
        i = names.index(n)
        lo, hi = (
            max(spec.x_range[i][0], -MAX_REGION_BOUND),
            min(spec.x_range[i][1], MAX_REGION_BOUND),
        )
        c, w = spec.default_x0[i], 0.1 * (hi - lo)
        box[n] = (max(lo, c - w), min(hi, c + w))
    return box


def default_degree(variables: int, k: int) -> int:
    """The degree of an E2 synthesis given none: :data:`TENSOR_DEGREE` per variable for one
    map (p - r = ``k`` = 1) of two or three ``variables`` (the tensor Ritz solve of eq. (20)),
    else the total degree :data:`TOTAL_DEGREE` (eq. (19) on a Sobol rule)."""
    return TENSOR_DEGREE if variables <= 3 and k == 1 else TOTAL_DEGREE


def arm_augmentations(kin: Kinematics, d: Mapping) -> list:
    """The maps of an arm with a home (a catalogue arm, or a URDF given with ``home``): by
    default, with one degree of redundancy (a 7-joint arm's pose task), one E2-optimal over all
    its joints, +-ARM_BOX around home within the joint limits; a home beyond a limit (accepted,
    as a start beyond one is) keeps at least ARM_BOX / 2 inside that limit.
    A definition's own maps replace it; an e2_synthesized one of them without a region (a
    scalar or, for p - r >= 2, a vector map) takes that box."""
    given = d.get("augmentations", [])
    if not isinstance(given, list):
        return given
    home = np.asarray(d["home"], dtype=float)
    lo, hi = np.asarray(kin.joint_limits, dtype=float).T
    centre = np.clip(home, lo - ARM_BOX / 2, hi + ARM_BOX / 2)
    box = {
        n: [float(max(lo[i], centre[i] - ARM_BOX)), float(min(hi[i], centre[i] + ARM_BOX))]
        for i, n in enumerate(kin.variable_names)
    }
    if "augmentations" not in d:
        return [{"name": "e2_synthesized", "region": box}] if kin.p - kin.r == 1 else given
    return [
        {**item, "region": box}
        if isinstance(item, Mapping)
        and item.get("name") == "e2_synthesized"
        and "region" not in item
        else item
        for item in given
    ]


def missing_map(name: str, p: int, r: int, arm: bool) -> str:
    """What the extended inverse (11) of a robot without an augmenting map needs: p - r maps h
    (eq. (9)), a formula or an E2 synthesis; an arm with a home (``arm``) has one by default
    only for p = r + 1 (:func:`arm_augmentations`); a robot with p = r has no room for one.
    ``name``: the robot's kind or name."""
    k = p - r
    if k == 0:
        return (
            f"the extended inverse needs redundancy (p > r), and this {name} has p = r = {p}: "
            "its Jacobian is square, so no augmenting map can be added; choose another "
            "algorithm (the pseudoinverse is then J^-1)"
        )
    if k == 1:
        return (
            "the extended inverse needs an augmenting map: {'name': 'formula', 'h': ...} or "
            "{'name': 'e2_synthesized', 'region': {...}}; an arm given with its home has an "
            "E2-optimal one by default"
        )
    formulas = f"{{'name': 'formula', 'h': [...]}} ({k} formulas, one per degree of redundancy)"
    if arm:
        return (
            f"the extended inverse needs p - r = {k} augmenting maps, and this {name} "
            f"(p = {p}, r = {r}) has a default map only when p = r + 1: ask for "
            f"'e2_synthesized' (E2-optimal over all its joints, +-{ARM_BOX:g} around its home; "
            f"{{'name': 'e2_synthesized'}} in a definition or a request) or give {formulas}"
        )
    return (
        f"the extended inverse needs p - r = {k} augmenting maps: give {formulas} or "
        f"{{'name': 'e2_synthesized', 'region': {{...}}}} over at least {k} of the joints"
    )
