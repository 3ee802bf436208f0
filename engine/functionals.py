"""Approximation error functionals E1, eq. (13)/(14), and E2, eq. (18)/(19), by Gauss quadrature.

Both are integrals over a box of the joint space. The box is given by the variables that are
integrated over (``region``); every other joint variable is held at a fixed value (``fixed``,
by default the robot's home: :func:`~jik.engine.kinematics.held_values`) and not integrated
over, as in the paper's reduction h = h(x2, x3) for Manipulator 2. A tensor Gauss-Legendre
rule with ``nodes`` points per integrated variable is evaluated in one batch.

Orientation of K: ``Kinematics.kernel`` returns the unit kernel vector with the paper's sign
(last component positive for Manipulators 1 and 2). E1 does not depend on it; E2 does, through
the term -2 dh K of (19), so flipping the sign of h changes E2 unless K is flipped too.

With p - r >= 2 degrees of redundancy h is a vector of p - r maps and K a p x (p - r) kernel
frame (:mod:`jik.engine.kernel_frame`); both functionals are then those of ``docs/e2-vector.md``,
E2 depending on the frame, E1 not. How E1 and E2 change with a map's parameters:
:func:`jik.engine.functional_report.parameter_sensitivity`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from .augmentations import AugmentingMap
from .exports import json_values
from .inverses import (
    extended_determinant,
    extended_inverse,
    extended_jacobian,
    pseudoinverse,
    require_kinematics,
)
from .kernel_frame import frame_axes_of, kernel_frame, maps_gradient, require_maps
from .kinematics import Kinematics, held_values
from .regions import check_box_region
from .validation import FloatArray, check_memory, count

# name -> (lo, hi); any two-item sequence (JSON gives lists), validated by check_region.
Region = Mapping[str, Sequence[float]]


@dataclass(frozen=True)
class FunctionalValue:
    """The value of an error functional over a box of the joint space.

    Attributes
    ----------
    value : float
        The integral; for E1, quadrature points where [J; dh] is singular are excluded (the
        integrand is infinite there), for E2 they are included (the integrand (19) is finite).
        Either is NaN where h is undefined at a point (dh not finite), as the Sobol rule of
        :mod:`jik.engine.e2_qmc` says None. E1 is ``inf`` when it diverges (``divergent``).
    region : dict
        ``{"x2": (lo, hi), ...}``: the integrated variables.
    n_points : int
        Number of quadrature points.
    singular_points : ndarray, shape (k, p)
        Quadrature points where the extended Jacobian [J; dh] is singular (or dh not finite).
    fixed : dict
        Values of the joint variables not integrated over.
    min_abs_dh_k : float
        min |det(dh K)| over the quadrature points (|dh K| for one map): E1 is singular where
        it is 0 (eq. (14)), and a sign change inside the region makes E1 infinite.
    divergent : bool
        For E1: det(dh K) vanishes inside the region, so the integral (14) diverges and
        ``value`` is ``inf``. Found by the sign of det [J; dh] = +-det(dh K) sqrt(det J J^T)
        (continuous on the box, unlike dh K, whose sign follows K's orientation): zero, or of
        both signs, over the quadrature points and the box's faces. Always False for E2,
        finite everywhere.
    frame_axes : tuple of int
        For E2 of a vector of p - r >= 2 maps: the joints (1-based) whose axes fix the kernel
        frame K it depends on (:func:`~jik.engine.kernel_frame.kernel_frame`); else empty.
    """

    value: float
    region: dict[str, tuple[float, float]]
    n_points: int
    singular_points: np.ndarray
    fixed: dict[str, float] = field(default_factory=dict)
    min_abs_dh_k: float = float("nan")
    divergent: bool = False
    frame_axes: tuple[int, ...] = ()

    def __repr__(self) -> str:
        box = ", ".join(f"{k} in [{lo:.4g}, {hi:.4g}]" for k, (lo, hi) in self.region.items())
        held = ", ".join(f"{k}={v:.4g}" for k, v in self.fixed.items())
        return (
            f"FunctionalValue({self.value:.10g}{' (divergent)' if self.divergent else ''}, "
            f"{box}{f', held {held}' if held else ''}, {self.n_points} points, "
            f"{int(self.singular_points.shape[0])} singular"
            f"{f', frame axes {list(self.frame_axes)}' if self.frame_axes else ''})"
        )

    def as_dict(self) -> dict:
        """JSON-friendly form (:func:`~jik.engine.exports.json_values`: a divergent E1's value
        None)."""
        return json_values(
            {
                "value": self.value,
                "region": {k: list(v) for k, v in self.region.items()},
                "fixed": dict(self.fixed),
                "n_points": self.n_points,
                "n_singular": int(self.singular_points.shape[0]),
                "singular_points": self.singular_points.tolist(),
                "min_abs_dh_k": self.min_abs_dh_k,
                "divergent": self.divergent,
                "frame_axes": list(self.frame_axes) or None,
            }
        )


def check_region(
    kinematics: Kinematics, region: Region, fixed: Mapping[str, float] | None = None
) -> tuple[dict[str, tuple[float, float]], dict[str, float]]:
    """Validate a box region of the kinematics' variables and the fixed values of the others
    (:func:`jik.engine.regions.check_box_region`).

    Returns
    -------
    region : dict name -> (lo, hi), in the kinematics' variable order
    fixed : dict name -> value for every variable not in ``region`` (default: held_values)
    """
    names = kinematics.names
    return check_box_region(names, region, fixed, list(held_values(kinematics)))


def point_bytes(kinematics: Kinematics) -> float:
    """Estimated peak memory, in bytes, of E1 or E2 per quadrature point: the point, J (with
    ``kinematics.scratch`` numbers to evaluate it), dh, K, and the integrand's J J^T, J^#
    and P. Measured peaks (tracemalloc, Manipulator 2 to a Panda) are 0.4 to 0.5 times this."""
    p, r = kinematics.p, kinematics.r
    return 8.0 * (kinematics.scratch + 4 * p * p + 4 * r * p + 2 * r * r + 8 * p + 8)


def quadrature(
    kinematics: Kinematics,
    region: Region,
    nodes: int = 16,
    fixed: Mapping[str, float] | None = None,
) -> tuple[FloatArray, FloatArray, dict, dict]:
    """Tensor Gauss-Legendre rule over a box of the joint space.

    Returns
    -------
    x : ndarray, shape (n, p)
        Quadrature points, n = nodes ** len(region).
    w : ndarray, shape (n,)
        Weights (they sum to the box volume).
    region, fixed : dict
        The validated region and fixed values.
    """
    nodes = count(nodes, "nodes", 1, 400)
    box, fix = check_region(kinematics, region, fixed)
    check_memory(
        nodes ** len(box),
        point_bytes(kinematics),
        "nodes",
        f"quadrature points ({nodes}^{len(box)}) of E1 or E2",
        "use fewer nodes or region variables (synthesize_e2_nd integrates E2 over many "
        "variables by a Sobol rule)",
    )
    names = kinematics.names
    t, tw = np.polynomial.legendre.leggauss(nodes)
    axes, weights = [], []
    for lo, hi in box.values():
        axes.append(0.5 * (hi + lo) + 0.5 * (hi - lo) * t)
        weights.append(0.5 * (hi - lo) * tw)
    grids = np.meshgrid(*axes, indexing="ij")
    w = np.ones(grids[0].shape)
    for i, wi in enumerate(weights):
        shape = [1] * len(weights)
        shape[i] = -1
        w = w * wi.reshape(shape)
    x = np.empty((w.size, kinematics.p))
    k = 0
    for i, name in enumerate(names):
        if name in box:
            x[:, i] = grids[k].ravel()
            k += 1
        else:
            x[:, i] = fix[name]
    return x, w.ravel(), box, fix


def _e1_diverges(
    kinematics: Kinematics,
    maps: tuple[AugmentingMap, ...],
    x: FloatArray,
    J: FloatArray,
    dh: FloatArray,
    box: dict[str, tuple[float, float]],
) -> bool:
    """Whether det(dh K) vanishes on the box, so that E1 (14) diverges: [J; dh] is singular (as
    :func:`~jik.engine.inverses.extended_determinant` says) at, or det [J; dh] (continuous,
    +-det(dh K) sqrt(det J J^T)) is of both signs over, the quadrature points ``x`` and the
    same points moved onto each face of the box (a zero on a face is outside the
    Gauss-Legendre points but makes the integral diverge all the same). Points where dh is
    not defined, and face points where J loses rank, do not count."""
    names = kinematics.names
    faces = []
    for name, ends in box.items():
        for end in ends:
            face = x.copy()
            face[:, names.index(name)] = end
            faces.append(np.unique(face, axis=0))
    xf = np.concatenate(faces)
    xf = xf[~np.atleast_1d(kinematics.is_singular(xf))]
    with np.errstate(all="ignore"):
        dhf = maps_gradient(maps, xf)[0]
    det, singular = extended_determinant(
        np.concatenate([J, kinematics.jacobian(xf)]), np.concatenate([dh, dhf])
    )
    defined = np.isfinite(det)
    if np.any(singular & defined):  # (det(dh K) = 0 at a point)
        return True
    det = det[defined]
    return bool(det.size) and bool(np.min(det) < 0.0 < np.max(det))


def e1_integrand(J: FloatArray, dh: FloatArray) -> FloatArray:
    """||J^P# - J^E#||_F^2 of eq. (13), shape (...,); NaN where [J; dh] is singular. ``dh``:
    (..., p) for one map, (..., p - r, p) for a vector of maps."""
    D = pseudoinverse(J) - extended_inverse(J, dh)
    return np.sum(D**2, axis=(-1, -2))


def e2_integrand(J: FloatArray, K: FloatArray, m: FloatArray, dh: FloatArray) -> FloatArray:
    """||E1^(-1) E2 - I||_F^2 m of eq. (18), shape (...,). ``K``, ``dh``: the unit kernel
    vector (..., p) and one map's gradient (..., p), or a kernel frame (..., p, p - r) and a
    vector of maps' gradients (..., p - r, p).

    E1^(-1) = [J; dh] (16) and E2 = [J^P#, K] (17), so no inverse of the extended Jacobian is
    needed: the integrand equals tr(dh P dh^T - 2 dh K + I) m, eq. (19), and is finite
    everywhere.
    """
    Jbar = extended_jacobian(J, dh)  # (..., p, p)
    frame = K if K.ndim == J.ndim else K[..., :, None]
    E2 = np.concatenate([pseudoinverse(J), frame], axis=-1)  # (..., p, p)
    D = Jbar @ E2 - np.eye(J.shape[-1])
    return np.sum(D**2, axis=(-1, -2)) * m


def _evaluate(
    which: str,
    kinematics: Kinematics,
    augmenting_map,
    region: Region,
    nodes: int,
    fixed: Mapping[str, float] | None,
    frame_axes: Sequence[int] | None = None,
) -> FunctionalValue:
    kinematics = require_kinematics(kinematics)
    maps = require_maps(kinematics, augmenting_map, "E1, E2")
    x, w, box, fix = quadrature(kinematics, region, nodes, fixed)
    kinematics.require_regular(x, "integration region (a quadrature point)", "region")
    J = kinematics.jacobian(x)
    with np.errstate(all="ignore"):
        dh = maps_gradient(maps, x)[0]  # (n, p - r, p)
        det, bad = extended_determinant(J, dh)
        dh_safe = np.where(bad[:, None, None], 0.0, dh)
        m = kinematics.manipulability(x)
        dhk = np.where(bad, 0.0, np.abs(det) / m)  # |det(dh K)|, whatever the frame
        axes, divergent = None, False
        if which == "e1":  # (no frame: E1 does not depend on it; NaN where h is undefined)
            f = np.where(bad, 0.0, e1_integrand(J, dh_safe))
            f = np.where(np.isnan(det), np.nan, f)
            divergent = not np.isnan(det).any() and _e1_diverges(kinematics, maps, x, J, dh, box)
        else:
            axes = frame_axes_of(kinematics, box, fix, frame_axes)
            f = e2_integrand(J, kernel_frame(kinematics, x, axes)[0], m, dh)  # (NaN: undefined)
    return FunctionalValue(
        value=float("inf") if divergent else float(np.dot(w, f)),
        divergent=divergent,
        region=box,
        n_points=int(w.size),
        singular_points=x[bad],
        fixed=fix,
        min_abs_dh_k=float(np.min(dhk)),
        frame_axes=() if axes is None else tuple(a + 1 for a in axes),
    )


def error_functional_e1(
    kinematics: Kinematics,
    augmenting_map: AugmentingMap | Sequence[AugmentingMap],
    region: Region,
    *,
    nodes: int = 16,
    fixed: Mapping[str, float] | None = None,
) -> FunctionalValue:
    """E1(h) = integral of ||J^P#(x) - J^E#(x)||_F^2 over a box, eq. (13) (= (14)).

    Parameters
    ----------
    kinematics : Kinematics
        With p > r.
    augmenting_map : AugmentingMap, or a sequence of p - r of them
        h, eq. (9): one map for one degree of redundancy, the vector (h_1, ..., h_(p-r)) of
        :class:`~jik.engine.extended_vector.VectorExtendedInverse` for more; only the gradient
        enters.
    region : mapping name -> (lo, hi)
        The integrated variables, e.g. ``{"x1": (0, 1), "x3": (0.5, 1.5)}``.
    nodes : int
        Gauss-Legendre points per integrated variable.
    fixed : mapping name -> value, optional
        Values of the variables not integrated over (default: the robot's held values,
        :func:`~jik.engine.kinematics.held_values`: its home, else its start).

    Returns
    -------
    FunctionalValue
        Quadrature points where [J; dh] is singular are excluded from the value and listed in
        ``singular_points``; where det(dh K) vanishes inside the region, the value is ``inf``
        and ``divergent`` is set; where h is undefined at a point, the value is NaN.

    Notes
    -----
    J^P# - J^E# = K W with W = (dh K)^(-1) dh J^P#, K an orthonormal kernel frame, so the
    integrand is tr(W W^T) of eq. (14), for one map dh P dh^T / (dh K)^2 - 1: it blows up where
    det(dh K) = 0 (non-integrable if it changes sign inside the region); ``min_abs_dh_k``
    reports how close the region is. E1 is invariant under h -> phi(h) for a diffeomorphism phi
    (monotone, for one map) and does not depend on the frame K (K -> K Q changes W to Q^T W).
    """
    return _evaluate("e1", kinematics, augmenting_map, region, nodes, fixed)


def error_functional_e2(
    kinematics: Kinematics,
    augmenting_map: AugmentingMap | Sequence[AugmentingMap],
    region: Region,
    *,
    nodes: int = 16,
    fixed: Mapping[str, float] | None = None,
    frame_axes: Sequence[int] | None = None,
) -> FunctionalValue:
    """E2(h) = integral of ||E1^(-1) E2 - I||_F^2 m(x) over a box, eq. (18) (= (19)).

    Parameters are as in :func:`error_functional_e1`, and

    frame_axes : sequence of int, optional
        For p - r >= 2: the p - r joints (1-based) whose axes fix the kernel frame K
        (:func:`~jik.engine.kernel_frame.kernel_frame`); default: the best conditioned at the
        box's centre (:func:`~jik.engine.kernel_frame.best_frame_axes`), as the E2 synthesis
        over all joints takes it. Reported in the result's ``frame_axes``.

    Notes
    -----
    The integrand tr(dh P dh^T - 2 dh K + I) m with P = J^P# J^P#^T + K K^T, eq. (19), is a
    quadratic in dh; it is finite where [J; dh] is singular, so such points are included in
    the value and reported; where h is undefined (dh not finite) the value is NaN. For one map
    K is the unit kernel with the paper's orientation (last component positive for
    Manipulators 1 and 2); E2 is not invariant under h -> -h, and for p - r >= 2 it depends on
    the frame (``docs/e2-vector.md``).
    """
    return _evaluate("e2", kinematics, augmenting_map, region, nodes, fixed, frame_axes)
