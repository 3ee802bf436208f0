"""Error functionals E1 (13)/(14) and E2 (18)/(19) against closed forms and each other."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from jik.engine.augmentations import AugmentingMap, E1Optimal, E2Optimal, PaperCubic, Polynomial2
from jik.engine.exceptions import InvalidInputError, RunCancelled
from jik.engine.formula_kinematics import FormulaMap
from jik.engine.functional_report import parameter_sensitivity
from jik.engine.functionals import (
    e1_integrand,
    e2_integrand,
    error_functional_e1,
    error_functional_e2,
    quadrature,
)
from jik.engine.inverses import pseudoinverse
from jik.engine.kinematics import Manipulator1, Manipulator2
from jik.engine.progress import ProgressCallbacks

REGION1 = {"x1": (0.0, 1.0), "x2": (0.0, 1.0), "x3": (0.5, 1.5)}
REGION2 = {"x2": (-1.0, 1.0), "x3": (0.0, np.pi)}
X3_SQUARE = (1.5**3 - 0.5**3) / 3.0  # integral of x3^2 over [0.5, 1.5]


def _e1_closed(a: float, b: float) -> float:
    """E1 of (36) on REGION1: integrand x3^2 a^2 (1 + x1^2) / (a x1 + b)^2 + x1^2 / (1 + x1^2).

    With h = x3 f(x1), dh P dh^T / (dh K)^2 - 1 = x3^2 (s f'/f - x1/s)^2 + x1^2/s^2, s = m(x).
    """

    def g(x1):
        return X3_SQUARE * a**2 * (1 + x1**2) / (a * x1 + b) ** 2 + x1**2 / (1 + x1**2)

    return integrate.quad(g, 0.0, 1.0, epsabs=1e-13, epsrel=1e-13, limit=200)[0]


def _e2_closed(a: float, b: float) -> float:
    """E2 of (36) on REGION1.

    dh K = a x1 + b and dh P dh^T = x3^2 a^2 s^2 + (a x1 + b)^2 (1 + 2 x1^2) / s^2.
    """

    def g(x1):
        s2 = 1 + x1**2
        f = a * x1 + b
        return np.sqrt(s2) * (X3_SQUARE * a**2 * s2 + f**2 * (1 + 2 * x1**2) / s2 - 2 * f + 1)

    return integrate.quad(g, 0.0, 1.0, epsabs=1e-13, epsrel=1e-13, limit=200)[0]


class _Negated(AugmentingMap):
    name = "negated"

    def __init__(self, h: AugmentingMap) -> None:
        self.h, self.p = h, h.p

    def value(self, x):
        return -self.h.value(x)

    def gradient(self, x):
        return -self.h.gradient(x)


@pytest.mark.parametrize("a, b", [(0.0, 1.0), (-2.0 / 3.0, 1.0), (0.4, 1.3), (1.0, 2.0)])
def test_e1_e2_of_36_match_one_dimensional_integrals(a, b):
    """E1 and E2 of h = x3 (a x1 + b) sqrt(1 + x1^2) reduce to 1-D integrals in x1."""
    k = Manipulator1()
    h = E2Optimal(a, b)
    e1 = error_functional_e1(k, h, REGION1, nodes=24)
    e2 = error_functional_e2(k, h, REGION1, nodes=24)
    assert e1.value == pytest.approx(_e1_closed(a, b), rel=1e-10, abs=1e-12)
    assert e2.value == pytest.approx(_e2_closed(a, b), rel=1e-10, abs=1e-12)
    assert e1.n_points == 24**3 and e1.singular_points.shape == (0, 3)


def test_e1_of_36_with_a_zero_is_one_minus_pi_over_four():
    """With f = sqrt(1 + x1^2) the x3-dependent part of the E1 integrand vanishes."""
    v = error_functional_e1(Manipulator1(), E2Optimal(0.0, 1.0), REGION1).value
    assert v == pytest.approx(1.0 - np.pi / 4.0, abs=1e-12)


def test_integrands_equal_paper_forms_14_and_19():
    """(13) = (14): ||J^P# - J^E#||^2 = dh P dh^T / (dh K)^2 - 1; (18) = (19)."""
    rng = np.random.default_rng(3)
    for kin, h in [(Manipulator1(), E1Optimal(1.3, 0.7)), (Manipulator2(0.7), PaperCubic())]:
        x = rng.uniform(0.2, 1.2, (200, 3))
        J, K, m, dh = kin.jacobian(x), kin.kernel(x), kin.manipulability(x), h.gradient(x)
        Jp = pseudoinverse(J)
        P = Jp @ np.swapaxes(Jp, -1, -2) + K[:, :, None] * K[:, None, :]
        dPd = np.einsum("ni,nij,nj->n", dh, P, dh)
        dk = np.einsum("ni,ni->n", dh, K)
        np.testing.assert_allclose(e1_integrand(J, dh), dPd / dk**2 - 1.0, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(
            e2_integrand(J, K, m, dh), (dPd - 2 * dk + 1) * m, rtol=1e-10, atol=1e-12
        )


def test_singular_points_are_reported_not_dropped_silently():
    """dh K = 0 on a line x3 = c through Gauss nodes: the points are listed; E1 diverges there
    (its integrand grows like (dh K)^(-2), eq. (14)), E2 stays finite."""
    nodes = 8
    x, _, _, _ = quadrature(Manipulator2(), REGION2, nodes)
    c = float(np.unique(x[:, 2])[3])
    h = Polynomial2({(0, 2): 0.5, (0, 1): -c})  # h3 = x3 - c, h2 = 0: dh K = 0 at x3 = c
    k = Manipulator2()
    e1 = error_functional_e1(k, h, REGION2, nodes=nodes)
    e2 = error_functional_e2(k, h, REGION2, nodes=nodes)
    assert e1.singular_points.shape == (nodes, 3)
    np.testing.assert_allclose(e1.singular_points[:, 2], c, atol=1e-15)
    assert e1.value == np.inf and e1.divergent
    assert e1.as_dict()["value"] is None  # (JSON-ready: no Infinity)
    assert e1.min_abs_dh_k == pytest.approx(0.0, abs=1e-15)
    assert e2.singular_points.shape == (nodes, 3) and np.isfinite(e2.value)
    assert not e2.divergent


@pytest.mark.parametrize(
    ("top", "divergent"), [(1.6, True), (np.pi / 2, True), (1.5, False), (1.55, False)]
)
def test_e1_diverges_where_dh_k_changes_sign_between_the_nodes(top, divergent):
    """Manipulator 2 with h = x1: dh K vanishes on x3 = pi/2 and nowhere else. A box across it
    (no Gauss node on it) or up to it (on a face) has E1 = inf; a box short of it a finite E1,
    growing as the box nears the line."""
    k = Manipulator2()
    h = FormulaMap("x1", k.variable_names)
    e1 = error_functional_e1(k, h, {"x2": (0.0, 1.0), "x3": (1.0, top)})
    assert e1.divergent is divergent and bool(np.isinf(e1.value)) is divergent
    assert e1.singular_points.shape[0] == 0  # (no node is singular: found by det's sign)
    if not divergent:
        assert 10 < e1.value < 1e3
        assert e1.as_dict()["divergent"] is False


def test_e2_depends_on_the_orientation_of_k():
    """E2(-h) - E2(h) = 4 integral of dh K m: the sign of K (last component > 0) matters."""
    k, h = Manipulator1(), E2Optimal(0.0, 1.0)  # dh K = 1 everywhere
    neg = _Negated(h)
    diff = error_functional_e2(k, neg, REGION1).value - error_functional_e2(k, h, REGION1).value
    vol_m = integrate.quad(lambda t: np.sqrt(1 + t**2), 0, 1)[0]
    assert diff == pytest.approx(4.0 * vol_m, rel=1e-12)
    e1p = error_functional_e1(k, h, REGION1).value
    assert error_functional_e1(k, neg, REGION1).value == pytest.approx(e1p, rel=1e-12)


def test_fixed_variables_are_not_integrated():
    """Manipulator 2, h(x2, x3): the value is the 2-D integral, independent of the fixed x1."""
    k, h = Manipulator2(), PaperCubic()
    a = error_functional_e2(k, h, REGION2, nodes=20)
    b = error_functional_e2(k, h, REGION2, nodes=20, fixed={"x1": 0.7})
    c = error_functional_e2(k, h, {**REGION2, "x1": (0.0, 2.0)}, nodes=20)
    assert a.n_points == 400 and a.fixed == {"x1": 0.0}
    assert b.value == pytest.approx(a.value, rel=1e-13)
    assert c.value == pytest.approx(2.0 * a.value, rel=1e-12)
    assert error_functional_e2(k, h, REGION2, nodes=40).value == pytest.approx(a.value, rel=1e-10)


@pytest.mark.parametrize(
    "region, fixed, message",
    [
        ({"x4": (0, 1)}, None, "unknown joint variable 'x4'"),
        ({"x1": (1, 0)}, None, "must have lo < hi"),
        ({"x1": (0, 1)}, {"x1": 0.5}, "both integrated over and fixed"),
        ({}, None, "non-empty mapping"),
        ({"x1": (0, np.inf)}, None, "must be finite"),
    ],
)
def test_bad_regions_raise_typed_errors(region, fixed, message):
    with pytest.raises(InvalidInputError, match=message):
        error_functional_e2(Manipulator1(), E2Optimal(), region, fixed=fixed)


def test_parameter_sensitivity_matches_closed_form_derivative():
    """dE2/db of (36) at (a, b) = (0, 1) equals the derivative of the 1-D closed form."""
    out = parameter_sensitivity(
        Manipulator1(), E2Optimal, {"a": 0.0, "b": 1.0}, REGION1, span=0.5, samples=5
    )
    step = 1e-5
    exact = (_e2_closed(0.0, 1.0 + step) - _e2_closed(0.0, 1.0 - step)) / (2 * step)
    assert out["value"] == pytest.approx(_e2_closed(0.0, 1.0), rel=1e-10)
    assert out["gradient"]["b"] == pytest.approx(exact, rel=1e-6)
    sweep = out["sweeps"]["a"]
    assert len(sweep["values"]) == 5
    assert sweep["functional"][2] == pytest.approx(out["value"], rel=1e-12)
    # a = b = 0 cannot be built: reported as None, not an exception
    swept_b = parameter_sensitivity(
        Manipulator1(), E2Optimal, {"a": 0.0, "b": 0.5}, REGION1, span=0.5, samples=3
    )["sweeps"]["b"]["functional"]
    assert swept_b[0] is None and swept_b[1] is not None


def test_parameter_sensitivity_reports_each_evaluation():
    """1 + 2 (2 + samples) evaluations of E2 for (a, b): each reported, in order, the last at
    the total; a cancel stops the sweep before the next evaluation (RunCancelled)."""
    seen = []
    parameter_sensitivity(
        Manipulator1(),
        E2Optimal,
        {"a": 0.0, "b": 1.0},
        REGION1,
        span=0.5,
        samples=3,
        progress=ProgressCallbacks(on_advance=lambda done, total: seen.append((done, total))),
    )
    assert seen == [(k, 11) for k in range(1, 12)]
    seen.clear()
    stop = ProgressCallbacks(
        on_advance=lambda *d: seen.append(d), is_cancelled=lambda: len(seen) == 4
    )
    with pytest.raises(RunCancelled, match="the sweep of E2"):
        parameter_sensitivity(
            Manipulator1(), E2Optimal, {"a": 0.0, "b": 1.0}, REGION1, samples=3, progress=stop
        )
    assert len(seen) == 4
