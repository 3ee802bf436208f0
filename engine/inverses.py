"""Right inverses of the Jacobian: pseudoinverse, eq. (8), and extended Jacobian inverse, eq. (11).

Pure linear-algebra functions work on Jacobians; the :class:`Inverse` classes bind them to a
kinematics (and an augmenting map) and raise typed errors that name the configuration.
Nothing here forms an explicit matrix inverse: every product J# e is a linear solve.
"""

from __future__ import annotations

import abc
from collections import Counter
from collections.abc import Sequence
from typing import Any

import numpy as np

from .augmentations import AugmentingMap
from .exceptions import (
    AlgorithmicSingularityError,
    InvalidInputError,
    KinematicSingularityError,
    SingularConfigurationError,
)
from .exports import call_repr, short_value
from .kinematics import SINGULAR_MANIPULABILITY, Kinematics
from .linalg import min_norm_matrix, min_norm_solve, solve_small
from .validation import FloatArray

#: |det [J; dh]| / (product of its row norms) below this counts as an algorithmic singularity.
SINGULAR_EXTENDED = 1e-10


def _safe_solve(A: FloatArray, b: FloatArray, bad: FloatArray) -> FloatArray:
    """Solve A z = b over a batch, skipping (and zeroing) the members flagged ``bad``."""
    if np.any(bad):
        eye = np.broadcast_to(np.eye(A.shape[-1]), A.shape)
        A = np.where(bad[..., None, None], eye, A)
    z = np.linalg.solve(A, b)
    return np.where(bad[..., None, None], 0.0, z) if np.any(bad) else z


def pseudoinverse(J: FloatArray) -> FloatArray:
    """Jacobian pseudoinverse J^T (J J^T)^(-1), eq. (8).

    Parameters
    ----------
    J : ndarray, shape (..., r, p)

    Returns
    -------
    ndarray, shape (..., p, r)
        By :func:`~jik.engine.linalg.min_norm_matrix` (Gram-Schmidt on J's rows); NaN
        where m(x) < SINGULAR_MANIPULABILITY.
    """
    out, det = min_norm_matrix(J)
    bad = ~(det >= SINGULAR_MANIPULABILITY**2)
    return np.where(bad[..., None, None], np.nan, out)


def extended_jacobian(J: FloatArray, dh: FloatArray) -> FloatArray:
    """The extended Jacobian [J; dh] of l = (k, h), eq. (10): shape (..., p, p). ``dh`` is the
    gradient of one map, (..., p), or of a vector of p - r maps, (..., p - r, p)."""
    rows = dh if dh.ndim == J.ndim else dh[..., None, :]
    return np.concatenate([J, rows], axis=-2)


def extended_singularity(Jbar: FloatArray, det: FloatArray | None = None) -> FloatArray:
    """Hadamard ratio |det Jbar| / prod(row norms) in [0, 1]: 0 means singular (``det``:
    Jbar's determinant, when the caller has it)."""
    norms = np.prod(np.linalg.norm(Jbar, axis=-1), axis=-1)
    det = np.linalg.det(Jbar) if det is None else det
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norms > 0, np.abs(det) / norms, 0.0)


def extended_determinant(J: FloatArray, dh: FloatArray) -> tuple[FloatArray, FloatArray]:
    """det [J; dh] of eq. (10), and where [J; dh] is singular (``dh`` as
    :func:`extended_jacobian` takes it).

    Returns
    -------
    det : ndarray, shape (...,)
        NaN where dh is not finite. det [J; dh] = +-det(dh K) sqrt(det J J^T) (K an orthonormal
        kernel frame) is continuous where J and dh are, so a sign change between two points is
        a rank loss between them.
    singular : ndarray of bool, shape (...,)
        dh not finite, or the Hadamard ratio (:func:`extended_singularity`) below
        :data:`SINGULAR_EXTENDED`: eq. (11) is undefined there.
    """
    rows = dh if dh.ndim == J.ndim else dh[..., None, :]  # (..., p - r, p)
    defined = np.all(np.isfinite(rows), axis=(-2, -1))
    Jbar = extended_jacobian(J, np.where(defined[..., None, None], rows, 0.0))
    det = np.linalg.det(Jbar)
    singular = ~defined | ~(extended_singularity(Jbar, det) >= SINGULAR_EXTENDED)
    return np.where(defined, det, np.nan), singular


