"""POST /atlas, GET /atlas/{id}, DELETE /atlas/{id}: atlas jobs through the API."""

from __future__ import annotations

import math
import re
import time
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

from jik.app.compute.atlas_jobs import AtlasJobNotFound, AtlasJobs, AtlasJobsFull, PoolBackend
from jik.app.compute.atlas_plan import AtlasLimits, planned
from jik.app.compute.atlas_schemas import AtlasRequest
from jik.app.compute.exceptions import RequestError
from jik.app.compute.pool import pool_in_thread
from jik.app.compute.schemas import MAX_ITERATIONS_CAP
from jik.app.compute.settings import Settings
from jik.app.dashboard.controls import MIN_ITERATIONS
from jik.engine.atlas_run import run_atlas
from jik.engine.registry import robot_spec
from tests.app.conftest import messages

LOOP = [[0.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]]


def body(**over) -> dict:
    b = {
        "robot": {"name": "manipulator2"},
        "path": LOOP,
        "starts": 6,
        "cycles": 2,
        "arc": [-2.0, 2.0],
    }
    b.update(over)
    return b


#: Large enough to be running when it is cancelled (about a minute of work on one core).
LONG = body(starts=20000, cycles=5, arc=None)


#: The atlas jobs of each test's app (tests/app/conftest.py's ``app``).
ATLAS_LIMITS = AtlasLimits(max_jobs=3, per_client=1)


@pytest.fixture
def client(app):
    return TestClient(app)


def wait_until_ended(client, job_id: str, limit: float = 300.0) -> dict:
    """Poll the job until it leaves queued/running (the limit only guards against a hang)."""
    end = time.monotonic() + limit
    while time.monotonic() < end:
        r = client.get(f"/atlas/{job_id}")
        assert r.status_code == 200, r.text
        if r.json()["status"] not in ("queued", "running"):
            return r.json()
        time.sleep(0.2)
    raise AssertionError(f"job {job_id} still running after {limit} s")


def test_a_job_runs_to_its_result_and_outlives_its_request(app, client):
    """202 with an id and a Location; another connection reads the result, which is the
    engine's atlas of the same request (both algorithms, leg ends) to 1e-12."""
    req = body(algorithms=["pseudoinverse", "extended"], leg_ends=True)
    r = client.post("/atlas", json=req)
    assert r.status_code == 202, r.text
    job = r.json()
    assert r.headers["location"] == f"/atlas/{job['id']}"
    assert job["status"] in ("queued", "running") and job["runs"] == 6
    # the robot and map used, as a run's response names them
    run = {
        "robot": req["robot"],
        "algorithm": "extended",
        "path": LOOP,
        "cycles": 1,
        "x0": [0.0, 0.0, 1.5],
    }
    rep = client.post("/repeatability", json=run).json()
    assert job["robot"] == rep["robot"] and job["augmentation"] == rep["augmentation"]
    assert job["robot"]["name"] == "manipulator2" and job["augmentation"]["name"]
    done = wait_until_ended(TestClient(app), job["id"])
    assert done["robot"] == job["robot"] and done["augmentation"] == job["augmentation"]
    assert done["status"] == "done", done["error"]
    assert done["progress"] == 1.0 and done["runs_done"] == 6
    res = done["result"]
    expected = run_atlas(planned(AtlasRequest.model_validate(req), AtlasLimits())[0])
    np.testing.assert_allclose(res["starts"], expected.starts, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res["parameter"], np.linspace(-2, 2, 6), rtol=0, atol=1e-15)
    for a, alg in enumerate(("pseudoinverse", "extended")):
        drift = np.array(res["drift"][alg], dtype=float)
        np.testing.assert_allclose(drift, expected.drift[a], rtol=0, atol=1e-12)
        np.testing.assert_allclose(
            np.array(res["leg_ends"][alg], dtype=float), expected.leg_ends[a], rtol=0, atol=1e-12
        )
    assert np.min(res["drift"]["pseudoinverse"]) > 1e-3
    assert np.nanmax(np.array(res["drift"]["extended"], dtype=float)) < 1e-8


