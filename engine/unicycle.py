"""Kinematics of the unicycle driven by a truncated Fourier control, eqs. (40)-(42).

The control vector is lambda = (l10, l11, l20, l21), the controls are
u1 = l10 + l11 sin t, u2 = l20 + l21 sin t (eq. (41)) and the kinematics is the end pose
q(T) of the unicycle (40) started at q0 (eq. (42)).
"""

from __future__ import annotations

import functools
from typing import Literal, overload

import numpy as np
import scipy.special

from .exceptions import InvalidInputError
from .kinematics import Kinematics
from .validation import FloatArray, as_points, as_vector, count, positive

#: Gauss-Legendre nodes per quadrature panel (time grids of :meth:`Unicycle.path`).
PANEL_NODES = 16
#: Largest phase change [rad] of q3 (and of sin t) allowed within one panel.
PANEL_PHASE = 8.0
#: Error bound, relative to each moment's scale, that the single rule on [0, T] is sized for.
QUADRATURE_TOL = 1e-15
#: Half-widths b in t of the Bernstein ellipses tried when sizing that rule (:func:`nodes_for`).
HALF_WIDTHS = np.geomspace(1e-4, 40.0, 256)
#: Most nodes of that rule, and of a path's composite rule: every start the API takes at
#: T = 2 pi (|l20|, |l21| up to 1000). Beyond it the quadrature's arrays (and the time to compute
#: the rule) grow with the controls' size, which a diverging solve can make arbitrarily large:
#: without this bound one request can take tens of GB.
MAX_NODES = 8192
#: Largest rule computed by numpy's Golub-Welsch (a dense n x n eigenproblem, O(n^2) memory);
#: larger ones by scipy's banded solver, O(n) memory (the two agree to 1e-13).
DENSE_RULE_MAX = 512


@functools.lru_cache(maxsize=64)
def _panel_rule(a: float, b: float, panels: int) -> tuple[FloatArray, FloatArray]:
    """Composite Gauss-Legendre nodes and weights on [a, b] with ``panels`` equal panels."""
    xi, wi = np.polynomial.legendre.leggauss(PANEL_NODES)
    edges = np.linspace(a, b, panels + 1)
    half = 0.5 * np.diff(edges)[:, None]
    mid = 0.5 * (edges[1:] + edges[:-1])[:, None]
    t = (mid + half * xi).ravel()
    w = (half * wi).ravel()
    t.flags.writeable = False
    w.flags.writeable = False
    return t, w


