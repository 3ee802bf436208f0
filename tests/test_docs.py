"""The API reference builds from the docstrings (mkdocs build --strict) and loads nothing from
another site."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_the_api_reference_builds_strictly_with_local_assets_only(tmp_path):
    pytest.importorskip("mkdocstrings_handlers.python", reason='pip install ".[docs]"')
    site = tmp_path / "site"
    out = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    solving = (site / "api" / "solving" / "index.html").read_text(encoding="utf-8")
    assert "solve_batch" in solving and "BatchSolveResult" in solving
    assert "Wazewski" in solving or "continuation" in solving
    # the docstrings' Sphinx roles are links (or code), never the text ":func:" before a name
    link = re.search(
        r'<a class="autorefs[^"]*"[^>]*href="([^"]+)"><code>solve_batch</code></a>', solving
    )
    assert link and link.group(1) == "#jik.engine.solver.solve_batch"
    for page in site.joinpath("api").rglob("*.html"):
        roles = re.findall(r":(?:func|class|data|mod|meth|attr|exc):", page.read_text("utf-8"))
        assert roles == [], page
    pages = [p.read_text(encoding="utf-8") for p in site.rglob("*.html")]
    assert len(pages) >= 9 and (site / "index.html").is_file()
    for page in pages:
        # scripts, style sheets, images, fonts: only from the site itself
        remote = re.findall(r'<(?:script|link|img)[^>]+(?:src|href)="((?:https?:)?//[^"]+)"', page)
        assert remote == [], remote
    for css in site.rglob("*.css"):
        assert not re.search(r"@import\s+url\((?:https?:)?//", css.read_text(encoding="utf-8"))
