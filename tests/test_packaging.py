"""The package's layout and its install lines: setuptools maps each top-level folder under
``jik`` with no symlink, lists every subpackage, and what the shipped code imports is installed
by its own install line: the engine (and the ``jik`` command's root package) by the plain
install, the web parts and benchmarks by the ``app`` extra, the harnesses (not shipped) by the
``test`` extra."""

import ast
import importlib.util
import re
import subprocess
import sys
import tomllib
from importlib import metadata
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
SETUPTOOLS = PYPROJECT["tool"]["setuptools"]
#: Source folder -> the extra its imports may come from (None: the plain install).
EXTRA_OF = {
    "jik": None,
    "cli": None,
    "docs": None,
    "engine": None,
    "app": "app",
    "static": "app",
    "benchmarks": "app",
    "benchmarks/harness": "test",
}
#: Folders of a mapped package that the wheel leaves out (run from a source checkout).
UNSHIPPED = {"benchmarks/harness"}


def _name(requirement: str) -> str:
    match = re.match(r"[A-Za-z0-9._-]+", requirement)
    assert match, requirement
    return re.sub(r"[-_.]+", "-", match[0]).lower()


def _packages_on_disk() -> set[str]:
    """Every folder with an __init__.py under the folders that package-dir maps, by the name it
    installs as, except the unshipped ones."""
    found = set()
    for package, folder in SETUPTOOLS["package-dir"].items():
        for init in (ROOT / folder).rglob("__init__.py"):
            where = init.parent.relative_to(ROOT)
            if any(where.is_relative_to(u) for u in UNSHIPPED):
                continue
            parts = init.parent.relative_to(ROOT / folder).parts
            found.add(".".join([package, *parts]))
    return found


def _declared(extra: str | None) -> list[str]:
    """The requirements of the plain install and of ``extra``, the project's own extras (a
    requirement on itself, ``NAME[app]``) expanded."""
    project = PYPROJECT["project"]
    requirements = list(project["dependencies"])
    extras = [extra] if extra else []
    while extras:
        for requirement in project["optional-dependencies"][extras.pop()]:
            own = re.fullmatch(rf"{re.escape(project['name'])}\[([\w,-]+)\]", requirement)
            if own:
                extras += own[1].split(",")
            else:
                requirements.append(requirement)
    return requirements


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
    nested = [ROOT / other for other in EXTRA_OF if other != folder and other.startswith(folder)]
    for path in sorted((ROOT / folder).rglob("*.py")):
        if any(path.is_relative_to(n) for n in nested):
            continue  # (counted with its own folder's extra)
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
    assert set(SETUPTOOLS["package-dir"].values()) | UNSHIPPED == set(EXTRA_OF)


def test_every_package_folder_is_in_the_wheel():
    """The packages setup.py finds are every folder with an __init__.py under engine/, app/,
    static/ and benchmarks/ (benchmarks/harness/ aside), by its installed name."""
    spec = importlib.util.spec_from_file_location("jik_setup", ROOT / "setup.py")
    assert spec is not None and spec.loader is not None
    setup_py = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(setup_py)  # (not __main__: setup() is not called)
    assert set(setup_py.packages()) == _packages_on_disk()
    assert "jik.engine.arm_data" in setup_py.packages()


