"""The options of ``jik solve``, ``jik repeatability`` and ``jik atlas`` that choose an inverse
J# and its parameters (the engine's catalogue :data:`jik.engine.registry.ALGORITHMS`)."""

from __future__ import annotations

import argparse

#: The algorithms' names (as the engine's catalogue; a test checks they agree).
ALGORITHM_NAMES = ("pseudoinverse", "extended", "damped", "weighted", "posture")


def add_algorithm_parameter_options(p: argparse.ArgumentParser) -> None:
    """--damping, --damping-threshold, --gain, --rest, --limits."""
    p.add_argument("--damping", type=float, help="damped: damping lambda >= 0 (default 0.1)")
    p.add_argument(
        "--damping-threshold",
        type=float,
        help="damped: damp only where the smallest singular value of J is below "
        "this (default 0: constant damping)",
    )
    p.add_argument("--gain", type=float, help="posture: null-space gain k >= 0 (default 1)")
    p.add_argument(
        "--rest",
        help="posture: rest posture 'x1, x2, ...' (default: the run's "
        "x0; for an atlas each run's own start)",
    )
    p.add_argument(
        "--limits",
        help="weighted: joint limits 'lo,hi; lo,hi; ...' (default: the "
        "robot's limits, else its configuration box)",
    )


def algorithm_parameters(args: argparse.Namespace, algorithm: str, x0=None) -> dict:
    """The options given that belong to ``algorithm`` (the others are ignored for it); the
    posture inverse's rest defaults to ``x0`` when given (a run's start)."""
    from ..engine.registry import ALGORITHMS
    from .robot_commands import parse_path, parse_vector

    spec = ALGORITHMS[algorithm]
    out: dict = {}
    for p in spec.parameters:
        value = getattr(args, p.name, None)
        if value is not None:
            out[p.name] = value
    if "rest" in spec.vectors and args.rest:
        out["rest"] = parse_vector(args.rest, "--rest")
    elif "rest" in spec.vectors and x0 is not None:
        out["rest"] = list(x0)
    if "limits" in spec.vectors and args.limits:
        out["limits"] = parse_path(args.limits, "--limits")
    return out
