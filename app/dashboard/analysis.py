"""What the h panel and the E1/E2 panel show beside the runs: h on a grid (its box following the
runs), the error functionals E1, E2 of section 5 on the robot's design region, their
sensitivity to the map's parameters, and which joint variables they ignore."""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping

import numpy as np

from jik.app.dashboard.arm_e2 import qmc_functionals, single_joint_sensitivity
from jik.app.dashboard.model import DashboardState, cache_key
from jik.app.dashboard.robots import state_kinematics, state_spec
from jik.app.dashboard.runs import AlgorithmRun, Cancelled, DashboardResult
from jik.engine.exceptions import JikError
from jik.engine.progress import ProgressCallbacks


def inert_variables(kin, amap, box: tuple[tuple[float, float], ...], samples: int = 8):
    """Joint variables x_k that neither J nor h nor dh depends on.

    At seeded points of ``box`` (one interval per variable), shifting x_k must leave J, h and dh
    bitwise unchanged (NaN where undefined included): an expression without x_k evaluates the
    same, one that merely cancels it would not and counts as dependent. A slice of h at x_k's
    start value then does not depend on that value, nor do E1 (13) and E2 (18), whose integrands
    are functions of J and dh. Maps that solve a problem per point are not probed (empty set),
    nor is a vector map (None).
    """
    if amap is None or expensive_map(amap):
        return frozenset()
    lo, hi = np.array(box, dtype=float).T
    X = np.random.default_rng(0).uniform(lo, hi, (samples, len(lo)))

    def probe(x):
        with np.errstate(all="ignore"):
            return (kin.jacobian(x), amap.value_masked(x)[0], amap.gradient_masked(x)[0])

    inert = set()
    try:
        at = probe(X)
        for k in range(len(lo)):
            shifted = X.copy()
            shifted[:, k] += 0.371 * (hi[k] - lo[k])
            again = probe(shifted)
            if all(np.array_equal(a, b, equal_nan=True) for a, b in zip(at, again, strict=True)):
                inert.add(k)
    except (JikError, ValueError, ArithmeticError):  # a map that cannot be probed: all matter
        return frozenset()
    return frozenset(inert)


_inert_cache: dict[str, frozenset[int]] = {}


def state_inert_variables(state: DashboardState) -> frozenset[int]:
    """:func:`inert_variables` of the state's kinematics and map over the robot's x_range
    (cached per robot, map and parameters)."""
    d = state.as_dict()
    keys = ("robot", "robot_parameters", "augmentation", "augmentation_parameters")
    key = json.dumps({k: d[k] for k in keys}, sort_keys=True)
    if key not in _inert_cache:
        kin, amap = kinematics_and_map(state)
        box = state_spec(state).x_range or ((-1.0, 1.0),) * kin.p
        if len(_inert_cache) >= 64:  # (slider values of l, a, b: keep the recent ones)
            del _inert_cache[next(iter(_inert_cache))]
        _inert_cache[key] = inert_variables(kin, amap, box)
    return _inert_cache[key]


def functionals_key(state: DashboardState) -> str:
    """Everything E1, E2 and their sensitivity depend on (see :func:`error_functionals`).

    On a robot's design region: the robot, the map and the start values of the variables
    outside the region (held fixed) that J, h or dh depends on (:func:`inert_variables`); the path,
    the cycles, gamma and the rest of x0 do not matter. Without a design region the box follows
    the runs: everything they depend on.
    """
    spec = state_spec(state)
    design = spec.functional_region
    if not design:
        return cache_key(state, "extended")
    d = state.as_dict()
    inert = state_inert_variables(state)
    fixed = {
        n: d["x0"][k]
        for k, n in enumerate(spec.variable_names)
        if n not in design and k not in inert
    }
    return json.dumps(
        {k: d[k] for k in ("robot", "robot_parameters", "augmentation", "augmentation_parameters")}
        | {"fixed": fixed},
        sort_keys=True,
    )


