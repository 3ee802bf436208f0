"""Augmenting maps h: R^p -> R for one degree of redundancy, eq. (9), with exact gradients.

The paper's analytic maps: Manipulator 1, (32) ``e1_optimal``, (33) ``e1_taylor``, (36)
``e2_optimal``; Manipulator 2, (38) ``paper_cubic`` as printed. A map is evaluated batched:
``value`` (..., p) -> (...,), ``gradient`` (..., p) -> (..., p); each checks that its ``x`` has
p columns, at the base class (:class:`AugmentingMap`).
"""

from __future__ import annotations

import abc
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from .exceptions import InvalidInputError
from .validation import FloatArray, as_numbers, as_points, checked_points, finite

#: h counts as conserved along a run when it changed by less than this (:func:`h_change`).
H_CONSERVED = 1e-6
#: The evaluations of a map, each of which checks its ``x`` (:meth:`AugmentingMap.check`).
CHECKED = ("value", "gradient", "value_masked", "gradient_masked")


def h_change(h) -> float | None:
    """How much h varied along a run: max - min over the finite values of each component of h
    (``h`` of shape (m,) or (m, p - r), one row per point), the largest of those; None without
    h or without a finite value (h undefined from the start).

    Notes
    -----
    The continuous extended Jacobian run (7) with (11) keeps each component of h constant on
    its own, eq. (12): components at different constant values have changed by 0, not by
    their spread.
    """
    if h is None:
        return None
    v = as_numbers(h, "h")
    if not v.size:
        return None
    columns = v.reshape(len(v), -1) if v.ndim else v.reshape(1, 1)
    known = np.isfinite(columns)
    if not known.any():
        return None
    high = np.where(known, columns, -np.inf).max(axis=0)
    low = np.where(known, columns, np.inf).min(axis=0)
    return float((high - low)[known.any(axis=0)].max())


