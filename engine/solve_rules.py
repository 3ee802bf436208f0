"""The rules of a solve of eq. (7): its modes, its limits, gamma's range, the check of its
settings and of its starts, the memory a batch of it holds (for
:func:`jik.engine.validation.check_memory`), and why a run stopped.

One definition of each, used by the solver (:mod:`jik.engine.solver`), the atlas, and the app's
request schemas and dashboard, which word their errors with :func:`gamma_problem`.
"""

from __future__ import annotations

import math
from typing import Literal, get_args

import numpy as np

from . import validation
from .exceptions import AlgorithmicSingularityError, InvalidInputError
from .inverses import Inverse
from .kinematics import Kinematics
from .limit_stall import pressed_joint
from .picard import DEGREE
from .stall import reach_note, stall_reason
from .validation import FloatArray, check_memory, count, positive

#: The task-error tolerance ``tol`` of a solve: its smallest (double precision) and largest
#: (a larger one stops every run at its start, far from the task).
TOL_MIN, TOL_MAX = 1e-14, 1.0
#: Default caps of :func:`solve`: integrator steps (continuous), iterations (discrete).
MAX_STEPS = 20000
MAX_ITERATIONS = 2000
#: The largest cap ``max_iterations`` (and ``chunk``) that a solve accepts.
MAX_ITERATIONS_LIMIT = 10**6
#: Largest |x| before a run counts as diverged.
DIVERGED_NORM = 1e8
#: The modes of eq. (7): its ODE (continuous), or the iteration x <- x - gamma J# e (discrete).
Mode = Literal["continuous", "discrete"]
MODES: tuple[Mode, ...] = get_args(Mode)
#: The integrators of continuous mode (:func:`jik.engine.solver.solve`'s ``method``).
METHODS = ("auto", "picard", "dop853")
#: The decay rate gamma of eq. (5) that the engine, the API and the dashboard accept. Continuous
#: runs depend on gamma only through theta = -log(1 - s) / gamma (theta's scale); far below
#: GAMMA_MIN that scale leaves the floating-point range.
GAMMA_MIN, GAMMA_MAX = 1e-6, 1e6
#: Discrete mode converges near a solution only for gamma below this: the task error shrinks
#: by |1 - gamma| per iteration there.
DISCRETE_GAMMA_BOUND = 2.0

#: Bytes of a batch member's stop message (a Python string in the result's tuple).
MESSAGE_BYTES = 256

# Recorded steps: (member indices (k,), theta (k,), x (k, p)) per accepted step.
Record = list[tuple[FloatArray, FloatArray, FloatArray]]


class Status:
    """A member's outcome: running, or why it stopped (kept as ints in arrays of statuses).
    UNDEFINED is a SINGULAR stop where J# is undefined because its augmenting map h is
    (:meth:`jik.engine.inverses.Inverse.map_undefined`), not [J; dh] singular (eq. (11))."""

    RUNNING, CONVERGED, SINGULAR, MAX_STEPS, DIVERGED, STALLED, UNDEFINED = range(7)
    #: Each outcome's name, as :attr:`jik.engine.results.SolveResult.status` gives it.
    NAMES = ("running", "converged", "singular", "max_steps", "diverged", "stalled", "undefined")


def gamma_problem(gamma: float, mode: str) -> str | None:
    """What is wrong with a positive ``gamma`` in ``mode``, as a phrase to follow the field's
    name ("must be < 2 in discrete mode, got 2.5 (...)"), or None: the one wording of gamma's
    rules, for the engine's errors and the app's."""
    if not GAMMA_MIN <= gamma <= GAMMA_MAX:
        return f"must be between {GAMMA_MIN:g} and {GAMMA_MAX:g}, got {gamma:g}"
    if mode == "discrete" and gamma >= DISCRETE_GAMMA_BOUND:
        return (
            f"must be < {DISCRETE_GAMMA_BOUND:g} in discrete mode, got {gamma:g} (near the "
            "solution the error shrinks by |1 - gamma| per iteration)"
        )
    return None


def check_gamma(gamma, mode: str) -> float:
    """``gamma`` as a float, checked for ``mode`` (:func:`gamma_problem`).

    Raises
    ------
    InvalidInputError
        With ``field="gamma"``: not a number, <= 0, outside [GAMMA_MIN, GAMMA_MAX], or not below
        :data:`DISCRETE_GAMMA_BOUND` in discrete mode.
    """
    try:
        value = positive(gamma, "gamma")
    except InvalidInputError as exc:
        raise InvalidInputError(str(exc), field="gamma") from None
    why = gamma_problem(value, mode)
    if why is not None:
        raise InvalidInputError(f"gamma {why}", field="gamma")
    return value


