"""Unicycle kinematics (40)-(42): quadrature vs an accurate ODE, J and Hessian vs FD."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from jik.engine.exceptions import InvalidInputError
from jik.engine.unicycle import Unicycle

ODE_TOL = 1e-9  # quadrature vs solve_ivp(rtol=1e-12)
FD_STEP = 1e-6
FD_TOL = 1e-7  # central differences of step 1e-6 on O(10) second derivatives


def ode_pose(lam, q0, T, t_eval=None):
    """q(T) (or q on t_eval) from an accurate integration of (40) with the controls (41)."""
    l10, l11, l20, l21 = lam

    def rhs(t, q):
        u1 = l10 + l11 * np.sin(t)
        return [u1 * np.cos(q[2]), u1 * np.sin(q[2]), l20 + l21 * np.sin(t)]

    sol = solve_ivp(rhs, (0.0, T), q0, method="DOP853", rtol=1e-12, atol=1e-13, t_eval=t_eval)
    return sol.y[:, -1] if t_eval is None else sol.y.T


def random_controls(n, scale=2.0, seed=0):
    return np.random.default_rng(seed).uniform(-scale, scale, (n, 4))


@pytest.mark.parametrize(
    "q0, T", [((0.0, 0.0, 0.0), 2 * np.pi), ((5.0, 0.0, np.pi / 2), 2 * np.pi), ((-1, 2, 0.3), 3.7)]
)
def test_forward_matches_accurate_ode(q0, T):
    """The quadrature kinematics agrees with solve_ivp (rtol 1e-12) to 1e-9, batched."""
    kin = Unicycle(q0=q0, T=T)
    lam = random_controls(12, scale=3.0, seed=1)
    got = kin.forward(lam)
    assert got.shape == (12, 3)
    want = np.array([ode_pose(l, q0, T) for l in lam])
    assert np.max(np.abs(got - want)) < ODE_TOL


def test_q3_closed_form_sign():
    """q3(T) = q03 + l20 T + l21 (1 - cos T): at T = pi, l21 = 1 turns by +2, not -2."""
    kin = Unicycle(T=np.pi)
    q = kin.forward([0.0, 0.0, 0.0, 1.0])
    assert q[2] == pytest.approx(2.0, abs=1e-12)
    assert ode_pose([0.0, 0.0, 0.0, 1.0], (0, 0, 0), np.pi)[2] == pytest.approx(2.0, abs=1e-9)


def test_jacobian_against_finite_differences():
    """J (43) as derived agrees with central differences of the kinematics; J33 = T."""
    kin = Unicycle(q0=(5.0, 0.0, np.pi / 2))
    x = random_controls(8, seed=2)
    J = kin.jacobian(x)
    fd = np.stack(
        [
            (kin.forward(x + FD_STEP * e) - kin.forward(x - FD_STEP * e)) / (2 * FD_STEP)
            for e in np.eye(4)
        ],
        axis=-1,
    )
    assert J.shape == (8, 3, 4)
    assert np.max(np.abs(J - fd)) < FD_TOL
    assert np.allclose(J[..., 2, :], [0.0, 0.0, 2 * np.pi, 0.0], atol=1e-12)


def test_jacobian_against_ode_finite_differences():
    """J agrees with central differences of the accurate ODE solution."""
    q0 = (5.0, 0.0, np.pi / 2)
    kin = Unicycle(q0=q0)
    x = np.array([0.5, -0.25, 0.3, -0.25])
    h = 1e-5
    fd = np.stack(
        [
            (ode_pose(x + h * e, q0, kin.T) - ode_pose(x - h * e, q0, kin.T)) / (2 * h)
            for e in np.eye(4)
        ],
        axis=-1,
    )
    assert np.max(np.abs(kin.jacobian(x) - fd)) < 1e-6


def test_hessian_against_finite_differences_of_jacobian():
    """The Hessian (3, 4, 4) is symmetric and agrees with central differences of J."""
    kin = Unicycle(q0=(-5.0, 5.0, np.pi / 2), T=5.0)
    x = random_controls(6, seed=3).reshape(2, 3, 4)
    H = kin.hessian(x)
    fd = np.stack(
        [
            (kin.jacobian(x + FD_STEP * e) - kin.jacobian(x - FD_STEP * e)) / (2 * FD_STEP)
            for e in np.eye(4)
        ],
        axis=-1,
    )
    assert H.shape == (2, 3, 3, 4, 4)
    assert np.max(np.abs(H - fd)) < FD_TOL
    assert np.max(np.abs(H - np.swapaxes(H, -1, -2))) < 1e-13
    assert np.max(np.abs(H[..., 2, :, :])) == 0.0


def test_fast_oscillating_controls_stay_accurate():
    """Large |l20|, |l21| (many turns within T) get more panels and keep 1e-9 accuracy."""
    kin = Unicycle()
    lam = np.array([[1.0, 0.5, 8.0, -6.0], [0.2, 0.1, 0.0, 0.0]])
    want = np.array([ode_pose(l, (0, 0, 0), kin.T) for l in lam])
    assert np.max(np.abs(kin.forward(lam) - want)) < ODE_TOL


@pytest.mark.parametrize("T", [20.0, 50.0, 20 * np.pi])
def test_long_horizons_stay_accurate(T):
    """Over many periods the sidebands of l21 cos t need more nodes than the largest rate
    |l20| + |l21| suggests (a rule sized so erred by 7e-5 at T = 50); forward and the Jacobian
    keep the ODE's accuracy."""
    kin = Unicycle(T=T)
    lam = np.array([[1.0, 1.0, 0.5, 1.0], [0.7, -0.4, 0.0, 0.3], [0.2, 1.0, 0.0, 3.0]])
    want = np.array([ode_pose(l, (0, 0, 0), T) for l in lam])
    assert np.max(np.abs(kin.forward(lam) - want)) < ODE_TOL
    step = 1e-6 * np.eye(4)
    fd = np.stack([(kin.forward(lam + s) - kin.forward(lam - s)) / 2e-6 for s in step], -1)
    assert np.max(np.abs(kin.jacobian(lam) - fd)) < 1e-6 * T


