"""What a run of the repeatability test found, and why, in sentences a reader can take as they
are (the dashboard's verdict, a notebook's summary).

Repeatability (section 2 of the paper): a closed task path driven from x0 gives a closed joint
path, ``x`` back at ``x0`` after each cycle. The extended Jacobian inverse (11) is repeatable
because its runs stay on the level set h(x) = h(x0) (eq. (12)); the continuous algorithm (7)
keeps h exactly, the discrete iteration ``x <- x - gamma J# e`` only to first order per step
(each step moves along the level set's tangent), and for gamma near 2 the iteration is at the
edge of convergence (the task error is multiplied by about ``1 - gamma`` per step).

The practical inverses beside the paper's two have their sentences in
:mod:`jik.engine.practical_findings`.

Each function returns ``(text, role)`` pairs, ``role`` one of "finding" (what the run did),
"why", "note" or "failure"; :func:`verdict` gathers the paper's part of them for runs of several
inverses as :class:`Finding` s (:meth:`RepeatabilityResult.findings
<jik.engine.repeatability_result.RepeatabilityResult.findings>` for one run).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np

from .augmentations import H_CONSERVED, h_change
from .exports import plural
from .repeatability import REPEATABLE_DRIFT, repeatable
from .validation import as_series, flag, of_type

#: In discrete mode, a gamma at or above this is "near 2" (the iteration's stability limit).
GAMMA_NEAR_TWO = 1.5
#: Each algorithm's name in the sentences.
NAMES = {
    "pseudoinverse": "pseudoinverse J^P#",
    "extended": "extended Jacobian J^E#",
    "damped": "damped least squares J^DLS",
    "weighted": "weighted least-norm J^W#",
    "posture": "posture inverse (J^P# with a null-space pull)",
}


class Finding(NamedTuple):
    """One sentence: its ``text``, its ``role`` ("finding", "why", "note" or "failure"; the
    dashboard adds "warning") and the ``algorithm`` it is about (None: the run's settings, not
    one inverse)."""

    text: str
    role: str = "finding"
    algorithm: str | None = None


def g(v: float) -> str:
    """A number in 3 significant digits."""
    return f"{v:.3g}"


def amount(v: float, unit: str) -> str:
    return f"{g(v)} {unit}" if unit else g(v)


def drift_sentence(name: str, drift, unit: str) -> str:
    """Whether the run named ``name`` was repeatable, from its ``drift`` ||x - x0|| after each
    cycle (cycles,) in ``unit``: the largest drift if so (below
    :data:`~jik.engine.repeatability.REPEATABLE_DRIFT`), else the last and how it grew."""
    d = np.asarray(drift, dtype=float)
    n = len(d)
    if repeatable(d):
        each = "each of " if n > 1 else ""
        return (
            f"{name}: repeatable. After {each}{plural(n, 'cycle')} the joints came back "
            f"to x0 within {amount(float(d.max()), unit)} (‖x − x0‖ below {g(REPEATABLE_DRIFT)})."
        )
    trend = ""
    if n > 1:
        grows = d[-1] > d[0] * 1.05
        trend = (
            f", growing from {g(float(d[0]))} after cycle 1"
            if grows
            else f" (after cycle 1: {g(float(d[0]))})"
        )
    return (
        f"{name}: not repeatable. After {plural(n, 'cycle')} the joints end "
        f"‖x − x0‖ = {amount(float(d[-1]), unit)} away from x0{trend}."
    )


def run_findings(
    name: str, drift, success: bool, message: str, closed: bool, unit: str
) -> list[tuple[str, str]]:
    """What the run named ``name`` did: on a closed path (``closed``) with completed cycles
    (``drift`` (cycles,)) its :func:`drift_sentence`, else the solver's ``message`` when it
    succeeded; and, when it did not, where it stopped ("failure"). ``name``, ``message`` and
    ``unit`` are strings, ``success`` and ``closed`` booleans (InvalidInputError otherwise)."""
    for text, field in ((name, "name"), (message, "message"), (unit, "unit")):
        of_type(text, str, field, "a string")
    drift, success = as_series(drift, "drift"), flag(success, "success")
    closed, n = flag(closed, "closed"), len(drift)
    out = []
    if closed and n:
        out.append((drift_sentence(name, drift, unit), "finding"))
    elif success:
        out.append((f"{name}: {message}.", "finding"))
    if not success:
        done = f" (after {n} completed cycle{'s' if n > 1 else ''})" if closed and n else ""
        out.append((f"{name} stopped{done}: {message}", "failure"))
    return out


def pseudoinverse_why(drift) -> str | None:
    """Why the pseudoinverse (8) drifted, or that it happened to come back, from its ``drift``
    after each cycle; None without a completed cycle."""
    if repeatable(drift) is False:
        return (
            "Why: J^P# picks the minimum-norm joint velocity, which has no memory of the start "
            "(it keeps nothing like h constant), so a closed task path need not close in the "
            "joints."
        )
    if repeatable(drift):
        return (
            "The pseudoinverse happens to come back on this path: its joint flow closes here, "
            "which it does not in general."
        )
    return None


def extended_why(
    h, drift, success: bool, closed: bool, mode: str, gamma: float, ends: bool = False
) -> list[tuple[str, str]]:
    """Why the extended Jacobian inverse (11) was repeatable or not, from h along its run
    (:func:`~jik.engine.augmentations.h_change` against
    :data:`~jik.engine.augmentations.H_CONSERVED`, eq. (12)) and its ``drift`` on a ``closed``
    path; in discrete ``mode`` that the iteration keeps h only approximately. None for a run
    without h, or stopped before it moved. ``ends``: ``h`` is h at the start and the legs' ends
    only (a run not recorded), and the sentences say so: h may have moved further between."""
    along = "from its start to its legs' ends" if ends else "along its run"
    dh = h_change(h)
    if dh is None or (not success and dh == 0):
        return []
    closed = closed and len(drift) > 0
    kept = dh < H_CONSERVED
    if kept:
        tail = (
            ", so each task point has one configuration on that level set, and the closed "
            "task path gave a closed joint path."
            if closed and repeatable(drift)
            else "."
        )
        text = (
            "Why: J^E# adds the equation h(x) = h(x0) (eq. (12)); "
            + ("h did not change" if dh == 0 else f"h changed by only {g(dh)}")
            + f" {along}{tail}"
        )
    else:
        lost = (
            " A closed task path gives a closed joint path only while h stays at h(x0): "
            "here it did not, so the joints did not come back."
            if closed and not repeatable(drift)
            else ""
        )
        run = "the extended Jacobian's " + ("start to its legs' ends" if ends else "run")
        text = f"h was not conserved: it changed by {g(dh)} {'from' if ends else 'along'} {run}."
        text += lost
    out = [(text, "why")]
    if mode == "discrete" and not kept:
        out.append(
            (
                "The discrete algorithm x ← x − γ J^E# e keeps h only approximately: each step "
                "moves along the tangent of the level set h = h(x0), not on it, so h changes by "
                "an amount that grows with γ (the continuous algorithm (7) keeps h exactly).",
                "note",
            )
        )
    return out


def gamma_note(mode: str, gamma: float) -> str | None:
    """In discrete mode, that a ``gamma`` of at least :data:`GAMMA_NEAR_TWO` is near the
    iteration's limit 2 (the task error is multiplied by about 1 - gamma per step)."""
    if mode != "discrete" or gamma < GAMMA_NEAR_TWO:
        return None
    return (
        f"γ = {g(gamma)} is near 2, the limit of the discrete iteration: the task "
        f"error is multiplied by about 1 − γ = {g(1 - gamma)} per step, so the "
        "iterates overshoot back and forth and h is far from conserved; at γ ≥ 2 the "
        "iteration diverges."
    )


