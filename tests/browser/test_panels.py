"""The page's panels: every panel of the configuration drawn, saved as PNG, the session's data
exported, and a long computation (the unicycle) shown on its way."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from tests.browser.conftest import probe

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


#: An export's file name: robot, panel (images), map, mode, generation, UTC time.
NAMED = r"jik-manipulator2-{}paper_cubic-continuous-g{}-\d{{8}}T\d{{6}}Z\.{}"


def test_every_panel_is_drawn_and_saves_as_png(tabs, config):
    """Each panel that /api/dashboard/config lists is drawn (plotly's SVG, or an HTML table for
    the table), and a panel's PNG button downloads jik-<robot>-<panel>-<map>-...-<time>.png."""
    tab = tabs.open(scene=False)
    panels = [p["id"] for p in config["panels"]]
    assert "table" in panels and len(panels) > 1
    for panel in panels:
        drawn = "table tbody tr" if panel == "table" else ".main-svg"
        expect(tab.page.locator(f"#plot-{panel} {drawn}").first).to_be_visible()

    with tab.page.expect_download() as saved:
        tab.page.locator("#plot-task .panel-tools button", has_text="PNG").click()
    assert re.fullmatch(NAMED.format("task-", 1, "png"), saved.value.suggested_filename)
    assert Path(saved.value.path()).read_bytes()[:8] == PNG_SIGNATURE


def test_exports_download_the_sessions_data(tabs):
    """The footer's export links download this session's result: CSV, one row per point of
    either run, and JSON, with the session's state and drifts."""
    tab = tabs.open(scene=False)
    tab.set_slider("#ctl-cycles", 2)
    snapshot = tab.snapshot()
    summary = snapshot["summary"]

    with tab.page.expect_download() as saved:
        tab.page.click("#export-csv")
    generation = snapshot["computed_generation"]
    assert re.fullmatch(NAMED.format("", generation, "csv"), saved.value.suggested_filename)
    lines = Path(saved.value.path()).read_text().splitlines()
    context = [r for r in lines if r.startswith("#")]
    assert re.fullmatch(r"# jik \S+, exported \d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\+00:00", context[1])
    assert '"cycles":2' in context[2]  # (the state that produced it)
    assert context[3] == (
        "# units: theta [dimensionless]; x_1 [m]; x_2 [m]; x_3 [rad]; y_1 [m]; y_2 [m]; "
        "error [m]; h [the unit of the map's formula]"
    )
    assert context[4] == "# coordinates: x_1 x1; x_2 x2; x_3 x3; y_1 y1; y_2 y2"
    assert any(r.startswith("# pseudoinverse drift after each cycle: ") for r in context)
    rows = lines[len(context) :]
    assert rows[0].startswith("algorithm,cycle,leg,theta,x_1")
    assert len(rows) - 1 == sum(run["points"] for run in summary.values())

    with tab.page.expect_download() as saved:
        tab.page.click("#export-json")
    assert re.fullmatch(NAMED.format("", generation, "json"), saved.value.suggested_filename)
    data = json.loads(Path(saved.value.path()).read_text())
    assert data["jik_version"] and data["exported_at"].endswith("+00:00")
    assert [data["units"][f"x_{k}"] for k in (1, 2, 3)] == ["m", "m", "rad"]
    assert data["state"] == snapshot["state"] and data["state"]["cycles"] == 2
    assert data["generation"] == snapshot["computed_generation"]
    for algorithm, run in summary.items():
        assert data["runs"][algorithm]["drift"] == pytest.approx(run["drift"], rel=1e-12)


