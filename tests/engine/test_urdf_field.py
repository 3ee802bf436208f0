"""URDF as the field writes it: every serial chain of example-robot-data builds in jik and
equals Pinocchio's kinematics; meshes are skipped with a note; dangling joints are refused."""

import glob
import importlib.metadata
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from jik.engine.exceptions import InvalidInputError
from jik.engine.urdf import UrdfChain
from tests.engine.test_urdf import TEXT

yourdfpy = pytest.importorskip("yourdfpy")
MOVABLE = ("revolute", "continuous", "prismatic")


def _robots_dir() -> Path | None:
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    path = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))
    return path if path.is_dir() else None


ROBOTS = _robots_dir()
FILES = sorted(glob.glob(f"{ROBOTS}/**/*.urdf", recursive=True)) if ROBOTS else []
needs_robots = pytest.mark.skipif(
    not FILES, reason="example-robot-data is not installed (pip install 'jik[test]')"
)


def _serial_chains(text: str) -> list[tuple[str, int]]:
    """(leaf link, movable joints) of each chain from the root to a leaf with at least two
    movable joints and none floating, planar or mimicking another."""
    tree = etree.fromstring(text.encode())
    joints = tree.findall("joint")
    parent = {j.find("child").get("link"): j for j in joints}
    has_child = {j.find("parent").get("link") for j in joints}
    chains = []
    for leaf in [e.get("name") for e in tree.findall("link") if e.get("name") not in has_child]:
        chain, link = [], leaf
        while link in parent:
            chain.append(parent[link])
            link = chain[-1].find("parent").get("link")
        if any(
            j.get("type") in ("floating", "planar") or j.find("mimic") is not None for j in chain
        ):
            continue
        movable = sum(j.get("type") in MOVABLE for j in chain)
        if movable >= 2:
            chains.append((leaf, movable))
    return chains


def _pinocchio_q(pin, model, names, x):
    """Pinocchio's configuration for jik's x: neutral, with each named joint set (a continuous
    joint as (cos, sin))."""
    q = pin.neutral(model)
    for name, value in zip(names, x, strict=True):
        j = model.joints[model.getJointId(name)]
        if j.nq == 2:
            q[j.idx_q : j.idx_q + 2] = np.cos(value), np.sin(value)
        else:
            q[j.idx_q] = value
    return q


@needs_robots
@pytest.mark.parametrize("path", FILES, ids=lambda p: Path(p).name)
def test_every_serial_chain_of_example_robot_data_builds_and_equals_pinocchio(path):
    pin = pytest.importorskip("pinocchio")
    text = Path(path).read_text(encoding="utf-8")
    try:
        model = pin.buildModelFromXML(text)
    except Exception:  # (one file has no robot name: Pinocchio refuses it)
        pytest.skip("Pinocchio does not load this file")
    data = model.createData()
    rng = np.random.default_rng(37)
    for leaf, movable in _serial_chains(text):
        kin = UrdfChain(text, leaf, task="xyz"[: min(3, movable - 1)])
        x = rng.uniform(-1.0, 1.0, (3, kin.p))
        T = kin.frames(x)[2]
        frame = model.getFrameId(leaf)
        for xi, Ti in zip(x, T, strict=True):
            pin.framesForwardKinematics(model, data, _pinocchio_q(pin, model, kin.joint_names, xi))
            M = data.oMf[frame]
            np.testing.assert_allclose(Ti[:3, 3], M.translation, atol=1e-10, err_msg=leaf)
            np.testing.assert_allclose(Ti[:3, :3], M.rotation, atol=1e-10, err_msg=leaf)


@needs_robots
def test_the_chains_counted():
    """The test above covers hundreds of chains, not a handful."""
    count = sum(len(_serial_chains(Path(f).read_text(encoding="utf-8"))) for f in FILES)
    assert count > 400


def test_a_fixed_joints_axis_is_ignored():
    """The URDF spec: a fixed joint's axis means nothing, so even a zero one is accepted."""
    text = TEXT.replace(
        "</robot>",
        '<link name="flange"/><joint name="tool_flange" type="fixed">'
        '<parent link="tool"/><child link="flange"/><origin xyz="0 0 0.02"/>'
        '<axis xyz="0 0 0"/></joint></robot>',
    )
    kin = UrdfChain(text, "flange")
    np.testing.assert_allclose(
        kin.forward([0.1, 0.2, 0.3, 0.4]) - UrdfChain(TEXT, "tool").forward([0.1, 0.2, 0.3, 0.4]),
        UrdfChain(TEXT, "tool").frames(np.array([0.1, 0.2, 0.3, 0.4]))[2][:3, 2] * 0.02,
        atol=1e-15,
    )


@pytest.mark.parametrize("axis", ["0 0 1e200", "0 0 1e-200", "1e308 1e308 0", "0 0 7"])
def test_an_axis_of_any_finite_size_is_the_same_unit_axis(axis):
    """An axis is a direction: '0 0 1e200' (whose plain norm overflows to inf, which divided
    the axis to zero and froze the joint) and '0 0 1e-200' (whose norm underflows to 0) are
    the unit axis of '0 0 1', and '1e308 1e308 0' is that of '1 1 0'."""
    x = np.array([0.1, 0.2, 0.3, 0.4])
    unit = "1 1 0" if axis.startswith("1e308") else "0 0 1"
    scaled = UrdfChain(TEXT.replace('<axis xyz="0 0 1"/>', f'<axis xyz="{axis}"/>', 1), "tool")
    plain = UrdfChain(TEXT.replace('<axis xyz="0 0 1"/>', f'<axis xyz="{unit}"/>', 1), "tool")
    np.testing.assert_allclose(scaled.forward(x), plain.forward(x), rtol=0, atol=1e-15)
    np.testing.assert_allclose(scaled.jacobian(x), plain.jacobian(x), rtol=0, atol=1e-15)
    assert np.abs(scaled.jacobian(x)[:, 0]).max() > 0.1  # (the joint moves the end)


@pytest.mark.parametrize(
    "name",
    [
        "file:///etc/passwd",
        "package:///meshes/x.stl",
        "../secret.stl",
        "https://example.invalid/x",
        "package://arm4/meshes/tool.dae",
    ],
)
def test_mesh_references_are_skipped_with_a_note_never_read(name, monkeypatch):
    text = TEXT.replace(
        '<link name="tool"/>',
        f'<link name="tool"><visual><geometry><mesh filename="{name}"/></geometry></visual></link>',
    )
    import builtins

    opened = []
    real_open = builtins.open
    monkeypatch.setattr(
        builtins, "open", lambda f, *a, **k: opened.append(f) or real_open(f, *a, **k)
    )
    kin = UrdfChain(text, "tool")
    assert kin.p == 4 and opened == []
    assert len(kin.notes) == 1 and "1 mesh file reference(s) skipped, never read" in kin.notes[0]
    assert UrdfChain(TEXT, "tool").notes == ()


def test_a_joint_whose_parent_link_does_not_exist_is_refused():
    text = TEXT.replace(
        '<parent link="base_link"/><child link="turret"/>',
        '<parent link="plinth"/><child link="turret"/>',
    )
    with pytest.raises(InvalidInputError, match="parent link 'plinth', which the URDF does not"):
        UrdfChain(text, "tool")
