"""The 3D scene (jik.app.scene): the start point's gizmo, the timeline, the GUI and the drag
writing to the session's dashboard, nodes moved in place, traces within their tolerance."""

from __future__ import annotations

import math
import threading
import time

import numpy as np
import pytest
import viser
from viser.transforms import SO3

from jik.app.dashboard import Dashboard, compute, default_state, updated_state
from jik.app.dashboard.algorithms import DEFAULT_ALGORITHMS
from jik.app.dashboard.messages import Event
from jik.app.scene import DashboardScene
from jik.app.scene.controls import MARK
from jik.app.scene.fixtures import TRACE_TOLERANCE, polyline, simplify
from jik.app.scene.gizmo import DRAG_INTERVAL, gizmo_pose, start_from_gizmo
from jik.app.scene.mechanisms import extent_of
from jik.app.scene.playback import Timeline
from jik.engine.registry import ROBOTS
from tests.helpers import run_async


@pytest.mark.parametrize(
    ("robot", "x0"),
    [
        ("manipulator2", (0.3, -0.4, 2.0)),
        ("manipulator2", None),  # x3 = pi/2: the quaternion's round trip is off by an ulp
        ("manipulator1", (0.7, 0.2, -0.6)),
        ("unicycle", None),
    ],
)
def test_the_start_point_gizmo_round_trips(robot, x0):
    """Dragging the gizmo to where it already is leaves the start point unchanged, exactly: a
    press on the gizmo is no change (the dashboard would solve both runs again)."""
    state = default_state(robot)
    if x0 is not None:
        state = updated_state(state, {"x0": list(x0)})
    xy, yaw = gizmo_pose(robot, state.x0, state.robot_parameters)
    yaw = float(SO3.from_z_radians(yaw).compute_yaw_radians())
    patch = start_from_gizmo(robot, xy, yaw, state)
    assert updated_state(state, patch) == state


def test_manipulator2_gizmo_moves_the_carriage():
    state = default_state("manipulator2")
    patch = start_from_gizmo("manipulator2", (0.4, 0.25), np.pi / 2 + 0.1, state)
    assert patch == {"x0": [0.25, 0.4, pytest.approx(np.pi / 2 + 0.1)]}


def test_animation_timeline_ends_at_the_last_configuration():
    result = compute(updated_state(default_state("manipulator2"), {"cycles": 1}))
    timeline = Timeline(result)
    assert timeline.length == len(result.targets)
    start, end = timeline.at(0.0), timeline.at(timeline.length)
    for a, run in result.runs.items():
        np.testing.assert_allclose(start[a], run.x[0], atol=1e-12)
        np.testing.assert_allclose(end[a], run.x[-1], atol=1e-9)


