"""Characteristics synthesis (section 4, 6.1): one-form, d omega, h and its exact gradient."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from jik.engine.characteristics import CharacteristicsMap, UnicycleCharacteristics
from jik.engine.collocation import LinearHomotopy
from jik.engine.exceptions import InvalidInputError, OneFormUndefinedError, RunCancelled
from jik.engine.inverses import ExtendedInverse
from jik.engine.kinematics import Manipulator2, kernel_cofactors
from jik.engine.one_form import (
    cofactors,
    kernel_cofactors_derivative,
    one_form,
    one_form_derivative,
)
from jik.engine.progress import ProgressCallbacks
from jik.engine.unicycle import Unicycle

LAMBDA0 = np.array([0.5, -0.25, 0.3, -0.25])
Q0_A = (5.0, 0.0, np.pi / 2)
H_ODE_TOL = 1e-9  # h by collocation vs solve_ivp(rtol 1e-13) of (28)
GRAD_FD_TOL = 1e-7  # exact dh vs central differences (step 1e-6) of h


def points(n, seed, spread=0.4):
    return LAMBDA0 + np.random.default_rng(seed).uniform(-spread, spread, (n, 4))


@pytest.fixture(scope="module")
def kin():
    return Unicycle(q0=Q0_A)


@pytest.fixture(scope="module")
def hmap(kin):
    return UnicycleCharacteristics(kin, a=1.0)


def h_by_ode(kin, lam, a=1.0):
    """h from an accurate backward integration of dz/ds = -(w1 y1 + w3 y2 + w4 y3), (28)."""
    y = np.array([lam[0] - a, lam[2], lam[3]])

    def rhs(s, z):
        w = one_form(kin, np.array([a + s * y[0], z[0], s * y[1], s * y[2]]), 1)
        return [-(w[0] * y[0] + w[2] * y[1] + w[3] * y[2])]

    sol = solve_ivp(rhs, (1.0, 0.0), [lam[1]], method="DOP853", rtol=1e-13, atol=1e-13)
    return sol.y[0, -1]


def test_fast_cofactors_match_determinants():
    J = np.random.default_rng(0).normal(size=(7, 3, 4))
    assert np.max(np.abs(cofactors(J) - kernel_cofactors(J))) < 1e-13


def test_one_form_annihilates_jacobian_transpose(kin):
    """omega J^T = 0 and omega_2 = 1 (1-based); at T = 2 pi omega_3 = 0 and w1, w4 are (sec. 6)."""
    x = points(10, 1)
    w = one_form(kin, x, 1)
    J = kin.jacobian(x)
    assert np.max(np.abs(np.einsum("nk,nik->ni", w, J))) < 1e-12
    assert np.allclose(w[:, 1], 1.0, atol=0.0)
    assert np.max(np.abs(w[:, 2])) < 1e-12
    J11, J12, J14 = J[:, 0, 0], J[:, 0, 1], J[:, 0, 3]
    J21, J22, J24 = J[:, 1, 0], J[:, 1, 1], J[:, 1, 3]
    den = J11 * J24 - J14 * J21
    assert np.allclose(w[:, 0], (J14 * J22 - J12 * J24) / den, rtol=1e-10)
    assert np.allclose(w[:, 3], (J12 * J21 - J11 * J22) / den, rtol=1e-10)


def test_one_form_undefined_names_configuration(kin):
    """With u1 = 0 (lambda10 = lambda11 = 0) the lambda11-component of the kernel vanishes."""
    with pytest.raises(OneFormUndefinedError, match=r"x = \(0, 0, 0.2, 0.1\)") as info:
        one_form(kin, [[0.5, 0.1, 0.2, 0.1], [0.0, 0.0, 0.2, 0.1]], 1)
    assert info.value.field == "x"  # (the argument, as an InvalidInputError names it)


def test_cofactor_and_one_form_derivatives_against_fd(kin):
    x = points(6, 2)
    J, H = kin.derivatives(x)
    eps = 1e-6
    dc_fd = np.stack(
        [
            (cofactors(kin.jacobian(x + eps * e)) - cofactors(kin.jacobian(x - eps * e)))
            / (2 * eps)
            for e in np.eye(4)
        ],
        axis=-1,
    )
    dc = kernel_cofactors_derivative(J, H)
    assert np.max(np.abs(dc - dc_fd)) < 1e-6 * max(1.0, np.max(np.abs(dc)))
    _, dw = one_form_derivative(kin, x, 1)
    dw_fd = np.stack(
        [
            (one_form(kin, x + eps * e, 1) - one_form(kin, x - eps * e, 1)) / (2 * eps)
            for e in np.eye(4)
        ],
        axis=-1,
    )
    assert np.max(np.abs(dw - dw_fd)) < 1e-7


def test_homotopy_identities():
    """Phi_1 = id, Phi_s o Phi_t = Phi_st, t dPhi_t/dt = X(Phi_t), eqs. (21), (22), (45)."""
    hom = LinearHomotopy([1.0, 0.0, 0.0, 0.0], 1)
    x = points(5, 3)
    assert np.allclose(hom(x, 1.0), x)
    assert np.allclose(hom(hom(x, 0.3), 0.5), hom(x, 0.15))
    assert np.allclose(hom(x, 0.0)[:, [0, 2, 3]], [1.0, 0.0, 0.0])
    t, dt = 0.4, 1e-6
    ddt = (hom(x, t + dt) - hom(x, t - dt)) / (2 * dt)
    assert np.allclose(t * ddt, hom.field(hom(x, t)), atol=1e-9)


def test_h_matches_accurate_ode(kin, hmap):
    """h by collocation agrees with solve_ivp on (28) to 1e-9, batched."""
    x = np.vstack([LAMBDA0, points(5, 4)])
    h = hmap.value(x)
    assert h.shape == (6,)
    want = np.array([h_by_ode(kin, lam) for lam in x])
    assert np.max(np.abs(h - want)) < H_ODE_TOL


def test_h_is_z_on_reference_leaf(hmap):
    """On E_{a,0} (lambda = (a, z, 0, 0)) the characteristic is trivial: h = z, eq. (29)."""
    z = np.linspace(-2.0, 2.0, 5)
    x = np.stack([np.ones(5), z, np.zeros(5), np.zeros(5)], axis=-1)
    assert np.max(np.abs(hmap.value(x) - z)) < 1e-14


def test_gradient_against_central_differences(hmap):
    """The variational gradient agrees with central differences of h at seeded random points."""
    x = points(8, 5).reshape(2, 4, 4)
    dh = hmap.gradient(x)
    assert dh.shape == (2, 4, 4)
    eps = 1e-6
    fd = np.stack(
        [(hmap.value(x + eps * e) - hmap.value(x - eps * e)) / (2 * eps) for e in np.eye(4)],
        axis=-1,
    )
    assert np.max(np.abs(dh - fd)) < GRAD_FD_TOL


def test_codistributions_agree_along_x(kin, hmap):
    """(23)/(24) with B = 1/(dh/dz): omega X = (dh X) / (dh/dz) at random points."""
    x = points(8, 6)
    w = one_form(kin, x, 1)
    X = hmap.homotopy.field(x)
    dh = hmap.gradient(x)
    lhs = np.sum(w * X, axis=-1)
    rhs = np.sum(dh * X, axis=-1) / dh[:, 1]
    # exact for the exact h; the residual is the collocation error of h (~1e-10 here)
    assert np.max(np.abs(lhs - rhs)) < 1e-8


def test_extended_inverse_with_characteristics(kin, hmap):
    """J J^E# = I and dh J^E# = 0, eq. (12)."""
    x = points(6, 7)
    inv = ExtendedInverse(kin, hmap)
    JE = inv.matrix(x)
    assert np.max(np.abs(kin.jacobian(x) @ JE - np.eye(3))) < 1e-10
    assert np.max(np.abs(np.einsum("nk,nkr->nr", hmap.gradient(x), JE))) < 1e-10


