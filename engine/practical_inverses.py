"""The inverses redundant arms run in practice, beside the paper's (8) and (11).

Each is an :class:`jik.engine.inverses.Inverse`, so the continuation algorithm (7), its discrete
form and the repeatability test run them unchanged, batched over configurations:

- :class:`DampedInverse`: damped least squares J^T (J J^T + lambda^2 I)^(-1) (Wampler 1986;
  Nakamura and Hanafusa 1986), with an optional damping that grows only near singularities;
- :class:`WeightedInverse`: the weighted least-norm inverse W^(-1) J^T (J W^(-1) J^T)^(-1) that
  slows joints near their limits (Chan and Dubey 1995);
- :class:`PostureInverse`: the pseudoinverse (8) plus a null-space pull toward a rest posture
  (gradient projection, Liegeois 1977).

The weighted and posture inverses are right inverses (J J# = I_r), so along (7) the task error
still decays as e0 exp(-gamma theta), eq. (5). Damped least squares is not (J J# != I_r for
lambda > 0): it trades tracking for bounded joint speeds, and the solver integrates it on (7)
itself (:attr:`right_inverse` is False), reporting the task error it leaves.
"""

from __future__ import annotations

import numpy as np

from .exceptions import InvalidInputError, KinematicSingularityError, SingularConfigurationError
from .inverses import Inverse, Pseudoinverse, require_kinematics
from .kinematics import SINGULAR_MANIPULABILITY, Kinematics
from .limits import limit_names, robot_limits
from .linalg import gram, min_norm_solve, solve_small
from .validation import FloatArray, as_box, finite, flag, within

#: Default and largest damping lambda (the largest also bounds the damping threshold).
DAMPING, MAX_DAMPING = 0.1, 10.0
#: Default and largest null-space gain k of the posture inverse.
GAIN, MAX_GAIN = 1.0, 100.0


def _nonnegative(value, name: str, maximum: float) -> float:
    v = finite(value, name)
    if not 0.0 <= v <= maximum:
        raise InvalidInputError(f"{name} must be in [0, {maximum:g}], got {v:g}", name)
    return v


def check_rest(kinematics: Kinematics, rest, limited: bool = True) -> FloatArray:
    """A rest posture x_rest (p,) of the posture inverse, checked: p finite numbers and, if
    ``limited`` (a rest given, not a default), within the robot's joint limits when it declares
    some (:func:`~jik.engine.limits.robot_limits`: a URDF arm's, a planar chain's or a formula
    robot's ``limits``); a robot without limits takes any finite rest.

    Raises
    ------
    InvalidInputError
        ``rest`` for a wrong shape or a value not finite; ``rest.<i>`` for coordinate i outside
        its joint's limits, naming the joint, its value and the limit.
    """
    x = kinematics.check(rest, "rest")
    if x.shape != (kinematics.p,):
        raise InvalidInputError(f"rest must be one configuration of {kinematics.p} numbers", "rest")
    limits = robot_limits(kinematics) if limited else None
    if limits is not None:
        names = limit_names(kinematics)
        within(x, limits, "rest", names, f"the joint limits of the {kinematics.name}")
    return x


def _singular(kinematics: Kinematics, x: FloatArray, what: str) -> KinematicSingularityError:
    return KinematicSingularityError(
        f"{what} of {kinematics.name} is undefined: J J^T is singular; "
        "start away from the singular set or add damping",
        x,
    )


def _jt(J: FloatArray, w: FloatArray) -> FloatArray:
    return np.einsum("...ji,...j->...i", J, w)  # J^T w


