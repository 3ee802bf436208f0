"""Figure builders: pure functions of a dashboard result (no server)."""

from __future__ import annotations

import base64
import json

import numpy as np
import plotly.graph_objects as go
import pytest

from jik.app.dashboard import COLORS, LABELS, compute, default_state, updated_state
from jik.app.dashboard.figures import figure_specs
from jik.app.dashboard.functionals import error_functionals, sensitivity
from jik.app.dashboard.plotting import figure_json, keep_ranges, nice_range
from jik.engine.registry import ROBOTS


def figures_for(result, functionals=None, only=None, sensitivity=None) -> dict[str, go.Figure]:
    """The panels of ``result`` (:func:`figure_specs`) as plotly figures, validated by plotly
    (the builders skip its validation: an unknown property raises here)."""
    return {
        k: go.Figure(v) for k, v in figure_specs(result, functionals, only, sensitivity).items()
    }


def panel(result, key, functionals=None, sensitivity=None) -> go.Figure:
    """One panel of ``result`` as a validated plotly figure (:func:`figures_for`)."""
    return figures_for(result, functionals, {key}, sensitivity)[key]


@pytest.fixture(scope="module")
def path_result():
    """Manipulator 2, the paper's closed path A-B-C-D-A driven twice."""
    return compute(updated_state(default_state("manipulator2"), {"cycles": 2}))


@pytest.fixture(scope="module")
def target_result():
    return compute(updated_state(default_state("manipulator1"), {"task": "target"}))


def _colors(fig) -> dict[str, str]:
    named = [t for t in fig.data if t.type == "scatter" and t.name in LABELS.values()]
    return {t.name: t.line.color for t in named}


def test_task_space_paths_use_one_colour_per_algorithm(path_result):
    fig = panel(path_result, "task")
    assert _colors(fig) == {LABELS[a]: COLORS[a] for a in path_result.state.algorithms}
    assert fig.layout.xaxis.title.text == "y1 [m]"
    assert fig.layout.yaxis.title.text == "y2 [m]"
    targets = next(t for t in fig.data if t.name == "targets")
    assert list(targets.text) == ["B", "C", "D", "A"]  # (Table 1: A = k(x0) = (0, 1))
    np.testing.assert_allclose(targets.x, [1, 1, 0, 0])
    # Both end-effector paths pass through every target (the solver's tol is 1e-10).
    for a, run in path_result.runs.items():
        for target in path_result.targets:
            assert np.min(np.linalg.norm(run.y - target, axis=1)) < 1e-8, a


def test_joint_figure_has_one_axis_per_joint_with_units(path_result):
    fig = panel(path_result, "joints")
    titles = [fig.layout[f"yaxis{'' if k == 0 else k + 1}"].title.text for k in range(3)]
    assert titles == ["x1 [m]", "x2 [m]", "x3 [rad]"]
    assert fig.layout.xaxis.title.text.startswith("θ")
    assert len(fig.data) == 6
    run = path_result.runs["pseudoinverse"]
    np.testing.assert_allclose(fig.data[2].y, run.x[:, 2])
    assert all(t.hovertemplate for t in fig.data)


def test_drift_is_log_scale_and_separates_the_algorithms(path_result):
    fig = panel(path_result, "drift")
    assert fig.layout.yaxis.type == "log"
    drift = {t.name: np.asarray(t.y) for t in fig.data}
    assert drift[LABELS["pseudoinverse"]].shape == (2,)
    # Table 1's message: the pseudoinverse drifts, the extended Jacobian returns.
    assert np.all(drift[LABELS["pseudoinverse"]] > 0.1)
    assert np.all(drift[LABELS["extended"]] < 1e-8)
    assert drift[LABELS["pseudoinverse"]][1] > drift[LABELS["pseudoinverse"]][0]


