"""Dashboard figures: the JSON of every panel after a control change.

Straightforward: plotly.py's way, a ``go.Figure`` per panel and its ``to_json()`` (what the
dashboard once did). jik: the figure dicts serialized directly
(:func:`jik.app.dashboard.figures.figure_specs`, :func:`jik.app.dashboard.figures.figure_json`).
Both from the same result, checked to decode to the same figures; wall-clock medians.
"""

from __future__ import annotations

import base64
import json
import statistics
import time

import numpy as np
import plotly.graph_objects as go

from ..app.dashboard import compute, default_state
from ..app.dashboard.figures import figure_specs
from ..app.dashboard.plotting import PANELS, figure_json

ROBOTS = ("manipulator2", "manipulator1", "unicycle")


def _values(v):
    """Decoded JSON with typed arrays as float lists, NaN as None (the two sides narrow ints
    differently)."""
    if isinstance(v, dict) and "bdata" in v:
        dtype = np.dtype(v["dtype"]).newbyteorder("<")  # (plotly's codes are numpy's: f4, i2, ...)
        a = np.frombuffer(base64.b64decode(v["bdata"]), dtype=dtype).astype(float)
        return [None if np.isnan(x) else x for x in a.tolist()]
    if isinstance(v, dict):
        return {k: _values(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_values(x) for x in v]
    return v


def _median_ms(fn, repeats: int) -> float:
    fn()  # (warm)
    walls = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        walls.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(walls)


def run(quick: bool = False) -> dict:
    out = {}
    for robot in ROBOTS:
        result = compute(default_state(robot))
        panels = set(PANELS) - {"sensitivity"}  # (the second phase's panel)

        def plotly_py(result=result, panels=panels):
            specs = figure_specs(result, None, panels)
            return {
                k: go.Figure(data=f["data"], layout=f["layout"], _validate=False).to_json()
                for k, f in specs.items()
            }

        def jik(result=result, panels=panels):
            return {k: figure_json(f) for k, f in figure_specs(result, None, panels).items()}

        a, b = plotly_py(), jik()
        for k in a:
            assert _values(json.loads(a[k])) == _values(json.loads(b[k])), f"{robot}: {k}"
        repeats = 10 if quick else 40
        slow, fast = _median_ms(plotly_py, repeats), _median_ms(jik, repeats)
        out[robot] = {"plotly_ms": slow, "jik_ms": fast, "ratio": slow / fast, "repeats": repeats}
    return out


def main(quick: bool = False) -> None:
    r = run(quick=quick)
    print(f"{'default state':16}{'go.Figure':>12}{'figure_json':>13}{'ratio':>8}{'runs':>6}")
    for robot, v in r.items():
        print(
            f"{robot:16}{v['plotly_ms']:10.1f}ms{v['jik_ms']:11.1f}ms{v['ratio']:8.2f}"
            f"{v['repeats']:6d}"
        )


if __name__ == "__main__":
    main()
