"""Robot files and definitions a user gives: each bad one refused by name, cheaply, in one line."""

import json

import pytest

from jik.cli import main
from jik.engine.exceptions import InvalidInputError
from jik.engine.robot_file import MAX_DEPTH, MAX_NODES
from jik.engine.robot_kinds import MAX_TITLE_CHARS
from jik.engine.robot_spec import load_robot, robot_from_dict
from jik.engine.robot_synthesis import MAX_REGION_BOUND

CHAIN = {"name": "planar_chain", "joints": "RRR", "lengths": [1, 1, 1]}
FORMULA = {"name": "formula", "variables": ["x1", "x2", "x3"], "task": ["x1", "x2+x3"]}


def _refusal(call) -> InvalidInputError:
    with pytest.raises(InvalidInputError) as err:
        call()
    return err.value


def _cli_refusal(capsys, robot_file) -> str:
    """``jik solve --robot robot_file`` exits 2 and prints one line: its message."""
    assert main(["solve", "--robot", str(robot_file)]) == 2
    out = capsys.readouterr()
    assert out.out == "" and out.err.startswith("jik solve: ")
    assert out.err.count("\n") == 1, out.err
    return out.err


def _alias_bomb(depth: int) -> str:
    """A list whose level d repeats level d - 1 ten times by aliases: 2 * 10^depth numbers."""
    if depth == 0:
        return "&a0 [1.0, 1.0]"
    return f"&a{depth} [" + _alias_bomb(depth - 1) + ", " + ", ".join([f"*a{depth - 1}"] * 9) + "]"


def test_yaml_anchors_and_aliases_are_refused_before_anything_is_built(tmp_path):
    """An alias bomb is refused at its first anchor (depth 5 here, 2e5 numbers once expanded:
    at depth 8, 477 bytes, they took gigabytes); so is a lone alias of a harmless value."""
    pytest.importorskip("yaml")
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text("name: planar_chain\njoints: RRR\nlengths: [1,1,1]\npath: " + _alias_bomb(5))
    err = _refusal(lambda: load_robot(bomb))
    assert err.field == "robot"
    assert str(err).startswith("bomb.yaml, line 4: YAML anchors and aliases")
    small = tmp_path / "alias.yaml"
    small.write_text("name: planar_chain\njoints: RRR\nlengths: &l [1, 1, 1]\nx0: *l\n")
    assert "anchors and aliases" in str(_refusal(lambda: load_robot(small)))


@pytest.mark.parametrize(
    ("suffix", "text", "words"),
    [
        (".yaml", "[" * 5000 + "]" * 5000, f"more than {MAX_DEPTH} levels deep"),
        (".json", "[" * 100_000 + "]" * 100_000, f"more than {MAX_DEPTH} levels deep"),
        (".json", "[" * (MAX_DEPTH + 1) + "]" * (MAX_DEPTH + 1), "levels deep"),
        (".yaml", "path: [" + "1, " * MAX_NODES + "1]\n", f"more than {MAX_NODES} values"),
        (".json", "[" + "0," * MAX_NODES + "0]", f"more than {MAX_NODES} values"),
        (".json", "\xff\xfe{}", "is not UTF-8 text (byte 0xff at offset 0)"),
        (".yaml", "name: \xe9t\xe9", "is not UTF-8 text (byte 0xe9 at offset 6)"),
        (".json", '{"lengths": [' + "1" * 5000 + "]}", "is not valid JSON"),
        (".yaml", "lengths: [" + "1" * 5000 + "]", "is not valid YAML"),
    ],
)
def test_a_bad_robot_file_exits_2_with_one_line_naming_it(capsys, tmp_path, suffix, text, words):
    """Deep nesting (a RecursionError in either parser), too many values, bytes that are not
    UTF-8 and an integer of 5000 digits: one line naming the file and the field, exit 2."""
    if suffix == ".yaml":
        pytest.importorskip("yaml")
    robot = tmp_path / f"robot{suffix}"
    robot.write_bytes(text.encode("latin-1"))
    err = _cli_refusal(capsys, robot)
    assert f"robot{suffix}" in err and words in err and err.endswith("(option --robot)\n")


