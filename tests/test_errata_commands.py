"""Every command of docs/paper-errata.md runs and shows what the erratum says it shows."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ERRATA = (Path(__file__).resolve().parents[1] / "docs" / "paper-errata.md").read_text("utf-8")
COMMANDS = re.findall(r'`python -c "(.*?)"`', ERRATA, re.S)
#: What each command's output (or, for the one that shows an error, its error) must contain:
#: the erratum's own figures, found by a fragment of the command.
SHOWS = {
    "for v in ((1, 2), (2, 1))": "119.25",
    "J = k.jacobian(np.array([0, 0, 0.7]))": "1.4142135623730951",
    "manipulator1_findings() + manipulator2_findings()": "True",
    "synthesize_e2(Manipulator1()": "0.01618",
    "solve_ivp(lambda t, q: [np.sin(t)]": "2.0000",
    "_panel_rule": "derived [-1.82646616  2.28704719]",
    "print(Unicycle().jacobian": "6.28318531",
    "for z in (19.0,19.6,19.615,19.63,20.0)": "19.615",
    "solve_ivp(f,(1,0)": "OneFormUndefinedError",
    "Pseudoinverse(k).matrix(x)": "1.00000000e+00",
    "PaperCubic().gradient(x)": "(3, 3)",
}
#: The commands that take a minute (Ritz syntheses up to degree 14): in the slow run.
SLOW = ("synthesize_e2(Manipulator1()",)


def test_every_command_has_its_check():
    assert len(COMMANDS) == len(SHOWS)
    for fragment in SHOWS:
        assert sum(fragment in c for c in COMMANDS) == 1, fragment


@pytest.mark.parametrize(
    "fragment",
    [pytest.param(f, marks=pytest.mark.slow) if f in SLOW else f for f in SHOWS],
)
def test_the_command_shows_it(fragment, tmp_path):
    (command,) = [c for c in COMMANDS if fragment in c]
    out = subprocess.run(
        [sys.executable, "-c", command], capture_output=True, text=True, cwd=tmp_path, timeout=300
    )
    if SHOWS[fragment] == "OneFormUndefinedError":
        assert out.returncode != 0 and "OneFormUndefinedError" in out.stderr
        assert "(0.0035121, 3.13017, 0.0769303, -0.182432)" in out.stderr
    else:
        assert out.returncode == 0, out.stderr
        assert SHOWS[fragment] in out.stdout, out.stdout
