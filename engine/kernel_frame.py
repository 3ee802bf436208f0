"""The kernel frame K(x) of eqs. (17) and (19), for any number p - r of degrees of redundancy,
and the vector of p - r maps h that E1 (13) and E2 (18) take.

E2 = [J^P#  K] (17) needs an orthonormal basis K of ker J(x). For p - r = 1 it is the robot's unit
kernel vector with the paper's orientation (:meth:`~jik.engine.kinematics.Kinematics.kernel`);
for p - r >= 2 it is determined only up to K -> K Q(x), Q orthogonal, and E2 changes with Q
(``docs/e2-vector.md``): jik takes the frame closest to chosen coordinate axes, the "frame
axes" (:func:`kernel_frame`). E1 (13) does not depend on the frame.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

import numpy as np

from .augmentations import AugmentingMap
from .exceptions import InvalidInputError
from .inverses import pseudoinverse, require_kinematics, require_map
from .kinematics import Kinematics
from .validation import FloatArray, count


def kernel_frame(kinematics: Kinematics, x: FloatArray, axes: Sequence[int] | None = None):
    """An orthonormal frame K(x) (..., p, p - r) of the kernel of J(x), and J(x)'s pseudoinverse.

    One degree of redundancy: K is the robot's unit kernel vector (:meth:`Kinematics.kernel`,
    the paper's orientation). More: K = N E (E^T N E)^(-1/2), with N = I - J^# J the kernel
    projector and E the 0-based coordinate axes ``axes`` (default: the last p - r joints). Among
    the orthonormal frames of the kernel it is the one closest to E in the Frobenius norm (the
    polar factor of N E); it is smooth wherever E^T N E is invertible and reduces to the paper's
    convention (last component positive) for p - r = 1 with E = e_p.
    """
    J = kinematics.jacobian(x)
    Jp = pseudoinverse(J)
    p, m = kinematics.p, kinematics.p - kinematics.r
    if m == 1:
        return kinematics.kernel(x)[..., None], Jp
    axes = list(range(p - m, p)) if axes is None else [int(a) for a in axes]
    Nproj = np.eye(p) - Jp @ J
    NE = Nproj[..., :, axes]  # (..., p, m)
    G = NE[..., axes, :]  # E^T N E, (..., m, m), symmetric positive semidefinite
    lam, U = np.linalg.eigh(G)
    if np.any(lam <= 1e-12):
        raise InvalidInputError(
            f"the kernel frame on joints {[a + 1 for a in axes]} is degenerate in the region "
            "(the kernel has no component along them); choose other frame axes",
            "frame_axes",
        )
    inv_sqrt = (U / np.sqrt(lam)[..., None, :]) @ np.swapaxes(U, -1, -2)
    return NE @ inv_sqrt, Jp


def best_frame_axes(kin: Kinematics, box: Mapping, fix: Mapping) -> list[int]:
    """The p - r joints (1-based) whose axes give the best-conditioned kernel frame at the box's
    centre: the largest least eigenvalue of E^T N E (:func:`kernel_frame`;
    the frame is degenerate where it is 0), over every choice of p - r joints at once."""
    names = kin.names
    x = np.array([fix.get(n, 0.0) for n in names], dtype=float)
    for n, (lo, hi) in box.items():
        x[names.index(n)] = 0.5 * (lo + hi)
    J = np.asarray(kin.jacobian(x), dtype=float)
    N = np.eye(kin.p) - np.linalg.pinv(J) @ J
    choices = np.array(list(itertools.combinations(range(kin.p), kin.p - kin.r)))
    least = np.linalg.eigvalsh(N[choices[:, :, None], choices[:, None, :]])[:, 0]
    return [int(a) + 1 for a in choices[int(np.argmax(least))]]


def check_frame_axes(kin: Kinematics, frame_axes, field: str = "frame_axes") -> list[int] | None:
    """``frame_axes`` as p - r distinct 1-based joints (1 to p), or None when not given; an
    InvalidInputError naming ``field`` otherwise, and for a robot with one degree of redundancy
    (its frame is its kernel vector: the joints would choose nothing)."""
    if frame_axes is None:
        return None
    m = kin.p - kin.r
    if m < 2:
        raise InvalidInputError(
            f"{field}: the kernel frame of {kin.name} (p - r = {m}) is its kernel vector; "
            "frame axes choose the frame of p - r >= 2 degrees of redundancy",
            field,
        )
    if isinstance(frame_axes, str | bytes) or not isinstance(frame_axes, Sequence | np.ndarray):
        raise InvalidInputError(
            f"{field} must be a list of {m} joints (1 to {kin.p}), got {frame_axes!r}", field
        )
    axes = [count(a, field, 1, kin.p, field) for a in frame_axes]
    if len(set(axes)) != m or len(axes) != m:
        raise InvalidInputError(f"{field} must name {m} distinct joints, got {axes}", field)
    return axes


def frame_axes_of(
    kin: Kinematics, box: Mapping, fix: Mapping, frame_axes: Sequence[int] | None
) -> list[int] | None:
    """The 0-based frame axes of :func:`kernel_frame` on ``box`` (held ``fix``): None for one
    degree of redundancy (the robot's own kernel vector), else ``frame_axes``
    (:func:`check_frame_axes`) or, without them, :func:`best_frame_axes`."""
    axes = check_frame_axes(kin, frame_axes)
    if kin.p - kin.r < 2:
        return None
    return [a - 1 for a in (best_frame_axes(kin, box, fix) if axes is None else axes)]


def require_maps(
    kinematics: Kinematics, maps, what: str, field: str = "augmenting_map"
) -> tuple[AugmentingMap, ...]:
    """The vector h = (h_1, ..., h_(p-r)) of eq. (9) that ``what`` needs, as a tuple of maps on
    R^p: one map for one degree of redundancy, a sequence of exactly p - r for more; else an
    InvalidInputError naming ``field`` (``field.i`` for the i-th of a sequence, from 0)."""
    kinematics = require_kinematics(kinematics)
    k = kinematics.p - kinematics.r
    one = isinstance(maps, AugmentingMap | str)
    if one:
        maps = [maps]  # (one map: refused below unless p - r = 1)
    if not isinstance(maps, Sequence):
        raise InvalidInputError(
            f"{field} must be an augmenting map or a list of p - r = {k} of them, got "
            f"{type(maps).__name__}",
            field,
        )
    fields = [field if one else f"{field}.{i}" for i in range(len(maps))]
    out = tuple(require_map(m, kinematics, f) for m, f in zip(maps, fields, strict=True))
    if len(out) != k:
        raise InvalidInputError(
            f"{what} of {kinematics.name} needs p - r = {k} augmenting maps, got {len(out)}",
            field,
        )
    for i, m in enumerate(out):
        if m.p != kinematics.p:
            raise InvalidInputError(
                f"augmenting map {'' if one else f'{i} '}is defined on R^{m.p}, but "
                f"{kinematics.name} has p = {kinematics.p}",
                fields[i],
            )
    return out


def maps_gradient(maps: Sequence[AugmentingMap], x: FloatArray) -> tuple[FloatArray, FloatArray]:
    """dh of the vector of ``maps`` at ``x`` (..., p): shape (..., p - r, p), and where some h_i
    is undefined (its gradient not finite), shape (...,)."""
    grads = [m.gradient_masked(x) for m in maps]
    dh = np.stack([np.asarray(g, dtype=float) for g, _ in grads], axis=-2)
    undefined = np.any(np.stack([np.asarray(u, dtype=bool) for _, u in grads], axis=-1), axis=-1)
    return dh, undefined
