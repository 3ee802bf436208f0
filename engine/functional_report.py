"""E1 (13) and E2 (18) of a map, or a vector of p - r maps, on a region as plain data, whatever
the region's dimension (what the dashboard's E1/E2 panel and its export show), and how they change
with a map's parameters.

Over at most :data:`MAX_TENSOR_VARIABLES` variables both are taken by the tensor Gauss rule of
:mod:`jik.engine.functionals`, each with its singular points. Over more, a tensor rule is too
large (``nodes ** 7`` points for a 7-joint arm): both are taken by the scrambled Sobol rule of
the total-degree synthesis (:mod:`jik.engine.e2_qmc`, docs/e2-vector.md), for one degree of
redundancy with E2 of h = s x_j for each joint beside it, which compares the map with holding a
single joint. E2 of a vector of maps depends on the kernel frame (:mod:`jik.engine.kernel_frame`),
which the report names.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from .augmentations import AugmentingMap
from .e2_qmc import e1_qmc, e2_qmc, error_estimate
from .exceptions import InvalidInputError, JikError
from .functionals import Region, check_region, error_functional_e1, error_functional_e2
from .inverses import require_kinematics
from .kernel_frame import frame_axes_of, require_maps
from .kinematics import Kinematics
from .progress import Progress, check_cancelled, check_progress, part
from .robot_synthesis import TOTAL_NODES as QMC_NODES
from .validation import count, finite

#: The most region variables of a tensor Gauss rule.
MAX_TENSOR_VARIABLES = 3
#: Seed of the Sobol rule's scrambling: the synthesis's independent check rule (its ``e2_check``).
QMC_SEED = 1


def functional_info(
    key: str,
    kinematics,
    amap,
    region: Mapping,
    fixed,
    nodes: int = 12,
    frame_axes=None,
    progress=None,
) -> dict:
    """E1 (13) or E2 (18) (``key`` "E1" or "E2") of ``amap`` (a map, or a vector of p - r maps)
    on ``region`` by the rule its size calls for: the Gauss rule of ``nodes`` per variable
    (:mod:`jik.engine.functionals`) over at most :data:`MAX_TENSOR_VARIABLES` variables, else
    the Sobol rule of :data:`QMC_NODES` nodes (:mod:`jik.engine.e2_qmc`). ``{"value": float, or
    None where infinite or undefined, "divergent", "n_points", "n_singular" (points where
    [J; dh] is singular; of the Sobol rule, where h is undefined), "min_abs_dh_k" (None for E2
    by the Sobol rule), "frame_axes" (E2 of a vector: 1-based, else None), "rule": "gauss" or
    "sobol", "error_estimate" (the Sobol rule's, :func:`~jik.engine.e2_qmc.error_estimate`;
    None for the Gauss rule)}``, and E2's ``single_joint`` by the Sobol rule (one degree of
    redundancy).
    ``progress`` follows the Sobol rule's nodes. Raises what the functional raises."""
    if key not in ("E1", "E2"):
        raise InvalidInputError(f"key must be 'E1' or 'E2', got {key!r}", "key")
    if len(region) <= MAX_TENSOR_VARIABLES:
        if key == "E1":
            value = error_functional_e1(kinematics, amap, region, nodes=nodes, fixed=fixed)
        else:
            value = error_functional_e2(
                kinematics, amap, region, nodes=nodes, fixed=fixed, frame_axes=frame_axes
            )
        info = value.as_dict()
        return {k: info[k] for k in _INFO} | {"rule": "gauss", "error_estimate": None}
    rule: dict = {"fixed": fixed, "nodes": QMC_NODES, "seed": QMC_SEED, "progress": progress}
    out = {"n_points": QMC_NODES, "rule": "sobol", "frame_axes": None}
    if key == "E1":
        e1 = e1_qmc(kinematics, amap, region, **rule)
        return out | {
            "value": None if e1["divergent"] else e1["E1"],
            "error_estimate": error_estimate(e1["E1"], e1["E1_half"]),
            "divergent": e1["divergent"],
            "n_singular": e1["undefined_points"],
            "min_abs_dh_k": e1["min_abs_dh_k"],
        }
    e2 = e2_qmc(kinematics, amap, region, frame_axes=frame_axes, **rule)
    return out | {
        "value": e2["E2"],
        "error_estimate": error_estimate(e2["E2"], e2["E2_half"]),
        "divergent": False,
        "n_singular": e2["undefined_points"],
        "min_abs_dh_k": None,
        "frame_axes": e2["frame_axes"],
        "single_joint": e2["single_joint"] or None,
    }


