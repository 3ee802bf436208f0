"""The table of leg ends: the configuration after every leg for each chosen algorithm, and on the
paper's experiment (Manipulator 2, l = 1, from x0 = (0, 0, pi/2) on the path (1, 1), (1, 2),
(0, 2), (0, 1)) Table 1 of the paper, with the printed columns beside jik's, the cells that differ
marked, and the errata entry (docs/paper-errata.md) in words.

The page draws the figure as an HTML table (static/panels.js): ``layout.meta`` carries the notes
shown under it (``notes``) and the cells that differ from the printed value (``differs``:
``[column, row, printed text]``).
"""

from __future__ import annotations

import numpy as np

from ...engine.reproductions.table1 import (
    PRINTED,
    cell,
    differing,
    is_experiment,
    not_table1,
    row_labels,
)
from ...engine.reproductions.table1 import notes as table1_notes
from .algorithms import STYLES
from .plotting import corner_names, figure, trace
from .runs import DashboardResult

TABLE1_TITLE = (
    "Table 1 of the paper: Manipulator 2 on the closed path, jik beside the printed values"
)
LEG_ENDS_TITLE = "Joint configuration at the end of each leg (not the paper's Table 1)"
#: The algorithms of the paper's Table 1.
PAPER = tuple(PRINTED)


def _tint(color: str) -> str:
    """An algorithm's colour mixed with 85 % white: its columns' fill."""
    rgb = [int(color[i : i + 2], 16) for i in (1, 3, 5)]
    return "#" + "".join(f"{round(255 - 0.15 * (255 - v)):02x}" for v in rgb)


#: Cell colours: each algorithm's columns, the printed ones, and a cell that differs.
FILLS = {
    **{a: _tint(s.color) for a, s in STYLES.items()},
    "printed": "#eeeeee",
    "differs": "#ffd966",
}
SHORT = {a: s.short.split(" (")[0] for a, s in STYLES.items()}


def _on_experiment(s) -> bool:
    """Whether the state ``s`` is Manipulator 2 (l = 1) from the paper's x0 on its closed path,
    whatever its algorithms."""
    l = s.robot_parameters.get("l", 1.0)
    return s.robot == "manipulator2" and s.task == "path" and is_experiment(l, s.x0, s.path)


def _ends(result: DashboardResult, algorithm: str) -> np.ndarray:
    """x0 and the configuration after each leg: (legs + 1, p)."""
    return np.vstack([np.asarray(result.state.x0)[None, :], result.runs[algorithm].leg_end])


class _Table:
    """A table's columns as they are added: header texts, cell texts, header fills."""

    def __init__(self, first: str, labels: list[str]) -> None:
        self.rows = len(labels)
        self.header, self.cols, self.fills = [first], [labels], ["#f4f4f4"]

    def add(self, names, values: np.ndarray, fill: str, label: str) -> None:
        """One column per variable of ``values`` (rows, p), headed ``label.format(name)``,
        to four decimals (:func:`~jik.engine.reproductions.table1.cell`), blank below them."""
        for k, name in enumerate(names):
            self.header.append(label.format(name))
            self.cols.append([cell(v, 0) for v in values[:, k]] + [""] * (self.rows - len(values)))
            self.fills.append(fill)


def table1_spec(result: DashboardResult) -> dict:
    """Table 1 (paper, sec. 5.2): for each of its two algorithms jik's columns, then the printed
    ones, the printed first cycle compared cell by cell to four decimals, as printed
    (:func:`~jik.engine.reproductions.table1.differing`); then one group of jik's columns per
    other chosen algorithm, in its colour (:data:`STYLES`)."""
    names = result.variable_names
    ends = {a: _ends(result, a) for a in result.runs}
    rows = max(len(e) for e in ends.values())
    table = _Table("row", row_labels(rows))
    differs: list[list] = []
    for a in PAPER:
        printed = np.asarray(PRINTED[a], dtype=float)
        mask = differing(a, ends[a])
        first = len(table.cols)
        differs += [
            [first + int(k), int(r), cell(printed[r, k], 0)] for k, r in np.argwhere(mask.T)
        ]
        table.add(names, ends[a], FILLS[a], f"{SHORT[a]} {{}} (jik)")
        table.add(names, printed, FILLS["printed"], f"{SHORT[a]} {{}} (printed)")
    others = [a for a in result.runs if a not in PAPER]
    for a in others:  # the other chosen algorithms: jik's columns only (the paper has none)
        table.add(names, ends[a], FILLS[a], f"{SHORT[a]} {{}} (jik)")
    shown = ", ".join(SHORT[a] for a in others)
    state = result.state
    notes = table1_notes(ends, state.augmentation, state.mode, state.gamma, shown)
    return _spec(TABLE1_TITLE, table, notes, differs)


def leg_ends_spec(result: DashboardResult) -> dict:
    """The configuration after every leg for each algorithm (any robot, path or target)."""
    L = len(result.targets)
    legs = corner_names(result)
    rows = max(len(r.leg_end) for r in result.runs.values()) + 1
    point = ["start x0"] + [
        f"cycle {c // L + 1}, leg to {legs[c % L]} {_point(result.targets[c % L])}"
        for c in range(rows - 1)
    ]
    table = _Table("leg end", point)
    for a in result.runs:
        table.add(result.variable_names, _ends(result, a), FILLS[a], f"{SHORT[a]} {{}}")
    notes = []
    on = _on_experiment(result.state)
    if on or result.state.robot == "manipulator2":
        notes.append(not_table1(on, " and ".join(STYLES[a].short for a in PAPER)))
    return _spec(LEG_ENDS_TITLE, table, notes, [])


def table_spec(result: DashboardResult) -> dict:
    """Table 1 on the paper's experiment (any mode, map, gamma, cycles) with the paper's two
    algorithms among those chosen, else the plainly named table of leg ends."""
    if set(PAPER) <= set(result.runs) and _on_experiment(result.state):
        return table1_spec(result)
    return leg_ends_spec(result)


def _spec(title: str, table: _Table, notes: list[str], differs: list[list]) -> dict:
    marked = {(c, r) for c, r, _ in differs}
    cell_fills = [
        [
            FILLS["differs"] if (c, r) in marked else ("white" if r % 2 == 0 else "#f7f7f7")
            for r in range(table.rows)
        ]
        for c in range(len(table.cols))
    ]
    data = trace(
        "table",
        # (fill=dict(color=...): plotly.py's "fill_color" shorthand is expanded only by its
        # validation, which the builders skip; the page reads fill.color)
        header=dict(
            values=table.header, fill=dict(color=table.fills), font=dict(size=11), align="center"
        ),
        cells=dict(
            values=table.cols,
            font=dict(size=11, family="monospace"),
            align="right",
            fill=dict(color=cell_fills),
        ),
    )
    spec = figure([data], title, margin=dict(l=10, r=10, t=40, b=10))
    spec["layout"]["meta"] = {"notes": notes, "differs": differs}
    return spec


def _point(p) -> str:
    """A task point to three digits, a coordinate of round-off (1e-12 of the point's size) as 0,
    as the path's box shows it."""
    tiny = 1e-12 * max(1.0, *(abs(v) for v in p))
    return "(" + ", ".join(f"{(v if abs(v) > tiny else 0.0) + 0.0:.3g}" for v in p) + ")"
