"""POST /synthesize and GET /synthesize: maps on a grid, coefficients, E1 and E2."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from jik.engine.augmentations import E2Optimal, PaperCubic
from jik.engine.functionals import error_functional_e2
from jik.engine.kinematics import Manipulator1, Manipulator2

REGION = {"x2": [-1.0, 1.0], "x3": [0.0, math.pi]}


def test_methods_are_listed_with_notes(api):
    b = api.get("/synthesize").json()
    assert b["methods"] == ["evaluate", "e2_variational", "e2_total_degree"]
    assert "Ritz" in b["notes"]["e2_variational"]
    assert "Sobol" in b["notes"]["e2_total_degree"]


def test_evaluate_paper_cubic(api):
    body = {"robot": {"name": "manipulator2"}, "region": REGION, "nodes": 12, "grid": 11}
    r = api.post("/synthesize", json=body)
    assert r.status_code == 200, r.text
    b = r.json()
    assert b["method"] == "evaluate" and b["augmentation"]["name"] == "paper_cubic"
    assert b["coefficients"]["x2^1 x3^1"] == -0.7501
    assert b["fixed"] == {"x1": 0.0}
    axes = b["grid"]["axes"]
    assert list(axes) == ["x2", "x3"] and len(axes["x2"]) == 11
    h = np.array(b["grid"]["h"], dtype=float)
    x2, x3 = np.meshgrid(axes["x2"], axes["x3"], indexing="ij")
    x = np.stack([np.zeros_like(x2), x2, x3], axis=-1)
    np.testing.assert_allclose(h, PaperCubic().value(x), atol=1e-12)
    ref = error_functional_e2(Manipulator2(), PaperCubic(), REGION, nodes=12)
    assert math.isclose(b["functionals"]["e2"]["value"], ref.value, rel_tol=1e-12)
    assert b["functionals"]["e2"]["n_points"] == 144


def test_evaluate_manipulator1_map_picks_the_axes_where_h_varies(api):
    body = {
        "robot": {"name": "manipulator1"},
        "augmentation": {"name": "e2_optimal", "a": 0.5, "b": 1.0},
        "nodes": 6,
        "grid": 5,
    }
    b = api.post("/synthesize", json=body).json()
    assert b["augmentation"] == {"name": "e2_optimal", "parameters": {"a": 0.5, "b": 1.0}}
    assert set(b["region"]) == {"x1", "x2", "x3"}  # default: a box around the default start
    assert list(b["grid"]["axes"]) == ["x1", "x3"]  # h = x3 (a x1 + b) sqrt(1 + x1^2)
    x1, x3 = np.meshgrid(*b["grid"]["axes"].values(), indexing="ij")
    x = np.stack([x1, np.zeros_like(x1), x3], axis=-1)
    np.testing.assert_allclose(b["grid"]["h"], E2Optimal(0.5, 1.0).value(x), atol=1e-12)
    ref = error_functional_e2(Manipulator1(), E2Optimal(0.5, 1.0), b["region"], nodes=6)
    assert math.isclose(b["functionals"]["e2"]["value"], ref.value, rel_tol=1e-12)


def test_e2_variational_beats_the_printed_cubic(api):
    """The Ritz minimiser of E2 has lower E2 than (38) on the same box."""
    body = {
        "robot": {"name": "manipulator2"},
        "method": "e2_variational",
        "region": REGION,
        "degree": 8,
        "nodes": 12,
    }
    r = api.post("/synthesize", json=body)
    assert r.status_code == 200, r.text
    b = r.json()
    assert b["augmentation"]["name"] == "e2_synthesized"
    assert b["convergence"][-1]["degree"] == 8
    assert len(b["coefficients"]) == 10  # the least-squares cubic, like (38)
    cubic = api.post(
        "/synthesize", json={"robot": {"name": "manipulator2"}, "region": REGION, "nodes": 12}
    ).json()
    assert b["functionals"]["e2"]["value"] < cubic["functionals"]["e2"]["value"]


def test_e2_variational_defaults_to_the_engine_s_degree_and_reports_its_own_e2(api):
    """No degree: the engine's default over two variables (16), and the headline E2 is the
    value minimised (the convergence's last), on the synthesis's own rule, not on the 8 nodes
    that leave it 3e-5 off."""
    from jik.engine.variational import MANIPULATOR2_REGION, synthesize_e2

    body = {"robot": {"name": "manipulator2"}, "method": "e2_variational"}
    r = api.post("/synthesize", json=body | {"region": REGION})
    assert r.status_code == 200, r.text
    b = r.json()
    assert b["convergence"][-1]["degree"] == 16
    e2 = synthesize_e2(Manipulator2(1.0), MANIPULATOR2_REGION).e2
    assert b["convergence"][-1]["e2"] == pytest.approx(e2, abs=1e-12)
    assert b["functionals"]["e2"]["value"] == pytest.approx(e2, abs=1e-12)


def test_e2_variational_shows_e2_against_the_degree_as_the_python_synthesis_does(api):
    """'convergence' is E2 against the Legendre degree (its description), as e2_total_degree's
    and synthesize_e2's convergence_degrees give it: it held the requested degree alone."""
    from jik.engine.variational import synthesize_e2

    body = {"robot": {"name": "manipulator2"}, "method": "e2_variational", "region": REGION}
    r = api.post("/synthesize", json=body | {"degree": 8})
    assert r.status_code == 200, r.text
    rows = r.json()["convergence"]
    box = {k: tuple(v) for k, v in REGION.items()}
    own = synthesize_e2(Manipulator2(1.0), box, degree=8, convergence_degrees=(2, 4, 6))
    assert [row["degree"] for row in rows] == [2, 4, 6, 8]
    assert [row["unknowns"] for row in rows] == [9, 25, 49, 81]
    np.testing.assert_allclose([row["e2"] for row in rows], own.columns()["e2"], rtol=1e-12)
    assert rows[0]["e2"] > rows[1]["e2"] > rows[2]["e2"] > rows[3]["e2"]


def test_default_frame_axes_are_the_best_conditioned_as_the_schema_says(api):
    """Without frame_axes a p - r = 2 synthesis takes the joints best conditioned at the box's
    centre (here 2 and 4, not the last two); the field's description said 'the last p - r'."""
    from jik.engine.kernel_frame import best_frame_axes
    from jik.engine.robot_spec import robot_from_dict

    robot = {"name": "formula", "variables": ["a", "b", "c", "d"]}
    robot["task"] = [f"{f}(a)+{f}(a+b)+{f}(a+b+c)+0.7*{f}(a+b+c+d)" for f in ("cos", "sin")]
    box = {"a": [-0.3, 0.3], "b": [0.5, 1.1], "c": [0.4, 1.0], "d": [0.3, 0.9]}
    body = {"robot": robot, "method": "e2_total_degree", "region": box, "degree": 2}
    r = api.post("/synthesize", json=body | {"qmc_nodes": 256})
    assert r.status_code == 200, r.text
    kin = robot_from_dict(robot).kinematics
    best = best_frame_axes(kin, {k: tuple(v) for k, v in box.items()}, {})
    assert r.json()["total_degree"]["frame_axes"] == best == [2, 4]
    field = api.get("/openapi.json").json()["components"]["schemas"]["SynthesizeFormulaRequest"]
    described = field["properties"]["frame_axes"]["description"]
    assert "best conditioned" in described and "last p - r" not in described


def test_evaluate_takes_a_vector_of_maps_and_names_the_frame_of_e2(api):
    """A planar 4R chain with a position task (p - r = 2) and two formula maps: E1 and E2 as the
    engine gives them, E2 in the best-conditioned frame or the one asked for; frame_axes wrong
    is a 422 at its field."""
    from jik.engine.formula_kinematics import FormulaMap
    from jik.engine.functionals import error_functional_e1
    from jik.engine.planar_chain import PlanarChain

    h = ["x3 + 0.1*x1**2", "x4 - 0.2*sin(x2)"]
    box = {"x2": [0.3, 1.2], "x3": [0.4, 1.3], "x4": [0.2, 1.0]}
    body = {
        "robot": {"name": "planar_chain", "joints": "RRRR", "lengths": [1.0] * 4},
        "method": "evaluate",
        "augmentation": {"name": "formula", "h": h},
        "region": box,
        "fixed": {"x1": 0.0},
    }
    kin = PlanarChain("RRRR", [1.0] * 4)
    maps = [FormulaMap(f, kin.names) for f in h]
    for axes in (None, [3, 4]):
        r = api.post("/synthesize", json=body | ({"frame_axes": axes} if axes else {}))
        assert r.status_code == 200, r.text
        b = r.json()
        e2 = error_functional_e2(kin, maps, box, nodes=8, fixed={"x1": 0.0}, frame_axes=axes)
        assert b["functionals"]["e2"]["value"] == e2.value
        assert b["functionals"]["e2"]["frame_axes"] == list(e2.frame_axes) == (axes or [2, 4])
        assert b["functionals"]["e1"]["value"] == error_functional_e1(kin, maps, box, nodes=8).value
        assert (
            f"E2 in the kernel frame of joints {e2.frame_axes and list(e2.frame_axes)}"
            in (b["message"])
        )
        assert "2 maps h_1 ... h_2; the grid shows h_1" in b["message"]
        assert b["singularities_searched"] is False and list(b["grid"]["axes"]) == ["x2", "x3"]
    m2 = {"robot": {"name": "manipulator2"}}  # (p - r = 1: its frame is its kernel vector)
    for request, words in (
        (body | {"frame_axes": [3, 3]}, "must name 2 distinct joints"),
        (body | {"frame_axes": [3, 9]}, "between 1 and 4"),
        (m2 | {"frame_axes": [2, 3]}, "is its kernel vector"),
        (m2 | {"frame_axes": [1], "method": "e2_total_degree", "degree": 2}, "kernel vector"),
    ):
        r = api.post("/synthesize", json=request)
        assert r.status_code == 422, r.text
        detail = r.json()["detail"][0]
        assert detail["loc"] == ["body", "frame_axes"] and words in detail["msg"]


def test_evaluate_over_every_joint_of_an_arm_takes_the_sobol_rule_as_the_dashboard(api):
    """The Panda's pose task and h = x1 over its seven joints: E1 and E2 by the Sobol rule, the
    numbers the engine's report (the dashboard's E1/E2 panel) gives on the same box;
    'e2_variational' is still refused past three variables."""
    from jik.engine.formula_kinematics import FormulaMap
    from jik.engine.functional_report import functionals_report
    from jik.engine.robot_spec import robot_from_dict

    arm, h = {"name": "panda", "task": "pose"}, {"name": "formula", "h": "x1"}
    kin = robot_from_dict(arm).kinematics
    box = {n: [x - 0.3, x + 0.3] for n, x in zip(kin.names, kin.home, strict=True)}
    body = {"robot": arm, "method": "evaluate", "augmentation": h, "region": box}
    r = api.post("/synthesize", json=body)
    assert r.status_code == 200, r.text
    f = r.json()["functionals"]
    want = functionals_report(kin, FormulaMap("x1", kin.names), box, {})
    assert f["e1"]["value"] == want["E1"] and f["e2"]["value"] == want["E2"]
    assert f["e1"]["rule"] == f["e2"]["rule"] == "sobol" and f["e1"]["n_points"] == 8192
    for k in ("e1", "e2"):  # (the same error estimates; the Gauss rule's is null)
        assert f[k]["error_estimate"] == want[f"{k.upper()}_error_estimate"] > 0
    small = {**body, "region": dict(list(box.items())[:2])}
    r = api.post("/synthesize", json=small)
    assert r.status_code == 200 and r.json()["functionals"]["e1"]["error_estimate"] is None
    r = api.post("/synthesize", json={"robot": arm, "method": "e2_variational", "region": box})
    assert r.status_code == 422 and "takes 2 or 3 variables, got 7" in r.text


def test_evaluate_takes_e2_of_a_synthesized_vector_in_the_frame_it_was_synthesized_in(api):
    """A vector synthesized in the kernel frame of joints 3, 4 minimises E2 in that frame (0.113);
    in the best-conditioned one (2, 4) its E2 is 13.3, above two formula maps' 9.57. 'evaluate'
    takes its frame unless the request names another."""
    box = {"x2": [0.3, 1.2], "x3": [0.4, 1.3], "x4": [0.2, 1.0]}
    body = {
        "robot": {"name": "planar_chain", "joints": "RRRR", "lengths": [1.0] * 4},
        "method": "evaluate",
        "augmentation": {"name": "e2_synthesized", "region": box, "frame_axes": [3, 4]},
        "region": box,
        "fixed": {"x1": 0.0},
    }
    e2 = {}
    for axes in (None, [3, 4], [2, 4]):
        r = api.post("/synthesize", json=body | ({"frame_axes": axes} if axes else {}))
        assert r.status_code == 200, r.text
        e2[str(axes)] = r.json()["functionals"]["e2"]
    assert e2["None"] == e2["[3, 4]"] and e2["None"]["frame_axes"] == [3, 4]
    assert e2["[2, 4]"]["frame_axes"] == [2, 4] and e2["[2, 4]"]["value"] > 10 * e2["None"]["value"]


def test_evaluate_says_e2_is_undefined_where_a_map_is(api):
    """h_2 = sqrt(x4 - 0.5) is undefined on part of the box: E1 and E2 are null (no dh is made
    up there, no point left out) and the message says why."""
    body = {
        "robot": {"name": "planar_chain", "joints": "RRRR", "lengths": [1.0] * 4},
        "method": "evaluate",
        "augmentation": {"name": "formula", "h": ["x3", "sqrt(x4 - 0.5)"]},
        "region": {"x2": [0.3, 1.2], "x3": [0.4, 1.3], "x4": [0.2, 1.0]},
        "fixed": {"x1": 0.0},
    }
    r = api.post("/synthesize", json=body)
    assert r.status_code == 200, r.text
    b = r.json()
    assert b["functionals"]["e2"]["value"] is None and b["functionals"]["e2"]["n_singular"] > 0
    assert b["functionals"]["e1"]["value"] is None and not b["functionals"]["e1"]["divergent"]
    assert "E1 undefined: h is not defined on all of the region" in b["message"]
    assert "E2 undefined: h is not defined on all of the region" in b["message"]


def test_synthesize_bad_input(api):
    def msg(body):
        r = api.post("/synthesize", json=body)
        assert r.status_code == 422, r.text
        detail = r.json()["detail"][0]
        return f"{'.'.join(map(str, detail['loc'][1:]))} | {detail['msg']}"

    m2 = {"name": "manipulator2"}
    assert msg({"robot": m2, "region": {"x7": [0, 1], "x2": [0, 1]}}).startswith(
        "region.x7 | region.x7: Input should be 'x1', 'x2' or 'x3'"
    )
    # The engine's refusals of a built-in robot's box (before the request is queued) and of a
    # user's robot's (in a worker) alike: at their field, the message led by it, as the app's.
    chain = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 1.0, 1.0]}
    for robot in (m2, chain):
        assert msg({"robot": robot, "region": {"x2": [1, 0], "x3": [0, 1]}}) == (
            "region.x2 | region.x2: must have lo < hi within +-100, got (1.0, 0.0)"
        )
        assert msg({"robot": robot, "region": REGION, "fixed": {"x2": 0.0}}) == (
            "fixed.x2 | fixed.x2: variables ['x2'] are both integrated over and fixed"
        )
    assert msg({"robot": m2, "grid": 1000}).startswith("grid | grid: Input should be less than")
    assert msg({"robot": m2, "method": "magic"}).startswith("method | method: Input should be")
    three = {"x1": [0, 1], "x2": [0, 1], "x3": [0, 1]}  # (at most 16 per variable over three)
    assert msg({"robot": m2, "method": "e2_variational", "region": three, "degree": 17}) == (
        "degree | degree: degree must be between 1 and 16, got 17"
    )


