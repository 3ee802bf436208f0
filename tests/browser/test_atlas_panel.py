"""The atlas panel: the repeatability atlas of the session's state computes with its progress
shown, can be cancelled, draws its heatmap, and a click on a cell moves the main view there."""

from __future__ import annotations

import csv
import io
import re
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest

from jik.app.compute.atlas_plan import AtlasLimits, planned
from jik.app.compute.atlas_schemas import AtlasRequest
from jik.engine.atlas_run import run_atlas
from tests.browser.conftest import ARTIFACTS, SCREEN_SIZES, get_json, poll, probe

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


def gone(url: str) -> bool:
    """Whether ``url`` answers 404."""
    try:
        urllib.request.urlopen(url, timeout=30).close()
    except urllib.error.HTTPError as error:
        return error.code == 404
    return False


def start_atlas(tab, starts: int, cycles: int) -> str:
    """Fill in the panel's boxes, press "Compute atlas"; the job's id (from its 202)."""
    page = tab.page
    page.fill("#atlas-starts", str(starts))
    page.fill("#atlas-cycles", str(cycles))
    with page.expect_response(
        lambda r: r.request.method == "POST" and r.url.endswith("/atlas")
    ) as response:
        page.click("#atlas-compute")
    assert response.value.status == 202, response.value.text()
    return response.value.json()["id"]


def screenshots(page, name: str) -> None:
    """The page at each of SCREEN_SIZES with the atlas panel at the top (below the sticky
    header): tests/artifacts/<name>-<width>.png."""
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    size = page.viewport_size
    for width, height in SCREEN_SIZES:
        page.set_viewport_size({"width": width, "height": height})
        page.evaluate(
            "() => { document.getElementById('atlas').scrollIntoView({block: 'start'});"
            " window.scrollBy(0, -document.querySelector('header').offsetHeight - 8); }"
        )
        page.wait_for_function("() => document.fonts.status === 'loaded'")
        page.screenshot(path=str(ARTIFACTS / f"{name}-{width}.png"))
    if size is not None:
        page.set_viewport_size(size)


# (CI's slow step: among the longest browser checks; the default run stays under 8 minutes)
@pytest.mark.slow
def test_the_atlas_computes_cancels_and_moves_the_main_view_to_a_clicked_start(tabs):
    """Manipulator 2 on the closed path. The first atlas shows its progress and a Cancel
    button; Cancel hides them, the panel says cancelled and the server forgets the job. The
    second (64 starts, 2 cycles) runs to its heatmap: two heatmaps (pseudoinverse, extended)
    with the colour key. A click on a cell of the pseudoinverse's sets x0 to that start (the
    session's state, the x0 boxes) and the main view recomputes from it."""
    tab = tabs.open()
    page = tab.page
    page.locator("#atlas").scroll_into_view_if_needed()
    progress = page.locator("#atlas-progress-box")
    status = page.locator("#atlas-status")

    first = start_atlas(tab, 2048, 2)
    expect(progress).to_be_visible()
    expect(page.locator("#atlas-progress-text")).to_contain_text(re.compile("computing|waiting"))
    expect(page.locator("#atlas-cancel")).to_be_visible()
    page.click("#atlas-cancel")
    expect(progress).to_be_hidden()
    expect(status).to_contain_text("Atlas cancelled")
    poll(lambda: gone(f"{tab.base}/atlas/{first}"), "the cancelled job forgotten (404)")

    job = start_atlas(tab, 64, 2)
    expect(progress).to_be_visible()
    expect(status).to_contain_text("Atlas done", timeout=120_000)
    # every run of both algorithms counts
    expect(status).to_contain_text("128 runs (64 starts x 2 algorithms) of 2 cycles")
    expect(progress).to_be_hidden()
    heatmaps = page.locator("#plot-atlas .heatmaplayer image")
    expect(heatmaps).to_have_count(2)
    expect(page.locator("#plot-atlas .colorbar")).to_have_count(1)
    expect(page.locator("#plot-atlas .panel-head")).to_contain_text("log10 of the drift")
    seen = page.evaluate(probe("overlaps"), "atlas")
    clear = seen["toolbarClearOfTitle"] and seen["toolbarClearOfPlots"]
    assert clear, f"plotly's toolbar {seen['toolbar']} covers the title or plots {seen['plots']}"
    screenshots(page, "atlas")

    atlas = get_json(f"{tab.base}/api/sessions/{tab.session_id}/atlas/{job}")
    starts = np.array(atlas["starts"])[0]  # (N, p): the one path
    assert starts.shape == (64, 3)
    before = tab.snapshot()["state"]["x0"]
    drag = page.locator("#plot-atlas .xy .nsewdrag")
    drag.scroll_into_view_if_needed()
    cell = drag.bounding_box()
    assert cell is not None
    with page.expect_response(lambda r: r.url.endswith("/state")):
        page.mouse.click(cell["x"] + 0.3 * cell["width"], cell["y"] + 0.25 * cell["height"])
    expect(status).to_contain_text("Moved the main view to start")
    i = int(re.search(r"start (\d+) of 64", status.text_content() or "").group(1)) - 1
    moved = tab.wait_settled(
        lambda s: np.allclose(s["state"]["x0"], starts[i], atol=1e-9, rtol=0),
        "the session's x0 at the clicked start",
    )
    assert not np.allclose(moved["state"]["x0"], before, atol=1e-6)
    boxes = [float(page.input_value(f"#ctl-x0-{k}-value")) for k in range(3)]
    np.testing.assert_allclose(boxes, starts[i], atol=6e-4, rtol=0)  # (3 decimals)
    expect(page.locator("#atlas-outdated")).to_be_hidden()  # (same curve: still this atlas)
    screenshots(page, "atlas-moved")