def test_delete_cancels_a_running_job_and_forgets_it(client):
    job = client.post("/atlas", json=LONG).json()
    assert client.delete(f"/atlas/{job['id']}").status_code == 204
    r = client.get(f"/atlas/{job['id']}")
    assert r.status_code == 404
    assert "no atlas job" in r.json()["detail"]
    # the client's slot is free again
    again = client.post("/atlas", json=body())
    assert again.status_code == 202, again.text


def test_a_job_past_its_time_limit_fails_and_says_so(app, client):
    """An atlas computes for at most the limits' max_seconds (its legs may each take up to
    max_iterations steps, which the bound on legs does not count): then it fails, naming
    starts and the runs done, and the client's slot is free again."""
    app.state.atlas_jobs = AtlasJobs(AtlasLimits(per_client=1, max_seconds=0.5))
    try:
        job = client.post("/atlas", json=LONG).json()
        done = wait_until_ended(client, job["id"])
        assert done["status"] == "failed" and done["result"] is None
        assert re.fullmatch(
            r"starts: the atlas reached the server's time limit of 0\.5 s after \d+ of 20000 "
            r"runs; ask for fewer starts or cycles or a lower max_iterations \(or run `jik "
            r"atlas` for larger atlases\)",
            done["error"],
        ), done["error"]
        assert done["runs_done"] < 20000
        assert client.post("/atlas", json=body()).status_code == 202
    finally:
        app.state.atlas_jobs.close()


def test_one_client_may_run_one_job_at_a_time_here(client):
    first = client.post("/atlas", json=LONG).json()
    r = client.post("/atlas", json=body())
    assert r.status_code == 429
    assert r.headers["retry-after"] == "10"
    assert "at most 1 atlas jobs per client" in r.json()["detail"]
    client.delete(f"/atlas/{first['id']}")


@pytest.mark.parametrize(
    ("over", "field", "text"),
    [
        ({"starts": 20001}, "starts", "less than or equal to 20000"),
        (
            {"starts": 20000, "cycles": 50, "algorithms": ["pseudoinverse", "extended"]},
            "starts",
            "legs x algorithms = 8000000 is more than 1200000",
        ),
        (
            {"starts": 20000, "cycles": 3, "leg_ends": True},
            "leg_ends",
            "the ends of 240000 legs are more than the 200000",
        ),
        (
            {"path": [[0.0, 1.0], [1.0, 1.0, 2.0]]},
            "path",
            "must have 2 components (r of manipulator2), got 3",
        ),
        ({"arc": [1.0, 2.0]}, "arc", "lo <= 0 <= hi"),
        ({"path": [[0.0, 1.0]]}, "path", "give at least 2 entries, got 1"),
        ({"mode": "discrete", "gamma": 2.0}, "gamma", "must be < 2 in discrete mode"),
    ],
)
def test_bad_or_too_large_requests_are_422_naming_the_field(client, over, field, text):
    r = client.post("/atlas", json=body(**over))
    assert any(text in m for m in messages(r)), r.text
    assert r.json()["detail"][0]["loc"][1] == field


@pytest.mark.parametrize(
    ("over", "loc", "text"),
    [
        ({"algorithms": ["weighted"], "algorithm_parameters": {"gain": 2}}, "gain", "unknown"),
        (
            {"algorithms": ["pseudoinverse"], "algorithm_parameters": {"rest": [0, 1, 0]}},
            "rest",
            "unknown parameter 'rest' for the algorithms ['pseudoinverse']; known: none",
        ),
        (
            {"algorithms": ["damped", "posture"], "algorithm_parameters": {"rest": [0, 1]}},
            "rest",
            "rest: must have shape",
        ),
    ],
)
def test_an_atlas_refuses_parameters_as_a_solve_does(client, over, loc, text):
    """A parameter belongs to at least one chosen algorithm, whose check its value passes."""
    r = client.post("/atlas", json=body(**over))
    assert any(text in m for m in messages(r)), r.text
    assert r.json()["detail"][0]["loc"][1:] == ["algorithm_parameters", loc]


