"""The scene's node sets: one per robot layout, kept and moved.

A layout's set (its mechanisms, the grey copy at the start, the unicycle's target, and the
fixtures of :func:`~jik.app.scene.fixtures.fixtures_of`, under a frame of their own) is built
when its layout (robot and task) is first shown, or ahead (:meth:`NodeSets.prebuild`), and then
kept, hidden when another layout is on screen: showing it again moves its nodes, which costs the
client far less than mounting new ones.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..dashboard.algorithms import COLORS, DEFAULT_ALGORITHMS, STYLES
from ..dashboard.plotting import corner_names
from .fixtures import fixtures_of, rgb
from .mechanisms import HOME_COLOR, MECHANISMS, Mechanism, extent_of, layout_name
from .playback import Timeline


def set_key(state) -> tuple:
    """A node set's key: the robot's layout, the task and the chosen algorithms (a copy each)."""
    return layout_name(state), state.task, state.algorithms


class NodeSets:
    """The node sets under ``/robot`` of a viser ``scene`` (see the module's text)."""

    def __init__(self, scene: Any) -> None:
        self.scene = scene
        scene.add_frame("/robot", show_axes=False)
        #: The moving copies on screen, by algorithm.
        self.mechanisms: dict[str, Mechanism] = {}
        self.fixtures: dict[str, Any] = {}  # handles of the nodes of fixtures_of(), by name
        # set_key() -> {"frame", "mechanisms", "still", "fixtures", "root"}
        self.sets: dict[tuple, dict[str, Any]] = {}

    def show(self, result) -> None:
        """Show ``result``: its layout's set with the result's values, the other sets hidden. A
        kept set's nodes stay and take the new values (re-creating them costs the client a
        remount of every node)."""
        layout, extent = set_key(result.state), extent_of(result)
        for key, entry in self.sets.items():
            entry["frame"].visible = key == layout  # (viser sends only a change)
        if layout in self.sets:
            entry = self.sets[layout]
            for m in (*entry["mechanisms"].values(), *entry["still"].values()):
                m.resize(result.state, extent)
            self._place_fixtures(result, extent, entry["root"], entry["fixtures"])
        else:
            entry = self._build(result, extent, visible=True)
        self.fixtures, self.mechanisms = entry["fixtures"], entry["mechanisms"]
        self._pose_still(entry, result.state)

    def prebuild(self, result) -> None:
        """Build the hidden set of a result solved ahead (another manipulator's defaults):
        switching to it then only moves nodes."""
        state = result.state
        if state.robot not in MECHANISMS or set_key(state) in self.sets:
            return
        entry = self._build(result, extent_of(result), visible=False)
        timeline = Timeline(result)
        for a, x in timeline.at(timeline.length).items():
            entry["mechanisms"][a].pose(x)
        self._pose_still(entry, state)

    @staticmethod
    def _pose_still(entry: dict[str, Any], state) -> None:
        """Pose a set's still copies: the grey one at the start (x0, the unicycle's q0), and
        the unicycle's black one at its target pose."""
        unicycle = state.robot == "unicycle"
        poses = {"home": state.robot_parameters["q0"] if unicycle else state.x0}
        for name, m in entry["still"].items():
            m.pose(np.asarray(poses.get(name, state.target)))

    def _build(self, result, extent, visible: bool) -> dict[str, Any]:
        """The nodes of ``result``'s robot and task under their own frame."""
        scene = self.scene
        state = result.state
        chosen = "" if state.algorithms == DEFAULT_ALGORITHMS else "-" + "-".join(state.algorithms)
        root = f"/robot/{layout_name(state)}-{state.task}{chosen}"
        entry: dict[str, Any] = {
            "root": root,
            "frame": scene.add_frame(root, show_axes=False, visible=visible),
            "mechanisms": {},
            "still": {},
            "fixtures": {},
        }
        cls = MECHANISMS.get(state.robot)
        if cls is not None:
            # (colour, opacity, height) of each copy: the still ones, one per algorithm
            still = {"home": (HOME_COLOR, 0.25, -0.03)}
            if state.robot == "unicycle":  # (its target is a pose: a black platform)
                still = {"home": (HOME_COLOR, 0.3, 0.0), "target": ((0, 0, 0), 0.3, 0.0)}
            copies = {a: (rgb(COLORS[a]), STYLES[a].opacity, STYLES[a].z) for a in result.runs}
            for part, styles in (("still", still), ("mechanisms", copies)):
                entry[part] = {
                    name: cls(scene, f"{root}/{name}", color, opacity, z, state, extent)
                    for name, (color, opacity, z) in styles.items()
                }
        self._place_fixtures(result, extent, root, entry["fixtures"])
        self.sets[set_key(state)] = entry
        return entry

    def _place_fixtures(self, result, extent, root: str, fixtures: dict[str, Any]) -> None:
        """Give the fixtures under ``root`` (their handles in ``fixtures``) the values of
        ``result``: existing nodes are moved, missing ones (all, in a new set; a target the
        path gained) are added, ones it lost are removed."""
        scene = self.scene
        wanted = fixtures_of(result, extent, root)
        labels = target_labels(wanted, corner_names(result), f"{root}/targets/")
        gone = [n for n in fixtures if n not in wanted and n not in labels]
        for name in gone:
            handle = fixtures.pop(name)
            if name.rpartition("/")[0] not in gone:  # (a removed node takes its children along)
                handle.remove()
        for name, (kind, values, style) in wanted.items():
            if name not in fixtures:
                fixtures[name] = getattr(scene, f"add_{kind}")(name, **style, **values)
            else:
                for key, value in values.items():
                    setattr(fixtures[name], key, value)
        for name, text in labels.items():
            if name in fixtures:
                fixtures[name].text = text
            else:
                fixtures[name] = scene.add_label(name, text, position=(0.05, 0.05, 0.05))


def target_labels(wanted: dict[str, Any], letters: list[str], prefix: str) -> dict[str, str]:
    """The label of each target node (``prefix`` + its index): its corner's letter, or the
    letters of every target at its position ("B, C": pose targets that differ in orientation
    only) on the first of them and nothing on the others, so that no two labels overlap."""
    first_at: dict[tuple[float, ...], str] = {}
    texts: dict[str, list[str]] = {}
    for name, (_, values, _) in wanted.items():
        if not name.startswith(prefix):
            continue
        where = tuple(np.round(np.asarray(values["position"], dtype=float), 9))
        owner = first_at.setdefault(where, name)
        texts.setdefault(owner, []).append(letters[int(name[len(prefix) :])])
        texts.setdefault(name, [])
    return {f"{name}/label": ", ".join(group) for name, group in texts.items()}
