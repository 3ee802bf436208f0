"""POST /atlas of a catalogue arm with a pose task, of the same arm given as URDF text, and of the
robots a request defines: planned and run in the compute workers, equal to the engine's atlas of
the same request in this process, with the runs that leave the joint limits counted."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import TypeAdapter

from jik.app.compute.atlas_plan import AtlasLimits, planned, result_document
from jik.app.compute.atlas_schemas import AtlasBody
from jik.engine.arms import ARMS
from jik.engine.atlas_run import run_atlas
from jik.engine.robot_spec import robot_from_dict
from tests.app.conftest import messages
from tests.app.test_atlas_api import wait_until_ended
from tests.app.test_user_robots import M2_FORMULA

pytest.importorskip("yourdfpy")
PANDA = ARMS["panda"]
#: A closed loop of poses around the Panda's home: position [m] and rotation vector [rad].
MOVES = np.array(
    [[0, 0, 0, 0, 0, 0], [0.05, 0, 0, 0, 0, 0], [0.05, 0.05, 0, 0, 0, 0.1], [0, 0.05, 0, 0, 0, 0.1]]
)
#: A 3R planar chain whose third joint is limited to [0, 1.6]: some starts of the atlas below lie
#: outside, and the runs leave the limits differently under the two algorithms.
LIMITED = {
    "name": "planar_chain",
    "joints": "RRR",
    "lengths": [1.0, 0.8, 0.6],
    "limits": [[-3, 3], [-3, 3], [0.0, 1.6]],
}


def _panda_path() -> list[list[float]]:
    kin = robot_from_dict({"name": "panda", "task": "pose"}).kinematics
    return (kin.forward(np.array(PANDA.home)) + MOVES).tolist()


def _atlas(api, body: dict) -> dict:
    r = api.post("/atlas", json=body)
    assert r.status_code == 202, r.text
    done = wait_until_ended(api, r.json()["id"])
    assert done["status"] == "done", done["error"]
    return done["result"]


def _here(body: dict) -> dict:
    """The engine's atlas of the same request, in this process."""
    req = TypeAdapter(AtlasBody).validate_python(body)
    plan = planned(req, AtlasLimits())[0]
    res = run_atlas(plan, keep_leg_ends=bool(body.get("leg_ends")))
    return result_document(res, plan.manifolds[0].arc, bool(body.get("leg_ends")))


def _same(a: dict, b: dict, atol: float = 1e-12) -> None:
    assert a["algorithms"] == b["algorithms"] and a["outside_limits"] == b["outside_limits"]
    np.testing.assert_allclose(a["starts"], b["starts"], atol=atol)
    for alg in a["algorithms"]:
        np.testing.assert_allclose(
            np.array(a["drift"][alg], dtype=float),
            np.array(b["drift"][alg], dtype=float),
            atol=atol,
        )


def test_a_panda_pose_atlas_by_name_by_urdf_text_and_in_process_agree(api):
    """The pseudoinverse drifts on every start and the extended inverse of h = x3 does not; the
    arm by name, by URDF text and the engine here give the same atlas; no run leaves the limits."""
    body = {
        "robot": {"name": "panda", "task": "pose"},
        "path": _panda_path(),
        "starts": 4,
        "cycles": 2,
        "arc": [-0.5, 0.5],
        "algorithms": ["pseudoinverse", "extended"],
        "augmentation": {"name": "formula", "h": "x3"},
    }
    by_name = _atlas(api, body)
    text = {
        "name": "urdf",
        "urdf": PANDA.urdf,
        "end_link": PANDA.end_link,
        "home": list(PANDA.home),
        "task": "pose",
    }
    by_text = _atlas(api, {**body, "robot": text})
    _same(by_name, by_text)
    _same(by_name, _here(body))
    assert by_name["outside_limits"] == {"pseudoinverse": 0, "extended": 0}
    drift = {a: np.array(by_name["drift"][a], dtype=float) for a in by_name["algorithms"]}
    assert drift["pseudoinverse"].min() > 1e-3 and drift["extended"].max() < 1e-10


def test_outside_limits_counts_the_runs_whose_start_or_a_leg_end_leaves_them(api):
    body = {
        "robot": LIMITED,
        "path": [[1.0, 1.3], [1.0, 1.7], [0.6, 1.7]],
        "starts": 12,
        "cycles": 2,
        "arc": [-2.0, 2.0],
        "reference": [0.3, 1.0, 1.0],
        "leg_ends": True,
        "algorithms": ["pseudoinverse", "extended"],
        "augmentation": {"name": "formula", "h": "x3"},
    }
    res = _atlas(api, body)
    lo, hi = np.array(LIMITED["limits"], dtype=float).T
    starts = np.array(res["starts"][0])
    counts = {}
    for alg in res["algorithms"]:
        legs = np.array(res["leg_ends"][alg][0], dtype=float)  # (N, legs, p)
        with np.errstate(invalid="ignore"):
            out = ((legs < lo) | (legs > hi)).any(axis=(1, 2))
        counts[alg] = int((out | ((starts < lo) | (starts > hi)).any(axis=1)).sum())
    assert res["outside_limits"] == counts
    assert 0 < counts["extended"] < counts["pseudoinverse"] < 12
    _same(res, _here(body))


def test_a_formula_robot_atlas_runs_in_the_workers(api):
    """A formula robot's functions are generated again in the worker that runs a chunk."""
    body = {
        "robot": M2_FORMULA,
        "path": [[1.0, 1.0], [1.0, 2.0], [0.0, 2.0], [0.0, 1.0]],
        "starts": 5,
        "cycles": 2,
        "arc": [-1.0, 1.0],
        "reference": [0.0, 0.0, 1.5708],
        "algorithms": ["pseudoinverse", "extended"],
        "augmentation": {"name": "formula", "h": "x3"},
    }
    res = _atlas(api, body)
    assert res["outside_limits"] is None
    assert all(all(row) for a in res["algorithms"] for row in res["success"][a])
    _same(res, _here(body))


@pytest.mark.parametrize(
    ("over", "field", "text"),
    [
        (
            {"path": [[0.3, 0.0, 0.5], [0.3, 0.1, 0.5]]},
            "path[0]",
            "must have 6 components (this panda robot has p = 7, r = 6), got 3",
        ),
        (
            {"reference": [0.0, 0.1]},
            "reference",
            "must have 7 components (this panda robot has p = 7, r = 6), got 2",
        ),
        ({"robot": {"name": "panda", "task": "pose", "end_link": "x"}}, "robot", "end_link"),
    ],
)
def test_bad_arm_atlases_are_422_naming_the_field(api, over, field, text):
    body = {"robot": {"name": "panda", "task": "pose"}, "path": _panda_path(), "starts": 2, **over}
    r = api.post("/atlas", json=body)
    assert r.status_code == 422, r.text
    assert any(field in m and text in m for m in messages(r)), messages(r)
