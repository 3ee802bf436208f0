"""What the page writes above the plots, computed from the result: for each algorithm whether it
was repeatable on the closed path and by how much, how much h changed along the extended
Jacobian's run, and why, in sentences the page shows as they are.

Repeatability (section 2 of the paper): a closed task path driven from x0 gives a closed joint
path, ``x`` back at ``x0`` after each cycle. The extended Jacobian inverse (11) is repeatable
because its runs stay on the level set h(x) = h(x0) (eq. (12)); the continuous algorithm (7)
keeps h exactly, the discrete iteration ``x <- x - gamma J# e`` only to first order per step
(each step moves along the level set's tangent), and for gamma near 2 the iteration is at the
edge of convergence (the task error is multiplied by about ``1 - gamma`` per step).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ...engine.augmentations import H_CONSERVED, h_change
from ...engine.registry import POSE_A, POSE_B
from ...engine.repeatability import REPEATABLE_DRIFT, repeatable
from .joint_limits import limits_texts
from .plotting import norm_unit, units
from .runs import AlgorithmRun, DashboardResult
from .singular import singular_sentence
from .verdict_algorithms import NAMES, g, practical_sentences

#: In discrete mode, a gamma at or above this is "near 2" (the iteration's stability limit).
GAMMA_NEAR_TWO = 1.5


@dataclass(frozen=True)
class Sentence:
    """One sentence: its ``text``, the algorithm it is about (None: both or neither) and its
    ``role``: "finding" (what the run did), "why", "note" or "failure"."""

    text: str
    algorithm: str | None = None
    role: str = "finding"


def _drift_sentence(algorithm: str, run: AlgorithmRun, unit: str) -> Sentence:
    d = np.asarray(run.drift)
    n = len(d)
    cycles = f"{n} cycle{'s' if n > 1 else ''}"
    if repeatable(run.drift):
        text = (
            f"{NAMES[algorithm]}: repeatable. After each of {cycles} the joints came back "
            f"to x0 within {g(float(d.max()))} {unit} (‖x − x0‖ below {g(REPEATABLE_DRIFT)})."
        )
    else:
        trend = ""
        if n > 1:
            grows = d[-1] > d[0] * 1.05
            trend = (
                f", growing from {g(float(d[0]))} after cycle 1"
                if grows
                else f" (after cycle 1: {g(float(d[0]))})"
            )
        text = (
            f"{NAMES[algorithm]}: not repeatable. After {cycles} the joints end "
            f"‖x − x0‖ = {g(float(d[-1]))} {unit} away from x0{trend}."
        )
    return Sentence(text, algorithm)


def _extended_why(result: DashboardResult, run: AlgorithmRun) -> list[Sentence]:
    state = result.state
    dh = h_change(run.h)
    if dh is None or (not run.success and dh == 0):  # (a run stopped before it moved: no why)
        return []
    closed = state.task == "path" and len(run.drift) > 0
    kept = dh < H_CONSERVED
    out = []
    if kept:
        tail = (
            ", so each task point has one configuration on that level set, and the closed "
            "task path gave a closed joint path."
            if closed and repeatable(run.drift)
            else "."
        )
        out.append(
            Sentence(
                f"Why: J^E# adds the equation h(x) = h(x0) (eq. (12)); h changed by only {g(dh)} "
                f"along its run{tail}",
                "extended",
                "why",
            )
        )
    else:
        lost = (
            " A closed task path gives a closed joint path only while h stays at h(x0): "
            "here it did not, so the joints did not come back."
            if closed and not repeatable(run.drift)
            else ""
        )
        out.append(
            Sentence(
                f"h was not conserved: it changed by {g(dh)} along the extended Jacobian's run."
                + lost,
                "extended",
                "why",
            )
        )
    if state.mode == "discrete" and not kept:
        out.append(
            Sentence(
                "The discrete algorithm x ← x − γ J^E# e keeps h only approximately: each step "
                "moves along the tangent of the level set h = h(x0), not on it, so h changes by "
                "an amount that grows with γ (the continuous algorithm (7) keeps h exactly).",
                "extended",
                "note",
            )
        )
    if state.mode == "discrete" and state.gamma >= GAMMA_NEAR_TWO:
        out.append(
            Sentence(
                f"γ = {g(state.gamma)} is near 2, the limit of the discrete iteration: the task "
                f"error is multiplied by about 1 − γ = {g(1 - state.gamma)} per step, so the "
                "iterates overshoot back and forth and h is far from conserved; at γ ≥ 2 the "
                "iteration diverges.",
                None,
                "note",
            )
        )
    return out


#: Section 6.2's runs: the start pose, and the figures of its pseudoinverse and extended runs.
PAPER_RUNS = {
    "A": (POSE_A, "Figs. 11 (J^P#) and 12 (J^E#)"),
    "B": (POSE_B, "Figs. 13 (J^P#) and 14 (J^E#)"),
}


def _paper_run(result: DashboardResult) -> str | None:
    """The paper's sec. 6.2 run this unicycle result repeats ("A", "B"), None if none."""
    state = result.state
    if state.robot != "unicycle" or state.augmentation != "characteristics":
        return None
    q0 = np.asarray(state.robot_parameters.get("q0", ()), dtype=float)
    for name, (pose, _) in PAPER_RUNS.items():
        if q0.shape == (3,) and np.allclose(q0, pose, atol=1e-9):
            return name
    return None