def check_inverse(inverse) -> Kinematics:
    """The kinematics of ``inverse``, which must be an :class:`Inverse` (field "inverse")."""
    if not isinstance(inverse, Inverse):
        raise InvalidInputError(
            "inverse must be an Inverse (Pseudoinverse(robot), ExtendedInverse(robot, map), "
            f"make_inverse(robot, 'damped', ...)), got {type(inverse).__name__} {inverse!r:.60}",
            "inverse",
        )
    return inverse.kinematics


def refused_starts(inverse: Inverse, x0: FloatArray) -> dict[int, str]:
    """The starts of a batch from which eq. (7) cannot run with ``inverse``, each with why.

    Parameters
    ----------
    inverse : Inverse
    x0 : array_like, shape (n, p) or (p,)
        Finite starts (a NaN is refused here, naming ``x0``, as :func:`solve_batch` does).

    Returns
    -------
    dict int -> str
        Index in ``x0`` -> why: the kinematics overflow there (k(x0) or its Jacobian not
        finite), J#(x0) is undefined (the inverse's singular error), h(x0) has no value
        (:func:`map_value_undefined`), or the kinematics' check of starts refuses it (a pose
        task's rotation cut). Empty when every start
        can run; :func:`jik.engine.solver.solve_batch` raises at the first refused one.
    """
    x0 = np.atleast_2d(validation.as_points(x0, check_inverse(inverse).p, "x0"))
    _, bad = inverse.apply_masked(x0, np.ones((len(x0), inverse.kinematics.r)))
    with np.errstate(all="ignore"):
        bad = bad | ~np.isfinite(inverse.kinematics.forward_unchecked(x0)).all(axis=-1)
    bad = bad | map_value_undefined(inverse, x0)
    out = {int(i): start_problem(inverse, x0[i]) for i in np.flatnonzero(np.atleast_1d(bad))}
    try:  # (the kinematics' own check of starts, all at once: a pose task's rotation cut)
        inverse.kinematics.check_start(x0)
    except InvalidInputError:
        for i in set(range(len(x0))) - out.keys():  # (which: one by one)
            try:
                inverse.kinematics.check_start(x0[i], "the start")
            except InvalidInputError as exc:
                out[i] = str(exc)
    return dict(sorted(out.items()))


def start_problem(inverse: Inverse, x: FloatArray) -> str:
    """Why eq. (7) cannot start at ``x`` (p,): k(x) or its Jacobian not finite (the task
    undefined or overflowing there), else J#(x) singular."""
    with np.errstate(all="ignore"):
        y = np.asarray(inverse.kinematics.forward(x), dtype=float)
        jacobian = np.asarray(inverse.kinematics.jacobian(x), dtype=float)
    if not (np.all(np.isfinite(y)) and np.all(np.isfinite(jacobian))):
        shown = ", ".join(f"{v:.6g}" for v in y)
        return (
            f"the kinematics are not finite at the start: k(x0) = ({shown}), its Jacobian "
            f"{'finite' if np.all(np.isfinite(jacobian)) else 'not finite'} (the task is "
            "undefined there, or overflows); choose a start where both are finite"
        )
    if map_value_undefined(inverse, x[None])[0]:
        return str(map_value_error(inverse, x))
    return f"{inverse.singular_error(x)}; move the start"


def map_value_undefined(inverse: Inverse, x0: FloatArray) -> FloatArray:
    """Where the extended inverse's augmenting map has no finite value at the starts ``x0``
    (n, p): bool (n,). A run uses only dh (eq. (11)), so it would run from there, yet what the
    inverse keeps, h(x) = h(x0) (eq. (12)), means nothing (a formula such as
    ``log(-1 - x1**2)``, whose gradient is real). All False for an inverse without a map, and
    for a map that solves a problem per point (the unicycle's characteristics map)."""
    x0 = np.asarray(x0, dtype=float)
    maps = getattr(inverse, "augmenting_maps", None) or (getattr(inverse, "augmenting_map", None),)
    if maps[0] is None or any(getattr(m, "solves_per_point", False) for m in maps):
        return np.zeros(len(x0), dtype=bool)
    with np.errstate(all="ignore"):
        h = np.asarray(inverse.augmenting_value(x0), dtype=float).reshape(len(x0), -1)
    return ~np.isfinite(h).all(axis=-1)


