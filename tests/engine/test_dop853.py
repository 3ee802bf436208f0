"""The DOP853 tableau of jik.engine.dop853: the order conditions, and SciPy's coefficients."""

import importlib

import numpy as np
import pytest

from jik.engine import dop853


def test_nodes_are_row_sums():
    """c_i = sum_j a_ij, to rounding."""
    np.testing.assert_allclose(dop853.A.sum(axis=1), dop853.C, rtol=0, atol=1e-14)


@pytest.mark.parametrize("k", range(8))
def test_quadrature_order_conditions(k):
    """sum_i b_i c_i^k = 1/(k+1) for k < 8: the weights integrate polynomials of degree 7."""
    assert abs(dop853.B @ dop853.C**k - 1 / (k + 1)) < 1e-14


def test_error_estimators_vanish_on_constants():
    """Both estimators are differences of two solutions' weights: they sum to zero."""
    assert abs(dop853.E3.sum()) < 1e-14
    assert abs(dop853.E5.sum()) < 1e-14


def test_matches_scipy_where_its_private_module_exists():
    """The same numbers as SciPy's solve_ivp uses, bit for bit (skipped if SciPy moved them)."""
    try:
        scipy_dop = importlib.import_module("scipy.integrate._ivp.dop853_coefficients")
    except ImportError:
        pytest.skip("this SciPy has no scipy.integrate._ivp.dop853_coefficients")
    n = scipy_dop.N_STAGES
    assert dop853.N_STAGES == n
    np.testing.assert_array_equal(dop853.A, scipy_dop.A[:n, :n])
    np.testing.assert_array_equal(dop853.C, scipy_dop.C[:n])
    for name in ("B", "E3", "E5"):
        np.testing.assert_array_equal(getattr(dop853, name), getattr(scipy_dop, name))


def test_one_step_matches_scipy_solve_ivp():
    """One fixed DOP853 step of dx/dt = -x^2 + t from our tableau equals a hand-rolled step
    built from the public solve_ivp result to its tolerance: the tableau drives a real method."""
    from scipy.integrate import solve_ivp

    def f(t, x):
        return -(x**2) + t

    h, x0 = 0.1, np.array([1.0])
    K = np.zeros((dop853.N_STAGES, 1))
    for s in range(dop853.N_STAGES):
        K[s] = f(dop853.C[s] * h, x0 + h * dop853.A[s, :s] @ K[:s])
    x1 = x0 + h * dop853.B @ K
    ref = solve_ivp(f, (0, h), x0, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    np.testing.assert_allclose(x1, ref, rtol=0, atol=1e-12)


def _log_robot():
    """A formula robot whose task log(a) + c is undefined for a <= 0."""
    from jik.engine.formula_kinematics import FormulaKinematics
    from jik.engine.inverses import Pseudoinverse

    kin = FormulaKinematics(variables=["a", "b", "c"], task=["log(a) + c", "b + sqrt(c)"])
    return Pseudoinverse(kin)


def test_initial_step_is_finite_where_its_trial_point_leaves_the_domain():
    """At a = 0.0015 the first trial step h0 f lands at a < 0, where k is NaN: the starting
    step is h0 (the step control shrinks it), not NaN, which no step would ever replace."""
    inverse = _log_robot()
    x = np.array([[0.0015115, 0.21282092, 0.6196509]])
    y_d = np.array([[-10.0, 1.0]])
    f, _, _ = dop853._rhs(inverse, x, y_d)
    h = dop853._initial_step(inverse, x, f, y_d, dop853.RTOL, dop853.ATOL)
    assert np.isfinite(h).all() and (h > 0).all()
    _, _, status, steps, _ = dop853.integrate(inverse, x, y_d, 1e-10, 500, False, np.zeros(1))
    assert status[0] == dop853.Status.CONVERGED and steps[0] < 100


def test_solve_hands_over_to_dop853_near_the_edge_of_the_domain():
    """Picard's sweeps stop at a = 0.0015, near log's edge; DOP853 goes on from there to the
    target (it used to spin there on a NaN step until max_iterations)."""
    from jik.engine.solver import solve

    result = solve(_log_robot(), [1.0, 0.0, 1.0], [-10.0, 1.0], max_iterations=500)
    assert result.success, result.message
    assert result.error < 1e-10
