"""A total-degree Legendre basis on a box and the augmenting map it spans, eq. (9).

The basis {phi_a : 1 <= |a| <= n} of products of normalised Legendre polynomials
sqrt(2 a_k + 1) P_(a_k)(t_k) has C(n + d, d) - 1 members: polynomial in the number of variables d
for a fixed total degree n, where a tensor basis has (n + 1)^d. Its order is graded (lower degrees
first), so the basis of a lower degree is a leading block. :mod:`jik.engine.synthesis_nd` fits
E2-optimal maps in it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from itertools import combinations_with_replacement

import numpy as np
from numpy.polynomial import legendre as L

from .augmentations import AugmentingMap
from .validation import FloatArray


def total_degree_indices(d: int, n: int) -> np.ndarray:
    """Multi-indices a (nb, d) with 1 <= |a| <= n, graded: all of degree k before degree k + 1.

    The graded order makes the basis hierarchical: the first ``basis_size(d, k)`` rows are the
    basis of total degree k, so a lower degree's Ritz system is a leading principal submatrix.
    """
    rows = []
    for k in range(1, n + 1):
        for combo in combinations_with_replacement(range(d), k):
            a = np.zeros(d, dtype=int)
            np.add.at(a, list(combo), 1)
            rows.append(a)
    return np.array(rows, dtype=int).reshape(-1, d)


def basis_size(d: int, n: int) -> int:
    """Number of non-constant polynomials of total degree <= n in d variables."""
    return math.comb(n + d, d) - 1


def _legendre(t: FloatArray, n: int) -> tuple[FloatArray, FloatArray]:
    """Normalised Legendre values sqrt(2i + 1) P_i(t) and derivatives, each (N, n + 1)."""
    V = L.legvander(t, n)
    D = np.zeros((n + 1, n + 1))
    if n:
        D[:n, :] = L.legder(np.eye(n + 1), axis=0)
    s = np.sqrt(2.0 * np.arange(n + 1) + 1.0)
    return V * s, (V @ D) * s


def sobol_nodes(d: int, nodes: int, seed) -> FloatArray:
    """``nodes`` points of a scrambled Sobol rule on [-1, 1]^d, where the basis lives: the
    quadrature of E2 (18) by :mod:`jik.engine.synthesis_nd` and :mod:`jik.engine.e2_qmc`."""
    from scipy.stats import qmc  # (on use: slow to import, and every compute worker imports this)

    return 2.0 * qmc.Sobol(d, scramble=True, seed=seed).random(nodes) - 1.0


def basis_gradients(t: FloatArray, index: np.ndarray) -> tuple[FloatArray, FloatArray]:
    """Basis values (N, nb) and gradients with respect to t (N, nb, d) at reference points t."""
    N, d = t.shape
    n = int(index.max(initial=0))
    vals, ders = zip(*(_legendre(t[:, k], n) for k in range(d)), strict=True)
    factors = [vals[k][:, index[:, k]] for k in range(d)]  # each (N, nb)
    # Products of all factors but one, by prefix and suffix products (no division by zeros).
    prefix = [np.ones((N, index.shape[0]))]
    for k in range(d - 1):
        prefix.append(prefix[-1] * factors[k])
    suffix = np.ones((N, index.shape[0]))
    grad = np.empty((N, index.shape[0], d))
    for k in reversed(range(d)):
        grad[:, :, k] = prefix[k] * suffix * ders[k][:, index[:, k]]
        suffix = suffix * factors[k]
    return suffix, grad


class TotalDegreeMap(AugmentingMap):
    """h(x) = sum_a c_a phi_a(t), a total-degree Legendre polynomial on a box, eq. (9).

    Parameters
    ----------
    index : ndarray of int, shape (nb, d)
        Multi-indices of the basis (:func:`total_degree_indices`).
    coefficients : ndarray, shape (nb,)
    region : dict name -> (lo, hi)
        The box; t = (2 x - lo - hi) / (hi - lo) maps it onto [-1, 1]^d.
    variables : tuple of int
        0-based indices of the region's variables in x.
    p : int
    """

    name = "e2_total_degree"

    def __init__(
        self,
        index,
        coefficients,
        region: Mapping[str, tuple[float, float]],
        variables: Sequence[int],
        p: int,
    ) -> None:
        self.index = np.asarray(index, dtype=int)
        self.coefficients = np.asarray(coefficients, dtype=float)
        self.region = {k: (float(a), float(b)) for k, (a, b) in region.items()}
        self.variables = tuple(int(v) for v in variables)
        self.p = int(p)
        lo = np.array([v[0] for v in self.region.values()])
        hi = np.array([v[1] for v in self.region.values()])
        self._center, self._scale = 0.5 * (lo + hi), 2.0 / (hi - lo)

    @property
    def parameters(self) -> dict[str, float]:
        """The total degree and the number of basis polynomials (integers)."""
        return {"degree": int(self.index.sum(axis=1).max()), "unknowns": len(self.index)}

    def _eval(self, x: FloatArray) -> tuple[FloatArray, FloatArray, tuple[int, ...]]:
        x = np.asarray(x, dtype=float)
        flat = x.reshape(-1, x.shape[-1])
        t = (flat[:, self.variables] - self._center) * self._scale
        phi, grad = basis_gradients(t, self.index)
        return phi @ self.coefficients, np.einsum("nbk,b->nk", grad, self.coefficients), x.shape

    def value(self, x: FloatArray) -> FloatArray:
        h, _, shape = self._eval(x)
        return h.reshape(shape[:-1])

    def gradient(self, x: FloatArray) -> FloatArray:
        _, gt, shape = self._eval(x)
        g = np.zeros((gt.shape[0], shape[-1]))
        g[:, self.variables] = gt * self._scale
        return g.reshape(shape)
