"""Planar serial chains: analytic Jacobian, the 3R arm's repeatability and its E2 synthesis."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from jik.engine.augmentations import Polynomial2
from jik.engine.characteristics import CharacteristicsMap
from jik.engine.exceptions import InvalidInputError
from jik.engine.functionals import error_functional_e2
from jik.engine.inverses import ExtendedInverse, Pseudoinverse, pseudoinverse
from jik.engine.planar_chain import PlanarChain
from jik.engine.repeatability import repeatability
from jik.engine.variational import synthesize_e2
from tests.helpers import central_difference

RNG = np.random.default_rng(29)
ARM = PlanarChain("RRR", [1.0, 0.8, 0.6])
X0 = np.array([0.3, 1.0, 1.0])
#: A closed path around k(X0) = (0.770, 1.514); the return leg to k(X0) closes it.
PATH = np.array([[1.0, 1.3], [1.0, 1.7], [0.6, 1.7]])
REGION = {"x2": (0.4, 2.0), "x3": (0.4, 2.0)}

CHAINS = [
    ARM,
    PlanarChain("RRR", [1.0, 0.8, 0.6], offsets=[0.1, -0.4, 0.3], orientation=True),
    PlanarChain("RPRP", [1.0, 0.5, 0.7, 0.2], offsets=[0.2, 0.3, -0.1, 0.4], orientation=True),
    PlanarChain("prr", [0.5, 1.0, 0.4]),
    PlanarChain("RRRRR", [0.4, 0.4, 0.4, 0.4, 0.4]),
]


@pytest.mark.parametrize("kin", CHAINS, ids=lambda k: k.joints + ("+o" if k.orientation else ""))
def test_jacobian_matches_finite_differences(kin):
    x = RNG.uniform(-2, 2, (40, kin.p))
    np.testing.assert_allclose(kin.jacobian(x), central_difference(kin.forward, x), atol=1e-8)
    assert kin.jacobian(x[0]).shape == (kin.r, kin.p)


@pytest.mark.parametrize("kin", CHAINS, ids=lambda k: k.joints + ("+o" if k.orientation else ""))
def test_hessian_matches_finite_differences_of_the_jacobian(kin):
    x = RNG.uniform(-2, 2, (20, kin.p))
    H = kin.hessian(x)
    assert H.shape == (20, kin.r, kin.p, kin.p)
    np.testing.assert_allclose(H, central_difference(kin.jacobian, x), atol=1e-8)


def test_the_3r_arm_by_hand():
    """k of the 3R arm is the sum of its links' vectors; the orientation is x1 + x2 + x3."""
    x = RNG.uniform(-3, 3, (10, 3))
    c = np.cumsum(x, axis=-1)
    y = np.stack([np.cos(c), np.sin(c)], -1) * np.array([1.0, 0.8, 0.6])[:, None]
    np.testing.assert_allclose(ARM.forward(x), y.sum(axis=1), atol=1e-14)
    turned = PlanarChain("RRR", [1.0, 0.8, 0.6], orientation=True)
    np.testing.assert_allclose(turned.forward(x)[:, 2], c[:, 2], atol=1e-14)


def test_prismatic_joint_stretches_its_link():
    """PR with offsets: a_1 = l_1 + x_1 + o_1 along the base x axis, then an arm at angle x_2."""
    kin = PlanarChain("PR", [1.0, 0.5], offsets=[0.25, 0.0])
    np.testing.assert_allclose(kin.forward([0.5, np.pi / 2]), [1.75, 0.5], atol=1e-15)


def test_points_start_at_the_base_and_end_at_k():
    x = RNG.uniform(-2, 2, (7, 4))
    kin = CHAINS[2]
    pts = kin.points(x)
    assert pts.shape == (7, 5, 2)
    np.testing.assert_allclose(pts[:, 0], 0.0)
    np.testing.assert_allclose(pts[:, -1], kin.forward(x)[:, :2], atol=1e-15)