def test_fixed_values_and_a_formula_robot_s_constants_are_coordinates_within_1000(api):
    """A value the kinematics only overflow on is refused naming its field, as x0's is."""
    body = {"robot": {"name": "manipulator1"}, "augmentation": {"name": "e2_optimal", "a": 1}}
    body |= {"region": {"x2": [-1, 1], "x3": [-1, 1]}, "fixed": {"x1": 1e300}}
    r = api.post("/synthesize", json=body)
    assert r.status_code == 422, r.text
    assert r.json()["detail"][0]["loc"][1:] == ["fixed", "x1"]
    assert "less than or equal to 1000" in r.json()["detail"][0]["msg"]
    formula = {"name": "formula", "variables": ["x1", "x2", "x3"], "parameters": {"l": 1e300}}
    formula["task"] = ["x2 + l*cos(x3)", "x1 + l*sin(x3)"]
    solve = {"robot": formula, "x0": [0.1, 0.2, 0.3], "target": [1.0, 1.0]}
    r = api.post("/solve", json=solve)
    assert r.status_code == 422, r.text
    assert r.json()["detail"][0]["loc"][1:] == ["robot", "parameters", "l"]


M1_REGION = {"x1": [0.0, 1.0], "x2": [0.0, 1.0], "x3": [0.5, 1.5]}


