"""Section 6.2 of the paper: the unicycle driven to y_d from starts A and B with both inverses.

The discrete algorithm (7), lambda <- lambda - gamma J#(lambda) (k(lambda) - y_d), runs with the
pseudoinverse (44) and the extended inverse (47) built from the characteristics map of section
6.1 (:class:`~jik.engine.characteristics.UnicycleCharacteristics`, a = 1). The continuous algorithm
is run as well, to show that h is conserved there (eq. (12)) and not by finite steps.

Stopping: ||k(lambda) - y_d|| < TOL = 1e-10. The kinematics is accurate to ~1e-12 (quadrature vs
an ODE solve), and near the solution the discrete error shrinks by 1 - gamma = 0.9 per
iteration, so 1e-10 costs ~25 iterations more than 1e-9 and is still well above rounding.

A run stops with a message (never NaN silently) where omega is undefined along the
characteristic of h, where [J; dh] is singular, or where lambda diverges (|lambda| >
LAMBDA_BOUND); the message also says when lambda10 crossed 0, the boundary of the foliation's
domain (the leaves E_{a,alpha} need lambda10 != 0).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import numpy as np

from ..characteristics import UnicycleCharacteristics
from ..exceptions import JikError
from ..exports import json_values
from ..inverses import ExtendedInverse, Pseudoinverse
from ..registry import POSE_A, POSE_B
from ..solver import solve
from ..unicycle import Unicycle

STARTS = {"A": POSE_A, "B": POSE_B}
LAMBDA0 = (0.5, -0.25, 0.3, -0.25)
Y_D = (1.0, 0.0, -math.pi / 2)
GAMMA = 0.1
A_PARAMETER = 1.0
T = 2.0 * math.pi
#: Stopping tolerance on the task error ||k(lambda) - y_d||.
TOL = 1e-10
#: Iteration cap of the discrete algorithm (the error needs ~240 iterations at gamma = 0.1).
MAX_ITERATIONS = 2000
#: |lambda| beyond this counts as divergence (|lambda0| = 0.67).
LAMBDA_BOUND = 20.0
#: Points of the platform path q(t), t in [0, T], under the final control.
PATH_POINTS = 101


def _floats(a) -> list:
    """A numpy array as nested lists of floats, None where missing (:func:`json_values`)."""
    return json_values(np.asarray(a, dtype=float))


def _inverses(q0):
    kin = Unicycle(q0=q0, T=T)
    # "nan": the solver stops cleanly where h is undefined (status "undefined"); the precise
    # reason is recovered below with the raising twin.
    masked = UnicycleCharacteristics(kin, a=A_PARAMETER, on_undefined="nan")
    strict = UnicycleCharacteristics(kin, a=A_PARAMETER)
    return (
        kin,
        {"pseudoinverse": Pseudoinverse(kin), "extended": ExtendedInverse(kin, masked)},
        strict,
    )


def _diagnose(lam, h, strict, stopped_singular) -> tuple[int | None, list[str]]:
    """Where to stop (index into the history) and the notes on domain exit and divergence."""
    notes = []
    stop = None
    norms = np.linalg.norm(lam, axis=-1)
    big = np.flatnonzero(~(norms <= LAMBDA_BOUND))
    if h is not None:
        cross = np.flatnonzero(np.sign(lam[:, 0]) != np.sign(A_PARAMETER))
        if cross.size:
            k = int(cross[0])
            jump = (
                ""
                if h is None or k == 0
                else (f"; h jumped from {h[k - 1]:.4g} to {h[k]:.4g}" if np.isfinite(h[k]) else "")
            )
            notes.append(
                f"lambda10 crossed 0 at iteration {k} (lambda10 = {lam[k, 0]:.4g}): outside the "
                f"foliation's domain (leaves E_(a,alpha) need lambda10 != 0), the characteristic "
                f"from the reference leaf lambda10 = a passes lambda10 = 0, near which the "
                f"normalising kernel component of omega can vanish{jump}"
            )
    if big.size:
        stop = int(big[0])
        notes.append(
            f"lambda diverged: |lambda| = {norms[stop]:.4g} > {LAMBDA_BOUND:g} at iteration "
            f"{stop}; stopped there"
        )
    elif stopped_singular and h is not None:
        try:
            strict.value(lam[-1])
        except JikError as exc:
            notes.append(str(exc))
    return stop, notes


def _run_one(kin, inverse, strict, mode) -> dict:
    extended = inverse.name == "extended"
    out: dict = {"algorithm": inverse.name, "mode": mode}
    try:
        # An undefined h reaches the solver as NaN in [J; dh]; the 'invalid value' warning of
        # that determinant is expected and diagnosed below.
        with np.errstate(invalid="ignore"):
            res = solve(
                inverse,
                LAMBDA0,
                Y_D,
                gamma=GAMMA,
                mode=mode,
                tol=TOL,
                max_iterations=MAX_ITERATIONS if mode == "discrete" else None,
                record=True,
            )
    except JikError as exc:
        out.update(success=False, message=f"could not start: {exc}", lambda_=list(LAMBDA0))
        out["lambda"] = out.pop("lambda_")
        return out
    tr = res.trajectory
    assert tr is not None  # record=True
    lam, err = tr.x, tr.error
    h = None if tr.h is None else np.asarray(tr.h, dtype=float)
    stop, notes = _diagnose(lam, h, strict, res.status in ("singular", "undefined"))
    n = len(lam) if stop is None else stop + 1
    success = bool(res.success) and stop is None
    message = res.message if stop is None else "stopped: " + " | ".join(notes)
    if notes and stop is None:
        message = message + " | " + " | ".join(notes)
    out.update(
        success=success,
        message=message,
        solver_message=res.message,
        notes=notes,
        iterations=int(n - 1) if mode == "discrete" else int(res.nit),
        error=float(err[n - 1]),
        **{"lambda": _floats(lam[n - 1])},
        lambda_history=_floats(lam[:n]),
        error_history=_floats(err[:n]),
    )
    if mode == "continuous":
        out["theta_history"] = _floats(tr.theta[:n])
    if extended:
        assert h is not None  # the extended inverse records h along the path
        hs = h[:n]
        drift = np.abs(hs - hs[0])
        out.update(
            h_start=float(hs[0]),
            h_final=None if not np.isfinite(hs[-1]) else float(hs[-1]),
            h_drift=None if not np.all(np.isfinite(drift)) else float(np.max(drift)),
            h_history=_floats(hs),
        )
    t = np.linspace(0.0, kin.T, PATH_POINTS)
    out["platform_path"] = (
        _floats(kin.path(lam[n - 1], t)) if np.all(np.isfinite(lam[n - 1])) else []
    )
    return out


def _compare(runs: dict) -> dict:
    """How similar the pseudoinverse and extended results are (the paper's remark, sec. 6.2):
    None where either run did not converge (a stopped run's controls are no result)."""
    p, e = runs["pseudoinverse"], runs["extended"]
    if not (p["success"] and e["success"] and p.get("platform_path") and e.get("platform_path")):
        return {"platform_path_max_distance": None, "final_lambda_distance": None}
    qp, qe = np.array(p["platform_path"]), np.array(e["platform_path"])
    return {
        "platform_path_max_distance": float(np.max(np.linalg.norm(qp[:, :2] - qe[:, :2], axis=-1))),
        "final_lambda_distance": float(np.linalg.norm(np.subtract(p["lambda"], e["lambda"]))),
    }


def run(progress: Callable[[float], None] | None = None) -> dict:
    """Section 6.2 recomputed; JSON-serialisable (plain lists, floats, None for undefined).

    Returns
    -------
    dict
        ``result[start][algorithm]`` for start in "A", "B" and algorithm in "pseudoinverse",
        "extended" (discrete algorithm): ``lambda``, ``iterations``, ``error``, ``success``,
        ``message``, ``lambda_history``, ``error_history``, ``platform_path`` (q(t) under the
        final lambda) and, for "extended", ``h_start``, ``h_final``, ``h_drift``, ``h_history``.
        ``result["continuous"][start][algorithm]`` the same for the continuous algorithm;
        ``result["comparison"]`` the distance between the two inverses' results;
        ``result["parameters"]`` the setting.
    """
    result: dict = {
        "parameters": {
            "q0": {k: list(v) for k, v in STARTS.items()},
            "lambda0": list(LAMBDA0),
            "y_d": list(Y_D),
            "gamma": GAMMA,
            "a": A_PARAMETER,
            "T": T,
            "tol": TOL,
            "max_iterations": MAX_ITERATIONS,
            "lambda_bound": LAMBDA_BOUND,
        },
        "continuous": {},
        "comparison": {},
    }
    total, done = 2 * 2 * 2, 0
    for start, q0 in STARTS.items():
        kin, inverses, strict = _inverses(q0)
        result[start] = {}
        result["continuous"][start] = {}
        for mode in ("discrete", "continuous"):
            target = result[start] if mode == "discrete" else result["continuous"][start]
            for name, inverse in inverses.items():
                target[name] = _run_one(kin, inverse, strict, mode)
                done += 1
                if progress is not None:
                    progress(done / total)
        result["comparison"][start] = {
            "discrete": _compare(result[start]),
            "continuous": _compare(result["continuous"][start]),
        }
    return result


def _fmt(v) -> str:
    return "   undefined" if v is None else f"{v:12.4e}"


def format_text(result: dict) -> str:
    """A readable summary: per start and algorithm, iterations, final lambda, error and h."""
    par = result["parameters"]
    out = [
        "Unicycle, section 6.2: lambda0 = (0.5, -0.25, 0.3, -0.25), y_d = (1, 0, -pi/2), "
        f"gamma = {par['gamma']}, a = {par['a']}, T = 2 pi, tol = {par['tol']:g}",
        "",
    ]
    for label, block in (("discrete (7)", None), ("continuous (7)", "continuous")):
        out.append(f"Algorithm {label}")
        out.append(
            f"{'start':6}{'inverse':15}{'ok':>4}{'steps':>7}{'error':>12}   "
            f"{'final lambda':44}{'h start':>12}{'h final':>12}{'h drift':>12}"
        )
        for start in ("A", "B"):
            runs = result[start] if block is None else result[block][start]
            for name in ("pseudoinverse", "extended"):
                r = runs[name]
                lam = (
                    "("
                    + ", ".join(f"{v:9.4f}" if v is not None else "nan" for v in r["lambda"])
                    + ")"
                )
                hs = (
                    (_fmt(r.get("h_start")) + _fmt(r.get("h_final")) + _fmt(r.get("h_drift")))
                    if (name == "extended")
                    else ""
                )
                ok = "yes" if r["success"] else "no"
                out.append(
                    f"{start:6}{name:15}{ok:>4}{r.get('iterations', 0):7d}"
                    f"{r.get('error', float('nan')):12.3e}   {lam:44}{hs}"
                )
                if not r["success"]:
                    out.append(f"{'':10}-> {r['message']}")
            cmp_ = result["comparison"][start]["discrete" if block is None else "continuous"]
            d = cmp_["platform_path_max_distance"]
            paths = f"{'':10}platform paths q(t) of the two inverses"
            out.append(
                f"{paths}: not compared, a run did not converge"
                if d is None
                else f"{paths} differ by at most {d:.3f} m"
            )
        out.append("")
    return "\n".join(out)


#: The figures of the paper's pseudoinverse and extended runs from each start of sec. 6.2.
FIGURES = {"A": "Figs. 11 (J^P#) and 12 (J^E#)", "B": "Figs. 13 (J^P#) and 14 (J^E#)"}


def paper_start(q0) -> str | None:
    """The start of sec. 6.2 ("A", "B") whose pose is ``q0`` (3,), None if none."""
    q0 = np.asarray(q0, dtype=float)
    for name, pose in STARTS.items():
        if q0.shape == (3,) and np.allclose(q0, pose, atol=1e-9):
            return name
    return None


def figs_11_14(q0, period: float, a, x0, target, gamma: float, mode: str) -> bool:
    """Whether a unicycle run is one that sec. 6.2 draws in Figs. 11-14: from pose A or B
    (:func:`paper_start`) with the horizon T = 2 pi and lambda0 = (0.5, -0.25, 0.3, -0.25) to
    y_d = (1, 0, -pi/2), by the discrete algorithm (7) with gamma = 0.1, the map (29) of a = 1."""
    close = functools.partial(np.allclose, rtol=0, atol=1e-9)
    return (
        paper_start(q0) is not None
        and (mode, gamma, a) == ("discrete", GAMMA, A_PARAMETER)
        and close(period, T)
        and close(x0, LAMBDA0)
        and close(target, Y_D)
    )


def undefined_why(q0, a: float, lam10: tuple[float, float], step: str, discrete: bool) -> list[str]:
    """Why the characteristics map (29) became undefined along an extended run: the ``step``
    ("iteration 3") took lambda10 from ``lam10[0]`` to ``lam10[1]``, out of the foliation's
    domain when across 0 (lambda10 of the sign of the reference leaf's ``a``, omega being
    undefined on lambda10 = 0), and the characteristic (28) from there runs into a zero of the
    kernel component that normalises omega; for a start ``q0`` of the paper's (sec. 6.2), that
    this is its Figs. 11-14's run and docs/paper-errata.md's finding (``discrete``: that the
    continuous run from there converges)."""
    before, after = lam10
    moved = f"{step} took lambda10 from {before:.3g} to {after:.3g}"
    if after * a <= 0:
        moved += (
            f", across lambda10 = 0 and out of the domain of the map's foliation "
            f"(lambda10 of the sign of a = {a:.3g}: ω is undefined on lambda10 = 0)"
        )
    out = [
        f"Why: h is defined by the characteristic (28) from x to the reference leaf "
        f"lambda10 = a (eq. (29)); {moved}. From there the characteristic runs into a zero of the "
        "kernel component that normalises ω (J11 J24 − J14 J21 = 0), where ω and dz/ds "
        "blow up, so h, and with it the extended Jacobian inverse (47), is undefined."
    ]
    paper = paper_start(q0)
    if paper is not None:
        note = (
            f"This is the paper's run from q0 = {paper} (sec. 6.2, {FIGURES[paper]}). Where the "
            "paper plots the extended run to its end, jik finds that it leaves the domain "
            'of h: docs/paper-errata.md (Unicycle, "Section 6.2, what jik finds") '
            "explains it, with a command that shows it."
        )
        if discrete:
            note += (
                " In mode continuous h is conserved exactly and the extended run from "
                f"q0 = {paper} converges."
            )
        out.append(note)
    return out
