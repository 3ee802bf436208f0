"""The type check of CI: mypy with the [tool.mypy] settings of pyproject.toml passes on every
file of the package, each named as it installs (tests/typecheck.py)."""

import subprocess
import sys
from pathlib import Path

from tests.typecheck import package_dirs, sources

ROOT = Path(__file__).resolve().parents[1]


def test_mypy_checks_every_file_under_its_installed_name() -> None:
    """engine/solver.py is checked as jik.engine.solver: its importers' types are checked
    against it (a folder's own name, engine.solver, would leave jik.engine unresolved)."""
    named = {Path(s.path or ""): s.module for s in sources()}
    assert named[Path("engine/solver.py")] == "jik.engine.solver"
    assert named[Path("app/api/routes/__init__.py")] == "jik.app.api.routes"
    files = {p.relative_to(ROOT) for d in package_dirs().values() for p in d.rglob("*.py")}
    assert set(named) == files


def test_mypy_passes() -> None:
    # The incremental cache (.mypy_cache, gitignored) keeps repeated runs to a few seconds.
    proc = subprocess.run(
        [sys.executable, str(ROOT / "tests" / "typecheck.py")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, f"mypy failed:\n{proc.stdout}{proc.stderr}"
