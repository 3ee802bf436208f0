"""The type check of CI: mypy with the [tool.mypy] settings of pyproject.toml passes."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_mypy_passes() -> None:
    # Files, excludes and flags come from pyproject.toml; the incremental cache (.mypy_cache,
    # gitignored) keeps repeated runs to a few seconds.
    proc = subprocess.run(
        [sys.executable, "-m", "mypy"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, f"mypy failed:\n{proc.stdout}{proc.stderr}"