def verdict(
    runs: Mapping[str, Any],
    closed: bool = True,
    mode: str = "continuous",
    gamma: float = 1.0,
    unit: str = "",
    undefined: Sequence[Finding] = (),
) -> list[Finding]:
    """What runs of the paper's test found and why: each run's :func:`run_findings`, then why
    the pseudoinverse (8) drifted (:func:`pseudoinverse_why`), why the extended Jacobian inverse
    (11) kept or lost h(x0) (:func:`extended_why`, eq. (12)) and :func:`gamma_note`.

    Parameters
    ----------
    runs : mapping of str to run
        By algorithm (a key of :data:`NAMES`), in order: objects with ``drift`` (cycles,),
        ``success``, ``message`` and ``h`` (m,) or (m, p - r), h along the run (None without h).
    closed : bool
        A closed path driven cycle after cycle (False: one solve to a target).
    mode, gamma : str, float
        The algorithm (7), "continuous", or its discrete iteration with step ``gamma``.
    unit : str
        The drift's unit, e.g. "[rad]" (:func:`jik.engine.units.norm_unit`); "" unstated.
    undefined : sequence of Finding
        Why the extended inverse's map became undefined along its run, said instead of its why
        and the gamma note (the unicycle's map (29):
        :func:`jik.engine.reproductions.unicycle.undefined_why`).
    """
    out = [
        Finding(text, role, a)
        for a, run in runs.items()
        for text, role in run_findings(NAMES[a], run.drift, run.success, run.message, closed, unit)
    ]
    if (
        closed
        and "pseudoinverse" in runs
        and (why := pseudoinverse_why(runs["pseudoinverse"].drift))
    ):
        out.append(Finding(why, "why", "pseudoinverse"))
    if "extended" in runs:
        e = runs["extended"]
        ends = bool(getattr(e, "h_at_ends", False))
        found = extended_why(e.h, e.drift, e.success, closed, mode, gamma, ends)
        out += undefined or [Finding(text, role, "extended") for text, role in found]
        if not undefined and found and (note := gamma_note(mode, gamma)):
            out.append(Finding(note, "note"))
    return out