def test_a_urdf_file_that_is_not_utf8_is_refused_naming_urdf_file(tmp_path):
    (tmp_path / "arm.urdf").write_bytes(b"<robot name='\xff'/>")
    robot = tmp_path / "arm.json"
    robot.write_text(json.dumps({"name": "urdf", "urdf_file": "arm.urdf", "end_link": "tool"}))
    err = _refusal(lambda: load_robot(robot))
    assert err.field == "urdf_file"
    assert str(err) == "arm.urdf is not UTF-8 text (byte 0xff at offset 13); save it as UTF-8"


def test_a_synthesis_region_beyond_the_bound_is_refused_as_the_api_refuses_it(capsys, tmp_path):
    """An E2 region of [0, 1e300] (a singular Ritz system, LinAlgError) is refused when the
    robot is built, at the bound the REST API's schema takes from the engine."""
    from jik.app.compute.schemas.fields import Bound

    bounds = {type(m).__name__: m for m in Bound.__metadata__[0].metadata}
    assert bounds["Ge"].ge == -MAX_REGION_BOUND and bounds["Le"].le == MAX_REGION_BOUND
    region = {"x2": [0, 1e300], "x3": [0, 1]}
    robot = {**FORMULA, "augmentations": [{"name": "e2_synthesized", "region": region}]}
    err = _refusal(lambda: robot_from_dict(robot))
    assert err.field == "augmentations.0.region.x2"
    assert f"within +-{MAX_REGION_BOUND:g}" in str(err)
    path = tmp_path / "r.json"
    path.write_text(json.dumps(robot))
    assert main(["solve", "--robot", str(path), "--algorithm", "extended"]) == 2
    assert f"(field augmentations.0.region.x2 of the robot file {path})" in capsys.readouterr().err
    edge = {"x2": [-MAX_REGION_BOUND, MAX_REGION_BOUND], "x3": [0, 1]}
    robot["augmentations"][0]["region"] = edge
    assert robot_from_dict(robot).spec.functional_region["x2"] == tuple(edge["x2"])


@pytest.mark.parametrize(
    ("robot", "field"),
    [
        ({**CHAIN, "title": "arm\r\n# injected line"}, "title"),
        ({**CHAIN, "title": "tab\there"}, "title"),
        ({**CHAIN, "title": "line\u2028separator"}, "title"),
        ({**CHAIN, "title": "arm \u202egnp.exe"}, "title"),  # (right-to-left override)
        ({**CHAIN, "title": "x" * (MAX_TITLE_CHARS + 1)}, "title"),
        ({**CHAIN, "title": ""}, "title"),
        ({"name": "manipulator2", "title": "two\nlines"}, "title"),
        ({"name": "panda", "title": "two\nlines"}, "title"),
        (
            {**FORMULA, "augmentations": [{"name": "formula", "h": "x3", "label": "a\nb"}]},
            "augmentations.0.label",
        ),
    ],
)
def test_a_title_or_label_is_one_line_of_bounded_length(robot, field):
    """A title or a map's label with a line break, a tab or a Unicode line separator (which
    would split a CSV export's '#' header line), a bidirectional control (which reorders the
    rest of its line), empty, or too long is refused by name."""
    assert _refusal(lambda: robot_from_dict(robot)).field == field


def test_a_one_line_title_and_label_are_kept():
    title = "Bras à trois segments — " + "x" * (MAX_TITLE_CHARS - 24)
    assert robot_from_dict({**FORMULA, "title": "ذراع ثلاثي"}).spec.title == "ذراع ثلاثي"
    robot = {**FORMULA, "title": title}
    robot["augmentations"] = [{"name": "formula", "h": "x3", "label": "h = x3 (ω)"}]
    spec = robot_from_dict(robot).spec
    assert spec.title == title and spec.augmentations[0].name == "h = x3 (ω)"