def test_path_matches_ode_on_grid():
    """path(lam, t) equals the ODE solution on a time grid and ends at forward(lam)."""
    q0 = (5.0, 0.0, np.pi / 2)
    kin = Unicycle(q0=q0)
    lam = np.array([0.5, -0.25, 0.3, -0.25])
    t = np.linspace(0.0, kin.T, 41)
    q = kin.path(lam, t)
    assert q.shape == (41, 3)
    assert np.max(np.abs(q - ode_pose(lam, q0, kin.T, t_eval=t))) < ODE_TOL
    assert np.max(np.abs(q[-1] - kin.forward(lam))) < 1e-12
    batch = kin.path(np.stack([lam, 2 * lam]), t)
    assert batch.shape == (2, 41, 3)


def test_kernel_and_parameters():
    """The base class gives a unit kernel with J K = 0; parameters are JSON-friendly."""
    kin = Unicycle(q0=(1, 2, 3), T=4.0)
    x = random_controls(5, seed=4)
    K = kin.kernel(x)
    assert np.max(np.abs(np.einsum("nij,nj->ni", kin.jacobian(x), K))) < 1e-12
    assert np.allclose(np.linalg.norm(K, axis=-1), 1.0)
    assert kin.parameters == {"q0": [1.0, 2.0, 3.0], "T": 4.0}


BAD = [{"T": 0.0}, {"T": -1.0}, {"q0": (0, 0)}, {"q0": (0, np.nan, 0)}]


@pytest.mark.parametrize("kwargs", BAD)
def test_invalid_parameters(kwargs):
    with pytest.raises(InvalidInputError):
        Unicycle(**kwargs)


def test_path_rejects_decreasing_times():
    with pytest.raises(InvalidInputError, match="nondecreasing"):
        Unicycle().path([1, 0, 0, 0], [0.0, 2.0, 1.0])


def test_a_large_rule_is_banded_and_accurate():
    """Controls that need more than DENSE_RULE_MAX nodes get scipy's O(n)-memory rule: the
    end pose still matches an accurate integration of (40)."""
    from jik.engine import unicycle

    lam = np.array([0.7, -0.4, 200.0, 120.0])
    assert unicycle.nodes_for(lam, 2 * np.pi) > unicycle.DENSE_RULE_MAX
    q = Unicycle().forward(lam)
    np.testing.assert_allclose(q, ode_pose(lam, (0.0, 0.0, 0.0), 2 * np.pi), atol=ODE_TOL)


def test_controls_too_fast_for_the_quadrature_are_refused():
    """The quadrature's size is bounded (MAX_NODES): beyond it forward, the Jacobian and a
    path are refused with a message naming the controls, not computed with ever larger arrays
    (a diverging solve asked for a 208 GB rule)."""
    from jik.engine import unicycle

    kin = Unicycle()
    fast = np.array([0.0, 0.0, 3000.0, 2500.0])
    for call in (kin.forward, kin.jacobian, lambda x: kin.path(x, [6.0])):
        with pytest.raises(InvalidInputError, match=r"\|lambda20\| = 3000.*more than 8192"):
            call(fast)
    # (a diverging solve's iterate reaches the unchecked core; the public forward refuses it)
    with pytest.raises(InvalidInputError, match="oscillate too fast"):
        kin.forward_unchecked(np.array([0.0, 0.0, np.inf, 0.0]))
    with pytest.raises(InvalidInputError, match="x contains NaN or infinite"):
        kin.forward(np.array([0.0, 0.0, np.inf, 0.0]))
    assert unicycle.nodes_for(np.array([0, 0, 1000.0, 1000.0]), 2 * np.pi) <= unicycle.MAX_NODES