class AugmentingMap(abc.ABC):
    """h: R^p -> R^(p-r) with p - r = 1, eq. (9); dh/dx is its exact gradient.

    Each of :data:`CHECKED` a subclass defines is wrapped, when the class is made, by the check
    of ``x`` (:meth:`check`: numbers of shape (..., p), :class:`InvalidInputError` with field
    ``"x"`` otherwise), as the kinematics' evaluations are; a float array of p columns passes
    in about a microsecond.
    """

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        for name in CHECKED:
            core = cls.__dict__.get(name)
            if core is not None and not getattr(core, "__isabstractmethod__", False):
                setattr(cls, name, checked_points(core, finite=False))

    name: ClassVar[str]
    p: int
    #: Whether each value of h solves a problem of its own (a characteristic's collocation,
    #: eq. (28)), so that a grid of h costs seconds: analyses over a box skip such a map or
    #: take it on a coarser grid.
    solves_per_point: ClassVar[bool] = False

    @abc.abstractmethod
    def value(self, x: FloatArray) -> FloatArray:
        """h(x): (..., p) -> (...,)."""

    @abc.abstractmethod
    def gradient(self, x: FloatArray) -> FloatArray:
        """dh/dx: (..., p) -> (..., p)."""

    def check(self, x, name: str = "x", field: str | None = None) -> FloatArray:
        """Validate configurations: numbers of shape (..., p); NaN and inf are let through (h
        is undefined there, as at a diverged solver's iterate)."""
        return as_points(x, self.p, name, field, finite=False)

    def value_masked(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """h(x) and where it is undefined (NaN there), without raising."""
        h = np.asarray(self.value(x), dtype=float)
        return h, ~np.isfinite(h)

    def gradient_masked(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """dh/dx and where h is undefined, without raising (the solver's view).

        Returns
        -------
        dh : ndarray, shape (..., p)
        undefined : ndarray of bool, shape (...,)
        """
        dh = self.gradient(x)
        return dh, ~np.all(np.isfinite(dh), axis=-1)

    @property
    def parameters(self) -> dict[str, float]:
        """The map's parameters, as a JSON-friendly dict."""
        return {}

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.parameters.items())
        return f"{type(self).__name__}({args})"


def _sqrt1p(x1: FloatArray) -> FloatArray:
    return np.sqrt(1.0 + x1**2)


class E1Optimal(AugmentingMap):
    """E1-optimal map of Manipulator 1, eq. (32).

    h(x) = x3 C1 sqrt(1 + x1^2) / g(x1)^(1/3),  g = x1 sqrt(1 + x1^2) + asinh(x1) + C2,
    with the real cube root; g' = 2 sqrt(1 + x1^2). Undefined where g(x1) = 0.
    """

    name = "e1_optimal"
    p = 3

    def __init__(self, C1: float = 1.0, C2: float = 1.0) -> None:
        self.C1 = finite(C1, "C1")
        self.C2 = finite(C2, "C2")
        if self.C1 == 0:
            raise InvalidInputError(
                "C1 must be nonzero: with C1 = 0, h = 0 and dh = 0 everywhere", "C1"
            )

    @property
    def parameters(self) -> dict[str, float]:
        return {"C1": self.C1, "C2": self.C2}

    def _g(self, x1: FloatArray) -> FloatArray:
        return x1 * _sqrt1p(x1) + np.arcsinh(x1) + self.C2

    def value(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        x1, x3 = x[..., 0], x[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            return x3 * self.C1 * _sqrt1p(x1) / np.cbrt(self._g(x1))

    def gradient(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        x1, x3 = x[..., 0], x[..., 2]
        s, g = _sqrt1p(x1), self._g(x1)
        with np.errstate(divide="ignore", invalid="ignore"):
            cg = np.cbrt(g)
            f = self.C1 * s / cg
            df = self.C1 * (x1 / (s * cg) - (2.0 / 3.0) * s**2 / (cg * g))
        return np.stack([x3 * df, np.zeros_like(x1), f], axis=-1)


class E2Optimal(AugmentingMap):
    """E2-optimal map of Manipulator 1, eq. (36): h = x3 (a x1 + b) sqrt(1 + x1^2)."""

    name = "e2_optimal"
    p = 3

    def __init__(self, a: float = 0.0, b: float = 1.0) -> None:
        self.a = finite(a, "a")
        self.b = finite(b, "b")
        if self.a == 0 and self.b == 0:
            raise InvalidInputError("a and b must not both be 0: h would vanish identically", "a")

    @property
    def parameters(self) -> dict[str, float]:
        return {"a": self.a, "b": self.b}

    def value(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        x1, x3 = x[..., 0], x[..., 2]
        return x3 * (self.a * x1 + self.b) * _sqrt1p(x1)

    def gradient(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        x1, x3 = x[..., 0], x[..., 2]
        s = _sqrt1p(x1)
        f = (self.a * x1 + self.b) * s
        df = self.a * s + (self.a * x1 + self.b) * x1 / s
        return np.stack([x3 * df, np.zeros_like(x1), f], axis=-1)


class E1Taylor(AugmentingMap):
    """Taylor approximation (33) of (32) with C1 = C2 = 1: h = x3 (1 - 2 x1 / 3) sqrt(1 + x1^2)."""

    name = "e1_taylor"
    p = 3

    def __init__(self) -> None:
        self._e2 = E2Optimal(a=-2.0 / 3.0, b=1.0)

    def value(self, x: FloatArray) -> FloatArray:
        return self._e2.value(x)

    def gradient(self, x: FloatArray) -> FloatArray:
        return self._e2.gradient(x)


class Polynomial2(AugmentingMap):
    """A polynomial in two joint variables, h = sum c_ij u^i v^j with (u, v) = (x_a, x_b).

    Parameters
    ----------
    coefficients : mapping (i, j) -> c_ij
        Monomial exponents of u and v and their coefficients.
    variables : (int, int)
        0-based indices a, b of the joint variables u = x_a, v = x_b.
    p : int
        Configuration-space dimension.
    """

    name = "polynomial"

    def __init__(
        self,
        coefficients: Mapping[tuple[int, int], float],
        variables: tuple[int, int] = (1, 2),
        p: int = 3,
    ) -> None:
        self.coefficients = {
            (int(i), int(j)): finite(c, f"c{i}{j}") for (i, j), c in coefficients.items()
        }
        if any(i < 0 or j < 0 for i, j in self.coefficients):
            raise InvalidInputError(
                f"polynomial exponents must be >= 0, got {sorted(self.coefficients)}"
            )
        self.variables = variables
        self.p = p
        # c_ij as a matrix indexed by the powers of u and v
        keys = list(self.coefficients) or [(0, 0)]
        self._matrix = np.zeros((max(i for i, _ in keys) + 1, max(j for _, j in keys) + 1))
        for (i, j), c in self.coefficients.items():
            self._matrix[i, j] += c

    @property
    def parameters(self) -> dict[str, float]:
        return {f"c{i}{j}": c for (i, j), c in sorted(self.coefficients.items())}

    def monomials(self) -> dict[str, float]:
        """The coefficients keyed by their monomials in the 1-based variable names,
        ``"x2^2 x3^1"`` (JSON-friendly)."""
        a, b = (f"x{v + 1}" for v in self.variables)
        return {f"{a}^{i} {b}^{j}": float(c) for (i, j), c in sorted(self.coefficients.items())}

    def _powers(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """U = (1, u, u^2, ...), V likewise (..., degree + 1), and their derivatives dU, dV.

        h = U C V^T with C = ``self._matrix``: h and dh cost a few array operations whatever the
        number of terms (the hot path of the extended inverse).
        """
        x = np.asarray(x, dtype=float)
        ku = np.arange(self._matrix.shape[0], dtype=float)
        kv = np.arange(self._matrix.shape[1], dtype=float)
        U = x[..., self.variables[0], None] ** ku
        V = x[..., self.variables[1], None] ** kv
        dU = np.zeros_like(U)
        dU[..., 1:] = ku[1:] * U[..., :-1]
        dV = np.zeros_like(V)
        dV[..., 1:] = kv[1:] * V[..., :-1]
        return U, V, dU, dV

    def value(self, x: FloatArray) -> FloatArray:
        U, V, _, _ = self._powers(x)
        return np.einsum("...i,ij,...j->...", U, self._matrix, V)

    def gradient(self, x: FloatArray) -> FloatArray:
        U, V, dU, dV = self._powers(x)
        g = np.zeros(np.shape(x))
        g[..., self.variables[0]] = np.einsum("...i,ij,...j->...", dU, self._matrix, V)
        g[..., self.variables[1]] = np.einsum("...i,ij,...j->...", U, self._matrix, dV)
        return g


#: Coefficients of (38), x = x2, y = x3, keyed by (power of x2, power of x3).
PAPER_CUBIC_COEFFICIENTS: dict[tuple[int, int], float] = {
    (3, 0): 0.0006,
    (0, 3): -0.2205,
    (2, 1): 0.3469,
    (1, 2): 0.0009,
    (2, 0): 0.0005,
    (0, 2): 0.0006,
    (1, 1): -0.7501,
    (1, 0): -0.0007,
    (0, 1): 0.1381,
    (0, 0): -0.0005,
}


class PaperCubic(Polynomial2):
    """The cubic fit (38) of Manipulator 2's E2-optimal map, exactly as printed, h = h(x2, x3).

    Its gradient is the exact one; the printed j32, j33 of (39) are not the gradient of (38)
    (see docs/paper-errata.md).
    """

    name = "paper_cubic"

    def __init__(self) -> None:
        super().__init__(PAPER_CUBIC_COEFFICIENTS, variables=(1, 2), p=3)

    @property
    def parameters(self) -> dict[str, float]:
        return {}


class PaperCubicPrintedGradient(PaperCubic):
    """(38) with the printed j32, j33 of (39) used as its 'gradient' (for the errata only).

    These are not the derivatives of (38): j32 has 0.0012 x2^2 (should be 0.0018), j33 has
    -0.4410 x3^2 (should be -0.6615) and -0.0007 x2 (should be -0.7501 x2).
    """

    name = "paper_cubic_printed_gradient"

    def gradient(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        x2, x3 = x[..., 1], x[..., 2]
        j32 = 0.0012 * x2**2 + 0.6938 * x2 * x3 + 0.0009 * x3**2 + 0.001 * x2 - 0.7501 * x3 - 0.0007
        j33 = (
            -0.4410 * x3**2 + 0.3469 * x2**2 + 0.0018 * x2 * x3 + 0.0012 * x3 - 0.0007 * x2 + 0.1381
        )
        return np.stack([np.zeros_like(x2), j32, j33], axis=-1)