def extended_inverse(J: FloatArray, dh: FloatArray) -> FloatArray:
    """Extended Jacobian inverse, eq. (11): the first r columns of [J; dh]^(-1).

    Parameters
    ----------
    J : ndarray, shape (..., r, p)
    dh : ndarray, shape (..., p), or (..., p - r, p) for a vector of maps

    Returns
    -------
    ndarray, shape (..., p, r)
        Computed as solve([J; dh], [I_r; 0]); NaN where [J; dh] is singular.
    """
    Jbar = extended_jacobian(J, dh)
    r, p = J.shape[-2:]
    bad = extended_singularity(Jbar) < SINGULAR_EXTENDED
    rhs = np.zeros(Jbar.shape[:-2] + (p, r))
    rhs[..., :r, :] = np.eye(r)
    out = _safe_solve(Jbar, rhs, bad)
    return np.where(bad[..., None, None], np.nan, out)


def require_kinematics(kinematics) -> Kinematics:
    """``kinematics`` if it is a :class:`Kinematics`, else an InvalidInputError (field
    ``"kinematics"``) that says how to make one."""
    if isinstance(kinematics, Kinematics):
        return kinematics
    hint = (
        f"; for a robot by name use robot_from_dict({{'name': {kinematics!r}}}).kinematics"
        if isinstance(kinematics, str)
        else ""
    )
    raise InvalidInputError(
        "kinematics must be a Kinematics (Manipulator2(), PlanarChain(...), "
        f"FormulaKinematics(...), UrdfChain(...)), got {type(kinematics).__name__} "
        f"{kinematics!r:.60}{hint}",
        "kinematics",
    )


def require_map(
    augmenting_map, kinematics: Kinematics | Sequence[str], field: str = "augmenting_map"
):
    """``augmenting_map`` if it is an :class:`AugmentingMap`, else an InvalidInputError naming
    ``field`` that says how to make one (of the variables of ``kinematics``, or of the names
    given instead)."""
    if isinstance(augmenting_map, AugmentingMap):
        return augmenting_map
    names = kinematics.variable_names if isinstance(kinematics, Kinematics) else kinematics
    hint = (
        f"; for a formula use FormulaMap({augmenting_map!r}, {list(names)})"
        if isinstance(augmenting_map, str)
        else ""
    )
    raise InvalidInputError(
        "the augmenting map must be an AugmentingMap (PaperCubic(), E2Optimal(...), "
        f"FormulaMap(...), synthesize_e2(...)), got {type(augmenting_map).__name__} "
        f"{augmenting_map!r:.60}{hint}",
        field,
    )


def require_compatible(kinematics: Kinematics, augmenting_map: AugmentingMap, what: str) -> None:
    """Check that they are a Kinematics and an AugmentingMap, one degree of redundancy
    (p - r = 1) and that h is defined on R^p."""
    kinematics = require_kinematics(kinematics)
    augmenting_map = require_map(augmenting_map, kinematics)
    if kinematics.p - kinematics.r != 1:
        raise InvalidInputError(
            f"{what}: one augmenting map needs one degree of redundancy (p - r = 1); "
            f"{kinematics.name} has p - r = {kinematics.p - kinematics.r}"
            + (
                " (VectorExtendedInverse takes p - r maps)"
                if kinematics.p > kinematics.r + 1
                else ""
            ),
            "kinematics",
        )
    if augmenting_map.p != kinematics.p:
        raise InvalidInputError(
            f"augmenting map {augmenting_map.name!r} is defined on R^{augmenting_map.p}, "
            f"but {kinematics.name} has p = {kinematics.p}",
            "augmenting_map",
        )


