"""The dashboard's words for a reader without the paper: the key of colours and line styles (the
same in every panel, its exported images and the 3D scene), a short explanation of each panel,
and of the paper's symbols that controls and panels use. The page gets them from
:func:`page_config` (``GET /api/dashboard/config``); the controls' help comes with the controls
(:func:`jik.app.dashboard.controls.controls`, with :data:`jik.app.dashboard.glossary.SYMBOLS`).
"""

from __future__ import annotations

from dataclasses import asdict

from ...engine.arms import ARMS
from ...engine.robot_kinds import ARM, robot_kinds
from .algorithms import COLORS, LABELS, STYLES
from .controls import PROGRESS_AFTER
from .plotting import PANEL_SIZES

#: What each panel shows, and how to read it.
PANEL_HELP = {
    "task": "The end effector's path in the task space for each chosen algorithm: × marks the "
    "targets of the legs, ○ the start k(x0). The algorithms follow the same task path; they "
    "differ in the joints. The paper's Figs. 5 and 6 (and 7-9 for the joints) are Manipulator "
    "2's single target (0, 2) from x0 = (0, 0, π/2), its defaults with the task “single "
    "target”; the panels cite them there.",
    "drift": "Repeatability: after each cycle of the closed path, how far the joints are from "
    "where they started, ‖x − x0‖ (the Euclidean norm of the joint vector, whose coordinates "
    "can mix units, e.g. m and rad). A repeatable algorithm stays near 0 (log scale). For a "
    "single target: the task error against θ (or the iteration).",
    "joints": "Each joint coordinate against θ, the continuation parameter of the algorithm "
    "(7) (discrete mode: the iteration). Closed joint paths return to their start values at "
    "the end of each cycle.",
    "augmenting": "The augmenting map h of the extended Jacobian (eqs. (9)-(11)) over two joint "
    "coordinates: contours of h, with both runs on top. The extended Jacobian keeps h at h(x0) "
    "(eq. (12)), so its run follows a contour; the pseudoinverse crosses them. E1 (13) and E2 "
    "(18) measure how far the extended Jacobian is from the pseudoinverse over the region.",
    "sensitivity": "The error functionals E1 (13), Roberts-Maciejewski, and E2 (18), the "
    "manipulability-weighted embedding, of the current map and its alternatives, and how they "
    "change with the map's parameters: lower is closer to the pseudoinverse.",
    "cspace": "The joint paths x(θ) of the chosen algorithms in configuration space (three "
    "coordinates), with the level surface h(x) = h(x0) that the extended Jacobian stays on "
    "(eq. (12)) and, in green, the self-motion manifolds k(x) = y of the path's corners (curves, "
    "since p − r = 1). A repeatable run is one closed curve on the surface; the pseudoinverse's "
    "slides along the green curves from cycle to cycle. Drag to turn the view.",
    "table": "The joint configuration at the end of each leg. On the paper's experiment "
    "(Manipulator 2 on the square path), Table 1 of the paper beside jik's numbers.",
}

#: The atlas panel (not a panel of every result: computed on demand, app/dashboard/atlas.py).
ATLAS_HELP = (
    "The repeatability atlas of the current state: the closed path driven from many starts on "
    "the self-motion curve k(x) = k(x0) (p − r = 1), each at its arc length s along the curve "
    "(s = 0 is x0; the curve is cut where it leaves the robot's joint box). Each cell is the "
    "drift ‖x − x0‖ after one cycle from one start, as log10 on one colour scale for all: one "
    "heatmap per chosen algorithm, left to right (the extended Jacobian with the chosen "
    "augmenting map is repeatable: round-off, about −13). With path scales, one band of rows "
    "per scale of the path about k(x0). Click a cell to move the main view to that start "
    "(and scale). CSV saves the atlas's table: a row per start, algorithm and cycle (its "
    "columns: the engine's AtlasResult.columns())."
)


def page_config() -> dict:
    """What the page needs before its session: the algorithms' colours, labels and styles,
    the panels (ids, sizes, help), and when a computation shows its progress."""
    kinds, arm = robot_kinds(), [asdict(f) for f in ARM]
    return {
        "colors": COLORS,
        "labels": LABELS,
        # (how each algorithm is drawn, everywhere: its line style in the plots, plotly's
        # ``dash``, and its robot in the 3D scene, :data:`jik.app.dashboard.algorithms.STYLES`)
        "styles": {
            a: {"dash": s.dash, "line": s.line, "robot": s.robot} for a, s in STYLES.items()
        },
        "panels": [{"id": k, "size": v, "help": PANEL_HELP[k]} for k, v in PANEL_SIZES.items()],
        "progress_after": PROGRESS_AFTER,
        "tools": [{"id": "atlas", "help": ATLAS_HELP}],
        # (the robot editor's fields: one description, the engine's; a catalogue arm is a kind
        # of its own, whose definition changes its task, reference, home or maps)
        "robot_kinds": {**kinds, "kinds": {**kinds["kinds"], **dict.fromkeys(ARMS, arm)}},
    }
