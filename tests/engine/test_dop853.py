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