def test_table1_puts_the_printed_columns_beside_jiks(path_result):
    """On the paper's experiment the table is Table 1: the paper's row labels, jik's columns
    each followed by the printed one, and the extended cells that differ from the print marked
    (the errata's first two legs), with the erratum in words."""
    fig = panel(path_result, "table")
    cells = fig.data[0].cells.values
    assert fig.layout.title.text.startswith("Table 1 of the paper")
    assert list(cells[0][:5]) == ["A  x0", "B  x1f", "C  x2f", "D  x3f", "A  x4f"]
    header = list(fig.data[0].header.values)
    assert header[1:7] == [f"J^P# x{k} (jik)" for k in (1, 2, 3)] + [
        f"J^P# x{k} (printed)" for k in (1, 2, 3)
    ]
    for col, (a, k) in enumerate([("pseudoinverse", k) for k in range(3)], start=1):
        assert float(cells[col][1]) == pytest.approx(path_result.runs[a].leg_end[0, k], abs=1e-4)
    differs = {(c, r) for c, r, _ in fig.layout.meta["differs"]}
    assert differs == {(c, r) for c in (7, 8, 9) for r in (1, 2)}
    assert any("Erratum" in n and "(38)" in n for n in fig.layout.meta["notes"])
    # Round-off zeros (the extended run's x2 back at 0 after a cycle, about -1e-16) print
    # without a sign, as Table 1 prints them.
    assert not any(c == "-0.0000" for col in cells for c in col)


def test_off_the_papers_path_the_table_is_plainly_named():
    result = compute(updated_state(default_state("manipulator2"), {"x0.0": 0.3, "cycles": 1}))
    fig = panel(result, "table")
    assert "not the paper's Table 1" in fig.layout.title.text
    assert fig.data[0].cells.values[0][0] == "start x0"


def test_on_the_papers_path_without_both_its_algorithms_the_table_says_to_choose_them():
    """Manipulator 2 on the paper's experiment with J^E# (11) unchosen is not Table 1, and its
    note names what is missing (the paper's two algorithms), not the robot, x0 and path that
    are already the paper's."""
    state = updated_state(default_state("manipulator2"), {"algorithms": ["pseudoinverse"]})
    notes = panel(compute(state), "table").layout.meta["notes"]
    assert notes == [
        "Not Table 1: the paper's Table 1 compares J^P# (8) and J^E# (11) on this experiment; "
        "choose both to compare with the printed values."
    ]


def test_augmenting_map_contours_with_the_extended_run_on_a_level_set(path_result):
    functionals = error_functionals(path_result)
    fig = panel(path_result, "augmenting", functionals)
    contour = fig.data[0]
    assert contour.type == "contour"
    assert np.asarray(contour.z).shape == (len(contour.y), len(contour.x))
    # PaperCubic depends on (x2, x3): those are the plotted axes.
    assert fig.layout.xaxis.title.text == "x2 [m]"
    assert fig.layout.yaxis.title.text == "x3 [rad]"
    # (38)'s dh K vanishes inside its design region: E1 diverges, and the title says so.
    assert "E1 = ∞ (dh K = 0 inside)" in fig.layout.title.text
    assert "E2 = 119.3" in fig.layout.title.text
    # The runs and x0 are shapes over the contours (moved by a relayout, see map_figures.py).
    runs = fig.layout.shapes[:2]
    assert [s.line.color for s in runs] == [COLORS["pseudoinverse"], COLORS["extended"]]
    ext = path_result.runs["extended"].x
    corners = [tuple(map(float, p.split(","))) for p in runs[1].path[1:].split("L")]
    assert np.allclose(corners, ext[:, 1:3], rtol=1e-4, atol=1e-4)
    x0 = fig.layout.shapes[2]
    assert (x0.xanchor, x0.yanchor) == tuple(path_result.state.x0[1:3])
    assert functionals["E1"] is None and functionals["E1_divergent"] and functionals["E2"] > 0
    h = path_result.runs["extended"].h
    assert np.ptp(h) < 1e-9