def test_viser_gui_and_drag_change_the_one_state():
    """The scene's GUI and its start-point gizmo write to the same Dashboard as the page."""
    import time
    from types import SimpleNamespace

    dashboard = Dashboard(updated_state(default_state("manipulator2"), {"task": "target"}))
    scene = DashboardScene(dashboard)
    try:
        assert dashboard.wait(1, timeout=60)
        deadline = time.monotonic() + 30
        while dashboard.scene_status.get("generation", 0) < 1 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert dashboard.scene_status["robot"] == "manipulator2"
        scene.controls.inputs["gamma"].value = 2.5  # what a slider move in the viser GUI does
        assert dashboard.state.gamma == 2.5
        target = SimpleNamespace(position=(0.4, 0.25, 0.3), wxyz=SO3.from_z_radians(1.7).wxyz)
        scene.gizmo.on_drag(SimpleNamespace(phase="end", target=target))
        np.testing.assert_allclose(dashboard.state.x0, (0.25, 0.4, 1.7), atol=1e-12)
        # A press where the gizmo is changes nothing; the first move
        # right after it is applied at once; a second within DRAG_INTERVAL when that ends,
        # though no event follows (the pose a drag rests at).
        generation = dashboard.generation
        scene.gizmo.on_drag(SimpleNamespace(phase="start", target=target))
        assert dashboard.generation == generation
        moved = SimpleNamespace(position=(0.5, 0.25, 0.3), wxyz=SO3.from_z_radians(1.7).wxyz)
        scene.gizmo.on_drag(SimpleNamespace(phase="update", target=moved))
        np.testing.assert_allclose(dashboard.state.x0, (0.25, 0.5, 1.7), atol=1e-12)
        rest = SimpleNamespace(position=(0.55, 0.3, 0.3), wxyz=SO3.from_z_radians(1.7).wxyz)
        scene.gizmo.on_drag(SimpleNamespace(phase="update", target=rest))
        assert dashboard.state.x0[1] == pytest.approx(0.5)  # (deferred)
        deadline = time.monotonic() + DRAG_INTERVAL + 10.0  # (a loaded machine is slow)
        while dashboard.state.x0[1] != pytest.approx(0.55) and time.monotonic() < deadline:
            time.sleep(0.02)
        np.testing.assert_allclose(dashboard.state.x0, (0.3, 0.55, 1.7), atol=1e-12)
        # A deferred move that a newer event overtakes is dropped.
        scene.gizmo.on_drag(SimpleNamespace(phase="update", target=moved))
        scene.gizmo.on_drag(SimpleNamespace(phase="end", target=rest))
        time.sleep(DRAG_INTERVAL + 0.1)
        np.testing.assert_allclose(dashboard.state.x0, (0.3, 0.55, 1.7), atol=1e-12)
        assert dashboard.wait(timeout=60)
        deadline = time.monotonic() + 30
        while dashboard.scene_status["generation"] < dashboard.generation:
            assert time.monotonic() < deadline, "the scene did not redraw"
            time.sleep(0.05)
        # A change from elsewhere (the page) moves the scene's GUI at once.
        generation, _ = dashboard.update({"gamma": 0.5})
        assert scene.controls.inputs["gamma"].value == 0.5
        assert dashboard.wait(generation, timeout=60)
        _drawn(scene, generation)  # (its status drawn: the refusal's below is not overwritten)
        # A value the dashboard refuses (no algorithm left) puts the GUI back to the value in
        # force and says so.
        boxes = scene.controls.inputs["algorithms"].boxes
        boxes["pseudoinverse"].value = False
        boxes["extended"].value = False
        assert dashboard.state.algorithms == ("extended",)
        assert boxes["extended"].value is True
        assert "refused" in scene.status.content and "algorithms" in scene.status.content
        # A user's change while another thread sets the GUI's values (the animation's
        # position slider, the worker's sync) is kept: only that thread's callbacks are its own.
        syncing, release = threading.Event(), threading.Event()

        def sync_elsewhere() -> None:
            with scene.controls.syncing:
                syncing.set()
                release.wait(10)

        other = threading.Thread(target=sync_elsewhere)
        other.start()
        assert syncing.wait(10)
        scene.controls.inputs["gamma"].value = 1.5  # (viser's thread, for a user)
        release.set()
        other.join()
        assert dashboard.state.gamma == 1.5
        # Another robot: its controls replace the old ones at once.
        dashboard.update({"robot": "manipulator1"})
        # (the dropdown shows the robots' titles, as the page's selector does)
        assert scene.controls.inputs["robot"].value == ROBOTS["manipulator1"].title
        assert "augmentation_parameters.a" in scene.controls.inputs
        dashboard.update({"robot": "manipulator2"})
        dashboard.update({"robot": "unicycle"})
        assert scene.controls.inputs["robot"].value == ROBOTS["unicycle"].title
        assert len(scene.controls.folders) == 2
        assert "robot_parameters.q0" in scene.controls.inputs
    finally:
        scene.stop()
        dashboard.stop()


