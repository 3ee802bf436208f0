"""Dashboard latency: a control change to the plots and to the 3D scene, medians and p95.

The targets: p95 under 300 ms for a manipulator change and under 2 s for the unicycle,
on a machine without a GPU. A real ``jik serve`` runs on a free loopback port, and the same
kinds of change are made through it: gamma, the start point x1, the arm length l, the number
of cycles, the switches from Manipulator 2 to Manipulator 1 and back, then the switch to the
unicycle and changes of its start point lambda10 and of gamma. Two measurements:

* **Server only** (httpx, no browser): ``POST /api/sessions/{id}/state`` with the control's
  key, as the page sends it, to the arrival of that generation's ``result`` event on the
  session's event stream. Straightforward: a fresh session created with the state after the
  change (``POST /api/sessions``) to its first ``result``: the same state computed cold,
  without the live session's run cache, the cycles it resumes, the panels it reuses and the
  other manipulator solved ahead. Its setup (the POST: a viser server per session) is shown
  apart.
* **Browser** (Debian's chromium, headless, software WebGL): from the control's ``input`` (a
  slider) or ``change`` (a select) event, dispatched in the page, to ``body[data-generation]``
  reaching the new generation (the page sets it once the plots are drawn), and to the viser
  client in the iframe first showing ``generation N`` (its status, sent after the scene's
  nodes). Both are MutationObservers on the same wall clock. Straightforward: the page loaded
  anew with the changed state in its link (``?state=``, what a reload or a copied link does): a
  new session computes it cold and the page and the scene draw it from nothing, as a
  dashboard that reloads on every change would; timed from the navigation's start. Changes
  of each kind alternate between the two.

No value repeats within a session, so that no change finds its runs cached. Each browser page
is a session of its own (the first switch to the unicycle is never cached). Between changes
the benchmark waits until the server's processes and the page's plotly calls are idle (their
background work, E1/E2 and the robot solved ahead, is not part of the next change). The
machine's load is reported with the figures: the load average, the CPU steal and the CPU that
other processes used meanwhile.
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import sys
import time
from dataclasses import dataclass

import numpy as np

from ..app.dashboard.controls import element_id
from .latency_server import EventStream, Machine, quiet, served

CHROMIUM = "/usr/bin/chromium"
#: The targets: p95 of a change [ms], by family.
TARGETS_MS = {"manipulator": 300.0, "unicycle": 2000.0}


@dataclass(frozen=True)
class Change:
    """One control change: the control ``key`` (as the page sends it) set to ``value``."""

    kind: str
    family: str  # "manipulator" or "unicycle": which target applies
    key: str  # "gamma", "x0.0", "robot_parameters.l", "cycles", "robot"
    value: float | str
    log: bool = False  # a log-scale slider (its position is log10 of the value)

    @property
    def selector(self) -> str:
        return "#" + element_id(self.key)

    @property
    def event(self) -> str:
        return "change" if isinstance(self.value, str) else "input"

    @property
    def position(self) -> float | str:
        """The page's input value for this change."""
        if isinstance(self.value, str):
            return self.value
        return math.log10(self.value) if self.log else self.value

    def linked(self, state: dict) -> dict:
        """The state of a link after this change (a robot switch: that robot's defaults)."""
        if self.key == "robot":
            return {"robot": self.value}
        state = json.loads(json.dumps(state))
        head, _, rest = self.key.partition(".")
        if head == "x0":
            state["x0"][int(rest)] = self.value
        elif rest:
            state[head][rest] = self.value
        else:
            state[head] = self.value
        return state