def test_the_work_of_a_two_point_closed_path_is_counted_as_the_engine_runs_it():
    """A two-point path whose ends meet keeps both points: two legs a cycle, not one."""
    two = body(path=[[0.0, 1.0], [0.0, 1.0]], starts=5, algorithms=["extended"])
    with pytest.raises(RequestError, match=re.escape("= 20 is more than 15")):
        planned(AtlasRequest.model_validate(two), AtlasLimits(max_work=15))[0]


def test_unknown_job_is_404(client):
    assert client.get("/atlas/nope").status_code == 404
    assert client.delete("/atlas/nope").status_code == 404


def test_ended_jobs_are_dropped_after_keep_for():
    jobs = AtlasJobs(AtlasLimits(keep_for=0.0))
    req = AtlasRequest.model_validate(body(starts=2, cycles=1))
    job = jobs.start("me", req, planned(req, jobs.limits))
    end = time.monotonic() + 300
    while job.ended is None and time.monotonic() < end:
        time.sleep(0.1)
    assert job.status == "done"
    with pytest.raises(AtlasJobNotFound):
        jobs.get(job.id)


def test_a_full_table_of_jobs_drops_the_one_that_ended_first():
    """A script that ran atlases one after another, each to its end, got 429 "retry when one has
    ended and expired" on the job after max_jobs, for keep_for seconds (600), whatever its
    Retry-After (10 s) said, and so did every other client: now the job that ended first makes
    room once kept ``min_keep`` seconds (another client's result that has just ended is not
    taken from under it), and only a table of queued or running jobs is full."""
    req = AtlasRequest.model_validate(body(starts=2, cycles=1))
    kept = AtlasJobs(AtlasLimits(max_jobs=1))
    try:
        first = kept.start("me", req, planned(req, kept.limits))
        end = time.monotonic() + 300
        while first.ended is None and time.monotonic() < end:
            time.sleep(0.05)
        with pytest.raises(AtlasJobsFull, match="at most 1 atlas jobs queued or running"):
            kept.start("you", req, planned(req, kept.limits))
        assert kept.get(first.id).status == "done"
    finally:
        kept.close()
    jobs = AtlasJobs(AtlasLimits(max_jobs=2, per_client=2, min_keep=0.0))
    started = []
    for _ in range(3):
        started.append(jobs.start("me", req, planned(req, jobs.limits)))
        end = time.monotonic() + 300
        while started[-1].ended is None and time.monotonic() < end:
            time.sleep(0.05)
    with pytest.raises(AtlasJobNotFound, match="room"):
        jobs.get(started[0].id)
    assert [jobs.get(j.id).status for j in started[1:]] == ["done", "done"]
    long = AtlasRequest.model_validate(LONG)
    plan = planned(long, jobs.limits)
    running = [jobs.start(client, long, plan) for client in ("a", "b")]
    try:
        with pytest.raises(AtlasJobsFull, match="at most 2 atlas jobs queued or running"):
            jobs.start("c", req, planned(req, jobs.limits))
    finally:
        jobs.close()
    assert all(j.cancel.is_set() for j in running)


def test_the_sessions_of_one_address_hold_at_most_per_address_jobs():
    """A session is a client of its own (per_client each), but the sessions of one address hold
    at most per_address jobs together: one address opening many tabs cannot take every slot."""
    jobs = AtlasJobs(AtlasLimits(max_jobs=8, per_client=1, per_address=3))
    long = AtlasRequest.model_validate(LONG)
    plan = planned(long, jobs.limits)
    try:
        for k in range(3):
            jobs.start("10.0.0.1", long, plan, session=f"tab{k}")
        with pytest.raises(AtlasJobsFull, match="at most 3 atlas jobs of one address"):
            jobs.start("10.0.0.1", long, plan, session="tab3")
        jobs.start("10.0.0.2", long, plan, session="other")
        with pytest.raises(AtlasJobsFull, match="at most 1 atlas jobs per client"):
            jobs.start("10.0.0.2", long, plan, session="other")
    finally:
        jobs.close()


def test_reference_must_be_a_configuration(client):
    r = client.post("/atlas", json=body(reference=[0.0, math.pi / 2]))
    assert "reference: must have 3 components (p of manipulator2), got 2" in messages(r)