def test_scene_follows_a_new_result_in_place():
    """A change that keeps the robot and the task moves the scene's nodes instead of
    re-creating them (a target the closed path gains or loses is added or removed); the
    start-point gizmo moves with the drawing."""
    # (k(x0) off the path's points for both: the closed path has the same number of legs)
    first = updated_state(default_state("manipulator2"), {"x0": [0.4, 0.0, 1.5]})
    dashboard = Dashboard(first)
    scene = DashboardScene(dashboard)
    M2 = "/robot/manipulator2-path"
    try:
        assert dashboard.wait(1, timeout=60)
        second = updated_state(first, {"x0": [0.45, 0.1, 1.4], "robot_parameters": {"l": 1.3}})
        scene._draw(compute(first, 101))
        fixtures, mechanisms = dict(scene.nodes.fixtures), dict(scene.nodes.mechanisms)
        scene._draw(compute(second, 102))
        assert scene.nodes.fixtures.keys() == fixtures.keys()
        assert all(scene.nodes.fixtures[k] is v for k, v in fixtures.items())
        assert all(scene.nodes.mechanisms[k] is v for k, v in mechanisms.items())
        # The default start maps onto the path's last point: one target fewer, the rest stays.
        scene._draw(compute(default_state("manipulator2"), 105))
        assert scene.nodes.fixtures.keys() == fixtures.keys() - {
            f"{M2}/targets/4",
            f"{M2}/targets/4/label",
        }
        assert all(
            scene.nodes.fixtures[k] is v for k, v in fixtures.items() if k in scene.nodes.fixtures
        )
        scene._draw(compute(second, 106))
        assert scene.nodes.fixtures.keys() == fixtures.keys()
        result = compute(second, 103)
        (xlo, xhi), (ylo, yhi) = extent_of(result)
        tol = TRACE_TOLERANCE * max(xhi - xlo, yhi - ylo)
        y = result.runs["extended"].y
        np.testing.assert_allclose(
            scene.nodes.fixtures[f"{M2}/trace/extended/task"].points[:, :, :2],
            polyline(np.column_stack([y, np.full(len(y), 0.16)]), tol)[:, :, :2],
            rtol=1e-6,  # viser keeps float32
        )
        assert scene.nodes.mechanisms["extended"].arm.dimensions[0] == pytest.approx(1.3)
        (X, Y), _ = gizmo_pose("manipulator2", second.x0, second.robot_parameters)
        np.testing.assert_allclose(scene.gizmo.handle.position, (X, Y, 0.3))
        # Another robot: its own nodes; the first robot's are hidden, and shown again (moved,
        # not re-created) when it comes back.
        fixtures, mechanisms = dict(scene.nodes.fixtures), dict(scene.nodes.mechanisms)
        scene._draw(compute(default_state("manipulator1"), 104))
        assert set(scene.nodes.fixtures) >= {"/robot/manipulator1-path/guide"}
        assert not any(k.startswith(M2) for k in scene.nodes.fixtures)
        assert (
            scene.nodes.sets[("manipulator2", "path", DEFAULT_ALGORITHMS)]["frame"].visible is False
        )
        scene._draw(compute(second, 107))
        assert (
            scene.nodes.sets[("manipulator2", "path", DEFAULT_ALGORITHMS)]["frame"].visible is True
        )
        assert (
            scene.nodes.sets[("manipulator1", "path", DEFAULT_ALGORITHMS)]["frame"].visible is False
        )
        assert all(scene.nodes.fixtures[k] is v for k, v in fixtures.items())
        assert all(scene.nodes.mechanisms[k] is v for k, v in mechanisms.items())
        # A result solved ahead: its nodes are built hidden, and shown by its result.
        other = compute(updated_state(default_state("manipulator1"), {"task": "target"}), 108)
        scene._on_event(Event("ahead", 108, "{}", other))
        ahead = scene.nodes.sets[("manipulator1", "target", DEFAULT_ALGORITHMS)]
        assert ahead["frame"].visible is False and ahead["mechanisms"]
        scene._draw(other)
        assert ahead["frame"].visible is True and scene.nodes.mechanisms is ahead["mechanisms"]
        # Paused, a new result is drawn at its end, and the position slider says so.
        scene.playback.playing = False
        scene._draw(compute(first, 109))
        timeline = scene.playback.timeline
        assert timeline is not None and scene.playback.position == timeline.length
        assert scene.playback.scrub.value == 1.0
    finally:
        scene.stop()
        dashboard.stop()


