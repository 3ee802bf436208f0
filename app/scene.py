"""The dashboard's 3D scene in viser: both algorithms as mechanisms, animated, with a GUI.

The scene only reads the dashboard's results and writes to scene handles; its GUI (built from
the registry) and the draggable start point change the one :class:`~jik.app.dashboard.Dashboard`
state, exactly like the page's controls. The task plane is the world XY plane (z up).

Drawn mechanisms
----------------
- Manipulator 2 (37): an XY gantry, a beam at height x1 on two rails, a carriage at x2 on the
  beam, and a revolute arm of length l at angle x3; the end effector is the task point.
- Manipulator 1 (30), schematic of its normal form k(x) = (x1, x2 + x1 x3): a slider at height
  x2 on the vertical guide, a lever of slope x3 pivoting on it, and a vertical runner at x1;
  the task point W = (x1, x2 + x1 x3) is where the lever crosses the runner.
- The unicycle (40): a platform with two wheels and a heading nose at the pose q(t).

The pseudoinverse is the translucent red ghost, the extended Jacobian the solid blue robot (the
colours of every plot); the grey ghost is the start configuration x0.
"""

from __future__ import annotations

import json
import math
import threading
import time
from collections.abc import Callable
from typing import Any, cast

import numpy as np
import viser

from jik.app.controls import GROUPS, Control, control_values, controls
from jik.app.dashboard import ALGORITHMS, COLORS, Dashboard, Event, runs_key
from jik.engine.exceptions import InvalidInputError

FPS = 25.0
#: The frame of the unicycle's nodes, drawn anew for each result (the manipulators' are kept,
#: one frame per robot and task: :meth:`DashboardScene._switch_set`).
UNICYCLE_ROOT = "/robot/unicycle"
#: Seconds of animation per leg (manipulators) or per shown iteration (unicycle) at speed 1.
SECONDS_PER_LEG = 1.6
#: Seconds between two changes of the start point while its gizmo is dragged (each starts a
#: computation; the dashboard solves only the newest state, but every change is an event).
DRAG_INTERVAL = 0.15
#: Unicycle iterations shown in the animation (geometrically spaced, the last always).
UNICYCLE_SHOWN = 10
_Z = {"pseudoinverse": 0.10, "extended": 0.0}
_OPACITY = {"pseudoinverse": 0.55, "extended": None}
HOME_COLOR = (150, 150, 150)


def _rgb(hex_color: str) -> tuple[int, int, int]:
    h = hex_color.lstrip("#")
    return int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16)


def yaw_quaternion(angle: float) -> tuple[float, float, float, float]:
    """wxyz of a rotation by ``angle`` [rad] about the z axis."""
    return (math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2))


def quaternion_yaw(wxyz) -> float:
    """Rotation about z of a quaternion (its other rotations are ignored)."""
    w, x, y, z = (float(v) for v in wxyz)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


# -- the start point as a draggable pose, and back --------------------------------------------
def gizmo_pose(robot: str, x0, robot_parameters: dict) -> tuple[tuple[float, float], float]:
    """Where the start-point gizmo sits: ((X, Y), yaw) in the task plane.

    Manipulator 2: the carriage (x2, x1), yaw x3. Manipulator 1: the task point
    W = (x1, x2 + x1 x3), yaw atan(x3) (the lever's slope). Unicycle: the initial pose q0.
    """
    if robot == "manipulator2":
        return (x0[1], x0[0]), x0[2]
    if robot == "manipulator1":
        return (x0[0], x0[1] + x0[0] * x0[2]), math.atan(x0[2])
    q0 = robot_parameters["q0"]
    return (q0[0], q0[1]), q0[2]


#: Coordinates of a start point from the gizmo that differ from the state's by no more than this
#: keep the state's value: the round trip through the gizmo's pose (a quaternion, a rotation of
#: the axes) is exact only to rounding, and a press on the gizmo must not be a change.
GIZMO_ROUNDING = 1e-9


def _snapped(values, before) -> list[float]:
    pairs = zip(values, map(float, before), strict=True)
    return [b if abs(v - b) <= GIZMO_ROUNDING else v for v, b in pairs]


