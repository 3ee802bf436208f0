import numpy as np
import pytest

from jik.engine import augmentations as aug
from jik.engine.exceptions import InvalidInputError
from tests.helpers import central_difference

RNG = np.random.default_rng(38)
MAPS = [
    aug.E1Optimal(),
    aug.E1Optimal(C1=-0.7, C2=2.5),
    aug.E1Taylor(),
    aug.E2Optimal(),
    aug.E2Optimal(a=1.3, b=-0.4),
    aug.PaperCubic(),
    aug.Polynomial2({(0, 0): 1.0, (2, 3): -0.5, (1, 0): 2.0}, variables=(0, 2)),
]


@pytest.mark.parametrize("h", MAPS, ids=repr)
def test_gradient_matches_finite_differences(h):
    x = RNG.uniform(0, 1.5, (60, 3))  # x1 >= 0 keeps (32)'s cube root away from g = 0
    np.testing.assert_allclose(h.gradient(x), central_difference(h.value, x), atol=2e-8)


def test_paper_formulas():
    x = RNG.uniform(-1, 1, (10, 3))
    x1, x2, x3 = x.T
    s = np.sqrt(1 + x1**2)
    g = x1 * s + np.arcsinh(x1) + 2.0
    np.testing.assert_allclose(aug.E1Optimal(3.0, 2.0).value(x), x3 * 3 * s / np.cbrt(g))
    np.testing.assert_allclose(aug.E1Taylor().value(x), x3 * (1 - 2 * x1 / 3) * s)
    np.testing.assert_allclose(aug.E2Optimal(0.5, 2).value(x), x3 * (0.5 * x1 + 2) * s)
    X, Y = x2, x3
    cubic = (
        0.0006 * X**3
        - 0.2205 * Y**3
        + 0.3469 * X**2 * Y
        + 0.0009 * X * Y**2
        + 0.0005 * X**2
        + 0.0006 * Y**2
        - 0.7501 * X * Y
        - 0.0007 * X
        + 0.1381 * Y
        - 0.0005
    )
    np.testing.assert_allclose(aug.PaperCubic().value(x), cubic, atol=1e-15)


def test_printed_j32_j33_are_not_the_gradient_of_38():
    """The errata: (39)'s j32, j33 differ from d(38)/d(x2, x3)."""
    x = RNG.uniform(-1, 1, (10, 3))
    exact = aug.PaperCubic().gradient(x)
    printed = aug.PaperCubicPrintedGradient().gradient(x)
    assert np.max(np.abs(exact - printed)) > 0.1


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: aug.E1Optimal(C1=0), "C1 must be nonzero"),
        (lambda: aug.E2Optimal(a=0, b=0), "must not both be 0"),
        (lambda: aug.E2Optimal(a=np.nan), "a must be finite"),
        (lambda: aug.Polynomial2({(-1, 0): 1.0}), "exponents must be >= 0"),
    ],
)
def test_bad_parameters(make, match):
    with pytest.raises(InvalidInputError, match=match):
        make()


def test_h_change_is_each_components_own_range():
    """A vector h (p - r components) is conserved when each component is: components that sit
    at different constant values have changed by 0, not by their spread; the largest range of
    one component is the change; undefined points are skipped."""
    constant = np.tile([0.785, -0.785, 0.1, 2.0], (5, 1))
    assert aug.h_change(constant) == 0.0
    drifting = constant.copy()
    drifting[:, 2] += np.linspace(0.0, 0.25, 5)
    drifting[1, 0] = np.nan
    assert aug.h_change(drifting) == pytest.approx(0.25, abs=1e-15)
    assert aug.h_change(np.array([0.3, np.nan, 0.5])) == pytest.approx(0.2, abs=1e-15)
    assert aug.h_change(np.full((3, 2), np.nan)) is None
    assert aug.h_change(None) is None


def test_a_polynomial_map_names_its_coefficients_by_their_monomials():
    """The paper's cubic (38) in x2, x3: each c_ij keyed "x2^i x3^j"."""
    cubic = aug.PaperCubic()
    named = cubic.monomials()
    assert len(named) == len(cubic.coefficients)
    for (i, j), c in cubic.coefficients.items():
        assert named[f"x2^{i} x3^{j}"] == c