def test_a_map_singular_in_its_box_says_where(api):
    """(32) with C2 = -1: g(x1) vanishes at x1* = 0.479 (h through a pole, for any x2, x3);
    the response's ``singularities`` say where on a grid of ``nodes`` points per variable, why,
    and the message too.
    (36) on the same box is regular: null."""
    x1 = brentq(lambda t: t * np.sqrt(1 + t * t) + np.arcsinh(t) - 1.0, 0.0, 1.0)
    body = {
        "robot": {"name": "manipulator1"},
        "augmentation": {"name": "e1_optimal", "C1": 1.0, "C2": -1.0},
        "region": M1_REGION,
        "nodes": 12,
        "grid": 5,
    }
    r = api.post("/synthesize", json=body)
    assert r.status_code == 200, r.text
    found = r.json()["singularities"]
    lo, hi = found["where"]["x1"]
    assert lo < x1 < hi and hi - lo == pytest.approx(1 / 11)
    assert found["where"]["x2"] == [0.0, 1.0] and found["where"]["x3"] == [0.5, 1.5]
    assert found["fraction"] == pytest.approx(2 / 12) and found["nodes"] == 12
    assert "h jumps through infinity" in found["reasons"]
    assert (
        f"h is singular in the box: {'; '.join(found['reasons'])} at x1 ∈ [0.455, 0.545], any "
        "x2, any x3 (288 of the 12^3 grid points)" in r.json()["message"]
    )
    regular = api.post(
        "/synthesize", json={**body, "augmentation": {"name": "e2_optimal", "a": 0.5, "b": 1.0}}
    ).json()
    assert "singularities" in regular and regular["singularities"] is None
    assert regular["message"] == "ok"