def test_an_atlas_the_state_cannot_have_is_refused_in_words_in_the_panel(tabs):
    """A single target is no closed path: the panel says so where it is, and shows no
    progress."""
    tabs.allow_console("422")  # (chromium logs the refused POST)
    tab = tabs.open(scene=False)
    tab.select("#ctl-task", "target")
    tab.page.click("#atlas-compute")
    status = tab.page.locator("#atlas-status")
    expect(status).to_contain_text(
        "the atlas was refused: task: the atlas drives a closed path; choose the closed-path task"
    )
    expect(status).to_have_class(re.compile("error"))
    expect(tab.page.locator("#atlas-progress-box")).to_be_hidden()


def test_an_empty_or_unreadable_count_is_refused_not_taken_as_the_default(tabs):
    """The starts box emptied, or text in the cycles box that is not a number: the box is
    marked as a refused control is (its note beside it, quoting the text; aria-invalid), the
    panel's status names it, and nothing is sent, instead of an atlas of 256 starts or of the
    controls' cycles the user did not ask for. A count the server refuses is marked at its box
    too."""
    tabs.allow_console(r"status of 422")
    tab = tabs.open(scene=False)
    page = tab.page
    requests = []
    page.on("request", lambda r: r.method == "POST" and "/atlas" in r.url and requests.append(r))
    status = page.locator("#atlas-status")
    starts, cycles = page.locator("#atlas-starts"), page.locator("#atlas-cycles")
    note = {
        box: page.locator("#atlas label", has=page.locator(box)).locator(".field-error")
        for box in ("#atlas-starts", "#atlas-cycles")
    }
    starts.fill("")
    page.click("#atlas-compute")
    expect(status).to_have_text("not sent: starts: give the number of starts")
    expect(status).to_have_class(re.compile("error"))
    expect(note["#atlas-starts"]).to_have_text("give the number of starts; nothing was sent")
    expect(starts).to_have_attribute("aria-invalid", "true")
    starts.fill("8")
    cycles.fill("2e")
    page.click("#atlas-compute")
    expect(status).to_have_text("not sent: cycles: “2e” is not a number")
    expect(note["#atlas-cycles"]).to_have_text("“2e” is not a number; nothing was sent")
    expect(cycles).to_have_attribute("aria-invalid", "true")
    expect(note["#atlas-starts"]).to_have_count(0)
    expect(starts).not_to_have_attribute("aria-invalid", "true")
    expect(page.locator("#atlas-progress-box")).to_be_hidden()
    assert requests == []

    cycles.fill("")
    starts.fill("1")
    with page.expect_response(lambda r: r.request.method == "POST" and "/atlas" in r.url) as sent:
        page.click("#atlas-compute")
    assert sent.value.status == 422
    expect(note["#atlas-starts"]).to_have_text(
        "“1” was refused: starts: Input should be greater than or equal to 2"
    )
    expect(starts).to_have_attribute("aria-invalid", "true")
    expect(note["#atlas-cycles"]).to_have_count(0)
    expect(status).to_contain_text("the atlas was refused: starts:")


