"""The damped, weighted and posture algorithms through /solve, /repeatability and /atlas."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from jik.app.compute.atlas_plan import AtlasLimits, planned
from jik.app.compute.atlas_schemas import AtlasRequest
from jik.engine.atlas_run import run_atlas
from tests.app.conftest import TABLE1_PATH, X0_M2, messages, solve_body
from tests.helpers import approx_tree


@pytest.mark.parametrize(
    ("algorithm", "params"),
    [("damped", {"damping": 0.2}), ("weighted", None), ("posture", {"gain": 0.5})],
)
def test_solve_runs_each_new_algorithm(api, algorithm, params):
    r = api.post("/solve", json=solve_body(algorithm=algorithm, algorithm_parameters=params))
    assert r.status_code == 200, r.text
    body = r.json()
    assert body["algorithm"] == algorithm
    assert body["converged"] and body["error"] < 1e-10


def test_repeatability_posture_drifts_less_than_the_pseudoinverse(api):
    def drift(algorithm, params=None):
        r = api.post(
            "/repeatability",
            json={
                "robot": {"name": "manipulator2"},
                "algorithm": algorithm,
                "x0": X0_M2,
                "path": TABLE1_PATH,
                "cycles": 10,
                "algorithm_parameters": params,
            },
        )
        assert r.status_code == 200, r.text
        return r.json()["drift"][-1], r.json()["repeatable"]

    plain, plain_ok = drift("pseudoinverse")
    posture, posture_ok = drift("posture", {"gain": 1.0})
    assert posture < 0.1 * plain and posture > 1e-12
    assert not plain_ok and not posture_ok


def test_robots_list_every_algorithm(api):
    body = api.get("/robots").json()
    names = ["pseudoinverse", "extended", "damped", "weighted", "posture"]
    assert body["robots"][0]["algorithms"] == names
    assert [a["name"] for a in body["algorithms"]] == names
    damped = body["algorithms"][2]
    assert [p["name"] for p in damped["parameters"]] == ["damping", "damping_threshold"]
    assert damped["parameters"][0]["maximum"] == 10.0 and "Nakamura" in damped["source"]


@pytest.mark.parametrize(
    ("algorithm", "params", "loc", "text"),
    [
        ("damped", {"damping": -1.0}, ["algorithm_parameters", "damping"], "greater than or equal"),
        ("damped", {"gain": 1.0}, ["algorithm_parameters", "gain"], "unknown parameter(s)"),
        (
            "posture",
            {"rest": [0.0, 1.0]},
            ["algorithm_parameters", "rest"],
            "rest: must have shape",
        ),
        ("weighted", {"limits": [[1.0, 0.0]] * 3}, ["algorithm_parameters", "limits"], "< high"),
        ("posture", {"speed": 1.0}, ["algorithm_parameters", "speed"], "unknown field"),
        ("newton", None, ["algorithm"], "Input should be"),
        ("extended", {"gain": 1.0}, ["algorithm_parameters"], "the extended inverse takes none"),
        ("pseudoinverse", {"damping": 0.1}, ["algorithm_parameters", "damping"], "unknown"),
    ],
)
def test_bad_parameters_are_422_naming_the_field(api, algorithm, params, loc, text):
    r = api.post("/solve", json=solve_body(algorithm=algorithm, algorithm_parameters=params))
    assert any(text in m for m in messages(r)), r.text
    got = [str(x) for x in r.json()["detail"][0]["loc"][1:]]
    assert got[: len(loc)] == loc, r.text


@pytest.mark.parametrize("algorithm", ["pseudoinverse", "damped", "weighted", "posture"])
def test_an_augmenting_map_given_to_another_algorithm_is_422(api, algorithm):
    """The map is the extended inverse's: given with another algorithm it was dropped silently
    (the response said augmentation null); it is refused as the extended inverse's
    algorithm_parameters are."""
    body = solve_body(algorithm=algorithm, augmentation={"name": "paper_cubic"})
    r = api.post("/solve", json=body)
    assert r.status_code == 422, r.text
    (said,) = r.json()["detail"]
    assert said["loc"] == ["body", "augmentation"]
    assert f"the {algorithm} inverse takes none (the extended inverse does)" in said["msg"]
    assert api.post("/solve", json=solve_body(algorithm=algorithm)).status_code == 200


def test_atlas_compares_algorithms_over_the_same_starts():
    req = AtlasRequest.model_validate(
        {
            "robot": {"name": "manipulator2"},
            "path": [[0.0, 1.0], *TABLE1_PATH[:3]],
            "starts": 5,
            "cycles": 2,
            "arc": [-1.0, 1.0],
            "algorithms": ["pseudoinverse", "damped", "posture"],
            "algorithm_parameters": {"damping": 0.5, "gain": 1.0},
        }
    )
    res = run_atlas(planned(req, AtlasLimits())[0])
    assert res.algorithms == ("pseudoinverse", "damped", "posture")
    drift = {a: res.drift[i] for i, a in enumerate(res.algorithms)}
    assert all(d.shape == (1, 5, 2) and np.isfinite(d).all() for d in drift.values())
    # the same starts, different algorithms: different drift (posture pulls toward its rest)
    assert abs(drift["damped"] - drift["pseudoinverse"]).max() > 1e-6
    assert abs(drift["posture"] - drift["pseudoinverse"]).max() > 1e-3


def test_posture_rest_defaults_to_the_runs_start(api):
    """Without rest, the posture inverse pulls toward the request's x0 (Manipulator 2 has no
    home): the same loop as with rest = x0 given, and not that of the catalogue's x0."""
    x0 = [0.2, -0.1, 1.2]

    def legs(params):
        r = api.post(
            "/repeatability",
            json={
                "robot": {"name": "manipulator2"},
                "algorithm": "posture",
                "x0": x0,
                "path": TABLE1_PATH,
                "cycles": 2,
                "algorithm_parameters": params,
            },
        )
        assert r.status_code == 200, r.text
        return r.json()["drift"]

    assert legs({"gain": 1.0}) == legs({"gain": 1.0, "rest": x0})
    assert legs({"gain": 1.0}) != legs({"gain": 1.0, "rest": X0_M2})


