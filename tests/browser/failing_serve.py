"""`jik serve` whose dashboards fail to compute any state with gamma = 2.5 (a JikError, as a
singular start raises) and compute gamma = 2.25 SLOW_SECONDS late: the browser tests of what
the page shows after a failure or while a result is on its way. Test code only: the product
has no such hook.

Usage: python tests/browser/failing_serve.py PORT
"""

from __future__ import annotations

import sys
import time

import jik.app.dashboard.session as session
from jik.cli import main
from jik.engine.exceptions import JikError

FAILING_GAMMA = 2.5
SLOW_GAMMA, SLOW_SECONDS = 2.25, 4.0
MESSAGE = "the start configuration is singular (injected by the test server)"


def serve_failing(port: str) -> int:
    """`jik serve --port PORT` with the dashboards' compute failing at gamma = 2.5 and slow at
    2.25 (patched in this process only: importing this module, as the tests do for MESSAGE,
    patches nothing)."""
    real = session.compute

    def failing(state, *args, **kwargs):
        if state.gamma == FAILING_GAMMA:
            raise JikError(MESSAGE)
        if state.gamma == SLOW_GAMMA:
            time.sleep(SLOW_SECONDS)
        return real(state, *args, **kwargs)

    session.compute = failing  # type: ignore[assignment]
    return main(["serve", "--port", port])


if __name__ == "__main__":
    raise SystemExit(serve_failing(sys.argv[1]))
