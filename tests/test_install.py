"""The built wheel, installed as a user installs it: into a fresh virtual environment outside the
source tree, run from another directory.

Every other test runs against the editable install of the source tree, which would hide a file
the wheel leaves out (it once left out ``engine/reproductions``). These build the wheel once and
install it twice: with the ``app`` extra (the command line, ``python -m jik`` and a served
dashboard that computes), and alone (the engine on numpy, scipy and sympy, no web package).
"""

from __future__ import annotations

import hashlib
import json
import os
import socket
import subprocess
import sys
import tarfile
import time
import venv
import zipfile
from pathlib import Path

import httpx
import pytest

#: Builds and installs into fresh environments (a minute or more): out of the default run,
#: in CI's slow step; in one worker under pytest-xdist (the tests share one wheel, built in the
#: source tree).
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("install")]

ROOT = Path(__file__).resolve().parents[1]
#: Packages of the ``app`` extra that the engine alone must not need.
WEB_MODULES = ("fastapi", "fastapi_offline", "starlette", "uvicorn", "viser", "plotly", "httpx")
#: Seconds for one pip install into a fresh environment (from pip's cache, normally under 60).
PIP_SECONDS = 600
#: Seconds for a served dashboard's first result.
FIRST_RESULT_SECONDS = 120


def run(*cmd: str | Path, cwd: Path, timeout: float = 300, env=None) -> str:
    out = subprocess.run(
        [str(c) for c in cmd], cwd=cwd, capture_output=True, text=True, timeout=timeout, env=env
    )
    assert out.returncode == 0, f"{cmd} exited {out.returncode}:\n{out.stdout}\n{out.stderr}"
    return out.stdout


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """The project's wheel, built from the source tree as pip builds it."""
    out = tmp_path_factory.mktemp("wheel")
    run(
        sys.executable,
        "-m",
        "pip",
        "wheel",
        "--no-deps",
        "-q",
        "-w",
        out,
        ROOT,
        cwd=out,
        timeout=PIP_SECONDS,
    )
    (built,) = out.glob("jik_lab-*.whl")
    return built


def wheel_files(path: Path) -> dict[str, str]:
    """A wheel's files, name -> sha256 (its RECORD aside: it lists the same hashes)."""
    with zipfile.ZipFile(path) as z:
        return {
            n: hashlib.sha256(z.read(n)).hexdigest()
            for n in z.namelist()
            if not n.endswith("/RECORD")
        }


def fresh_env(where: Path) -> tuple[Path, Path]:
    """A new virtual environment at ``where`` (no system site-packages): bin/, site-packages."""
    venv.EnvBuilder(with_pip=True, clear=True).create(where)
    bin_dir = where / "bin"
    site = run(
        bin_dir / "python",
        "-c",
        "import sysconfig; print(sysconfig.get_path('purelib'))",
        cwd=where,
    ).strip()
    return bin_dir, Path(site)