def start_from_gizmo(robot: str, xy, yaw: float, state) -> dict:
    """The dashboard change for a gizmo moved to ``xy`` with rotation ``yaw`` (inverse of above).

    Manipulator 1 keeps x3 = tan(yaw) within a slope of +-20 (the lever cannot turn vertical).
    Coordinates within :data:`GIZMO_ROUNDING` of the state's keep their value: a gizmo where
    the state puts it gives the state's start point exactly.
    """
    X, Y = float(xy[0]), float(xy[1])
    if robot == "manipulator2":
        x3 = float(state.x0[2]) + math.remainder(yaw - float(state.x0[2]), 2 * math.pi)
        return {"x0": _snapped([Y, X, x3], state.x0)}
    if robot == "manipulator1":
        x3 = math.tan(max(-1.52, min(1.52, yaw)))
        return {"x0": _snapped([X, Y - X * x3, x3], state.x0)}
    q0 = list(state.robot_parameters["q0"])
    q3 = q0[2] + math.remainder(yaw - q0[2], 2 * math.pi)
    return {"robot_parameters": {"q0": _snapped([X, Y, q3], q0)}}


# -- animation timelines ------------------------------------------------------------------------
class Timeline:
    """Configurations of both algorithms as functions of one playback position s in [0, length]."""

    def __init__(self, result) -> None:
        self.result = result
        self.unicycle = any(r.platform is not None for r in result.runs.values())
        if self.unicycle:
            m = max(len(r.platform) for r in result.runs.values())
            shown = np.unique(np.geomspace(1, m, num=UNICYCLE_SHOWN).astype(int) - 1)
            self.shown = np.union1d(shown, [0, m - 1]).astype(int)
            self.length = float(len(self.shown))
        else:
            self.theta_end = max(float(r.theta[-1]) for r in result.runs.values())
            legs = int(max(r.leg.max() for r in result.runs.values())) + 1
            self.leg_theta = self.theta_end / legs
            self.length = float(legs)

    def at(self, s: float) -> dict[str, np.ndarray]:
        """Per algorithm: the configuration x (manipulators) or pose q (unicycle) at ``s``."""
        s = min(max(s, 0.0), self.length)
        out = {}
        if self.unicycle:
            i = min(int(s), len(self.shown) - 1)
            frac = s - i if s < self.length else 1.0
            for a, run in self.result.runs.items():
                P = run.platform[min(self.shown[i], len(run.platform) - 1)]
                j = frac * (len(P) - 1)
                j0 = min(int(j), len(P) - 2)
                out[a] = P[j0] + (j - j0) * (P[j0 + 1] - P[j0])
            return out
        theta = s * self.leg_theta
        for a, run in self.result.runs.items():
            out[a] = np.array(
                [np.interp(theta, run.theta, run.x[:, k]) for k in range(run.x.shape[1])]
            )
        return out

    def iteration(self, s: float) -> int | None:
        if not self.unicycle:
            return None
        return int(self.shown[min(int(s), len(self.shown) - 1)])


# -- mechanisms ---------------------------------------------------------------------------------
class _Mechanism:
    """Scene nodes of one robot copy (one algorithm, or the grey start ghost)."""

    def __init__(self, scene, root: str, color, opacity, z: float, state, extent) -> None:
        self.scene, self.root, self.color, self.opacity, self.z = scene, root, color, opacity, z
        self.state, self.extent = state, extent
        self.build()

    def box(self, name, dims, position=(0.0, 0.0, 0.0), wxyz=(1.0, 0.0, 0.0, 0.0), color=None):
        return self.scene.add_box(
            f"{self.root}/{name}",
            color=color or self.color,
            dimensions=dims,
            opacity=self.opacity,
            position=position,
            wxyz=wxyz,
            cast_shadow=False,
        )

    def ball(self, name, radius, position=(0.0, 0.0, 0.0), color=None):
        return self.scene.add_icosphere(
            f"{self.root}/{name}",
            radius=radius,
            color=color or self.color,
            opacity=self.opacity,
            position=position,
            cast_shadow=False,
            subdivisions=2,
        )

    def build(self) -> None: ...

    def resize(self, state, extent) -> None:
        """Follow a new arm length or task-plane box in place (no node is re-created)."""
        self.state, self.extent = state, extent

    def pose(self, x) -> None: ...