# (CI's slow step: among the longest browser checks; the default run stays under 8 minutes)
@pytest.mark.slow
def test_an_atlas_after_a_cancel_starts_at_once(tabs):
    """Cancel an atlas while its workers compute a chunk: the next atlas starts at once (its
    job running within seconds, the panel never saying it waits for another atlas), not after
    the cancelled job's chunks in flight end."""
    tab = tabs.open(scene=False)
    page = tab.page
    page.locator("#atlas").scroll_into_view_if_needed()
    text = page.locator("#atlas-progress-text")
    jobs = f"{tab.base}/api/sessions/{tab.session_id}/atlas"

    first = start_atlas(tab, 4096, 20)
    poll(lambda: get_json(f"{jobs}/{first}")["status"] == "running", "the first atlas running")
    with page.expect_request(lambda r: r.method == "DELETE"):
        page.click("#atlas-cancel")
    poll(lambda: gone(f"{tab.base}/atlas/{first}"), "the cancelled job forgotten (404)")

    second = start_atlas(tab, 4096, 20)
    poll(
        lambda: get_json(f"{jobs}/{second}")["status"] == "running",
        "the next atlas running after a cancel",
        timeout=5,
    )
    expect(text).to_contain_text("computing")
    assert "waiting" not in (text.text_content() or "")
    page.click("#atlas-cancel")
    poll(lambda: gone(f"{tab.base}/atlas/{second}"), "the second job forgotten (404)")


@pytest.mark.slow
def test_the_atlas_panels_csv_downloads_the_table_of_the_atlas_shown(tabs):
    """Its CSV button, off until an atlas is drawn, downloads that atlas's table: the header
    the engine's AtlasResult.columns() of the same request, a row per start, algorithm and
    cycle, the same file as the REST API's table of the job."""
    tab = tabs.open(scene=False)
    page = tab.page
    page.locator("#atlas").scroll_into_view_if_needed()
    button = page.locator("#atlas-csv")
    expect(button).to_be_disabled()
    job = start_atlas(tab, 8, 1)
    expect(page.locator("#atlas-status")).to_contain_text("Atlas done", timeout=120_000)
    expect(button).to_be_enabled()
    with page.expect_download() as saved:
        button.click()
    assert re.fullmatch(rf"jik-manipulator2-atlas-{job}\.csv", saved.value.suggested_filename)
    text = Path(saved.value.path()).read_bytes().decode()
    rows = list(csv.reader(io.StringIO(text)))
    request = get_json(f"{tab.base}/api/sessions/{tab.session_id}/atlas/{job}")["request"]
    plan = planned(AtlasRequest.model_validate(request), AtlasLimits())[0]
    assert rows[0] == list(run_atlas(plan, keep_leg_ends=request["leg_ends"]).columns())
    assert len(rows) - 1 == 8 * len(request["algorithms"])
    with urllib.request.urlopen(f"{tab.base}/atlas/{job}/table.csv", timeout=30) as rest:
        assert rest.read().decode() == text


