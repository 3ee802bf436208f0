"""The options of ``jik solve``, ``jik repeatability`` and ``jik atlas`` that choose an inverse
J# and its parameters (the engine's catalogue :data:`jik.engine.registry.ALGORITHMS`), and how
each leg runs: eq. (7)'s mode and gamma, the tolerance and the cap on steps."""

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
        help="posture: rest posture 'x1, x2, ...', within the robot's joint limits if it has "
        "some (default: the robot's home, else the run's x0; for an atlas each run's own start)",
    )
    p.add_argument(
        "--limits",
        help="weighted: joint limits 'lo,hi; lo,hi; ...' (default: the "
        "robot's limits, else its configuration box)",
    )


def add_run_options(p: argparse.ArgumentParser) -> None:
    """--mode, --gamma, --tol, --max-iterations: how each solve (each leg of a path) runs."""
    p.add_argument(
        "--mode",
        choices=("continuous", "discrete"),
        default=None,
        help="algorithm (7) continuous (ODE) or discrete (default: the robot's)",
    )
    p.add_argument("--gamma", type=float, default=None, help="decay rate (discrete: step)")
    p.add_argument(
        "--tol", type=float, default=None, help="task error at which a solve stops (default 1e-10)"
    )
    p.add_argument(
        "--max-iterations",
        type=int,
        default=None,
        help="most steps (continuous) or iterations (discrete) per solve (default: the engine's)",
    )


def run_settings(args: argparse.Namespace, spec) -> dict:
    """The engine's keywords of :func:`add_run_options` (``spec``: the robot's defaults of mode
    and gamma)."""
    return {
        "mode": args.mode or spec.default_mode,
        "gamma": args.gamma if args.gamma is not None else spec.default_gamma,
        "max_iterations": args.max_iterations,
        **({} if args.tol is None else {"tol": args.tol}),
    }


def refuse_unused_options(args: argparse.Namespace, algorithms: list[str]) -> None:
    """Refuse an algorithm option given that none of the chosen ``algorithms`` takes (as the
    REST API refuses an unknown parameter): ``--damping`` with the pseudoinverse alone, an
    ``--augmentation`` without the extended inverse."""
    from ..engine.exceptions import InvalidInputError
    from ..engine.registry import ALGORITHMS

    # option (its dest) -> the algorithms that take it
    takers: dict[str, list[str]] = {"augmentation": ["extended"]}
    for name, spec in ALGORITHMS.items():
        for option in (*(p.name for p in spec.parameters), *spec.vectors):
            takers.setdefault(option, []).append(name)
    for option, names in takers.items():
        if getattr(args, option, None) is not None and not set(names) & set(algorithms):
            raise InvalidInputError(
                f"--{option.replace('_', '-')} is a parameter of {' and '.join(names)}, not of "
                f"{', '.join(algorithms)}: choose it with --algorithm {names[0]}",
                option,
            )


def algorithm_parameters(args: argparse.Namespace, algorithm: str) -> dict:
    """The options given that belong to ``algorithm`` (the others are another chosen
    algorithm's: :func:`refuse_unused_options` refuses those no chosen one takes); without
    ``--rest``, the posture inverse's rest is the engine's default (``Robot.inverse``'s
    ``x0``)."""
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
    if "limits" in spec.vectors and args.limits:
        out["limits"] = parse_path(args.limits, "--limits")
    return out
