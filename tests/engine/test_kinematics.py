import numpy as np
import pytest

from jik.engine.exceptions import InvalidInputError, KinematicSingularityError
from jik.engine.kinematics import Kinematics, Manipulator1, Manipulator2
from tests.helpers import central_difference

RNG = np.random.default_rng(20091204)
ROBOTS = [Manipulator1(), Manipulator2(), Manipulator2(l=0.37), Manipulator2(l=2.5)]


@pytest.mark.parametrize("kin", ROBOTS, ids=lambda k: f"{k.name}{k.parameters}")
def test_jacobian_matches_finite_differences(kin):
    x = RNG.uniform(-2, 2, (50, 3))
    np.testing.assert_allclose(kin.jacobian(x), central_difference(kin.forward, x), atol=1e-8)


@pytest.mark.parametrize("kin", ROBOTS, ids=lambda k: f"{k.name}{k.parameters}")
def test_kernel_is_unit_null_vector_with_positive_last_component(kin):
    x = RNG.uniform(-2, 2, (50, 3))
    K = kin.kernel(x)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", kin.jacobian(x), K), 0, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(K, axis=-1), 1, atol=1e-14)
    assert np.all(K[:, -1] > 0)


def test_kernels_match_the_paper():
    x = RNG.uniform(-2, 2, (20, 3))
    x1, x3 = x[:, 0], x[:, 2]
    K1 = np.stack([0 * x1, -x1, np.ones_like(x1)], -1) / np.sqrt(1 + x1**2)[:, None]
    np.testing.assert_allclose(Manipulator1().kernel(x), K1, atol=1e-15)
    l = 1.7
    K2 = np.stack([-l * np.cos(x3), l * np.sin(x3), np.ones_like(x3)], -1) / np.sqrt(1 + l**2)
    np.testing.assert_allclose(Manipulator2(l).kernel(x), K2, atol=1e-15)


@pytest.mark.parametrize("kin", ROBOTS, ids=lambda k: f"{k.name}{k.parameters}")
def test_closed_form_manipulability_equals_sqrt_det_JJt(kin):
    x = RNG.uniform(-2, 2, (50, 3))
    np.testing.assert_allclose(kin.manipulability(x), Kinematics.manipulability(kin, x), rtol=1e-13)


def test_batched_shapes():
    x = RNG.uniform(-1, 1, (4, 5, 3))
    kin = Manipulator2()
    assert kin.forward(x).shape == (4, 5, 2)
    assert kin.jacobian(x).shape == (4, 5, 2, 3)
    assert kin.kernel(x).shape == (4, 5, 3)
    assert kin.manipulability(x).shape == (4, 5)


@pytest.mark.parametrize(
    ("bad", "match"),
    [
        ([0.0, 1.0], r"shape \(\.\.\., 3\)"),
        ([0, np.nan, 1], "NaN"),
        ([0, np.inf, 1], "NaN or inf"),
        ("abc", "numeric"),
    ],
)
def test_check_rejects_bad_configurations(bad, match):
    with pytest.raises(InvalidInputError, match=match):
        Manipulator2().check(bad, "x0")


@pytest.mark.parametrize("l", [0, -1, np.nan])
def test_arm_length_must_be_positive(l):
    with pytest.raises(InvalidInputError, match="arm length"):
        Manipulator2(l=l)


def test_singular_jacobian_is_reported_with_configuration():
    class Fold(Kinematics):
        """k(x) = (x1^2, x2): J loses rank at x1 = 0 (for the check only)."""

        name = "fold"
        p, r = 3, 2

        def forward(self, x):
            return np.stack([x[..., 0] ** 2, x[..., 1]], axis=-1)

        def jacobian(self, x):
            J = np.zeros((*x.shape[:-1], 2, 3))
            J[..., 0, 0] = 2 * x[..., 0]
            J[..., 1, 1] = 1.0
            return J

    kin = Fold()
    assert kin.is_singular(np.array([0.0, 1.0, 2.0]))
    with pytest.raises(KinematicSingularityError, match=r"x = \(0, 1, 2\)"):
        kin.require_regular(np.array([[1.0, 1.0, 2.0], [0.0, 1.0, 2.0]]))


@pytest.mark.parametrize("kin", ROBOTS, ids=lambda k: f"{k.name}{k.parameters}")
def test_every_robot_gives_k_and_j_together(kin):
    """``forward_jacobian`` of a robot without its own one-pass evaluation is k(x) and J(x),
    with the check of x."""
    x = RNG.uniform(-2, 2, (5, 3))
    k, J = kin.forward_jacobian(x)
    np.testing.assert_array_equal(k, kin.forward(x))
    np.testing.assert_array_equal(J, kin.jacobian(x))
    with pytest.raises(InvalidInputError):
        kin.forward_jacobian(np.full(3, np.nan))