@pytest.mark.slow
def test_a_click_in_a_scaled_band_keeps_the_atlas_current(tabs):
    """An atlas of two path scales (0.5, 1): a click on a cell of the 0.5 band moves the main
    view to that start with the path scaled by 0.5, a state the atlas holds, so the panel does
    not call it an atlas of an earlier state."""
    tab = tabs.open(scene=False)
    page = tab.page
    page.fill("#atlas-scales", "0.5, 1")
    start_atlas(tab, 8, 1)
    status = page.locator("#atlas-status")
    expect(status).to_contain_text("Atlas done", timeout=120_000)
    # (the runs counted as the plot's title counts the starts: 8 each, on two paths)
    expect(status).to_contain_text("(8 starts x 2 path scales x 2 algorithms)")
    drag = page.locator("#plot-atlas .xy .nsewdrag")
    drag.scroll_into_view_if_needed()
    cell = drag.bounding_box()
    assert cell is not None
    page.mouse.click(cell["x"] + 0.5 * cell["width"], cell["y"] + 0.1 * cell["height"])
    expect(status).to_contain_text("path ×0.5")
    tab.wait_settled(lambda s: s["state"]["path"][0] == [0.5, 1.0], "the path scaled by 0.5")
    expect(page.locator("#atlas-outdated")).to_be_hidden()


@pytest.mark.slow  # (CI's slow step: the default run stays under 8 minutes)
def test_the_atlas_panels_image_buttons_are_off_until_an_atlas_is_drawn(tabs):
    """Before any atlas, its panel has nothing to save: PNG and SVG are off (as CSV is), not
    buttons that do nothing; once an atlas is drawn, PNG saves it."""
    tab = tabs.open(scene=False)
    page = tab.page
    page.locator("#atlas").scroll_into_view_if_needed()
    tools = page.locator("#plot-atlas .panel-tools")
    for name in ("PNG", "SVG", "CSV"):
        expect(tools.get_by_role("button", name=name, exact=True)).to_be_disabled()
    expect(tools.get_by_role("button", name="what this panel shows", exact=False)).to_be_enabled()
    start_atlas(tab, 4, 1)
    expect(page.locator("#atlas-status")).to_contain_text("Atlas done", timeout=120_000)
    for name in ("PNG", "SVG", "CSV"):
        expect(tools.get_by_role("button", name=name, exact=True)).to_be_enabled()
    with page.expect_download() as saved:
        tools.get_by_role("button", name="PNG", exact=True).click()
    assert saved.value.suggested_filename.startswith("jik-manipulator2-atlas-")
    assert saved.value.suggested_filename.endswith(".png")


@pytest.mark.slow  # (CI's slow step: the default run stays under 8 minutes)
def test_a_click_on_a_cell_shows_its_start_in_the_x0_box_typed_in_before(tabs):
    """An x0 coordinate typed and sent with Enter keeps the focus in its box, which a click in
    the heatmap does not take: the box then shows the start clicked, as the session has it,
    not the value typed before."""
    tab = tabs.open(scene=False)
    page = tab.page
    page.locator("#atlas").scroll_into_view_if_needed()
    start_atlas(tab, 16, 1)
    expect(page.locator("#atlas-status")).to_contain_text("Atlas done", timeout=120_000)
    box = page.locator("#ctl-x0-0-value")
    box.fill("0.1")
    tab.change(lambda: box.press("Enter"))
    expect(box).to_be_focused()
    drag = page.locator("#plot-atlas .xy .nsewdrag")
    drag.scroll_into_view_if_needed()
    cell = drag.bounding_box()
    assert cell is not None
    tab.change(
        lambda: page.mouse.click(cell["x"] + 0.7 * cell["width"], cell["y"] + 0.5 * cell["height"])
    )
    x0 = tab.wait_settled(lambda s: s["state"]["x0"][0] != 0.1, "the start clicked")["state"]["x0"]
    assert float(box.input_value()) == pytest.approx(x0[0], abs=6e-4)  # (3 decimals)
