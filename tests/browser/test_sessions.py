"""Sessions in the browser: every tab has its own state, and a copied link opens a new
session with the same state and the same numbers."""

from __future__ import annotations

import re

import pytest

from tests.browser.conftest import SCENE_FRAME, Tab, probe

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser

#: A number the verdict writes with an exponent: a drift at rounding level, which two runs of
#: the same state need not reproduce digit for digit.
TINY = re.compile(r"-?\d\.\d+e-\d+")


def seen(tab) -> dict:
    """What a tab shows of its state, and its session on the server."""
    snapshot = tab.snapshot()
    return {
        "url": tab.url_state(),
        "controls": tab.controls(),
        "robot": tab.robot,
        "generation": tab.generation,
        "status": tab.status(),
        "session": {k: snapshot[k] for k in ("generation", "state", "summary")},
        "scene": {k: snapshot["scene"].get(k) for k in ("generation", "robot")},
    }


# (CI's slow step: among the longest browser checks; the default run stays under 8 minutes)
@pytest.mark.slow
def test_changes_in_one_tab_leave_another_as_it_was(tabs):
    """A robot switch, a new gamma and a drag of the start point in tab A's scene change nothing
    in tab B (its URL, controls, plots, session); a tab opened afterwards has the defaults."""
    a, b = tabs.open(), tabs.open()
    assert a.session_id != b.session_id
    b.wait_scene_drawn(1)
    before = seen(b)
    defaults = before["session"]["state"]
    assert before["url"] == defaults and before["robot"] == "manipulator2"

    generation = a.select("#ctl-robot", "manipulator1")
    assert a.robot == "manipulator1" and a.snapshot()["state"]["robot"] == "manipulator1"
    assert seen(b) == before

    generation = a.set_slider("#ctl-gamma", 0.30103)  # log10(2), snapped to the slider's step
    gamma = a.snapshot()["state"]["gamma"]
    assert gamma == pytest.approx(2.0, rel=0.02) and a.url_state()["gamma"] == gamma
    assert seen(b) == before

    a.wait_scene_drawn(generation)
    assert seen(b) == before
    x0 = a.snapshot()["state"]["x0"]
    a.drag_start_point()
    a.wait_settled(lambda s: s["state"]["x0"] != x0, "A's start point dragged, drawn")
    assert seen(b) == before

    c = tabs.open()
    assert c.session_id not in (a.session_id, b.session_id)
    assert c.snapshot()["state"] == defaults
    assert c.url_state() == defaults
    assert c.controls() == before["controls"]
    assert c.robot == "manipulator2"


# (CI's slow step: among the longest browser checks; the default run stays under 8 minutes)
@pytest.mark.slow
def test_a_copied_link_opens_the_same_view(tabs):
    """The link that #copy-link puts on the clipboard opens, in a fresh browser, a new session
    with the same state, the same controls and the same numbers."""
    a = tabs.open(permissions=["clipboard-read", "clipboard-write"], scene=False)
    a.set_slider("#ctl-x0-0", 0.45)
    a.set_slider("#ctl-cycles", 4)
    a.page.click("#copy-link")
    expect(a.page.locator("#copy-link")).to_have_text("link copied")
    link = a.page.evaluate("navigator.clipboard.readText()")
    assert link == a.page.url

    d = tabs.open(link, scene=False)
    assert d.session_id != a.session_id
    state = a.snapshot()["state"]
    assert state["cycles"] == 4 and state["x0"][0] == pytest.approx(0.45, abs=1e-12)
    assert d.snapshot()["state"] == state
    assert d.url_state() == a.url_state() == state
    assert d.controls() == a.controls()
    # The same verdict, up to the rounding-level drift of the extended Jacobian.
    verdicts = [TINY.sub("~0", t.page.inner_text("#verdict")) for t in (a, d)]
    assert verdicts[0] == verdicts[1] and "After 4 cycles" in verdicts[0]
    ours, theirs = a.snapshot()["summary"], d.snapshot()["summary"]
    for algorithm in ("pseudoinverse", "extended"):
        drift = ours[algorithm]["drift"]
        assert len(drift) == 4
        assert theirs[algorithm]["drift"] == pytest.approx(drift, rel=1e-9, abs=1e-12)
        assert theirs[algorithm]["x_final"] == pytest.approx(
            ours[algorithm]["x_final"], rel=1e-9, abs=1e-12
        )
    # A change after the copy: the link copied is of the state before, the button says so no more.
    a.set_slider("#ctl-cycles", 3)
    expect(a.page.locator("#copy-link")).to_have_text("copy link")


