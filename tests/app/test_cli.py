"""The `jik reproduce` commands print what the issues promise (JSON contracts and tables)."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from jik.cli import main
from jik.engine.reproductions.table1 import PRINTED

ROOT = Path(__file__).resolve().parents[2]


def run_cli(capsys, *argv):
    assert main(list(argv)) == 0
    return capsys.readouterr().out


def test_table1_json_contract(capsys):
    out = json.loads(run_cli(capsys, "reproduce", "table1", "--json"))
    assert set(out) == {"pseudoinverse", "extended", "augmentation"}
    assert out["augmentation"] == "paper_cubic"
    assert np.shape(out["pseudoinverse"]) == (5, 3) and np.shape(out["extended"]) == (5, 3)
    np.testing.assert_allclose(out["pseudoinverse"], PRINTED["pseudoinverse"], atol=5e-5)
    np.testing.assert_allclose(out["extended"][0], [0, 0, math.pi / 2])


def test_table1_text_has_both_columns_and_printed_values(capsys):
    out = run_cli(capsys, "reproduce", "table1")
    assert "Jacobian pseudoinverse" in out and "Extended Jacobian" in out
    assert out.count("1.0432") == 2  # ours and the printed value on row C
    # Rows D and A of the extended column have x2 = 0 up to round-off (about -1e-16), printed
    # as a zero without a sign.
    assert "-0.0000" not in out and " 0.0000" in out


def test_errata_prints_the_errata_page(capsys):
    """``jik errata`` prints docs/paper-errata.md as it is; ``jik reproduce table1`` names both."""
    out = run_cli(capsys, "errata")
    assert out == (ROOT / "docs" / "paper-errata.md").read_text(encoding="utf-8")
    assert "`jik errata`" in run_cli(capsys, "reproduce", "table1")


def test_manipulator1_json_contract(capsys):
    out = json.loads(run_cli(capsys, "reproduce", "manipulator1", "--json"))
    assert out["region"] == {"x1": [0, 1], "x2": [0, 1], "x3": [0.5, 1.5]}
    for functional in ("E1", "E2"):
        assert set(out[functional]) >= {"e1_optimal", "e1_taylor", "e2_optimal"}
        assert all(np.isfinite(v) and v >= 0 for v in out[functional].values())
    # E1 of (36) with a = 0, b = 1 has the closed form 1 - pi/4 on this region.
    assert out["E1"]["e2_optimal"] == pytest.approx(1 - math.pi / 4, abs=1e-8)
    assert "symbolic" in out
    # The E2 minimum is a Ritz value (an upper bound, falling with the degree), given with its
    # degrees, not as the minimum itself.
    box = out["e2_minimum_on_box"]
    values = [c["e2"] for c in box["convergence"]]
    assert values == sorted(values, reverse=True) and values[-1] == box["E2"]
    assert box["E2"] < 0.0162 < values[0]


def test_manipulator2_json_contract(capsys):
    out = json.loads(run_cli(capsys, "reproduce", "manipulator2", "--json"))
    assert out["region"] == {"x2": [-1, 1], "x3": [0, math.pi]}
    assert out["E2"]["e2_synthesized"] < 0.1 * out["E2"]["paper_cubic"]
    # (38)'s dh K changes sign inside the region: its E1 diverges; the E2-optimal map's does not.
    assert out["E1"]["paper_cubic"] is None and out["E1_divergent"]["paper_cubic"] is True
    assert 1.0 < out["E1"]["e2_synthesized"] < 3.0 and not out["E1_divergent"]["e2_synthesized"]
    assert len(out["polynomial"]) >= 10
    rows = np.array(out["table1_extended"])
    assert rows.shape == (5, 3)
    np.testing.assert_allclose(rows[-1], rows[0], atol=1e-8)  # repeatable


def test_unknown_reproduction_is_rejected(capsys):
    with pytest.raises(SystemExit):
        main(["reproduce", "table2"])
    assert "invalid choice" in capsys.readouterr().err


def test_a_reproduction_that_needs_an_extra_says_so_before_it_runs():
    """Without yourdfpy (an install without the urdf extra), `jik reproduce algorithms`, whose
    second table is the Panda's, says in one line what to install, before it computes."""
    import subprocess
    import sys

    code = (
        "import sys; sys.modules['yourdfpy'] = None; from jik.cli import main; "
        "raise SystemExit(main(['reproduce', 'algorithms']))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stderr
    assert done.stdout == "" and "Traceback" not in done.stderr
    assert done.stderr.startswith("jik reproduce: URDF robots need the yourdfpy package: pip")
    assert "[urdf]" in done.stderr and done.stderr.count("\n") == 1


def test_only_the_printing_commands_die_quietly_on_a_closed_pipe(monkeypatch):
    """`jik reproduce ... | head` ends quietly; `jik serve` keeps Python's handling of SIGPIPE
    (a worker or client that goes away must not end the server), and main() leaves the
    caller's handling as it found it."""
    import signal

    from jik.cli import command as cli

    seen = {}
    monkeypatch.setattr(
        cli,
        "reproduce",
        lambda a: seen.setdefault("reproduce", signal.getsignal(signal.SIGPIPE)) and 0,
    )
    monkeypatch.setattr(
        cli, "serve", lambda a: seen.setdefault("serve", signal.getsignal(signal.SIGPIPE)) and 0
    )
    before = signal.getsignal(signal.SIGPIPE)
    cli.main(["reproduce", "table1"])
    cli.main(["serve"])
    assert seen["reproduce"] == signal.SIG_DFL
    assert seen["serve"] == before != signal.SIG_DFL
    assert signal.getsignal(signal.SIGPIPE) == before


def test_serve_on_a_busy_port_says_so_and_names_the_option():
    """A taken port is reported with the option that changes it, before anything claims a
    start (no uvicorn or viser banner), and the command exits 2."""
    import socket
    import subprocess
    import sys

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        busy = taken.getsockname()[1]
        out = subprocess.run(
            [sys.executable, "-m", "jik", "serve", f"--port={busy}"],
            capture_output=True,
            text=True,
            timeout=60,
        )
    assert out.returncode == 2, out
    assert f"port {busy} on 127.0.0.1 is in use" in out.stderr
    assert "choose another with --port PORT" in out.stderr
    assert "startup complete" not in out.stdout + out.stderr
    assert "viser" not in out.stdout + out.stderr


@pytest.mark.parametrize(
    ("variable", "value", "said"),
    [
        ("JIK_WORKERS", "abc", "JIK_WORKERS='abc': Input should be a valid integer"),
        ("JIK_TIMEOUT", "-5", "JIK_TIMEOUT='-5': Input should be greater than 0"),
        ("JIK_BATCH", "maybe", "JIK_BATCH='maybe': Input should be a valid boolean"),
        ("JIK_WORKER_MEMORY_MB", "x", "JIK_WORKER_MEMORY_MB='x': Input should be a valid integer"),
    ],
)
def test_serve_with_a_bad_setting_names_the_variable(monkeypatch, capsys, variable, value, said):
    """A JIK_* variable that is not valid is one line naming the variable as the user set it
    (an alias too), exit status 2, before a port is taken or anything starts."""
    monkeypatch.setenv(variable, value)
    assert main(["serve", "--port", "1"]) == 2  # (port 1 is never bound: the setting is first)
    err = capsys.readouterr().err
    assert err.startswith(f"jik serve: {said}") and err.count("\n") == 1, err
