"""E2 synthesis over all joints (total-degree basis, QMC rule), scalar and vector h."""

import itertools

import numpy as np
import pytest

from jik.engine import synthesis_nd
from jik.engine.exceptions import InvalidInputError, RunCancelled
from jik.engine.functionals import error_functional_e2
from jik.engine.kernel_frame import kernel_frame
from jik.engine.kinematics import Kinematics, Manipulator2
from jik.engine.planar_chain import PlanarChain
from jik.engine.progress import ProgressCallbacks
from jik.engine.synthesis_nd import MAIN_PASS, chunk_for, synthesize_e2_nd
from jik.engine.total_degree import basis_size, total_degree_indices
from jik.engine.variational import MANIPULATOR2_REGION, synthesize_e2

#: The tensor Ritz minimum of Manipulator 2 on its default region (degree 16, Gauss-Legendre).
TENSOR_E2 = 1.8152


class Linear(Kinematics):
    """k(x) = A x: constant J, K, m; h = K^T x makes E2 vanish exactly (see test)."""

    name = "linear"

    def __init__(self, A):
        self.A = np.asarray(A, dtype=float)
        self.r, self.p = self.A.shape
        self.variable_names = tuple(f"x{i + 1}" for i in range(self.p))

    def forward(self, x):
        return np.asarray(x) @ self.A.T

    def jacobian(self, x):
        return np.broadcast_to(self.A, (*np.shape(x)[:-1], self.r, self.p)).copy()


class TwoManipulators2(Kinematics):
    """Two Manipulator 2 side by side: p = 6, r = 4, p - r = 2, block-diagonal J."""

    name = "two_manipulators_2"
    p, r = 6, 4
    variable_names = ("x1", "x2", "x3", "x4", "x5", "x6")

    def __init__(self):
        self.one = Manipulator2(1.0)

    def forward(self, x):
        x = np.asarray(x)
        return np.concatenate([self.one.forward(x[..., :3]), self.one.forward(x[..., 3:])], -1)

    def jacobian(self, x):
        x = np.asarray(x)
        J = np.zeros((*x.shape[:-1], 4, 6))
        J[..., :2, :3] = self.one.jacobian(x[..., :3])
        J[..., 2:, 3:] = self.one.jacobian(x[..., 3:])
        return J


def test_the_basis_is_graded_and_counted():
    """All 1 <= |a| <= n, lower degrees first (a hierarchical basis), C(n + d, d) - 1 of them."""
    idx = total_degree_indices(4, 3)
    assert len(idx) == basis_size(4, 3) == 34
    degrees = idx.sum(axis=1)
    assert np.all(np.diff(degrees) >= 0) and degrees.min() == 1 and degrees.max() == 3
    assert len({tuple(a) for a in idx}) == len(idx)


def test_manipulator2_agrees_with_the_tensor_ritz_minimum():
    """Two variables, total degree 16: E2 within 1% (here 1e-4) of the tensor Ritz value."""
    res = synthesize_e2_nd(Manipulator2(1.0), MANIPULATOR2_REGION, degree=16, nodes=2**14)
    assert res.e2 == pytest.approx(TENSOR_E2, rel=1e-4)
    assert res.e2_check == pytest.approx(TENSOR_E2, rel=1e-4)
    tensor = synthesize_e2(Manipulator2(1.0), MANIPULATOR2_REGION, degree=16)
    x = np.array([[0.3, -0.4, 1.0], [0.0, 0.7, 2.5], [1.0, 0.1, 0.4]])
    # The same minimiser up to the additive constant (both have mean ~0 over the box).
    dh = res.augmenting_map.gradient(x) - tensor.augmenting_map.gradient(x)
    assert np.max(np.abs(dh)) < 2e-3


def test_the_ritz_value_is_the_functional_of_the_map():
    """E2 of the synthesized map by the engine's Gauss-Legendre evaluation equals the Ritz value."""
    res = synthesize_e2_nd(Manipulator2(1.0), MANIPULATOR2_REGION, degree=10, nodes=2**13)
    value = error_functional_e2(
        Manipulator2(1.0), res.augmenting_map, MANIPULATOR2_REGION, nodes=40
    ).value
    assert value == pytest.approx(res.e2, rel=2e-4)