def test_generic_map_on_another_kinematics():
    """The synthesis is generic: Manipulator 2 with a Hessian gives h = z on its reference leaf."""

    class Manip2H(Manipulator2):
        def hessian(self, x):
            x = np.asarray(x, dtype=float)
            H = np.zeros((*x.shape[:-1], 2, 3, 3))
            H[..., 0, 2, 2] = -self.l * np.cos(x[..., 2])
            H[..., 1, 2, 2] = -self.l * np.sin(x[..., 2])
            return H

    m = CharacteristicsMap(Manip2H(), [0.0, 0.0, 0.0], fixed_index=2)
    x = np.array([[0.0, 0.0, 0.7], [0.3, -0.2, 0.5]])
    h = m.value(x)
    assert abs(h[0] - 0.7) < 1e-14
    eps = 1e-6
    fd = np.stack(
        [(m.value(x + eps * e) - m.value(x - eps * e)) / (2 * eps) for e in np.eye(3)], -1
    )
    assert np.max(np.abs(m.gradient(x) - fd)) < GRAD_FD_TOL


def test_undefined_along_characteristic_raises(kin):
    """Reference leaf at lambda10 = 0: the characteristic ends at a kinematic singularity."""
    m = CharacteristicsMap(kin, [0.0, 0.0, 0.0, 0.0], fixed_index=1)
    with pytest.raises(OneFormUndefinedError, match="characteristic") as info:
        m.value(LAMBDA0)
    assert info.value.field == "x"
    masked = CharacteristicsMap(kin, [0.0, 0.0, 0.0, 0.0], fixed_index=1, on_undefined="nan")
    assert np.isnan(masked.value(LAMBDA0))
    assert np.all(np.isnan(masked.gradient(LAMBDA0)))


def test_invalid_parameters(kin):
    with pytest.raises(InvalidInputError, match="a must be nonzero"):
        UnicycleCharacteristics(kin, a=0.0)
    with pytest.raises(InvalidInputError):
        UnicycleCharacteristics(kin, a=np.inf)
    with pytest.raises(InvalidInputError):
        UnicycleCharacteristics(kin, on_undefined="ignore")
    with pytest.raises(InvalidInputError):
        UnicycleCharacteristics(kin).value([1.0, 2.0, 3.0])
    assert UnicycleCharacteristics(kin, a=2.0).parameters == {"a": 2.0}