def _distance_topolyline(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Distance of each point to the polyline ``line`` (m, d)."""
    a, b = line[:-1], line[1:]
    d = b - a
    rel = points[:, None, :] - a[None]
    t = np.clip(
        np.einsum("nmd,md->nm", rel, d) / np.maximum(np.einsum("md,md->m", d, d), 1e-300), 0.0, 1.0
    )
    return np.min(np.linalg.norm(rel - t[..., None] * d[None], axis=-1), axis=1)


@pytest.mark.parametrize("robot", ["manipulator1", "manipulator2"])
def test_scene_traces_stay_within_their_tolerance(robot):
    """The scene draws each path with far fewer segments, never farther than the tolerance from
    any computed point; the ends are kept."""
    result = compute(default_state(robot))
    (xlo, xhi), (ylo, yhi) = extent_of(result)
    tol = TRACE_TOLERANCE * max(xhi - xlo, yhi - ylo)
    for run in result.runs.values():
        for path in (run.y, run.x):
            kept = simplify(path, tol)
            assert len(kept) < len(path) / 4
            np.testing.assert_array_equal(kept[[0, -1]], path[[0, -1]])
            assert _distance_topolyline(path, kept).max() <= tol
    line = np.column_stack([np.linspace(0, 1, 50), np.linspace(0, 2, 50)])
    assert len(simplify(line, 1e-12)) == 2
    corner = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    np.testing.assert_array_equal(simplify(corner, 0.1), corner)


def test_the_scenes_integer_sliders_send_integers():
    """viser's slider gives a float; the cycles it sets are an integer (the state is strict)."""
    dashboard = Dashboard(default_state("manipulator2"))
    scene = DashboardScene(dashboard)
    try:
        scene.controls.show(dashboard.state)
        scene.controls.inputs["cycles"].value = 4.0  # what a move of the slider gives
        assert dashboard.state.cycles == 4 and isinstance(dashboard.state.cycles, int)
    finally:
        scene.stop()
        dashboard.stop()


def test_a_number_typed_in_a_sliders_box_is_sent_once_within_its_range():
    """viser's box beside a slider sends every keystroke: "5" on the way to "500" iterations,
    "0" on the way to γ = 0.25. Those values off the slider's range are not sent (the dashboard
    would refuse them and reset the box under the typing, which then read "020000" or 0.251);
    the box brings a value left off the range into it when it loses focus, and sends that."""
    dashboard = Dashboard(default_state("manipulator2"))
    scene = DashboardScene(dashboard)
    inputs = scene.controls.inputs
    try:
        scene.controls.show(dashboard.state)
        generation = dashboard.generation
        for typed in (5.0, 50.0, 500.0):  # (what viser's box sends as "500" is typed)
            inputs["max_iterations"].value = typed
        assert dashboard.state.max_iterations == 500
        assert dashboard.generation == generation + 2  # (50, 500)
        for typed in (0.0, 0.2, 0.25):
            inputs["gamma"].value = typed
        assert dashboard.state.gamma == 0.25
        assert "refused" not in scene.status.content
        assert not inputs["gamma"].label.startswith(MARK)
        inputs["gamma"].value = 50.0  # (left typed: the box sends its maximum on blur)
        assert dashboard.state.gamma == 0.25
    finally:
        scene.stop()
        dashboard.stop()


def test_a_vector_box_takes_and_shows_the_decimals_the_page_does():
    """Manipulator 2's target (0, 2), by steps of 0.1: viser's boxes would show and take one
    decimal (0.25 typed became 0.2, the page's 0.375 showed as 0.4); the scene's take and show
    the page's DECIMALS, and a first value with more keeps them all."""
    from jik.app.dashboard.control_changes import DECIMALS

    state = updated_state(default_state("manipulator2"), {"task": "target"})
    dashboard = Dashboard(state)
    scene = DashboardScene(dashboard)
    try:
        scene.controls.show(dashboard.state)
        assert scene.controls.inputs["target"].precision == DECIMALS
        dashboard.update({"robot": "unicycle"})  # (its q0, (5, 0, pi/2): 7 decimals)
        assert scene.controls.inputs["robot_parameters.q0"].precision == 7
    finally:
        scene.stop()
        dashboard.stop()


def test_the_scene_shows_the_runs_progress_not_the_second_phases():
    """The scene's status keeps the drawn result's line while E1, E2 (which it does not draw)
    are computed; a new state's runs show their progress there, until a failure."""
    import json

    dashboard = Dashboard(updated_state(default_state("manipulator2"), {"cycles": 1}))
    scene = DashboardScene(dashboard)
    try:
        assert dashboard.wait(1, timeout=60)
        scene._show_status(dashboard.result)
        drawn = scene.status.content
        # (the last cycle's drift, as the verdict's "not repeatable" sentence gives it; one
        # cycle, not "cycles"; the algorithms by the symbols of the page's key)
        assert drawn.startswith(
            "generation 1: drift ‖x − x0‖ after the last cycle (1 cycle) — J^P# (8) **"
        )
        assert ", J^E# (11) **" in drawn

        def progress(phase: str) -> Event:
            return Event(
                "progress",
                1,
                json.dumps(
                    {
                        "type": "progress",
                        "generation": 1,
                        "phase": phase,
                        "what": "h on a grid",
                        "fraction": 0.4,
                        "elapsed": 0.8,
                    }
                ),
            )

        scene._on_event(progress("second"))
        assert scene.status.content == drawn and scene.progress.visible is False
        scene._on_event(progress("runs"))
        assert scene.status.content == "computing… 40%" and scene.progress.visible is True
        # A refused change leaves the computation's bar; a failed one ends it.
        scene._on_event(Event("refused", 1, json.dumps({"message": "gamma: too large"})))
        assert scene.status.content == "**refused:** gamma: too large"
        assert scene.progress.visible is True
        scene._on_event(Event("error", 1, json.dumps({"message": "the solver failed"})))
        assert scene.status.content == "**error:** the solver failed"
        assert scene.progress.visible is False
    finally:
        scene.stop()
        dashboard.stop()


FORMULA = {
    "name": "formula",
    "variables": ["x1", "x2", "x3"],
    "task": [
        "0.05*cos(x1) + 0.05*cos(x1 + x2) + 0.03*cos(x1 + x2 + x3)",
        "0.05*sin(x1) + 0.05*sin(x1 + x2) + 0.03*sin(x1 + x2 + x3)",
    ],
}
ARM = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}


