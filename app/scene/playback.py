"""The scene's playback: the animation's :class:`Timeline` (both algorithms' configurations as
functions of one playback position), its GUI folder (play, speed, position, the step on show,
the status) and the thread that animates the mechanisms along it."""

from __future__ import annotations

import threading
import time
from collections.abc import Mapping

import numpy as np
import viser

from ..dashboard.runs import spaced_iterations
from .controls import Syncing
from .mechanisms import Mechanism

#: Frames per second of the animation (poses sent to the clients).
FPS = 25.0
#: Seconds of animation per leg (manipulators) or per shown iteration (unicycle) at speed 1.
SECONDS_PER_LEG = 1.6
#: Unicycle iterations shown in the animation (geometrically spaced, the last always).
UNICYCLE_SHOWN = 10


def shown_iterations(result) -> np.ndarray:
    """The unicycle's iterations that the animation and the traces show: :data:`UNICYCLE_SHOWN`
    geometrically spaced ones, the first and the last always."""
    return spaced_iterations(max(len(r.platform) for r in result.runs.values()), UNICYCLE_SHOWN)


class Timeline:
    """Configurations of both algorithms as functions of one playback position s in [0, length]."""

    def __init__(self, result) -> None:
        self.result = result
        self.unicycle = any(r.platform is not None for r in result.runs.values())
        if self.unicycle:
            self.shown = shown_iterations(result)
            self.length = float(len(self.shown))
        else:
            theta_end = max(float(r.theta[-1]) for r in result.runs.values())
            legs = int(max(r.leg.max() for r in result.runs.values())) + 1
            self.leg_theta = theta_end / legs
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

    def counter(self, s: float) -> str:
        """What the animation shows at ``s``: the unicycle's iteration (of the discrete
        algorithm), or the leg of the closed path (its cycle)."""
        if self.unicycle:
            k = int(self.shown[min(int(s), len(self.shown) - 1)])
            last = max(len(r.platform) for r in self.result.runs.values()) - 1
            return f"**iteration {k}** of {last}"
        legs = max(round(self.length), 1)
        j = min(int(s), legs - 1)
        per = len(self.result.targets)
        cycle = f" (cycle {j // per + 1}, leg {j % per + 1} of {per})" if per < legs else ""
        return f"**leg {j + 1}** of {legs}{cycle}"


class Playback:
    """The "Playback" folder of a viser ``gui`` and the animation of the mechanisms shown:
    they and the timeline change under ``lock`` (the scene's); ``status`` is the dashboard's
    ``scene_status``, whose ``playing`` this keeps."""

    def __init__(self, gui: viser.GuiApi, lock: threading.RLock, status: dict) -> None:
        self._lock, self._scene_status = lock, status
        self._syncing = Syncing()  # (moving the position slider: not a user's scrub)
        with gui.add_folder("Playback", order=1):
            self.play = gui.add_button("Pause", icon=None)
            self.speed = gui.add_slider("speed", min=0.1, max=5.0, step=0.1, initial_value=1.0)
            self.scrub = gui.add_slider("position", min=0.0, max=1.0, step=0.001, initial_value=0.0)
            self.counter = gui.add_markdown("")  # (the iteration or leg on show)
            self.status = gui.add_markdown("computing…")
            self.progress = gui.add_progress_bar(0.0, visible=False, animated=True)
        self.playing = True
        self.timeline: Timeline | None = None
        self._mechanisms: Mapping[str, Mechanism] = {}
        #: Where the playback is along the timeline (0 to its length).
        self.position = 0.0
        self._posed: tuple[Timeline | None, float] = (None, 0.0)  # what the mechanisms show
        self._stopped = False
        self.play.on_click(self._toggle)
        self.scrub.on_update(self._scrubbed)
        self._thread = threading.Thread(target=self._animate, name="jik-scene", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stopped = True
        self._thread.join(timeout=2.0)

    def show(self, timeline: Timeline, mechanisms: Mapping[str, Mechanism]) -> None:
        """Play ``timeline`` on ``mechanisms`` (call under the scene's lock): from the start
        when playing; paused, at the end, where the drift of J^P# shows."""
        self.timeline, self._mechanisms = timeline, mechanisms
        self.position = 0.0 if self.playing else timeline.length
        self._pose(timeline, self.position)
        self._show_position(timeline)

    def _toggle(self, _) -> None:
        self.playing = not self.playing
        self.play.label = "Pause" if self.playing else "Play"
        self._scene_status["playing"] = self.playing

    def _scrubbed(self, _) -> None:
        if self._syncing or self.timeline is None:
            return
        if self.playing:  # (a scrub pauses)
            self._toggle(None)
        self.position = float(self.scrub.value) * self.timeline.length

    def _pose(self, timeline: Timeline, s: float) -> None:
        self._posed = (timeline, s)
        configs = timeline.at(s)
        for a, m in self._mechanisms.items():
            m.pose(configs[a])

    def _show_position(self, timeline: Timeline) -> None:
        """The position slider at the playback position (not a change of it by the user)."""
        with self._syncing:
            self.scrub.value = round(min(self.position / timeline.length, 1.0), 3)  # type: ignore[misc]  # viser: settable
            counter = timeline.counter(self.position)
            if self.counter.content != counter:
                self.counter.content = counter

    def _animate(self) -> None:
        last, last_gui = time.monotonic(), 0.0
        while not self._stopped:
            time.sleep(1.0 / FPS)
            now = time.monotonic()
            dt, last = now - last, now
            with self._lock:
                # (Read under the lock: a timeline read before a drawing swapped it would differ
                # from the one just posed, and pose the new one again.)
                timeline = self.timeline
                if timeline is None:
                    continue
                moving = self.playing
                if moving:
                    self.position += dt * float(self.speed.value) / SECONDS_PER_LEG
                    if self.position > timeline.length + 0.5:  # hold the end a moment, then loop
                        self.position = 0.0
                # Paused: nothing to send until scrubbed (or drawn, which poses too).
                if self._posed != (timeline, self.position):
                    self._pose(timeline, self.position)
            if not moving or self._stopped:
                continue
            if now - last_gui > 0.25:
                last_gui = now
                self._show_position(timeline)
