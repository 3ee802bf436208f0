"""A session's 3D scene in viser: both algorithms as mechanisms, animated, with a GUI.

:class:`DashboardScene` follows the session's :class:`~jik.app.dashboard.Dashboard` (its
events) and puts each result on screen: the node sets (:mod:`jik.app.scene.nodes`), the
playback (:mod:`jik.app.scene.playback`), the camera (:mod:`jik.app.scene.camera`) and the
status. Its GUI (built from the control specification, :mod:`jik.app.scene.controls`) and the
draggable start point (:mod:`jik.app.scene.gizmo`) change the dashboard exactly like the page's
controls. The task plane is the world XY plane (z up). The viser server is a
:class:`~jik.app.scene.server.SceneServer`: only the API's relay reaches it.
"""

from __future__ import annotations

import contextlib
import json
import threading
from collections.abc import Sequence

from viser import FrameHandle

from ...engine.exceptions import InvalidInputError
from ...engine.exports import plural
from ..dashboard import COLORS, LABELS, Dashboard, Event, runs_key
from ..dashboard.algorithms import DEFAULT_ALGORITHMS, STYLES
from ..dashboard.controls import PROGRESS_AFTER
from .camera import CameraFraming
from .controls import SceneControls
from .fixtures import add_floor_grid
from .gizmo import StartGizmo
from .mechanisms import layout_name
from .nodes import NodeSets
from .playback import Playback, Timeline
from .server import SceneServer