def plan(sessions: int, rounds: int, unicycle_changes: int) -> list[list[Change]]:
    """The changes of each session: ``rounds`` rounds of Manipulator 2's controls and the
    switches to Manipulator 1 and back, then the switch to the unicycle and
    ``unicycle_changes`` changes of it. A slider's values lie at least two of its steps apart
    and never repeat within a session, so that no change finds its runs cached."""
    m, u = "manipulator", "unicycle"
    out = []
    for s in range(sessions):
        changes = []
        for r in range(rounds):
            n = s * rounds + r
            gamma, x1, arm = 1.25 * 1.08**n, 0.06 + 0.03 * n, 1.05 + 0.05 * n
            changes += [
                Change("gamma (manipulator2)", m, "gamma", round(gamma, 3), log=True),
                Change("start point x1 (manipulator2)", m, "x0.0", round(x1, 3)),
                Change("arm length l (manipulator2)", m, "robot_parameters.l", round(arm, 3)),
                Change("cycles (manipulator2)", m, "cycles", 4 + n % 3),
                Change("switch to manipulator1", m, "robot", "manipulator1"),
                Change("switch to manipulator2", m, "robot", "manipulator2"),
            ]
        changes.append(Change("switch to unicycle", u, "robot", "unicycle"))
        for i in range(unicycle_changes):
            k = s * unicycle_changes + i
            if i % 2 == 0:  # lambda10 = 0.5 +- 0.03, 0.06, ...
                lam = 0.5 + (-1) ** (k // 2) * 0.03 * (k // 4 + 1)
                changes.append(Change("start point lambda10 (unicycle)", u, "x0.0", round(lam, 3)))
            else:
                gamma = 0.1 * 1.04 ** (k + 1)
                changes.append(Change("gamma (unicycle)", u, "gamma", round(gamma, 3), log=True))
        out.append(changes)
    return out


def _progress(text: str) -> None:
    """Where the run is, on one line of a terminal (nothing when stderr is not one)."""
    if sys.stderr.isatty():
        sys.stderr.write(f"\r  {text:60}\r")
        sys.stderr.flush()


def _timed_session(client, base: str, state: dict | None) -> tuple[str, float, float, dict]:
    """A new session (of ``state``): its id, the setup (the POST) and the time to its first
    result [s], and that result."""
    t0 = time.perf_counter()
    r = client.post("/api/sessions", json={"state": state or {}})
    r.raise_for_status()
    setup = time.perf_counter() - t0
    session = r.json()["id"]
    stream = EventStream(base, session)
    try:
        arrived, result = stream.wait(1)
    finally:
        stream.close()
    return session, setup, arrived - t0, result


def server_only(base: str, pid: int, sessions: list[list[Change]]) -> list[dict]:
    """Each change through a live session, and as a fresh session of the same state."""
    import httpx

    samples = []
    with httpx.Client(base_url=base, timeout=30.0) as client:
        for p, changes in enumerate(sessions):
            r = client.post("/api/sessions", json={"state": {}})
            r.raise_for_status()
            session = r.json()["id"]
            stream = EventStream(base, session)
            try:
                stream.wait(1)
                quiet(pid)
                for i, change in enumerate(changes):
                    _progress(f"server only: session {p + 1} of {len(sessions)}, change {i + 1}")
                    t0 = time.perf_counter()
                    r = client.post(
                        f"/api/sessions/{session}/state", json={change.key: change.value}
                    )
                    r.raise_for_status()
                    arrived, result = stream.wait(r.json()["generation"])
                    live = arrived - t0
                    quiet(pid)
                    fresh_id, setup, fresh, _ = _timed_session(client, base, r.json()["state"])
                    client.delete(f"/api/sessions/{fresh_id}")
                    samples.append(
                        {
                            "kind": change.kind,
                            "family": change.family,
                            "live_ms": 1e3 * live,
                            "fresh_ms": 1e3 * fresh,
                            "setup_ms": 1e3 * setup,
                            "compute_ms": 1e3 * result["timing"]["compute"],
                        }
                    )
                    quiet(pid)
            finally:
                stream.close()
                client.delete(f"/api/sessions/{session}")
    return samples


def _browser_missing() -> str:
    """Why the browser's half cannot run here, or ""."""
    from . import CHECKOUT_HINT, has_harness

    if not has_harness():
        return CHECKOUT_HINT
    if not os.path.exists(CHROMIUM):
        return f"{CHROMIUM} not found (Debian's chromium)"
    if importlib.util.find_spec("playwright") is None:
        return "the playwright package is not installed"
    return ""


# -- figures ----------------------------------------------------------------------------------
def _stats(values: list[float]) -> tuple[float, float]:
    """Median and 95th percentile (linear between order statistics), NaNs left out."""
    values = [v for v in values if not math.isnan(v)]
    if not values:
        return math.nan, math.nan
    return float(np.median(values)), float(np.percentile(values, 95))


def summarize(samples: list[dict], fields: tuple[str, ...], by: str | None = None) -> dict:
    """Per kind (and per value of ``by``): n, and median and p95 of each of ``fields``; then
    the rows "all manipulator changes" and "all unicycle changes", which pool the kinds."""
    groups: dict[tuple[str, str], list[dict]] = {}
    pooled: dict[tuple[str, str], list[dict]] = {}
    for s in samples:
        mode = s[by] if by else ""
        groups.setdefault((s["kind"], mode), []).append(s)
        pooled.setdefault((f"all {s['family']} changes", mode), []).append(s)
    return {
        key: {"n": len(group)} | {f: _stats([s[f] for s in group]) for f in fields}
        for key, group in (groups | pooled).items()
    }


def run(quick: bool = False) -> dict:
    sessions = plan(1, 2, 1) if quick else plan(4, 5, 4)
    server_sessions = plan(1, 1, 1) if quick else plan(2, 4, 2)
    out: dict = {"quick": quick}
    machine = Machine()
    with served() as (base, proc):
        samples = server_only(base, proc.pid, server_sessions)
        out["server"] = summarize(samples, ("live_ms", "fresh_ms", "setup_ms", "compute_ms"))
        skipped = _browser_missing()
        if skipped:
            out["browser_skipped"] = skipped
        else:
            from .harness.browser_latency import browser

            samples = browser(base, proc.pid, sessions)
            out["browser"] = summarize(samples, ("plots_ms", "scene_ms", "compute_ms"), "mode")
            out["browser_samples"] = samples
    out["machine"] = machine.report()
    _progress("")
    return out


def _ms(v: float) -> str:
    return "-" if math.isnan(v) else f"{v:.0f}"


def _pair(stats: tuple[float, float]) -> str:
    """The median and the p95 in ms, 12 characters wide."""
    return f"{_ms(stats[0]):>6} /{_ms(stats[1]):>4}"


def _ratio(a: float, b: float) -> str:
    return f"{a / b:7.2f}" if not (math.isnan(a) or math.isnan(b)) else f"{'-':>7}"


_NONE = {
    "n": 0,
    "plots_ms": (math.nan,) * 2,
    "scene_ms": (math.nan,) * 2,
    "compute_ms": (math.nan,) * 2,
}


def main(quick: bool = False) -> None:
    r = run(quick=quick)
    m = r["machine"]
    print(
        f"load average {m['loadavg_start']} at the start, {m['loadavg_end']} at the end; "
        f"{m['cores']} cores, {m['seconds']:.0f} s"
        + (
            f"; CPU steal {m['steal_percent']:.1f} %, this benchmark (server, browser) "
            f"{m['our_cores']:.2f} cores, other processes {m['other_cores']:.2f} cores"
            if "steal_percent" in m
            else ""
        )
    )
    print(
        "\nserver only: POST /state -> its result event (live session) vs a fresh session "
        "of the same state -> its first result; median / p95 [ms]"
    )
    print(f"{'change':34}{'n':>3}{'live':>12}{'fresh':>12}{'ratio':>7}{'setup':>7}{'compute':>9}")
    for (kind, _), v in r["server"].items():
        print(
            f"{kind:34}{v['n']:3d}{_pair(v['live_ms'])}{_pair(v['fresh_ms'])}"
            f"{_ratio(v['fresh_ms'][0], v['live_ms'][0])}{_ms(v['setup_ms'][0]):>7}"
            f"{_ms(v['compute_ms'][0]):>9}"
        )
    if "browser_skipped" in r:
        print(f"\nbrowser: skipped, {r['browser_skipped']}")
        return
    b = r["browser"]
    print(
        "\nbrowser: control -> plots drawn, -> scene shown; the page's own update (jik) vs the "
        "page reloaded with the changed state (reload); median / p95 [ms]"
    )
    print(f"{'':37}{'jik':^33}{'reload':^28}{'ratio':^14}")
    print(
        f"{'change':34}{'n':>3}{'plots':>12}{'scene':>12}{'compute':>9}{'n':>4}{'plots':>12}"
        f"{'scene':>12}{'plots':>7}{'scene':>7}"
    )
    for kind in dict.fromkeys(k for k, _ in b):
        j, s = b.get((kind, "jik"), _NONE), b.get((kind, "reload"), _NONE)
        print(
            f"{kind:34}{j['n']:3d}{_pair(j['plots_ms'])}{_pair(j['scene_ms'])}"
            f"{_ms(j['compute_ms'][0]):>9}{s['n']:4d}{_pair(s['plots_ms'])}{_pair(s['scene_ms'])}"
            f"{_ratio(s['plots_ms'][0], j['plots_ms'][0])}"
            f"{_ratio(s['scene_ms'][0], j['scene_ms'][0])}"
        )
    print()
    for family, target in TARGETS_MS.items():
        v = b.get((f"all {family} changes", "jik"))
        if v is None:
            continue
        verdicts = [
            f"{what} {v[f'{what}_ms'][1]:.0f} ms "
            f"({'met' if v[f'{what}_ms'][1] < target else 'NOT met'})"
            for what in ("plots", "scene")
        ]
        own = [s for s in r["browser_samples"] if s["family"] == family and s["mode"] == "jik"]
        within = sum(max(s["plots_ms"], s["scene_ms"]) < target for s in own)
        print(
            f"target p95 < {target:.0f} ms for a {family} change: "
            + ", ".join(verdicts)
            + f"; {within} of {len(own)} changes within it, plots and scene"
        )


if __name__ == "__main__":
    main()