#: The fields of :meth:`~jik.engine.functionals.FunctionalValue.as_dict` a functional's info keeps.
_INFO = ("value", "divergent", "n_points", "n_singular", "min_abs_dh_k", "frame_axes")


def functional_value(
    key: str, kinematics, amap, region: Mapping, nodes: int, fixed, frame_axes=None, progress=None
) -> dict:
    """``{key: E1 or E2 of :func:`functional_info`, or None where undefined}`` with its singular
    points, the Sobol rule's ``key_error_estimate``, ``key_divergent`` (E1 = inf) or
    ``key_error`` (why it could not be evaluated) if so,
    E2's ``E2_frame_axes`` for a vector (``frame_axes``, else the best conditioned) and, by the
    Sobol rule, ``E2_single_joint``."""
    try:
        info = functional_info(key, kinematics, amap, region, fixed, nodes, frame_axes, progress)
    except (JikError, ValueError, ArithmeticError) as exc:
        return {key: None, f"{key}_error": str(exc)}
    out: dict = {key: info["value"], f"{key}_singular_points": info["n_singular"]}
    if info["error_estimate"] is not None:
        out[f"{key}_error_estimate"] = info["error_estimate"]
    if info["frame_axes"]:
        out[f"{key}_frame_axes"] = info["frame_axes"]
    if "single_joint" in info:
        out["E2_single_joint"] = info["single_joint"]
    return out | ({f"{key}_divergent": True} if info["divergent"] else {})


def functionals_report(
    kinematics,
    amap,
    region: Mapping,
    fixed: Mapping | None = None,
    nodes: int = 12,
    progress: Progress | None = None,
    frame_axes=None,
) -> dict:
    """E1 and E2 of ``amap`` (a map, or for p - r >= 2 a vector of p - r maps) on ``region``
    (name -> (lo, hi)), the other variables at ``fixed`` (default:
    :func:`~jik.engine.robot_defaults.held_values`), each by :func:`functional_value` (the
    Gauss rule of ``nodes`` per variable over at most three variables, else the Sobol rule of
    :data:`QMC_NODES` nodes, with ``E2_single_joint`` (name -> {"sign", "e2"}; for one degree
    of redundancy), ``E2_rule`` (the rule of both) and a ``note`` saying how). For a vector,
    ``E2_frame_axes``: the 1-based joints fixing the kernel frame E2 depends on
    (``frame_axes``, default the best conditioned at the box's centre). A functional that
    cannot be evaluated on a valid region (h undefined there) is reported as data
    (``E1_error``, ``E2_error``); invalid input raises.

    ``progress`` (:class:`~jik.engine.progress.Progress`) is told ``advance(k, 2)`` after each
    of the two functionals (what it raises stops them), and the Sobol rule's fraction of nodes
    done; its ``cancelled()`` is polled between them and between the Sobol rule's chunks of
    nodes (:class:`~jik.engine.exceptions.RunCancelled`).

    Raises
    ------
    InvalidInputError
        ``kinematics`` not a Kinematics, ``amap`` not an AugmentingMap or p - r of them,
        ``region`` or ``fixed`` not a box of the robot's variables and values of the others
        (:func:`~jik.engine.functionals.check_region`), ``nodes`` not 1 to 400, ``frame_axes``
        not p - r distinct joints, ``progress`` not a Progress.
    """
    kinematics = require_kinematics(kinematics)
    amap = require_maps(kinematics, amap, "E1, E2", "amap")
    region, fixed = check_region(kinematics, region, fixed)
    nodes, progress = count(nodes, "nodes", 1, 400), check_progress(progress)
    axes = frame_axes_of(kinematics, region, fixed, frame_axes)
    frame = None if axes is None else [a + 1 for a in axes]
    out: dict = {}
    for k, key in enumerate(("E1", "E2")):
        check_cancelled(progress, "E1, E2")
        out |= functional_value(
            key, kinematics, amap, region, nodes, fixed, frame, part(progress, k, 2)
        )
        if progress is not None:
            progress.advance(k + 1, 2)
    if len(region) <= MAX_TENSOR_VARIABLES:
        return out
    out["E2_rule"] = {"kind": "sobol", "nodes": QMC_NODES, "seed": QMC_SEED}
    frame_words = "" if frame is None else f", E2 in the kernel frame of joints {frame}"
    if "E1_error" in out and out.get("E2_error") == out["E1_error"]:
        out["note"] = f"E1, E2 not computed: {out['E1_error']}"
    else:
        how = f"(Sobol rule, {QMC_NODES} nodes{frame_words})"
        out["note"] = f"{report_words(out, 'the region')} {how}"
    return out


