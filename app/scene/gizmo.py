"""The draggable start point: a transform gizmo in the task plane whose pose is the start x0
(or the unicycle's initial pose q0): :func:`gizmo_pose`, and back, :func:`start_from_gizmo`."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable

import numpy as np
import viser
from viser.transforms import SO3

from .mechanisms import NORMAL_FORM

#: Seconds between two changes of the start point while its gizmo is dragged (each starts a
#: computation; the dashboard solves only the newest state, but every change is an event).
DRAG_INTERVAL = 0.15


def gizmo_pose(robot: str, x0, robot_parameters: dict) -> tuple[tuple[float, float], float]:
    """Where the start-point gizmo sits: ((X, Y), yaw) in the task plane.

    Manipulator 2: the carriage (x2, x1), yaw x3. Manipulator 1: the task point
    W = (x1, x2 + x1 x3), yaw atan(x3) (the lever's slope). Unicycle: the initial pose q0.
    """
    if robot == "manipulator2":
        return (x0[1], x0[0]), x0[2]
    if robot == "manipulator1":
        X, Y = (float(v) for v in NORMAL_FORM.forward(np.asarray(x0, dtype=float)))
        return (X, Y), math.atan(x0[2])
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


class StartGizmo:
    """The gizmo of one scene: placed at a state's start point, dragged to change it
    (``send(patch)``, from the state in force, ``state()``)."""

    def __init__(self, scene: viser.SceneApi, state: Callable, send: Callable[[dict], None]):
        self._scene = scene
        self._state = state
        self._send = send
        self.handle: viser.TransformControlsHandle | None = None
        self._robot: str | None = None
        self.dragging = False
        self._last = 0.0  # when a move last changed the state
        self._pending: tuple | None = None  # the newest move within DRAG_INTERVAL
        self._timer: threading.Timer | None = None  # applies it when the interval ends
        self._lock = threading.Lock()

    def place(self, state) -> None:
        """Put the gizmo at ``state``'s start point (not while it is dragged)."""
        if self.dragging:
            return
        if state.robot_definition is not None:  # (a user's robot: its start is set on the page)
            if self.handle is not None:
                self.handle.visible = False
            return
        (X, Y), yaw = gizmo_pose(state.robot, state.x0, state.robot_parameters)
        if self.handle is None or self._robot != state.robot:
            if self.handle is not None:
                self.handle.remove()
            self.handle = self._scene.add_transform_controls(
                "/start",
                scale=1.2 if state.robot == "unicycle" else 0.5,
                active_axes=(True, True, False),
                depth_test=False,
            )
            self._robot = state.robot
            self._scene.add_label("/start/label", "drag: start point", position=(0, 0, 0.15))
            self.handle.on_update(self.on_drag)
        self.handle.visible = True
        self.handle.position = (X, Y, 0.3)
        self.handle.wxyz = SO3.from_z_radians(yaw).wxyz

    def on_drag(self, event) -> None:
        """The gizmo pressed, moved or released: the start point follows.

        The press changes nothing unless the gizmo is off the state's pose. Moves change the
        state at most once per :data:`DRAG_INTERVAL`; the newest move within it is applied when
        it ends, unless a press, a release or a later move applied meanwhile (the last pose of a
        drag that stops always arrives). The release applies the final pose.
        """
        self.dragging = event.phase != "end"
        pose = (tuple(map(float, event.target.position)), tuple(map(float, event.target.wxyz)))
        with self._lock:
            wait = self._last + DRAG_INTERVAL - time.monotonic()
            if event.phase == "update" and wait > 0:
                # One timer per interval, for the newest of the moves within it.
                self._pending = pose
                if self._timer is None:
                    self._timer = threading.Timer(wait, self._deferred)
                    self._timer.daemon = True
                    self._timer.start()
                return
            if self._timer is not None:  # this newer event overtakes the deferred move
                self._timer.cancel()
                self._timer = self._pending = None
            self._apply(pose, counts=event.phase == "update")

    def _deferred(self) -> None:
        """The end of an interval: apply the newest move made within it, unless a newer event
        overtook it (then this timer is no longer the gizmo's)."""
        with self._lock:
            if threading.current_thread() is not self._timer:
                return
            pose, self._pending, self._timer = self._pending, None, None
            assert pose is not None  # (set with the timer)
            self._apply(pose, counts=True)

    def _apply(self, pose, counts: bool) -> None:
        """Apply a gizmo pose, with the lock held (``counts``: a move, which starts a new
        :data:`DRAG_INTERVAL`)."""
        position, wxyz = pose
        if counts:
            self._last = time.monotonic()
        state, yaw = self._state(), float(SO3(np.asarray(wxyz)).compute_yaw_radians())
        self._send(start_from_gizmo(state.robot, position[:2], yaw, state))
