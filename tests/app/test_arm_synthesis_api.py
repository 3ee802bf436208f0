"""REST: the Panda's pose task runs its synthesized repeatable inverse, by name or by URDF."""

import numpy as np
from fastapi.testclient import TestClient

from jik.app.api.factory import create_app
from jik.engine.arms import ARMS
from jik.engine.robot_spec import robot_from_dict
from tests.engine.test_synthesis_arms import STEPS


def test_the_catalogue_name_and_the_urdf_give_the_same_repeatable_run():
    """{"name": "panda", "task": "pose"} and the same URDF text with its end link and home: the
    same E2-synthesized map by default, the same cycle ends, drift below 1e-9 after 10 cycles."""
    panda = robot_from_dict({"name": "panda", "task": "pose"})
    home = np.array(panda.spec.default_x0)
    y0 = panda.kinematics.forward(home)
    path = [(y0 + np.array(step)).tolist() for step in STEPS]
    arm = ARMS["panda"]
    as_urdf = {
        "name": "urdf",
        "urdf": arm.urdf,
        "end_link": arm.end_link,
        "home": list(arm.home),
        "task": "pose",
    }
    answers = []
    with TestClient(create_app()) as client:
        for robot in ({"name": "panda", "task": "pose"}, as_urdf):
            body = {
                "robot": robot,
                "algorithm": "extended",
                "x0": home.tolist(),
                "path": path,
                "cycles": 10,
            }
            r = client.post("/repeatability", json=body)
            assert r.status_code == 200, r.text
            answers.append(r.json())
    assert max(answers[0]["drift"]) < 1e-9
    assert np.allclose(answers[0]["cycle_end"], answers[1]["cycle_end"], atol=1e-12, rtol=0)