def _h_ode(kin, lam, rhs_kind, a=1.0):
    y = np.array([lam[0] - a, lam[2], lam[3]])

    def rhs(s, z):
        w = one_form(kin, np.array([a + s * y[0], z[0], s * y[1], s * y[2]]), 1)
        if rhs_kind == "printed":  # the right-hand side printed after (28)
            return [w[0] * y[0] - w[3] * y[2]]
        return [-(w[0] * y[0] + w[2] * y[1] + w[3] * y[2])]  # -F(Phi_s)/s from (28)

    sol = solve_ivp(rhs, (1.0, 0.0), [lam[1]], method="DOP853", rtol=1e-12, atol=1e-12)
    return sol.y[0, -1]


@pytest.mark.parametrize("rhs_kind, holds", [("derived", True), ("printed", False)])
def test_printed_rhs_after_28_violates_24(kin, rhs_kind, holds):
    """(24) omega X = dh X / (dh/dz) holds for h from -F(Phi_s)/s, not from the printed RHS."""
    x = np.array([1.5, 0.3, -0.4, 0.6])
    eps = 1e-5
    dh = np.array(
        [
            (_h_ode(kin, x + eps * e, rhs_kind) - _h_ode(kin, x - eps * e, rhs_kind)) / (2 * eps)
            for e in np.eye(4)
        ]
    )
    X = np.array([x[0] - 1.0, 0.0, x[2], x[3]])
    residual = abs(one_form(kin, x, 1) @ X - dh @ X / dh[1])
    assert (residual < 1e-6) if holds else (residual > 0.1)  # printed: 0.26


def test_evaluation_in_batches_is_the_cold_evaluation_member_by_member(kin):
    """Batches of 7 (each a cold Newton solve, reported after it) give h, dh and the failures
    of one batch of all: each member's characteristic is its own solve; a batch only shares
    the iterations (to Newton's tolerance)."""
    x = points(30, seed=3, spread=1.5)
    whole = UnicycleCharacteristics(kin, a=1.0, on_undefined="nan").evaluate(x)
    seen = []
    batched = UnicycleCharacteristics(kin, a=1.0, on_undefined="nan").evaluate_batches(
        x, 7, ProgressCallbacks(on_advance=lambda done, total: seen.append((done, total)))
    )
    assert seen == [(k, 5) for k in range(1, 6)]
    assert np.array_equal(whole[2], batched[2])
    ok = ~whole[2]
    assert ok.sum() >= 10 and (~ok).sum() >= 5  # (both kinds of members)
    assert np.max(np.abs(whole[0][ok] - batched[0][ok])) < 1e-10
    assert np.max(np.abs(whole[1][ok] - batched[1][ok])) < 1e-8
    assert np.all(np.isnan(batched[0][~ok]))


def test_what_the_batch_callback_raises_stops_the_evaluation(hmap):
    """A caller's progress: what it raises after the second batch ends the evaluation, and so
    does its cancellation (RunCancelled)."""
    calls = []

    def stop(done, total):
        calls.append(done)
        if done == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        hmap.evaluate_batches(points(20, seed=4), 5, ProgressCallbacks(on_advance=stop))
    assert calls == [1, 2]
    calls.clear()
    cancel = ProgressCallbacks(
        on_advance=lambda done, total: calls.append(done), is_cancelled=lambda: len(calls) == 3
    )
    with pytest.raises(RunCancelled, match="after batch 3 of 4"):
        hmap.evaluate_batches(points(20, seed=4), 5, cancel)
    assert calls == [1, 2, 3]


def test_a_large_batch_is_solved_in_bounded_memory(kin, monkeypatch):
    """More than MAX_MEMBERS points are solved MAX_MEMBERS at a time: the peak memory of 4x the
    points is that of one part (the refined collocation systems grow with the batch), and the
    results are those of one batch of all (each member's Newton solve is its own)."""
    import tracemalloc

    from jik.engine import collocation

    monkeypatch.setattr(collocation, "MAX_MEMBERS", 50)
    x = points(200, seed=5, spread=1.5)

    def peak(n: int) -> int:
        tracemalloc.start()
        UnicycleCharacteristics(kin, a=1.0, on_undefined="nan").evaluate(x[:n])
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        return peak

    assert peak(200) < 1.5 * peak(50)
    parts = UnicycleCharacteristics(kin, a=1.0, on_undefined="nan").evaluate(x)
    monkeypatch.setattr(collocation, "MAX_MEMBERS", 1000)
    whole = UnicycleCharacteristics(kin, a=1.0, on_undefined="nan").evaluate(x)
    assert np.array_equal(whole[2], parts[2])
    ok = ~whole[2]
    assert ok.sum() >= 50 and (~ok).sum() >= 10
    assert np.max(np.abs(whole[0][ok] - parts[0][ok])) < 1e-10
    assert np.max(np.abs(whole[1][ok] - parts[1][ok])) < 1e-8
