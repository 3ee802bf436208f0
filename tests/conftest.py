"""Settings of the whole suite."""

import os
import zlib

import numpy as np
import pytest

# Starlette's TestClient sends "Host: testserver": a name the server answers to only in tests
# (jik.app.api.security allows the loopback names and JIK_ALLOWED_HOSTS).
os.environ["JIK_ALLOWED_HOSTS"] = ",".join(
    filter(None, [os.environ.get("JIK_ALLOWED_HOSTS", ""), "testserver"])
)


def pytest_collection_modifyitems(items):
    """Under pytest-xdist (``-n``), the default run's browser tests run in one worker, one after
    another: they share one server and one chromium (``tests/browser/conftest.py``), and the
    other workers share the rest of the suite. The slow browser tests spread over the workers
    (each then starts its own server and chromium): beside them the slow step has only a few
    long tests (the random search, the wheel's installs), which left the other worker idle
    while one ran every browser test."""
    for item in items:
        if item.get_closest_marker("browser") and not item.get_closest_marker("slow"):
            item.add_marker(pytest.mark.xdist_group("browser"))


@pytest.fixture(autouse=True)
def _module_rng_per_test(request):
    """A module's seeded ``RNG`` starts anew for each test, from the module's seed and the
    test's name: a test draws the same numbers whichever of the module's tests ran before it
    in its process (pytest-xdist spreads a module's tests over workers differently each run)."""
    module = request.module
    rng = getattr(module, "RNG", None)
    if isinstance(rng, np.random.Generator):
        seed = module.__dict__.setdefault("_RNG_SEED", rng.bit_generator.seed_seq.entropy)
        module.RNG = np.random.default_rng([seed, zlib.crc32(request.node.name.encode())])
    yield
