"""What a run of the repeatability test found, and why, in sentences a reader can take as they
are (the dashboard's verdict, a notebook's summary).

Repeatability (section 2 of the paper): a closed task path driven from x0 gives a closed joint
path, ``x`` back at ``x0`` after each cycle. The extended Jacobian inverse (11) is repeatable
because its runs stay on the level set h(x) = h(x0) (eq. (12)); the continuous algorithm (7)
keeps h exactly, the discrete iteration ``x <- x - gamma J# e`` only to first order per step
(each step moves along the level set's tangent), and for gamma near 2 the iteration is at the
edge of convergence (the task error is multiplied by about ``1 - gamma`` per step).

Beside the paper's two inverses: how far the posture inverse's null-space pull (Liegeois 1977)
toward its rest x_rest (named with its numbers) brings the drift of the pseudoinverse (8) down,
and that it does not reach the extended Jacobian's repeatability (11); the task error damped
least squares is left with where it damps (it is not a right inverse, J J# != I); whether the
weighted least-norm inverse (Chan and Dubey 1995) kept every joint within its limits.

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
from .limits import limit_names
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


def _amount(v: float, unit: str) -> str:
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
            f"to x0 within {_amount(float(d.max()), unit)} (‖x − x0‖ below {g(REPEATABLE_DRIFT)})."
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
        f"‖x − x0‖ = {_amount(float(d[-1]), unit)} away from x0{trend}."
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
    h, drift, success: bool, closed: bool, mode: str, gamma: float
) -> list[tuple[str, str]]:
    """Why the extended Jacobian inverse (11) was repeatable or not, from h along its run
    (:func:`~jik.engine.augmentations.h_change` against
    :data:`~jik.engine.augmentations.H_CONSERVED`, eq. (12)) and its ``drift`` on a ``closed``
    path; in discrete ``mode`` that the iteration keeps h only approximately. None for a run
    without h, or stopped before it moved."""
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
            f"Why: J^E# adds the equation h(x) = h(x0) (eq. (12)); h changed by only {g(dh)} "
            f"along its run{tail}"
        )
    else:
        lost = (
            " A closed task path gives a closed joint path only while h stays at h(x0): "
            "here it did not, so the joints did not come back."
            if closed and not repeatable(drift)
            else ""
        )
        text = f"h was not conserved: it changed by {g(dh)} along the extended Jacobian's run."
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


def leg_end_errors(error, leg) -> np.ndarray:
    """The task error at the last point of each leg of a run: ``error`` (m,) and ``leg`` (m,)
    the leg of every point."""
    leg = np.asarray(leg)
    if not len(leg):
        return np.zeros(0)
    last = np.r_[np.flatnonzero(np.diff(leg)), len(leg) - 1]
    return np.asarray(error, dtype=float)[last]


def posture_findings(
    name: str, gain: float, rest: str, drift, unit: str, pinv_drift=None, ext_drift=None
) -> list[tuple[str, str]]:
    """How far the posture inverse's null-space pull (Liegeois 1977) toward its rest (``rest``:
    x_rest in words) at gain ``gain`` brought its ``drift`` after each cycle down against the
    pseudoinverse's (8) ``pinv_drift``, and that it does not reach the extended Jacobian's
    (11) repeatability (``ext_drift``); none without a completed cycle. The pull is said to
    slow the drift only where the drift is below the pseudoinverse's (a high gain can make it
    larger)."""
    n = len(drift)
    if not n:
        return []
    d = float(drift[-1])
    head = f"{name}, gain k = {g(gain)}, {rest}: after {plural(n, 'cycle')}"
    if gain == 0:
        return [(f"{head} it is the pseudoinverse (k = 0), drift {_amount(d, unit)}.", "why")]
    parts, slower = [], True
    if pinv_drift is not None and len(pinv_drift) >= n:
        dp = float(pinv_drift[n - 1])
        slower = d < dp
        than = "less than" if slower else "not less than"
        parts.append(f"it drifts {_amount(d, unit)}, {than} the pseudoinverse's {g(dp)}")
    else:
        parts.append(f"it drifts {_amount(d, unit)}")
    if d >= REPEATABLE_DRIFT:
        reach = (
            f"the extended Jacobian's {g(float(ext_drift[n - 1]))}"
            if ext_drift is not None and len(ext_drift) >= n
            else "repeatability"
        )
        pull = (
            "the pull toward x_rest moves the joints inside the self-motion and slows the drift"
            if slower
            else "on this path the pull toward x_rest does not slow the drift"
        )
        parts.append(
            f"but does not reach {reach}: {pull}, yet the end of a cycle does not come back to x0"
        )
    else:
        parts.append("and came back to x0 within round-off on this path")
    return [(f"{head} " + ", ".join(parts) + ".", "why")]


def damped_findings(
    name: str, damping: float, threshold: float, tol: float, run, pinv=None, legs: int = 0
) -> list[tuple[str, str]]:
    """The task error damped least squares (damping ``damping``, adaptive where sigma_min(J)
    < ``threshold`` if positive) is left with at the end of its legs, since it is not a right
    inverse (J J# != I), and how it fared where the pseudoinverse (8) stopped. ``run`` and
    ``pinv`` carry ``error``, ``leg`` and ``success`` (a run point by point; ``leg`` counts
    the legs of the whole run from 0). With ``legs`` (legs per cycle) the worst leg is named
    as the failures and the limits name one, "cycle 2, leg 1"; else by its place in the run; a
    run of one leg (a single target) names none."""
    ends = leg_end_errors(run.error, run.leg)
    if not len(ends):
        return []
    worst = int(np.argmax(ends))
    at = f"leg {worst + 1}; "
    if legs > 0:
        cycle, leg = divmod(worst, legs)
        at = f"cycle {cycle + 1}, leg {leg + 1}; "
    ended = "at the end of its legs up to"
    if len(ends) == 1:  # (one leg: a single target's run)
        at, ended = "", "at its end"
    where = "adaptive, where σ_min(J) < " + g(threshold) if threshold > 0 else "constant"
    text = (
        f"{name} (λ = {g(damping)}, {where}): task error {ended} "
        f"{g(float(ends[worst]))} ({at}tolerance {g(tol)}). Damping "
        "bounds the joint speed near singularities at the price of tracking (J J# ≠ I)"
    )
    if pinv is not None and not pinv.success and run.success:
        text += "; it went through where the pseudoinverse stopped"
    elif pinv is not None and not pinv.success and run.error[-1] < pinv.error[-1]:
        text += (
            f"; where the pseudoinverse stalled at task error {g(float(pinv.error[-1]))}, "
            f"it got to {g(float(run.error[-1]))}"
        )
    elif not run.success:
        text += f"; it stopped with task error {g(float(run.error[-1]))}"
    return [(text + ".", "why")]


def weighted_findings(name: str, x, limits, names, box: bool = True) -> list[tuple[str, str]]:
    """Whether the weighted least-norm inverse (Chan and Dubey 1995) kept every joint of its
    run ``x`` (m, p) within the ``limits`` (p, 2) it took (``box``: said to be the
    configuration box x_range of a robot without joint limits), and its closest approach, or
    which left."""
    lo, hi = limits[:, 0], limits[:, 1]
    below, above = x < lo, x > hi
    bounds = "; ".join(f"{names[k]} in [{g(lo[k])}, {g(hi[k])}]" for k in range(len(lo)))
    if box:
        bounds += "; the robot has no joint limits: its configuration box x_range"
    if not (below.any() or above.any()):
        margin = np.minimum(x - lo, hi - x).min(axis=0)
        k = int(np.argmin(margin))
        return [
            (
                f"{name}: every joint stayed within its limits ({bounds}); "
                f"closest: {names[k]}, {g(float(margin[k]))} from a limit.",
                "why",
            )
        ]
    out = sorted({names[k] for k in np.flatnonzero((below | above).any(axis=0))})
    return [(f"{name}: left its limits ({bounds}): {', '.join(out)}.", "failure")]


#: The posture inverse's default rest when the robot has a home configuration, in words.
HOME = "the robot's home"


def rest_words(inverse, x0) -> str:
    """The posture inverse's rest in words, for :func:`posture_findings`: ``x_rest = the
    robot's home (...)`` or ``x_rest = x0 (...)`` for the default
    (:func:`~jik.engine.algorithm_registry.default_rest`), else ``x_rest = x0 (...)`` when the
    rest given is the start ``x0``, or the numbers given, ``x_rest = (...) (set)``."""
    rest = [float(v) for v in inverse.rest]
    shown = "(" + ", ".join(f"{v:.4g}" for v in rest) + ")"
    if not inverse.rest_given:
        home = getattr(inverse.kinematics, "home", None) is not None
        return f"x_rest = {HOME if home else 'x0'} {shown}"
    return f"x_rest = x0 {shown}" if rest == [float(v) for v in x0] else f"x_rest = {shown} (set)"


#: The practical inverses beside the paper's two, which :func:`practical_findings` speaks of.
PRACTICAL = ("damped", "weighted", "posture")


def practical_findings(
    inverse,
    run,
    unit: str,
    tol: float,
    runs: Mapping[str, Any] | None = None,
    rest=None,
    box: bool = False,
    legs: int = 0,
) -> list[tuple[str, str]]:
    """What a practical inverse beside the paper's two did on ``run``, from its parameters:
    :func:`posture_findings` (its rest in ``rest``, else :func:`rest_words` of the run's
    start), :func:`damped_findings`, :func:`weighted_findings` (against the limits it was
    given; ``box``: the configuration box of a robot without limits); none for the paper's
    inverses. ``legs``: the legs of a cycle, by which damped least squares names its worst leg
    (cycle and leg).

    ``run`` carries ``drift`` (cycles,), ``success``, ``x`` (m, p) the configurations it went
    through, ``error`` and ``leg`` (m',) the task error and leg of points of it, at least of
    each leg's end; ``runs`` the other inverses' runs by algorithm, which the posture and
    damped sentences compare with (the pseudoinverse's, the extended Jacobian's).
    """
    name, runs = NAMES.get(inverse.name, inverse.name), runs or {}
    if inverse.name == "posture":
        p, e = runs.get("pseudoinverse"), runs.get("extended")
        words = rest or rest_words(inverse, run.x[0])
        drifts = [None if other is None else other.drift for other in (p, e)]
        return posture_findings(name, inverse.gain, words, run.drift, unit, *drifts)
    if inverse.name == "damped":
        lam, eps = inverse.damping, inverse.damping_threshold
        return damped_findings(name, lam, eps, tol, run, runs.get("pseudoinverse"), legs)
    if inverse.name == "weighted":
        names = limit_names(inverse.kinematics)
        return weighted_findings(name, run.x, inverse.limits, names, box)
    return []


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
        found = extended_why(e.h, e.drift, e.success, closed, mode, gamma)
        out += undefined or [Finding(text, role, "extended") for text, role in found]
        if not undefined and found and (note := gamma_note(mode, gamma)):
            out.append(Finding(note, "note"))
    return out