def _session(client, **state) -> str:
    r = client.post("/api/sessions", json={"state": state})
    assert r.status_code == 201, r.text
    return r.json()["id"]


def test_a_session_atlas_is_the_atlas_of_its_state(client):
    """POST /api/sessions/{id}/atlas: a job of the same jobs, whose request is the session's
    state (the loop from k(x0) through its path, s = 0 at x0, its gamma and mode); once done,
    GET gives the heatmap (log10 drift, a cell's customdata its run) and the starts."""
    # (5.0: JSON's integer 5)
    sid = _session(client, mode="discrete", gamma=0.5, cycles=2, max_iterations=60)
    r = client.post(f"/api/sessions/{sid}/atlas", json={"starts": 5.0, "scales": [1, 0.5]})
    assert r.status_code == 202, r.text
    assert r.headers["location"] == f"/atlas/{r.json()['id']}"
    done = wait_until_ended(client, r.json()["id"])
    assert done["status"] == "done", done["error"]
    body = client.get(f"/api/sessions/{sid}/atlas/{done['id']}").json()
    req = body["request"]
    np.testing.assert_allclose(req["path"], [[0.0, 1.0], *LOOP[1:], [0.0, 1.0]], atol=1e-15)
    assert (req["reference"], req["mode"], req["gamma"], req["cycles"]) == (
        [0.0, 0.0, math.pi / 2],
        "discrete",
        0.5,
        2,
    )
    assert (req["tolerance"], req["max_iterations"]) == (1e-10, 60)
    starts = np.array(body["starts"])  # (P, N, p)
    assert starts.shape == (2, 5, 3)
    kin = robot_spec("manipulator2").build(l=1.0)
    np.testing.assert_allclose(
        kin.forward(starts), np.broadcast_to([0.0, 1.0], (2, 5, 2)), atol=1e-9
    )
    x_title = body["figure"]["layout"]["xaxis"]["title"]["text"]
    assert x_title.startswith("arc length s of the start [m and rad mixed]")  # (the job's units)
    heat = body["figure"]["data"]
    assert [t["type"] for t in heat] == ["heatmap", "heatmap"]
    assert heat[0]["y"] == ["×1, cycle 1", "×1, cycle 2", "×0.5, cycle 1", "×0.5, cycle 2"]
    drift = np.array(done["result"]["drift"]["pseudoinverse"], dtype=float)  # (P, N, C)
    assert np.min(drift) > 1e-4


def test_ending_a_session_cancels_its_atlas(client):
    """A deleted tab's atlas had run on to its limit, holding the pool's workers (and the
    client's one running job) for nobody: it ends with the session, and the next can start."""
    mine, other = _session(client, cycles=20), _session(client, cycles=20)
    job = client.post(f"/api/sessions/{mine}/atlas", json={"starts": 4096})
    assert job.status_code == 202, job.text
    assert client.delete(f"/api/sessions/{mine}").status_code == 204
    assert client.get(f"/atlas/{job.json()['id']}").status_code == 404
    after = client.post(f"/api/sessions/{other}/atlas", json={"starts": 4096})
    assert after.status_code == 202, after.text
    assert client.delete(f"/atlas/{after.json()['id']}").status_code == 204


def test_tabs_behind_one_address_each_have_their_own_atlas_limit(client):
    """Students reaching a shared server through one address (SSH tunnels, a NAT) were one
    client: while one tab's atlas ran, every other tab's was refused with 429 "at most 1 atlas
    jobs per client". A dashboard session is the client of its atlases: each tab has its own
    limit, and a second of the same tab is still refused."""
    mine, other = _session(client, cycles=20), _session(client, cycles=20)
    started = [
        client.post(f"/api/sessions/{s}/atlas", json={"starts": 4096}) for s in (mine, other)
    ]
    try:
        assert [r.status_code for r in started] == [202, 202], [r.text for r in started]
        again = client.post(f"/api/sessions/{mine}/atlas", json={"starts": 4096})
        assert again.status_code == 429 and "at most 1 atlas jobs per client" in again.text
    finally:
        for r in started:
            client.delete(f"/atlas/{r.json().get('id')}")