def augmenting_axes(amap, x: np.ndarray, on_batch=None) -> tuple[int, int]:
    """The two joint variables h depends on most along the configurations ``x`` (n, p).

    ``on_batch(done, total)``: after each batch of :data:`GRID_BATCH` points of an expensive
    map (:func:`expensive_map`), whose gradient solves a problem per point.
    """
    with np.errstate(all="ignore"):
        if expensive_map(amap):
            dh = amap.evaluate_batches(x, GRID_BATCH, ProgressCallbacks(on_advance=on_batch))[1]
            g = np.abs(np.asarray(dh, dtype=float))
        else:
            g = np.abs(np.asarray(amap.gradient(x), dtype=float))
    weight = np.nan_to_num(np.nanmean(g, axis=0)) * (np.ptp(x, axis=0) + 1.0)
    i, j = sorted(np.argsort(-weight, kind="stable")[:2])
    return int(i), int(j)


def kinematics_and_map(state: DashboardState, kin=None):
    """The state's kinematics (``kin`` when the caller has built it) and its augmenting map h,
    built from the registry; h is None for a robot with p - r > 1, whose map is a vector of
    p - r maps (the extended inverse of :mod:`jik.engine.extended_vector` runs with it; the
    panels of one scalar h, E1 (13) and E2 (18) do not apply)."""
    spec = state_spec(state)
    kin = state_kinematics(state) if kin is None else kin
    if vector_map(state):
        return kin, None
    return kin, spec.augmentation(state.augmentation).build(kin, **state.augmentation_parameters)


def vector_map(state: DashboardState) -> bool:
    """Whether the state's robot has p - r > 1 degrees of redundancy (h a vector of maps)."""
    spec = state_spec(state)
    return spec.p - spec.r > 1


def vector_note(state: DashboardState) -> str | None:
    """What the panels of one scalar h say for a robot with p - r > 1 (None for p = r + 1)."""
    if not vector_map(state):
        return None
    spec = state_spec(state)
    h = spec.augmentation(state.augmentation).description
    return (
        f"{h}: a vector of p − r = {spec.p - spec.r} maps, each kept constant by the "
        "extended inverse (eq. (12)); the h panel, E1 (13) and E2 (18) are for one "
        "degree of redundancy (p = r + 1)"
    )


def expensive_map(amap) -> bool:
    """Maps evaluated by solving a problem per point (characteristics): h is computed after
    the runs have been shown, on a coarser grid."""
    return hasattr(amap, "evaluate")


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


