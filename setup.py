"""jik's packages, found at build time: every package under the folders that pyproject.toml's
``[tool.setuptools.package-dir]`` maps (``engine/`` installs as ``jik.engine``, its
``engine/arm_data/`` as ``jik.engine.arm_data``), so that no subpackage can be left out of the
wheel. setuptools' own discovery (``packages.find``) names a package after its folder and cannot
put it under ``jik``. ``benchmarks/harness/`` (the harnesses that drive a server with the test
tools) runs from a source checkout and stays out of the wheel."""

import tomllib
from pathlib import Path

from setuptools import find_packages, setup

ROOT = Path(__file__).resolve().parent
#: Packages under the mapped folders that the wheel leaves out.
UNSHIPPED = ("harness", "harness.*")


def packages() -> list[str]:
    """Each mapped package and every package found in its folder, by its installed name."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    found = []
    for package, folder in config["tool"]["setuptools"]["package-dir"].items():
        subpackages = find_packages(str(ROOT / folder), exclude=UNSHIPPED)
        found += [package, *(f"{package}.{sub}" for sub in subpackages)]
    return sorted(found)


if __name__ == "__main__":
    setup(packages=packages())
