"""The API's documentation works offline: Swagger UI at /docs renders from the
server's own files, and no request leaves 127.0.0.1."""

from __future__ import annotations

import pytest

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


def test_swagger_ui_renders_offline(tabs):
    """/docs shows Swagger UI with the API's title and its operations, all from 127.0.0.1."""
    page = tabs.new_page(tabs.context())
    page.goto(f"{tabs.base}/docs")
    expect(page.locator(".swagger-ui .info .title")).to_contain_text("jik")
    expect(page.locator(".opblock-summary-path", has_text="/solve").first).to_be_visible()
    page.wait_for_load_state("networkidle")
    tabs.check()


def test_redoc_is_not_served(tabs):
    """ReDoc's bundle draws its side menu's logo from cdn.redoc.ly whatever its options, so the
    server does not offer /redoc: /docs is the API's documentation."""
    tabs.allow_console(r"^Failed to load resource: .* status of 404")  # (this page's own)
    page = tabs.new_page(tabs.context())
    response = page.goto(f"{tabs.base}/redoc")
    assert response is not None and response.status == 404
    tabs.check()