class DampedInverse(Inverse):
    """Damped least squares J^T (J J^T + lambda(x)^2 I)^(-1) (Wampler 1986).

    Parameters
    ----------
    kinematics : Kinematics
    damping : float
        lambda >= 0, default :data:`DAMPING`. With ``damping_threshold`` 0 the damping is
        constant; lambda = 0 is the pseudoinverse (8), bit for bit (the same code runs).
    damping_threshold : float
        epsilon >= 0. When positive, the adaptive damping of Nakamura and Hanafusa (1986):
        lambda(x)^2 = lambda^2 (1 - s(x) / epsilon)^2 where the smallest singular value s(x) of
        J(x) is below epsilon, and 0 elsewhere (the pseudoinverse away from singularities).
        A tiny epsilon (even a subnormal one) is meaningful: it damps only where J is singular
        to within epsilon, and is computed without overflow.

    Notes
    -----
    J# e minimizes ||J v - e||^2 + lambda^2 ||v||^2: the joint speed stays bounded (by
    ||e|| / (2 lambda)) through a singularity, at the cost of a task error that no longer
    decays as in eq. (5). Nakamura and Hanafusa write the damping as k0 (1 - w / w0)^2 in the
    manipulability w; here it is written in the smallest singular value (as Chiaverini 1997
    does), which measures the distance to the singular set in the same units for any r.
    """

    name = "damped"
    right_inverse = False

    def __init__(
        self, kinematics: Kinematics, damping: float = DAMPING, damping_threshold: float = 0.0
    ) -> None:
        self.kinematics = require_kinematics(kinematics)
        self.damping = _nonnegative(damping, "damping", MAX_DAMPING)
        self.damping_threshold = _nonnegative(damping_threshold, "damping_threshold", MAX_DAMPING)
        self._plain = Pseudoinverse(kinematics) if self.damping == 0.0 else None
        if self._plain is not None:
            self.right_inverse = True

    @property
    def parameters(self) -> dict[str, object]:
        return {"damping": self.damping, "damping_threshold": self.damping_threshold}

    def damping_squared(self, J: FloatArray) -> FloatArray:
        """lambda(x)^2 for Jacobians J (..., r, p): constant, or Nakamura-Hanafusa's."""
        lam2 = np.full(J.shape[:-2], self.damping**2)
        if self.damping_threshold > 0.0:
            s = np.linalg.svd(J, compute_uv=False)[..., -1]
            eps = self.damping_threshold
            # (eps - s)^+ / eps = (1 - s / eps)^+ lies in [0, 1]; s / eps itself overflows
            # where s dwarfs a tiny eps (1e-320, or 1e-300 with s > 1e8)
            near = np.clip(eps - s, 0.0, None) / eps
            lam2 = lam2 * near**2
        return lam2

    def apply_masked(self, x: FloatArray, e: FloatArray) -> tuple[FloatArray, FloatArray]:
        if self._plain is not None:
            return self._plain.apply_masked(x, e)
        J = self.kinematics.jacobian_unchecked(x)
        lam2 = self.damping_squared(J)
        M = gram(J) + lam2[..., None, None] * np.eye(J.shape[-2])
        w, d = solve_small(M, e)
        # Undamped members (adaptive damping far from the singular set) are the pseudoinverse.
        bad = ~(np.abs(d) >= SINGULAR_MANIPULABILITY**2) & (lam2 == 0.0)
        v = _jt(J, w)
        bad |= ~np.isfinite(v).all(axis=-1)
        return (np.where(bad[..., None], 0.0, v) if bad.any() else v), bad

    def matrix(self, x: FloatArray) -> FloatArray:
        x = self.kinematics.check(x)
        r = self.kinematics.r
        eyes = np.broadcast_to(np.eye(r), (*x.shape[:-1], r, r))
        cols = [self.apply_masked(x, np.ascontiguousarray(eyes[..., i]))[0] for i in range(r)]
        out = np.stack(cols, axis=-1)
        _, bad = self.apply_masked(x, np.zeros((*x.shape[:-1], r)))
        self._raise_if(x, bad)
        return out

    def singular_error(self, x: FloatArray) -> SingularConfigurationError:
        return _singular(self.kinematics, x, "the undamped least-squares inverse")


def limit_gradient(x: FloatArray, limits: FloatArray) -> FloatArray:
    """dH/dx of Chan and Dubey's joint-limit measure H = sum (hi - lo)^2 / (4 (hi - x)(x - lo)).

    dH/dx_i = (hi - lo)^2 (2 x_i - hi - lo) / (4 (hi - x_i)^2 (x_i - lo)^2): zero at mid-range,
    infinite at a limit. Joints with an infinite range contribute 0; at or past a limit, inf.
    It is evaluated as 2 t / (h (1 - t)^2 (1 + t)^2) with h = (hi - lo) / 2 and
    t = (x - (lo + hi) / 2) / h, which neither overflows nor underflows to 0/0 for huge ranges:
    a joint whose range dwarfs x gets a gradient of 0 (weight 1), as an unlimited one.
    """
    lo, hi = limits[:, 0], limits[:, 1]
    bounded = np.isfinite(lo) & np.isfinite(hi)
    lo_b, hi_b = np.where(bounded, lo, -1.0), np.where(bounded, hi, 1.0)
    half = hi_b / 2 - lo_b / 2
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        t = (x - (lo_b / 2 + hi_b / 2)) / half
        g = 2 * t / (half * (1 - t) ** 2 * (1 + t) ** 2)
    inside = (x > lo_b) & (x < hi_b)
    return np.where(bounded, np.where(inside, g, np.inf), 0.0)


