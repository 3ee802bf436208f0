"""The catalogue arms' task Jacobians against central differences of their task maps, and each
inverse's step J# e against a plain numpy formula of it (eqs. (8), (11) and docs/algorithms.md)."""

from __future__ import annotations

import numpy as np
import pytest

from jik.engine.arms import ARMS
from jik.engine.augmentations import PaperCubic
from jik.engine.inverses import ExtendedInverse, Pseudoinverse
from jik.engine.kinematics import Manipulator2
from jik.engine.planar_chain import PlanarChain
from jik.engine.practical_inverses import (
    DampedInverse,
    PostureInverse,
    WeightedInverse,
    limit_gradient,
)
from jik.engine.robot_spec import robot_from_dict
from tests.helpers import central_difference


@pytest.mark.parametrize(
    ("arm", "task"),
    [
        (arm, task)
        for arm in ARMS
        for task in ("pose", "xyz", "xyz rz", "rx ry rz", "z rx")
        if (arm, task) != ("ur5e", "pose")  # (six joints: not redundant for the pose)
    ],
)
def test_catalogue_arm_jacobian_is_the_derivative_of_its_task_map(arm, task):
    """J = dk/dx for each catalogue arm (Gen3's continuous joints, the UR5e's six joints) with
    the rotation coordinates log(R0^T R) and their rows Jl^-1(phi) R0^T Jw, near the home: the
    one-configuration and the batched evaluations alike."""
    kin = robot_from_dict({"name": arm, "task": task}).kinematics
    x = np.asarray(kin.home) + np.random.default_rng(41).uniform(-0.6, 0.6, (6, kin.p))
    J = kin.jacobian(x)
    np.testing.assert_allclose(J, central_difference(kin.forward, x), rtol=0, atol=5e-9)
    for xi, Ji in zip(x[:2], J[:2], strict=True):
        np.testing.assert_allclose(kin.jacobian(xi), Ji, rtol=0, atol=1e-14)


def _reference_steps(kin, x, e):
    """J# e of each inverse by textbook formulas, member by member (numpy's pinv, inv)."""
    lim = np.array([[-1.0, 1.5]] * kin.p)
    rest = np.full(kin.p, 0.2)
    out: dict[str, list] = {"pinv": [], "damped": [], "weighted": [], "posture": [], "ext": []}
    for xi, ei in zip(x, e, strict=True):
        J = kin.jacobian(xi)
        P = np.linalg.pinv(J)
        out["pinv"].append(P @ ei)
        out["damped"].append(J.T @ np.linalg.solve(J @ J.T + 0.3**2 * np.eye(kin.r), ei))
        W = np.diag(1.0 / (1.0 + np.abs(limit_gradient(xi[None], lim)[0])))
        out["weighted"].append(W @ J.T @ np.linalg.solve(J @ W @ J.T, ei))
        null = (np.eye(kin.p) - P @ J) @ (rest - xi)
        out["posture"].append(P @ ei - 2.0 * np.linalg.norm(ei) * null)
        if isinstance(kin, Manipulator2):
            Jbar = np.vstack([J, PaperCubic().gradient(xi)])
            out["ext"].append(np.linalg.inv(Jbar)[:, : kin.r] @ ei)
    inverses = {
        "pinv": Pseudoinverse(kin),
        "damped": DampedInverse(kin, 0.3),
        "weighted": WeightedInverse(kin, lim),
        "posture": PostureInverse(kin, rest, gain=2.0),
        "ext": ExtendedInverse(kin, PaperCubic()) if isinstance(kin, Manipulator2) else None,
    }
    return {k: (inverses[k], np.array(v)) for k, v in out.items() if v}


@pytest.mark.parametrize("kin", [Manipulator2(), PlanarChain("RRR", [1.0, 0.8, 0.6])])
def test_each_inverse_step_equals_its_textbook_formula(kin):
    """Away from singularities (x in [-0.5, 1]^3, the 3R arm bent) the engine's steps agree
    with the formulas written with numpy's pinv and inv to 1e-12 relative."""
    rng = np.random.default_rng(41)
    x = rng.uniform(-0.5, 1.0, (15, 3))
    x[:, 2] = rng.uniform(0.5, 1.2, 15)  # (the cubic's extended Jacobian is regular there)
    e = rng.normal(size=(15, kin.r))
    for name, (inverse, ref) in _reference_steps(kin, x, e).items():
        got = inverse.apply(x, e)
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12 * np.abs(ref).max(), err_msg=name)
