"""What the page writes above the plots, computed from the result: for each algorithm whether it
was repeatable on the closed path and by how much, how much h changed along the extended
Jacobian's run, and why, in sentences the page shows as they are (the engine's
:mod:`jik.engine.findings`, which says what repeatability is and why the extended Jacobian has
it, and what the practical inverses beside the paper's two did; the unicycle's undefined map:
:func:`jik.engine.reproductions.unicycle.undefined_why`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ...engine.findings import (
    damped_findings,
    extended_why,
    gamma_note,
    posture_findings,
    pseudoinverse_why,
    run_findings,
    weighted_findings,
)
from ...engine.reproductions.unicycle import undefined_why
from .algorithms import STYLES, rest_words, scalar
from .joint_limits import limits_reports, state_limits
from .plotting import norm_unit, units
from .robots import state_inverse, state_kinematics, state_spec
from .runs import AlgorithmRun, DashboardResult
from .singular import singular_sentence

#: The algorithms' names in the verdict's sentences.
NAMES = {a: s.named for a, s in STYLES.items()}


@dataclass(frozen=True)
class Sentence:
    """One sentence: its ``text``, the algorithm it is about (None: both or neither) and its
    ``role``: "finding" (what the run did), "why", "note" or "failure"."""

    text: str
    algorithm: str | None = None
    role: str = "finding"


def _undefined_why(result: DashboardResult, run: AlgorithmRun) -> list[Sentence]:
    """Why the unicycle's map of characteristics (29) became undefined along the extended run
    (:func:`jik.engine.reproductions.unicycle.undefined_why`)."""
    state = result.state
    if (
        state.robot != "unicycle"
        or state.augmentation != "characteristics"
        or run.status != "undefined"
        or len(run.x) < 2
    ):
        return []
    a = float(state.augmentation_parameters.get("a", 1.0))
    discrete = state.mode == "discrete"
    step = f"iteration {len(run.x) - 1}" if discrete else "the run's last step"
    q0 = state.robot_parameters.get("q0", ())
    lam10 = (float(run.x[-2][0]), float(run.x[-1][0]))
    texts = undefined_why(q0, a, lam10, step, discrete)
    return [Sentence(t, "extended", r) for t, r in zip(texts, ("why", "note"), strict=False)]


def _posture(result: DashboardResult, unit: str) -> list[tuple[str, str]]:
    runs, state = result.runs, result.state
    if state.task != "path":
        return []
    rest = rest_words(state, state_spec(state), state_kinematics(state))
    p, e = runs.get("pseudoinverse"), runs.get("extended")
    return posture_findings(
        NAMES["posture"],
        scalar(state, "gain"),
        rest,
        runs["posture"].drift,
        unit,
        None if p is None else p.drift,
        None if e is None else e.drift,
    )


def _damped(result: DashboardResult, unit: str) -> list[tuple[str, str]]:
    state = result.state
    lam, eps = scalar(state, "damping"), scalar(state, "damping_threshold")
    run, p = result.runs["damped"], result.runs.get("pseudoinverse")
    return damped_findings(NAMES["damped"], lam, eps, state.tolerance, run, p)


def _weighted(result: DashboardResult, unit: str) -> list[tuple[str, str]]:
    """Within the box the weighted inverse took for limits (a robot that declares joint
    limits has its sentence from :func:`jik.app.dashboard.joint_limits.limits_reports`)."""
    if state_limits(result.state) is not None:
        return []
    run = result.runs["weighted"]
    inverse = state_inverse(result.state, "weighted")
    limits = np.asarray(getattr(inverse, "limits", ()), dtype=float)
    if limits.shape != (run.x.shape[1], 2):
        return []
    return weighted_findings(NAMES["weighted"], run.x, limits, result.variable_names)


def verdict(result: DashboardResult) -> list[dict]:
    """The sentences the page shows above the plots for ``result`` (:class:`Sentence` dicts):
    each chosen algorithm's finding, then why; failures with the engine's message."""
    runs = result.runs
    out: list[Sentence] = []
    path = result.state.task == "path"
    unit = norm_unit(units(result)[0])
    for algorithm, run in runs.items():
        found = run_findings(NAMES[algorithm], run.drift, run.success, run.message, path, unit)
        out += [Sentence(text, algorithm, role) for text, role in found]
    if path and "pseudoinverse" in runs and (why := pseudoinverse_why(runs["pseudoinverse"].drift)):
        out.append(Sentence(why, "pseudoinverse", "why"))
    if "extended" in runs:
        e, state = runs["extended"], result.state
        undefined = _undefined_why(result, e)
        found = extended_why(e.h, e.drift, e.success, path, state.mode, state.gamma)
        out += undefined or [Sentence(text, "extended", role) for text, role in found]
        if not undefined and found and (note := gamma_note(state.mode, state.gamma)):
            out.append(Sentence(note, None, "note"))
    practical = {"posture": _posture, "damped": _damped, "weighted": _weighted}
    for a in (a for a in runs if a in practical):
        out += [Sentence(text, a, role) for text, role in practical[a](result, unit)]
    robot = state_spec(result.state).title
    for a, report in limits_reports(result).items():
        role = "note" if report.within else "warning"
        out.append(Sentence(report.sentence(NAMES[a], robot), a, role))
    if "extended" in runs and (warning := singular_sentence(result.state)):
        out.append(Sentence(warning, "extended", "warning"))
    return [asdict(s) for s in out]