def parameter_sensitivity(
    kinematics: Kinematics,
    factory: Callable[..., AugmentingMap],
    parameters: Mapping[str, float],
    region: Region,
    *,
    functional: str = "e2",
    span: float = 1.0,
    samples: int = 21,
    nodes: int = 16,
    fixed: Mapping[str, float] | None = None,
    progress: Progress | None = None,
) -> dict:
    """The value of E1 or E2 at the given parameters and how it changes as each one moves.

    Parameters
    ----------
    factory : callable
        ``factory(**parameters) -> AugmentingMap``, e.g. ``E2Optimal`` or ``E1Optimal``.
    parameters : mapping name -> value
        The current parameters (C1, C2 or a, b).
    functional : {"e1", "e2"}
    span, samples : float, int
        Each parameter is swept over [v - span, v + span] with ``samples`` values, the others
        held; parameter values where the map cannot be built are reported as None.
    progress : Progress, optional
        Told ``advance(done, total)`` after each of the ``1 + len(parameters) (2 + samples)``
        evaluations of the functional, and polled before each: ``cancelled()`` True stops the
        sweep with :class:`~jik.engine.exceptions.RunCancelled`.

    Returns
    -------
    dict
        ``{"value", "gradient": {name: dE/dname (central differences, step 1e-4)},
        "sweeps": {name: {"values": [...], "functional": [...]}}}``.
    """
    if functional not in ("e1", "e2"):
        raise InvalidInputError(
            f"functional must be 'e1' or 'e2', got {functional!r}", "functional"
        )
    samples = count(samples, "samples", 2, 201)
    span = finite(span, "span")
    evaluate = error_functional_e1 if functional == "e1" else error_functional_e2
    base = {k: finite(v, k) for k, v in parameters.items()}
    total, done = 1 + len(base) * (2 + samples), 0

    def at(params: dict) -> float | None:
        nonlocal done
        check_cancelled(progress, f"the sweep of {functional.upper()}")
        try:
            amap = factory(**params)
        except InvalidInputError:
            v = np.nan
        else:
            v = evaluate(kinematics, amap, region, nodes=nodes, fixed=fixed).value
        done += 1
        if progress is not None:
            progress.advance(done, total)
        return v if np.isfinite(v) else None

    out: dict = {"value": at(base), "gradient": {}, "sweeps": {}}
    step = 1e-4
    for name, v in base.items():
        hi, lo = at({**base, name: v + step}), at({**base, name: v - step})
        out["gradient"][name] = None if hi is None or lo is None else (hi - lo) / (2 * step)
        grid = np.linspace(v - span, v + span, samples)
        out["sweeps"][name] = {
            "values": grid.tolist(),
            "functional": [at({**base, name: float(g)}) for g in grid],
        }
    return out


