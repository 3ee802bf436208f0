"""The code base stays ruff-clean (lint and format), as configured in pyproject.toml."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def ruff(*args: str) -> subprocess.CompletedProcess:
    exe = shutil.which("ruff")
    cmd = [exe] if exe else [sys.executable, "-m", "ruff"]
    return subprocess.run([*cmd, *args], cwd=ROOT, capture_output=True, text=True)


@pytest.mark.parametrize("args", [("check", "."), ("format", "--check", ".")], ids=" ".join)
def test_ruff_is_clean(args):
    out = ruff(*args)
    assert out.returncode == 0, out.stdout + out.stderr


#: The folders of the installed package's code (the test harnesses of benchmarks/harness/ and
#: the tests themselves are not its modules).
PACKAGE_FOLDERS = ("engine", "app", "jik", "benchmarks")
#: Above this many lines a module holds more than one job (STYLE.md: split it).
MAX_MODULE_LINES = 400


def test_every_module_is_one_room():
    """No module of the package has more than MAX_MODULE_LINES lines, and none is kept whole by
    a formatter escape: ruff format owns every statement."""
    long, skipped = [], []
    for folder in PACKAGE_FOLDERS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            text = path.read_text(encoding="utf-8")
            name = str(path.relative_to(ROOT))
            if "harness" not in path.parts and text.count("\n") > MAX_MODULE_LINES:
                long.append(f"{name} ({text.count(chr(10))} lines)")
            if "fmt: " + "skip" in text or "fmt: " + "off" in text:
                skipped.append(name)
    assert long == [] and skipped == [], f"over {MAX_MODULE_LINES} lines: {long}; {skipped}"
