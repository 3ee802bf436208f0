"""POST /synthesize with 'e2_total_degree': E2-optimal maps over any number of joints (a 7-joint
arm's), and h_1 ... h_(p-r) for p - r >= 2, as the engine gives them; 422s naming the field."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from jik.engine.e2_qmc import e1_qmc
from jik.engine.kernel_frame import best_frame_axes
from jik.engine.robot_spec import robot_from_dict
from jik.engine.synthesis_nd import synthesize_e2_nd
from jik.engine.total_degree import TotalDegreeMap
from tests.app.conftest import messages

REGION = {"x2": [-1.0, 1.0], "x3": [0.0, math.pi]}
PANDA = {"name": "panda", "task": "pose"}
RRRR = {"name": "planar_chain", "joints": "RRRR", "lengths": [0.5, 0.5, 0.5, 0.5]}


def _ok(api, body: dict) -> dict:
    r = api.post("/synthesize", json=body)
    assert r.status_code == 200, r.text
    return r.json()


def _engine(robot: dict, b: dict, degree: int, nodes: int, **kw):
    """The engine's synthesis of the same robot, box and rule, in this process."""
    kin = robot_from_dict(robot).kinematics
    region = {k: tuple(v) for k, v in b["region"].items()}
    return synthesize_e2_nd(kin, region, degree=degree, nodes=nodes, fixed=b["fixed"], **kw)


def test_manipulator2_agrees_with_the_tensor_ritz_minimum_within_1_percent(api):
    """On the box of the paper's figures, E2 = 1.8152 by the tensor Ritz method (degree 8)."""
    total = _ok(
        api,
        {
            "robot": {"name": "manipulator2"},
            "method": "e2_total_degree",
            "region": REGION,
            "degree": 8,
            "qmc_nodes": 4096,
        },
    )
    tensor = _ok(
        api,
        {
            "robot": {"name": "manipulator2"},
            "method": "e2_variational",
            "region": REGION,
            "degree": 8,
            "nodes": 12,
        },
    )
    e2, ritz = total["functionals"]["e2"]["value"], tensor["functionals"]["e2"]["value"]
    assert math.isclose(ritz, 1.8152, rel_tol=1e-4) and math.isclose(e2, ritz, rel_tol=0.01)
    assert total["augmentation"]["name"] == "e2_total_degree"
    by_degree = [row for row in total["convergence"] if row["nodes"] == 4096]
    by_nodes = [row for row in total["convergence"] if row["nodes"] < 4096]
    assert [row["degree"] for row in by_degree] == list(range(1, 9))
    assert [row["nodes"] for row in by_nodes] == [1024, 2048] and by_nodes[0]["degree"] == 8
    e2_by_degree = [row["e2"] for row in by_degree]
    assert all(a >= b - 1e-12 for a, b in itertools.pairwise(e2_by_degree))


def test_a_7_joint_arm_over_all_its_joints_is_the_engines_synthesis(api):
    b = _ok(
        api,
        {"robot": PANDA, "method": "e2_total_degree", "degree": 2, "qmc_nodes": 1024, "grid": 5},
    )
    assert len(b["region"]) == 7 and b["fixed"] == {}
    # the default box is the arm's design region, as /robots says and its e2_synthesized uses
    design = robot_from_dict(PANDA).spec.functional_region
    assert b["region"] == {n: list(v) for n, v in design.items()}
    info = b["total_degree"]
    ref = _engine(PANDA, b, 2, 1024, convergence_degrees=[1])
    assert math.isclose(info["e2"], ref.e2, rel_tol=1e-10)
    assert math.isclose(info["e2_check"], ref.e2_check, rel_tol=1e-10)
    assert info["unknowns"] == 35 and np.shape(info["coefficients"]) == (1, 35)
    np.testing.assert_allclose(
        info["coefficients"][0], ref.maps[0].coefficients, rtol=1e-8, atol=1e-10
    )
    e1 = e1_qmc(robot_from_dict(PANDA).kinematics, ref.maps[0], ref.region, fixed=ref.fixed)
    assert b["functionals"]["e1"]["rule"] == "sobol" and not e1["divergent"]
    assert math.isclose(b["functionals"]["e1"]["value"], e1["E1"], rel_tol=1e-9)
    assert set(info["single_joint"]) == set(b["region"])
    assert min(j["e2"] for j in info["single_joint"].values()) > info["e2"]
    # the grid is h of the basis and coefficients reported, on two of the box's axes
    amap = TotalDegreeMap(info["basis"], info["coefficients"][0], b["region"], range(7), 7)
    (a1, v1), (a2, v2) = b["grid"]["axes"].items()
    names = list(b["region"])
    x = np.broadcast_to([np.mean(b["region"][n]) for n in names], (5, 5, 7)).copy()
    x[..., names.index(a1)], x[..., names.index(a2)] = np.meshgrid(v1, v2, indexing="ij")
    np.testing.assert_allclose(b["grid"]["h"], amap.value(x), atol=1e-12)