# (CI's slow step: among the longest browser checks; the default run stays under 8 minutes)
@pytest.mark.slow
def test_a_tab_whose_session_ended_opens_a_new_one_with_its_state(tabs):
    """The server ends a session (expired, or the server restarted): its page notices that the
    session is gone and opens a new one from the state in its link, with the same numbers."""
    import urllib.request

    # (chromium logs the 404 by which the page learns that its session is gone)
    tabs.allow_console(r"^Failed to load resource: .* status of 404")
    tab = tabs.open()
    tab.wait_drawn(1)
    tab.select("#ctl-robot", "manipulator1")
    old, before = tab.session_id, tab.url_state()
    request = urllib.request.Request(f"{tab.base}/api/sessions/{old}", method="DELETE")
    urllib.request.urlopen(request, timeout=30).close()
    tab.page.wait_for_function(
        "old => !document.getElementById('scene').src.includes(old)", arg=old, timeout=60_000
    )
    tab.wait_drawn(1)
    assert tab.session_id != old and tab.robot == "manipulator1"
    assert tab.url_state() == before and tab.snapshot()["state"] == before


@pytest.mark.slow
@pytest.mark.parametrize("text", ["[1, 2]", "null"])
def test_a_link_whose_state_is_not_an_object_says_so(tabs, text):
    """A link's ?state= that is JSON but not an object of the state's fields opens the
    defaults and says why beside the status, as a link that is not JSON does."""
    tab = tabs.open(f"/?state={text}", scene=False)
    expect(tab.page.locator("#notice")).to_have_text(
        f"the link's state is not an object of the state's fields ({text}); showing the defaults"
    )
    assert tab.snapshot()["state"]["robot"] == "manipulator2"


@pytest.mark.slow
@pytest.mark.parametrize("z", ["abc"])
def test_a_link_whose_deflated_state_is_damaged_says_so(tabs, z):
    """A ?z= link cut short or changed opens the defaults and says that the link is damaged, in
    the page's words, not the browser's ("Failed to fetch" read as a network error)."""
    tab = tabs.open(f"/?z={z}", scene=False)
    expect(tab.page.locator("#notice")).to_have_text(
        "the link's state is damaged: it does not inflate (a link cut short or changed); "
        "showing the defaults"
    )
    assert tab.snapshot()["state"]["robot"] == "manipulator2"


@pytest.mark.slow
def test_seven_tabs_of_one_browser_each_draw_when_hidden_tabs_let_go(tabs):
    """A browser keeps six connections to one server, and each tab's event stream holds one: a
    seventh dashboard tab of one browser stayed at "connecting…" while six were open. A hidden
    tab lets go of its stream; shown again, it follows its session again and draws its next
    change."""
    context = tabs.context()
    context.route(SCENE_FRAME, lambda route: route.abort())  # (the page's own connections)
    opened = []
    for _ in range(6):
        page = tabs.new_page(context)
        page.goto(tabs.base + "/")
        # (the page follows its session right after it sets the scene's address)
        page.wait_for_function("() => document.getElementById('scene').getAttribute('src')")
        page.evaluate(probe("set_hidden"), True)  # (the next tab opens in front of it)
        opened.append(Tab(page, tabs.base, scene=False))
    seventh = Tab(tabs.new_page(context), tabs.base, scene=False)
    seventh.page.goto(tabs.base + "/")
    seventh.wait_drawn(1)
    first = opened[0]
    first.page.evaluate(probe("set_hidden"), False)
    first.select("#ctl-robot", "manipulator1")
    assert first.robot == "manipulator1"
    assert all(t.snapshot()["state"]["robot"] == "manipulator2" for t in [*opened[1:], seventh])


@pytest.mark.slow
def test_a_tab_the_full_server_refused_opens_when_a_session_is_free(tabs):
    """Every session of the server in use (503, Retry-After: its first answers are made so
    here): the header says so and when it asks again, and the tab opens when one is free."""
    tabs.allow_console(r"status of 503")
    full = {"detail": "the server has 32 dashboard sessions in use, its limit (JIK_MAX_SESSIONS)"}
    refused: list = []

    def answer(route) -> None:
        if route.request.method != "POST" or len(refused) == 2:
            route.continue_()
            return
        refused.append(route.request.url)
        route.fulfill(status=503, headers={"Retry-After": "1"}, json=full)

    context = tabs.context()
    context.route(re.compile(r"/api/sessions$"), answer)
    page = tabs.new_page(context)
    page.goto(tabs.base + "/")
    expect(page.locator("#status-text")).to_have_text(f"{full['detail']}; trying again every 1 s…")
    tab = Tab(page, tabs.base)
    tab.wait_drawn(1)
    assert len(refused) == 2 and tab.status().startswith("up to date")
    assert tab.snapshot()["state"] == tab.url_state()