def _ivp_legs(kin, x, targets):
    """Leg ends of eq. (7) with the pseudoinverse, integrated by scipy alone (tight tolerances,
    to theta = 40 where the task error has decayed by e^-40)."""
    out = []
    for y_d in targets:

        def f(t, x, y_d=y_d):
            return -(pseudoinverse(kin.jacobian(x)) @ (kin.forward(x) - y_d))

        x = solve_ivp(f, (0, 40), x, method="DOP853", rtol=1e-13, atol=1e-14).y[:, -1]
        out.append(x)
    return np.array(out)


def test_3r_pseudoinverse_leg_ends_match_an_independent_solve_ivp():
    """Two cycles of a closed path: the pseudoinverse drifts, and jik's legs are scipy's."""
    rep = repeatability(Pseudoinverse(ARM), X0, PATH, cycles=2)
    assert rep.success
    reference = _ivp_legs(ARM, X0, [*rep.targets, *rep.targets])
    np.testing.assert_allclose(rep.legs, reference, atol=1e-8, rtol=0)
    assert rep.drift[0] > 1e-3  # the pseudoinverse is not repeatable


@pytest.fixture(scope="module")
def synthesis():
    return synthesize_e2(ARM, REGION, degree=12)


def test_3r_synthesized_map_beats_h_equal_x3(synthesis):
    """E2 (19) of the Ritz map is below that of h = x3 on the same box (both by quadrature)."""
    x3 = Polynomial2({(0, 1): 1.0}, variables=(1, 2), p=3)
    e2_x3 = error_functional_e2(ARM, x3, REGION, nodes=32).value
    e2_synth = error_functional_e2(ARM, synthesis.augmenting_map, REGION, nodes=32).value
    assert e2_synth == pytest.approx(synthesis.e2, rel=1e-9)
    assert e2_synth < 0.2 * e2_x3


def test_3r_extended_inverse_of_the_synthesized_map_is_repeatable(synthesis):
    rep = repeatability(ExtendedInverse(ARM, synthesis.augmenting_map), X0, PATH, cycles=5)
    assert rep.success
    assert np.max(rep.drift) < 1e-9
    pinv = repeatability(Pseudoinverse(ARM), X0, PATH, cycles=1)
    assert np.max(np.linalg.norm(rep.legs[:4] - pinv.legs, axis=1)) < 0.1


@pytest.mark.parametrize(
    ("kwargs", "field", "text"),
    [
        ({"joints": "RXR", "lengths": [1, 1, 1]}, "joints", "'X' at position 1"),
        ({"joints": "", "lengths": []}, "joints", "string of R and P"),
        ({"joints": "RRR", "lengths": [1, 1]}, "lengths", "one entry per joint (3)"),
        ({"joints": "RRR", "lengths": [1, "a", 1]}, "lengths.1", "lengths[1] must be a number"),
        ({"joints": "RRR", "lengths": [1, True, 1]}, "lengths.1", "lengths[1] must be a number"),
        ({"joints": "RR", "lengths": [1, 1], "offsets": [0, np.inf]}, "offsets.1", "finite"),
        ({"joints": "RR", "lengths": [1, 1], "orientation": True}, "joints", "at least 3 joints"),
        ({"joints": "RR", "lengths": "11"}, "lengths", "a list of 2 numbers"),
        ({"joints": "RRR", "lengths": [1, -0.5, 1]}, "lengths.1", "lengths[1] must be positive"),
        ({"joints": "RP", "lengths": [1, 0]}, "lengths.1", "positive (a link's length), got 0"),
    ],
)
def test_bad_definitions_name_the_field(kwargs, field, text):
    with pytest.raises(InvalidInputError) as err:
        PlanarChain(**kwargs)
    assert err.value.field == field
    assert text in str(err.value)


def test_characteristics_map_of_the_3r_arm_is_repeatable():
    """The map by characteristics (section 4), which needs the Hessian, on the 3R arm."""
    h = CharacteristicsMap(ARM, reference=X0, fixed_index=0)
    x = X0 + RNG.uniform(-0.2, 0.2, (5, 3))
    np.testing.assert_allclose(h.gradient(x), central_difference(h.value, x, 1e-5), atol=1e-8)
    rep = repeatability(ExtendedInverse(ARM, h), X0, PATH, cycles=2)
    assert rep.success and np.max(rep.drift) < 1e-9