class WeightedInverse(Inverse):
    """Weighted least-norm inverse W^(-1) J^T (J W^(-1) J^T)^(-1) (Chan and Dubey 1995).

    Parameters
    ----------
    kinematics : Kinematics
    limits : array_like, shape (p, 2)
        [lo, hi] per joint (inf for an unlimited joint).
    box : bool
        The limits are the configuration box x_range of a robot that has no joint limits (its
        default limits, :func:`~jik.engine.algorithm_registry.make_inverse`): its findings say
        so, not that the robot's joints have these limits.

    Notes
    -----
    W(x) = diag(1 + |dH/dx_i|) with H the joint-limit measure of :func:`limit_gradient`, so a
    joint slows as it nears a limit and stops at it (weight inf). Chan and Dubey switch a
    weight back to 1 while the joint moves away from its limit; that switch depends on the
    motion's history, so it is left out here: the flow (7) stays autonomous and the same in
    continuous and discrete mode. J J# = I_r, so the task error decays as in eq. (5). A
    configuration at or past a limit is a singular one for this inverse: a start there raises,
    and a discrete run whose step crosses a limit stops there with a message naming the joint.
    So is one where J is regular but joints so near their limits that J W^-1 J^T is singular
    (a continuous run pressed against them stops there): its error names the nearest joint.
    """

    name = "weighted"

    def __init__(self, kinematics: Kinematics, limits, box: bool = False) -> None:
        self.kinematics = kinematics = require_kinematics(kinematics)
        self.limits = as_box(limits, kinematics.p, "limits", finite=False)
        self.box = flag(box, "box")

    @property
    def parameters(self) -> dict[str, object]:
        return {"limits": self.limits}

    def outside(self, x: FloatArray) -> FloatArray:
        """Where a joint is at or past one of its limits, shape (...,)."""
        return np.asarray(~((x > self.limits[:, 0]) & (x < self.limits[:, 1])).all(axis=-1))

    def weights_inverse(self, x: FloatArray) -> FloatArray:
        """diag(W(x))^(-1), shape (..., p): 0 at or past a limit."""
        return 1.0 / (1.0 + np.abs(limit_gradient(x, self.limits)))

    def apply_masked(self, x: FloatArray, e: FloatArray) -> tuple[FloatArray, FloatArray]:
        J = self.kinematics.jacobian_unchecked(x)
        winv = self.weights_inverse(x)
        sw = np.sqrt(winv)
        Jw = J * sw[..., None, :]
        # W^-1 J^T (J W^-1 J^T)^-1 e = W^-1/2 Jw^T (Jw Jw^T)^-1 e with Jw = J W^-1/2
        u, d = min_norm_solve(Jw, e)
        bad = ~(d >= SINGULAR_MANIPULABILITY**2) | self.outside(x)
        # (a trial point at a limit: weight 0 times the step of a singular Jw; marked bad
        # below, not warned)
        with np.errstate(invalid="ignore"):
            v = sw * u
        bad |= ~np.isfinite(v).all(axis=-1)
        return (np.where(bad[..., None], 0.0, v) if bad.any() else v), bad

    def matrix(self, x: FloatArray) -> FloatArray:
        x = self.kinematics.check(x)
        J = self.kinematics.jacobian_unchecked(x)
        winv = self.weights_inverse(x)
        Jw = J * winv[..., None, :]
        M = Jw @ np.swapaxes(J, -1, -2)
        bad = ~(np.abs(np.linalg.det(M)) >= SINGULAR_MANIPULABILITY**2) | self.outside(x)
        self._raise_if(x, bad)
        return np.swapaxes(Jw, -1, -2) @ np.linalg.inv(M)

    def singular_error(self, x: FloatArray) -> SingularConfigurationError:
        x = np.asarray(x, dtype=float)
        out = np.flatnonzero(~((x > self.limits[:, 0]) & (x < self.limits[:, 1])))
        if out.size:
            i = int(out[0])
            lo, hi = self.limits[i]
            return KinematicSingularityError(
                f"the weighted inverse of {self.kinematics.name} is undefined: joint {i + 1} "
                f"is at or past its limits [{lo:g}, {hi:g}] (x{i + 1} = {x[i]:.6g}), where its "
                "weight is infinite: a start must lie inside the limits, and a discrete step "
                "can cross one (lower gamma)",
                x,
            )
        J = self.kinematics.jacobian_unchecked(x)
        if min_norm_solve(J, np.zeros(J.shape[-2]))[1] >= SINGULAR_MANIPULABILITY**2:
            # J regular: the weights make J W^-1 J^T singular, the largest (nearest its limit)
            winv = self.weights_inverse(x)
            i = int(np.argmin(winv))
            lo, hi = self.limits[i]
            side, limit = ("upper", hi) if hi - x[i] < x[i] - lo else ("lower", lo)
            return SingularConfigurationError(
                f"the weighted inverse of {self.kinematics.name} is undefined: J is regular but "
                f"J W^-1 J^T is singular: joint {i + 1}, {limit_names(self.kinematics)[i]} = "
                f"{x[i]:.9g}, is {abs(limit - x[i]):.3g} from its {side} limit {limit:g}, where "
                f"its weight 1 + |dH/dx| is {1 / winv[i]:.3g}, and the other joints cannot move "
                "the task in every direction: move the start or the target, or widen the limits",
                x,
            )
        return _singular(self.kinematics, x, "the weighted inverse (J W^-1 J^T singular)")