def test_single_target_shows_convergence_instead_of_drift(target_result):
    fig = panel(target_result, "drift")
    assert fig.layout.title.text.startswith("Convergence")
    for t in fig.data:
        assert t.y[-1] < 1e-9 and t.y[0] > 0.1


def test_the_papers_figures_5_to_9_are_cited_on_their_run_only(path_result):
    """Figs. 5-9 show Manipulator 2's single target (0, 2) from x0 = (0, 0, pi/2) (sec. 5.2.1);
    Table 1's closed path, which the paper draws in no figure, and another target cite none."""
    m2 = default_state("manipulator2")
    figs = compute(updated_state(m2, {"task": "target"}))
    assert "(Figs. 5, 6)" in panel(figs, "task").layout.title.text
    assert "(Figs. 7-9)" in panel(figs, "joints").layout.title.text
    other_target = compute(updated_state(m2, {"task": "target", "target": [1.0, 1.0]}))
    for result in (path_result, other_target):
        assert "Figs." not in panel(result, "task").layout.title.text
        assert "Figs." not in panel(result, "joints").layout.title.text


def test_the_papers_figures_11_to_14_are_cited_on_the_unicycles_runs_of_them_only():
    """Figs. 11-14 show the unicycle from pose A or B, lambda0 = (0.5, -0.25, 0.3, -0.25), to
    y_d = (1, 0, -pi/2) by the discrete algorithm with gamma = 0.1 (sec. 6.2); another gamma,
    mode or start is not what they show and cites none."""
    unicycle = default_state("unicycle")
    for patch, cited in (({}, True), ({"gamma": 0.5}, False), ({"mode": "continuous"}, False)):
        result = compute(updated_state(unicycle, patch))
        titles = [panel(result, k).layout.title.text for k in ("task", "joints")]
        assert [("(Figs. 11-14 a)" in titles[0]), ("(Figs. 11-14 b, c)" in titles[1])] == [
            cited
        ] * 2, (patch, titles)


def test_a_single_target_is_named_target_not_a_corner_letter():
    """The paper's letters are Manipulator 2's corners (A = (1, 1)) and the unicycle's starts
    (q0 = A): a single target lettered A was read as one of them."""
    result = compute(updated_state(default_state("manipulator2"), {"task": "target"}))
    (marks,) = [t for t in panel(result, "task").data if t.name == "targets"]
    assert list(marks.text) == ["target"]
    rows = panel(result, "table").data[0].cells.values[0]
    assert list(rows) == ["start x0", "cycle 1, leg to target (0, 2)"]


def test_every_panel_serialises_to_plotly_json(path_result, target_result):
    for result in (path_result, target_result):
        figs = figures_for(result)
        assert set(figs) == {
            "task",
            "joints",
            "drift",
            "table",
            "augmenting",
            "sensitivity",
            "cspace",
        }
        for key, fig in figs.items():
            parsed = json.loads(fig.to_json())
            # (the sensitivity panel waits for the second phase: a title, no data yet)
            assert parsed["data"] or key == "sensitivity"
            assert parsed["layout"]["title"]["text"]
            # The builders skip plotly's validation for speed: every property must still be
            # valid (go.Figure validates a plain dict and raises on an unknown property).
            go.Figure(parsed)
        go.Figure(panel(result, "augmenting", error_functionals(result)).to_dict())


_DTYPES = {
    "f8": "<f8",
    "f4": "<f4",
    "i4": "<i4",
    "u4": "<u4",
    "i2": "<i2",
    "u2": "<u2",
    "i1": "i1",
    "u1": "u1",
}


