"""The rules of a solve of eq. (7): its modes, its limits, gamma's range, and why a run stopped.

One definition of each, used by the solver (:mod:`jik.engine.solver`), the atlas, and the app's
request schemas and dashboard, which word their errors with :func:`gamma_problem`.
"""

from __future__ import annotations

from .exceptions import InvalidInputError
from .validation import FloatArray, positive

#: The smallest task-error tolerance ``tol`` of a solve (double precision).
TOL_MIN = 1e-14
#: Default caps of :func:`solve`: integrator steps (continuous), iterations (discrete).
MAX_STEPS = 20000
MAX_ITERATIONS = 2000
#: The largest cap ``max_iterations`` (and ``chunk``) that a solve accepts.
MAX_ITERATIONS_LIMIT = 10**6
#: Largest |x| before a run counts as diverged.
DIVERGED_NORM = 1e8
#: The modes of eq. (7): its ODE (continuous), or the iteration x <- x - gamma J# e (discrete).
MODES = ("continuous", "discrete")
#: The decay rate gamma of eq. (5) that the engine, the API and the dashboard accept. Continuous
#: runs depend on gamma only through theta = -log(1 - s) / gamma (theta's scale); far below
#: GAMMA_MIN that scale leaves the floating-point range.
GAMMA_MIN, GAMMA_MAX = 1e-6, 1e6
#: Discrete mode converges near a solution only for gamma below this: the task error shrinks
#: by |1 - gamma| per iteration there.
DISCRETE_GAMMA_BOUND = 2.0

# Recorded steps: (member indices (k,), theta (k,), x (k, p)) per accepted step.
Record = list[tuple[FloatArray, FloatArray, FloatArray]]


class Status:
    """A member's outcome: running, or why it stopped (kept as ints in arrays of statuses)."""

    RUNNING, CONVERGED, SINGULAR, MAX_STEPS, DIVERGED, STALLED = range(6)


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


def stop_message(status, nit, err, tol, mode, x, inverse, max_iterations) -> str:
    """What a member that stopped with ``status`` after ``nit`` steps at task error ``err`` says."""
    steps = "steps" if mode == "continuous" else "iterations"
    if status == Status.CONVERGED:
        if nit == 0:
            return f"already at the target (error {err:.3g} < {tol:g}): no motion"
        return f"converged: task error {err:.3g} < {tol:g} after {nit} {steps}"
    if status == Status.SINGULAR:
        return str(inverse.singular_error(x)) + "; the run stopped there"
    if status == Status.DIVERGED:
        return f"diverged after {nit} {steps} (error {err:.3g}); " + (
            "lower gamma" if mode == "discrete" else "the target may be unreachable"
        )
    if status == Status.STALLED:
        return (
            f"stalled after {nit} {steps} at error {err:.3g}: the step size collapsed near a "
            "singularity or the target is unreachable"
        )
    return (
        f"did not converge within {max_iterations} {steps} (error {err:.3g} >= {tol:g}); "
        "raise max_iterations or gamma"
    )