def check_map_value(inverse: Inverse, x0: FloatArray) -> None:
    """Refuse the starts ``x0`` (n, p) if the augmenting map has no real value at one of them
    (:func:`map_value_undefined`): raise :func:`map_value_error` at the first such start (a
    solve, a batch and a repeatability run alike)."""
    undefined = np.flatnonzero(map_value_undefined(inverse, x0))
    if undefined.size:
        raise map_value_error(inverse, x0[undefined[0]])


def map_value_error(inverse: Inverse, x: FloatArray) -> AlgorithmicSingularityError:
    """The error of a start ``x`` (p,) where :func:`map_value_undefined`."""
    with np.errstate(all="ignore"):
        h = np.asarray(inverse.augmenting_value(np.asarray(x, dtype=float)[None]), dtype=float)
    h = np.ravel(h)  # (one value, or p - r)
    shown = ", ".join(f"{v:.6g}" for v in h)
    return AlgorithmicSingularityError(
        f"the augmenting map has no real value at the start (h(x0) = {shown}): the "
        "extended inverse (11) keeps h(x) = h(x0), which means nothing there; choose a start "
        "where h is defined, or another map",
        x,
        "x0",
    )


def check_settings(
    mode, gamma, tol, max_iterations, method: str = "auto"
) -> tuple[str, float, float, int]:
    """A solve's ``mode``, ``gamma``, ``tol`` and step cap (``max_iterations``, default
    :data:`MAX_STEPS` or :data:`MAX_ITERATIONS` by mode), checked; ``method`` too.

    Raises
    ------
    InvalidInputError
        Naming the field: mode, gamma (:func:`check_gamma`), tol, max_iterations or method.
    """
    if mode not in MODES:
        raise InvalidInputError(f"mode must be 'continuous' or 'discrete', got {mode!r}", "mode")
    gamma = check_gamma(gamma, mode)
    tol = positive(tol, "tol")
    if not TOL_MIN <= tol <= TOL_MAX:
        raise InvalidInputError(
            f"tol must be between {TOL_MIN:g} (double precision) and {TOL_MAX:g}, got {tol:g}",
            "tol",
        )
    if method not in METHODS:
        raise InvalidInputError(
            f"method must be 'auto', 'picard' or 'dop853', got {method!r}", "method"
        )
    if method != "auto" and mode == "discrete":
        raise InvalidInputError(
            f"method {method!r} integrates (7) in continuous mode; a discrete run iterates",
            "method",
        )
    default = MAX_STEPS if mode == "continuous" else MAX_ITERATIONS
    cap = count(
        default if max_iterations is None else max_iterations,
        "max_iterations",
        1,
        MAX_ITERATIONS_LIMIT,
    )
    return mode, gamma, tol, cap


def counted(n: int, mode: str) -> str:
    """``n`` steps of ``mode``: integrator steps (continuous) or iterations (discrete), the
    singular for one ("1 step", "20 iterations")."""
    return f"{n} {'step' if mode == 'continuous' else 'iteration'}{'' if n == 1 else 's'}"


def stop_message(status, nit, err, tol, mode, gamma, x, inverse, max_iterations, target) -> str:
    """What a member that stopped with ``status`` after ``nit`` steps at task error ``err``, at
    ``x`` on its way to ``target``, says: a stall says why
    (:func:`jik.engine.stall.stall_reason`); a run that diverged or ran out of steps says
    whether the target is out of reach (:func:`jik.engine.stall.reach_note`), else what to
    change: a discrete run that diverged a lower gamma (shorter steps) and, for the posture
    inverse, a lower gain k (its null-space pull grows with k ||e||), one out of iterations
    gamma nearer 1 (near a solution the error shrinks by |1 - gamma| per iteration, eq. (5));
    in continuous mode gamma only rescales theta, so more steps, not another gamma. A run of
    the weighted inverse blocked at a joint limit says so instead, stalled or out of steps
    (:func:`jik.engine.limit_stall.pressed_joint`): more steps do not help it."""
    steps = counted(nit, mode)
    if status == Status.CONVERGED:
        if nit == 0:
            return f"already at the target (error {err:.3g} < {tol:g}): no motion"
        return f"converged: task error {err:.3g} < {tol:g} after {steps}"
    if status in (Status.SINGULAR, Status.UNDEFINED):
        return str(inverse.singular_error(x)) + "; the run stopped there"
    pressed = pressed_joint(inverse, target, x)
    if status == Status.STALLED:
        why = pressed or stall_reason(inverse, target, x)
        return f"stalled after {steps} at error {err:.3g}: {why}"
    out, _ = reach_note(inverse.kinematics, target)
    nearer = mode == "discrete" and gamma != 1.0
    if status == Status.DIVERGED:
        gain = getattr(inverse, "gain", None)  # (the posture inverse's k)
        lower = "lower gamma" + ("" if gain is None else f" or the posture gain k ({gain:g})")
        advice = out or (lower if mode == "discrete" else "the target may be unreachable")
        return f"diverged after {steps} (error {err:.3g}); {advice}"
    advice = (
        out or pressed or "raise max_iterations" + (", or take gamma nearer 1" if nearer else "")
    )
    return (
        f"did not converge within {counted(max_iterations, mode)} (error {err:.3g} >= {tol:g}); "
        + advice
    )