def _undefined_why(result: DashboardResult, run: AlgorithmRun) -> list[Sentence]:
    """Why the unicycle's map of characteristics (29) became undefined along the extended run:
    the step that left the foliation's domain (lambda10 of the sign of the reference leaf's a,
    omega being undefined on lambda10 = 0), the characteristic (28) from there running into a
    zero of the kernel component that normalises omega, and, for the paper's run B, that this is
    Figs. 13-14's run and docs/paper-errata.md's finding."""
    state = result.state
    if (
        state.robot != "unicycle"
        or state.augmentation != "characteristics"
        or run.status != "undefined"
        or len(run.x) < 2
    ):
        return []
    a = float(state.augmentation_parameters.get("a", 1.0))
    before, after = float(run.x[-2][0]), float(run.x[-1][0])
    which = f"iteration {len(run.x) - 1}" if state.mode == "discrete" else "the run's last step"
    step = f"{which} took lambda10 from {g(before)} to {g(after)}"
    if after * a <= 0:
        left = (
            f"{step}, across lambda10 = 0 and out of the domain of the map's foliation "
            f"(lambda10 of the sign of a = {g(a)}: ω is undefined on lambda10 = 0)"
        )
    else:
        left = step
    text = (
        f"Why: h is defined by the characteristic (28) from x to the reference leaf "
        f"lambda10 = a (eq. (29)); {left}. From there the characteristic runs into a zero of the "
        "kernel component that normalises ω (J11 J24 − J14 J21 = 0), where ω and dz/ds "
        "blow up, so h, and with it the extended Jacobian inverse (47), is undefined."
    )
    out = [Sentence(text, "extended", "why")]
    paper = _paper_run(result)
    if paper is not None:
        figures = PAPER_RUNS[paper][1]
        note = (
            f"This is the paper's run from q0 = {paper} (sec. 6.2, {figures}). Where the "
            "paper plots the extended run to its end, jik finds that it leaves the domain "
            'of h: docs/paper-errata.md (Unicycle, "Section 6.2, what jik finds") '
            "explains it, with a command that shows it."
        )
        if state.mode == "discrete":
            note += (
                " In mode continuous h is conserved exactly and the extended run from "
                f"q0 = {paper} converges."
            )
        out.append(Sentence(note, "extended", "note"))
    return out


def _pseudoinverse_why(run: AlgorithmRun) -> list[Sentence]:
    if repeatable(run.drift) is False:
        return [
            Sentence(
                "Why: J^P# picks the minimum-norm joint velocity, which has no memory of the start "
                "(it keeps nothing like h constant), so a closed task path need not close in the "
                "joints.",
                "pseudoinverse",
                "why",
            )
        ]
    if repeatable(run.drift):
        return [
            Sentence(
                "The pseudoinverse happens to come back on this path: its joint flow closes here, "
                "which it does not in general.",
                "pseudoinverse",
                "why",
            )
        ]
    return []


def verdict(result: DashboardResult) -> list[dict]:
    """The sentences the page shows above the plots for ``result`` (:class:`Sentence` dicts):
    each chosen algorithm's finding, then why (:mod:`.verdict_algorithms` for the practical
    inverses); failures with the engine's message."""
    runs = result.runs
    out: list[Sentence] = []
    path = result.state.task == "path"
    unit = norm_unit(units(result)[0])
    for algorithm, run in runs.items():
        if path and len(run.drift):
            out.append(_drift_sentence(algorithm, run, unit))
        elif run.success:
            out.append(Sentence(f"{NAMES[algorithm]}: {run.message}.", algorithm))
        if not run.success:
            done = (
                f" (after {len(run.drift)} completed cycle{'s' if len(run.drift) > 1 else ''})"
                if path and len(run.drift)
                else ""
            )
            out.append(
                Sentence(f"{NAMES[algorithm]} stopped{done}: {run.message}", algorithm, "failure")
            )
    out += _pseudoinverse_why(runs["pseudoinverse"]) if path and "pseudoinverse" in runs else []
    if "extended" in runs:
        ext = runs["extended"]
        out += _undefined_why(result, ext) or _extended_why(result, ext)
    out += [Sentence(*s) for s in practical_sentences(result, unit)]
    for text, algorithm, within in limits_texts(result, NAMES):
        out.append(Sentence(text, algorithm, "note" if within else "warning"))
    if "extended" in runs and (warning := singular_sentence(result.state)):
        out.append(Sentence(warning, "extended", "warning"))
    return [asdict(s) for s in out]
