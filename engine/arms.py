"""A catalogue of real arms: small URDF files (kinematics only) shipped with jik.

Each arm is a URDF of :mod:`jik.engine.arm_data` written from its maker's published kinematic
parameters (the source is cited in the file), with joint limits, a home configuration and a
default task. An arm is used as a robot definition ``{"name": "panda", "task": "pose"}``
(:func:`jik.engine.robot_spec.robot_from_dict`): the same as ``{"name": "urdf", "urdf": TEXT,
"end_link": ..., "home": HOME, "task": "pose"}`` with the file's text and the arm's end link and
home, so that the reference orientation R0 defaults to the orientation at home (its rotation
coordinates are 0).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from importlib import resources


@dataclass(frozen=True)
class Arm:
    """A catalogue arm: its URDF file, end link, home configuration [rad] and default task."""

    name: str
    title: str
    file: str
    end_link: str
    home: tuple[float, ...]
    task: str
    description: str

    @property
    def urdf(self) -> str:
        """The URDF text shipped with jik."""
        return _text(self.file)

    def definition(self, **overrides) -> dict:
        """The arm as a ``urdf`` robot definition, with ``overrides`` (task, reference, ...)."""
        return {
            "name": "urdf",
            "urdf": self.urdf,
            "end_link": self.end_link,
            "home": list(self.home),
            "task": self.task,
            "title": self.title,
            **overrides,
        }


@functools.cache
def _text(file: str) -> str:
    return (resources.files("jik.engine.arm_data") / file).read_text(encoding="utf-8")


_PI = math.pi
ARMS: dict[str, Arm] = {
    a.name: a
    for a in (
        Arm(
            "panda",
            "Franka Panda",
            "panda.urdf",
            "panda_link8",
            (0.0, -_PI / 4, 0.0, -3 * _PI / 4, 0.0, _PI / 2, _PI / 4),
            "pose",
            "Franka Emika Panda, 7 revolute joints, to the flange; home: Franka's 'ready' pose",
        ),
        Arm(
            "iiwa14",
            "KUKA LBR iiwa 14",
            "iiwa14.urdf",
            "iiwa_link_ee",
            (0.0, _PI / 6, 0.0, -_PI / 2, 0.0, _PI / 3, 0.0),
            "pose",
            "KUKA LBR iiwa 14 R820, 7 revolute joints, to the media flange",
        ),
        Arm(
            "gen3",
            "Kinova Gen3",
            "gen3.urdf",
            "end_effector_link",
            (0.0, 0.2618, _PI, -2.2689, 0.0, 0.9599, _PI / 2),
            "pose",
            "Kinova Gen3, 7 joints (1, 3, 5, 7 continuous), to the interface module; home: "
            "Kinova's 'Home' position (0, 15, 180, 230, 0, 55, 90 deg)",
        ),
        Arm(
            "ur5e",
            "Universal Robots UR5e",
            "ur5e.urdf",
            "tool0",
            (0.0, -_PI / 2, _PI / 2, -_PI / 2, -_PI / 2, 0.0),
            "x y z rx ry",
            "Universal Robots UR5e, 6 revolute joints, to the tool flange; 6 joints leave no "
            "redundancy for a full pose, so its default task leaves out rz",
        ),
    )
}


def arm(name: str) -> Arm:
    """The catalogue arm ``name`` (a ``KeyError`` for any other name)."""
    return ARMS[name]