def _drawn(scene: DashboardScene, generation: int, timeout: float = 60) -> None:
    """Wait until the scene has drawn ``generation`` and shows its status."""
    deadline = time.monotonic() + timeout
    while (drawn := scene.dashboard.scene_status.get("generation", 0)) < generation or not (
        scene.status.content.startswith(f"generation {drawn}:")
    ):
        assert time.monotonic() < deadline, "the scene did not draw"
        time.sleep(0.05)


def test_the_camera_frames_each_robots_reach_for_each_client():
    """When the robot changes, the camera looks at what it can reach, from a distance at which
    that fills the view: a formula robot of a few centimetres is not tiny in a corner, an arm's
    whole reach (the length of its links around its base) is in view; a client reporting a
    tall, narrow view is framed farther away than the initial camera (framed for a canvas
    0.4 times as wide as high, INITIAL_ASPECT). The session's scene status counts the client
    as a viewer while it is connected."""
    import asyncio

    import msgspec

    formula = updated_state(default_state(), {"robot": "formula", "robot_definition": FORMULA})
    dashboard = Dashboard(formula)
    scene = DashboardScene(dashboard)
    initial = scene.server.initial_camera
    try:
        assert dashboard.wait(1, timeout=60)
        _drawn(scene, 1)
        result = dashboard.result
        points = np.vstack([r.y for r in result.runs.values()] + [result.targets])
        middle = (points.min(axis=0) + points.max(axis=0)) / 2
        span = float(np.max(points.max(axis=0) - points.min(axis=0)))
        np.testing.assert_allclose(initial.look_at[:2], middle, atol=0.2 * span)
        distance = float(np.linalg.norm(initial.position - initial.look_at))
        half = math.atan(math.tan(initial.fov / 2) * 0.4)  # (half the initial width's angle)
        assert span / 2 < distance * math.tan(half) < 2 * span, (distance, span)
        # An arm: its base looked at, its reach (2.4) within the view, not much more.
        generation, _ = dashboard.update({"robot": "planar_chain", "robot_definition": ARM})
        assert dashboard.wait(generation, timeout=60)
        _drawn(scene, generation)
        np.testing.assert_allclose(initial.look_at, (0.0, 0.0, 0.0), atol=1e-9)
        distance = float(np.linalg.norm(initial.position - initial.look_at))
        assert 2.4 <= distance * math.sin(half) <= 1.5 * 2.4, distance
        # A client whose view is three times taller than wide: framed for its narrow width.
        camera = {
            "type": "ViewerCameraMessage",
            "wxyz": (1.0, 0.0, 0.0, 0.0),
            "position": (0.0, -5.0, 5.0),
            "fov": 1.0,
            "near": 0.01,
            "far": 100.0,
            "image_height": 900,
            "image_width": 300,
            "look_at": (0.0, 0.0, 0.0),
            "up_direction": (0.0, 0.0, 1.0),
        }

        async def tall_client() -> float:
            async with scene.connect([f"viser-v{viser.__version__}"]) as ws:
                await ws.send(msgspec.msgpack.encode(camera))
                deadline = time.monotonic() + 30
                while True:
                    clients = list(scene.server.get_clients().values())
                    if clients and np.allclose(clients[0].camera.look_at, 0.0, atol=1e-9):
                        seen = clients[0].camera
                        if np.linalg.norm(seen.position - (0.0, -5.0, 5.0)) > 1e-6:
                            assert dashboard.scene_status["viewers"] == 1  # (the session's)
                            return float(np.linalg.norm(seen.position - seen.look_at))
                    assert time.monotonic() < deadline, "the client was not framed"
                    await asyncio.sleep(0.05)

        narrow = run_async(tall_client())
        deadline = time.monotonic() + 30
        while dashboard.scene_status["viewers"] != 0:  # (the client left)
            assert time.monotonic() < deadline, "the scene still counts a viewer that left"
            time.sleep(0.05)
        horizontal = math.atan(math.tan(0.5) / 3)  # (half the width's angle)
        assert narrow * math.sin(horizontal) == pytest.approx(1.15 * 2.4, rel=1e-6)
    finally:
        scene.stop()
        dashboard.stop()