@pytest.mark.parametrize(
    ("state", "over", "field", "text"),
    [
        ({"task": "target"}, {}, "task", "task: the atlas drives a closed path"),
        ({}, {"starts": 1}, "starts", "greater than or equal to 2"),
        ({}, {"scales": [0.0]}, "scales", "greater than 0"),
    ],
)
def test_a_session_atlas_it_cannot_make_is_422_naming_the_field(client, state, over, field, text):
    sid = _session(client, **state)
    r = client.post(f"/api/sessions/{sid}/atlas", json=over)
    assert r.status_code == 422, r.text
    assert any(text in m for m in messages(r)), r.text
    assert r.json()["detail"][0]["loc"][1] == field


def test_the_plan_is_made_in_a_compute_worker(client, monkeypatch):
    """Tracing the self-motion curves solves eq. (7): the server's process does not (a request
    once drove it past 20 GB); the compute workers do, within their time and memory limits."""

    def not_here(*_args):
        raise AssertionError("planned in the server's process")

    monkeypatch.setattr("jik.app.compute.atlas_plan.planned", not_here)
    r = client.post("/atlas", json=body())
    assert r.status_code == 202, r.text
    assert wait_until_ended(client, r.json()["id"])["status"] == "done"


def test_a_reference_whose_solve_runs_away_is_refused_by_name(client):
    """schemathesis's case: the unicycle from a reference with controls of size ~800, whose
    solve to the path's first point needed an ever larger quadrature. 422 at ``reference``
    with the engine's words; the worker that refused it serves the next request."""
    bad = {
        "robot": {"name": "unicycle"},
        "path": [[0.0, -3.0, 0.0], [3.0, 3.0, 0.0], [-3.0, -3.0, 3.0]],
        "reference": [0.0, -820.6, 738.5, 840.0],
    }
    r = client.post("/atlas", json=bad)
    assert r.status_code == 422, r.text
    (error,) = r.json()["detail"]
    assert error["loc"] == ["body", "reference"] and "oscillate too fast" in error["msg"]
    assert client.post("/atlas", json=body()).status_code == 202


def test_a_session_reads_only_the_atlases_it_started(client):
    """A tab's atlas route gives its own jobs: a job of the REST API or of another session is
    a 404, as for a job that is not there."""
    sid, other = _session(client), _session(client)
    rest = client.post("/atlas", json=body()).json()["id"]
    assert wait_until_ended(client, rest)["status"] == "done"
    r = client.post(f"/api/sessions/{other}/atlas", json={"starts": 4})
    assert r.status_code == 202, r.text
    theirs = r.json()["id"]
    assert wait_until_ended(client, theirs)["status"] == "done"
    for job in (rest, theirs):
        r = client.get(f"/api/sessions/{sid}/atlas/{job}")
        assert r.status_code == 404 and "this session did not start it" in r.text
    assert client.get(f"/api/sessions/{other}/atlas/{theirs}").status_code == 200


def test_an_atlas_takes_every_robot_and_refuses_a_bad_one_naming_the_field(client):
    """The document offers /atlas the catalogue's robots, its arms and the robots a request
    defines: a URDF robot without links is a 422 naming the robot, not a 500
    (schemathesis's coverage phase); an unknown name lists them all; leg_ends is a boolean."""
    urdf = {"name": "urdf", "urdf": "<robot name='r'/>", "end_link": "tool"}
    r = client.post("/atlas", json=body(robot=urdf))
    assert r.status_code == 422, r.text
    (error,) = r.json()["detail"]
    assert error["loc"][:2] == ["body", "robot"] and "no links" in error["msg"], error
    r = client.post("/atlas", json=body(robot={"name": "nao"}))
    (error,) = r.json()["detail"]
    assert "'panda'" in error["msg"] and "'urdf'" in error["msg"], error
    names = client.get("/openapi.json").json()["components"]["schemas"]
    assert {"AtlasUrdfRequest", "AtlasPandaRequest", "AtlasManipulator2Request"} <= set(names)
    r = client.post("/atlas", json=body(leg_ends=0))
    assert r.status_code == 422 and r.json()["detail"][0]["loc"] == ["body", "leg_ends"]


