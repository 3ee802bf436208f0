"""Kinematics k: R^p -> R^r with analytic Jacobians (paper, eqs. (4), (30), (37)).

Every method is batched over leading axes: ``x`` of shape (..., p) gives (..., r) and (..., r, p).
The public evaluations (:data:`CHECKED`) check their ``x`` once, at the boundary; the solvers,
which check their inputs at their own entry, call the unchecked cores (``forward_unchecked``).
"""

from __future__ import annotations

import abc
import math
from typing import Any, ClassVar

import numpy as np

from .exceptions import InvalidInputError, KinematicSingularityError
from .exports import call_repr
from .linalg import min_norm_solve
from .validation import FloatArray, as_points, bounded, checked_points, positive

#: m(x) below this counts as a kinematic singularity.
SINGULAR_MANIPULABILITY = 1e-9
#: The evaluations that a subclass of :class:`Kinematics` implements and that check ``x``.
CHECKED = ("forward", "jacobian", "forward_jacobian", "manipulability")


def kernel_cofactors(J: FloatArray) -> FloatArray:
    """Generalised cross product of the rows of J, for one degree of redundancy.

    Parameters
    ----------
    J : ndarray, shape (..., r, r + 1)

    Returns
    -------
    c : ndarray, shape (..., r + 1)
        ``c_i = (-1)^(r + 1 + i) det(J without column i)`` (1-based i), so that J c = 0,
        ``det [J; c^T] = |c|^2`` and, by Cauchy-Binet, ``|c| = sqrt(det J J^T) = m(x)``.
    """
    r, p = J.shape[-2:]
    if p != r + 1:
        raise InvalidInputError(f"kernel_cofactors needs p = r + 1, got r = {r}, p = {p}")
    others = np.array([[j for j in range(p) if j != i] for i in range(p)])  # (p, r)
    # (one det call over the p minors J without column i, (..., p, r, r): a batch of one
    # point, as an ODE's right-hand side asks for, costs one call, not p)
    minors = np.linalg.det(np.swapaxes(J[..., :, others], -3, -2))
    signs = np.array([(-1.0) ** (r + 1 + i) for i in range(1, p + 1)])
    return minors * signs


