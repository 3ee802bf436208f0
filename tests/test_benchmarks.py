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


def test_the_figures_benchmark_decodes_every_typed_array():
    """Its check that plotly's JSON and jik's agree decodes plotly's typed arrays of any dtype
    (plotly sends float32 as f4): a dtype it did not list stopped `jik bench figures`."""
    import base64

    import numpy as np

    from jik.benchmarks.bench_figures import _values

    for dtype in ("f8", "f4", "i4", "i2", "i1", "u1", "u2"):
        data = np.array([1, 2, 3], dtype=np.dtype(dtype).newbyteorder("<"))
        typed = {"dtype": dtype, "bdata": base64.b64encode(data.tobytes()).decode()}
        assert _values({"x": typed}) == {"x": [1.0, 2.0, 3.0]}


def test_the_atlas_benchmark_times_dask_only_where_it_is_installed(monkeypatch, capsys):
    """Without the ``atlas`` extra, ``jik bench atlas`` (and so ``jik bench``) timed the
    in-process and 2-process atlases, then died with a traceback at the Dask backend; it now
    times those two and says what installs Dask."""
    import importlib.util

    from jik.benchmarks import bench_atlas

    assert bench_atlas.backends() == ("inprocess", "processes:2", "dask:local:2")
    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "distributed" else real(name)
    )
    assert bench_atlas.backends() == ("inprocess", "processes:2")