def test_an_atlas_in_the_compute_pool_is_the_engines_atlas():
    """The API's atlases run their chunks in the compute pool's workers: the same numbers as
    in-process, to 1e-12."""
    plan = planned(AtlasRequest.model_validate(body(starts=9)), AtlasLimits())[0]
    with pool_in_thread(Settings(workers=1, timeout=60.0)) as pool:
        pooled = run_atlas(plan, PoolBackend(pool))
    here = run_atlas(plan)
    np.testing.assert_allclose(pooled.drift, here.drift, rtol=0, atol=1e-12)
    np.testing.assert_allclose(pooled.leg_ends, here.leg_ends, rtol=0, atol=1e-12)


def test_a_posture_atlas_pulls_each_run_toward_its_own_start(client):
    """Without rest, the posture inverse of an atlas pulls each run toward its own start, as
    /repeatability's does toward its x0: each run's drift is that start's /repeatability drift,
    and below the pseudoinverse's at the same starts (the pull toward one fixed posture would
    be measured instead, larger than the pseudoinverse's drift)."""
    req = body(
        algorithms=["posture", "pseudoinverse"], algorithm_parameters={"gain": 1.0}, starts=4
    )
    done = wait_until_ended(client, client.post("/atlas", json=req).json()["id"])
    assert done["status"] == "done", done["error"]
    res = done["result"]
    posture = np.array(res["drift"]["posture"], dtype=float)[0]  # the one path's (N, cycles)
    pinv = np.array(res["drift"]["pseudoinverse"], dtype=float)[0]
    assert np.all(posture[:, -1] < 0.5 * pinv[:, -1])
    for i, x0 in enumerate(res["starts"][0]):
        r = client.post(
            "/repeatability",
            json={
                "robot": {"name": "manipulator2"},
                "algorithm": "posture",
                "x0": x0,
                "path": LOOP[1:],
                "cycles": 2,
                "algorithm_parameters": {"gain": 1.0},
            },
        )
        assert r.status_code == 200, r.text
        np.testing.assert_allclose(posture[i], r.json()["drift"], rtol=1e-8, atol=1e-12)


def test_a_session_atlas_of_a_urdf_robot_does_not_send_its_text_back(client):
    """The request a session's atlas repeats names a URDF by its size and SHA-256, as every
    response does: the text is never echoed."""
    pytest.importorskip("yourdfpy")
    text = (Path(__file__).parents[1] / "data" / "arm4.urdf").read_text()
    definition = {"name": "urdf", "urdf": text, "end_link": "tool"}
    sid = _session(client, robot="urdf", robot_definition=definition)
    r = client.post(f"/api/sessions/{sid}/atlas", json={"starts": 3, "cycles": 1})
    assert r.status_code == 202, r.text
    done = wait_until_ended(client, r.json()["id"])
    assert done["status"] == "done", done["error"]
    response = client.get(f"/api/sessions/{sid}/atlas/{done['id']}")
    assert "<robot" not in response.text and "link name" not in response.text
    robot = response.json()["request"]["robot"]
    assert robot["urdf_bytes"] == len(text.encode()) and "urdf" not in robot
    # Its continuous wrist closes the self-motion curve: the starts cover one turn, once.
    result = done["result"]
    period = result["period"]
    assert period is not None and 6.0 < period < 7.0
    assert result["arc"][1] - result["arc"][0] == pytest.approx(period)
    assert all(0 <= s < period for s in result["parameter"]) and len(result["parameter"]) == 3


def test_a_first_point_out_of_reach_is_refused_at_path(client):
    """No reference given: a path whose first point Manipulator 2 reaches only outside its box
    (x1 = 4.35 > 3) is refused at ``path``, in words, not at the default reference the user
    never sent."""
    r = client.post("/atlas", json={"robot": {"name": "manipulator2"}, "path": [[5, 5], [1, 1]]})
    (error,) = r.json()["detail"]
    assert r.status_code == 422 and error["loc"] == ["body", "path"], r.text
    assert error["msg"] == (
        "path: the path's first point (5, 5) is out of reach in the box (x_range, joint limits): "
        "eq. (7) from the reference reaches it only where x1 = 4.34525 is not in [-3, 3]"
    )