def test_batched_posture_runs_each_pull_toward_their_own_start():
    """Micro-batched /solve requests share one inverse: posture requests without a rest (whose
    rest is each one's x0 on Manipulator 2) batch only with equal starts, so each gets what it
    gets alone (a batch of two gave the second the first's rest)."""
    from jik.app.compute import schemas as S
    from jik.app.compute.requests import batch_key, solve_batch_json

    def req(x0, **params):
        body = {"robot": {"name": "manipulator2"}, "algorithm": "posture", "x0": x0}
        body |= {"target": [1.0, 1.5], "algorithm_parameters": params or None}
        return S.SolveRequest.model_validate(body)

    a, b = req([0.0, 0.0, 1.5707963]), req([0.3, 0.2, 1.2])
    assert batch_key(a) != batch_key(b)
    assert batch_key(req([0.0, 0.0, 1.5], rest=[0, 0, 1])) == batch_key(
        req([0.3, 0.2, 1.2], rest=[0, 0, 1])
    )
    (alone,) = solve_batch_json([b])
    assert json.loads(alone)["algorithm_parameters"] == {"gain": 1.0, "rest": [0.3, 0.2, 1.2]}


@pytest.mark.parametrize(
    ("algorithm", "params", "used"),
    [
        ("damped", {"damping": 0.2}, {"damping": 0.2, "damping_threshold": 0.0}),
        ("posture", {"gain": 0.5}, {"gain": 0.5, "rest": X0_M2}),
        ("weighted", None, {"limits": [[-3.0, 3.0], [-3.0, 3.0], [-math.pi, 2 * math.pi]]}),
        ("pseudoinverse", None, {}),
    ],
)
def test_a_response_says_which_parameters_the_inverse_used(api, algorithm, params, used):
    """Defaults filled in: posture's rest (Manipulator 2 has no home: the run's x0), weighted's
    limits (its configuration box), damped's threshold."""
    body = solve_body(algorithm=algorithm, algorithm_parameters=params)
    r = api.post("/solve", json=body)
    assert r.status_code == 200, r.text
    assert r.json()["algorithm_parameters"] == approx_tree(used)
    rep = {k: v for k, v in body.items() if k != "target"} | {"path": TABLE1_PATH, "cycles": 1}
    r = api.post("/repeatability", json=rep)
    assert r.status_code == 200, r.text
    assert r.json()["algorithm_parameters"] == approx_tree(used)


#: A planar RRR chain with joint limits and no home.
LIMITED = {"name": "planar_chain", "joints": "RRR", "lengths": [1, 0.8, 0.6]}
LIMITED["limits"] = [[-1, 1], [None, 1.2], [-3, 3]]
RRR_PATH = [[1.2, 1.0], [1.0, 1.2]]


