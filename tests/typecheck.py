"""mypy over the package as it installs: ``python tests/typecheck.py`` (tests/test_types.py).

The package's folders sit at the top of the repository and pyproject.toml's
``[tool.setuptools.package-dir]`` maps them under ``jik`` (``engine/solver.py`` installs as
``jik.engine.solver``). mypy names a file's module by its folders and does not follow setuptools'
editable finder, so given the folders it would check ``engine.solver`` and find no
``jik.engine``. This hands mypy every file under its installed name, read from that table, with
the settings of ``[tool.mypy]``.
"""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

from mypy import build
from mypy.errors import CompileError
from mypy.main import process_options
from mypy.modulefinder import BuildSource

ROOT = Path(__file__).resolve().parents[1]


def package_dirs() -> dict[str, Path]:
    """Package name -> its folder, as pyproject.toml maps them."""
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    mapping = pyproject["tool"]["setuptools"]["package-dir"]
    return {package: ROOT / folder for package, folder in mapping.items()}


def sources() -> list[BuildSource]:
    """Every .py file of the mapped folders, named as the installed package names it."""
    out = []
    for package, folder in package_dirs().items():
        for path in sorted(folder.rglob("*.py")):
            parts = list(path.relative_to(folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            out.append(BuildSource(str(path.relative_to(ROOT)), ".".join([package, *parts])))
    return out


def main() -> int:
    _, options = process_options(
        ["--config-file", str(ROOT / "pyproject.toml")], require_targets=False
    )
    try:
        messages = build.build(sources(), options).errors
    except CompileError as error:
        messages = error.messages
    print("\n".join(messages) or f"mypy: no issues in {len(sources())} files")
    return 1 if messages else 0


if __name__ == "__main__":
    sys.exit(main())