@functools.lru_cache(maxsize=64)
def _moment_basis(T: float, nodes: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Nodes t (N,), C = 1 - cos t (N,) and the weighted basis G (N, 12) of the moments on [0, T].

    Columns: 1, s, t, C, s t, s C, t^2, t C, C^2, s t^2, s t C, s C^2 with s = sin t,
    C = 1 - cos t (the derivatives of u1 and q3 with respect to lambda).
    """
    if nodes <= DENSE_RULE_MAX:
        xi, wi = np.polynomial.legendre.leggauss(nodes)
    else:
        xi, wi = scipy.special.roots_legendre(nodes)
    t, w = 0.5 * T * (xi + 1.0), 0.5 * T * wi
    s, C = np.sin(t), 1.0 - np.cos(t)
    one = np.ones_like(t)
    cols = [one, s, t, C, s * t, s * C, t * t, t * C, C * C, s * t * t, s * t * C, s * C * C]
    G = np.stack(cols, axis=-1) * w[:, None]
    G.flags.writeable = False
    C.flags.writeable = False
    return t, C, G


def _phase(lam: FloatArray, length: float) -> float:
    """Bound on the phase advance of the integrands over ``length``, batch maximum (sizes the
    panels of a path: over a panel's few radians the largest rate bounds the phase)."""
    lam = np.asarray(lam, dtype=float)
    return (1.0 + float(np.max(np.abs(lam[..., 2]) + np.abs(lam[..., 3]), initial=0.0))) * length


def nodes_for(lam: FloatArray, T: float) -> int:
    """Number of Gauss-Legendre nodes on [0, T] for the controls ``lam`` (..., 4).

    Notes
    -----
    The integrands of eq. (42) and of its derivatives are f(t) = P(t) g(t) exp(+-i q3(t)):
    P a polynomial of degree <= 2 in t, g a product of at most three of sin t and 1 - cos t, and
    q3 = l20 t + l21 (1 - cos t). With t = T (xi + 1) / 2, f is entire in xi; on the Bernstein
    ellipse E_rho, of half-width b = T (rho - 1/rho) / 4 in t,
    |exp(+-i q3)| <= exp(|l20| b + |l21| sinh b), |g| <= (2 cosh b)^3 and
    |P / P's scale| <= ((rho + 1/rho) / 2 + 1)^2 / 4. An N-point Gauss-Legendre rule errs by at
    most 64 M rho^(-2N) / (15 (rho^2 - 1)) for |f| <= M on E_rho (Trefethen, Approximation
    Theory and Approximation Practice, Theorem 19.3); N is the least count that brings this
    under :data:`QUADRATURE_TOL` for the best of the ellipses :data:`HALF_WIDTHS`.

    The sinh b term holds the sidebands of l21 cos t (Bessel orders beyond |l21|): over horizons
    of many periods a count from the largest rate |dq3/dt| <= |l20| + |l21| alone is too small.
    The count is for the batch's largest |l20|, |l21|, rounded up to steps of 2^(1/16) so that
    nearby controls (a solver's iterates) share one cached count and one cached rule.
    """
    lam = np.asarray(lam, dtype=float)
    l20, l21 = np.max(np.abs(lam[..., 2:4]).reshape(-1, 2), axis=0, initial=0.0)
    return _bounded(_rule_size(_round_up(l20), _round_up(l21), float(T)), lam, T)


def _round_up(v: float) -> float:
    """``v`` >= 0 rounded up to the grid 2^(k/16); 0, inf and NaN as they are."""
    if not 0.0 < v < np.inf:
        return float(v)
    return float(2.0 ** (np.ceil(16.0 * np.log2(v)) / 16.0))


@functools.lru_cache(maxsize=1024)
def _rule_size(l20: float, l21: float, T: float) -> float:
    """The least N of :func:`nodes_for`'s bound for |l20|, |l21| over [0, T] (inf for NaN)."""
    if not (np.isfinite(l20) and np.isfinite(l21)):
        return np.inf
    b = HALF_WIDTHS
    rho = 2.0 * b / T + np.sqrt((2.0 * b / T) ** 2 + 1.0)
    log_m = (
        l20 * b
        + l21 * np.sinh(b)
        + 3.0 * np.log(2.0 * np.cosh(b))
        + 2.0 * np.log(0.5 * (0.5 * (rho + 1.0 / rho) + 1.0))
    )
    n = (log_m + np.log(64.0 / (15.0 * (rho * rho - 1.0) * QUADRATURE_TOL))) / (2.0 * np.log(rho))
    return float(np.ceil(np.min(n)))


def panels_for(lam: FloatArray, length: float) -> int:
    """Number of composite panels of :data:`PANEL_NODES` nodes over ``length`` (for path()),
    each covering at most :data:`PANEL_PHASE` rad of phase (see :func:`nodes_for`)."""
    panels = max(1.0, np.ceil(_phase(lam, length) / PANEL_PHASE))
    return _bounded(panels * PANEL_NODES, lam, length) // PANEL_NODES


def _bounded(nodes: float, lam: FloatArray, length: float) -> int:
    """``nodes`` if at most :data:`MAX_NODES`; otherwise the controls oscillate too fast."""
    if nodes <= MAX_NODES:  # (False for NaN)
        return int(nodes)
    l20, l21 = np.max(np.abs(np.asarray(lam)[..., 2:4]).reshape(-1, 2), axis=0)
    raise InvalidInputError(
        f"the controls oscillate too fast for the quadrature of eq. (42): |lambda20| = "
        f"{l20:.4g}, |lambda21| = {l21:.4g} over T = {length:.4g} s need {nodes:.0f} nodes, more "
        f"than {MAX_NODES}; start from smaller lambda20, lambda21 or use a shorter horizon T"
    )


def _derivative_map() -> FloatArray:
    """Constant (72, 60) matrix taking [V, l10 V, l11 V] (V = moments of cos q3, sin q3) to the
    flattened J (12 entries, row 3 set separately) and Hessian (48 entries)."""
    P = np.zeros((72, 60))

    def add(entries, terms):
        # terms: (block, moment index, sign); block 0 = 1, 1 = l10, 2 = l11; Mc_k = k, Ms_k = 12 + k
        for e in entries:
            for block, v, sign in terms:
                P[24 * block + v, e] += sign

    def j(i, k):
        return 4 * i + k

    def h(i, a, b):
        return [12 + 16 * i + 4 * a + b] + ([12 + 16 * i + 4 * b + a] if a != b else [])

    c, s_ = 0, 12
    add([j(0, 0)], [(0, c + 0, 1)])
    add([j(0, 1)], [(0, c + 1, 1)])
    add([j(0, 2)], [(1, s_ + 2, -1), (2, s_ + 4, -1)])
    add([j(0, 3)], [(1, s_ + 3, -1), (2, s_ + 5, -1)])
    add([j(1, 0)], [(0, s_ + 0, 1)])
    add([j(1, 1)], [(0, s_ + 1, 1)])
    add([j(1, 2)], [(1, c + 2, 1), (2, c + 4, 1)])
    add([j(1, 3)], [(1, c + 3, 1), (2, c + 5, 1)])
    # d2 (u1 cos q3): -(a b^T + b a^T) sin q3 - u1 cos q3 b b^T; d2 (u1 sin q3): + cos q3, - sin q3
    for i, (cross, bb, sign) in enumerate(((s_, c, -1), (c, s_, 1))):
        add(h(i, 0, 2), [(0, cross + 2, sign)])
        add(h(i, 0, 3), [(0, cross + 3, sign)])
        add(h(i, 1, 2), [(0, cross + 4, sign)])
        add(h(i, 1, 3), [(0, cross + 5, sign)])
        add(h(i, 2, 2), [(1, bb + 6, -1), (2, bb + 9, -1)])
        add(h(i, 2, 3), [(1, bb + 7, -1), (2, bb + 10, -1)])
        add(h(i, 3, 3), [(1, bb + 8, -1), (2, bb + 11, -1)])
    P.flags.writeable = False
    return P


_DERIVATIVE_MAP = _derivative_map()


class Unicycle(Kinematics):
    """Unicycle (40) with Fourier controls (41): k(lambda) = q(T), eq. (42); p = 4, r = 3.

    q3(t) = q03 + l20 t + l21 (1 - cos t) in closed form (the printed q3 has the opposite sign on
    the l21 term); q1, q2 are Gauss-Legendre quadratures of u1 cos q3, u1 sin q3.

    Parameters
    ----------
    q0 : array_like, shape (3,)
        Initial pose (q01, q02, q03) [m, m, rad], default (0, 0, 0).
    T : float
        Control horizon, > 0, default 2 pi.

    Notes
    -----
    The Jacobian (43), derived from the kinematics (the printed J13, J14, J23, J24 carry the
    sign of the printed q3 and J33 is printed as 1), with a = (1, sin t, 0, 0) = du1/dlambda and
    b = (0, 0, t, 1 - cos t) = dq3/dlambda::

        dq1/dlambda = int_0^T a cos q3 - u1 sin q3 b dt,
        dq2/dlambda = int_0^T a sin q3 + u1 cos q3 b dt,
        dq3/dlambda = (0, 0, T, 1 - cos T).

    ``kernel_orientation`` stays +1: K is the cofactor vector of J divided by its norm.
    """

    name = "unicycle"
    p = 4
    r = 3
    start = (0.5, -0.25, 0.3, -0.25)
    kernel_orientation = 1.0
    variable_names = ("lambda10", "lambda11", "lambda20", "lambda21")

    def __init__(self, q0=(0.0, 0.0, 0.0), T: float = 2.0 * np.pi) -> None:
        self.q0 = as_vector(q0, 3, "initial pose q0", "q0")
        self.T = positive(T, "horizon T", "T")

    @property
    def parameters(self) -> dict[str, object]:
        return {"q0": [float(v) for v in self.q0], "T": self.T}

    def _moments(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Mc = int cos q3 G, Ms = int sin q3 G: shapes (..., 12) each."""
        t, C, G = _moment_basis(self.T, nodes_for(x, self.T))
        q3 = self.q0[2] + x[..., 2:3] * t + x[..., 3:4] * C  # (..., N) [rad]
        return np.cos(q3) @ G, np.sin(q3) @ G

    def forward(self, x: FloatArray) -> FloatArray:
        """q(T), eq. (42): (..., 4) -> (..., 3)."""
        x = np.asarray(x, dtype=float)
        Mc, Ms = self._moments(x)
        l10, l11 = x[..., 0], x[..., 1]
        q3 = self.q0[2] + x[..., 2] * self.T + x[..., 3] * (1.0 - np.cos(self.T))
        return np.stack(
            [
                self.q0[0] + l10 * Mc[..., 0] + l11 * Mc[..., 1],
                self.q0[1] + l10 * Ms[..., 0] + l11 * Ms[..., 1],
                q3,
            ],
            axis=-1,
        )

    def jacobian(self, x: FloatArray) -> FloatArray:
        """J = dq(T)/dlambda, eq. (43) as derived (see class notes): (..., 4) -> (..., 3, 4)."""
        return self.derivatives(x, hessian=False)[0]

    def hessian(self, x: FloatArray) -> FloatArray:
        """Second derivatives d^2 q_i(T) / dlambda_j dlambda_k: (..., 4) -> (..., 3, 4, 4).

        Notes
        -----
        d^2/dlambda^2 of u1 cos q3 is -(a b^T + b a^T) sin q3 - u1 cos q3 b b^T and of u1 sin q3
        is (a b^T + b a^T) cos q3 - u1 sin q3 b b^T (a, b as in the class notes); q3(T) is
        linear in lambda, so its Hessian is zero.
        """
        return self.derivatives(x, hessian=True)[1]

    def moments(self, x: FloatArray) -> FloatArray:
        """The moments [int cos q3 G, int sin q3 G] (..., 24) of the quadrature basis.

        They depend on lambda20, lambda21 only (q3 does not involve lambda10, lambda11), so a
        caller that varies only lambda10, lambda11 (the characteristics of section 6.1 vary
        lambda11 during Newton) computes them once and passes them to :meth:`derivatives`.
        """
        x = np.asarray(x, dtype=float)
        t, C, G = _moment_basis(self.T, nodes_for(x, self.T))
        q3 = self.q0[2] + x[..., 2:3] * t + x[..., 3:4] * C  # (..., N) [rad]
        return np.concatenate([np.cos(q3) @ G, np.sin(q3) @ G], axis=-1)  # no complex exp: slower

    @overload
    def derivatives(
        self, x: FloatArray, hessian: Literal[True] = ..., moments: FloatArray | None = ...
    ) -> tuple[FloatArray, FloatArray]: ...
    @overload
    def derivatives(
        self, x: FloatArray, hessian: Literal[False], moments: FloatArray | None = ...
    ) -> tuple[FloatArray, None]: ...
    def derivatives(
        self, x: FloatArray, hessian: bool = True, moments: FloatArray | None = None
    ) -> tuple[FloatArray, FloatArray | None]:
        """The Jacobian (..., 3, 4) and the Hessian (..., 3, 4, 4) from one set of quadratures.

        The Hessian is None when ``hessian`` is False. ``moments`` (from :meth:`moments` at
        points with the same lambda20, lambda21) skips the quadrature.

        Notes
        -----
        Every entry of J and of the Hessian is linear in the moments int (cos q3, sin q3) G with
        coefficients 1, l10 or l11 (u1-weighted moments), so all of them come from one product
        with the constant matrix :data:`_DERIVATIVE_MAP` (few numpy calls: this is a hot path
        of the characteristics synthesis).
        """
        x = np.asarray(x, dtype=float)
        V = self.moments(x) if moments is None else moments  # (..., 24)
        V = np.concatenate([V, x[..., 0:1] * V, x[..., 1:2] * V], axis=-1)  # (..., 72)
        out = V @ (_DERIVATIVE_MAP if hessian else _DERIVATIVE_MAP[:, :12])
        J = out[..., :12].reshape(*x.shape[:-1], 3, 4)
        J[..., 2, 2], J[..., 2, 3] = self.T, 1.0 - np.cos(self.T)
        if not hessian:
            return J, None
        return J, out[..., 12:].reshape(*x.shape[:-1], 3, 4, 4)

    def path(self, lam, t, intervals: int | None = None) -> FloatArray:
        """The pose q(t) on a time grid for given controls: shape (..., len(t), 3).

        Parameters
        ----------
        lam : array_like, shape (..., 4)
            Control vectors lambda.
        t : array_like, shape (m,)
            Nondecreasing times >= 0 [s].
        intervals : int, optional
            Panels per grid interval; by default chosen from the phase rate as in
            :func:`panels_for`.

        Notes
        -----
        Each grid interval [t_{i-1}, t_i] (with t_{-1} = 0) is integrated by composite
        Gauss-Legendre and the increments are summed cumulatively, so every point is as accurate
        as :meth:`forward`.
        """
        lam = as_points(lam, 4, "control vector lambda", "lam")
        t = np.asarray(t, dtype=float)
        if t.ndim != 1 or t.size == 0 or np.any(~np.isfinite(t)) or np.any(t < 0):
            raise InvalidInputError("t must be a nonempty 1-D array of finite times >= 0")
        if np.any(np.diff(t) < 0):
            raise InvalidInputError("t must be nondecreasing")
        starts = np.concatenate([[0.0], t[:-1]])
        longest = float(np.max(t - starts))
        n_sub = (
            panels_for(lam, longest)
            if intervals is None
            else count(intervals, "intervals", 1, 10_000)
        )
        xi, wi = _panel_rule(-1.0, 1.0, n_sub)  # nodes on [-1, 1]
        half = 0.5 * (t - starts)[:, None]
        tau = 0.5 * (t + starts)[:, None] + half * xi  # (m, n_sub * PANEL_NODES)
        w = half * wi
        l10, l11, l20, l21 = (lam[..., i, None, None] for i in range(4))
        q3 = self.q0[2] + l20 * tau + l21 * (1.0 - np.cos(tau))
        u1 = l10 + l11 * np.sin(tau)
        d1 = np.sum(w * u1 * np.cos(q3), axis=-1)
        d2 = np.sum(w * u1 * np.sin(q3), axis=-1)
        q1 = self.q0[0] + np.cumsum(d1, axis=-1)
        q2 = self.q0[1] + np.cumsum(d2, axis=-1)
        q3t = self.q0[2] + lam[..., 2, None] * t + lam[..., 3, None] * (1.0 - np.cos(t))
        return np.stack([q1, q2, q3t], axis=-1)
