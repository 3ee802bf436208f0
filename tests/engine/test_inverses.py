import numpy as np
import pytest

from jik.engine.augmentations import E1Optimal, E2Optimal, PaperCubic
from jik.engine.exceptions import AlgorithmicSingularityError, InvalidInputError
from jik.engine.inverses import ExtendedInverse, Pseudoinverse, extended_inverse, pseudoinverse
from jik.engine.kinematics import Manipulator1, Manipulator2

RNG = np.random.default_rng(12)
CASES = [
    (Manipulator1(), E2Optimal()),
    (Manipulator1(), E1Optimal()),
    (Manipulator2(), PaperCubic()),
    (Manipulator2(l=0.5), PaperCubic()),
]


def points(n=40):
    x = RNG.uniform(0, 1, (n, 3))
    x[:, 2] += 0.5
    return x


@pytest.mark.parametrize(("kin", "h"), CASES, ids=lambda c: getattr(c, "name", ""))
def test_eq12_right_inverse_annihilated_by_dh(kin, h):
    """(12): J J^E# = I_r and dh J^E# = 0."""
    x = points()
    JE = ExtendedInverse(kin, h).matrix(x)
    J = kin.jacobian(x)
    np.testing.assert_allclose(J @ JE, np.broadcast_to(np.eye(2), (len(x), 2, 2)), atol=1e-12)
    np.testing.assert_allclose(np.einsum("ni,nij->nj", h.gradient(x), JE), 0, atol=1e-12)


@pytest.mark.parametrize("kin", [Manipulator1(), Manipulator2(), Manipulator2(l=3)])
def test_pseudoinverse_is_the_minimum_norm_right_inverse(kin):
    x = points()
    JP = Pseudoinverse(kin).matrix(x)
    J = kin.jacobian(x)
    np.testing.assert_allclose(J @ JP, np.broadcast_to(np.eye(2), (len(x), 2, 2)), atol=1e-12)
    np.testing.assert_allclose(JP, np.linalg.pinv(J), atol=1e-12)
    # Any other right inverse J# + K w^T gives a larger norm of J# e: J^P# e is orthogonal to K.
    e = RNG.normal(size=(len(x), 2))
    vp = np.einsum("nij,nj->ni", JP, e)
    np.testing.assert_allclose(np.einsum("ni,ni->n", vp, kin.kernel(x)), 0, atol=1e-12)
    JE = ExtendedInverse(kin, E2Optimal(0.3, 1.0)).matrix(x)
    ve = np.einsum("nij,nj->ni", JE, e)
    assert np.all(np.linalg.norm(vp, axis=-1) <= np.linalg.norm(ve, axis=-1) + 1e-12)


def test_apply_equals_matrix_times_vector():
    kin, h = Manipulator2(), PaperCubic()
    x, e = points(), RNG.normal(size=(40, 2))
    for inv in (Pseudoinverse(kin), ExtendedInverse(kin, h)):
        np.testing.assert_allclose(
            inv.apply(x, e), np.einsum("nij,nj->ni", inv.matrix(x), e), atol=1e-12
        )


def test_pure_functions_mark_singular_members_nan():
    J = np.array([[[1.0, 0, 0], [0, 1, 0]], [[1.0, 0, 0], [2.0, 0, 0]]])
    P = pseudoinverse(J)
    assert np.all(np.isfinite(P[0])) and np.all(np.isnan(P[1]))
    E = extended_inverse(J[:1], np.array([[1.0, 0, 0]]))
    assert np.all(np.isnan(E))


def test_algorithmic_singularity_names_the_configuration():
    """(36) with a = 1, b = 0: dh K = (a x1 + b) = 0 at x1 = 0, so [J; dh] is singular there."""
    inv = ExtendedInverse(Manipulator1(), E2Optimal(a=1.0, b=0.0))
    with pytest.raises(AlgorithmicSingularityError, match=r"at x = \(0, 0.5, 1\)"):
        inv.apply(np.array([[0.3, 0.5, 1.0], [0.0, 0.5, 1.0]]), np.ones((2, 2)))


def test_dimension_mismatch_is_rejected():
    from jik.engine.augmentations import Polynomial2

    with pytest.raises(InvalidInputError, match="R\\^4"):
        ExtendedInverse(Manipulator2(), Polynomial2({(1, 0): 1.0}, variables=(0, 3), p=4))
