"""The small batched solves of the hot path against numpy.linalg."""

from __future__ import annotations

import numpy as np
import pytest

import jik.engine as jik
from jik.engine.linalg import (
    cofactor_rows,
    det_small,
    gram,
    min_norm_matrix,
    min_norm_solve,
    solve_small,
)


@pytest.mark.parametrize("n", [2, 3, 4])
def test_solve_small_and_det_against_numpy(n):
    rng = np.random.default_rng(n)
    A = rng.normal(size=(500, n, n))
    b = rng.normal(size=(500, n))
    z, d = solve_small(A, b)
    np.testing.assert_allclose(d, np.linalg.det(A), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(det_small(A), np.linalg.det(A), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(A @ z[..., None], b[..., None], atol=1e-9 * (1 + np.abs(z).max()))


def test_singular_members_are_flagged_not_raised():
    A = np.array([[[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 1.0, 1.0]], np.eye(3)])
    z, d = solve_small(A, np.ones((2, 3)))
    assert d[0] == 0 and not np.all(np.isfinite(z[0]))
    np.testing.assert_array_equal(z[1], np.ones(3))


def test_cofactor_rows_are_cross_products_and_gram_is_j_jt():
    rng = np.random.default_rng(7)
    A = rng.normal(size=(50, 3, 3))
    C = cofactor_rows(A)
    for i in range(3):
        np.testing.assert_array_equal(C[:, i], np.cross(A[:, (i + 1) % 3], A[:, (i + 2) % 3]))
    np.testing.assert_allclose(
        np.swapaxes(C, -1, -2) @ A, np.linalg.det(A)[:, None, None] * np.eye(3), atol=1e-12
    )
    J = rng.normal(size=(50, 2, 3))
    np.testing.assert_allclose(gram(J), J @ np.swapaxes(J, -1, -2), rtol=1e-14)


@pytest.mark.parametrize(("r", "p"), [(2, 3), (3, 4), (6, 7)])
def test_min_norm_solve_is_the_pseudoinverse_step_and_det_j_jt(r, p):
    rng = np.random.default_rng(r)
    J = rng.normal(size=(4, 5, r, p))
    e = rng.normal(size=(4, 5, r))
    v, d = min_norm_solve(J, e)
    np.testing.assert_allclose(v, np.einsum("...ij,...j->...i", np.linalg.pinv(J), e), atol=1e-11)
    np.testing.assert_allclose(d, np.linalg.det(J @ np.swapaxes(J, -1, -2)), rtol=1e-12)
    P, dP = min_norm_matrix(J)
    np.testing.assert_allclose(P, np.linalg.pinv(J), atol=1e-11)
    np.testing.assert_array_equal(dP, d)
    v1, d1 = min_norm_solve(J[1, 2], e[1, 2])
    np.testing.assert_allclose(v1, v[1, 2], atol=1e-14)
    assert np.isclose(d1, d[1, 2], rtol=1e-14)
    for rows in ([[1.0, 2.0, 3.0], [2.0, 4.0, 6.0]], [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]]):
        assert min_norm_solve(np.array(rows), np.ones(2))[1] == 0


def _exact_step(J, e):
    """J^T (J J^T)^-1 e and m = sqrt(det J J^T) of the float J, to 40 digits."""
    import mpmath as mp

    with mp.workdps(40):
        Jm = mp.matrix(J.tolist())
        M = Jm * Jm.T
        step = Jm.T * mp.inverse(M) * mp.matrix(e.tolist())
        return np.array([float(c) for c in step]), float(mp.sqrt(mp.det(M)))


def test_pseudoinverse_step_and_manipulability_near_a_stretched_singularity_are_accurate():
    """3R chain at (0.2, d, d): kappa(J) ~ 1e8 at d = 1e-8. Cramer's rule on J J^T was 1 %
    wrong at d = 1e-7 and m(x) was 0 at d = 1e-8 (true 4.4e-8), so is_singular said singular
    where the inverse stepped on."""
    kin = jik.PlanarChain("RRR", [1, 1, 1])
    inverse = jik.Pseudoinverse(kin)
    e = np.array([0.3, -0.7])
    for d in (1e-6, 1e-7, 1e-8):
        x = np.array([0.2, d, d])
        step, m = _exact_step(kin.jacobian(x), e)
        v = inverse.apply(x, e)
        assert np.abs(v - step).max() <= 1e-7 * np.abs(step).max()
        assert abs(kin.manipulability(x) - m) <= 1e-15
        assert not kin.is_singular(x)