def test_a_reference_outside_the_box_is_refused_at_reference(client):
    """A given reference outside the box is at fault, not the default path it was sent with."""
    body = {"robot": {"name": "manipulator2"}, "reference": [100, 100, 100], "starts": 4}
    r = client.post("/atlas", json=body)
    (error,) = r.json()["detail"]
    assert r.status_code == 422 and error["loc"] == ["body", "reference"], r.text
    assert error["msg"].startswith("reference: the reference (100, 100, 100) lies outside the box")


def test_every_catalogue_arm_has_a_default_atlas_and_the_unicycle_says_why_not(client):
    """A catalogue arm's atlas with nothing but its name runs (the Gen3's continuous joints
    turn past the box's pi: a window on one turn, not a limit); the unicycle's default path is
    its experiment's targets, which /robots says (default_path_loops) and /atlas names."""
    for arm in ("panda", "iiwa14", "gen3", "ur5e"):
        r = client.post("/atlas", json={"robot": {"name": arm}, "starts": 3, "cycles": 1})
        assert r.status_code == 202, (arm, r.text)
        assert wait_until_ended(client, r.json()["id"])["status"] == "done", arm
        assert client.delete(f"/atlas/{r.json()['id']}").status_code == 204
    r = client.post("/atlas", json={"robot": {"name": "unicycle"}, "starts": 3, "cycles": 1})
    (error,) = r.json()["detail"]
    assert error["loc"] == ["body", "path"]
    assert "is the targets of the paper's experiment, reached once, not a loop" in error["msg"]
    robots = {r["name"]: r for r in client.get("/robots").json()["robots"]}
    assert robots["unicycle"]["default_path_loops"] is False
    assert robots["manipulator2"]["default_path_loops"] is True


def test_an_atlas_takes_the_cap_on_steps_as_a_solve_does(client):
    """max_iterations caps every leg of an atlas as it caps a /solve: discrete legs at gamma 0.5
    given 3 iterations fail, and say so; beyond the API's bound it is refused by name."""
    over = {"mode": "discrete", "gamma": 0.5, "max_iterations": 3}
    r = client.post("/atlas", json=body(**over))
    assert r.status_code == 202, r.text
    done = wait_until_ended(client, r.json()["id"])
    assert done["status"] == "done", done["error"]
    failures = done["result"]["failures"]["pseudoinverse"]
    assert len(failures) == 6
    assert all("did not converge within 3 iterations" in why for why in failures.values())
    too_many = body(max_iterations=MAX_ITERATIONS_CAP + 1)
    assert messages(client.post("/atlas", json=too_many))[0].startswith(
        f"max_iterations: Input should be less than or equal to {MAX_ITERATIONS_CAP}"
    )


def test_a_session_with_the_pages_largest_cap_gets_its_atlas(client):
    """The page's cap on steps goes up to the bound a request takes: a session whose state
    asks for the largest gets its atlas, as a /solve gets its run. Its least is the page's
    slider's (the scene's slider shows no value below its range)."""
    low = client.post("/api/sessions", json={"state": {"max_iterations": MIN_ITERATIONS - 1}})
    assert low.status_code == 422
    assert messages(low)[0].startswith(
        f"state.max_iterations: Input should be greater than or equal to {MIN_ITERATIONS}"
    ), messages(low)
    sid = _session(client, max_iterations=MAX_ITERATIONS_CAP)
    r = client.post(f"/api/sessions/{sid}/atlas", json={"starts": 2})
    assert r.status_code == 202, r.text
    done = wait_until_ended(client, r.json()["id"])
    assert done["status"] == "done", done["error"]
    shown = client.get(f"/api/sessions/{sid}/atlas/{done['id']}").json()
    assert shown["request"]["max_iterations"] == MAX_ITERATIONS_CAP