def region_words(region: Mapping) -> str:
    """A box (name -> (lo, hi)) in words: ``x2 ∈ [-1, 1], x3 ∈ [0, 3.14]``."""
    return ", ".join(f"{k} ∈ [{lo:.3g}, {hi:.3g}]" for k, (lo, hi) in region.items())


def report_words(report: Mapping, where: str) -> str:
    """A :func:`functionals_report` in words, on ``where`` (the box, in words): its note if it
    has one, else each functional's value (± the Sobol rule's error estimate), ∞ where E1
    diverges (dh K = 0 inside) or undefined."""
    if report.get("note"):
        return report["note"]
    values = {k: report.get(k) for k in ("E1", "E2")}
    if all(v is None for v in values.values()):
        return f"E1, E2 undefined: h is not defined on all of {where}"
    return (
        ", ".join(
            f"{k} = {v:.4g}{plus_minus(report.get(f'{k}_error_estimate'))}"
            if v is not None
            else f"{k} = ∞ (dh K = 0 inside)"
            if report.get(f"{k}_divergent")
            else f"{k} undefined"
            for k, v in values.items()
        )
        + f" on {where}"
    )


def plus_minus(estimate: float | None) -> str:
    """ " ± e" of a functional's error estimate ``estimate`` (one digit), "" without one."""
    return "" if estimate is None else f" ± {estimate:.1g}"


def parameters_report(
    kinematics,
    factory,
    parameters: Mapping,
    region: Mapping,
    nodes: int,
    fixed,
    samples: int,
    progress: Progress | None = None,
) -> dict:
    """How E1 (13) and E2 (18) of the map ``factory(**parameters)`` change with its parameters:
    ``{"kind": "parameters", "parameters", "E1", "E2"}``, each functional's
    :func:`parameter_sensitivity` (its value, gradient and a sweep of
    ``samples`` values of every parameter over v - 1 .. v + 1) by a tensor rule of ``nodes``;
    ``progress`` told after each evaluation of either functional (E1's sweep its first half) and
    polled before each (:class:`~jik.engine.exceptions.RunCancelled`)."""
    out: dict = {"kind": "parameters", "parameters": dict(parameters)}
    for k, key in enumerate(("E1", "E2")):
        out[key] = parameter_sensitivity(
            kinematics,
            factory,
            parameters,
            region,
            functional=key.lower(),
            samples=samples,
            nodes=nodes,
            fixed=fixed,
            progress=part(progress, k, 2),
        )
    return out


def maps_report(
    kinematics,
    maps,
    current: str,
    region: Mapping,
    nodes: int,
    fixed,
    progress: Progress | None = None,
) -> dict:
    """E1 (13) and E2 (18) of each of ``maps`` ((name, build) pairs, ``build()`` the map):
    ``{"kind": "alternatives", "maps": [{"name", "current", "E1", "E2"}]}`` (``current``: the
    map named so; ``E1_divergent`` True where E1 = inf), by :func:`functional_value`, none of a
    map that solves a problem per point; ``progress`` told after each map (two evaluations a
    map) and polled before each (:class:`~jik.engine.exceptions.RunCancelled`)."""
    rows = []
    for m, (name, build) in enumerate(maps):
        check_cancelled(progress, "E1, E2 of the robot's maps")
        amap = build()
        if not amap.solves_per_point:
            row: dict = {"name": name, "current": name == current}
            for key in ("E1", "E2"):
                value = functional_value(key, kinematics, amap, region, nodes, fixed)
                row[key] = value[key]
                if value.get(f"{key}_divergent"):  # (E1 = inf: dh K = 0 inside)
                    row[f"{key}_divergent"] = True
            rows.append(row)
        if progress is not None:
            progress.advance(2 * m + 2, 2 * len(maps))
    return {"kind": "alternatives", "maps": rows}