class Inverse(abc.ABC):
    """A right inverse J#(x) of the Jacobian of a kinematics (J J# = I_r), used in eq. (7)."""

    name: str
    kinematics: Kinematics
    #: J J# = I_r, so along (7) the task error is e0 exp(-gamma theta), eq. (5), and the
    #: solver may integrate the homotopy form (:mod:`jik.engine.picard`); False: (7) itself.
    right_inverse: bool = True

    @property
    def parameters(self) -> dict[str, Any]:
        """What the inverse computes with besides its kinematics: its parameters (numbers,
        vectors) and augmenting map(s); what its repr and its label in an atlas show."""
        return {}

    def __repr__(self) -> str:
        return call_repr(type(self).__name__, repr(self.kinematics), **self.parameters)

    @abc.abstractmethod
    def apply_masked(self, x: FloatArray, e: FloatArray) -> tuple[FloatArray, FloatArray]:
        """J#(x) e for a batch, without raising.

        Returns
        -------
        v : ndarray, shape (..., p)
            J#(x) e, zero where singular.
        singular : ndarray of bool, shape (...,)
            Where J#(x) is undefined.
        """

    @abc.abstractmethod
    def matrix(self, x: FloatArray) -> FloatArray:
        """J#(x): (..., p) -> (..., p, r); raises a typed error at a singular configuration."""

    @abc.abstractmethod
    def singular_error(self, x: FloatArray) -> SingularConfigurationError:
        """The typed error describing a singularity of this inverse at configuration ``x``."""

    def augmenting_value(self, x: FloatArray) -> FloatArray | None:
        """h(x) for the extended inverse, None for the pseudoinverse."""
        return None

    def map_undefined(self, x: FloatArray) -> FloatArray:
        """Where J#(x) is undefined because an augmenting map h of eq. (9) is (its gradient
        cannot be evaluated there), not because [J; dh] is singular: bool (...,), all False
        for an inverse without a map."""
        return np.zeros(np.shape(x)[:-1], dtype=bool)

    def apply(self, x: FloatArray, e: FloatArray) -> FloatArray:
        """J#(x) e, shape (..., p); raises at a singular configuration."""
        x = self.kinematics.check(x)
        e = self.kinematics.check_task(e, "e")
        v, bad = self.apply_masked(x, e)
        self._raise_if(x, bad)
        return v

    def _raise_if(self, x: FloatArray, bad: FloatArray) -> None:
        bad = np.atleast_1d(bad)
        if np.any(bad):
            error = self.singular_error(
                np.reshape(x, (-1, x.shape[-1]))[np.flatnonzero(bad.ravel())[0]]
            )
            error.field = "x"
            raise error


class Pseudoinverse(Inverse):
    """The Jacobian pseudoinverse J^T (J J^T)^(-1), eq. (8), of a kinematics."""

    name = "pseudoinverse"

    def __init__(self, kinematics: Kinematics) -> None:
        self.kinematics = require_kinematics(kinematics)

    def apply_masked(self, x: FloatArray, e: FloatArray) -> tuple[FloatArray, FloatArray]:
        J = self.kinematics.jacobian_unchecked(x)
        v, d = min_norm_solve(J, e)  # J^T (J J^T)^-1 e and det(J J^T) = m^2
        bad = ~(d >= SINGULAR_MANIPULABILITY**2)  # also catches NaN
        return (np.where(bad[..., None], 0.0, v) if bad.any() else v), bad

    def matrix(self, x: FloatArray) -> FloatArray:
        x = self.kinematics.check(x)
        out = pseudoinverse(self.kinematics.jacobian_unchecked(x))
        self._raise_if(x, np.isnan(out[..., 0, 0]))
        return out

    def singular_error(self, x: FloatArray) -> SingularConfigurationError:
        return KinematicSingularityError(
            f"the pseudoinverse (8) of {self.kinematics.name} is undefined: J J^T is singular; "
            "start away from the singular set",
            x,
        )