def test_a_synthesized_map_is_searched_and_a_vector_of_maps_is_said_not_to_be(api):
    """The Ritz minimiser of E2 on Manipulator 2's design region is regular there; a 4R chain's
    pair of maps (p - r = 2) is not one h: null, and the message says why."""
    body = {"robot": {"name": "manipulator2"}, "method": "e2_variational", "region": REGION}
    b = api.post("/synthesize", json={**body, "degree": 6, "nodes": 8}).json()
    assert b["singularities"] is None and "singularities" not in b["message"]
    assert b["singularities_searched"] is True
    chain = {"name": "planar_chain", "joints": "RRRR", "lengths": [1.0] * 4}
    body = {"robot": chain, "method": "e2_total_degree", "degree": 2, "qmc_nodes": 256}
    b = api.post("/synthesize", json=body).json()
    assert b["singularities"] is None and b["singularities_searched"] is False
    assert "singularities of h not searched: h is a vector of maps" in b["message"]


def test_a_map_that_solves_a_problem_per_point_is_not_searched(api):
    """The unicycle's characteristics map solves a collocation problem (28) for each value:
    the search on a grid would cost seconds more than E1 and E2, so it is skipped and said."""
    b = api.post("/synthesize", json={"robot": {"name": "unicycle"}, "nodes": 2, "grid": 3}).json()
    assert b["augmentation"]["name"] == "characteristics"
    assert b["singularities"] is None and b["singularities_searched"] is False
    assert "singularities of h not searched: each value of h solves a problem" in b["message"]


