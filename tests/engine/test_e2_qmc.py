"""E2 (18) by a scrambled Sobol rule over many joints, and of h = s x_j for each joint."""

import numpy as np
import pytest

from jik.engine.e2_qmc import e2_qmc
from jik.engine.exceptions import InvalidInputError, RunCancelled
from jik.engine.planar_chain import PlanarChain
from jik.engine.progress import ProgressCallbacks
from jik.engine.synthesis_nd import synthesize_e2_nd
from tests.engine.test_synthesis_nd import Linear

CHAIN = PlanarChain("RRRR", [1.0, 0.8, 0.6, 0.4], orientation=True)
REGION = {"x1": (-0.3, 0.3), "x2": (0.5, 1.1), "x3": (0.4, 1.0), "x4": (0.3, 0.9)}


def test_it_is_the_synthesis_rule():
    """On the synthesis's own nodes (seed 0) E2 of its map is the Ritz value and the single
    joints are the synthesis's; on seed 1 it is the synthesis's independent check."""
    res = synthesize_e2_nd(CHAIN, REGION, degree=3, nodes=2**11)
    fit = e2_qmc(CHAIN, res.maps[0], REGION, nodes=2**11, seed=0)
    check = e2_qmc(CHAIN, res.maps[0], REGION, nodes=2**11, seed=1)
    assert fit["E2"] == pytest.approx(res.e2, rel=1e-9)
    assert check["E2"] == pytest.approx(res.e2_check, rel=1e-9)
    for name, row in res.single_joint.items():
        assert fit["single_joint"][name]["sign"] == row["sign"]
        assert fit["single_joint"][name]["e2"] == pytest.approx(row["e2"], rel=1e-9)
    assert fit["E2"] < min(v["e2"] for v in fit["single_joint"].values())


def test_closed_form_of_a_linear_map():
    """k = A x (p - r = 1): J, K and m = sqrt(det(A A^T)) are constant. h = K^T x has E2 = 0;
    h = s x_j has E2 = vol m (P_jj - 2 |K_j| + 1), P = A^# A^#T + K K^T."""
    A = np.array([[1.0, 2.0, -1.0], [0.0, 1.0, 1.5]])
    kin = Linear(A)
    region = {"x1": (-1.0, 1.0), "x2": (0.0, 0.5), "x3": (-0.2, 0.4)}
    h = synthesize_e2_nd(kin, region, degree=1, nodes=2**8).maps[0]
    out = e2_qmc(kin, h, region, nodes=2**8)
    assert abs(out["E2"]) < 1e-12 and out["undefined_points"] == 0
    Ap = np.linalg.pinv(A)
    K = np.linalg.svd(A)[2][-1]
    P = Ap @ Ap.T + np.outer(K, K)
    m, vol = np.sqrt(np.linalg.det(A @ A.T)), 2.0 * 0.5 * 0.6
    for j, name in enumerate(region):
        expected = vol * m * (P[j, j] - 2 * abs(K[j]) + 1)
        assert out["single_joint"][name]["e2"] == pytest.approx(expected, rel=1e-12)


def test_bad_input_names_its_field_and_cancel_stops():
    res = synthesize_e2_nd(CHAIN, REGION, degree=2, nodes=2**12)
    with pytest.raises(InvalidInputError, match="needs p - r = 2 augmenting maps, got 1") as err:
        e2_qmc(Linear(np.eye(2, 4)), res.maps[0], {"x1": (0, 1)})
    assert err.value.field == "amap"
    with pytest.raises(InvalidInputError) as err:
        e2_qmc(CHAIN, None, REGION)
    assert err.value.field == "amap"
    with pytest.raises(InvalidInputError) as err:
        e2_qmc(CHAIN, res.maps[0], REGION, nodes=1000)
    assert err.value.field == "nodes"
    calls = []
    progress = ProgressCallbacks(
        on_advance=lambda done, total: calls.append(done), is_cancelled=lambda: len(calls) >= 2
    )
    with pytest.raises(RunCancelled):
        e2_qmc(CHAIN, res.maps[0], REGION, nodes=2**12, progress=progress)
    assert len(calls) == 2


def test_the_error_estimate_is_the_difference_from_the_rules_first_half():
    """E1 and E2 on the rule's first half of the nodes are the rules of half the nodes (the same
    scrambled sequence), within one chunk of nodes and across four; the estimate is their
    difference from the whole rule's, and it shrinks as the nodes grow; the Gauss rule has none."""
    from jik.engine.e2_qmc import e1_qmc, error_estimate
    from jik.engine.functional_report import functional_info

    h = synthesize_e2_nd(CHAIN, REGION, degree=3, nodes=2**11).maps[0]
    estimates = {}
    for nodes in (2**8, 2**12):
        for rule, key in ((e1_qmc, "E1"), (e2_qmc, "E2")):
            whole = rule(CHAIN, h, REGION, nodes=nodes)
            half = rule(CHAIN, h, REGION, nodes=nodes // 2)[key]
            assert whole[f"{key}_half"] == pytest.approx(half, rel=1e-12)
            estimates[key, nodes] = error_estimate(whole[key], whole[f"{key}_half"])
            assert estimates[key, nodes] == abs(whole[key] - half)
    for key in ("E1", "E2"):
        assert 0 < estimates[key, 2**12] < estimates[key, 2**8] / 4
    info = functional_info("E2", CHAIN, h, REGION, None)
    assert info["rule"] == "sobol" and info["error_estimate"] == error_estimate(
        *(e2_qmc(CHAIN, h, REGION, nodes=info["n_points"])[k] for k in ("E2", "E2_half"))
    )
    box = {"x3": (0.4, 1.0), "x4": (0.3, 0.9)}
    assert functional_info("E1", CHAIN, h, box, {"x1": 0.0, "x2": 0.8})["error_estimate"] is None
    assert error_estimate(None, 1.0) is None and error_estimate(np.inf, 1.0) is None