class _Gantry(_Mechanism):
    """Manipulator 2: XY gantry (prismatic x1 vertical, x2 horizontal) with a revolute arm."""

    def build(self) -> None:
        (lo, hi), _ = self.extent
        self.span = (lo, hi)
        l = float(self.state.robot_parameters["l"])
        self.beam = self.box("beam", (hi - lo, 0.07, 0.05))
        self.carriage = self.scene.add_frame(f"{self.root}/carriage", show_axes=False)
        self.box("carriage/body", (0.2, 0.2, 0.09))
        self.ball("carriage/joint", 0.06, (0.0, 0.0, 0.07), color=(40, 40, 40))
        self.arm = self.box("carriage/arm", (l, 0.06, 0.04), (l / 2, 0.0, 0.07))
        self.effector = self.ball("carriage/effector", 0.07, (l, 0.0, 0.07))

    def resize(self, state, extent) -> None:
        super().resize(state, extent)
        (lo, hi), _ = extent
        self.span = (lo, hi)
        l = float(state.robot_parameters["l"])
        self.beam.dimensions = (hi - lo, 0.07, 0.05)
        self.arm.dimensions = (l, 0.06, 0.04)
        self.arm.position = (l / 2, 0.0, 0.07)
        self.effector.position = (l, 0.0, 0.07)

    def pose(self, x) -> None:
        lo, hi = self.span
        self.beam.position = ((lo + hi) / 2, float(x[0]), self.z)
        self.carriage.position = (float(x[1]), float(x[0]), self.z + 0.05)
        self.carriage.wxyz = yaw_quaternion(float(x[2]))


class _NormalForm(_Mechanism):
    """Manipulator 1 (30): slider x2 on the vertical guide, lever of slope x3, runner at x1."""

    def build(self) -> None:
        (xlo, xhi), (lo, hi) = self.extent
        self.runner = self.box("runner", (0.05, hi - lo, 0.04))
        self.runner_span = (lo, hi)
        self.slider = self.box("slider", (0.18, 0.14, 0.08))
        self.lever = self.scene.add_frame(f"{self.root}/lever", show_axes=False)
        # Along the lever from x = xlo to x = xhi of the task-plane box when level: shorter in x
        # when it tilts, so it stays in the framed view.
        self.bar = self.box("lever/bar", (xhi - xlo, 0.045, 0.03), ((xlo + xhi) / 2, 0.0, 0.05))
        self.ball("lever/pivot", 0.06, (0.0, 0.0, 0.05), color=(40, 40, 40))
        self.point = self.ball("W", 0.08)
        if self.root.endswith("extended"):
            self.scene.add_label(f"{self.root}/W/label", "W (task point)", position=(0.08, 0.08, 0))

    def resize(self, state, extent) -> None:
        super().resize(state, extent)
        (xlo, xhi), (lo, hi) = extent
        self.runner.dimensions = (0.05, hi - lo, 0.04)
        self.runner_span = (lo, hi)
        self.bar.dimensions = (xhi - xlo, 0.045, 0.03)
        self.bar.position = ((xlo + xhi) / 2, 0.0, 0.05)

    def pose(self, x) -> None:
        x1, x2, x3 = (float(v) for v in x)
        lo, hi = self.runner_span
        self.runner.position = (x1, (lo + hi) / 2, self.z)
        self.slider.position = (0.0, x2, self.z)
        self.lever.position = (0.0, x2, self.z)
        self.lever.wxyz = yaw_quaternion(math.atan(x3))
        self.point.position = (x1, x2 + x1 * x3, self.z + 0.08)


class _Platform(_Mechanism):
    """The unicycle: a wheeled platform at pose (q1, q2, q3), nose pointing along the heading."""

    def build(self) -> None:
        self.frame = self.scene.add_frame(f"{self.root}/platform", show_axes=False)
        self.box("platform/body", (0.7, 0.45, 0.18), (0.0, 0.0, 0.2))
        self.box("platform/nose", (0.3, 0.12, 0.08), (0.45, 0.0, 0.2))
        axle = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)  # cylinder axis -> y
        for side in (-1, 1):
            self.scene.add_cylinder(
                f"{self.root}/platform/wheel{side}",
                radius=0.16,
                height=0.08,
                color=(50, 50, 50),
                opacity=self.opacity,
                position=(0.0, side * 0.28, 0.16),
                wxyz=axle,
                cast_shadow=False,
            )

    def pose(self, q) -> None:
        self.frame.position = (float(q[0]), float(q[1]), self.z)
        self.frame.wxyz = yaw_quaternion(float(q[2]))


_MECHANISMS = {"manipulator1": _NormalForm, "manipulator2": _Gantry}


# Every line (traces, grid) is sized in pixels: viser's world-unit lines solve a ray-segment
# distance per fragment and redraw each line in a second blended pass; the four traces of a
# manipulator doubled the cost of a frame in software WebGL (no GPU).


