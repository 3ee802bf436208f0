"""E1 (13) and E2 (18) of a map on a region as plain data, whatever the region's dimension (what
the dashboard's E1/E2 panel and its export show).

Over at most :data:`MAX_TENSOR_VARIABLES` variables both are taken by the tensor Gauss rule of
:mod:`jik.engine.functionals`, each with its singular points. Over more, a tensor rule is too
large (``nodes ** 7`` points for a 7-joint arm): for one degree of redundancy, E2 is taken by the
scrambled Sobol rule of the total-degree synthesis (:func:`jik.engine.e2_qmc.e2_qmc`,
docs/e2-vector.md), with E2 of h = s x_j for each joint beside it, which compares the map with
holding a single joint. E1 has no such rule and is not computed.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .e2_qmc import e2_qmc
from .exceptions import JikError
from .functionals import (
    check_region,
    error_functional_e1,
    error_functional_e2,
    parameter_sensitivity,
)
from .inverses import require_kinematics, require_map
from .progress import Progress, check_cancelled, check_progress, part
from .robot_synthesis import TOTAL_NODES as QMC_NODES
from .validation import count

#: The most region variables of a tensor Gauss rule.
MAX_TENSOR_VARIABLES = 3
#: Seed of the Sobol rule's scrambling: the synthesis's independent check rule (its ``e2_check``).
QMC_SEED = 1


def functional_value(key: str, kinematics, amap, region: Mapping, nodes: int, fixed) -> dict:
    """``{key: E1 (13) or E2 (18) (``key`` "E1" or "E2") of ``amap`` on ``region`` by a tensor
    rule of ``nodes`` per variable, or None where undefined}`` with its singular points, and
    ``key_divergent`` (E1 = inf) or ``key_error`` (why it could not be evaluated) if so."""
    fn = error_functional_e1 if key == "E1" else error_functional_e2
    try:
        value = fn(kinematics, amap, region, nodes=nodes, fixed=fixed)
    except (JikError, ValueError, ArithmeticError) as exc:
        return {key: None, f"{key}_error": str(exc)}
    out = {
        key: float(value.value) if np.isfinite(value.value) else None,
        f"{key}_singular_points": int(value.singular_points.shape[0]),
    }
    return out | ({f"{key}_divergent": True} if value.divergent else {})


def functionals_report(
    kinematics,
    amap,
    region: Mapping,
    fixed: Mapping | None = None,
    nodes: int = 12,
    progress: Progress | None = None,
) -> dict:
    """E1 and E2 of ``amap`` on ``region`` (name -> (lo, hi)), the other variables at
    ``fixed`` (default: :func:`~jik.engine.robot_defaults.held_values`), as the module's notes
    say: by the tensor rule (:func:`functional_value` of each, ``nodes`` per variable), else by
    the Sobol rule of :data:`QMC_NODES` nodes: ``E2``, ``E2_single_joint`` (name -> {"sign",
    "e2"}) and ``E2_rule``, ``E1`` None and a ``note`` saying why and how. A functional that
    cannot be evaluated on a valid region (h undefined there) is reported as data
    (``E1_error``, ``E2_error``); invalid input raises.

    ``progress`` (:class:`~jik.engine.progress.Progress`) is told ``advance(k, 2)`` after each
    of the two functionals (what it raises stops them), and the Sobol rule's fraction of nodes
    done; its ``cancelled()`` is polled between them and between the Sobol rule's chunks of
    nodes (:class:`~jik.engine.exceptions.RunCancelled`).

    Raises
    ------
    InvalidInputError
        ``kinematics`` not a Kinematics, ``amap`` not an AugmentingMap, ``region`` or
        ``fixed`` not a box of the robot's variables and values of the others
        (:func:`~jik.engine.functionals.check_region`), ``nodes`` not 1 to 400, ``progress``
        not a Progress.
    """
    kinematics = require_kinematics(kinematics)
    amap = require_map(amap, kinematics, "amap")
    region, fixed = check_region(kinematics, region, fixed)
    nodes, progress = count(nodes, "nodes", 1, 400), check_progress(progress)
    if len(region) <= MAX_TENSOR_VARIABLES:
        out: dict = {}
        for k, key in enumerate(("E1", "E2"), start=1):
            check_cancelled(progress, "E1, E2")
            out |= functional_value(key, kinematics, amap, region, nodes, fixed)
            if progress is not None:
                progress.advance(k, 2)
        return out
    large = f"a tensor rule over the {len(region)} variables of the design region is too large"
    if kinematics.p - kinematics.r != 1:
        return {"E1": None, "E2": None, "note": f"E1, E2 not computed: {large}"}
    try:
        e2 = e2_qmc(
            kinematics, amap, region, fixed=fixed, nodes=QMC_NODES, seed=QMC_SEED, progress=progress
        )
    except (JikError, ValueError, ArithmeticError) as exc:
        e2 = {"E2": None, "error": str(exc)}
    if progress is not None:
        progress.advance(2, 2)
    if "error" in e2:
        return {
            "E1": None,
            "E2": None,
            "E2_error": e2["error"],
            "note": f"E1 not computed: {large}; E2 not computed: {e2['error']}",
        }
    value = "undefined (h is not defined on all of it)" if e2["E2"] is None else (f"{e2['E2']:.4g}")
    return {
        "E1": None,
        "E2": e2["E2"],
        "E2_single_joint": e2["single_joint"],
        "E2_rule": {"kind": "sobol", "nodes": QMC_NODES, "seed": QMC_SEED},
        "note": f"E2 = {value} on the design box (Sobol rule, {QMC_NODES} nodes); "
        f"E1 not computed over {len(region)} joints",
    }


def region_words(region: Mapping) -> str:
    """A box (name -> (lo, hi)) in words: ``x2 ∈ [-1, 1], x3 ∈ [0, 3.14]``."""
    return ", ".join(f"{k} ∈ [{lo:.3g}, {hi:.3g}]" for k, (lo, hi) in region.items())


def report_words(report: Mapping, where: str) -> str:
    """A :func:`functionals_report` in words, on ``where`` (the box, in words): its note if it
    has one, else each functional's value, ∞ where E1 diverges (dh K = 0 inside) or undefined."""
    if report.get("note"):
        return report["note"]
    values = {k: report.get(k) for k in ("E1", "E2")}
    if all(v is None for v in values.values()):
        return f"E1, E2 undefined: h is not defined on all of {where}"
    return (
        ", ".join(
            f"{k} = {v:.4g}"
            if v is not None
            else f"{k} = ∞ (dh K = 0 inside)"
            if report.get(f"{k}_divergent")
            else f"{k} undefined"
            for k, v in values.items()
        )
        + f" on {where}"
    )


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
    :func:`~jik.engine.functionals.parameter_sensitivity` (its value, gradient and a sweep of
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