def test_the_singularities_field_is_documented(api):
    schemas = api.get("/openapi.json").json()["components"]["schemas"]
    field = schemas["SynthesizeResponse"]["properties"]["singularities"]
    assert "null when h is regular" in field["description"]
    assert "singularities" in schemas["SynthesizeResponse"]["required"]
    info = schemas["MapSingularitiesInfo"]["properties"]
    assert set(info) == {"where", "fraction", "reasons", "nodes"}


def test_a_urdf_arm_with_huge_limits_synthesizes_over_a_box_within_the_bound(api):
    """Limits of +-1e200 (an arm "without" limits) made the default box +-2e199 wide and the
    Ritz solve's matrices not finite (HTTP 500): the default box keeps within the engine's
    region bound, and an explicit region beyond it is refused at its field."""
    joint = (
        '<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{j}"/>'
        '<origin xyz="1 0 0"/><axis xyz="0 0 1"/><limit lower="-1e200" upper="1e200"/></joint>'
    )
    urdf = (
        '<robot name="a">'
        + "".join(f'<link name="l{i}"/>' for i in range(4))
        + "".join(joint.format(i=i, j=i + 1) for i in range(3))
        + "</robot>"
    )
    robot = {"name": "urdf", "end_link": "l3", "task": "xy", "urdf": urdf}
    body = {"robot": robot, "method": "e2_variational", "degree": 4, "nodes": 12}
    r = api.post("/synthesize", json=body)
    assert r.status_code == 200, r.text
    assert all(-100 <= lo < hi <= 100 for lo, hi in r.json()["region"].values())
    r = api.post("/synthesize", json={**body, "region": {"x2": [-1e3, 1], "x3": [0, 1]}})
    assert r.status_code == 422 and r.json()["detail"][0]["loc"][1:3] == ["region", "x2"]
