"""Manipulator 2 (sec. 5.2): E2 synthesis of h(x2, x3), its cubic fit, Table 1 with it.

``run()`` synthesises the E2-optimal map on x2 in [-1, 1], x3 in [0, pi] (natural boundary
conditions, mean zero), compares its E2 with the paper's cubic (38), shows the convergence of E2
with the basis degree against a finer reference solve, and runs Table 1's closed path with the
extended Jacobian of ``e2_synthesized`` beside the pseudoinverse and (38).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from ..augmentations import PaperCubic
from ..functionals import error_functional_e1, error_functional_e2
from ..inverses import ExtendedInverse, Pseudoinverse
from ..kinematics import Manipulator2
from ..progress import ProgressCallbacks
from ..symbolic import findings_summary, manipulator2_findings
from ..variational import (
    MANIPULATOR2_DEGREE,
    MANIPULATOR2_REGION,
    synthesize_e2,
    synthesize_manipulator2,
)
from .table1 import cell
from .table1 import rows as table1_rows

#: Degree of the reference solve that stands for the converged minimum.
REFERENCE_DEGREE = 40
NODES = 48


def _distances(rows: np.ndarray, reference: np.ndarray) -> list[float]:
    return np.linalg.norm(rows - reference, axis=1).tolist()


def run(progress: Callable[[float], None] | None = None, symbolic: bool = True) -> dict:
    """The Manipulator 2 reproduction as a JSON-friendly dict."""
    report = progress or (lambda f: None)
    kin = Manipulator2()
    t0 = time.perf_counter()
    res = synthesize_manipulator2(
        1.0, progress=ProgressCallbacks(on_advance=lambda done, total: report(0.3 * done / total))
    )
    seconds = time.perf_counter() - t0
    reference = synthesize_e2(kin, MANIPULATOR2_REGION, degree=REFERENCE_DEGREE).e2
    report(0.4)
    cubic = error_functional_e2(kin, PaperCubic(), MANIPULATOR2_REGION, nodes=NODES)
    ours = error_functional_e2(kin, res.augmenting_map, MANIPULATOR2_REGION, nodes=NODES)
    e1 = {
        name: error_functional_e1(kin, h, MANIPULATOR2_REGION, nodes=NODES)
        for name, h in (("paper_cubic", PaperCubic()), ("e2_synthesized", res.augmenting_map))
    }
    table = {
        "pseudoinverse": np.array(table1_rows(Pseudoinverse(kin))),
        "paper_cubic": np.array(table1_rows(ExtendedInverse(kin, PaperCubic()))),
    }
    report(0.7)
    table["e2_synthesized"] = np.array(table1_rows(ExtendedInverse(kin, res.augmenting_map)))
    report(0.9)
    findings = manipulator2_findings(1.0) if symbolic else []
    report(1.0)
    return {
        "region": {k: list(v) for k, v in MANIPULATOR2_REGION.items()},
        "E2": {"paper_cubic": cubic.value, "e2_synthesized": ours.value},
        # E1 (13): null where it diverges (dh K = 0 inside the region, eq. (14))
        "E1": {k: None if v.divergent else v.value for k, v in e1.items()},
        "E1_divergent": {k: v.divergent for k, v in e1.items()},
        "polynomial": res.polynomial_coefficients(),
        "table1_extended": table["e2_synthesized"].tolist(),
        "polynomial_e2": res.polynomial_e2,
        "e2_zero_map": float(np.sqrt(2.0) * np.pi * 2.0),
        "convergence": res.convergence,
        "reference": {"degree": REFERENCE_DEGREE, "e2": reference},
        "relative_gap_to_reference": (res.e2 - reference) / reference,
        "degree": MANIPULATOR2_DEGREE,
        "synthesis_seconds": seconds,
        "normalisation": "natural boundary conditions; mean of h over the box = 0; x1 = 0",
        "table1": {k: v.tolist() for k, v in table.items()},
        "distance_to_pseudoinverse": {
            k: _distances(table[k], table["pseudoinverse"])
            for k in ("paper_cubic", "e2_synthesized")
        },
        "cycle_drift": {k: float(np.linalg.norm(v[-1] - v[0])) for k, v in table.items()},
        "min_abs_dh_k": {"paper_cubic": cubic.min_abs_dh_k, "e2_synthesized": ours.min_abs_dh_k},
        "symbolic": {"findings": findings, "summary": findings_summary(findings)},
    }


def _e1(result: dict, name: str) -> str:
    """E1 of a map in the table's column: its value, or inf where it diverges."""
    value = result["E1"][name]
    return f"{'inf':>14}" if value is None else f"{value:>14.8f}"


def format_text(result: dict) -> str:
    """Readable tables of :func:`run`'s result."""
    reg = ", ".join(f"{k} in [{a:g}, {b:.6g}]" for k, (a, b) in result["region"].items())
    e2 = result["E2"]
    out = [
        f"Manipulator 2 (l = 1), region {reg}, h = h(x2, x3); "
        f"synthesis {result['synthesis_seconds']:.3f} s",
        "",
        f"{'augmenting map':<28} {'E2 (18)':>14} {'E1 (13)':>14}",
        f"{'paper_cubic (38)':<28} {e2['paper_cubic']:>14.8f} {_e1(result, 'paper_cubic')}",
        f"{'e2_synthesized':<28} {e2['e2_synthesized']:>14.8f} {_e1(result, 'e2_synthesized')}",
        f"{'cubic fit of e2_synthesized':<28} {result['polynomial_e2']:>14.8f}",
        f"{'h = const (dh = 0)':<28} {result['e2_zero_map']:>14.8f}",
        "(E1 = inf: dh K vanishes inside the region, so the extended Jacobian is singular there)",
        "",
        f"convergence (reference degree {result['reference']['degree']}: "
        f"E2 = {result['reference']['e2']:.12f})",
        f"{'degree':>6} {'unknowns':>9} {'E2':>18} {'relative gap':>13}",
    ]
    ref = result["reference"]["e2"]
    for c in result["convergence"]:
        gap = (c["e2"] - ref) / ref
        out.append(f"{c['degree']:>6} {c['unknowns']:>9} {c['e2']:>18.12f} {gap:>13.2e}")
    out += ["", "cubic fit (like (38)), h = sum c x2^i x3^j:"]
    out += [f"  {k:<12} {v:>+12.6f}" for k, v in result["polynomial"].items()]
    out += ["", "Table 1 path, configuration after each leg (|x - x_pinv| in brackets):"]
    labels = ["A x0 ", "B x1f", "C x2f", "D x3f", "A x4f"]
    for name in ("pseudoinverse", "paper_cubic", "e2_synthesized"):
        out.append(f"  {name}  (cycle drift {result['cycle_drift'][name]:.2e})")
        dist = result["distance_to_pseudoinverse"].get(name)
        for i, row in enumerate(result["table1"][name]):
            d = f"  [{dist[i]:.4f}]" if dist else ""
            out.append(f"    {labels[i]} " + " ".join(cell(v) for v in row) + d)
    if result["symbolic"]["findings"]:
        out += ["", "Symbolic checks (sympy):"]
        for f in result["symbolic"]["findings"]:
            out.append(f"  [{'holds' if f['holds'] else 'FAILS'}] {f['claim']}")
    return "\n".join(out)