class DashboardScene:
    """A viser server showing the dashboard's current result and editing its state;
    ``low_end``: drawn for a software renderer (no shadows, no environment map)."""

    def __init__(self, dashboard: Dashboard, low_end: bool = False) -> None:
        self.dashboard = dashboard
        self.server = SceneServer()  # (on a free loopback port: the page reaches it by the relay)
        self.server.scene.set_up_direction("+z")
        if low_end:  # (the page asks for it only when its browser renders WebGL without a GPU)
            self.server.scene.configure_default_lights(cast_shadow=False)
            self.server.scene.configure_environment_map(hdri=None)
        # (no share button: a share link would open the scene to anyone; jik's page has its own
        # "copy link")
        self.server.gui.configure_theme(
            control_width="small", show_logo=False, show_share_button=False
        )
        self.server.gui.main_panel.dock_right()
        self.server.gui.main_panel.set_width(300)
        self._lock = threading.RLock()
        self._stopped = False
        self._drawn_runs: tuple[str, ...] | None = None  # runs_key of what the scene shows
        self._framed: str | None = None  # layout_name of the robot the camera frames
        self.legend = self.server.gui.add_markdown(order=0, content=legend(DEFAULT_ALGORITHMS))
        self.playback = Playback(self.server.gui, self._lock, dashboard.scene_status)
        self.status, self.progress = self.playback.status, self.playback.progress
        self.controls = SceneControls(self.server.gui, self._send)
        self.gizmo = StartGizmo(self.server.scene, lambda: self.dashboard.state, self._send)
        self.camera = CameraFraming(self.server)
        add_floor_grid(self.server.scene)
        self.nodes = NodeSets(self.server.scene)
        self.server.on_client_connect(self._count_viewers)
        self.server.on_client_disconnect(self._count_viewers)
        self._unsubscribe = dashboard.subscribe(self._on_event, last=True)

    def connect(self, subprotocols: Sequence[str] | None):
        """The relay's websocket to this scene (await it; see :class:`SceneServer`)."""
        return self.server.connect(subprotocols)

    def stop(self) -> None:
        self._unsubscribe()
        with self._lock:  # (an event being shown ends first: nothing is sent to a stopped server)
            self._stopped = True
        self.playback.stop()
        self.server.stop()

    def _on_event(self, event: Event) -> None:
        with self._lock:
            if self._stopped:
                return
            try:
                if event.kind == "state":
                    self.controls.show(self.dashboard.state)
                elif event.kind == "progress":
                    msg = json.loads(event.data)
                    # (the runs only: the scene draws no E1, E2, and its status keeps the drawn
                    # result's while the page shows their progress)
                    runs = msg.get("phase") == "runs"
                    now = event.generation == self.dashboard.generation
                    if runs and now and msg["elapsed"] > PROGRESS_AFTER:
                        fraction = msg["fraction"]  # (None: not known)
                        self.progress.visible = fraction is None or fraction < 1
                        self.progress.value = min(100.0, 100.0 * (fraction or 0.0))  # type: ignore[misc]  # viser: settable
                        done = "" if fraction is None else f" {100 * fraction:.0f}%"
                        self.status.content = f"computing…{done}"
                elif event.kind == "result" and event.result is not None:
                    self._draw(event.result)
                elif event.kind == "ahead" and event.result is not None:
                    with self.server.atomic():  # (the hidden nodes of a result solved ahead)
                        self.nodes.prebuild(event.result)
                elif event.kind in ("refused", "error"):
                    msg = json.loads(event.data)
                    self.controls.sync(self.dashboard.state)
                    if event.kind == "refused":  # (its field's inputs say so, as the page's do)
                        self.controls.mark("refused", [(msg.get("field"), msg["message"])])
                    # (a refusal stops no computation: its progress bar stays)
                    self.progress.visible &= event.kind == "refused"
                    self.status.content = f"**{event.kind}:** {msg['message']}"
            except Exception as exc:  # never let a drawing error kill the worker thread
                self.status.content = f"**scene error:** {type(exc).__name__}: {exc}"

    def _count_viewers(self, _client) -> None:
        """The scene's status counts the browsers showing it: viser counts a client once its
        camera reported, and until then drops its clicks and edits."""
        self.dashboard.scene_status["viewers"] = len(self.server.get_clients())

    def _send(self, patch: dict) -> None:
        """A change from the GUI or the gizmo. A refused one needs nothing here: the
        dashboard's "refused" event shows it in the scene and on the page, and the controls go
        back to the values in force."""
        with contextlib.suppress(InvalidInputError):
            self.dashboard.update(patch, source="scene")

    def _draw(self, result) -> None:
        state = result.state
        drawn = runs_key(state)
        with self._lock, self.server.atomic():
            # The same configurations (gamma in continuous mode only rescales theta; the
            # animation runs per leg) change nothing in the scene but its controls' marks and its
            # status (a redraw would make every client render anew).
            if drawn != self._drawn_runs:
                self._drawn_runs = drawn
                # The start-point gizmo moves with the drawing it belongs to, in the same batch:
                # the client shows the start point and the paths that leave it together, never
                # one without the other.
                self.gizmo.place(state)
                self.nodes.show(result)
                if self._framed != layout_name(state):  # another robot: frame its reach
                    self._framed = layout_name(state)
                    self.camera.frame(result)
                self.playback.show(Timeline(result), self.nodes.mechanisms)
                first = next(iter(self.nodes.mechanisms.values()), None)
                self.dashboard.scene_status.update(
                    robot=state.robot,
                    playing=self.playback.playing,
                    mechanism=type(first).__name__,
                    joints=len(getattr(first, "joints", ())),
                    pose_frames=sum(
                        isinstance(h, FrameHandle) for h in self.nodes.fixtures.values()
                    ),
                )
            self.controls.sync(self.dashboard.state)
            # (each stopped run's field, x0 at a singular start, and message)
            self.controls.mark(
                "stopped", [(r.field, r.message) for r in result.runs.values() if r.field]
            )
            self.dashboard.scene_status.update(generation=result.generation)
        self._show_status(result)

    def _show_status(self, result) -> None:
        state = result.state
        self.progress.visible = False
        self.legend.content = legend(state.algorithms)
        runs = result.runs
        if state.task == "path" and all(len(r.drift) for r in runs.values()):
            n = len(next(iter(runs.values())).drift)
            drifts = ", ".join(f"{STYLES[a].short} **{r.drift[-1]:.3g}**" for a, r in runs.items())
            self.status.content = (
                f"generation {result.generation}: drift ‖x − x0‖ after the last cycle "
                f"({plural(n, 'cycle')}) — {drifts}"
            )
        else:
            messages = "; ".join(r.message for r in runs.values())
            self.status.content = f"generation {result.generation}: {messages}"


def legend(algorithms) -> str:
    """The scene's key: each chosen algorithm's colour, name and copy, and the grey start."""
    keys = " · ".join(
        f"<span style='color:{COLORS[a]}'>■ {LABELS[a]}</span>: {STYLES[a].robot}"
        for a in algorithms
    )
    lines = " and ".join(STYLES[a].line for a in algorithms)
    return f"{keys} · grey: start x0 (the plots: {lines})"
