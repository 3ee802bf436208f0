"""mkdocs hook: the API reference reads jik's modules from a copy of the package as it installs.

``[tool.setuptools.package-dir]`` installs ``engine/`` as ``jik.engine`` (and ``app/``,
``static/``, ``benchmarks/`` likewise); griffe finds a package's submodules in its folder, so in
the source tree it would find no ``jik/engine``. This lays the mapped folders out under
``build/docs-package/jik/`` (copies, made anew on each build, gitignored) before mkdocstrings
reads them: mkdocs.yml points the Python handler's ``paths`` there.
"""

from __future__ import annotations

import shutil
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TREE = ROOT / "build" / "docs-package"


def lay_out() -> None:
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    shutil.rmtree(TREE, ignore_errors=True)
    for package, folder in sorted(pyproject["tool"]["setuptools"]["package-dir"].items()):
        shutil.copytree(
            ROOT / folder,
            TREE.joinpath(*package.split(".")),
            dirs_exist_ok=True,
            ignore=shutil.ignore_patterns("__pycache__"),
        )


# (at import: mkdocs loads hooks with the configuration, before any plugin reads the paths)
lay_out()
