"""Symbolic derivations (sympy) against the numeric engine and the paper's printed formulas."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from jik.engine.augmentations import E1Optimal, E2Optimal
from jik.engine.functionals import error_functional_e1
from jik.engine.inverses import pseudoinverse
from jik.engine.kinematics import Manipulator1, Manipulator2
from jik.engine.symbolic import (
    X,
    euler_equation_e2,
    kinematics_quantities,
    manipulator1_findings,
    manipulator2_findings,
    x1,
    x2,
    x3,
)


def _numeric_P(kin, x):
    J, K = kin.jacobian(x), kin.kernel(x)
    Jp = pseudoinverse(J)
    return Jp @ np.swapaxes(Jp, -1, -2) + K[:, :, None] * K[:, None, :]


@pytest.mark.parametrize(
    "kin, exprs",
    [
        (Manipulator1(), [x1, x2 + x1 * x3]),
        (
            Manipulator2(0.7),
            [x2 + sp.Rational(7, 10) * sp.cos(x3), x1 + sp.Rational(7, 10) * sp.sin(x3)],
        ),
    ],
)
def test_symbolic_quantities_match_the_engine(kin, exprs):
    """J, K (same orientation: last component > 0), m and P agree at random points."""
    q = kinematics_quantities(exprs, X)
    pts = np.random.default_rng(0).uniform(-1.5, 1.5, (15, 3))
    f = {name: sp.lambdify(X, q[name], "numpy") for name in ("J", "K", "m", "P")}
    for x in pts:
        np.testing.assert_allclose(np.array(f["J"](*x), float), kin.jacobian(x), atol=1e-13)
        np.testing.assert_allclose(np.array(f["K"](*x), float).ravel(), kin.kernel(x), atol=1e-13)
        assert float(f["m"](*x)) == pytest.approx(float(kin.manipulability(x)), rel=1e-13)
        np.testing.assert_allclose(
            np.array(f["P"](*x), float), _numeric_P(kin, x[None])[0], atol=1e-12
        )


def test_euler_equation_20_is_the_first_variation_of_e2():
    """For a polynomial h the residual of (20) is the L2 gradient of E2: check a known solution."""
    q = kinematics_quantities([x1, x2 + x1 * x3], X)
    a, b = sp.Rational(3, 7), sp.Rational(-2, 5)
    h = x3 * (a * x1 + b) * sp.sqrt(1 + x1**2)
    assert sp.simplify(euler_equation_e2(q, h, X)) == 0
    assert sp.simplify(euler_equation_e2(q, x3**2, X)) != 0


def _by_claim(findings):
    return {f["claim"]: f["holds"] for f in findings}


def test_manipulator1_findings():
    """(34) is (20), (36) solves it; the printed P, M and (35) have typos; (31) solves the E1
    ODE but is not the minimiser of E1 within h = x3 f(x1)."""
    got = _by_claim(manipulator1_findings())
    assert got["(20) for Manipulator 1 is (34) (div(m K) = 0)"]
    assert got["(36) solves (20) for all a, b"]
    assert got["f = (a x1 + b) sqrt(1 + x1^2) solves the corrected (35) for all a, b"]
    assert got[
        "the paper's E1 ODE (before (31)) is the Euler equation (15) of (14) for h = x3 f(x1)"
    ]
    assert got["(31) solves the paper's E1 ODE for all C1, C2"]
    assert got["K = (0, -x1, 1)/sqrt(1 + x1^2) and m = sqrt(1 + x1^2)"]
    assert not got["printed P(x) of sec. 5.1.2 equals (J^T J + K K^T)^(-1)"]
    assert not got["printed M(x) of Manipulator 1 equals J J^T"]
    assert not got["(35) as printed is the reduction of (34) for h = x3 f(x1)"]
    assert not got["E1 restricted to h = x3 f(x1) is minimised by (31)"]


def test_e1_numbers_agree_with_the_symbolic_finding():
    """Numerically, (36) with a = 0 has lower E1 than (32) for several C1, C2."""
    region = {"x1": (0.0, 1.0), "x2": (0.0, 1.0), "x3": (0.5, 1.5)}
    best = error_functional_e1(Manipulator1(), E2Optimal(0.0, 1.0), region).value
    for C1, C2 in [(1.0, 1.0), (2.0, 0.5), (1.0, 5.0), (-1.0, 3.0)]:
        assert best < error_functional_e1(Manipulator1(), E1Optimal(C1, C2), region).value


def test_manipulator2_findings():
    got = _by_claim(manipulator2_findings(1.0))
    assert got["printed R(x) = m P of sec. 5.2 (l = 1)"]
    assert got["for h = h(x2, x3), R reduces to the printed 2 x 2 block"]
    assert got["div(m K) = 0, so (20) is div(R grad h) = 0 as printed"]
    assert got["m = sqrt(1 + l^2) and K = (-l cos x3, l sin x3, 1)/m"]
    assert not got["printed M(x) of Manipulator 2 equals J J^T (arm length l)"]