def test_viser_prints_nothing_to_the_servers_output(capsys, caplog):
    """viser's banners (each server's address, "Server stopped") go to the jik.scene.viser
    logger at DEBUG, not to ``jik serve``'s output."""
    import logging

    caplog.set_level(logging.DEBUG, logger="jik.scene.viser")
    dashboard = Dashboard(default_state("manipulator2"))
    scene = DashboardScene(dashboard)
    scene.stop()
    dashboard.stop()
    out, err = capsys.readouterr()
    assert "viser" not in out + err and "Server stopped" not in out + err, out + err
    logged = [r.getMessage() for r in caplog.records if r.name == "jik.scene.viser"]
    assert any("Server stopped" in line for line in logged), logged


def test_targets_at_one_position_share_one_label():
    """Pose targets that differ in orientation only sit at one point: the first carries the
    letters of all ("B, C"), the others none, so that no two labels overlap."""
    from jik.app.scene.nodes import target_labels

    def frame(position):
        return ("frame", {"position": position, "wxyz": (1.0, 0.0, 0.0, 0.0)}, {})

    wanted = {
        "/r/targets/0": frame((0.3, 0.0, 0.5)),
        "/r/targets/1": frame((0.3, 0.1, 0.5)),
        "/r/targets/2": frame((0.3, 0.1, 0.5 + 1e-12)),
        "/r/targets/3": frame((0.3, 0.0, 0.5)),
        "/r/path": ("line_segments", {"points": None}, {}),
    }
    assert target_labels(wanted, ["B", "C", "D", "A"], "/r/targets/") == {
        "/r/targets/0/label": "B, A",
        "/r/targets/1/label": "C, D",
        "/r/targets/2/label": "",
        "/r/targets/3/label": "",
    }


@pytest.mark.parametrize(
    "chosen, labelled",
    [(("pseudoinverse", "extended"), "extended"), (("pseudoinverse", "damped"), "pseudoinverse")],
)
def test_manipulator1_names_its_task_point_on_one_chosen_copy(chosen, labelled):
    """Manipulator 1's task point W is labelled once: on the extended inverse's copy when it is
    chosen, else on the first chosen algorithm's (it was missing without the extended one)."""
    from unittest.mock import MagicMock

    from jik.app.scene.mechanisms import NormalForm

    state = updated_state(default_state(), {"robot": "manipulator1", "algorithms": list(chosen)})
    scene = MagicMock()
    for a in chosen:
        NormalForm(scene, f"/robot/m1/{a}", (0, 0, 0), None, 0.0, state, ((-1, 1), (-1, 1)))
    labels = [c.args[:2] for c in scene.add_label.call_args_list]
    assert labels == [(f"/robot/m1/{labelled}/W/label", "W (task point)")]