class PostureInverse(Inverse):
    """Pseudoinverse (8) with a null-space pull toward a rest posture (Liegeois 1977).

    Parameters
    ----------
    kinematics : Kinematics
    rest : array_like, shape (p,)
        The rest posture x_rest; given (``rest_given``), it must lie within the robot's joint
        limits if it has some (:func:`check_rest`).
    gain : float
        k >= 0, default :data:`GAIN`; 0 is the pseudoinverse (8), bit for bit (the same code runs).
    rest_given : bool
        False: ``rest`` is a default (:func:`~jik.engine.algorithm_registry.default_rest`: the
        robot's home, else the run's start), not checked against the limits (a start outside
        them is allowed and reported as leaving them; so is a home outside them, which a URDF
        given its ``home`` may have, though no catalogue arm does); an atlas pulls each run
        toward its own start x0 instead (:mod:`jik.engine.posture_at_start`), so that it
        measures drift, not the pull.

    Notes
    -----
    Along a leg, dx = J# dy + (I - J# J) k (x_rest - x) ||dy||: per unit of the task path's
    length the joints move toward x_rest in the kernel of J, by gradient projection of
    -k ||x - x_rest||^2 / 2. In eq. (7), where dy = -gamma e dtheta,

        dx/dtheta = -gamma (J# e - k ||e|| (I - J# J) (x_rest - x)),

    so J dx/dtheta = -gamma e (eq. (5) holds) and the pull, like the leg, is over in finite
    length: the drift of a closed path does not depend on gamma or on the solver's tol. The
    pull makes closed paths contract toward one cycle, so drift per cycle falls but does not
    vanish in finitely many cycles, unlike the extended inverse (11).
    """

    name = "posture"

    def __init__(
        self, kinematics: Kinematics, rest, gain: float = GAIN, rest_given: bool = True
    ) -> None:
        self.kinematics = kinematics = require_kinematics(kinematics)
        self.rest_given = rest_given = flag(rest_given, "rest_given")
        self.rest = check_rest(kinematics, rest, limited=rest_given)
        self.gain = _nonnegative(gain, "gain", MAX_GAIN)
        self._plain = Pseudoinverse(kinematics)

    @property
    def parameters(self) -> dict[str, object]:
        out: dict[str, object] = {"rest": self.rest, "gain": self.gain}
        if not self.rest_given:
            out["rest_given"] = False
        return out

    def apply_masked(self, x: FloatArray, e: FloatArray) -> tuple[FloatArray, FloatArray]:
        return self.pull(x, e, self.rest)

    def pull(self, x: FloatArray, e: FloatArray, rest: FloatArray) -> tuple[FloatArray, FloatArray]:
        """:meth:`apply_masked` with the rest posture ``rest``, shape (p,) or one per member
        (..., p)."""
        if self.gain == 0.0:
            return self._plain.apply_masked(x, e)
        J = self.kinematics.jacobian_unchecked(x)
        # J# e - g (I - J# J) z = J# (e + g J z) - g z, g = gain |e|, z = x_rest - x
        # (a diverged iterate, a Picard sweep's, overflows here: marked bad below, not warned)
        with np.errstate(over="ignore", invalid="ignore"):
            gz = self.gain * np.linalg.norm(e, axis=-1)[..., None] * (rest - x)
            u, d = min_norm_solve(J, e + np.einsum("...ij,...j->...i", J, gz))
            v = u - gz
        bad = ~(d >= SINGULAR_MANIPULABILITY**2)
        bad |= ~np.isfinite(v).all(axis=-1)
        return (np.where(bad[..., None], 0.0, v) if bad.any() else v), bad

    def matrix(self, x: FloatArray) -> FloatArray:
        """J#(x) of the task part (the pseudoinverse); the pull is not linear in e."""
        return self._plain.matrix(x)

    def singular_error(self, x: FloatArray) -> SingularConfigurationError:
        return self._plain.singular_error(x)