def test_convergence_is_reported_with_degree_and_nodes():
    res = synthesize_e2_nd(
        Manipulator2(1.0), MANIPULATOR2_REGION, degree=8, nodes=2**12, convergence_degrees=(2, 4, 6)
    )
    by_degree = [c for c in res.convergence if c["nodes"] == 2**12]
    assert [c["degree"] for c in by_degree] == [2, 4, 6, 8]
    e2 = [c["e2"] for c in by_degree]
    assert all(a >= b - 1e-12 for a, b in itertools.pairwise(e2))  # Ritz: monotone
    assert {c["nodes"] for c in res.convergence} >= {1024, 2048, 4096}
    assert res.convergence[-1]["e2"] == res.e2


def test_the_gradient_is_exact():
    """dh of the synthesized map against central differences, 4R planar chain with end angle."""
    kin = PlanarChain("RRRR", [1.0, 0.8, 0.6, 0.4], orientation=True)
    region = {"x1": (-0.3, 0.3), "x2": (0.5, 1.1), "x3": (0.4, 1.0), "x4": (0.3, 0.9)}
    h = synthesize_e2_nd(kin, region, degree=4, nodes=2**11).augmenting_map
    x = np.random.default_rng(7).uniform([-0.3, 0.5, 0.4, 0.3], [0.3, 1.1, 1.0, 0.9], (5, 4))
    eps = 1e-6
    fd = np.stack(
        [(h.value(x + eps * e) - h.value(x - eps * e)) / (2 * eps) for e in np.eye(4)], axis=-1
    )
    assert np.allclose(h.gradient(x), fd, atol=1e-7)


def test_four_joints_beat_every_single_joint_map():
    """On a 4R chain (p - r = 1), the synthesized h has lower E2 than h = +-x_j for every j."""
    kin = PlanarChain("RRRR", [1.0, 0.8, 0.6, 0.4], orientation=True)
    region = {"x1": (-0.3, 0.3), "x2": (0.5, 1.1), "x3": (0.4, 1.0), "x4": (0.3, 0.9)}
    res = synthesize_e2_nd(kin, region, degree=4, nodes=2**12)
    assert set(res.single_joint) == set(region)
    assert res.e2 < min(v["e2"] for v in res.single_joint.values())
    assert abs(res.e2_check - res.e2) < 1e-2 * res.e2


def test_chunks_of_nodes_hold_the_basis_gradients_within_their_bytes():
    """A degree-6 map of a 7-joint arm (1716 unknowns) is assembled 128 nodes at a time (its
    gradients in 16 MB a chunk, not 98 MB), a small basis 1024 at a time; powers of two."""
    assert chunk_for(basis_size(7, 2), 7) == 1024
    assert chunk_for(basis_size(7, 6), 7) == 128
    assert chunk_for(10**6, 7) == 64
    for nb in range(1, 5000, 37):
        c = chunk_for(nb, 7)
        assert c & (c - 1) == 0 and 64 <= c <= 1024


def test_the_chunk_size_does_not_change_the_map(monkeypatch):
    """The same synthesis assembled in chunks of 64 nodes (the convergence table's 2^k nodes
    still end on a chunk) as in chunks of 1024: the same coefficients and E2 to rounding."""
    kin = PlanarChain("RRRR", [1.0, 0.8, 0.6, 0.4], orientation=True)
    region = {"x1": (-0.3, 0.3), "x2": (0.5, 1.1), "x3": (0.4, 1.0), "x4": (0.3, 0.9)}
    whole = synthesize_e2_nd(kin, region, degree=4, nodes=2**11)
    monkeypatch.setattr(synthesis_nd, "CHUNK_BYTES", 1)
    small = synthesize_e2_nd(kin, region, degree=4, nodes=2**11)
    np.testing.assert_allclose(small.maps[0].coefficients, whole.maps[0].coefficients, rtol=1e-9)
    assert small.e2 == pytest.approx(whole.e2, rel=1e-12)
    keys = [(row["degree"], row["nodes"], row["unknowns"]) for row in whole.convergence]
    assert [(row["degree"], row["nodes"], row["unknowns"]) for row in small.convergence] == keys
    assert [row["e2"] for row in small.convergence] == pytest.approx(
        [row["e2"] for row in whole.convergence], rel=1e-10
    )