def test_the_unicycles_nodes_are_kept_and_moved():
    """The unicycle's set is kept like a manipulator's: a new result moves its platforms and its
    traces (one per algorithm and shown iteration, the last thicker) instead of drawing them
    anew; the grey platform stands at the start q0, the black one at the target."""
    from jik.app.scene.nodes import set_key
    from jik.app.scene.playback import shown_iterations

    state = default_state("unicycle")
    dashboard = Dashboard(default_state("manipulator2"))
    scene = DashboardScene(dashboard)
    try:
        assert dashboard.wait(1, timeout=60)
        first = compute(state, 101)
        scene._draw(first)
        fixtures, mechanisms = dict(scene.nodes.fixtures), dict(scene.nodes.mechanisms)
        n = len(shown_iterations(first))
        root = f"/robot/unicycle-{state.task}"
        assert fixtures.keys() == {f"{root}/trace/{a}/{k}" for a in first.runs for k in range(n)}
        assert [fixtures[f"{root}/trace/extended/{k}"].thickness for k in (0, n - 1)] == [1.5, 3.5]
        second = updated_state(state, {"robot_parameters": {"q0": [0.2, -0.1, 0.3]}})
        scene._draw(compute(second, 102))
        assert all(
            scene.nodes.fixtures[k] is v for k, v in fixtures.items() if k in scene.nodes.fixtures
        )
        assert all(scene.nodes.mechanisms[k] is v for k, v in mechanisms.items())
        still = scene.nodes.sets[set_key(second)]["still"]
        np.testing.assert_allclose(still["home"].frame.position, (0.2, -0.1, 0.0))
        np.testing.assert_allclose(still["target"].frame.position[:2], second.target[:2])
    finally:
        scene.stop()
        dashboard.stop()


def test_a_vector_shown_as_text_stays_text_in_force():
    """A vector of more than three numbers (a pose task's target) is a text input: it shows the
    numbers in force, exactly, after every change (not a Python tuple), and its text sent back
    is no change."""
    from jik.app.dashboard.control_changes import path_text

    dashboard = Dashboard(updated_state(default_state("panda"), {"task": "target"}))
    scene = DashboardScene(dashboard)
    try:
        text = scene.controls.inputs["target"]
        assert text.value == path_text([dashboard.state.target])
        target = list(dashboard.state.target)
        target[0] += 0.05
        dashboard.update({"target": target})
        assert text.value == path_text([target])
        before = dashboard.state
        scene.controls.applies["target"].value = True  # (a click on its "apply target")
        assert dashboard.state == before
        typed = path_text([[*target[:-1], target[-1] + 0.1]])
        text.value = typed  # (typing: nothing is sent until the button is pressed)
        assert dashboard.state == before
        scene.controls.applies["target"].value = True
        assert dashboard.state.target[-1] == pytest.approx(target[-1] + 0.1)
    finally:
        scene.stop()
        dashboard.stop()


def test_a_refused_value_marks_its_inputs_in_the_scene_until_one_is_accepted():
    """A closed path the dashboard refuses, typed in the scene's GUI, marks the scene's path
    input (MARK before its label, the refusal as its hint) and no other, as the page
    marks its box; the next value accepted takes the mark away. A refusal from elsewhere (the
    page) marks the scene's inputs too: each of x0's sliders, each algorithm's checkbox."""
    from jik.app.dashboard import LABELS
    from jik.app.dashboard.control_changes import path_text
    from jik.app.dashboard.controls import controls
    from jik.engine.exceptions import InvalidInputError

    dashboard = Dashboard(default_state("manipulator2"))
    scene = DashboardScene(dashboard)
    inputs = scene.controls.inputs

    def marked() -> dict[str, str]:
        elements = {k: [h] for k, h in inputs.items() if k != "algorithms"}
        elements |= {f"algorithms.{a}": [b] for a, b in inputs["algorithms"].boxes.items()}
        return {k: h.hint for k, (h,) in elements.items() if h.label.startswith(MARK.strip())}

    try:
        path = inputs["path"]
        plain = (path.label, path.hint)
        (spec,) = [c for c in controls(dashboard.state) if c.key == "path"]
        assert plain == (spec.label, spec.help)
        path.value = "1, x"  # (what a user's typing in the viser GUI does: nothing sent)
        assert path.label == "closed path"
        scene.controls.applies["path"].value = True  # (a click on "apply closed path")
        assert path.value == path_text(dashboard.state.path)  # (the path in force)
        assert path.label == MARK + "closed path"
        assert marked() == {
            "path": "refused: path: point 1 of 1, '1, x', is not numbers separated by ',' "
            "(write 'y1, y2; y1, y2; ...')"
        }
        inputs["gamma"].value = 2.0
        assert dashboard.state.gamma == 2.0
        assert (path.label, path.hint) == plain and marked() == {}

        with pytest.raises(InvalidInputError):
            dashboard.update({"x0": [1.0, 2.0]})  # (the page's change, refused)
        assert sorted(marked()) == ["x0.0", "x0.1", "x0.2"]
        with pytest.raises(InvalidInputError):
            dashboard.update({"algorithms": []})
        assert sorted(marked()) == [f"algorithms.{a}" for a in sorted(inputs["algorithms"].boxes)]
        dashboard.update({"cycles": 2})
        assert marked() == {}
        assert inputs["algorithms"].boxes["extended"].label == LABELS["extended"]
    finally:
        scene.stop()
        dashboard.stop()


