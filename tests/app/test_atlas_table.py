"""An atlas job's table as CSV: ``GET /atlas/{id}/table.csv`` (REST) and
``GET /api/sessions/{sid}/atlas/{id}/table.csv`` (the dashboard's atlas panel): the engine's
``AtlasResult.columns()`` of the same atlas, its cells as ``jik atlas --csv`` writes them."""

from __future__ import annotations

import csv
import io

import numpy as np
import pytest
from fastapi.testclient import TestClient

from jik.app.compute.atlas_plan import AtlasLimits, planned
from jik.app.compute.atlas_schemas import AtlasRequest
from jik.engine.atlas_run import run_atlas
from jik.engine.exports import csv_rows
from tests.app.test_atlas_api import LONG, body, wait_until_ended

#: Columns of text (the rest are numbers, compared to 1e-12).
TEXT = {"algorithm", "path", "start", "cycle", "leg", "success"}


#: The atlas jobs of each test's app (tests/app/conftest.py's ``app``).
ATLAS_LIMITS = AtlasLimits(max_jobs=4, per_client=2)


@pytest.fixture
def client(app):
    return TestClient(app)


def table(response) -> list[list[str]]:
    assert response.status_code == 200, response.text
    assert response.headers["content-type"].startswith("text/csv")
    assert response.headers["content-disposition"].startswith("attachment; filename=")
    return list(csv.reader(io.StringIO(response.text)))


def assert_same_table(rows: list[list[str]], columns: dict) -> None:
    """``rows`` (header first) are ``columns``: the same names, the text cells equal, the
    numbers to 1e-12 (NaN an empty cell)."""
    assert rows[0] == list(columns)
    expected = list(csv_rows(columns))
    assert len(rows) - 1 == len(expected)
    for k, name in enumerate(columns):
        got, want = [r[k] for r in rows[1:]], [r[k] for r in expected]
        if name in TEXT:
            assert got == want, name
        else:
            as_float = lambda cells: np.array([float(c) if c else np.nan for c in cells])  # noqa: E731
            np.testing.assert_allclose(as_float(got), as_float(want), rtol=0, atol=1e-12)


def test_a_done_jobs_table_is_the_engines_table_of_its_atlas(client):
    """Two algorithms, leg ends kept: a row per run, algorithm and cycle with the cycle's end;
    ``every_leg``: a row per leg. Both the engine's columns() of the same request's atlas."""
    req = body(algorithms=["pseudoinverse", "extended"], leg_ends=True)
    job = client.post("/atlas", json=req).json()["id"]
    assert wait_until_ended(client, job)["status"] == "done"
    expected = run_atlas(planned(AtlasRequest.model_validate(req), AtlasLimits())[0])
    rows = table(client.get(f"/atlas/{job}/table.csv"))
    assert_same_table(rows, expected.columns())
    assert len(rows) - 1 == 2 * 6 * 2  # (algorithms x starts x cycles)
    legs = table(client.get(f"/atlas/{job}/table.csv", params={"every_leg": "true"}))
    assert_same_table(legs, expected.columns(every_leg=True))


def test_a_table_without_leg_ends_has_no_x_columns_and_no_row_per_leg(client):
    job = client.post("/atlas", json=body()).json()["id"]
    assert wait_until_ended(client, job)["status"] == "done"
    expected = run_atlas(
        planned(AtlasRequest.model_validate(body()), AtlasLimits())[0], keep_leg_ends=False
    )
    rows = table(client.get(f"/atlas/{job}/table.csv"))
    assert "x_1" not in rows[0]
    assert_same_table(rows, expected.columns())
    r = client.get(f"/atlas/{job}/table.csv", params={"every_leg": "true"})
    assert r.status_code == 422, r.text
    (error,) = r.json()["detail"]
    assert error["loc"] == ["query", "every_leg"]
    assert "a row per leg needs the leg ends" in error["msg"]


def test_a_job_not_done_answers_its_state_as_the_result_endpoint_does(client):
    job = client.post("/atlas", json=LONG).json()["id"]
    try:
        r = client.get(f"/atlas/{job}/table.csv")
        state = client.get(f"/atlas/{job}").json()
        assert r.status_code == 200 and r.headers["content-type"] == "application/json"
        got = r.json()
        assert got["status"] in ("queued", "running") and got["result"] is None
        moving = {"runs_done", "progress", "elapsed_s", "status", "message", "queue_position"}
        assert {k: v for k, v in got.items() if k not in moving} == {
            k: v for k, v in state.items() if k not in moving
        }
    finally:
        client.delete(f"/atlas/{job}")


@pytest.mark.parametrize(
    ("job_id", "why"),
    [
        ("nope", "no job of this server has had this id"),
        ("abcdef" + "A" * 16, "the server restarted since it was started"),
    ],
)
def test_an_unknown_or_foreign_job_has_no_table_as_it_has_no_result(client, job_id, why):
    """404 with the words of GET /atlas/{id} (a job of an earlier server: its id's prefix)."""
    r = client.get(f"/atlas/{job_id}/table.csv")
    assert r.status_code == 404
    assert r.json() == client.get(f"/atlas/{job_id}").json()
    assert why in r.json()["detail"]


def _session(client) -> str:
    r = client.post("/api/sessions", json={"state": {"cycles": 2}})
    assert r.status_code == 201, r.text
    return r.json()["id"]


def test_a_sessions_atlas_table_is_its_own_and_no_other_tabs(app, client):
    """The panel's CSV: the table of the atlas the session started (the REST table of the
    same job, header the engine's columns()); another session, and the session for a job of
    the REST API, get 404 as for a job that is not there."""
    sid, other = _session(client), _session(client)
    r = client.post(f"/api/sessions/{sid}/atlas", json={"starts": 4})
    assert r.status_code == 202, r.text
    job = r.json()["id"]
    assert wait_until_ended(client, job)["status"] == "done"
    mine = client.get(f"/api/sessions/{sid}/atlas/{job}/table.csv")
    rows = table(mine)
    atlas = app.state.atlas_jobs.get(job).atlas
    assert rows[0] == list(atlas.columns()) and len(rows) - 1 == 2 * 4 * 2
    assert mine.text == client.get(f"/atlas/{job}/table.csv").text
    refused = client.get(f"/api/sessions/{other}/atlas/{job}/table.csv")
    assert refused.status_code == 404 and "this session did not start it" in refused.text
    rest = client.post("/atlas", json=body()).json()["id"]
    assert wait_until_ended(client, rest)["status"] == "done"
    assert client.get(f"/api/sessions/{sid}/atlas/{rest}/table.csv").status_code == 404
    assert client.get(f"/api/sessions/nope/atlas/{job}/table.csv").status_code == 404


def test_the_tables_are_documented_as_csv(client):
    paths = client.get("/openapi.json").json()["paths"]
    for path in (
        "/atlas/{job_id}/table.csv",
        "/api/sessions/{session_id}/atlas/{job_id}/table.csv",
    ):
        answers = paths[path]["get"]["responses"]
        assert set(answers["200"]["content"]) == {"text/csv", "application/json"}
        assert "404" in answers