def _decoded(v):
    """JSON from plotly with its typed arrays (base64) read back as float arrays."""
    if isinstance(v, dict) and "bdata" in v:
        a = np.frombuffer(base64.b64decode(v["bdata"]), dtype=_DTYPES[v["dtype"]])
        shape = tuple(int(n) for n in v["shape"].split(",")) if "shape" in v else a.shape
        return a.reshape(shape).astype(float)
    if isinstance(v, dict):
        return {k: _decoded(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_decoded(x) for x in v]
    return v


def _same(a, b, where="") -> None:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        assert np.array_equal(np.asarray(a, float), np.asarray(b, float), equal_nan=True), where
    elif isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), (where, set(a) ^ set(b))
        for k in a:
            _same(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{where}[{i}]")
    else:
        assert a == b, (where, a, b)


def test_the_dashboards_json_is_plotlys(path_result, target_result):
    """The dashboard serializes figure dicts itself (figure_json, 5x faster than plotly's
    to_json): the page must get what plotly.py would send, typed arrays included."""
    for result in (path_result, target_result):
        functionals = error_functionals(result)
        sens = sensitivity(result, functionals)
        for key, spec in figure_specs(result, functionals, sensitivity=sens).items():
            ours = json.loads(figure_json(spec))
            theirs = json.loads(go.Figure(spec).to_json())  # (validated, too)
            _same(_decoded(ours), _decoded(theirs), key)
    # numpy scalars, non-finite numbers (null) and 2-D arrays (with their shape)
    spec = {
        "data": [
            {
                "type": "heatmap",
                "z": np.array([[1.0, np.nan], [2.0, 3.0]]),
                "x": [np.float64(0.5), float("inf")],
                "y": np.arange(2),
            }
        ],
        "layout": {"title": {"text": "t"}},
    }
    ours = json.loads(figure_json(spec))
    assert ours["data"][0]["x"] == [0.5, None]
    assert ours["data"][0]["z"]["shape"] == "2, 2" and ours["data"][0]["y"]["dtype"] == "i4"
    plotlys = go.Figure(data=spec["data"], layout=spec["layout"], _validate=False).to_json()
    _same(_decoded(ours)["data"], _decoded(json.loads(plotlys))["data"])  # (no template here)


@pytest.mark.skipif("unicycle" not in ROBOTS, reason="the unicycle is not in the registry yet")
def test_unicycle_platform_paths_and_controls():
    state = default_state("unicycle")
    result = compute(state)
    figs = figures_for(result)
    task = figs["task"]
    assert task.layout.title.text.startswith("Platform paths")
    finals = [t for t in task.data if t.name in LABELS.values()]
    assert len(finals) == 2
    for t in finals:
        # The last iteration's platform path ends at the target pose.
        assert np.hypot(t.x[-1] - state.target[0], t.y[-1] - state.target[1]) < 1e-6
    assert figs["joints"].layout.title.text.startswith("Controls")
    for fig in figs.values():
        go.Figure(fig.to_dict())  # valid plotly (the builders skip the validation)


def test_sensitivity_sweeps_each_parameter_through_the_current_value():
    """E1, E2 at the current (a, b) of e2_optimal and how they change as a, b move."""
    result = compute(updated_state(default_state("manipulator1"), {"task": "target"}))
    functionals = error_functionals(result)
    sens = sensitivity(result, functionals)
    assert sens["kind"] == "parameters" and set(sens["parameters"]) == {"a", "b"}
    for key in ("E1", "E2"):
        assert sens[key]["value"] == pytest.approx(functionals[key], rel=1e-9)
        for name, v in sens["parameters"].items():
            sweep = sens[key]["sweeps"][name]
            assert sweep["values"][0] == pytest.approx(v - 1) and len(sweep["values"]) > 5
            mid = len(sweep["values"]) // 2  # the sweep passes through the current value
            assert sweep["functional"][mid] == pytest.approx(sens[key]["value"], rel=1e-9)
    fig = panel(result, "sensitivity", sensitivity=sens)
    go.Figure(fig.to_dict())
    assert "as the parameters of e2_optimal move" in fig.layout.title.text
    assert fig.layout.xaxis.title.text == "a" and fig.layout.xaxis2.title.text == "b"
    marked = [t for t in fig.data if t.mode == "markers"]
    assert sorted((t.x[0], t.y[0]) for t in marked) == sorted(
        (sens["parameters"][p], sens[k]["value"]) for p in ("a", "b") for k in ("E1", "E2")
    )


def test_sensitivity_without_parameters_compares_the_alternatives(path_result):
    """paper_cubic has no parameters: the E2 values of the robot's other maps are shown."""
    sens = sensitivity(path_result, error_functionals(path_result))
    assert sens["kind"] == "alternatives"
    names = [m["name"] for m in sens["maps"]]
    assert set(names) == {"paper_cubic", "e2_synthesized"}
    current = next(m for m in sens["maps"] if m["current"])
    assert current["name"] == "paper_cubic"
    assert current["E2"] == pytest.approx(error_functionals(path_result)["E2"], rel=1e-9)
    fig = panel(path_result, "sensitivity", sensitivity=sens)
    go.Figure(fig.to_dict())
    assert "no parameters" in fig.layout.title.text
    # E1 of paper_cubic diverges (dh K = 0 inside): no bar, and its map's foot says so.
    assert current["E1"] is None and current["E1_divergent"]
    assert [a.text for a in fig.layout.annotations] == ["E1 = ∞"]
    assert fig.layout.annotations[0].x == "paper_cubic (current)"
    assert [t.name for t in fig.data] == ["E1", "E2"]
    assert "computing" in panel(path_result, "sensitivity", sensitivity=None).layout.title.text


def test_functionals_use_the_design_region_and_rank_the_synthesized_map_first(path_result):
    """E1/E2 are taken on the paper's box for Manipulator 2 (x2 in [-1, 1], x3 in [0, pi]),
    the values of `jik reproduce manipulator2`, whatever the start point; there the synthesized
    map beats the printed cubic (38) by far."""
    from jik.engine.functionals import error_functional_e2
    from jik.engine.registry import robot_spec

    functionals = error_functionals(path_result)
    region = robot_spec("manipulator2").functional_region
    assert functionals["design_region"] is True
    assert functionals["region"] == {k: list(v) for k, v in region.items()}
    assert (
        "x2 ∈ [-1, 1], x3 ∈ [0, 3.14]"
        in panel(path_result, "augmenting", functionals).layout.title.text
    )
    spec = robot_spec("manipulator2")
    kin = spec.build()
    ref = error_functional_e2(kin, spec.augmentation("paper_cubic").build(kin), region, nodes=12)
    assert functionals["E2"] == pytest.approx(ref.value, rel=1e-12)
    alternatives = {m["name"]: m for m in sensitivity(path_result, functionals)["maps"]}
    assert alternatives["e2_synthesized"]["E2"] < 0.05 * alternatives["paper_cubic"]["E2"]


def test_the_h_grid_keeps_its_box_while_the_trajectories_fill_it(path_result):
    """The h panel's box stays for a nearby start point (the page then moves only the
    trajectories: h over (x2, x3) does not depend on x1, the grid is the same), and follows
    trajectories that leave it or shrink to less than half of it."""
    grid = path_result.augmenting
    state = path_result.state
    near = compute(updated_state(state, {"x0": [0.45, 0.0, np.pi / 2]}), grid_before=grid)
    assert near.augmenting["box"] == grid["box"]
    assert np.array_equal(near.augmenting["h"], grid["h"], equal_nan=True)
    assert (
        compute(updated_state(state, {"x0": [0.45, 0.0, np.pi / 2]})).augmenting["box"]
        != (grid["box"])
    )  # (its own box without the one on screen)
    small = dict(grid, box=[(lo, lo + 0.3 * (hi - lo)) for lo, hi in grid["box"]])
    away = compute(updated_state(state, {"x0": [0.45, 0.0, np.pi / 2]}), grid_before=small)
    assert away.augmenting["box"] != small["box"]  # (the trajectories leave it)
    wide = dict(grid, box=[(lo - 10.0, hi + 10.0) for lo, hi in grid["box"]])
    assert compute(state, grid_before=wide).augmenting["box"] == grid["box"]  # (under half)
    other = dict(grid, axes=(0, 2))
    assert compute(state, grid_before=other).augmenting["box"] == grid["box"]


def test_nice_range_pads_the_data_and_rounds_to_a_step():
    assert nice_range([-0.41, 1.39]) == [-0.6, 1.6]  # span 1.8: padded 0.09, step 0.2
    assert nice_range([0.0, 446.5], from_zero=True) == [0.0, 450.0]
    assert nice_range([5.0, 5.0]) == [4.95, 5.05]  # one value: a tenth of it around
    assert nice_range([0.0, 0.0]) == [-0.01, 0.01]
    assert nice_range([np.nan, np.inf]) is None  # plotly autoranges
    assert nice_range([0.5, 0.5 + 1e-15]) == [0.49, 0.51]  # constant up to rounding
    lo, hi = nice_range([1e-12, 3e-12])  # tiny but real spans keep their scale
    assert lo < 1e-12 and 3e-12 < hi < 4e-12
    rng = np.random.default_rng(3)
    for _ in range(200):
        v = rng.normal(size=20) * 10.0 ** rng.uniform(-6, 6)
        lo, hi = nice_range(v)
        span = v.max() - v.min()
        assert lo <= v.min() - 0.05 * span and hi >= v.max() + 0.05 * span
        assert lo >= v.min() - 0.3 * span and hi <= v.max() + 0.3 * span


def test_axis_ranges_hold_the_data_and_stay_put_for_a_small_change(path_result):
    """The page moves traces without a redraw when the layout is unchanged (static/panels.js):
    a nearby start point keeps every range; the ranges hold every plotted point."""
    here, nearby = (
        compute(updated_state(path_result.state, {"x0": [x1, 0.0, np.pi / 2]}))
        for x1 in (0.45, 0.46)
    )  # (the browser test's step)
    for key in ("task", "joints", "drift"):
        fig, fig2 = panel(here, key), panel(nearby, key)
        assert fig.layout.to_plotly_json() == fig2.layout.to_plotly_json(), key
        for t in fig.data:
            for axis, values in (("x", t.x), ("y", t.y)):
                name = f"{axis}axis" + (getattr(t, f"{axis}axis") or axis)[1:]
                layout_axis = fig.layout[name]
                lo, hi = layout_axis.range
                v = np.asarray(values, dtype=float)
                if layout_axis.type == "log":
                    v = np.log10(v)
                assert lo <= v.min() and v.max() <= hi, (key, name)


def test_axes_keep_their_range_while_the_data_fill_it(path_result):
    """Sticky axes (keep_ranges): the range on screen stays while the new data lie inside it
    and span at least half of it; otherwise the new figure's own range; never on the drift
    panel's cycle axis (a fixed tick step) or on categories."""

    def spec(key: str, **kw) -> dict:
        return figure_specs(path_result, only={key}, **kw)[key]

    fig = spec("task")
    own = fig["layout"]["xaxis"]["range"]
    x = fig["data"]
    lo, hi = min(x[0]["x"].min(), x[2]["x"].min()), max(x[0]["x"].max(), 1.0)
    wide = {"xaxis": {"range": [lo - 0.4, hi + 0.4]}, "yaxis": {"range": [-100.0, 100.0]}}
    kept = keep_ranges(spec("task"), wide)["layout"]
    assert kept["xaxis"]["range"] == [lo - 0.4, hi + 0.4]  # inside, filled >= half
    assert kept["yaxis"]["range"] == fig["layout"]["yaxis"]["range"]  # far too wide: its own
    inside = {"xaxis": {"range": [lo + 0.1, hi]}}  # cuts the data: its own
    assert keep_ranges(spec("task"), inside)["layout"]["xaxis"]["range"] == own
    drift = spec("drift")["layout"]
    before = {"xaxis": {"range": [0.0, 3.0]}, "yaxis": {"range": [-17.0, 2.0]}}
    kept = keep_ranges(spec("drift"), before)["layout"]
    assert kept["xaxis"]["range"] == drift["xaxis"]["range"]  # dtick = 1: never kept
    assert kept["yaxis"]["range"] == [-17.0, 2.0]  # log axis: in decades
    sens = spec("sensitivity", sensitivity=sensitivity(path_result, error_functionals(path_result)))
    keep_ranges(sens, sens["layout"])  # (the alternatives by name: no error)
    bars = {
        "data": [{"type": "bar", "x": ["a", "b"], "y": [1.0, 2.0]}],
        "layout": {"xaxis": {"range": [-0.5, 1.5]}},
    }
    assert keep_ranges(bars, {"xaxis": {"range": [-1, 2]}})["layout"]["xaxis"]["range"] == [
        -0.5,
        1.5,
    ]
    assert keep_ranges(fig, None) is fig


def test_a_panels_message_is_wrapped_to_fit_the_panel():
    """A long message (the note of a vector map in the h panel) is cut into lines of at most
    MESSAGE_CHARS characters, keeping the line breaks it has; nothing is lost."""
    from jik.app.dashboard.map_figures import MESSAGE_CHARS, message_figure

    note = (
        "formula: h = x2, x3, x5, x7: a vector of p − r = 4 maps, each kept constant by the "
        "extended inverse (eq. (12)); the h panel, E1 (13) and E2 (18) are for one degree of "
        "redundancy (p = r + 1)"
    )
    text = message_figure("Augmenting map h", note + "<br>second")["layout"]["annotations"][0]
    lines = text["text"].split("<br>")
    assert len(lines) > 3 and lines[-1] == "second"
    assert max(len(line) for line in lines) <= MESSAGE_CHARS
    assert " ".join(lines[:-1]) == note


def test_cspace_draws_each_corners_self_motion_manifold_through_its_leg_end(path_result):
    """The green curves are the engine's traced fibres k(x) = corner (one per corner, through
    the extended run's leg end there), a point every SPACING box diagonals, inside the box
    widened by half (up to the drawing's tolerance: the ends are where the curve leaves it)."""
    from jik.app.dashboard.analysis import runs_box
    from jik.app.dashboard.cspace import cspace_spec
    from jik.app.dashboard.robots import state_kinematics
    from jik.engine.self_motion import SPACING

    kin = state_kinematics(path_result.state)
    curves = [t for t in cspace_spec(path_result)["data"] if t.get("legendgroup") == "fibres"]
    assert len(curves) == len(path_result.targets)
    lo, hi = runs_box(path_result.state, path_result.runs)
    diagonal = float(np.linalg.norm(hi - lo))
    seeds = path_result.runs["extended"].leg_end
    for curve, target, seed in zip(curves, path_result.targets, seeds, strict=False):
        x = np.stack([curve["x"], curve["y"], curve["z"]], axis=1)  # (axes 0, 1, 2 of p = 3)
        assert len(x) > 20 and np.isfinite(x).all()
        np.testing.assert_allclose(kin.forward(x), np.broadcast_to(target, (len(x), 2)), atol=1e-9)
        assert np.min(np.linalg.norm(x - seed, axis=1)) < SPACING * diagonal
        gaps = np.linalg.norm(np.diff(x, axis=0), axis=1)
        assert np.all(gaps <= SPACING * diagonal * (1 + 1e-3))
        outside = np.maximum(lo - 0.5 * (hi - lo) - x, x - hi - 0.5 * (hi - lo))
        assert np.max(outside) < 1e-5


def test_a_big_endian_array_keeps_its_values():
    """A typed array is the array's bytes, which plotly.js reads little-endian: an array of
    the other byte order goes as a list of its values, not as bytes read backwards."""
    values = np.array([0.5, 2.0], dtype=">f8")
    assert json.loads(figure_json({"data": [{"x": values}], "layout": {}}))["data"][0]["x"] == [
        0.5,
        2.0,
    ]


def test_the_configuration_space_says_why_it_draws_no_level_surface():
    """A map undefined at x0 (a user's h = log(x3) from x3 < 0) has no level h = h(x0): the
    panel says so, not that h is solved point by point (it is not)."""
    definition = {
        "name": "formula",
        "variables": ["x1", "x2", "x3"],
        "task": ["x2 + cos(x3)", "x1 + sin(x3)"],
        "augmentations": [{"name": "formula", "h": "log(x3)"}],
    }
    state = updated_state(default_state("formula", definition), {"x0.2": -0.5})
    title = figure_specs(compute(state), only={"cspace"})["cspace"]["layout"]["title"]["text"]
    assert "level surface not drawn: h is undefined at x0" in title
    assert "point by point" not in title


def test_the_drift_axis_of_a_robot_without_units_has_no_empty_unit():
    """A formula robot states no unit: its drift axis reads "‖x(end of cycle) − x0‖ (log)",
    not with a blank where the unit would be."""
    definition = {
        "name": "formula",
        "variables": ["x1", "x2", "x3"],
        "task": ["x2 + cos(x3)", "x1 + sin(x3)"],
    }
    state = updated_state(default_state("formula", definition), {"cycles": 1})
    yaxis = figure_specs(compute(state), only={"drift"})["drift"]["layout"]["yaxis"]
    assert yaxis["title"]["text"] == "‖x(end of cycle) − x0‖ (log)"


def test_table1_of_discrete_runs_that_stop_in_the_first_cycle():
    """The paper's experiment in discrete mode with a step (gamma = 1.99) at which neither run
    finishes its first leg: the table still shows (x0 and the printed columns) and says the
    iteration stopped before the end of the first cycle."""
    state = updated_state(default_state("manipulator2"), {"mode": "discrete", "gamma": 1.99})
    result = compute(state)
    assert not any(run.success for run in result.runs.values())
    notes = figure_specs(result, only={"table"})["table"]["layout"]["meta"]["notes"]
    assert "γ = 1.99 stopped before the end of the first cycle" in notes[-1]


def test_the_configuration_space_of_a_robot_undefined_on_its_fibres_is_drawn(monkeypatch):
    """A user's k = (x1^2 + x2, x3 / x1): the corners' fibres reach x1 = 0, where k is
    undefined and the integrator creeps (steps of about 1e-5 over an arc of units). The panel
    is drawn with the curves traced up to there, not after hours with the session's result
    waiting on it (a counting integrator stands guard: far beyond the dashboard's bound, it
    stops the test instead of the clock)."""
    from scipy.integrate import DOP853

    import jik.engine.self_motion as self_motion
    from jik.engine.self_motion import DRAW_STEPS as MAX_TRACE_STEPS

    class Guard(DOP853):
        steps = 0

        def step(self):
            Guard.steps += 1
            assert Guard.steps <= 100 * MAX_TRACE_STEPS, "the self-motion curves creep on"
            return super().step()

    monkeypatch.setattr(self_motion, "DOP853", Guard)
    definition = {
        "name": "formula",
        "variables": ["x1", "x2", "x3"],
        "task": ["x1**2 + x2", "x3/x1"],
    }
    result = compute(default_state("formula", definition))
    spec = figure_specs(result, only={"cspace"})["cspace"]
    curves = [t for t in spec["data"] if t.get("legendgroup") == "fibres"]
    assert len(curves) == len(result.targets) and all(len(c["x"]) >= 2 for c in curves)
    assert Guard.steps <= 2 * len(result.targets) * MAX_TRACE_STEPS
