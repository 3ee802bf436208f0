"""The augmenting map h of a Ritz synthesis: a tensor Legendre polynomial on a box, eq. (9).

The basis of :func:`jik.engine.variational.synthesize_e2`: Legendre values and derivatives at
points of [-1, 1], the Gauss-Lobatto-Legendre nodes, and the map with its exact gradient.
"""

from __future__ import annotations

import string
from collections.abc import Mapping, Sequence

import numpy as np
from numpy.polynomial import legendre as L

from .augmentations import AugmentingMap
from .exceptions import InvalidInputError
from .validation import FloatArray


def _derivative_matrix(n: int) -> FloatArray:
    """D (n+1, n+1) with P_i'(t) = sum_k D[k, i] P_k(t) for Legendre P_0..P_n."""
    D = np.zeros((n + 1, n + 1))
    if n:
        D[:n, :] = L.legder(np.eye(n + 1), axis=0)
    return D


def legendre_vander(t: FloatArray, n: int) -> tuple[FloatArray, FloatArray]:
    """Legendre values and derivatives, each (..., n + 1), at reference points t."""
    t = np.asarray(t, dtype=float)
    V = L.legvander(t, n).reshape(*t.shape, n + 1)
    return V, V @ _derivative_matrix(n)


def lgl_nodes(n: int) -> FloatArray:
    """Gauss-Lobatto-Legendre nodes of degree n: -1, roots of P_n', 1."""
    if n == 1:
        return np.array([-1.0, 1.0])
    inner = L.legroots(L.legder(np.eye(n + 1)[n]))
    return np.concatenate([[-1.0], np.sort(inner.real), [1.0]])


class SynthesizedMap(AugmentingMap):
    """h(x) = sum c_ij.. P_i(t_a) P_j(t_b) .., a tensor Legendre polynomial on a box, eq. (9).

    Parameters
    ----------
    coefficients : ndarray, shape (n_1 + 1, ..., n_d + 1)
        Legendre coefficients; axis k belongs to the k-th variable of ``region``.
    region : dict name -> (lo, hi)
        The box; t = (2 x - lo - hi) / (hi - lo) maps it onto [-1, 1]^d.
    variables : tuple of int
        0-based indices of the region's variables in x.
    p : int
        Configuration-space dimension.

    Notes
    -----
    A polynomial, so value and gradient are continuous everywhere (outside the box it is the
    polynomial continuation). Batched over leading axes of x.
    """

    name = "e2_synthesized"

    def __init__(
        self,
        coefficients: FloatArray,
        region: Mapping[str, tuple[float, float]],
        variables: Sequence[int],
        p: int,
    ) -> None:
        self.coefficients = np.asarray(coefficients, dtype=float)
        self.region = {k: (float(a), float(b)) for k, a, b in ((k, *v) for k, v in region.items())}
        self.variables = tuple(int(v) for v in variables)
        self.p = int(p)
        if self.coefficients.ndim != len(self.variables) or len(self.region) != len(self.variables):
            raise InvalidInputError("coefficients, region and variables must have one axis each")
        lo = np.array([v[0] for v in self.region.values()])
        hi = np.array([v[1] for v in self.region.values()])
        self._center, self._scale = 0.5 * (lo + hi), 2.0 / (hi - lo)  # t = (x - c) * scale
        d = len(self.variables)
        letters = string.ascii_lowercase[:d]
        self._contract = ",".join(f"...{c}" for c in letters) + f",{letters}->..."

    @property
    def parameters(self) -> dict[str, float]:
        """The basis degree per variable (integers)."""
        shape = self.coefficients.shape
        return {f"degree_{k}": int(n - 1) for k, n in zip(self.region, shape, strict=True)}

    def _bases(self, x: FloatArray) -> list[tuple[FloatArray, FloatArray]]:
        x = np.asarray(x, dtype=float)
        return [
            legendre_vander((x[..., v] - self._center[k]) * self._scale[k], n - 1)
            for k, (v, n) in enumerate(zip(self.variables, self.coefficients.shape, strict=True))
        ]

    def value(self, x: FloatArray) -> FloatArray:
        bases = self._bases(x)
        return np.einsum(self._contract, *(V for V, _ in bases), self.coefficients)

    def gradient(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        bases = self._bases(x)
        g = np.zeros(x.shape)
        for k, v in enumerate(self.variables):
            mats = [dV if i == k else V for i, (V, dV) in enumerate(bases)]
            g[..., v] = np.einsum(self._contract, *mats, self.coefficients) * self._scale[k]
        return g
