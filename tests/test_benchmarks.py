"""The benchmarks run wherever jik is installed, not only from the source tree."""

from __future__ import annotations

import httpx

from jik.benchmarks import available


def test_bench_load_serves_from_another_folder(tmp_path, monkeypatch):
    """Its uvicorn server imports the app by its installed name (from a folder without the
    source tree's app/, a name relative to the tree fails)."""
    from jik.benchmarks.bench_load import start_server, stop_server

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("JIK_WORKERS", "1")
    proc, url = start_server(batching=False)
    try:
        assert httpx.get(f"{url}/health", timeout=30).json() == {"status": "ok"}
    finally:
        stop_server(proc)


def test_the_harness_benchmarks_are_found_in_a_source_checkout():
    """``jik bench`` lists the benchmarks of benchmarks/ and of benchmarks/harness/ (this is a
    source checkout)."""
    assert {"fuzz", "latency", "load", "solver"} <= set(available())
