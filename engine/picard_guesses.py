"""Picard guesses for the continuous solves of eq. (7): from earlier trajectories, chained
over a closed path's legs (:mod:`jik.engine.picard`), and a repeatability run's guesses for one
cycle (:func:`cycle_guesses`); :func:`solve` is :func:`jik.engine.solver.solve`."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .exceptions import InvalidInputError
from .inverses import Inverse
from .picard import CHAIN_SWEEPS, Guess, picard_chain
from .results import Trajectory
from .solve_rules import MAX_ITERATIONS_LIMIT, check_gamma
from .unicycle import Unicycle
from .validation import count


def picard_guesses(
    guess, n: int, p: int, gamma: float, single: bool = False
) -> list[Guess | None] | None:
    """Picard guesses (sigma, x) from earlier trajectories (see :func:`solve`), validated.

    ``guess`` is one Trajectory per start (a sequence of n, each a Trajectory or None), or with
    ``single`` the one start's Trajectory; a refusal's field is ``guess`` (``guess.k`` for the
    k-th of a sequence)."""
    if guess is None:
        return None
    if single or isinstance(guess, Trajectory):
        items = [guess]
    elif isinstance(guess, Sequence) and not isinstance(guess, str):
        items = list(guess)
    else:
        raise InvalidInputError(
            "guess must be a list of Trajectory (a SolveResult's .trajectory) or None, one per "
            f"start, got {type(guess).__name__}",
            "guess",
        )
    if len(items) != n:
        raise InvalidInputError(
            f"guess has {len(items)} trajectories for {n} start configurations; give one "
            "Trajectory (or None) per start",
            "guess",
        )
    out: list[Guess | None] = []
    for k, tr in enumerate(items):
        name, field = ("guess", "guess") if single else (f"guess[{k}]", f"guess.{k}")
        if tr is None:
            out.append(None)
            continue
        if not isinstance(tr, Trajectory):
            raise InvalidInputError(
                f"{name} must be a Trajectory (a SolveResult's .trajectory) or None, got "
                f"{type(tr).__name__}",
                field,
            )
        theta = np.asarray(tr.theta, dtype=float)
        x = np.asarray(tr.x, dtype=float)
        if theta.ndim != 1 or x.shape != (len(theta), p) or len(theta) < 2:
            raise InvalidInputError(
                f"{name} must have theta of shape (m,) and x of shape (m, {p}), m >= 2", field
            )
        if not (np.all(np.isfinite(theta)) and np.all(np.isfinite(x))):
            raise InvalidInputError(f"{name} contains NaN or infinite values", field)
        if np.any(np.diff(theta) <= 0):
            raise InvalidInputError(f"{name}.theta must be increasing", field)
        # The homotopy parameter of (*) in engine.picard: sigma = 1 - exp(-gamma theta); the
        # last point of a converged leg is its end, sigma = 1.
        sigma = -np.expm1(-gamma * (theta - theta[0]))
        sigma[-1] = 1.0
        out.append((sigma, x))
    return out


def chain_guesses(
    inverse: Inverse, x0, y_d, *, gamma: float = 1.0, max_sweeps: int = CHAIN_SWEEPS
) -> list[Trajectory] | None:
    """Guesses for solving legs of eq. (7) one after another in continuous mode: leg j from
    where leg j - 1 ends, to ``y_d[j]`` (a closed path's legs, cycle after cycle).

    Pass ``guesses[j]`` as ``guess`` of the solve of leg j (:func:`solve`): the results are
    the same to the sweep tolerance; each leg then takes one or two Picard sweeps instead of
    about ten, and the guesses cost about three legs' worth (:func:`jik.engine.picard.picard_chain`;
    ``jik bench solver``).

    Parameters
    ----------
    inverse : Inverse
    x0 : array_like, shape (p,)
        Start of the first leg.
    y_d : array_like, shape (L, r)
        The legs' targets.
    gamma : float
        The decay rate the legs will be solved with (it only sets their theta).
    max_sweeps : int
        The most sweeps the chain may take (a run's cap on a leg's steps bounds its chain too).

    Returns
    -------
    list of L Trajectory (at the Chebyshev nodes of each leg), or None when the legs
    cannot all be swept on one segment each (a singular J# on the way, a path that needs finer
    segments) within ``max_sweeps``: solve them without guesses then.
    """
    kin = inverse.kinematics
    x0 = kin.check(x0, "x0")
    y_d = kin.check_target(y_d, "y_d")
    gamma = check_gamma(gamma, "continuous")
    if x0.ndim != 1 or y_d.ndim != 2 or len(y_d) == 0:
        raise InvalidInputError(
            f"x0 must be one configuration (p,) and y_d the legs' targets (L, r), L >= 1; "
            f"got shapes {x0.shape} and {y_d.shape}"
        )
    max_sweeps = count(max_sweeps, "max_sweeps", 1, MAX_ITERATIONS_LIMIT)
    chained = picard_chain(inverse, x0, y_d, min(max_sweeps, CHAIN_SWEEPS))
    if chained is None:
        return None
    sigma, X = chained
    # sigma = 1 - exp(-gamma theta) (engine.picard); the last node, sigma = 1, is the leg's end
    # and stands at any later theta (see picard_guesses).
    theta = -np.log1p(-sigma[:-1]) / gamma
    theta = np.append(theta, theta[-1] + 1.0)
    y = kin.forward_unchecked(X)  # (L, nodes, r)
    error = np.linalg.norm(y - y_d[:, None, :], axis=-1)
    return [
        Trajectory(theta=theta, x=X[j], y=y[j], error=error[j], h=inverse.augmenting_value(X[j]))
        for j in range(len(X))
    ]


def cycle_guesses(
    inverse: Inverse,
    start,
    targets,
    guides: list[Trajectory | None],
    gamma: float = 1.0,
    max_sweeps: int = CHAIN_SWEEPS,
) -> list[Trajectory | None]:
    """Picard guesses for one cycle's legs of a closed path from ``start`` (continuous mode,
    one start): the ``guess`` of each leg's :func:`jik.engine.solver.solve`, eq. (7).

    The extended inverse is repeatable: a leg repeats the same leg of the cycle before, so
    ``guides`` (those legs' trajectories, None in the first cycle) are its guesses, and a leg
    then takes one or two sweeps. The pseudoinverse (and the other right inverses, weighted and
    posture) drifts, so the cycle before saves almost nothing: its legs are swept together from
    ``start`` (:func:`jik.engine.picard_guesses.chain_guesses`), one or two sweeps a leg instead of
    about ten, and a cycle's numbers depend only on its start. A chain evaluates J# about three
    times as often as the legs would, so it pays only where an evaluation costs little beyond
    numpy's per-call overhead: not for the unicycle. The chain takes at most ``max_sweeps``
    sweeps, the run's cap on a leg's steps: a cap that a leg's solve cannot meet is not met by
    sweeping the cycle's legs together either.
    """
    if (
        inverse.name != "extended"
        and inverse.right_inverse
        and len(targets) > 1
        and not isinstance(inverse.kinematics, Unicycle)
    ):
        chained = chain_guesses(inverse, start, targets, gamma=gamma, max_sweeps=max_sweeps)
        if chained is not None:
            return list(chained)
    # A leg that started at its target recorded its start alone: nothing to sweep from.
    return [g if g is not None and len(g.theta) >= 2 else None for g in guides]
