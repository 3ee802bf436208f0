"""Table 1 on the page: the paper's printed columns beside jik's, differences marked, the
erratum in words, the paper's row labels; a plainly named table off the paper's experiment, and
a note when discrete mode changes the numbers."""

from __future__ import annotations

import pytest

from tests.browser.conftest import probe

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
# A display check: in CI's slow step, to keep the default run under 8 minutes.
pytestmark = [pytest.mark.browser, pytest.mark.slow]


def test_table1_beside_the_printed_values(tabs):
    tab = tabs.open()
    table = tab.page.locator("#plot-table")
    expect(table.locator(".table-title")).to_contain_text("Table 1 of the paper")
    headers = table.locator("thead th").all_text_contents()
    assert headers[1:7] == [f"J^P# x{k} (jik)" for k in (1, 2, 3)] + [
        f"J^P# x{k} (printed)" for k in (1, 2, 3)
    ]
    labels = table.locator("tbody tr td:first-child").all_text_contents()
    assert labels[:5] == ["A  x0", "B  x1f", "C  x2f", "D  x3f", "A  x4f"]
    # The pseudoinverse is reproduced; the extended column differs in its first two legs.
    first = table.locator("tbody tr").nth(1).locator("td").all_text_contents()
    assert first[1:4] == first[4:7] == ["0.1132", "0.5379", "1.0904"]
    marked = table.locator("td.differs")
    expect(marked).to_have_count(6)
    assert marked.first.get_attribute("title") == "printed: 0.1208"
    expect(table.locator(".table-note").nth(0)).to_contain_text("pseudoinverse: 0 of 15")
    expect(table).to_contain_text("Erratum")
    expect(table).to_contain_text("the printed j32, j33 of (39) are not the gradient of (38)")
    expect(table).to_contain_text("Row labels as printed: A, B, C, D, A")
    # The note's mention of the errata's file opens the errata page beside the dashboard.
    link = table.locator(".table-note a.errata-link")
    expect(link).to_have_text("docs/paper-errata.md")
    with tab.page.context.expect_page() as opened:
        link.click()
    expect(opened.value.locator("h1")).to_have_text("Paper errata")
    opened.value.close()
    table.scroll_into_view_if_needed()
    tab.screenshots("table1")

    tab.select("#ctl-mode", "discrete")
    expect(table).to_contain_text("Discrete mode changes the numbers")
    expect(table.locator(".table-note").nth(0)).to_contain_text("pseudoinverse: 12 of 15")

    tab.change(lambda: tab.page.select_option("#ctl-robot", "manipulator1"))
    expect(table.locator(".table-title")).to_have_text(
        "Joint configuration at the end of each leg (not the paper's Table 1)"
    )
    assert "printed" not in " ".join(table.locator("thead th").all_text_contents())


def test_the_corner_letters_are_table_1s(tabs):
    """The task panel letters the closed path's corners as Table 1 labels its rows: A = k(x0)
    = (0, 1), then B = (1, 1), C = (1, 2), D = (0, 2); the leg-end table of another robot uses
    the task panel's letters."""
    tab = tabs.open(scene=False)
    targets = tab.page.locator("#plot-task .scatterlayer .textpoint text")
    expect(targets).to_have_count(4)
    task = tab.page.evaluate(probe("target_letters"), "plot-task")
    assert tab.snapshot()["state"]["path"] == [[1, 1], [1, 2], [0, 2], [0, 1]]
    assert task == ["B", "C", "D", "A"]
    tab.change(lambda: tab.page.select_option("#ctl-robot", "manipulator1"))
    task = tab.page.evaluate(probe("target_letters"), "plot-task")
    rows = tab.page.locator("#plot-table tbody tr td:first-child").all_text_contents()
    legs = [r.removeprefix("cycle 1, leg to ").split(" ")[0] for r in rows[1 : 1 + len(task)]]
    assert legs == task
