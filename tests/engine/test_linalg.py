"""The small batched solves of the hot path against numpy.linalg."""

from __future__ import annotations

import numpy as np
import pytest

from jik.engine.linalg import cofactor_rows, det_small, gram, solve_small


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
