"""The engine's front door: ``import jik.engine`` gives the documented API, lightly; results
print on one line and export their numbers."""

import doctest
import importlib
import json
import math
import pydoc
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import jik.engine as jik
from jik.engine import _EXPORTS
from jik.engine.atlas_table import AtlasResult
from jik.engine.solve_rules import DISCRETE_GAMMA_BOUND, check_gamma, gamma_problem

X0 = np.array([0.0, 0.0, math.pi / 2])
PATH = [(1, 1), (1, 2), (0, 2)]


def _plan():
    """Two starts on the self-motion curve of k(X0) = (0, 1), Table 1's loop, two cycles."""
    return jik.plan_atlas(
        jik.Pseudoinverse(jik.Manipulator2()),
        [(0, 1), *PATH],
        cycles=2,
        n_starts=2,
        arc=(-0.2, 0.2),
        reference=X0,
    )


def _atlas() -> AtlasResult:
    return jik.run_atlas(_plan())


def _imported_after(code: str) -> set[str]:
    """The heavy top-level packages imported by ``code`` in a fresh interpreter."""
    probe = (
        f"import sys\n{code}\n"
        "print(' '.join(m for m in ('numpy', 'scipy', 'sympy', 'yourdfpy', 'pandas', 'fastapi')"
        " if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return set(out.stdout.split())


def test_import_is_light_and_names_load_what_they_need():
    """``import jik.engine`` imports no numerics at all; solving loads numpy but not sympy
    (formulas), yourdfpy (URDF), pandas or a web package."""
    assert _imported_after("import jik.engine") == set()
    used = _imported_after(
        "import jik.engine as jik\n"
        "jik.solve(jik.Pseudoinverse(jik.Manipulator2()), [0, 0, 1.5], [1, 1])"
    )
    assert "numpy" in used and not used & {"sympy", "yourdfpy", "pandas", "fastapi"}


def test_every_exported_name_is_its_modules_object_with_a_docstring():
    assert sorted(jik.__all__) == sorted(_EXPORTS) and len(set(jik.__all__)) == len(jik.__all__)
    for name, module in _EXPORTS.items():
        obj = getattr(jik, name)
        assert obj is getattr(importlib.import_module(f"jik.engine.{module}"), name), name
        if name != "ROBOTS":
            assert (obj.__doc__ or "").strip(), f"{name} has no docstring"
        assert name in jik.__doc__, f"{name} is not in the module's table"
    assert set(jik.__all__) <= set(dir(jik))
    machinery = {"Any", "TYPE_CHECKING", "annotations", "importlib", "sys", "types"}
    assert not machinery & set(dir(jik)), "a notebook's completion lists the front door's imports"
    importlib.import_module("jik.engine.solver")
    assert "solver" in dir(jik) and "__doc__" in dir(jik)
    with pytest.raises(AttributeError, match="no attribute 'solve_ik'"):
        _ = jik.solve_ik


ROOT = Path(__file__).resolve().parents[2]
#: Exported data tables, shown in the reference by the functions that read them.
TABLES = {"ROBOTS", "ARMS", "ALGORITHMS"}


def test_the_reference_documents_every_exported_name():
    """docs/api holds each name of ``jik.engine.__all__``: by its own directive
    (``::: jik.engine.<module>.<name>``) or by its whole module's."""
    pages = "".join(p.read_text() for p in (ROOT / "docs" / "api").glob("*.md"))
    directives = set(re.findall(r"^::: jik\.engine\.([\w.]+)$", pages, re.M))
    missing = [
        name
        for name, module in _EXPORTS.items()
        if name not in TABLES and f"{module}.{name}" not in directives and module not in directives
    ]
    assert not missing, f"not in docs/api: {missing}"


def test_help_lists_the_api():
    """help(jik.engine) shows the table and documents every exported class and function."""
    text = pydoc.render_doc(jik, renderer=pydoc.plaintext)
    assert "Robots (kinematics k: R^p -> R^r" in text
    for name in jik.__all__:
        assert f"\n    {name}" in text or f"class {name}" in text, name


def test_the_module_docstring_example_runs():
    failures, tried = doctest.testmod(jik, verbose=False, report=False)[:2]
    assert tried >= 4 and failures == 0


def test_solve_takes_one_start_and_solve_batch_a_batch():
    inv = jik.Pseudoinverse(jik.Manipulator2())
    one = jik.solve(inv, X0, [1, 1])
    assert isinstance(one, jik.SolveResult) and one.success
    batch = jik.solve_batch(inv, X0, [1, 1])
    assert isinstance(batch, jik.BatchSolveResult) and len(batch) == 1
    np.testing.assert_array_equal(batch[0].x, one.x)
    with pytest.raises(jik.InvalidInputError, match="solve_batch solves a batch"):
        jik.solve(inv, [X0, X0], [1, 1])


def _one_line(obj, *parts: str) -> str:
    text = repr(obj)
    assert "\n" not in text and len(text) < 260, text
    for part in parts:
        assert part in text, (part, text)
    return text


def test_results_print_on_one_line_with_their_numbers():
    inv = jik.Pseudoinverse(jik.Manipulator2())
    one = jik.solve(inv, X0, [1, 1])
    _one_line(
        one,
        "SolveResult(pseudoinverse, continuous, success=True",
        f"nit={one.nit}",
        f"{len(one.trajectory)} points",
        "converged",
    )
    _one_line(one.trajectory, f"Trajectory({len(one.trajectory)} points", "x [0, 0, 1.571]")
    starts = np.array([X0, X0 + [0.0, 0.1, 0.0]])
    _one_line(jik.solve_batch(inv, starts, [1, 1]), "2 solves, 2 converged")
    rep = jik.repeatability(inv, X0, PATH, cycles=3)
    _one_line(
        rep,
        "(pseudoinverse, continuous, gamma=1, success=True, 3 cycles of 4 legs",
        f"{rep.drift[-1]:.3g}",
    )
    _one_line(jik.repeatability(inv, X0, PATH), "1 cycle of 4 legs")
    reps = jik.repeatability(inv, starts, PATH, cycles=2)
    _one_line(reps, "2 starts, 2 completed, 2 cycles", f"{np.max(reps.drift[:, -1]):.3g}")
    big = jik.PlanarChain(joints="R" * 12, lengths=[0.1] * 12)
    _one_line(jik.solve(jik.Pseudoinverse(big), np.full(12, 0.2), [0.6, 0.8]), ", ..., ")


def test_an_atlas_and_a_synthesis_print_on_one_line():
    _one_line(_plan(), "AtlasPlan(pseudoinverse, 1 path x 2 starts x 2 cycles of 4 legs, 2 runs")
    atlas = _atlas()
    _one_line(
        atlas,
        "AtlasResult(pseudoinverse, 1 path x 2 starts x 2 cycles, 2 of 2 runs",
        f"pseudoinverse {np.max(atlas.drift[..., -1]):.3g}",
    )
    synthesis = jik.synthesize_e2(jik.Manipulator2(), {"x2": (-1, 1), "x3": (0, 3)}, degree=4)
    _one_line(synthesis, f"E2 = {synthesis.e2:.6g}, degree 4, x2 in [-1, 1], x3 in [0, 3]")


def test_columns_and_dicts_hold_the_results_numbers():
    inv = jik.ExtendedInverse(jik.Manipulator2(), jik.PaperCubic())
    one = jik.solve(inv, X0, [1, 1])
    cols = one.trajectory.columns()
    assert list(cols) == ["theta", "x_1", "x_2", "x_3", "y_1", "y_2", "error", "h"]
    np.testing.assert_array_equal(cols["x_2"], one.trajectory.x[:, 1])
    np.testing.assert_array_equal(cols["h"], one.trajectory.h)
    d = json.loads(json.dumps(one.as_dict(trajectory=True)))
    assert d["x"] == one.x.tolist() and d["trajectory"]["theta"] == one.trajectory.theta.tolist()
    starts = np.array([X0, X0 + [0.0, 0.1, 0.0]])
    batch = jik.solve_batch(inv, starts, [[1, 1], [1, 2]])
    bc = batch.columns()
    np.testing.assert_array_equal(bc["y_2"], batch.y[:, 1])
    assert bc["message"].tolist() == list(batch.message)
    assert json.loads(json.dumps(batch.as_dict()))["nit"] == batch.nit.tolist()
    rep = jik.repeatability(inv, starts, PATH, cycles=3)
    rc = rep.columns()
    assert rc["start"].tolist() == [0, 0, 0, 1, 1, 1] and rc["cycle"].tolist() == [1, 2, 3] * 2
    np.testing.assert_array_equal(rc["drift"], rep.drift.ravel())
    np.testing.assert_array_equal(rc["x_3"], rep.cycle_end[..., 2].ravel())
    assert json.loads(json.dumps(rep.as_dict()))["success"] == [True, True]
    single = jik.repeatability(inv, X0, PATH, cycles=2).columns()
    assert "start" not in single and single["cycle"].tolist() == [1, 2]


def test_an_atlas_in_long_format():
    atlas = _atlas()
    cols = atlas.columns()
    assert len(cols["drift"]) == atlas.drift.size == 4
    assert cols["start"].tolist() == [0, 0, 1, 1] and cols["cycle"].tolist() == [1, 2, 1, 2]
    np.testing.assert_array_equal(cols["s"], np.repeat(atlas.parameter, 2))
    np.testing.assert_array_equal(cols["drift"], atlas.drift.ravel())
    np.testing.assert_array_equal(cols["x0_3"], np.repeat(atlas.starts[0, :, 2], 2))


def test_to_dataframe_with_or_without_pandas(monkeypatch):
    """With pandas: a DataFrame of the columns. Without: an ImportError that names the extra to
    install (one pyproject.toml declares, with pandas in it)."""
    import tomllib
    from pathlib import Path

    tr = jik.solve(jik.Pseudoinverse(jik.Manipulator2()), X0, [1, 1]).trajectory
    try:
        import pandas  # noqa: F401
    except ImportError:
        pass
    else:
        frame = tr.to_dataframe()
        assert list(frame.columns) == list(tr.columns()) and len(frame) == len(tr)
    monkeypatch.setitem(sys.modules, "pandas", None)  # (import pandas now raises ImportError)
    with pytest.raises(ImportError, match=r"needs pandas: pip install 'jik-lab\[dataframes\]'"):
        tr.to_dataframe()
    root = Path(__file__).resolve().parents[2]
    extras = tomllib.loads((root / "pyproject.toml").read_text())["project"]
    assert any(r.startswith("pandas") for r in extras["optional-dependencies"]["dataframes"])


def test_gamma_rules_are_worded_once():
    """check_gamma's message is gamma_problem's phrase after the field's name."""
    assert gamma_problem(1.5, "discrete") is None and gamma_problem(5.0, "continuous") is None
    why = gamma_problem(DISCRETE_GAMMA_BOUND, "discrete")
    assert why is not None and why.startswith("must be < 2 in discrete mode, got 2")
    with pytest.raises(jik.InvalidInputError, match="gamma must be < 2 in discrete") as info:
        check_gamma(2.0, "discrete")
    assert str(info.value) == f"gamma {why}" and info.value.field == "gamma"
    with pytest.raises(jik.InvalidInputError, match="gamma must be > 0"):
        check_gamma(0.0, "continuous")


def test_a_progress_implements_only_what_it_shows():
    """A Progress subclass with ``leg`` alone runs a discrete repeatability run (its pieces
    call ``advance`` and ``cancelled``, which do nothing by default) to the numbers of a run
    without it."""

    class Legs(jik.Progress):
        def __init__(self):
            self.seen = []

        def leg(self, leg):
            self.seen.append((leg.cycle, leg.index))

    inv = jik.ExtendedInverse(jik.Manipulator2(), jik.PaperCubic())
    progress = Legs()
    watched = jik.repeatability(
        inv, X0, PATH, cycles=2, mode="discrete", gamma=0.05, progress=progress
    )
    plain = jik.repeatability(inv, X0, PATH, cycles=2, mode="discrete", gamma=0.05)
    assert progress.seen == [(c, j) for c in range(2) for j in range(4)]
    np.testing.assert_array_equal(watched.legs, plain.legs)
    assert watched.message == plain.message and watched.success


def test_repeatability_takes_its_run_and_one_progress_no_other_hooks():
    """The run's own settings and one Progress: going on from an earlier run is a Resume given
    as the start, and stopping at a leg's error is the progress's answer."""
    import inspect

    params = inspect.signature(jik.repeatability).parameters
    names = "inverse x0 path cycles gamma mode tol max_iterations record close progress"
    assert list(params) == names.split()
    inv = jik.Pseudoinverse(jik.Manipulator2())
    part = jik.repeatability(inv, X0, PATH, cycles=1)
    rest = jik.repeatability(inv, jik.Resume.of(part), PATH, cycles=2)
    np.testing.assert_array_equal(rest.legs, jik.repeatability(inv, X0, PATH, cycles=2).legs)