def test_vector_h_of_a_linear_map_is_the_kernel_frame():
    """Closed form, p - r = 2: for k = A x, h = K^T x gives E2 = 0, the minimum."""
    A = np.array([[1.0, 2.0, -1.0, 0.5], [0.0, 1.0, 1.0, -2.0]])
    kin = Linear(A)
    region = {f"x{i}": (-1.0, 1.0) for i in range(1, 5)}
    res = synthesize_e2_nd(kin, region, degree=2, nodes=2**10)
    assert len(res.maps) == 2
    assert abs(res.e2) < 1e-10 and abs(res.e2_check) < 1e-10
    # (1-based, as the parameter takes them and every other door reports them)
    assert list(res.frame_axes) == res.as_dict()["frame_axes"] == [1, 3]
    assert (
        res.frame_axes
        == synthesize_e2_nd(kin, region, degree=2, nodes=2**10, frame_axes=[1, 3]).frame_axes
    )
    assert "frame_axes=[1, 3]" in repr(res)
    K, _ = kernel_frame(kin, np.zeros((1, 4)), [a - 1 for a in res.frame_axes])
    x = np.random.default_rng(1).uniform(-1, 1, (6, 4))
    for i, h in enumerate(res.maps):
        assert np.allclose(h.gradient(x), K[0, :, i], atol=1e-10)
    # The frame: orthonormal, in the kernel, closest to its axes (the best-conditioned pair).
    assert np.allclose(K[0].T @ K[0], np.eye(2), atol=1e-12)
    assert np.allclose(A @ K[0], 0, atol=1e-12)


def test_vector_h_of_two_decoupled_arms_is_each_arms_scalar_optimum():
    """Closed form by reduction, p - r = 2: two Manipulator 2 side by side. With the frame on
    joints 3 and 6, K = diag(K_a, K_b) and m = m_a m_b = 2 (each m = sqrt(2)), so
    E2 = 2 * sqrt(2) * |box of one arm| * E2_one, and h_1 depends on the first arm only."""
    region = {"x2": (-1.0, 1.0), "x3": (0.0, np.pi), "x5": (-1.0, 1.0), "x6": (0.0, np.pi)}
    res = synthesize_e2_nd(TwoManipulators2(), region, degree=10, nodes=2**13, frame_axes=(3, 6))
    expected = 2 * np.sqrt(2) * (2 * np.pi) * TENSOR_E2
    assert res.e2 == pytest.approx(expected, rel=5e-4)
    x = np.random.default_rng(3).uniform([0, -1, 0, 0, -1, 0], [0, 1, np.pi, 0, 1, np.pi], (8, 6))
    g1, g2 = (h.gradient(x) for h in res.maps)
    assert np.max(np.abs(g1[:, 3:])) < 5e-3 and np.max(np.abs(g2[:, :3])) < 5e-3
    one = synthesize_e2(Manipulator2(1.0), MANIPULATOR2_REGION, degree=16).augmenting_map
    assert np.max(np.abs(g1[:, :3] - one.gradient(x[:, :3]))) < 2e-2  # degree 10 against 16


def test_bad_input_names_its_field():
    kin = Manipulator2(1.0)
    with pytest.raises(InvalidInputError) as e:
        synthesize_e2_nd(kin, MANIPULATOR2_REGION, nodes=1000)
    assert e.value.field == "nodes"
    with pytest.raises(InvalidInputError) as e:
        synthesize_e2_nd(kin, MANIPULATOR2_REGION, degree=20, nodes=256)
    assert e.value.field == "nodes"


