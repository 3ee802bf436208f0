"""What the shipped code imports is installed by its own install line: the engine (and the ``jik``
command's root package) by ``pip install jik`` alone, the web parts and benchmarks by
``pip install 'jik[app]'``."""

import ast
import re
import sys
import tomllib
from importlib import metadata
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
#: Source folder -> the extra its imports may come from (None: the plain install).
EXTRA_OF = {"jik": None, "engine": None, "app": "app", "static": "app", "benchmarks": "app"}


def _name(requirement: str) -> str:
    match = re.match(r"[A-Za-z0-9._-]+", requirement)
    assert match, requirement
    return re.sub(r"[-_.]+", "-", match[0]).lower()


def _linked_folders() -> set[str]:
    """``jik`` and the top-level folders that jik/ links in as its subpackages."""
    links = {p for p in (ROOT / "jik").iterdir() if p.is_symlink()}
    for link in links:
        assert link.resolve() == ROOT / link.name, f"jik/{link.name} must link to ../{link.name}"
    return {"jik", *(link.name for link in links)}


def _declared(extra: str | None) -> list[str]:
    requirements = list(PYPROJECT["project"]["dependencies"])
    if extra:
        requirements += PYPROJECT["project"]["optional-dependencies"][extra]
    return [r for r in requirements if not r.startswith("jik")]


def _runtime_distributions(extra: str | None) -> set[str]:
    """The declared dependencies and, installed here, everything they require (no extras)."""
    todo, seen = [_name(r) for r in _declared(extra)], set()
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


def _optional(tree: ast.AST) -> set[ast.AST]:
    """The import statements inside ``try: ... except ImportError``: optional dependencies,
    whose absence the code handles."""
    out: set[ast.AST] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Try) and any(
            isinstance(h.type, ast.Name) and h.type.id in ("ImportError", "ModuleNotFoundError")
            for h in node.handlers
        ):
            out.update(n for stmt in node.body for n in ast.walk(stmt))
    return out


def _third_party_imports(folder: str) -> dict[str, str]:
    """Top-level modules imported by the code in ``folder`` -> a file that imports it (not the
    optional ones, see :func:`_optional`)."""
    found: dict[str, str] = {}
    for path in sorted((ROOT / folder).rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        optional = _optional(tree)
        for node in ast.walk(tree):
            if node in optional:
                continue
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for top in {n.split(".")[0] for n in names}:
                if top not in sys.stdlib_module_names and top != "jik":
                    found.setdefault(top, str(path.relative_to(ROOT)))
    return found


def test_every_installed_folder_has_a_declared_extra():
    assert _linked_folders() == set(EXTRA_OF)


def test_packages_are_discovered_not_listed():
    """setuptools finds jik and every subpackage: a new one cannot be left out of the wheel."""
    setuptools = PYPROJECT["tool"]["setuptools"]
    assert setuptools["packages"]["find"]["include"] == ["jik", "jik.*"]


@pytest.mark.parametrize("folder", sorted(EXTRA_OF))
def test_shipped_code_imports_only_its_install_lines_dependencies(folder):
    extra = EXTRA_OF[folder]
    runtime = _runtime_distributions(extra)
    providers = metadata.packages_distributions()
    missing = {
        module: where
        for module, where in _third_party_imports(folder).items()
        if not {_name(d) for d in providers.get(module, [module])} & runtime
    }
    line = "pip install jik" + (f"[{extra}]" if extra else "")
    assert not missing, (
        f"imported by {folder}/ but not installed by `{line}`: {missing}; "
        "declare them in pyproject.toml (or move the import to the web parts)"
    )
