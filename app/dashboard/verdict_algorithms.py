"""The verdict's sentences about the practical inverses beside the paper's two: how far the
posture inverse's null-space pull (Liegeois 1977) toward its rest x_rest (named with its
numbers) brings the drift of the pseudoinverse (8) down,
and that it does not reach the extended Jacobian's repeatability (11); the task error damped
least squares is left with where it damps (it is not a right inverse, J J# != I); whether the
weighted least-norm inverse (Chan and Dubey 1995) kept every joint within its limits.
"""

from __future__ import annotations

import numpy as np

from ...engine.findings import g
from ...engine.repeatability import REPEATABLE_DRIFT
from .algorithms import STYLES, rest_words, scalar
from .joint_limits import state_limits
from .robots import state_inverse, state_kinematics, state_spec
from .runs import AlgorithmRun, DashboardResult

#: The algorithms' names in the verdict's sentences.
NAMES = {a: s.named for a, s in STYLES.items()}


def leg_end_errors(run: AlgorithmRun) -> np.ndarray:
    """The task error at the last point of each leg of a run."""
    if not len(run.leg):
        return np.zeros(0)
    last = np.r_[np.flatnonzero(np.diff(run.leg)), len(run.leg) - 1]
    return np.asarray(run.error, dtype=float)[last]


def _posture(result: DashboardResult, unit: str) -> list[tuple[str, str]]:
    runs, state = result.runs, result.state
    run = runs["posture"]
    gain = scalar(state, "gain")
    if state.task != "path" or not len(run.drift):
        return []
    n, d = len(run.drift), float(run.drift[-1])
    rest = rest_words(state, state_spec(state), state_kinematics(state))
    head = f"{NAMES['posture']}, gain k = {g(gain)}, {rest}: after {n} cycle{'s' if n > 1 else ''}"
    if gain == 0:
        return [(f"{head} it is the pseudoinverse (k = 0), drift {g(d)} {unit}.", "why")]
    parts = []
    p = runs.get("pseudoinverse")
    if p is not None and len(p.drift) >= n:
        dp = float(p.drift[n - 1])
        than = "less than" if d < dp else "not less than"
        parts.append(f"it drifts {g(d)} {unit}, {than} the pseudoinverse's {g(dp)}")
    else:
        parts.append(f"it drifts {g(d)} {unit}")
    e = runs.get("extended")
    if d >= REPEATABLE_DRIFT:
        reach = (
            f"the extended Jacobian's {g(float(e.drift[n - 1]))}"
            if e is not None and len(e.drift) >= n
            else "repeatability"
        )
        parts.append(
            f"but does not reach {reach}: the pull toward x_rest moves the joints inside the "
            "self-motion and slows the drift, yet the end of a cycle does not come back to x0"
        )
    else:
        parts.append("and came back to x0 within round-off on this path")
    return [(f"{head} " + ", ".join(parts) + ".", "why")]


def _damped(result: DashboardResult, unit: str) -> list[tuple[str, str]]:
    runs, state = result.runs, result.state
    run = runs["damped"]
    lam = scalar(state, "damping")
    eps = scalar(state, "damping_threshold")
    ends = leg_end_errors(run)
    if not len(ends):
        return []
    worst = int(np.argmax(ends))
    where = "adaptive, where σ_min(J) < " + g(eps) if eps > 0 else "constant"
    text = (
        f"{NAMES['damped']} (λ = {g(lam)}, {where}): task error at the end of its legs up to "
        f"{g(float(ends[worst]))} (leg {worst + 1}; tolerance {g(state.tolerance)}). Damping "
        "bounds the joint speed near singularities at the price of tracking (J J# ≠ I)"
    )
    p = runs.get("pseudoinverse")
    if p is not None and not p.success and run.success:
        text += "; it went through where the pseudoinverse stopped"
    elif p is not None and not p.success and run.error[-1] < p.error[-1]:
        text += (
            f"; where the pseudoinverse stalled at task error {g(float(p.error[-1]))}, "
            f"it got to {g(float(run.error[-1]))}"
        )
    elif not run.success:
        text += f"; it stopped with task error {g(float(run.error[-1]))}"
    return [(text + ".", "why")]


def _weighted(result: DashboardResult, unit: str) -> list[tuple[str, str]]:
    """Within the box the weighted inverse took for limits (a robot that declares joint
    limits has its sentence from :func:`jik.app.dashboard.joint_limits.limits_texts`)."""
    if state_limits(result.state) is not None:
        return []
    run = result.runs["weighted"]
    inverse = state_inverse(result.state, "weighted")
    limits = np.asarray(getattr(inverse, "limits", ()), dtype=float)
    if limits.shape != (run.x.shape[1], 2):
        return []
    lo, hi = limits[:, 0], limits[:, 1]
    below, above = run.x < lo, run.x > hi
    names = result.variable_names
    bounds = "; ".join(f"{names[k]} in [{g(lo[k])}, {g(hi[k])}]" for k in range(len(lo)))
    bounds += "; the robot has no joint limits: its configuration box x_range"
    if not (below.any() or above.any()):
        margin = np.minimum(run.x - lo, hi - run.x).min(axis=0)
        k = int(np.argmin(margin))
        return [
            (
                f"{NAMES['weighted']}: every joint stayed within its limits ({bounds}); "
                f"closest: {names[k]}, {g(float(margin[k]))} from a limit.",
                "why",
            )
        ]
    out = sorted({names[k] for k in np.flatnonzero((below | above).any(axis=0))})
    return [(f"{NAMES['weighted']}: left its limits ({bounds}): {', '.join(out)}.", "failure")]


SENTENCES = {"posture": _posture, "damped": _damped, "weighted": _weighted}


def practical_sentences(result: DashboardResult, unit: str) -> list[tuple[str, str, str]]:
    """(text, algorithm, role) of the chosen practical inverses' sentences."""
    return [
        (text, a, role)
        for a in result.runs
        if a in SENTENCES
        for text, role in SENTENCES[a](result, unit)
    ]
