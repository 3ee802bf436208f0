"""The scene's node sets: one per manipulator layout, kept and moved; the unicycle's, redrawn.

A manipulator's set (its mechanisms, the grey copy at x0 and the fixtures of
:func:`~jik.app.scene.mechanisms.fixtures_of`, under a frame of their own) is built when its
layout (robot and task) is first shown, or ahead (:meth:`NodeSets.prebuild`), and then kept,
hidden when another layout is on screen: showing it again moves its nodes, which costs the
client far less than mounting new ones. The unicycle's paths are drawn anew for each result.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, cast

import numpy as np

from ..dashboard.algorithms import COLORS, DEFAULT_ALGORITHMS
from ..dashboard.plotting import corner_names
from .mechanisms import (
    HOME_COLOR,
    MECHANISMS,
    OPACITY,
    Mechanism,
    Platform,
    Z,
    extent_of,
    fixtures_of,
    layout_name,
    polyline,
    rgb,
    trace_tolerance,
)
from .pose import Timeline

#: The frame of the unicycle's nodes, drawn anew for each result.
UNICYCLE_ROOT = "/robot/unicycle"


def set_key(state) -> tuple:
    """A node set's key: the robot's layout, the task and the chosen algorithms (a copy each)."""
    return layout_name(state), state.task, state.algorithms


class NodeSets:
    """The node sets under ``/robot`` of a viser ``scene`` (see the module's text)."""

    def __init__(self, scene: Any) -> None:
        self.scene = scene
        scene.add_frame("/robot", show_axes=False)
        #: The moving copies on screen, by algorithm, and the grey copy at x0.
        self.mechanisms: dict[str, Mechanism] = {}
        self.home: Mechanism | None = None
        self.fixtures: dict[str, Any] = {}  # handles of the nodes of fixtures_of(), by name
        self._layout: tuple | None = None  # set_key() of the set on screen
        self._unicycle = False  # whether the unicycle's drawing is on screen
        # set_key() -> {"frame", "mechanisms", "home", "fixtures", "root"}
        self.sets: dict[tuple, dict[str, Any]] = {}

    def show(self, result, timeline: Timeline, extent) -> None:
        """Show ``result``: its layout's set with the result's values, or the unicycle's."""
        state = result.state
        layout = set_key(state)
        if timeline.unicycle or layout != self._layout:
            self._switch(None if timeline.unicycle else layout, result, timeline, extent)
        else:
            # Same robot and task: the nodes stay and take the new values (re-creating them
            # costs the client a remount of every node).
            self._update(self.sets[layout], result, extent)
        if self.home is not None:
            self.home.pose(np.asarray(state.x0))

    def prebuild(self, result) -> None:
        """Build the hidden set of a result solved ahead (another manipulator's defaults):
        switching to it then only moves nodes."""
        state = result.state
        if state.robot not in MECHANISMS or set_key(state) in self.sets:
            return
        entry = self._build(result, extent_of(result), visible=False)
        for a, m in entry["mechanisms"].items():
            m.pose(result.runs[a].x[-1])
        entry["home"].pose(np.asarray(state.x0))

    def _switch(self, layout: tuple | None, result, timeline: Timeline, extent) -> None:
        """Show the set of ``layout``, or the unicycle's when None, and hide the others."""
        if self._unicycle:
            self.scene.remove_by_name(UNICYCLE_ROOT)
        self._layout, self._unicycle = layout, layout is None
        for key, entry in self.sets.items():
            if key != layout:
                entry["frame"].visible = False
        if layout is None:
            self.scene.add_frame(UNICYCLE_ROOT, show_axes=False)
            self.mechanisms, self.fixtures, self.home = {}, {}, None
            self._draw_unicycle(result, timeline, extent)
            return
        if layout not in self.sets:
            entry = self._build(result, extent, visible=True)
        else:
            entry = self.sets[layout]
            entry["frame"].visible = True
            self._update(entry, result, extent)
        self.fixtures, self.mechanisms, self.home = (
            entry["fixtures"],
            entry["mechanisms"],
            entry["home"],
        )

    def _build(self, result, extent, visible: bool) -> dict[str, Any]:
        """The nodes of ``result``'s manipulator and task under their own frame."""
        scene = self.scene
        state = result.state
        chosen = "" if state.algorithms == DEFAULT_ALGORITHMS else "-" + "-".join(state.algorithms)
        root = f"/robot/{layout_name(state)}-{state.task}{chosen}"
        entry: dict[str, Any] = {
            "root": root,
            "frame": scene.add_frame(root, show_axes=False, visible=visible),
            "mechanisms": {},
            "home": None,
            "fixtures": {},
        }
        cls = MECHANISMS.get(state.robot)
        if cls is not None:
            entry["home"] = cls(scene, f"{root}/home", HOME_COLOR, 0.25, -0.03, state, extent)
            entry["mechanisms"] = {
                a: cls(scene, f"{root}/{a}", rgb(COLORS[a]), OPACITY[a], Z[a], state, extent)
                for a in result.runs
            }
        self._place_fixtures(result, extent, root, entry["fixtures"])
        self.sets[set_key(state)] = entry
        return entry

    def _update(self, entry: dict[str, Any], result, extent) -> None:
        for m in (*entry["mechanisms"].values(), entry["home"]):
            if m is not None:
                m.resize(result.state, extent)
        self._place_fixtures(result, extent, entry["root"], entry["fixtures"])

    def _place_fixtures(self, result, extent, root: str, fixtures: dict[str, Any]) -> None:
        """Give the fixtures under ``root`` (their handles in ``fixtures``) the values of
        ``result``: existing nodes are moved, missing ones (all, in a new set; a target the
        path gained) are added, ones it lost are removed."""
        scene = self.scene
        add: dict[str, Callable[..., Any]] = {
            "box": scene.add_box,
            "line": scene.add_line_segments,
            "ball": scene.add_icosphere,
            "frame": scene.add_frame,
        }
        wanted = fixtures_of(result, extent, root)
        labels = target_labels(wanted, corner_names(result), f"{root}/targets/")
        gone = [n for n in fixtures if n not in wanted and n not in labels]
        for name in gone:
            handle = fixtures.pop(name)
            if name.rpartition("/")[0] not in gone:  # (a removed node takes its children along)
                handle.remove()
        for name, (kind, values, style) in wanted.items():
            if name not in fixtures:
                fixtures[name] = add[kind](name, **style, **values)
            else:
                for key, value in values.items():
                    setattr(fixtures[name], key, value)
        for name, text in labels.items():
            if name in fixtures:
                fixtures[name].text = text
            else:
                fixtures[name] = scene.add_label(name, text, position=(0.05, 0.05, 0.05))

    def _draw_unicycle(self, result, timeline: Timeline, extent) -> None:
        scene = self.scene
        state = result.state
        tol = trace_tolerance(extent)
        target = Platform(scene, f"{UNICYCLE_ROOT}/target", (0, 0, 0), 0.3, 0.0, state, None)
        target.pose(state.target)
        q0 = state.robot_parameters["q0"]
        home = Platform(scene, f"{UNICYCLE_ROOT}/home", HOME_COLOR, 0.3, 0.0, state, None)
        home.pose(q0)
        for a, run in result.runs.items():
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
            self.mechanisms[a] = Platform(
                scene,
                f"{UNICYCLE_ROOT}/{a}",
                rgb(COLORS[a]),
                OPACITY[a],
                Z[a] * 0.5,
                state,
                None,
            )


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