@pytest.mark.slow
def test_back_while_a_change_is_posted_keeps_the_entry_ahead(tabs):
    """Back pressed while a change is still being posted (its POST held here until then): the
    session, address and controls come back to the entry's state, and forward still brings the
    entry that was ahead (the change's state, answered after the back, took its place)."""
    tab = tabs.open(scene=False)
    page = tab.page
    first = (tab.url_state(), tab.controls())
    tab.select("#ctl-robot", "manipulator1")
    ahead = (tab.url_state(), tab.controls())
    length = page.evaluate("history.length")
    held: list = []  # (the first POST of a change is held; the next ones go)
    posts = re.compile(r"/api/sessions/[^/]+/state$")
    page.route(posts, lambda route: route.continue_() if held else held.append(route))
    with page.expect_request(lambda r: r.method == "POST" and posts.search(r.url)):
        page.select_option("#ctl-mode", "discrete")
    page.go_back()
    tab.change(held[0].continue_)  # (the back's own POST follows the held one)
    tab.wait_settled(lambda s: s["state"] == first[0], "the state before, after the change")
    assert (tab.url_state(), tab.controls()) == first
    assert page.evaluate("history.length") == length  # (no entry made, none dropped)
    tab.change(page.go_forward)
    tab.wait_settled(lambda s: s["state"] == ahead[0], "the entry ahead")
    assert (tab.url_state(), tab.controls()) == ahead


@pytest.mark.slow
def test_back_while_a_refused_change_is_posted_keeps_the_entry_ahead(tabs):
    """Back pressed while a change the session refuses is being posted (its POST held here until
    then): the refusal's state, the one in force before the back, makes no entry either, and
    forward still brings the entry that was ahead."""
    tabs.allow_console(r"status of 422")
    tab = tabs.open(scene=False)
    page = tab.page
    first = tab.url_state()
    tab.select("#ctl-robot", "manipulator1")
    ahead = tab.url_state()
    length = page.evaluate("history.length")
    held: list = []  # (the first POST of a change is held; the next ones go)
    posts = re.compile(r"/api/sessions/[^/]+/state$")
    page.route(posts, lambda route: route.continue_() if held else held.append(route))
    cycles = page.locator("#ctl-cycles-value")
    with page.expect_request(lambda r: r.method == "POST" and posts.search(r.url)):
        cycles.fill("50")
        cycles.press("Enter")
    page.go_back()
    with page.expect_response(lambda r: bool(posts.search(r.url)) and r.status == 422):
        held[0].continue_()
    tab.wait_settled(lambda s: s["state"] == first, "the state before, after the refusal")
    assert page.evaluate("history.length") == length  # (no entry made, none dropped)
    tab.change(page.go_forward)
    tab.wait_settled(lambda s: s["state"] == ahead, "the entry ahead")
    assert tab.url_state() == ahead


@pytest.mark.slow
def test_back_and_forward_bring_the_previous_states_back(tabs):
    """Each change is an entry of the tab's history: back brings the session, controls and
    verdict of the state before, forward the one after, and a slider's drag is one entry."""
    tab = tabs.open(scene=False)
    page = tab.page
    seen = [(tab.url_state(), tab.controls())]
    tab.select("#ctl-robot", "manipulator1")
    seen.append((tab.url_state(), tab.controls()))
    length = page.evaluate("history.length")
    for position in (0.3, 0.5):  # (one drag, two steps)
        tab.set_slider("#ctl-x0-0", position)
    seen.append((tab.url_state(), tab.controls()))
    assert page.evaluate("history.length") == length + 1

    def travel(go) -> None:
        tab.change(go)
        tab.wait_settled(lambda s: True, "the state of the history's entry")

    for before in (seen[1], seen[0]):
        travel(page.go_back)
        assert (tab.url_state(), tab.controls()) == before
        assert tab.snapshot()["state"] == before[0]
    travel(page.go_forward)
    travel(page.go_forward)
    assert (tab.url_state(), tab.controls()) == seen[2]
    assert tab.snapshot()["state"]["robot"] == "manipulator1"


@pytest.mark.slow  # (CI's slow step: the default run stays under 8 minutes)
def test_back_after_a_typed_value_shows_the_entry_s_value_in_its_box(tabs):
    """A value typed in a box and sent with Enter keeps the focus there; back then brings the
    state before, and that box and its slider show the entry's value, not the typed one."""
    tab = tabs.open(scene=False)
    page = tab.page
    before = (tab.url_state(), tab.controls())
    box = page.locator("#ctl-gamma-value")
    box.fill("0.5")
    tab.change(lambda: box.press("Enter"))
    expect(box).to_be_focused()
    tab.change(page.go_back)
    tab.wait_settled(lambda s: s["state"] == before[0], "the state before the typed value")
    expect(box).to_be_focused()
    assert tab.controls() == before[1]
