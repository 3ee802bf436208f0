"""Where the scene's camera looks: the robot's reach, framed for each client's view.

When the robot changes (another robot, or another definition of a user's robot), the camera
of every client is set to look at the sphere the robot can reach (:func:`view_of`) from the
front, tilted, at the distance where the sphere fills the client's narrower field of view
(viser reports each client's vertical field of view and canvas size); a client that connects
later is framed the same way when it first reports its camera.

viser's canvas is first as wide as the page's scene frame, then narrower by its control panel
once that is laid out beside it (the vertical field of view stays): a client reporting a canvas
wide enough to hold the panel is framed for the width left of it (:func:`settled_aspect`); the
initial camera, for clients that have reported nothing yet, for a tall narrow canvas
(:data:`INITIAL_ASPECT`), the scene frame's at the narrowest page.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np

from ..dashboard.robots import state_kinematics
from .mechanisms import AXES_FRACTION, CHAINS, chain_points, extent_of, runs_points

#: Unit vector from the point looked at to the camera: in front of the task plane, tilted.
VIEW_DIRECTION = np.array([0.0, -0.75, 1.05]) / math.hypot(0.75, 1.05)
#: Room around the framed sphere, as a factor of its radius.
MARGIN = 1.15
#: Width [px] of viser's control panel ("small", 16 em) with its padding, beside the canvas.
PANEL_PX = 320.0
#: Aspect (width / height) the initial camera is framed for: the canvas of a 580 px scene frame
#: beside the panel, in a window about 1000 px high.
INITIAL_ASPECT = 0.4


def view_of(result) -> tuple[np.ndarray, float]:
    """The sphere (center (3,), radius) the camera frames for ``result``'s robot.

    A planar chain: centred on its base, of radius its reach, the length of its links at x0
    (at least the farthest point of its drawn configurations). An arm in space (a URDF or
    catalogue arm): the sphere around the box of its drawn configurations. Any other:
    the task-plane box its mechanisms, paths and targets span (:func:`extent_of`).
    """
    state = result.state
    if state.robot in CHAINS:
        kin = state_kinematics(state)
        home = chain_points(kin, np.asarray(state.x0, dtype=float), 0.0)  # (n + 1, 3)
        reach = float(np.linalg.norm(np.diff(home, axis=0), axis=1).sum())
        drawn = runs_points(result, kin)
        if np.ptp(drawn[:, 2]) > 0:  # (an arm standing in space)
            # (and the targets' positions, where its pose frames are drawn)
            targets = np.asarray(result.targets, dtype=float)
            if targets.ndim == 2 and targets.shape[1] >= 3:
                drawn = np.vstack([drawn, targets[:, :3]])
            center = (drawn.min(axis=0) + drawn.max(axis=0)) / 2
            radius = float(np.linalg.norm(drawn - center, axis=1).max())
            # (and the end link's frame, its axes AXES_FRACTION of the reach long).
            return center, max(radius + AXES_FRACTION * reach, 1e-3)
        radius = max(reach, float(np.linalg.norm(drawn - home[0], axis=1).max()))
        return home[0], max(radius, 1e-3)
    (xlo, xhi), (ylo, yhi) = extent_of(result)
    center = np.array([(xlo + xhi) / 2, (ylo + yhi) / 2, 0.0])
    return center, max(math.hypot(xhi - xlo, yhi - ylo) / 2, 1e-3)


def settled_aspect(width: float, height: float) -> float:
    """The aspect of a canvas reported ``width`` x ``height`` [px] once viser's control panel
    is beside it: narrower by the panel when it is wide enough to hold it."""
    free = width - PANEL_PX if width >= 2 * PANEL_PX else width
    return free / height


def camera_pose(
    center: np.ndarray, radius: float, fov: float, aspect: float
) -> tuple[np.ndarray, np.ndarray]:
    """(position, look_at) of a camera with vertical field of view ``fov`` [rad] and
    ``aspect`` (width / height) that shows the whole sphere (``center``, ``radius``)."""
    half = min(fov / 2, math.atan(math.tan(fov / 2) * aspect))  # the narrower half-angle
    distance = MARGIN * radius / math.sin(half)
    return center + distance * VIEW_DIRECTION, np.asarray(center, dtype=float)


class CameraFraming:
    """Frames the cameras of a viser ``server``'s clients on the robot on show."""

    def __init__(self, server: Any) -> None:
        self.server = server
        self.view: tuple[np.ndarray, float] | None = None
        self._lock = threading.Lock()
        server.on_client_connect(self.frame_client)

    def frame(self, result) -> None:
        """Frame every client (and the initial camera of clients to come) on ``result``'s
        robot."""
        with self._lock:
            self.view = view_of(result)
        aim(self.server.initial_camera, self.view, INITIAL_ASPECT)
        for client in self.server.get_clients().values():
            self.frame_client(client)

    def frame_client(self, client: Any) -> None:
        """Frame one client on the robot on show, for its field of view and aspect."""
        with self._lock:
            view = self.view
        if view is None:
            return
        camera = client.camera
        if camera.image_height > 0:
            aspect = settled_aspect(camera.image_width, camera.image_height)
        else:
            aspect = INITIAL_ASPECT
        with client.atomic():
            aim(camera, view, aspect)


def aim(camera: Any, view: tuple[np.ndarray, float], aspect: float) -> None:
    """Point a viser camera (a client's, or the initial one) at ``view`` (center, radius) for
    its field of view and ``aspect`` (:func:`camera_pose`)."""
    position, look_at = camera_pose(*view, camera.fov, aspect)
    camera.position, camera.look_at = position, look_at
    camera.near = min(0.01, float(np.linalg.norm(position - look_at)) / 100)  # (a tiny robot)