def test_cancel_stops_between_chunks():
    calls = []
    progress = ProgressCallbacks(
        on_advance=lambda done, total: calls.append(done), is_cancelled=lambda: len(calls) >= 2
    )
    with pytest.raises(RunCancelled):
        synthesize_e2_nd(
            Manipulator2(1.0), MANIPULATOR2_REGION, degree=6, nodes=2**13, progress=progress
        )
    assert len(calls) == 2


def test_cancel_stops_the_check_of_e2_too():
    """After the Ritz system (progress MAIN_PASS) E2 is checked on a second rule, a quarter of
    the time: progress goes on there, and a cancel there stops the synthesis too."""
    calls = []
    progress = ProgressCallbacks(
        on_advance=lambda done, total: calls.append(done),
        is_cancelled=lambda: bool(calls) and MAIN_PASS < calls[-1] < 1.0,
    )
    with pytest.raises(RunCancelled):
        synthesize_e2_nd(
            Manipulator2(1.0), MANIPULATOR2_REGION, degree=6, nodes=2**13, progress=progress
        )
    assert MAIN_PASS in calls and MAIN_PASS < calls[-1] < 1.0 and calls == sorted(calls)


def test_the_joints_outside_the_region_are_held_at_home_within_the_joint_limits():
    """Not told ``fixed``, a synthesis holds the other joints at the robot's home (the
    dashboard's default start; the Panda's joint 4 limits exclude 0), and a robot without a
    home at 0 moved into its joint limits."""
    from jik.engine.functionals import check_region
    from jik.engine.kinematics import held_values
    from jik.engine.robot_spec import load_robot

    panda = load_robot("panda")
    kin, home = panda.kinematics, np.array(panda.spec.default_x0)
    region = {"x1": (-0.2, 0.2), "x2": (home[1] - 0.2, home[1] + 0.2)}
    res = synthesize_e2_nd(kin, region, degree=1, nodes=64)
    held = np.array([res.fixed[n] for n in ("x3", "x4", "x5", "x6", "x7")])
    np.testing.assert_allclose(held, home[2:], rtol=0, atol=1e-15)
    lo, hi = np.asarray(kin.joint_limits).T
    assert np.all((lo <= held_values(kin)) & (held_values(kin) <= hi))
    bounded = PlanarChain("RRR", [1, 1, 1])
    bounded.joint_limits = np.array([[0.5, 1.0], [-1.0, 1.0], [-2.0, -1.0]])
    assert check_region(bounded, {"x2": (-1, 1)})[1] == {"x1": 0.5, "x3": -1.0}
    assert check_region(Manipulator2(), {"x2": (-1, 1)})[1] == {"x1": 0.0, "x3": np.pi / 2}


def test_a_robot_without_a_home_holds_the_other_joints_at_its_default_start():
    """Manipulator 2's paper cubic is singular at x3 = 0: held at its default start (the
    dashboard's and /synthesize's), E1 is finite; a definition's x0 is its start."""
    from jik.engine.augmentations import PaperCubic
    from jik.engine.functionals import check_region, error_functional_e1
    from jik.engine.registry import ROBOTS
    from jik.engine.robot_spec import robot_from_dict

    for name, spec in ROBOTS.items():
        held = check_region(spec.build(), {spec.variable_names[0]: (0, 1)})[1]
        assert list(held.values()) == list(spec.default_x0[1:]), name
    e1 = error_functional_e1(Manipulator2(), PaperCubic(), {"x1": (-1, 1), "x2": (-1, 1)})
    assert not e1.divergent and np.isfinite(e1.value)
    chain = robot_from_dict({"name": "planar_chain", "joints": "RRR", "lengths": [1, 1, 1]})
    assert check_region(chain.kinematics, {"x1": (0, 1)})[1] == {"x2": 0.5, "x3": 0.5}
    moved = robot_from_dict({"name": "manipulator2", "x0": [0.1, 0.2, 1.0]})
    assert check_region(moved.kinematics, {"x1": (0, 1)})[1] == {"x2": 0.2, "x3": 1.0}
