"""`jik serve` whose dashboards fail to compute any state with gamma = 2.5 (a JikError, as a
singular start raises): the browser tests of what the page shows after a failure. Test code
only: the product has no such hook.

Usage: python tests/browser/failing_serve.py PORT
"""

from __future__ import annotations

import sys

import jik.app.dashboard.session as session
from jik.cli import main
from jik.engine.exceptions import JikError

FAILING_GAMMA = 2.5
MESSAGE = "the start configuration is singular (injected by the test server)"
real = session.compute


def failing(state, *args, **kwargs):
    if state.gamma == FAILING_GAMMA:
        raise JikError(MESSAGE)
    return real(state, *args, **kwargs)


session.compute = failing  # type: ignore[assignment]

if __name__ == "__main__":
    raise SystemExit(main(["serve", "--port", sys.argv[1]]))
