"""What the shipped code imports is installed by ``pip install .`` alone (no test extras): the
README's first command, then ``jik serve``, ``jik reproduce`` or ``jik bench``."""

import ast
import re
import sys
import tomllib
from importlib import metadata
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
#: The top-level packages that ``pip install .`` ships.
SHIPPED = sorted({p.split(".")[0] for p in PYPROJECT["tool"]["setuptools"]["packages"]})


def _name(requirement: str) -> str:
    match = re.match(r"[A-Za-z0-9._-]+", requirement)
    assert match, requirement
    return re.sub(r"[-_.]+", "-", match[0]).lower()


def _runtime_distributions() -> set[str]:
    """The declared dependencies and, installed here, everything they require (no extras)."""
    todo, seen = [_name(r) for r in PYPROJECT["project"]["dependencies"]], set()
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        try:
            requires = metadata.requires(name) or []
        except metadata.PackageNotFoundError:
            continue
        todo += [_name(r) for r in requires if not re.search(r"extra\s*==", r)]
    return seen


def _third_party_imports() -> dict[str, str]:
    """Top-level modules imported by the shipped packages -> a file that imports it."""
    found: dict[str, str] = {}
    for package in SHIPPED:
        for path in sorted((ROOT / package).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Import):
                    names = [alias.name for alias in node.names]
                elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    names = [node.module]
                else:
                    continue
                for top in {n.split(".")[0] for n in names}:
                    if top not in sys.stdlib_module_names and top not in SHIPPED:
                        found.setdefault(top, str(path.relative_to(ROOT)))
    return found


def test_shipped_code_imports_only_runtime_dependencies():
    runtime = _runtime_distributions()
    providers = metadata.packages_distributions()
    missing = {
        module: where
        for module, where in _third_party_imports().items()
        if not {_name(d) for d in providers.get(module, [module])} & runtime
    }
    assert not missing, (
        f"imported by shipped code but not installed by `pip install .`: {missing}; "
        "add them to [project] dependencies in pyproject.toml"
    )
