"""The draggable start point: a transform gizmo in the task plane whose pose is the start x0
(or the unicycle's initial pose q0), see :func:`jik.app.scene.pose.gizmo_pose`."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import numpy as np
import viser
from viser.transforms import SO3

from .pose import gizmo_pose, start_from_gizmo

#: Seconds between two changes of the start point while its gizmo is dragged (each starts a
#: computation; the dashboard solves only the newest state, but every change is an event).
DRAG_INTERVAL = 0.15


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