def _add_floor_grid(scene, half: float = 10.0, cell: float = 0.5, section: float = 1.0) -> None:
    """A grid on the task plane (z slightly below 0) drawn as two sets of line segments.

    viser's ``add_grid`` shades every pixel of its plane; in software WebGL (no GPU) that is a
    fifth of each frame, line segments cost next to nothing.
    """
    ticks = np.arange(-half, half + cell / 2, cell)
    on_section = np.isclose(np.remainder(ticks + half, section), 0.0) | np.isclose(
        np.remainder(ticks + half, section), section
    )
    z = -0.06
    for name, where, color in (
        ("cells", ticks[~on_section], (200, 200, 200)),
        ("sections", ticks[on_section], (140, 140, 140)),
    ):
        n = len(where)
        lines = np.zeros((2 * n, 2, 3))
        lines[:n, :, 0] = where[:, None]  # along y
        lines[:n, 0, 1], lines[:n, 1, 1] = -half, half
        lines[n:, :, 1] = where[:, None]  # along x
        lines[n:, 0, 0], lines[n:, 1, 0] = -half, half
        lines[..., 2] = z
        scene.add_line_segments(
            f"/grid/{name}", lines, color, thickness=1.0, thickness_units="screen"
        )


#: Largest distance of a drawn trace from the computed path, as a fraction of the scene's size
#: (about a third of a pixel at the dashboard's size).
TRACE_TOLERANCE = 1e-3


def simplify(points: np.ndarray, tol: float) -> np.ndarray:
    """The points of the polyline ``points`` (n, d) that keep it within ``tol`` of every
    original point (Ramer-Douglas-Peucker; the first and the last are always kept).

    A trace costs the viser client per segment: in software WebGL (no GPU) a thousand segments
    add about 15 ms to every frame. The continuous task paths are straight between targets, eq.
    (5), so most of their recorded points lie on a line.
    """
    n = len(points)
    keep = np.zeros(n, dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, n - 1)]
    while stack:
        i, j = stack.pop()
        if j <= i + 1:
            continue
        a, d = points[i], points[j] - points[i]
        rel = points[i + 1 : j] - a
        L2 = float(d @ d)
        t = np.clip(rel @ d / L2, 0.0, 1.0) if L2 > 0 else np.zeros(len(rel))
        dist = np.linalg.norm(rel - t[:, None] * d, axis=1)
        k = int(np.argmax(dist))
        if dist[k] > tol:
            m = i + 1 + k
            keep[m] = True
            stack += [(i, m), (m, j)]
    return points[keep]


def _trace_tolerance(extent) -> float:
    """:data:`TRACE_TOLERANCE` of the task-plane box ``extent`` (see :func:`_extent`)."""
    (xlo, xhi), (ylo, yhi) = extent
    return TRACE_TOLERANCE * max(xhi - xlo, yhi - ylo)