def augmenting_grid(
    kin,
    state: DashboardState,
    runs: Mapping[str, AlgorithmRun],
    n: int = GRID_POINTS,
    before: dict | None = None,
    progress: Callable[[int, int], None] | None = None,
):
    """h on a grid over the two variables it depends on most, other variables at x0.

    The box covers both trajectories with a margin, clipped to the robot's x_range. The box of
    ``before`` (the grid on screen) is kept while the trajectories lie inside it and span at
    least :data:`BOX_FILL` of it, like the other panels' axes
    (:func:`jik.app.dashboard.plotting.keep_ranges`): a small change then gives the same grid,
    often the same h, and the page moves only the trajectories. Returns None when h cannot be
    evaluated on the grid.

    ``progress(done, total)``: after each of the :func:`grid_batches` steps; what it raises
    (:class:`Cancelled`) stops the grid there.
    """
    spec = state_spec(state)
    try:
        _, amap = kinematics_and_map(state, kin)
        if amap is None:
            return None
        xs = np.concatenate([r.x for r in runs.values()])
        total, along = grid_batches(runs, amap), -(-len(xs) // GRID_BATCH)

        def step(offset: int):
            return None if progress is None else lambda done, _: progress(offset + done, total)

        i, j = augmenting_axes(amap, xs, step(0))
        box = []
        for k in (i, j):
            lo, hi = float(np.min(xs[:, k])), float(np.max(xs[:, k]))
            pad = 0.25 * (hi - lo) + 0.25
            lo, hi = lo - pad, hi + pad
            if spec.x_range:
                lo, hi = max(lo, spec.x_range[k][0]), min(hi, spec.x_range[k][1])
            box.append((lo, hi))
        if expensive_map(amap):
            n = min(n, EXPENSIVE_GRID_POINTS)  # h solves a collocation problem per point
        if before is not None and tuple(before["axes"]) == (i, j) and before["n"] == n:
            inside = all(
                b_lo <= np.min(xs[:, k])
                and np.max(xs[:, k]) <= b_hi
                and hi - lo >= BOX_FILL * (b_hi - b_lo)
                for k, (lo, hi), (b_lo, b_hi) in zip((i, j), box, before["box"], strict=True)
            )
            if inside:
                box = [tuple(b) for b in before["box"]]
        u, v = np.linspace(*box[0], n), np.linspace(*box[1], n)
        X = np.broadcast_to(np.asarray(state.x0, dtype=float), (n, n, kin.p)).copy()
        X[..., i] = u[None, :]
        X[..., j] = v[:, None]
        with np.errstate(all="ignore"):
            if expensive_map(amap):  # (maps that can be undefined at some points)
                h = amap.evaluate_batches(
                    X.reshape(-1, kin.p), GRID_BATCH, ProgressCallbacks(on_advance=step(along))
                )[0]
                H = np.asarray(h, dtype=float)
            else:
                H = np.asarray(amap.value(X.reshape(-1, kin.p)), dtype=float)
                if progress is not None:
                    progress(total, total)
        H = H.reshape(n, n)
    except (JikError, ValueError, ArithmeticError):
        return None
    H = np.where(np.isfinite(H), H, np.nan)
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


#: E1 and E2 are taken by a tensor Gauss rule over at most this many region variables.
MAX_QUADRATURE_VARIABLES = 3


def error_functionals(
    result: DashboardResult,
    nodes: int = 12,
    on_step: Callable[[], None] | None = None,
    cancelled: Callable[[], bool] = lambda: False,
) -> dict | None:
    """E1 (13) and E2 (18) of the current map, or None if unavailable.

    Over the robot's design region from the registry (the boxes of sec. 5, the ones
    ``jik reproduce`` uses) where it has one, so the values do not move with the start point and
    a synthesized map is judged on the box it was built for; else over the heat-map box.
    ``on_step()`` after each of the two (progress; what it raises stops them). Over more than
    three variables, E2 by a Sobol rule (:func:`~jik.app.dashboard.arm_e2.qmc_functionals`,
    polling ``cancelled``).
    """
    grid = result.augmenting
    if grid is None:
        return None
    if expensive_map(grid["map"]):
        nodes = min(nodes, 6)
    try:
        from jik.engine.functionals import error_functional_e1, error_functional_e2
    except ImportError:
        return None
    names = result.variable_names
    i, j = grid["axes"]
    design = state_spec(result.state).functional_region
    region = dict(design) or {names[i]: tuple(grid["box"][0]), names[j]: tuple(grid["box"][1])}
    fixed = {n: float(result.state.x0[k]) for k, n in enumerate(names) if n not in region}
    out = {
        "region": {k: list(v) for k, v in region.items()},
        "fixed": fixed,
        "nodes": nodes,
        "design_region": bool(design),
    }
    if len(region) > MAX_QUADRATURE_VARIABLES:  # (nodes ** 7 points for a 7-joint arm)
        return qmc_functionals(grid, region, fixed, out, cancelled, on_step)
    for key, fn in (("E1", error_functional_e1), ("E2", error_functional_e2)):
        try:
            value = fn(grid["kinematics"], grid["map"], region, nodes=nodes, fixed=fixed)
            out[key] = value.value if np.isfinite(value.value) else None
            out[f"{key}_singular_points"] = int(value.singular_points.shape[0])
        except (JikError, ValueError, ArithmeticError) as exc:
            out[key] = None
            out[f"{key}_error"] = str(exc)
        if on_step is not None:
            on_step()
    return out


#: Values of each parameter in the E1/E2 sweep of the dashboard (over v - 1 .. v + 1).
SENSITIVITY_SAMPLES = 11


def sensitivity_evaluations(state: DashboardState, amap) -> int:
    """How many values of E1 or E2 :func:`sensitivity` computes for ``state`` and its map
    ``amap`` (its steps of progress): none for an expensive map or a design region over more
    variables than a tensor rule takes (E2 from a Sobol rule alone, no sweep); else both
    functionals at every point of the parameters' sweeps, or of each of the robot's maps."""
    if amap is None or expensive_map(amap):
        return 0
    spec = state_spec(state)
    if len(spec.functional_region) > MAX_QUADRATURE_VARIABLES:
        return 0
    params = spec.augmentation(state.augmentation).parameters
    if params:
        return 2 * (1 + len(params) * (2 + SENSITIVITY_SAMPLES))
    return 2 * len(spec.augmentations)


def sensitivity(
    result: DashboardResult,
    functionals: dict | None,
    cancelled: Callable[[], bool] = lambda: False,
    progress: Callable[[int, int], None] | None = None,
) -> dict:
    """How E1 (13) and E2 (18) change with the parameters of the current map.

    Over the same box and fixed variables as ``functionals`` (see :func:`error_functionals`):

    * a map with parameters (C1, C2 or a, b): ``{"kind": "parameters", "parameters": {...},
      "E1": ..., "E2": ...}``, each from :func:`jik.engine.functionals.parameter_sensitivity`
      (the value, the gradient and a sweep of every parameter over v - 1 .. v + 1);
    * a map without parameters: ``{"kind": "alternatives", "maps": [{"name", "E1", "E2",
      "current"}]}``, the functionals of every map the robot offers, at their defaults;
    * ``{"kind": "unavailable", "reason": ...}`` when they cannot be evaluated here.

    ``cancelled`` is polled before every evaluation of a functional (raises :class:`Cancelled`);
    ``progress(done, total)`` follows each of the :func:`sensitivity_evaluations`.
    """
    grid = result.augmenting
    if grid is None:
        note = vector_note(result.state)
        return {"kind": "unavailable", "reason": note or "h could not be evaluated on a grid"}
    if functionals is None:
        return {"kind": "unavailable", "reason": "E1, E2 could not be evaluated"}
    if functionals.get("E2_single_joint") is not None:  # (E2 by a Sobol rule, many joints)
        return single_joint_sensitivity(functionals)
    state = result.state
    if expensive_map(grid["map"]):
        return {
            "kind": "unavailable",
            "reason": "each value of E1, E2 of this map solves a "
            "collocation problem per node: no sweep in the dashboard",
        }
    if functionals.get("E1") is None and functionals.get("E2") is None:
        return {"kind": "unavailable", "reason": "E1, E2 are undefined on this box"}
    from jik.engine.functionals import (
        error_functional_e1,
        error_functional_e2,
        parameter_sensitivity,
    )

    spec = state_spec(state)
    kin, nodes, fixed = grid["kinematics"], functionals["nodes"], functionals["fixed"]
    region = {k: tuple(v) for k, v in functionals["region"].items()}
    aug = spec.augmentation(state.augmentation)

    def build(other, **params):
        if cancelled():
            raise Cancelled
        return other.build(kin, **params)

    total = sensitivity_evaluations(state, grid["map"])

    def report(done: int) -> None:
        if progress is not None:
            progress(done, total)

    try:
        if aug.parameters:
            out: dict = {"kind": "parameters", "parameters": dict(state.augmentation_parameters)}
            for k, key in enumerate(("E1", "E2")):

                def evaluated(done: int, n: int, k: int = k) -> None:
                    report(k * n + done)

                out[key] = parameter_sensitivity(
                    kin,
                    lambda **p: build(aug, **p),
                    state.augmentation_parameters,
                    region,
                    functional=key.lower(),
                    span=1.0,
                    samples=SENSITIVITY_SAMPLES,
                    nodes=nodes,
                    fixed=fixed,
                    on_evaluation=evaluated,
                )
            return out
        maps = []
        for m, other in enumerate(spec.augmentations):
            amap = build(other, **{p.name: p.default for p in other.parameters})
            if expensive_map(amap):
                report(2 * m + 2)
                continue
            row: dict = {"name": other.name, "current": other.name == aug.name}
            for key, fn in (("E1", error_functional_e1), ("E2", error_functional_e2)):
                try:
                    v = fn(kin, amap, region, nodes=nodes, fixed=fixed).value
                    row[key] = float(v) if np.isfinite(v) else None
                except (JikError, ValueError, ArithmeticError):
                    row[key] = None
            maps.append(row)
            report(2 * m + 2)
        return {"kind": "alternatives", "maps": maps}
    except (JikError, ValueError, ArithmeticError) as exc:
        return {"kind": "unavailable", "reason": str(exc)}
