"""What the practical inverses beside the paper's two did, in sentences (the dashboard's
verdict, a notebook's summary; :mod:`jik.engine.findings` has the paper's).

How far the posture inverse's null-space pull (Liegeois 1977) toward its rest x_rest (named with
its numbers) brings the drift of the pseudoinverse (8) down, and that it does not reach the
extended Jacobian's repeatability (11); the task error damped least squares is left with where
it damps (it is not a right inverse, J J# != I); whether the weighted least-norm inverse (Chan
and Dubey 1995) kept every joint within its limits. Each function returns ``(text, role)``
pairs, as :mod:`jik.engine.findings`'s do.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .exports import plural
from .findings import NAMES, amount, g
from .limits import limit_names
from .repeatability import REPEATABLE_DRIFT


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
        return [(f"{head} it is the pseudoinverse (k = 0), drift {amount(d, unit)}.", "why")]
    parts, slower = [], True
    if pinv_drift is not None and len(pinv_drift) >= n:
        dp = float(pinv_drift[n - 1])
        slower = d < dp
        than = "less than" if slower else "not less than"
        parts.append(f"it drifts {amount(d, unit)}, {than} the pseudoinverse's {g(dp)}")
    else:
        parts.append(f"it drifts {amount(d, unit)}")
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
    legs: int = 0,
) -> list[tuple[str, str]]:
    """What a practical inverse beside the paper's two did on ``run``, from its parameters:
    :func:`posture_findings` (its rest in ``rest``, else :func:`rest_words` of the run's
    start), :func:`damped_findings`, :func:`weighted_findings` (against the limits it was
    given, said to be the configuration box of a robot without limits where they are,
    :attr:`~jik.engine.practical_inverses.WeightedInverse.box`); none for the paper's
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
        return weighted_findings(name, run.x, inverse.limits, names, inverse.box)
    return []
