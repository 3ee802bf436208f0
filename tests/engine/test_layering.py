"""The import layers: engine <- app/compute <- app/api, and no import cycles in app/.

The engine is a library (no web package, no app); app/compute turns requests into engine calls
and never reaches up into the HTTP side; app/api is the only package that imports app/api.
Imports are read from the source with ast, function-level ones included: an import inside a
function is still a dependency, and a cycle through one only fails later, at call time.
"""

import ast
import importlib
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

#: Import cycles that are known and on their way out; each entry is one strongly connected set.
KNOWN_CYCLES: list[set[str]] = []


def _modules(folder: str) -> dict[str, Path]:
    """Module name -> file, for every .py file under ``folder`` (the jik.<folder> package)."""
    out = {}
    for path in sorted((ROOT / folder).rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(["jik", *parts])] = path
    return out


def _imported(name: str, path: Path) -> set[str]:
    """Every dotted name an import in the file may load, wherever the import statement is.

    ``from a.b import c`` gives ``a.b`` and ``a.b.c`` (c may be a submodule); relative imports
    are resolved against the module's package.
    """
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                module = f"{base}.{node.module}" if node.module else base
            else:
                module = node.module or ""
            found.add(module)
            found.update(f"{module}.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.Call) and _dynamic_import(node) is not None:
            found.add(_dynamic_import(node))  # type: ignore[arg-type]
    lazy = _lazy_exports(name, path)
    if lazy and "<a module named at run time>" in found:
        found.discard("<a module named at run time>")
        found.update(lazy)
    return found


def _lazy_exports(name: str, path: Path) -> set[str]:
    """The modules a package's front door loads lazily (PEP 562): the values of its literal
    ``_EXPORTS = {"Name": "module", ...}``, as submodules of the package. Its dynamic import
    names only these, so they are what it depends on."""
    if path.name != "__init__.py":
        return set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        target = node.targets[0] if isinstance(node, ast.Assign) and node.targets else None
        if isinstance(target, ast.Name) and target.id == "_EXPORTS":
            value = node.value  # type: ignore[union-attr]
            if isinstance(value, ast.Dict):
                return {
                    f"{name}.{v.value}"
                    for v in value.values
                    if isinstance(v, ast.Constant) and isinstance(v.value, str)
                }
    return set()


def _dynamic_import(node: ast.Call) -> str | None:
    """The literal module name of ``importlib.import_module("a.b")``, ``import_module("a.b")``
    or ``__import__("a.b")``; the package of ``f"a.b.{name}"`` (its layer is known); a name
    given otherwise is refused (it cannot be checked)."""
    fn = node.func
    name = fn.attr if isinstance(fn, ast.Attribute) else getattr(fn, "id", None)
    if name not in ("import_module", "__import__"):
        return None
    arg = node.args[0] if node.args else None
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        return arg.value
    if isinstance(arg, ast.JoinedStr) and arg.values and isinstance(arg.values[0], ast.Constant):
        head = str(arg.values[0].value)
        if head.endswith(".") and head.count(".") >= 2:
            return head[:-1]
    return "<a module named at run time>"


ENGINE = _modules("engine")
APP = _modules("app")
IMPORTS = {name: _imported(name, path) for name, path in {**ENGINE, **APP}.items()}


def _within(name: str, package: str) -> bool:
    return name == package or name.startswith(package + ".")


def _violations(importers: list[str], forbidden: str) -> dict[str, list[str]]:
    """Importer -> the names under ``forbidden`` it imports (only importers that have any)."""
    out = {}
    for module in importers:
        bad = sorted(n for n in IMPORTS[module] if _within(n, forbidden))
        if bad:
            out[module] = bad
    return out


def test_engine_imports_no_web_or_plotting_package():
    """engine/ is a library for notebooks: importing all of it pulls in no web or plot package."""
    code = (
        "import importlib, pkgutil, sys, jik.engine, jik.engine.reproductions\n"
        "for m in pkgutil.walk_packages(jik.engine.__path__, 'jik.engine.'):\n"
        "    importlib.import_module(m.name)\n"
        "bad = [m for m in ('fastapi', 'starlette', 'pydantic', 'uvicorn', 'viser', 'plotly')\n"
        "       if m in sys.modules]\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"engine imported {out.stdout.strip()}"


def test_the_import_graph_covers_the_packages():
    """The file scan finds the modules (a guard against a scan that silently finds nothing)."""
    assert {"jik.engine.solver", "jik.app.compute.pool", "jik.app.api.factory"} <= set(IMPORTS)


@pytest.mark.parametrize("module", sorted(APP))
def test_every_app_module_imports(module):
    """Each module under jik.app imports on its own (no import names a moved module)."""
    importlib.import_module(module)


def test_every_app_file_is_a_module_of_the_package():
    """Every .py file under app/ is a module of jik.app (the scan and the package agree)."""
    import jik.app

    walked = {m.name for m in pkgutil.walk_packages(jik.app.__path__, "jik.app.")}
    assert walked | {"jik.app"} == set(APP)


def test_engine_never_imports_app():
    assert _violations(sorted(ENGINE), "jik.app") == {}
    assert _violations(sorted(ENGINE), "app") == {}


def test_compute_never_imports_api():
    compute = [m for m in APP if _within(m, "jik.app.compute")]
    assert _violations(compute, "jik.app.api") == {}


def test_compute_imports_only_the_engine_and_itself():
    """app/compute sits right above the engine: no dashboard, scene or session code either."""
    bad = {
        module: sorted(
            n
            for n in IMPORTS[module]
            if _within(n, "jik")
            and not _within(n, "jik.engine")
            and not _within(n, "jik.app.compute")
        )
        for module in APP
        if _within(module, "jik.app.compute")
    }
    assert {m: names for m, names in bad.items() if names} == {}


def test_only_api_imports_api():
    """The dashboard, its figures, controls, sessions and scene never reach up into app/api."""
    outside = [m for m in APP if not _within(m, "jik.app.api")]
    assert _violations(outside, "jik.app.api") == {}


def _reachable(graph: dict[str, set[str]], start: str) -> set[str]:
    seen, todo = set(), [start]
    while todo:
        for nxt in graph[todo.pop()]:
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return seen


def test_no_import_cycles_in_app():
    """The graph of imports among jik.app modules is acyclic (function-level imports count)."""
    graph = {m: {n for n in IMPORTS[m] if n in APP and n != m} for m in APP}
    reach = {m: _reachable(graph, m) for m in graph}
    cycles = []
    for m in sorted(graph):
        scc = {m} | {n for n in reach[m] if m in reach[n]}
        if len(scc) > 1 and scc not in cycles:
            cycles.append(scc)
    unexpected = [sorted(c) for c in cycles if c not in KNOWN_CYCLES]
    assert unexpected == [], f"import cycles among jik.app modules: {unexpected}"


def test_dynamic_imports_count_as_imports():
    """``importlib.import_module`` and ``__import__`` with a literal name are imports too; a name
    known only at run time is reported as such (the layers could not be checked)."""
    code = "import importlib\nimportlib.import_module('jik.app.dashboard.offload')\n"
    code += "__import__('jik.app.api')\nimport_module(name)\nimport_module(f'jik.engine.{m}')\n"
    calls = [n for n in ast.walk(ast.parse(code)) if isinstance(n, ast.Call)]
    assert [_dynamic_import(c) for c in calls] == [
        "jik.app.dashboard.offload",
        "jik.app.api",
        "<a module named at run time>",
        "jik.engine",
    ]


def test_no_module_is_imported_by_a_name_known_only_at_run_time():
    """Every dynamic import names its module literally, or (the engine's front door) is one of
    the modules its literal ``_EXPORTS`` lists, which the scan takes as its imports."""
    assert {"jik.engine.solver", "jik.engine.repeatability"} <= IMPORTS["jik.engine"]
    assert [m for m, names in IMPORTS.items() if "<a module named at run time>" in names] == []
