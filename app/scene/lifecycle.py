"""A session's 3D scene in viser: both algorithms as mechanisms, animated, with a GUI.

(It stays whole, at about 440 lines: one class whose drawing, node sets kept per robot and
animation share the scene's lock, its timeline and its handles.)

The scene reads the session's results and writes to scene handles; its GUI (built from the
control specification, :mod:`jik.app.scene.controls`) and the draggable start point
(:mod:`jik.app.scene.gizmo`) change the session's :class:`~jik.app.dashboard.Dashboard`
exactly like the page's controls. The task plane is the world XY plane (z up); the nodes are
those of :mod:`jik.app.scene.mechanisms`, posed along :class:`~jik.app.scene.pose.Timeline`.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from typing import Any, cast

import numpy as np
import viser

from jik.app.dashboard import ALGORITHMS, COLORS, Dashboard, Event, runs_key
from jik.app.dashboard.help import STYLES
from jik.app.dashboard.plotting import corner_names
from jik.app.scene.controls import SceneControls
from jik.app.scene.gizmo import StartGizmo
from jik.app.scene.mechanisms import (
    HOME_COLOR,
    MECHANISMS,
    OPACITY,
    Mechanism,
    Platform,
    Z,
    add_floor_grid,
    extent_of,
    fixtures_of,
    layout_name,
    polyline,
    rgb,
    trace_tolerance,
)
from jik.app.scene.pose import Timeline
from jik.engine.exceptions import InvalidInputError

#: Frames per second of the animation (poses sent to the clients).
FPS = 25.0
#: The frame of the unicycle's nodes, drawn anew for each result (the manipulators' are kept,
#: one frame per robot and task: :meth:`DashboardScene._switch_set`).
UNICYCLE_ROOT = "/robot/unicycle"
#: Seconds of animation per leg (manipulators) or per shown iteration (unicycle) at speed 1.
SECONDS_PER_LEG = 1.6


class DashboardScene:
    """A viser server showing the dashboard's current result and editing its state.

    Parameters
    ----------
    dashboard : Dashboard
    host, port : str, int
        Where viser serves its client (the page frames it in an iframe).
    """

    def __init__(
        self, dashboard: Dashboard, host: str = "127.0.0.1", port: int = 0, low_end: bool = False
    ) -> None:
        self.dashboard = dashboard
        # Its own viser server on a loopback port: the page reaches it only through the API's
        # relay (jik.app.api.routes.sessions), which knows the session.
        self.server = viser.ViserServer(host=host, port=port, label="jik scene", verbose=False)
        self.server.scene.set_up_direction("+z")
        if low_end:
            # The low-end mode, which the page asks for only when its browser renders WebGL
            # without a GPU: without shadows and the environment map a frame costs far less.
            self.server.scene.configure_default_lights(cast_shadow=False)
            self.server.scene.configure_environment_map(hdri=None)
        self.server.gui.configure_theme(control_width="small", show_logo=False)
        self.server.gui.main_panel.dock_right()
        self.server.gui.main_panel.set_width(300)
        self._framed: str | None = None
        self._local = threading.local()  # see _syncing
        self._lock = threading.RLock()
        self._timeline: Timeline | None = None
        self._mechanisms: dict[str, Mechanism] = {}
        self._home: Mechanism | None = None  # the grey copy at the start x0
        self._s = 0.0
        self._posed: tuple[Timeline | None, float] = (None, 0.0)  # what the mechanisms show
        self.drawn_generation = 0
        self._drawn_runs: tuple[str, ...] | None = None  # runs_key of what the scene shows
        self._layout: tuple | None = None  # (robot, task) of the nodes on screen
        self._fixtures: dict[str, Any] = {}  # handles of the nodes of fixtures_of(), by name
        # Node sets of the manipulators' layouts drawn so far, hidden when not on screen:
        # (robot, task) -> {"frame", "mechanisms", "home", "fixtures", "root"}.
        self._sets: dict[tuple, dict[str, Any]] = {}
        self._stopped = False
        self._build_static_gui()
        self.controls = SceneControls(self.server.gui, self._send)
        self.gizmo = StartGizmo(self.server.scene, lambda: self.dashboard.state, self._send)
        add_floor_grid(self.server.scene)
        self.server.scene.add_frame("/robot", show_axes=False)
        self._unsubscribe = dashboard.subscribe(self._on_event, last=True)
        self._thread = threading.Thread(target=self._animate, name="jik-scene", daemon=True)
        self._thread.start()

    @property
    def _syncing(self) -> bool:
        """Whether this thread is moving the position slider (its callback is then not a user's
        scrub). Per thread: a user's scrub, which viser's thread delivers, is never dropped."""
        return getattr(self._local, "syncing", False)

    @_syncing.setter
    def _syncing(self, value: bool) -> None:
        self._local.syncing = value

    @property
    def port(self) -> int:
        return self.server.get_port()

    def stop(self) -> None:
        self._stopped = True
        self._unsubscribe()
        self._thread.join(timeout=2.0)
        self.server.stop()

    # -- GUI ------------------------------------------------------------------------------
    def _build_static_gui(self) -> None:
        gui = self.server.gui
        p, e = COLORS["pseudoinverse"], COLORS["extended"]
        gui.add_markdown(
            order=0,
            content=f"<span style='color:{p}'>■ pseudoinverse J^P# (8)</span>: "
            f"{STYLES['pseudoinverse']['robot']} · "
            f"<span style='color:{e}'>■ extended Jacobian J^E# (11)</span>: "
            f"{STYLES['extended']['robot']} · grey: start x0 (the plots: "
            f"{STYLES['pseudoinverse']['line']} and {STYLES['extended']['line']})",
        )
        with gui.add_folder("Playback", order=1):
            self.play = gui.add_button("Pause", icon=None)
            self.speed = gui.add_slider("speed", min=0.1, max=5.0, step=0.1, initial_value=1.0)
            self.scrub = gui.add_slider("position", min=0.0, max=1.0, step=0.001, initial_value=0.0)
            self.counter = gui.add_markdown("")  # (the iteration or leg on show)
            self.status = gui.add_markdown("computing…")
            self.progress = gui.add_progress_bar(0.0, visible=False, animated=True)
        self.playing = True

        @self.play.on_click
        def _(_) -> None:
            self.playing = not self.playing
            self.play.label = "Pause" if self.playing else "Play"
            self.dashboard.scene_status["playing"] = self.playing

        @self.scrub.on_update
        def _(_) -> None:
            if self._syncing or self._timeline is None:
                return
            self.playing = False
            self.play.label = "Play"
            self.dashboard.scene_status["playing"] = False
            self._s = float(self.scrub.value) * self._timeline.length

    # -- events ---------------------------------------------------------------------------
    def _on_event(self, event: Event) -> None:
        try:
            if event.kind == "state":
                self.controls.show(self.dashboard.state)
            elif event.kind == "progress":
                msg = json.loads(event.data)
                # (the runs only: the scene draws no E1, E2, and its status keeps the drawn
                # result's while the page shows their progress)
                runs = msg.get("phase") == "runs"
                if runs and event.generation == self.dashboard.generation and msg["elapsed"] > 0.5:
                    self.progress.visible = msg["fraction"] < 1
                    self.progress.value = min(100.0, 100.0 * msg["fraction"])  # type: ignore[misc]  # viser: settable
                    self.status.content = f"computing… {100 * msg['fraction']:.0f}%"
            elif event.kind == "result" and event.result is not None:
                self._draw(event.result)
            elif event.kind == "refused":
                self._sync_now()
                self.status.content = f"**refused:** {json.loads(event.data)['message']}"
            elif event.kind == "ahead" and event.result is not None:
                self._prebuild(event.result)
            elif event.kind == "error":
                self._sync_now()
                self.progress.visible = False
                self.status.content = f"**error:** {json.loads(event.data)['message']}"
        except Exception as exc:  # never let a drawing error kill the worker thread
            self.status.content = f"**scene error:** {type(exc).__name__}: {exc}"

    def _send(self, patch: dict) -> None:
        """A change from the GUI or the gizmo. A refused one needs nothing here: the
        dashboard's "refused" event shows it in the scene and on the page, and the controls go
        back to the values in force."""
        try:
            self.dashboard.update(patch, source="scene")
        except InvalidInputError:
            return

    # -- drawing --------------------------------------------------------------------------
    def _sync_now(self) -> None:
        """Show the values in force in the GUI (after a drawing, an error or a refusal)."""
        self.controls.sync(self.dashboard.state)

    def _draw(self, result) -> None:
        state = result.state
        drawn = runs_key(state)
        if drawn == self._drawn_runs:
            # The same configurations (gamma in continuous mode only rescales theta; the
            # animation runs per leg): nothing in the scene changes but its status, so nothing
            # is sent but the status (a redraw would make every client render anew).
            with self._lock:  # (the timeline on screen plays the same legs)
                self.drawn_generation = result.generation
                self._sync_now()
                self.dashboard.scene_status.update(generation=result.generation)
            self._show_status(result)
            return
        with self._lock, self.server.atomic():
            self._drawn_runs = drawn
            timeline = Timeline(result)
            extent = extent_of(result)
            # The start-point gizmo moves with the drawing it belongs to, in the same batch: the
            # client shows the start point and the paths that leave it together, never one
            # without the other.
            self.gizmo.place(state)
            layout = (layout_name(state), state.task)
            if timeline.unicycle or layout != self._layout:
                self._switch_set(None if timeline.unicycle else layout, result, timeline, extent)
            else:
                # Same robot and task: the nodes stay and take the new values (re-creating them
                # costs the client a remount of every node).
                self._update_set(self._sets[layout], result, extent)
            if self._home is not None:
                self._home.pose(np.asarray(state.x0))
            if self._framed != layout_name(state):
                self._framed = layout_name(state)
                self._frame_camera(extent)
            self._timeline = timeline
            # Playing: from the start. Paused: at the end, where the drift of J^P# shows.
            self._s = 0.0 if self.playing else timeline.length
            self._pose(self._s)
            self._show_position(timeline)
            self.drawn_generation = result.generation
            self._sync_now()
            self.dashboard.scene_status.update(
                generation=result.generation, robot=state.robot, playing=self.playing,
                mechanism=type(next(iter(self._mechanisms.values()), None)).__name__,
                joints=len(getattr(self._mechanisms.get("extended"), "joints", ())),
            )  # fmt: skip
        self._show_status(result)

    def _switch_set(self, layout: tuple | None, result, timeline: Timeline, extent) -> None:
        """Show the node set of ``layout`` (robot, task), or the unicycle's when None, and hide
        the others. A manipulator's set is built when first needed (or ahead, see
        :meth:`_prebuild`) and then kept: showing it again moves its nodes, which costs the
        client far less than mounting new ones. The unicycle's paths are drawn anew each time."""
        scene = self.server.scene
        if self._timeline is not None and self._timeline.unicycle:  # (the drawing on screen)
            scene.remove_by_name(UNICYCLE_ROOT)
        self._layout = layout
        for key, entry in self._sets.items():
            if key != layout:
                entry["frame"].visible = False
        if layout is None:
            scene.add_frame(UNICYCLE_ROOT, show_axes=False)
            self._mechanisms, self._fixtures, self._home = {}, {}, None
            self._draw_unicycle(result, timeline, extent)
            return
        if layout not in self._sets:
            entry = self._build_set(result, extent, visible=True)
        else:
            entry = self._sets[layout]
            entry["frame"].visible = True
            self._update_set(entry, result, extent)
        self._fixtures, self._mechanisms, self._home = (
            entry["fixtures"],
            entry["mechanisms"],
            entry["home"],
        )

    def _build_set(self, result, extent, visible: bool) -> dict[str, Any]:
        """The nodes of ``result``'s manipulator and task under their own frame."""
        scene = self.server.scene
        state = result.state
        root = f"/robot/{layout_name(state)}-{state.task}"
        entry: dict[str, Any] = {
            "root": root, "frame": scene.add_frame(root, show_axes=False, visible=visible),
            "mechanisms": {}, "home": None, "fixtures": {},
        }  # fmt: skip
        cls = MECHANISMS.get(state.robot)
        if cls is not None:
            entry["home"] = cls(scene, f"{root}/home", HOME_COLOR, 0.25, -0.03, state, extent)
            entry["mechanisms"] = {
                a: cls(scene, f"{root}/{a}", rgb(COLORS[a]), OPACITY[a], Z[a], state, extent)
                for a in ALGORITHMS
            }
        self._place_fixtures(result, extent, root, entry["fixtures"])
        self._sets[(layout_name(state), state.task)] = entry
        return entry

    def _update_set(self, entry: dict[str, Any], result, extent) -> None:
        for m in (*entry["mechanisms"].values(), entry["home"]):
            if m is not None:
                m.resize(result.state, extent)
        self._place_fixtures(result, extent, entry["root"], entry["fixtures"])

    def _prebuild(self, result) -> None:
        """Build the hidden node set of a result solved ahead (the other manipulator's
        defaults, see ``Dashboard._prefetch``): switching to it then only moves nodes."""
        state = result.state
        layout = (layout_name(state), state.task)
        if state.robot not in MECHANISMS:
            return
        with self._lock, self.server.atomic():
            if layout in self._sets:
                return
            entry = self._build_set(result, extent_of(result), visible=False)
            for a, m in entry["mechanisms"].items():
                m.pose(result.runs[a].x[-1])
            entry["home"].pose(np.asarray(state.x0))

    def _show_status(self, result) -> None:
        state = result.state
        self.progress.visible = False
        p, e = result.runs["pseudoinverse"], result.runs["extended"]
        if state.task == "path" and len(p.drift) and len(e.drift):
            self.status.content = (
                f"generation {result.generation}: drift after {len(p.drift)} cycles — "
                f"pseudoinverse **{p.drift[-1]:.3g}**, extended **{e.drift[-1]:.2g}**"
            )
        else:
            self.status.content = f"generation {result.generation}: {p.message}; {e.message}"

    def _frame_camera(self, extent) -> None:
        """Look at the task plane from the front, tilted, so the whole workspace is in view."""
        (xlo, xhi), (ylo, yhi) = extent
        center = np.array([(xlo + xhi) / 2, (ylo + yhi) / 2, 0.0])
        size = max(xhi - xlo, yhi - ylo)
        position = center + np.array([0.0, -0.75 * size, 1.05 * size])
        self.server.initial_camera.position = position
        self.server.initial_camera.look_at = center
        for client in self.server.get_clients().values():
            with client.atomic():
                client.camera.position = position
                client.camera.look_at = center

    def _place_fixtures(self, result, extent, root: str, fixtures: dict[str, Any]) -> None:
        """Give the fixtures under ``root`` (rails or guide, traces, targets; see
        :func:`_fixtures`; their handles in ``fixtures``) the values of ``result``: existing
        nodes are moved, missing ones (all, in a new set; a target the path gained) are added,
        ones it lost are removed."""
        scene = self.server.scene
        add: dict[str, Callable[..., Any]] = {
            "box": scene.add_box, "line": scene.add_line_segments, "ball": scene.add_icosphere
        }  # fmt: skip
        wanted = fixtures_of(result, extent, root)
        for name in [n for n in fixtures if n not in wanted]:
            fixtures.pop(name).remove()
        for name, (kind, values, style) in wanted.items():
            if name not in fixtures:
                fixtures[name] = add[kind](name, **style, **values)
                if name.startswith(f"{root}/targets/"):
                    k = int(name.rsplit("/", 1)[1])
                    scene.add_label(
                        f"{name}/label",
                        corner_names(result)[k],
                        position=(0.05, 0.05, 0.05),
                    )
                continue
            for key, value in values.items():
                setattr(fixtures[name], key, value)

    def _draw_unicycle(self, result, timeline: Timeline, extent) -> None:
        scene = self.server.scene
        state = result.state
        tol = trace_tolerance(extent)
        target = Platform(scene, f"{UNICYCLE_ROOT}/target", (0, 0, 0), 0.3, 0.0, state, None)
        target.pose(state.target)
        q0 = state.robot_parameters["q0"]
        home = Platform(scene, f"{UNICYCLE_ROOT}/home", HOME_COLOR, 0.3, 0.0, state, None)
        home.pose(q0)
        for a in ALGORITHMS:
            run = result.runs[a]
            base = np.asarray(rgb(COLORS[a]), dtype=float)
            for n, i in enumerate(timeline.shown):
                i = min(int(i), len(run.platform) - 1)
                P = run.platform[i]
                last = n == len(timeline.shown) - 1
                mix = 1.0 if last else 0.3 + 0.5 * n / len(timeline.shown)
                color = cast(
                    "tuple[int, int, int]", tuple(int(v) for v in (255 - mix * (255 - base)))
                )
                pts = np.column_stack([P[:, 0], P[:, 1], np.full(len(P), 0.02 + Z[a] * 0.2)])
                scene.add_line_segments(
                    f"{UNICYCLE_ROOT}/trace/{a}/{n}",
                    polyline(pts, tol),
                    color,
                    thickness=3.5 if last else 1.5,
                    thickness_units="screen",
                )
            self._mechanisms[a] = Platform(
                scene,
                f"{UNICYCLE_ROOT}/{a}",
                rgb(COLORS[a]),
                OPACITY[a],
                Z[a] * 0.5,
                state,
                None,
            )

    def _pose(self, s: float) -> None:
        if self._timeline is None:
            return
        self._posed = (self._timeline, s)
        configs = self._timeline.at(s)
        for a, m in self._mechanisms.items():
            m.pose(configs[a])

    # -- animation ------------------------------------------------------------------------
    def _show_position(self, timeline: Timeline) -> None:
        """The position slider at the playback position (not a change of it by the user)."""
        self._syncing = True
        try:
            self.scrub.value = round(min(self._s / timeline.length, 1.0), 3)  # type: ignore[misc]  # viser: settable
            counter = timeline.counter(self._s)
            if self.counter.content != counter:
                self.counter.content = counter
        finally:
            self._syncing = False

    def _animate(self) -> None:
        last, last_gui = time.monotonic(), 0.0
        while not self._stopped:
            time.sleep(1.0 / FPS)
            now = time.monotonic()
            dt, last = now - last, now
            with self._lock:
                # (Read under the lock: a timeline read before a drawing swapped it would differ
                # from the one just posed, and pose the new one again.)
                timeline = self._timeline
                if timeline is None:
                    continue
                moving = self.playing
                if moving:
                    self._s += dt * float(self.speed.value) / SECONDS_PER_LEG
                    if self._s > timeline.length + 0.5:  # hold the end a moment, then loop
                        self._s = 0.0
                # Paused: nothing to send until scrubbed (or drawn, which poses too).
                if self._posed != (timeline, self._s):
                    self._pose(self._s)
            if not moving:
                continue
            if now - last_gui > 0.25:
                last_gui = now
                self._show_position(timeline)


def start_scene(dashboard: Dashboard, low_end: bool = False) -> DashboardScene:
    """Start the viser scene for one session's ``dashboard``, on a free loopback port."""
    return DashboardScene(dashboard, low_end=low_end)
