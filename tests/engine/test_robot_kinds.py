"""The description of robot definitions agrees with what robot_from_dict accepts."""

import json
from pathlib import Path

import pytest

from jik.engine.exceptions import InvalidInputError
from jik.engine.robot_kinds import AUGMENTATIONS, COMMON, KINDS, robot_kinds
from jik.engine.robot_spec import robot_from_dict

ARM4 = Path(__file__).resolve().parents[1] / "data" / "arm4.urdf"


def _from_examples(kind: str) -> dict:
    d = {"name": kind}
    for f in KINDS[kind]:
        if f.name == "urdf":
            d[f.name] = ARM4.read_text()
        elif f.example is not None:
            d[f.name] = f.example
    return d


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_the_examples_make_a_robot(kind):
    if kind == "urdf":
        pytest.importorskip("yourdfpy")
    robot = robot_from_dict(_from_examples(kind))
    assert robot.spec.name == kind


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_every_described_key_is_known_and_no_other(kind):
    if kind == "urdf":
        pytest.importorskip("yourdfpy")
    good = _from_examples(kind)
    for f in (*KINDS[kind], *COMMON):
        try:
            robot_from_dict({**good, f.name: object()})
        except InvalidInputError as exc:
            assert "unknown key" not in str(exc), f.name
    with pytest.raises(InvalidInputError, match="unknown key 'colour'"):
        robot_from_dict({**good, "colour": "red"})


@pytest.mark.parametrize("name", sorted(AUGMENTATIONS))
def test_every_described_augmentation_key_is_known(name):
    good = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}
    example = {f.name: f.example for f in AUGMENTATIONS[name] if f.required}
    robot_from_dict({**good, "augmentations": [{"name": name, **example}]})
    with pytest.raises(InvalidInputError, match=r"unknown key\(s\) \['colour'\]"):
        robot_from_dict({**good, "augmentations": [{"name": name, **example, "colour": 1}]})


def test_the_description_is_json():
    out = json.loads(json.dumps(robot_kinds()))
    assert set(out["kinds"]) == {"planar_chain", "formula", "urdf"}
    assert {f["name"] for f in out["kinds"]["planar_chain"]} == {
        "joints",
        "lengths",
        "offsets",
        "orientation",
        "limits",
    }
    assert set(out["augmentations"]) == {"formula", "e2_synthesized"}
