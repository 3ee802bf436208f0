"""Settings of the whole suite."""

import os

import pytest

# Starlette's TestClient sends "Host: testserver": a name the server answers to only in tests
# (jik.app.api.security allows the loopback names and JIK_ALLOWED_HOSTS).
os.environ["JIK_ALLOWED_HOSTS"] = ",".join(
    filter(None, [os.environ.get("JIK_ALLOWED_HOSTS", ""), "testserver"])
)


def pytest_collection_modifyitems(items):
    """Under pytest-xdist (``-n``), the browser tests run in one worker, one after another: they
    share one server and one chromium (``tests/browser/conftest.py``), as in a serial run."""
    for item in items:
        if item.get_closest_marker("browser"):
            item.add_marker(pytest.mark.xdist_group("browser"))
