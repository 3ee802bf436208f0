"""Settings of the whole suite."""

import os

# Starlette's TestClient sends "Host: testserver": a name the server answers to only in tests
# (jik.app.api.security allows the loopback names and JIK_ALLOWED_HOSTS).
os.environ["JIK_ALLOWED_HOSTS"] = ",".join(
    filter(None, [os.environ.get("JIK_ALLOWED_HOSTS", ""), "testserver"])
)
