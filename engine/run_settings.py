"""Going on from a repeatability run (:class:`Resume`), and what identifies the run besides
its start, so that going on never mixes two runs.

A leg of eq. (7) depends on its start, its target, the inverse J# and the solver's settings;
:class:`RunSettings` holds the last three, and :func:`inverse_fingerprint` digests the numbers an
inverse computes with (its parameters, its augmenting map's, its robot's), so that two inverses
that print alike but differ (maps of two syntheses, say) are told apart.
"""

from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .exceptions import InvalidInputError
from .exports import short_vector
from .validation import FloatArray

if TYPE_CHECKING:
    from .repeatability_result import RepeatabilityResult
    from .results import Trajectory

#: Simple values digested as their repr.
_SIMPLE = (bool, int, float, str, type(None), np.integer, np.floating)


def inverse_fingerprint(inverse) -> str:
    """A digest of what ``inverse`` computes with: its class and, recursively, the public
    attributes of it, its kinematics and its maps (numbers, strings, arrays; not caches, whose
    names start with ``_``). Equal for two inverses built alike, different when a parameter, a
    map's coefficient or a link length differs."""
    digest = hashlib.sha256()
    _feed(digest, inverse, 0)
    return digest.hexdigest()[:16]


def _feed(digest, obj, depth: int) -> None:
    """Digest an object's class and public attributes (module-level, not a closure: a
    recursive closure is a reference cycle that lives until the garbage collector runs)."""
    digest.update(type(obj).__qualname__.encode())
    items = (
        {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}
        if dataclasses.is_dataclass(obj)
        else vars(obj)
        if hasattr(obj, "__dict__")
        else {}
    )
    for key in sorted(items):
        if not key.startswith("_"):
            digest.update(key.encode())
            _value(digest, items[key], depth)


def _value(digest, v, depth: int) -> None:
    """Digest one attribute's value: simple values by repr, arrays by their bytes, containers
    item by item, objects (to depth 4) by :func:`_feed`."""
    if isinstance(v, _SIMPLE):
        digest.update(repr(v).encode())
    elif isinstance(v, np.ndarray):
        digest.update(str(v.dtype).encode() + str(v.shape).encode())
        digest.update(np.ascontiguousarray(v).tobytes())
    elif isinstance(v, (list, tuple)):
        for item in v:
            _value(digest, item, depth)
    elif isinstance(v, dict):
        for k in sorted(v, key=str):
            digest.update(str(k).encode())
            _value(digest, v[k], depth)
    elif depth < 4 and not callable(v) and (hasattr(v, "__dict__") or dataclasses.is_dataclass(v)):
        _feed(digest, v, depth + 1)


@dataclass(frozen=True)
class RunSettings:
    """What fixes the legs of a repeatability run besides its start: the inverse, the closed
    path's targets and the settings of eq. (7). A :class:`Resume`
    carries it and :func:`jik.engine.repeatability.repeatability` goes on only from a run whose
    settings equal its own.

    Attributes
    ----------
    algorithm : str
        ``Inverse.name``.
    inverse : str
        The inverse as printed (its parameters, map and robot).
    fingerprint : str
        :func:`inverse_fingerprint`: two inverses that print alike but compute differently
        (maps of two syntheses) differ here.
    targets : ndarray, shape (L, r) or (n, L, r)
    mode, gamma, tol, max_iterations
        As given to :func:`jik.engine.solver.solve`.
    """

    algorithm: str
    inverse: str
    fingerprint: str
    targets: FloatArray
    mode: str
    gamma: float
    tol: float
    max_iterations: int | None

    def difference(self, other: RunSettings) -> str | None:
        """The first field in which ``other`` differs, with both values; None when equal."""
        for name in ("algorithm", "inverse", "fingerprint", "mode", "gamma", "tol"):
            mine, theirs = getattr(self, name), getattr(other, name)
            if mine != theirs:
                return f"{name}: the earlier run's {mine!r}, this run's {theirs!r}"
        if self.max_iterations != other.max_iterations:
            return (
                f"max_iterations: the earlier run's {self.max_iterations}, this run's "
                f"{other.max_iterations}"
            )
        a, b = np.asarray(self.targets), np.asarray(other.targets)
        if a.shape != b.shape or not np.array_equal(a, b):
            return (
                f"targets: the earlier run's legs went to {short_vector(a)}, this run's go to "
                f"{short_vector(b)} (the path closed by k(x0))"
            )
        return None


@dataclass(frozen=True)
class Resume:
    """Cycles already driven from ``x0``, for :func:`jik.engine.repeatability.repeatability`
    (given as its ``x0``) to go on from their end.

    A leg of eq. (7) depends only on where it starts and on its target, so going on from the
    end of c cycles gives the numbers of a run from x0, bit for bit, when the next cycle's Picard
    guesses are those the run from x0 would use (``guides``).

    Attributes
    ----------
    x0 : array_like, shape (p,) or (n, p)
        The start(s) of the run.
    legs : array_like, shape (c * L, p) or (n, c * L, p)
        The configuration after each leg of the first c cycles: ``legs`` of a run of c cycles
        (every leg converged) from the same x0, path and settings.
    guides : sequence of L Trajectory or None
        Continuous mode, one start: the trajectories of cycle c's legs, each the Picard guess of
        the same leg of the next cycle (:func:`jik.engine.picard_guesses.cycle_guesses`).
        Without them the extended inverse's next cycle starts its sweeps cold: the same legs to
        the sweep tolerance.
    settings : RunSettings or None
        The earlier run's inverse, targets, mode, gamma, tol and max_iterations
        (:attr:`RepeatabilityResult.settings`): a run with other ones refuses to go on, naming
        the field that differs. None (a Resume built by hand): not checked.
    """

    x0: FloatArray
    legs: FloatArray
    guides: Sequence[Trajectory | None] = ()
    settings: RunSettings | None = None

    @classmethod
    def of(cls, result: RepeatabilityResult) -> Resume:
        """Go on from ``result`` (the guides come from its ``leg_results``, if recorded)."""
        L = result.targets.shape[-2]
        guides = [r.trajectory for r in result.leg_results[-L:]] if result.leg_results else []
        return cls(result.x0, result.legs, guides, result.settings)


def resumed_legs(resume: Resume, n: int, L: int, p: int, cycles: int):
    """The legs (n, c * L, p) of ``resume`` and its guides (a list of L, or []); a refusal's
    field is ``x0``, where the Resume was given."""
    try:
        given = np.asarray(resume.legs, dtype=float)
    except (TypeError, ValueError):
        given = np.zeros(0)
    done = given[None] if given.ndim == 2 and n == 1 else given
    m = done.shape[1] if done.ndim == 3 else 0
    if done.shape != (n, m, p) or m == 0 or m % L or m // L > cycles:
        raise InvalidInputError(
            f"resume.legs must be the legs of 1 to {cycles} whole cycles of {L} legs, shape "
            f"(c * {L}, {p}) for one start or (n, c * {L}, {p}) for n starts; got "
            + (f"shape {given.shape}" if given.size else f"{resume.legs!r:.60}"),
            "x0",
        )
    if not np.all(np.isfinite(done)):
        raise InvalidInputError(
            "resume.legs contains NaN: go on only from a run whose legs all converged", "x0"
        )
    guides = list(resume.guides)
    if guides and len(guides) != L:
        raise InvalidInputError(
            f"resume.guides must have one trajectory (or None) per leg, {L}", "x0"
        )
    return done, guides
