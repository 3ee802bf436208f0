"""E2 of a map over more joints than a tensor rule can take (a 7-joint arm's synthesized map).

The dashboard takes E1 (13) and E2 (18) by a tensor Gauss rule over at most three variables
(:func:`jik.app.dashboard.functionals.error_functionals`). Over more, for one degree of redundancy,
E2 is taken by the scrambled Sobol rule of the total-degree synthesis
(:func:`jik.engine.e2_qmc.e2_qmc`, docs/e2-vector.md), with E2 of h = s x_j for each joint
beside it: the E1/E2 panel compares the map with holding a single joint. E1 has no such rule
here and is not computed. It runs in the second phase, which polls ``cancelled`` between the
rule's chunks of nodes.
"""

from __future__ import annotations

from collections.abc import Callable

from ...engine.e2_qmc import e2_qmc
from ...engine.exceptions import JikError, RunCancelled
from ...engine.progress import ProgressCallbacks
from ...engine.robot_synthesis import TOTAL_NODES as QMC_NODES

#: Seed of the rule's scrambling: the synthesis's independent check rule (its ``e2_check``).
QMC_SEED = 1


def qmc_functionals(
    grid: dict, region: dict, fixed: dict, out: dict, cancelled, on_step: Callable[[], None]
) -> dict:
    """``out`` (the region, fixed variables) with E2 of the grid's map by the Sobol rule of a
    synthesis over more than three joints (:data:`~jik.engine.robot_synthesis.TOTAL_NODES`
    nodes) and ``E2_single_joint`` (name -> {"sign", "e2"}) when p - r = 1; E1 None and a
    ``note`` saying why and how. Raises :class:`~jik.app.dashboard.runs.Cancelled` when
    ``cancelled()`` turns True; ``on_step()`` twice when done (the two functionals' steps)."""
    from .runs import Cancelled

    kin = grid["kinematics"]
    large = f"a tensor rule over the {len(region)} variables of the design region is too large"
    if kin.p - kin.r != 1:
        return {**out, "E1": None, "E2": None, "note": f"E1, E2 not computed: {large}"}
    report = ProgressCallbacks(is_cancelled=cancelled)
    try:
        e2 = e2_qmc(
            kin, grid["map"], region, fixed=fixed, nodes=QMC_NODES, seed=QMC_SEED, progress=report
        )
    except RunCancelled:
        raise Cancelled from None
    except (JikError, ValueError, ArithmeticError) as exc:
        e2 = {"E2": None, "error": str(exc)}
    on_step()
    on_step()
    if "error" in e2:
        return {
            **out,
            "E1": None,
            "E2": None,
            "E2_error": e2["error"],
            "note": f"E1 not computed: {large}; E2 not computed: {e2['error']}",
        }
    value = "undefined (h is not defined on all of it)" if e2["E2"] is None else (f"{e2['E2']:.4g}")
    return {
        **out,
        "E1": None,
        "E2": e2["E2"],
        "E2_single_joint": e2["single_joint"],
        "E2_rule": {"kind": "sobol", "nodes": QMC_NODES, "seed": QMC_SEED},
        "note": f"E2 = {value} on the design box (Sobol rule, {QMC_NODES} nodes); "
        f"E1 not computed over {len(region)} joints",
    }


def single_joint_sensitivity(functionals: dict) -> dict:
    """The E1/E2 panel's data for a map whose E2 came from :func:`qmc_functionals`: E2 of the
    map and of h = s x_j for each joint, ``{"kind": "single_joint", "E2", "maps": [{"name",
    "E2", "current"}], "nodes"}``."""
    maps = [{"name": "h (current)", "E2": functionals["E2"], "current": True}]
    for name, row in functionals["E2_single_joint"].items():
        sign = "+" if row["sign"] > 0 else "−"
        maps.append({"name": f"h = {sign}{name}", "E2": row["e2"], "current": False})
    return {
        "kind": "single_joint",
        "E2": functionals["E2"],
        "maps": maps,
        "nodes": functionals["E2_rule"]["nodes"],
    }