def test_a_checkout_imports_from_its_root_without_an_install():
    """A notebook started at the checkout's root (this jik/ first on sys.path, no editable
    install's finder): jik.engine and jik.app are the checkout's engine/ and app/."""
    code = (
        "import sys; sys.meta_path[:] = [f for f in sys.meta_path if 'editable' not in "
        "getattr(f, '__module__', '') + getattr(f, '__name__', '')]; "
        "import jik.engine, jik.app.compute.schemas; print(jik.engine.__file__)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert Path(out.stdout.strip()) == ROOT / "engine" / "__init__.py"


def test_the_source_tree_holds_no_symlinks():
    """A checkout without symlinks (Windows' default, core.symlinks=false) writes a link as a
    small text file: the package must not depend on one."""
    try:
        listed = subprocess.run(
            ["git", "ls-files", "-s"], cwd=ROOT, capture_output=True, text=True, check=True
        ).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    links = [line.split("\t")[1] for line in listed.splitlines() if line.startswith("120000")]
    assert not links, f"tracked symlinks: {links}"


def _jik_imports(path: Path) -> list[ast.ImportFrom | ast.Import]:
    """The imports in ``path`` of jik's own modules: relative ones, and absolute ``jik...``."""
    found: list[ast.ImportFrom | ast.Import] = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and (
            node.level or (node.module or "").split(".")[0] == "jik"
        ):
            found.append(node)
        elif isinstance(node, ast.Import) and any(
            a.name.split(".")[0] == "jik" for a in node.names
        ):
            found.append(node)
    return found


@pytest.mark.parametrize("folder", sorted(set(SETUPTOOLS["package-dir"].values()) - {"jik"}))
def test_imports_between_the_mapped_folders_resolve_in_the_source_tree(folder):
    """A tool that reads imports from the files (an editor, pyright, jedi) finds every module:
    the mapped folders import jik's packages relatively (``from ..engine.solver import solve``
    in app/api/, whose ``..`` is the tree's root, where engine/ sits), and each relative import
    names a module or package that exists in the tree. Only the root package ``jik`` (its
    ``__version__``) is imported by its absolute name, which the tree's jik/ folder holds."""
    problems = []
    for path in sorted((ROOT / folder).rglob("*.py")):
        where = f"{path.relative_to(ROOT)}"
        for node in _jik_imports(path):
            if isinstance(node, ast.Import) or not node.level:
                names = [node.module] if isinstance(node, ast.ImportFrom) else []
                names += [a.name for a in getattr(node, "names", [])]
                if any(n and n.startswith("jik.") for n in names):
                    problems.append(f"{where}:{node.lineno} absolute import of a jik subpackage")
                continue
            base = path.parent
            for _ in range(node.level - 1):
                base = base.parent
            target = base.joinpath(*(node.module or "").split(".")) if node.module else base
            # (``from . import name``: a module, or a name the package's __init__ defines)
            modules = [target] if node.module else [target / a.name for a in node.names]
            for module in modules:
                found = module.with_suffix(".py").is_file() or (module / "__init__.py").is_file()
                if not found and not (node.module is None and (target / "__init__.py").is_file()):
                    problems.append(f"{where}:{node.lineno} {module} is not in the tree")
    assert problems == []


def test_the_root_package_imports_none_of_its_mapped_subpackages():
    """jik/ holds the root package only (its version, the install hint): a static tool looks
    for ``jik.engine`` in jik/ and would not find it, so no module there imports one; the
    ``jik`` command's code is cli/ (``jik.cli``), which imports the others relatively. The one
    exception is ``python -m jik``, whose jik/__main__.py must name ``jik.cli``."""
    found = [
        f"{path.name}:{node.lineno}"
        for path in sorted((ROOT / "jik").glob("*.py"))
        for node in _jik_imports(path)
        if node.level
        or any(
            n.startswith("jik.")
            for n in [getattr(node, "module", None) or "", *(a.name for a in node.names)]
        )
    ]
    assert found == ["__main__.py:3"]


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
    line = f"pip install {PYPROJECT['project']['name']}" + (f"[{extra}]" if extra else "")
    assert not missing, (
        f"imported by {folder}/ but not installed by `{line}`: {missing}; "
        "declare them in pyproject.toml (or move the import to the web parts)"
    )


#: An install command in a message or a document: ``pip install [-e] 'NAME[extra]'`` or
#: ``".[extra]"``.
INSTALL_HINT = re.compile(r"""pip install (?:-\w+ )*['"]?([\w.-]+)\[([\w,-]+)\]""")


def test_every_install_hint_names_this_distribution_and_its_extras():
    """A hint that names another distribution installs another project: ``jik`` on the package
    index is not this one."""
    project = PYPROJECT["project"]
    assert project["name"] != "jik", "jik on the package index is another project (0.0.2)"
    files = [ROOT / "README.md", ROOT / "Dockerfile", *sorted((ROOT / "docs").glob("*.md"))]
    for folder in EXTRA_OF:
        files += sorted((ROOT / folder).rglob("*.py"))
    wrong = []
    for path in files:
        for name, extras in INSTALL_HINT.findall(path.read_text(encoding="utf-8")):
            if name not in (".", project["name"]) or not set(extras.split(",")) <= set(
                project["optional-dependencies"]
            ):
                wrong.append(f"{path.relative_to(ROOT)}: {name}[{extras}]")
    assert not wrong, wrong


def test_the_readme_says_every_extra_a_user_installs():
    """README's "Installing" names each extra with its pip command, so that to_dataframe()'s
    pandas (``dataframes``) or the API reference's tools (``docs``) are not found only by the
    ImportError that asks for them."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Installing", 1)[1].split("\n## ", 1)[0]
    said = {extra for _, extras in INSTALL_HINT.findall(section) for extra in extras.split(",")}
    assert set(PYPROJECT["project"]["optional-dependencies"]) <= said, said


def test_every_package_the_web_parts_import_is_named_by_the_app_extras_message():
    """Without the ``app`` extra, ``jik serve`` and ``jik bench`` say which command installs it
    when the missing module is one of the web parts' (``jik.cli.command.WEB_PACKAGES``); any
    other missing module is re-raised as a fault. Each module that app/ and benchmarks/ import
    and the plain install lacks must be there: ``jik bench dashboard`` after ``pip install
    jik-lab`` printed pydantic's ModuleNotFoundError as a traceback."""
    from jik.cli.command import WEB_PACKAGES

    plain = _runtime_distributions(None)
    providers = metadata.packages_distributions()
    web = {
        module
        for folder in ("app", "static", "benchmarks")
        for module in _third_party_imports(folder)
        if not {_name(d) for d in providers.get(module, [module])} & plain
    }
    assert web - WEB_PACKAGES == set()