@pytest.mark.parametrize(
    ("route", "body"),
    [
        ("/solve", {"x0": [0.3, 0.2, 0.3], "target": [1.2, 1.0]}),
        ("/repeatability", {"x0": [0.3, 0.2, 0.3], "path": RRR_PATH, "cycles": 1}),
        ("/atlas", {"path": RRR_PATH, "starts": 4, "cycles": 1}),
    ],
)
def test_a_rest_outside_the_joint_limits_is_refused_naming_its_coordinate(api, route, body):
    """The engine's rule, one for every run: a robot with joint limits takes a rest within them
    (422 at algorithm_parameters.rest[i], in the engine's words); a robot without limits
    takes any finite rest."""
    key = "algorithms" if route == "/atlas" else "algorithm"
    posture = {key: ["posture"] if route == "/atlas" else "posture"}
    bad = {**body, **posture, "robot": LIMITED, "algorithm_parameters": {"rest": [0, 2.5, 0]}}
    r = api.post(route, json=bad)
    assert messages(r) == [
        "algorithm_parameters.rest[1]: rest x2 must be at most 1.2 (the joint limits of the "
        "planar_chain), got 2.5"
    ]
    assert r.json()["detail"][0]["loc"] == ["body", "algorithm_parameters", "rest", 1]
    free = {k: v for k, v in LIMITED.items() if k != "limits"}
    ok = api.post(route, json={**bad, "robot": free})
    assert ok.status_code in (200, 202), ok.text
    if route == "/atlas":
        api.delete(f"/atlas/{ok.json()['id']}")


@pytest.mark.parametrize(
    ("limits", "used"),
    [
        ([[0.2, 1], [0, 2], [0, 2]], [[0.2, 1], [0, 2], [0, 2]]),
        (LIMITED["limits"], [[-1, 1], [-math.pi, 1.2], [-3, 3]]),
    ],
)
def test_the_weighted_inverse_defaults_to_a_chain_s_own_limits(api, limits, used):
    """A planar chain's ``limits`` are the weighted inverse's default (a side without a limit
    takes the chain's box x_range, [-pi, pi]), which keeps the run within them."""
    robot = {**LIMITED, "limits": limits}
    body = {"robot": robot, "algorithm": "weighted", "x0": [0.3, 1, 1], "cycles": 2}
    r = api.post("/repeatability", json=body | {"path": [[1, 1.3], [1, 1.7], [0.6, 1.7]]})
    assert r.status_code == 200, r.text
    np.testing.assert_allclose(r.json()["algorithm_parameters"]["limits"], used)
    if limits[0][0] == 0.2:
        assert r.json()["limits"] == {
            "within": True,
            "violation": None,
            "farthest": None,
            "ends_outside": False,
        }


@pytest.mark.parametrize(
    ("algorithm", "params", "known"),
    [("posture", {"damping": 0.1}, "['gain', 'rest']"), ("weighted", {"gain": 1}, "['limits']")],
)
def test_a_refused_parameter_names_every_parameter_the_algorithm_takes(
    api, algorithm, params, known
):
    r = api.post("/solve", json=solve_body(algorithm=algorithm, algorithm_parameters=params))
    assert messages(r)[0].endswith(f"known: {known}"), r.text


def test_the_default_rest_at_a_start_outside_the_limits_runs(api):
    """No rest given: the default (the start, the chain has no home) is not refused when the
    start is outside the limits; the run reports leaving them at the start. The same numbers
    given as the rest are refused."""
    x0 = [1.5, 0.2, 0.3]
    body = {"robot": LIMITED, "algorithm": "posture", "x0": x0, "path": RRR_PATH, "cycles": 1}
    r = api.post("/repeatability", json=body)
    assert r.status_code == 200, r.text
    assert r.json()["algorithm_parameters"]["rest"] == x0
    assert r.json()["limits"]["violation"]["cycle"] == 0
    given = api.post("/repeatability", json={**body, "algorithm_parameters": {"rest": x0}})
    assert messages(given)[0].startswith("algorithm_parameters.rest[0]: rest x1 must be in")


def test_a_panda_rest_outside_its_limits_is_refused_by_solve(api):
    pytest.importorskip("yourdfpy")
    from jik.engine.arms import ARMS

    home = list(ARMS["panda"].home)
    rest = [*home[:3], 0.0, *home[4:]]
    body = {"robot": {"name": "panda"}, "algorithm": "posture", "x0": home}
    body |= {"target": [0.3, 0.0, 0.5, 0.0, 0.0, 0.0], "algorithm_parameters": {"rest": rest}}
    assert messages(api.post("/solve", json=body)) == [
        "algorithm_parameters.rest[3]: rest x4 (panda_joint4) must be in [-3.0718, -0.0698] "
        "(the joint limits of the panda), got 0"
    ]


@pytest.mark.parametrize("route", ["/solve", "/repeatability"])
def test_a_wrong_start_for_posture_is_refused_at_x0(api, route):
    """The posture inverse's default rest is the start: a start of the wrong length is the
    start's fault (422 at x0, as for the pseudoinverse), not the rest's, which was not given."""
    chain = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}
    body = {"robot": chain, "algorithm": "posture", "x0": [0.3, 0.2]}
    body |= {"target": [1.2, 1.0]} if route == "/solve" else {"path": [[1.2, 1.0], [1.0, 1.2]]}
    r = api.post(route, json=body)
    assert r.status_code == 422, r.text
    assert [e["loc"] for e in r.json()["detail"]] == [["body", "x0"]]
