"""Where an augmenting map is singular in a box: poles of h, |dh| blowing up, and rank losses
of the extended Jacobian [J; dh], eq. (10), found on one batch of a grid."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import brentq

import jik.engine as jik
from jik.engine.augmentations import E1Optimal, E2Optimal, PaperCubic
from jik.engine.exceptions import InvalidInputError
from jik.engine.formula_kinematics import FormulaMap
from jik.engine.functionals import error_functional_e1
from jik.engine.inverses import extended_determinant
from jik.engine.kinematics import Manipulator1, Manipulator2
from jik.engine.map_singularities import MapSingularities, map_singularities
from jik.engine.planar_chain import PlanarChain
from jik.engine.registry import MANIPULATOR1_REGION
from jik.engine.variational import MANIPULATOR2_REGION

POLE = "h jumps through infinity"
RANK = "the extended Jacobian (10) loses rank"
CHAIN = PlanarChain(joints="RRRR", lengths=[1.0] * 4)  # (p - r = 2)


@pytest.mark.parametrize("C2", [-0.5, -1.0, -2.0])
def test_e1_optimal_map_with_a_vanishing_g_is_singular_where_g_vanishes(C2):
    """(32) with C2 < 0: g(x1) = x1 sqrt(1 + x1^2) + asinh(x1) + C2 has a zero x1* in [0, 1],
    where h = x3 C1 sqrt(1 + x1^2) / g^(1/3) goes through infinity for every x2, x3: the grid
    points on either side of x1* (2 of 25 per line), with any x2 and x3."""
    x1 = brentq(lambda t: t * np.sqrt(1 + t * t) + np.arcsinh(t) + C2, 0.0, 1.0)
    found = map_singularities(Manipulator1(), E1Optimal(1.0, C2), MANIPULATOR1_REGION)
    assert isinstance(found, MapSingularities)
    lo, hi = found.where["x1"]
    assert lo < x1 < hi and hi - lo == pytest.approx(1 / 24)
    assert found.where["x2"] == (0.0, 1.0) and found.where["x3"] == (0.5, 1.5)
    assert found.fraction == pytest.approx(2 / 25)
    assert POLE in found.reasons and RANK not in found.reasons
    assert found.region == MANIPULATOR1_REGION and found.nodes == 25


def test_the_warning_names_the_map_its_parameters_the_region_and_where():
    found = map_singularities(Manipulator1(), E1Optimal(1.0, -1.0), MANIPULATOR1_REGION)
    said = found.warning("e1_optimal", {"C1": 1.0, "C2": -1.0})
    box = ", ".join(f"{k} ∈ [{lo:.3g}, {hi:.3g}]" for k, (lo, hi) in MANIPULATOR1_REGION.items())
    assert said.startswith(
        f"Warning: the augmenting map e1_optimal (C1 = 1, C2 = -1) is singular "
        f"in the design region {box}: {found}. E1 and E2 there are not"
    )
    assert "(C" not in found.warning("h", {})


def test_g_vanishing_on_a_face_makes_h_undefined_there():
    """C2 = 0: g(0) = 0, so h and dh are not finite on the face x1 = 0 (1 of 25 lines)."""
    found = map_singularities(Manipulator1(), E1Optimal(1.0, 0.0), MANIPULATOR1_REGION)
    assert found is not None and found.where["x1"] == (0.0, 0.0)
    assert found.reasons == ("h or its gradient is not finite",)
    assert found.fraction == pytest.approx(1 / 25)


@pytest.mark.parametrize("amap", [E1Optimal(1.0, 1.0), E2Optimal(0.0, 1.0), E2Optimal(0.5, 1.0)])
def test_a_regular_map_gives_none(amap):
    """dh K = C1 g^(-1/3) with g >= 1 on [0, 1] for C2 = 1 (32), dh K = a x1 + b > 0 for (36):
    regular on the design region."""
    assert map_singularities(Manipulator1(), amap, MANIPULATOR1_REGION) is None


def test_the_rank_test_at_a_constructed_point_and_between_grid_points():
    """Manipulator 1 with h = x3 + 2 x2: det [J; dh] = 1 - 2 x1, zero on the plane x1 = 0.5.
    With 25 nodes that plane holds grid points (1 of 25 lines, where the Hadamard ratio is 0);
    with 24 it lies between two (det changes sign: the points either side)."""
    k = Manipulator1()
    h = FormulaMap("x3 + 2*x2", k.variable_names)
    x = np.array([[0.5, 0.3, 1.0], [0.3, 0.3, 1.0]])
    det, singular = extended_determinant(k.jacobian(x), h.gradient(x))
    np.testing.assert_allclose(det, 1 - 2 * x[:, 0], atol=1e-15)
    assert singular.tolist() == [True, False]
    on = map_singularities(k, h, MANIPULATOR1_REGION, nodes=25)
    assert on is not None and on.reasons == (RANK,)
    assert on.where["x1"] == (0.5, 0.5) and on.fraction == pytest.approx(1 / 25)
    between = map_singularities(k, h, MANIPULATOR1_REGION, nodes=24)
    assert between is not None and between.reasons == (RANK,)
    assert between.where["x1"] == pytest.approx((11 / 23, 12 / 23))
    assert between.fraction == pytest.approx(2 / 24)
    off = map_singularities(k, h, {"x1": (0.0, 0.45), "x3": (0.5, 1.5)}, fixed={"x2": 0.3})
    assert off is None


def test_a_rank_loss_is_found_where_e1_diverges():
    """The paper's cubic (38) on Manipulator 2's design region: E1 diverges (det [J; dh]
    changes sign over the Gauss points), and the grid finds the rank loss, with where."""
    k, h = Manipulator2(), PaperCubic()
    assert error_functional_e1(k, h, MANIPULATOR2_REGION).divergent
    found = map_singularities(k, h, MANIPULATOR2_REGION)
    assert found is not None and found.reasons == (RANK,)
    lo, hi = found.where["x3"]
    assert 0.0 <= lo < hi < 1.0 and found.fixed == {"x1": 0.0}
    assert 0 < found.fraction < 0.1


def test_the_grid_is_evaluated_in_one_batch():
    """h and dh are asked once each, for the whole grid at once (nodes^d points), with the
    variables outside the box at their fixed values."""
    calls = []

    class Counted(E1Optimal):
        def value_masked(self, x):
            calls.append(("h", np.array(x)))
            return super().value_masked(x)

        def gradient_masked(self, x):
            calls.append(("dh", np.array(x)))
            return super().gradient_masked(x)

    region = {"x1": (0.0, 1.0), "x3": (0.5, 1.5)}
    map_singularities(Manipulator1(), Counted(1.0, -1.0), region, fixed={"x2": 0.7}, nodes=9)
    assert [name for name, _ in calls] == ["h", "dh"]
    for _, x in calls:
        assert x.shape == (81, 3) and np.all(x[:, 1] == 0.7)
        assert sorted(set(x[:, 0])) == pytest.approx(np.linspace(0.0, 1.0, 9))


def test_result_prints_on_one_line_says_where_in_words_and_exports_json():
    found = jik.map_singularities(jik.Manipulator1(), jik.E1Optimal(1.0, -1.0), MANIPULATOR1_REGION)
    text = repr(found)
    assert "\n" not in text and len(text) < 260
    assert text.startswith("MapSingularities(8.00% of a 25^3 grid, x1 in [0.4583, 0.5], x2 in [0")
    assert str(found) == (
        "the gradient of h blows up; h jumps through infinity at x1 ∈ [0.458, 0.5], any x2, "
        "any x3 (1250 of the 25^3 grid points)"
    )
    assert str(map_singularities(Manipulator1(), E1Optimal(1.0, 0.0), MANIPULATOR1_REGION)) == (
        "h or its gradient is not finite at x1 ≈ 0, any x2, any x3 (625 of the 25^3 grid points)"
    )
    d = json.loads(json.dumps(found.as_dict()))
    assert d["where"]["x1"] == pytest.approx([11 / 24, 0.5]) and d["fraction"] == pytest.approx(
        0.08
    )
    assert d["reasons"] == list(found.reasons) and d["nodes"] == 25
    assert d["region"]["x3"] == [0.5, 1.5] and d["fixed"] == {}


@pytest.mark.parametrize(
    ("call", "field", "words"),
    [
        (lambda: map_singularities(Manipulator1(), E2Optimal(), {"y": (0, 1)}), "region", "y"),
        (
            lambda: map_singularities(Manipulator1(), E2Optimal(), MANIPULATOR1_REGION, nodes=60),
            "nodes",
            "60^3",
        ),
        (
            lambda: map_singularities(Manipulator1(), E2Optimal(), {"x1": (0, 1)}, nodes=1),
            "nodes",
            "nodes",
        ),
        (lambda: map_singularities(CHAIN, E2Optimal(), {"x1": (0, 1)}), "kinematics", "p - r"),
        (lambda: map_singularities(Manipulator1(), "h", {"x1": (0, 1)}), "augmenting_map", "str"),
        (lambda: map_singularities("m1", E2Optimal(), {"x1": (0, 1)}), "kinematics", "m1"),
    ],
)
def test_bad_input_is_refused_naming_its_field(call, field, words):
    with pytest.raises(InvalidInputError) as err:
        call()
    assert err.value.field == field and words in str(err.value)


@pytest.mark.parametrize("nodes", [8, 12, 24])
def test_a_pole_between_grid_points_is_found_on_a_coarse_grid_too(nodes):
    """h = 1 / (x2 - 0.5) never sits on a grid point here: between the two points beside
    x2 = 0.5 it changes sign against its slope (dh/dx2 < 0 at both), which a smooth zero never
    does; the step there is only about 14 times the median at 8 nodes."""
    chain = jik.PlanarChain("RRR", [1.0, 0.8, 0.6])
    found = map_singularities(
        chain,
        jik.FormulaMap("1/(x2 - 0.5)", ["x1", "x2", "x3"]),
        {"x1": (0, 1), "x2": (0.2, 1)},
        nodes=nodes,
    )
    assert found is not None and "h jumps through infinity" in found.reasons
    lo, hi = found.where["x2"]
    assert lo < 0.5 < hi and hi - lo <= 0.8 / (nodes - 1) + 1e-12
    assert found.where["x1"] == (0.0, 1.0)
