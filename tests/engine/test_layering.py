import subprocess
import sys


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
