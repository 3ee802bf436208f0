"""What the page writes above the plots, computed from the result: for each algorithm whether it
was repeatable on the closed path and by how much, how much h changed along the extended
Jacobian's run, and why, in sentences the page shows as they are (the engine's
:mod:`jik.engine.findings`, which says what repeatability is and why the extended Jacobian has
it; the unicycle's undefined map: :func:`jik.engine.reproductions.unicycle.undefined_why`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from ...engine.findings import extended_why, gamma_note, pseudoinverse_why, run_findings
from ...engine.reproductions.unicycle import undefined_why
from .joint_limits import limits_texts
from .plotting import norm_unit, units
from .runs import AlgorithmRun, DashboardResult
from .singular import singular_sentence
from .verdict_algorithms import NAMES, practical_sentences


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


def verdict(result: DashboardResult) -> list[dict]:
    """The sentences the page shows above the plots for ``result`` (:class:`Sentence` dicts):
    each chosen algorithm's finding, then why (:mod:`.verdict_algorithms` for the practical
    inverses); failures with the engine's message."""
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
    out += [Sentence(*s) for s in practical_sentences(result, unit)]
    for text, algorithm, within in limits_texts(result, NAMES):
        out.append(Sentence(text, algorithm, "note" if within else "warning"))
    if "extended" in runs and (warning := singular_sentence(result.state)):
        out.append(Sentence(warning, "extended", "warning"))
    return [asdict(s) for s in out]