def test_two_degrees_of_redundancy_give_two_maps(api):
    """A 4R planar chain with a position task (p - r = 2): h_1 and h_2, the kernel frame on the
    best-conditioned joints at the box's centre by default, as the engine gives them."""
    b = _ok(
        api, {"robot": RRRR, "method": "e2_total_degree", "degree": 3, "qmc_nodes": 1024, "grid": 5}
    )
    info = b["total_degree"]
    ref = _engine(RRRR, b, 3, 1024)
    best = best_frame_axes(robot_from_dict(RRRR).kinematics, ref.region, ref.fixed)
    assert np.shape(info["coefficients"]) == (2, 34) and info["frame_axes"] == best
    assert info["single_joint"] == {} and b["augmentation"]["parameters"]["maps"] == 2
    assert math.isclose(info["e2_check"], ref.e2_check, rel_tol=1e-10)
    # E1 of the two maps over the four joints, by the Sobol rule (E1 takes no frame): the
    # E2-optimal maps make [J; dh] singular inside this box (det(dh K) changes sign).
    e1 = e1_qmc(robot_from_dict(RRRR).kinematics, ref.maps, ref.region, fixed=ref.fixed)
    got = b["functionals"]["e1"]
    assert got["rule"] == "sobol" and got["n_points"] == 8192
    assert got["divergent"] is e1["divergent"] is True and got["value"] is None
    assert "E1 diverges" in b["message"] and b["functionals"]["e2"]["frame_axes"] == best
    other = _ok(
        api,
        {
            "robot": RRRR,
            "method": "e2_total_degree",
            "degree": 3,
            "qmc_nodes": 1024,
            "frame_axes": [3, 4],
        },
    )
    assert other["total_degree"]["frame_axes"] == [3, 4] != best
    assert other["total_degree"]["e2"] != info["e2"]


@pytest.mark.parametrize(
    ("body", "field", "text"),
    [
        ({"robot": PANDA, "qmc_nodes": 1000}, "qmc_nodes", "power of two"),
        ({"robot": PANDA, "degree": 12}, "degree", "lower the degree"),
        ({"robot": PANDA, "degree": 3, "qmc_nodes": 128}, "qmc_nodes", "at least twice"),
        ({"robot": RRRR, "frame_axes": [4, 4]}, "frame_axes", "2 distinct joints"),
        (
            {"robot": {"name": "manipulator2"}, "augmentation": {"name": "paper_cubic"}},
            "augmentation",
            "give no map",
        ),
        (
            {
                "robot": PANDA,
                "method": "e2_variational",
                "region": {f"x{i}": [-0.1, 0.1] for i in range(1, 5)},
            },
            "region",
            "'e2_total_degree' synthesizes h of any number",
        ),
    ],
)
def test_bad_total_degree_requests_are_422_naming_the_field(api, body, field, text):
    r = api.post("/synthesize", json={"method": "e2_total_degree", **body})
    assert any(m.startswith(f"{field}: ") and text in m for m in messages(r)), messages(r)


def test_a_requested_map_over_all_seven_joints_makes_the_pose_loop_repeatable(api):
    """``{"name": "e2_synthesized", "region": {7 joints}}`` as a request's map: the total-degree
    synthesis on that box; its extended inverse returns to x0 after every cycle. A total degree
    over 6 is a 422 naming augmentation.degree."""
    from tests.engine.test_synthesis_arms import STEPS

    panda = robot_from_dict(PANDA)
    home = np.array(panda.spec.default_x0)
    y0 = panda.kinematics.forward(home)
    box = {f"x{i + 1}": [home[i] - 0.2, home[i] + 0.2] for i in range(7)}
    body = {
        "robot": PANDA,
        "algorithm": "extended",
        "x0": home.tolist(),
        "cycles": 3,
        "path": [(y0 + np.array(step)).tolist() for step in STEPS],
        "augmentation": {"name": "e2_synthesized", "region": box, "degree": 2},
    }
    r = api.post("/repeatability", json=body)
    assert r.status_code == 200, r.text
    assert r.json()["success"] and r.json()["max_drift"] < 1e-9
    body["augmentation"]["degree"] = 9
    r = api.post("/repeatability", json=body)
    assert any(
        m.startswith("augmentation.degree: ") and "between 1 and 6" in m for m in messages(r)
    ), messages(r)