def test_the_unicycle_shows_its_computations_on_their_way(tabs, config):
    """A switch to the unicycle shows "computing generation N…" until its plots are drawn; a
    smaller gamma (ten times the iterations, a few seconds) also shows the progress bar while it
    runs past config.progress_after, and hides it once drawn."""
    tab = tabs.open(scene=False)
    tab.watch_header()
    generation = tab.select("#ctl-robot", "unicycle")
    assert tab.robot == "unicycle" and tab.snapshot()["state"]["mode"] == "discrete"
    status = tab.page.locator("#status-text")
    expect(status).to_have_text(f"up to date (generation {generation})")
    assert f"computing generation {generation}…" in tab.header_seen()["statuses"]
    expect(tab.page.locator("#plot-task .main-svg").first).to_be_visible()

    tab.watch_header()
    generation = tab.set_slider("#ctl-gamma", -1.5)  # gamma 0.03 (discrete mode: 0.01..1.99)
    assert tab.snapshot()["state"]["gamma"] == pytest.approx(0.03, rel=0.05)
    expect(status).to_have_text(f"up to date (generation {generation})")
    seen = tab.header_seen()
    assert f"computing generation {generation}…" in seen["statuses"], seen
    timing = tab.page.text_content("#timing") or ""
    match = re.match(rf"generation {generation}: compute (\d+) ms", timing)
    assert match, timing
    if int(match.group(1)) > 2000 * config["progress_after"]:
        assert seen["progress"], f"no progress bar during a computation of {timing}"
    expect(tab.page.locator("#progress")).to_be_hidden()


def test_the_table_saves_as_csv_with_its_notes_and_state(tabs):
    """The table panel's CSV button saves Table 1 as on screen, after '#' lines with the state
    it shows, its notes (the erratum) and the cells that differ from the print; the footer's
    export links name the generation they export."""
    tab = tabs.open(scene=False)
    with tab.page.expect_download() as saved:
        tab.page.locator("#plot-table .panel-tools button", has_text="CSV").click()
    assert re.fullmatch(NAMED.format("table-", 1, "csv"), saved.value.suggested_filename)
    lines = Path(saved.value.path()).read_text().splitlines()
    context = [r for r in lines if r.startswith("#")]
    assert context[0].startswith("# jik · generation 1 · manipulator2, continuous mode")
    assert any("Erratum" in r for r in context)
    assert sum(r.startswith("# differs from the print: row B  x1f") for r in context) == 3
    rows = lines[len(context) :]
    assert rows[0].startswith("row,J^P# x1 (jik),J^P# x2 (jik)")
    assert rows[2].startswith("B  x1f,0.1132,0.5379,1.0904,0.1132,0.5379,1.0904")
    expect(tab.page.locator("#export-json")).to_have_text("export JSON (generation 1)")
    expect(tab.page.locator("#export-csv")).to_have_text("export CSV (generation 1)")


@pytest.mark.parametrize("panel", ["task", "drift", "augmenting"])
def test_a_saved_svg_holds_its_legend_and_whole_caption(tabs, panel):
    """A panel saved as SVG holds its legend (the algorithms, the targets) and, under it, the
    caption with the state it shows, whole: both inside the image, in lines that fit its width
    (the state of a link with a long name makes the caption longer than a line). The h panel,
    whose runs are shapes without legend entries, names the algorithms in their colours in the
    caption instead."""
    tab = tabs.open(scene=False)
    with tab.page.expect_download() as saved:
        tab.page.locator(f"#plot-{panel} .panel-tools button", has_text="SVG").click()
    svg = Path(saved.value.path()).read_text()
    fits = tab.page.evaluate(probe("svg_fits"), svg)
    legend, caption = fits["legend"], fits["caption"]
    if panel == "augmenting":
        assert caption["lines"][0] == "▬ pseudoinverse J^P# (8) · ▬ extended Jacobian J^E# (11)"
        assert 'fill:#d62728">▬ pseudoinverse' in svg  # (in the pseudoinverse's red)
        caption["lines"] = caption["lines"][1:]
        legend = legend or {"top": 0, "bottom": 0, "right": 0}
    else:
        assert legend is not None and "pseudoinverse J^P#" in " ".join(fits["legendItems"])
    assert 0 <= legend["top"] and legend["bottom"] <= fits["height"] + 0.5, fits
    assert legend["right"] <= fits["width"] + 0.5, fits
    assert caption["bottom"] <= fits["height"] + 0.5 and caption["right"] <= fits["width"], fits
    assert caption["top"] >= legend["bottom"] - 0.5, fits  # (under the legend, not over it)
    text = " ".join(caption["lines"])
    assert text.startswith("jik · generation 1 · manipulator2, continuous mode")
    assert text.endswith("closed path, 3 cycles"), text