def solve_extended(
    Jbar: FloatArray, e: FloatArray, undefined: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """v with [J; dh] v = [e; 0] (the extended inverse (11) applied to e, for one map or p - r
    of them) and where it is undefined: a map undefined there, or |det| below
    ``SINGULAR_EXTENDED`` times the product of the rows' norms (v is 0 there)."""
    rhs = np.concatenate([e, np.zeros((*e.shape[:-1], Jbar.shape[-2] - e.shape[-1]))], axis=-1)
    v, d = solve_small(Jbar, rhs)
    norms = np.prod(np.linalg.norm(Jbar, axis=-1), axis=-1)
    bad = undefined | ~(np.abs(d) >= SINGULAR_EXTENDED * norms)
    bad |= ~np.isfinite(v).all(axis=-1)
    return (np.where(bad[..., None], 0.0, v) if bad.any() else v), bad


class ExtendedInverse(Inverse):
    """The extended Jacobian inverse, eq. (11), of a kinematics augmented by a map h, eq. (9).

    By construction J J^E# = I_r and dh J^E# = 0, eq. (12), so h is constant along eq. (7).
    """

    name = "extended"

    def __init__(self, kinematics: Kinematics, augmenting_map: AugmentingMap) -> None:
        kinematics = require_kinematics(kinematics)
        augmenting_map = require_map(augmenting_map, kinematics)
        require_compatible(kinematics, augmenting_map, "the extended inverse")
        self.kinematics = kinematics
        self.augmenting_map = augmenting_map

    @property
    def parameters(self) -> dict[str, Any]:
        return {"map": self.augmenting_map}

    def augmenting_value(self, x: FloatArray) -> FloatArray:
        """h(x), NaN where h is undefined (a run can stop at such a point)."""
        return self.augmenting_map.value_masked(x)[0]

    def map_undefined(self, x: FloatArray) -> FloatArray:
        return self.augmenting_map.gradient_masked(x)[1]

    def apply_masked(self, x: FloatArray, e: FloatArray) -> tuple[FloatArray, FloatArray]:
        dh, undefined = self.augmenting_map.gradient_masked(x)
        dh = np.where(undefined[..., None], 0.0, dh)  # keeps the solve below free of NaN
        J = self.kinematics.jacobian_unchecked(x)
        return solve_extended(extended_jacobian(J, dh), e, undefined)

    def matrix(self, x: FloatArray) -> FloatArray:
        x = self.kinematics.check(x)
        J = self.kinematics.jacobian_unchecked(x)
        out = extended_inverse(J, self.augmenting_map.gradient(x))
        self._raise_if(x, ~np.isfinite(out[..., 0, 0]))
        return out

    def singular_error(self, x: FloatArray) -> SingularConfigurationError:
        if self.map_undefined(np.asarray(x, dtype=float)[None])[0]:
            return AlgorithmicSingularityError(
                f"the augmenting map {self.augmenting_map.name!r} is undefined (its gradient "
                "cannot be evaluated), so the extended Jacobian inverse (11) is undefined; "
                "choose another start or augmentation parameters",
                x,
            )
        return AlgorithmicSingularityError(
            f"the extended Jacobian [J; dh] of {self.kinematics.name} with augmenting map "
            f"{self.augmenting_map.name!r} is singular (algorithmic singularity, eq. (11)); "
            "choose another start or augmentation parameters",
            x,
        )


def algorithm_labels(inverses: Sequence[Inverse]) -> tuple[str, ...]:
    """A distinct label per inverse: its name (``Inverse.name``) where no other inverse has
    it, else the name and the parameters in which it differs from those that share it,
    ``damped(damping=0.01)``; inverses alike in every parameter are numbered, ``damped #2``."""
    names = [inv.name for inv in inverses]
    labels = []
    for inv in inverses:
        group = [other for other in inverses if other.name == inv.name]
        if len(group) == 1:
            labels.append(inv.name)
            continue
        mine = inv.parameters
        differ = {
            k: v
            for k, v in mine.items()
            if any(short_value(o.parameters.get(k)) != short_value(v) for o in group)
        }
        labels.append(call_repr(inv.name, **differ) if differ else inv.name)
    counts, seen = Counter(labels), Counter[str]()
    for i, label in enumerate(labels):
        if counts[label] > 1:
            seen[label] += 1
            labels[i] = f"{label} #{seen[label]}"
    assert len(set(labels)) == len(names)
    return tuple(labels)