def _polyline(points: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """(n, 3) points -> segments (m - 1, 2, 3) of the polyline simplified to within ``tol``."""
    points = simplify(points, tol) if tol > 0 and len(points) > 2 else points
    return np.stack([points[:-1], points[1:]], axis=1)


def _fixtures(result, extent, root: str) -> dict[str, tuple[str, dict, dict]]:
    """The parts of a manipulator's scene besides the mechanisms, by node name: (kind, the
    values that follow the result, the fixed style). The rails (Manipulator 2) or the guide
    (Manipulator 1) span the task-plane box; the task paths of both algorithms, and for
    Manipulator 2 the carriage paths (x2, x1), which are the joint paths: closed for J^E#,
    not for J^P#; the targets of the path's legs."""
    (xlo, xhi), (ylo, yhi) = extent
    tol = _trace_tolerance(extent)
    robot = result.state.robot
    grey: dict = {"color": (90, 90, 90)}
    out: dict[str, tuple[str, dict, dict]] = {}
    rail = (0.06, yhi - ylo, 0.05)
    if robot == "manipulator2":
        for side, x in (("left", xlo), ("right", xhi)):
            out[f"{root}/rails/{side}"] = (
                "box", {"dimensions": rail, "position": (x, (ylo + yhi) / 2, -0.02)}, grey
            )  # fmt: skip
    elif robot == "manipulator1":
        out[f"{root}/guide"] = (
            "box", {"dimensions": rail, "position": (0.0, (ylo + yhi) / 2, -0.02)}, grey
        )  # fmt: skip
    for a in ALGORITHMS:
        run = result.runs[a]
        line = {"colors": _rgb(COLORS[a]), "thickness_units": "screen"}  # pixels, see above
        task = np.column_stack([run.y[:, 0], run.y[:, 1], np.full(len(run.y), _Z[a] + 0.16)])
        out[f"{root}/trace/{a}/task"] = (
            "line", {"points": _polyline(task, tol)},
            {**line, "thickness": 3.0 if a == "pseudoinverse" else 2.0},
        )  # fmt: skip
        if robot == "manipulator2":
            joints = np.column_stack([run.x[:, 1], run.x[:, 0], np.full(len(run.x), _Z[a] + 0.1)])
            out[f"{root}/trace/{a}/joints"] = (
                "line", {"points": _polyline(joints, tol)}, {**line, "thickness": 1.2}
            )  # fmt: skip
    for k, target in enumerate(result.targets):
        out[f"{root}/targets/{k}"] = (
            "ball", {"position": (float(target[0]), float(target[1]), 0.2)},
            {"radius": 0.05, "color": (0, 0, 0)},
        )  # fmt: skip
    return out


# -- the scene ----------------------------------------------------------------------------------
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
        # proxy (jik.app.routers.scene), which knows the session.
        self.server = viser.ViserServer(host=host, port=port, label="jik scene", verbose=False)
        self.server.scene.set_up_direction("+z")
        if low_end:
            # The page asks for this only when its browser reports a software WebGL renderer:
            # without shadows and the environment map a frame costs that renderer far less.
            self.server.scene.configure_default_lights(cast_shadow=False)
            self.server.scene.configure_environment_map(hdri=None)
        self.server.gui.configure_theme(control_width="small", show_logo=False)
        self.server.gui.main_panel.dock_right()
        self.server.gui.main_panel.set_width(300)
        self._framed: str | None = None
        self._local = threading.local()  # see _syncing
        self._dragging = False
        self._lock = threading.RLock()
        self._timeline: Timeline | None = None
        self._mechanisms: dict[str, _Mechanism] = {}
        self._home: _Mechanism | None = None  # the grey copy at the start x0
        self._s = 0.0
        self._posed: tuple[Timeline | None, float] = (None, 0.0)  # what the mechanisms show
        self.drawn_generation = 0
        self._drawn_runs: tuple[str, ...] | None = None  # runs_key of what the scene shows
        self._structure: tuple | None = None
        self._layout: tuple | None = None  # (robot, task) of the nodes on screen
        self._fixtures: dict[str, Any] = {}  # handles of the nodes of _fixtures(), by name
        # Node sets of the manipulators' layouts drawn so far, hidden when not on screen:
        # (robot, task) -> {"frame", "mechanisms", "home", "fixtures", "root"}.
        self._sets: dict[tuple, dict[str, Any]] = {}
        # viser declares the setter of a GUI handle's ``value`` apart from its getter, so mypy
        # sees a read-only property; assigning it is viser's API (ignores marked "viser: settable").
        self._controls: dict[str, viser.GuiInputHandle[Any]] = {}
        self._options: dict[str, dict[str, str]] = {}  # a select's value -> its label
        self._folders: list = []
        self._last_drag = 0.0  # when a move of the gizmo last changed the state
        self._drag_pending: tuple | None = None  # the newest move within DRAG_INTERVAL
        self._drag_timer: threading.Timer | None = None  # applies it when the interval ends
        self._drag_lock = threading.Lock()
        self._stopped = False
        self._build_static_gui()
        _add_floor_grid(self.server.scene)
        self.server.scene.add_frame("/robot", show_axes=False)
        self._unsubscribe = dashboard.subscribe(self._on_event, last=True)
        self._thread = threading.Thread(target=self._animate, name="jik-scene", daemon=True)
        self._thread.start()

    @property
    def _syncing(self) -> bool:
        """Whether this thread is setting the GUI's values to the state's (the update callbacks
        that viser calls from within the assignment are then not a user's change).

        Per thread: a user's change, which viser's thread delivers, is never dropped while the
        animation's thread moves the position slider or the worker syncs the controls."""
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
            content=f"<span style='color:{p}'>■ pseudoinverse J^P# (8)</span>, translucent · "
            f"<span style='color:{e}'>■ extended Jacobian J^E# (11)</span>, solid · "
            "grey: start x0",
        )
        with gui.add_folder("Playback", order=1):
            self.play = gui.add_button("Pause", icon=None)
            self.speed = gui.add_slider("speed", min=0.1, max=5.0, step=0.1, initial_value=1.0)
            self.scrub = gui.add_slider("position", min=0.0, max=1.0, step=0.001, initial_value=0.0)
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

    def _change(self, patch: dict) -> None:
        if self._syncing:
            return
        try:
            self.dashboard.update(patch, source="scene")
        except InvalidInputError:
            # The dashboard's "refused" event shows the refusal here and on the page, and the
            # controls go back to the values in force.
            return

    def _rebuild_controls(self, state) -> None:
        """GUI inputs for ``state``: one per control of :func:`jik.app.controls.controls` (the
        page's are built from the same list), in one folder per group."""
        gui = self.server.gui
        for folder in self._folders:
            folder.remove()
        self._folders, self._controls, self._options = [], {}, {}
        spec = controls(state)
        values = control_values(state)
        self._syncing = True
        try:
            for order, (group, title) in enumerate(GROUPS, start=2):
                with gui.add_folder(title, order=order) as folder:
                    self._folders.append(folder)
                    for control in spec:
                        if control.group == group:
                            self._add_control(control, values.get(control.key))
        finally:
            self._syncing = False

    def _add_control(self, control: Control, value: Any) -> None:
        """One viser input for ``control``; its changes go to the dashboard by the control's key
        (:func:`jik.app.controls.expand` makes them a state patch)."""
        gui, key = self.server.gui, control.key
        handle: Any
        if control.kind == "preset":
            button = gui.add_button(control.label, hint=control.help)
            button.on_click(lambda _: self._change({key: control.value}))
            return
        if control.kind == "select":
            by_label = {label: v for v, label in control.options}
            labels = self._options[key] = {v: label for v, label in control.options}
            handle = gui.add_dropdown(control.label, list(by_label), initial_value=labels[value],
                                      hint=control.help)  # fmt: skip
            handle.on_update(lambda e: self._change({key: by_label[e.target.value]}))
        elif control.kind == "slider":
            handle = gui.add_slider(
                control.label, min=control.minimum, max=control.maximum, step=control.step,
                initial_value=min(max(value, control.minimum), control.maximum), hint=control.help,
            )  # fmt: skip
            handle.on_update(lambda e: self._change({key: e.target.value}))
        elif control.kind == "vector" and control.size in (2, 3):
            add: Any = gui.add_vector2 if control.size == 2 else gui.add_vector3
            lo = None if control.minimum is None else tuple(control.minimum)
            hi = None if control.maximum is None else tuple(control.maximum)
            handle = add(control.label, tuple(value), min=lo, max=hi, step=control.step,
                         hint=control.help)  # fmt: skip
            handle.on_update(lambda e: self._change({key: list(e.target.value)}))
        else:  # text (the path), or a vector of another size: as text, parsed by the server
            hint = f"{control.help} ({control.format})" if control.format else control.help
            shown = value if isinstance(value, str) else ", ".join(f"{v:g}" for v in value)
            handle = gui.add_text(control.label, shown, hint=hint)
            handle.on_update(lambda e: self._change({key: e.target.value}))
        self._controls[key] = handle

    def _sync_controls(self, state) -> None:
        """Set every input to the value in force (the user's own changes included)."""
        values = control_values(state)
        self._syncing = True
        try:
            for key, handle in self._controls.items():
                value = values.get(key)
                if key in self._options and isinstance(value, str):
                    value = self._options[key].get(value, value)
                elif isinstance(value, list):
                    value = tuple(value)
                try:
                    handle.value = value  # type: ignore[misc]  # viser: settable
                except (ValueError, AssertionError):
                    pass
        finally:
            self._syncing = False

    # -- events ---------------------------------------------------------------------------
    def _on_event(self, event: Event) -> None:
        try:
            if event.kind == "state":
                self._on_state(self.dashboard.state)
            elif event.kind == "progress":
                msg = json.loads(event.data)
                if event.generation == self.dashboard.generation and msg["elapsed"] > 0.5:
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

    def _on_state(self, state) -> None:
        structure = (state.robot, state.augmentation, state.task, state.mode)
        with self._lock:
            if structure == self._structure:
                self._sync_controls(state)
                return
            self._structure = structure
            for folder in self._folders:
                folder.remove()
            self._folders, self._controls = [], {}
            self._rebuild_controls(state)

    def _place_gizmo(self, state) -> None:
        if self._dragging:
            return
        (X, Y), yaw = gizmo_pose(state.robot, state.x0, state.robot_parameters)
        gizmo = getattr(self, "gizmo", None)
        if gizmo is None or getattr(self, "_gizmo_robot", None) != state.robot:
            if gizmo is not None:
                gizmo.remove()
            scale = 1.2 if state.robot == "unicycle" else 0.5
            self.gizmo = self.server.scene.add_transform_controls(
                "/start",
                scale=scale,
                active_axes=(True, True, False),
                depth_test=False,
                position=(X, Y, 0.3),
                wxyz=yaw_quaternion(yaw),
            )
            self._gizmo_robot = state.robot
            self.server.scene.add_label("/start/label", "drag: start point", position=(0, 0, 0.15))
            self.gizmo.on_update(self._on_drag)
        else:
            self.gizmo.position = (X, Y, 0.3)
            self.gizmo.wxyz = yaw_quaternion(yaw)

    def _on_drag(self, event) -> None:
        """The gizmo pressed, moved or released: the start point follows.

        The press changes nothing unless the gizmo is off the state's pose. Moves change the
        state at most once per :data:`DRAG_INTERVAL`; the newest move within it is applied when
        it ends, unless a press, a release or a later move applied meanwhile (the last pose of a
        drag that stops always arrives). The release applies the final pose.
        """
        self._dragging = event.phase != "end"
        pose = (tuple(map(float, event.target.position)), tuple(map(float, event.target.wxyz)))
        with self._drag_lock:
            wait = self._last_drag + DRAG_INTERVAL - time.monotonic()
            if event.phase == "update" and wait > 0:
                # One timer per interval, for the newest of the moves within it.
                self._drag_pending = pose
                if self._drag_timer is None:
                    self._drag_timer = threading.Timer(wait, self._drag_deferred)
                    self._drag_timer.daemon = True
                    self._drag_timer.start()
                return
            if self._drag_timer is not None:  # this newer event overtakes the deferred move
                self._drag_timer.cancel()
                self._drag_timer = self._drag_pending = None
            self._drag_to(pose, counts=event.phase == "update")

    def _drag_deferred(self) -> None:
        """The end of an interval: apply the newest move made within it, unless a newer event
        overtook it (then this timer is no longer the scene's)."""
        with self._drag_lock:
            if threading.current_thread() is not self._drag_timer:
                return
            pose, self._drag_pending, self._drag_timer = self._drag_pending, None, None
            assert pose is not None  # (set with the timer)
            self._drag_to(pose, counts=True)

    def _drag_to(self, pose, counts: bool) -> None:
        """Apply a gizmo pose, with ``_drag_lock`` held (``counts``: a move, which starts a new
        :data:`DRAG_INTERVAL`)."""
        position, wxyz = pose
        if counts:
            self._last_drag = time.monotonic()
        state = self.dashboard.state
        self._change(start_from_gizmo(state.robot, position[:2], quaternion_yaw(wxyz), state))

    # -- drawing --------------------------------------------------------------------------
    def _sync_now(self) -> None:
        """Show the values in force in the GUI (after a drawing, an error or a refusal)."""
        with self._lock:
            if self._folders:
                self._sync_controls(self.dashboard.state)

    def _draw(self, result) -> None:
        state = result.state
        drawn = runs_key(state)
        if drawn == self._drawn_runs:
            # The same configurations (gamma in continuous mode only rescales theta; the
            # animation runs per leg): nothing in the scene changes but its status. A redraw
            # would cost the client a quarter second of frames (software WebGL here).
            with self._lock:  # (the timeline on screen plays the same legs)
                self.drawn_generation = result.generation
                self._sync_now()
                self.dashboard.scene_status.update(generation=result.generation)
            self._show_status(result)
            return
        with self._lock, self.server.atomic():
            self._drawn_runs = drawn
            timeline = Timeline(result)
            extent = _extent(result)
            # The start-point gizmo moves with the drawing it belongs to, in the same batch: moved
            # on the change itself it would start the client's frames (a quarter second of
            # software WebGL here) while the result is computed, and the result would wait for them.
            self._place_gizmo(state)
            layout = (state.robot, state.task)
            if timeline.unicycle or layout != self._layout:
                self._switch_set(None if timeline.unicycle else layout, result, timeline, extent)
            else:
                # Same robot and task: the nodes stay and take the new values (re-creating them
                # costs the client a remount of every node).
                self._update_set(self._sets[layout], result, extent)
            if self._home is not None:
                self._home.pose(np.asarray(state.x0))
            if self._framed != state.robot:
                self._framed = state.robot
                self._frame_camera(extent)
            self._timeline = timeline
            # Playing: from the start. Paused: at the end, where the drift of J^P# shows.
            self._s = 0.0 if self.playing else timeline.length
            self._pose(self._s)
            self._show_position(timeline)
            self.drawn_generation = result.generation
            self._sync_now()
            self.dashboard.scene_status.update(
                generation=result.generation, robot=state.robot, playing=self.playing
            )
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
        root = f"/robot/{state.robot}-{state.task}"
        entry: dict[str, Any] = {
            "root": root, "frame": scene.add_frame(root, show_axes=False, visible=visible),
            "mechanisms": {}, "home": None, "fixtures": {},
        }  # fmt: skip
        cls = _MECHANISMS.get(state.robot)
        if cls is not None:
            entry["home"] = cls(scene, f"{root}/home", HOME_COLOR, 0.25, -0.03, state, extent)
            entry["mechanisms"] = {
                a: cls(scene, f"{root}/{a}", _rgb(COLORS[a]), _OPACITY[a], _Z[a], state, extent)
                for a in ALGORITHMS
            }
        self._place_fixtures(result, extent, root, entry["fixtures"])
        self._sets[(state.robot, state.task)] = entry
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
        layout = (state.robot, state.task)
        if state.robot not in _MECHANISMS:
            return
        with self._lock, self.server.atomic():
            if layout in self._sets:
                return
            entry = self._build_set(result, _extent(result), visible=False)
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
        wanted = _fixtures(result, extent, root)
        for name in [n for n in fixtures if n not in wanted]:
            fixtures.pop(name).remove()
        for name, (kind, values, style) in wanted.items():
            if name not in fixtures:
                fixtures[name] = add[kind](name, **style, **values)
                if name.startswith(f"{root}/targets/"):
                    k = int(name.rsplit("/", 1)[1])
                    scene.add_label(
                        f"{name}/label",
                        chr(ord("A") + k) if k < 26 else str(k),
                        position=(0.05, 0.05, 0.05),
                    )
                continue
            for key, value in values.items():
                setattr(fixtures[name], key, value)

    def _draw_unicycle(self, result, timeline: Timeline, extent) -> None:
        scene = self.server.scene
        state = result.state
        tol = _trace_tolerance(extent)
        target = _Platform(scene, f"{UNICYCLE_ROOT}/target", (0, 0, 0), 0.3, 0.0, state, None)
        target.pose(state.target)
        q0 = state.robot_parameters["q0"]
        home = _Platform(scene, f"{UNICYCLE_ROOT}/home", HOME_COLOR, 0.3, 0.0, state, None)
        home.pose(q0)
        for a in ALGORITHMS:
            run = result.runs[a]
            rgb = np.asarray(_rgb(COLORS[a]), dtype=float)
            for n, i in enumerate(timeline.shown):
                i = min(int(i), len(run.platform) - 1)
                P = run.platform[i]
                last = n == len(timeline.shown) - 1
                mix = 1.0 if last else 0.3 + 0.5 * n / len(timeline.shown)
                color = cast(
                    "tuple[int, int, int]", tuple(int(v) for v in (255 - mix * (255 - rgb)))
                )
                pts = np.column_stack([P[:, 0], P[:, 1], np.full(len(P), 0.02 + _Z[a] * 0.2)])
                scene.add_line_segments(
                    f"{UNICYCLE_ROOT}/trace/{a}/{n}",
                    _polyline(pts, tol),
                    color,
                    thickness=3.5 if last else 1.5,
                    thickness_units="screen",
                )
            self._mechanisms[a] = _Platform(
                scene,
                f"{UNICYCLE_ROOT}/{a}",
                _rgb(COLORS[a]),
                _OPACITY[a],
                _Z[a] * 0.5,
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


def _extent(result) -> tuple[tuple[float, float], tuple[float, float]]:
    """Box of the task plane used by the mechanisms (rails, runner), covering both runs."""
    if any(r.platform is not None for r in result.runs.values()):
        ys = np.concatenate([r.platform.reshape(-1, 3) for r in result.runs.values()])
        ys = np.vstack([ys, [result.state.target]])
        lo, hi = ys.min(axis=0)[:2] - 1.0, ys.max(axis=0)[:2] + 1.0
        return (float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1]))
    ys = np.concatenate([r.y for r in result.runs.values()])
    xs = np.concatenate([r.x for r in result.runs.values()])
    lo = np.minimum(ys.min(axis=0)[:2], 0.0) - 0.6
    hi = np.maximum(ys.max(axis=0)[:2], 1.0) + 0.6
    if result.state.robot == "manipulator2":
        lo[0] = min(lo[0], xs[:, 1].min() - 0.4)
        hi[0] = max(hi[0], xs[:, 1].max() + 0.4)
    return (float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1]))


def start_scene(dashboard: Dashboard, low_end: bool = False) -> DashboardScene:
    """Start the viser scene for one session's ``dashboard``, on a free loopback port."""
    return DashboardScene(dashboard, low_end=low_end)