def pip_install(bin_dir: Path, *args: str | Path) -> None:
    run(
        bin_dir / "python",
        "-m",
        "pip",
        "install",
        "-q",
        "--disable-pip-version-check",
        *args,
        cwd=bin_dir,
        timeout=PIP_SECONDS,
    )


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_wheel_installs_one_package_and_serves(wheel, tmp_path):
    """From the wheel alone: only ``jik`` in site-packages; the command, ``python -m jik``,
    ``jik reproduce table1 --json`` and a ``jik serve`` whose dashboard computes a result."""
    bin_dir, site = fresh_env(tmp_path / "env")
    before = {p.name for p in site.iterdir()}
    pip_install(bin_dir, "--no-deps", wheel)
    gained = {p.name for p in site.iterdir()} - before
    top_level = {name for name in gained if not name.endswith(".dist-info")}
    assert top_level == {"jik"}, f"site-packages gained {sorted(gained)}"
    pip_install(bin_dir, f"{wheel}[app]")

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    located = run(bin_dir / "python", "-c", "import jik; print(jik.__file__)", cwd=elsewhere)
    assert Path(located.strip()).is_relative_to(site), located
    assert "usage: jik" in run(bin_dir / "python", "-m", "jik", "--help", cwd=elsewhere)
    assert run(bin_dir / "jik", "--help", cwd=elsewhere) == run(
        bin_dir / "python", "-m", "jik", "--help", cwd=elsewhere
    )
    table = json.loads(run(bin_dir / "jik", "reproduce", "table1", "--json", cwd=elsewhere))
    assert table["pseudoinverse"], table

    port = free_port()
    env = {**os.environ, "JIK_WORKERS": "1"}
    server = subprocess.Popen(
        [bin_dir / "jik", "serve", "--port", str(port)],
        cwd=elsewhere,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        snapshot = first_dashboard_result(f"http://127.0.0.1:{port}", server)
        assert snapshot["summary"], snapshot
        docs = httpx.get(f"http://127.0.0.1:{port}/docs", timeout=10)
        assert docs.status_code == 200 and "cdn" not in docs.text.lower(), docs.text[:500]
        errata = httpx.get(f"http://127.0.0.1:{port}/errata", timeout=10)
        assert errata.status_code == 200 and "<h1>Paper errata</h1>" in errata.text
    finally:
        server.terminate()
        output = server.communicate(timeout=60)[0]
    assert server.returncode == 0, output
    assert "resource_tracker" not in output and "Traceback" not in output, output


def first_dashboard_result(base: str, server: subprocess.Popen) -> dict:
    """Open a dashboard session over HTTP (as the page does) and poll it until it has computed a
    result; its snapshot."""
    deadline = time.monotonic() + FIRST_RESULT_SECONDS
    last: object = None
    session = None
    while time.monotonic() < deadline:
        assert server.poll() is None, f"jik serve exited {server.returncode}"
        try:
            if session is None:
                created = httpx.post(f"{base}/api/sessions", json={"state": {}}, timeout=30)
                assert created.status_code == 201, created.text
                session = created.json()["id"]
            last = httpx.get(f"{base}/api/sessions/{session}", timeout=5).json()
        except httpx.TransportError as error:
            last = error
        else:
            if isinstance(last, dict) and last.get("summary"):
                return last
        time.sleep(0.5)  # polling a separate process's server: nothing to wait on but time
    raise AssertionError(f"no dashboard result in {FIRST_RESULT_SECONDS} s; last answer {last!r}")


def test_engine_alone_reproduces_table1(wheel, tmp_path):
    """Installed without the extra, the engine needs numpy, scipy and sympy alone: Table 1 from
    Python, with no web package importable; ``jik serve`` names the command that adds them."""
    bin_dir, _ = fresh_env(tmp_path / "env")
    pip_install(bin_dir, wheel)
    script = (
        "import importlib.util, json\n"
        f"web = [m for m in {WEB_MODULES!r} if importlib.util.find_spec(m)]\n"
        "assert not web, web\n"
        "from jik.engine.reproductions import table1\n"
        "print(json.dumps(table1.run()))\n"
    )
    table = json.loads(run(bin_dir / "python", "-c", script, cwd=tmp_path))
    assert len(table["pseudoinverse"]) == 5, table
    errata = (ROOT / "docs" / "paper-errata.md").read_text(encoding="utf-8")
    assert run(bin_dir / "jik", "errata", cwd=tmp_path) == errata
    serve = subprocess.run(
        [bin_dir / "jik", "serve"], cwd=tmp_path, capture_output=True, text=True, timeout=60
    )
    assert serve.returncode == 2
    assert "pip install 'jik-lab[app]'" in serve.stderr, serve.stderr


def test_sdist_builds_the_same_wheel_without_tests_or_docs(wheel, tmp_path):
    """The sdist holds what builds the wheel, and the wheel pip builds from it is the one built
    from the tree; the tests, docs (but for the errata the wheel ships), scripts and harnesses
    stay in the repository."""
    pytest.importorskip("build", reason="the build package (of the test extra) builds sdists")
    run(
        sys.executable,
        "-m",
        "build",
        "--sdist",
        "-o",
        tmp_path,
        ROOT,
        cwd=tmp_path,
        timeout=PIP_SECONDS,
    )
    (sdist,) = tmp_path.glob("jik_lab-*.tar.gz")
    with tarfile.open(sdist) as tar:
        names = tar.getnames()
    folders = {Path(*Path(n).parts[1:3]) for n in names if len(Path(n).parts) > 2}
    left_in = {f for f in folders if f.parts[0] in ("tests", "scripts", ".ci")}
    assert not left_in and Path("benchmarks/harness") not in folders, sorted(left_in)
    docs = {Path(*Path(n).parts[1:]) for n in names if Path(n).parts[1:2] == ("docs",)}
    assert docs - {Path("docs")} == {Path("docs/__init__.py"), Path("docs/paper-errata.md")}
    assert {Path("engine/reproductions"), Path("app/api")} <= folders, sorted(folders)
    out = tmp_path / "from-sdist"
    run(
        sys.executable,
        "-m",
        "pip",
        "wheel",
        "--no-deps",
        "-q",
        "-w",
        out,
        sdist,
        cwd=tmp_path,
        timeout=PIP_SECONDS,
    )
    (rebuilt,) = out.glob("jik_lab-*.whl")
    assert wheel_files(rebuilt) == wheel_files(wheel)