class Kinematics(abc.ABC):
    """k: R^p -> R^r with p - r degrees of redundancy (paper, eq. (4)).

    Subclasses implement only :meth:`forward` and :meth:`jacobian` (and may implement
    ``forward_jacobian``, both from one pass); the kernel, the manipulability and singularity
    checks follow from the Jacobian. Each of those a subclass defines is wrapped, when the class
    is made, by the check of ``x`` (finite, shape (..., p): :class:`InvalidInputError` with
    field ``"x"`` otherwise); the subclass's own code stays reachable, unchecked, as
    ``forward_unchecked``, ``jacobian_unchecked`` (and ``forward_jacobian_unchecked``), for
    callers that checked their configurations once (the solvers, whose iterates may also leave
    the finite range when a run diverges).
    """

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        for name in CHECKED:
            core = cls.__dict__.get(name)
            if core is None or getattr(core, "__isabstractmethod__", False):
                continue
            setattr(cls, f"{name}_unchecked", core)
            setattr(cls, name, checked_points(core))

    name: ClassVar[str]
    p: int  # configuration-space dimension
    r: int  # task-space dimension
    #: +1 or -1: sign applied to the cofactor vector to fix the orientation of K(x).
    kernel_orientation: ClassVar[float] = 1.0
    #: Names of the configuration variables, for plots and messages.
    variable_names: tuple[str, ...] = ()
    #: Joint limits (p, 2), [lower, upper] per variable (+-inf: no bound), or None: the runs
    #: report whether they stayed within them (:mod:`jik.engine.limits`).
    joint_limits: FloatArray | None = None
    #: The robot's home configuration (p,) or None: where syntheses hold the variables outside
    #: their region (:func:`held_values`). A catalogue arm's lies within its joint limits; a
    #: URDF's given ``home`` may not (taken, as a start outside them is, and reported by runs).
    home: tuple[float, ...] | None = None
    #: The default start (p,) of a robot without a home (a catalogue manipulator's, a robot
    #: definition's ``x0``), or None: where syntheses hold them then (:func:`held_values`).
    start: tuple[float, ...] | None = None

    @abc.abstractmethod
    def forward(self, x: FloatArray) -> FloatArray:
        """k(x): (..., p) -> (..., r)."""

    @abc.abstractmethod
    def jacobian(self, x: FloatArray) -> FloatArray:
        """J(x) = dk/dx: (..., p) -> (..., r, p)."""

    @property
    def names(self) -> tuple[str, ...]:
        """The variables' names, ``x1`` ... ``xp`` for a kinematics that gives none."""
        return tuple(self.variable_names) or tuple(f"x{i + 1}" for i in range(self.p))

    def forward_jacobian(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """k(x) and J(x) of eq. (4) together; a subclass that has both from one pass (a serial
        chain's) implements its own."""
        return self.forward(x), self.jacobian(x)

    def forward_unchecked(self, x: FloatArray) -> FloatArray:
        """:meth:`forward` without the check of ``x`` (a float array (..., p))."""
        return self.forward(x)  # (replaced by each subclass's own forward)

    def jacobian_unchecked(self, x: FloatArray) -> FloatArray:
        """:meth:`jacobian` without the check of ``x`` (a float array (..., p))."""
        return self.jacobian(x)  # (replaced by each subclass's own jacobian)

    @property
    def parameters(self) -> dict[str, object]:
        """The kinematic parameters, as a JSON-friendly dict."""
        return {}

    def __repr__(self) -> str:
        """One line: the class, p, r and what sets the robot apart (:meth:`_described`)."""
        return call_repr(type(self).__name__, p=self.p, r=self.r, **self._described())

    def _described(self) -> dict[str, object]:
        """What the repr shows besides p and r: the parameters by default."""
        return self.parameters

    @property
    def scratch(self) -> int:
        """About how many float64 numbers an evaluation of J(x) holds per configuration,
        its result included: the memory estimates of batched calls
        (:func:`jik.engine.solve_rules.solve_bytes`) use it. A kinematics whose evaluation
        builds larger intermediates (a chain's transforms) says so."""
        return 3 * self.r * self.p

    def check(self, x, name: str = "x", field: str | None = None) -> FloatArray:
        """Validate configurations: finite, shape (..., p); errors name ``field`` (default
        ``name``, :func:`jik.engine.validation.field_for`)."""
        return as_points(x, self.p, name, field)

    def check_task(self, y, name: str = "y", field: str | None = None) -> FloatArray:
        """Validate task-space points: finite, shape (..., r), coordinates within
        :data:`~jik.engine.validation.MAX_COORDINATE`."""
        return bounded(as_points(y, self.r, name, field), name, field)

    def check_target(self, y, name: str = "target", field: str | None = None) -> FloatArray:
        """Validate targets (a solve's y_d, a path's points): :meth:`check_task`, and within
        the task's range where that is known without solving (a pose task's rotation
        coordinates, :meth:`jik.engine.pose_task.PoseTask.check_reachable`)."""
        return self.check_task(y, name, field)

    def check_start(self, x, name: str = "x0") -> FloatArray:
        """Validate a solve's starts: :meth:`check`, coordinates within
        :data:`~jik.engine.validation.MAX_COORDINATE`."""
        return bounded(self.check(x, name), name)

    def kernel(self, x: FloatArray) -> FloatArray:
        """Unit kernel vector K(x) of J(x), shape (..., p) (one degree of redundancy).

        Notes
        -----
        Orientation: K = s c / |c| with c the cofactor vector of :func:`kernel_cofactors`
        (``det [J; c^T] > 0``) and s = ``kernel_orientation``. For Manipulators 1 and 2 s is
        chosen so that the last component of K is positive, the paper's convention (sec. 5),
        which matters for the term -2 dh K of E2, eq. (19).
        """
        if self.p != self.r + 1:
            raise InvalidInputError(
                f"K(x) is the kernel of J of a robot with one degree of redundancy (p = r + 1); "
                f"{self.name} has p = {self.p}, r = {self.r}"
            )
        c = self.kernel_orientation * kernel_cofactors(self.jacobian(x))
        norm = np.linalg.norm(c, axis=-1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            return c / norm

    def manipulability(self, x: FloatArray) -> FloatArray:
        """m(x) = sqrt(det J J^T), shape (...,) (paper, after eq. (18)), as the product of the
        diagonal of R in J^T = Q R (:func:`~jik.engine.linalg.min_norm_solve`): accurate to
        ~ eps |J|^r absolutely, where det(J J^T) by elimination loses ~ eps |J|^2r."""
        J = self.jacobian(x)
        return np.sqrt(min_norm_solve(J, np.zeros(J.shape[:-1]))[1])

    def is_singular(self, x: FloatArray, tol: float = SINGULAR_MANIPULABILITY) -> FloatArray:
        """Boolean mask (...,): where m(x) < tol, i.e. J(x) loses rank."""
        return self.manipulability(x) < tol

    def require_regular(
        self, x: FloatArray, what: str = "configuration", field: str | None = None
    ) -> None:
        """Raise :class:`KinematicSingularityError` naming the first singular configuration
        (its ``field``: the input ``x`` came from)."""
        bad = np.atleast_1d(self.is_singular(x))
        if np.any(bad):
            xb = np.reshape(x, (-1, self.p))[np.flatnonzero(bad.ravel())[0]]
            raise KinematicSingularityError(
                f"the {what} is a kinematic singularity of {self.name} (J loses rank, "
                f"m(x) < {SINGULAR_MANIPULABILITY:g}); move it away from the singular set",
                xb,
                field,
            )


def held_values(kinematics: Kinematics) -> FloatArray:
    """Where E1, E2 and their syntheses hold the variables outside their region by default,
    shape (p,): the robot's default start, where its maps are defined (the dashboard's, and
    ``POST /synthesize``'s): the kinematics' home (a catalogue arm's or a URDF's, as given),
    else its ``start`` (Manipulator 2's paper cubic is singular at
    x3 = 0), else 0 moved into the joint limits."""
    for given in (kinematics.home, kinematics.start):
        if given is not None:
            return np.asarray(given, dtype=float)
    zero = np.zeros(kinematics.p)
    if kinematics.joint_limits is None:
        return zero
    lo, hi = np.asarray(kinematics.joint_limits, dtype=float).T
    return np.clip(zero, lo, hi)


class Manipulator1(Kinematics):
    """Manipulator 1 in its normal form, k(x) = (x1, x2 + x1 x3), eq. (30).

    J = [[1, 0, 0], [x3, 1, x1]], m(x) = sqrt(1 + x1^2) (the printed M is garbled),
    K(x) = (0, -x1, 1) / sqrt(1 + x1^2), last component positive as in the paper.
    """

    name = "manipulator1"
    p = 3
    r = 2
    start = (0.5, 0.5, 1.0)
    kernel_orientation = 1.0
    variable_names = ("x1", "x2", "x3")

    def forward(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        return np.stack([x[..., 0], x[..., 1] + x[..., 0] * x[..., 2]], axis=-1)

    def jacobian(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        J = np.zeros((*x.shape[:-1], 2, 3))
        J[..., 0, 0] = 1.0
        J[..., 1, 0] = x[..., 2]
        J[..., 1, 1] = 1.0
        J[..., 1, 2] = x[..., 0]
        return J

    def manipulability(self, x: FloatArray) -> FloatArray:
        """m(x) = sqrt(det J J^T) = sqrt(1 + x1^2) (paper, sec. 5.1)."""
        x = np.asarray(x, dtype=float)
        return np.sqrt(1.0 + x[..., 0] ** 2)


class Manipulator2(Kinematics):
    """Manipulator 2, an XY gantry with a revolute arm: k = (x2 + l cos x3, x1 + l sin x3), (37).

    J = [[0, 1, -l sin x3], [1, 0, l cos x3]], m = sqrt(1 + l^2) (the printed M is garbled),
    K(x) = (-l cos x3, l sin x3, 1) / m, last component positive as in the paper.

    Parameters
    ----------
    l : float
        Arm length, > 0 (default 1).
    """

    name = "manipulator2"
    p = 3
    r = 2
    start = (0.0, 0.0, math.pi / 2)
    kernel_orientation = -1.0
    variable_names = ("x1", "x2", "x3")

    def __init__(self, l: float = 1.0) -> None:
        self.l = positive(l, "arm length l", "l")

    @property
    def parameters(self) -> dict[str, object]:
        return {"l": self.l}

    def forward(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        return np.stack(
            [x[..., 1] + self.l * np.cos(x[..., 2]), x[..., 0] + self.l * np.sin(x[..., 2])],
            axis=-1,
        )

    def jacobian(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        J = np.zeros((*x.shape[:-1], 2, 3))
        J[..., 0, 1] = 1.0
        J[..., 0, 2] = -self.l * np.sin(x[..., 2])
        J[..., 1, 0] = 1.0
        J[..., 1, 2] = self.l * np.cos(x[..., 2])
        return J

    def manipulability(self, x: FloatArray) -> FloatArray:
        """m(x) = sqrt(1 + l^2), constant (sec. 5.2; the printed M is garbled)."""
        x = np.asarray(x, dtype=float)
        return np.full(x.shape[:-1], np.sqrt(1.0 + self.l**2))