def recorded_steps(mode: str, gamma: float, tol: float, cap: int) -> int:
    """About how many steps a recorded run keeps per member: a few Picard segments of
    DEGREE + 1 nodes (continuous), or the iterations that shrink the error by ``tol`` at the
    rate |1 - gamma| of a discrete step near the solution, at most ``cap``."""
    if mode == "continuous":
        return min(cap, 3 * (DEGREE + 1))
    rate = min(gamma, 2.0 - gamma, 1.0)
    return min(cap, 8 + math.ceil(-math.log(tol) / rate))


def solve_bytes(
    kinematics,
    n: int,
    mode: str,
    record: bool,
    gamma: float = 1.0,
    tol: float = 1e-10,
    cap: int = MAX_STEPS,
) -> float:
    """Estimated peak memory, in bytes, of a batched solve of eq. (7) with ``n`` members
    (:func:`jik.engine.solver.solve_batch`).

    Per member: the working set of a sweep (continuous: the Picard iterates, their changes and
    J#(x) e at the DEGREE + 1 nodes of a segment, :mod:`jik.engine.picard`; discrete: one
    iterate), each evaluation of J holding ``kinematics.scratch`` numbers; the recorded steps
    (:func:`recorded_steps`, kept twice while the record is gathered); the result's arrays
    and message. Measured peaks (tracemalloc, Manipulator 2 to a Panda) are 0.45 to 0.85
    times this.
    """
    p, r = kinematics.p, kinematics.r
    if mode == "continuous":
        work = (DEGREE + 1) * (6 * p + 2 * r + kinematics.scratch)
    else:
        work = 4 * p + 2 * r + kinematics.scratch
    kept = 2 * recorded_steps(mode, gamma, tol, cap) * (p + 2) if record else 0
    return float(n) * (8.0 * (work + kept + 2 * p + 3 * r + 2) + MESSAGE_BYTES)


def run_bytes(
    kinematics, cycles: int, legs: int, mode: str, record: bool, gamma: float, tol: float, cap: int
) -> float:
    """Estimated peak memory, in bytes, of :func:`repeatability` per start: its leg ends
    (cycles x legs configurations, and their drift), the targets, and one leg's batched solve
    (:func:`jik.engine.solve_rules.solve_bytes`); with ``record``, every leg's trajectory."""
    p, r = kinematics.p, kinematics.r
    held = 8.0 * (2 * cycles * legs * p + legs * r + cycles * (p + 1) + 3 * p)
    each_leg = solve_bytes(kinematics, 1, mode, record, gamma, tol, cap)
    return held + (cycles * legs * each_leg if record else each_leg)


def chunk_limit(kinematics, algorithms: int, cycles: int, legs: int, settings, chunk) -> int:
    """How many runs of an atlas fit in a chunk within :data:`MEMORY_LIMIT
    <jik.engine.validation.MEMORY_LIMIT>` (:func:`jik.engine.atlas.plan_atlas`).

    A run of a chunk (:func:`jik.engine.atlas_run.run_chunk`) holds its start, targets, drift
    and leg ends for each of the ``algorithms`` (with the masks of the joint limits' check), and
    its share of one batched repeatability run (:func:`run_bytes`).

    Raises
    ------
    InvalidInputError
        Naming ``cycles`` when one run does not fit, ``chunk`` when ``chunk`` (if given)
        runs do not.
    """
    p, r = kinematics.p, kinematics.r
    kept = 8.0 * (algorithms * (1.25 * cycles * legs * p + cycles + 2) + p + legs * r)
    mode, gamma, tol = settings["mode"], settings["gamma"], settings["tol"]
    each = kept + run_bytes(kinematics, cycles, legs, mode, False, gamma, tol, MAX_STEPS)
    if each > validation.MEMORY_LIMIT:
        check_memory(cycles, each / cycles, "cycles", "cycles of one run", "ask for fewer cycles")
    if chunk is not None:
        check_memory(
            chunk, each, "chunk", "runs of a chunk", "give a smaller chunk or fewer cycles"
        )
    return int(validation.MEMORY_LIMIT // each)