def test_a_singular_start_marks_the_starts_inputs_in_the_scene_until_a_result_without_it():
    """The 3R arm stretched out, x0 = (0, 0, 0), where J J^T is singular: the runs stop at their
    first leg, and the scene's x0 sliders are marked (MARK, the engine's message as their
    hint), as the page marks its boxes; a refusal meanwhile adds its own hint and leaves that
    mark; a start off the singular set gives a result without it, and every mark goes."""
    from jik.app.dashboard.controls import controls
    from jik.engine.exceptions import InvalidInputError

    chain = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 1.0, 1.0]}
    state = updated_state(
        default_state("manipulator2"),
        {"robot": "planar_chain", "robot_definition": chain, "x0": [0.0, 0.0, 0.0]},
    )
    dashboard = Dashboard(updated_state(state, {"task": "target", "target": [2.0, 1.0]}))
    scene = DashboardScene(dashboard)
    inputs = scene.controls.inputs
    try:
        assert dashboard.wait(1, timeout=60)
        _drawn(scene, 1)
        marked = {k: h.hint for k, h in inputs.items() if h.label.startswith(MARK)}
        assert sorted(marked) == ["x0.0", "x0.1", "x0.2"]
        assert all(h.startswith("stopped: ") and "J J^T is singular" in h for h in marked.values())
        with pytest.raises(InvalidInputError):
            dashboard.update({"x0": [1.0, 2.0]})
        assert inputs["x0.1"].hint.startswith("refused: ") and "; stopped: " in inputs["x0.1"].hint

        generation, _ = dashboard.update({"x0.1": 0.5})
        assert dashboard.wait(generation, timeout=60)
        _drawn(scene, generation)
        assert not [k for k, h in inputs.items() if h.label.startswith(MARK)]
        (spec,) = [c for c in controls(dashboard.state) if c.key == "x0.1"]
        assert (inputs["x0.1"].label, inputs["x0.1"].hint) == (spec.label, spec.help)
    finally:
        scene.stop()
        dashboard.stop()


class _RecordingScene:
    """A stand-in for viser's scene API: ``add_<kind>(name, ...)`` makes a node whose later
    assignments (node updates, each a message to every client) are recorded."""

    def __init__(self) -> None:
        self.updates: list[tuple[str, str]] = []
        self.nodes: dict[str, dict] = {}

    def __getattr__(self, attr: str):
        if not attr.startswith("add_"):
            raise AttributeError(attr)

        def add(name: str, *args, **values):
            self.nodes[name] = values
            return _RecordedNode(self, name)

        return add


class _RecordedNode:
    def __init__(self, scene: _RecordingScene, name: str) -> None:
        object.__setattr__(self, "_at", (scene, name))

    def __setattr__(self, key: str, value) -> None:
        scene, name = self._at
        scene.updates.append((name, key))
        scene.nodes[name][key] = value


@pytest.mark.parametrize("robot", ["manipulator1", "manipulator2"])
def test_sized_boxes_are_created_at_their_size(robot):
    """Manipulator 1's lever and runner and Manipulator 2's beam and arm are created at the size
    the task-plane box and the arm length give them: building a copy updates none of its nodes,
    and following the same state again leaves every value as built."""
    from jik.app.scene.mechanisms import MECHANISMS

    state = updated_state(
        default_state(robot), {"robot_parameters": {"l": 1.3}} if robot == "manipulator2" else {}
    )
    extent = ((-0.9, 2.1), (-0.7, 2.4))
    scene = _RecordingScene()
    copy = MECHANISMS[robot](scene, "/r/extended", (0, 0, 255), None, 0.0, state, extent)
    assert scene.updates == []
    built = {name: dict(values) for name, values in scene.nodes.items()}
    copy.resize(state, extent)
    assert scene.nodes == built
    sized = {  # (axis, length) of each sized box
        "manipulator1": {"runner": (1, 3.1), "lever/bar": (0, 3.0)},
        "manipulator2": {"beam": (0, 3.0), "carriage/arm": (0, 1.3)},
    }
    for name, (axis, length) in sized[robot].items():
        assert built[f"/r/extended/{name}"]["dimensions"][axis] == pytest.approx(length)
