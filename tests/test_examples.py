"""Every script in examples/ runs (with fast settings) and prints the numbers it promises."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

#: Each script's fast settings.
FAST = {
    "01_table1.py": ["--cycles", "2"],
    "02_your_own_arm.py": ["--cycles", "2"],
    "03_e2_synthesis.py": ["--degree", "6"],
    "04_atlas.py": ["--starts", "12", "--cycles", "1"],
    "05_dask_atlas.py": ["--starts", "16"],
}


def run(name: str) -> str:
    out = subprocess.run(
        [sys.executable, str(EXAMPLES / name), *FAST[name]],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert out.returncode == 0, out.stdout + out.stderr
    return out.stdout


def numbers(line: str) -> list[float]:
    return [float(t) for t in re.findall(r"-?\d+\.\d+(?:e[-+]\d+)?", line)]


def test_every_example_has_fast_settings():
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == sorted(FAST)


def test_table1():
    """Table 1's pseudoinverse column as printed; the extended inverse comes back to x0."""
    text = run("01_table1.py")
    assert "B    0.1132    0.5379    1.0904" in text  # (the pseudoinverse's first leg)
    assert "A    0.0529    0.3210    1.8976" in text  # (its end of the first cycle)
    table, said = text.split("What each run found, and why")
    drift = {line.split()[0]: numbers(line) for line in table.splitlines() if "e-" in line}
    assert max(drift["extended"]) < 1e-12 and min(drift["pseudoinverse"]) > 0.4
    assert "pseudoinverse J^P#: not repeatable. After 2 cycles" in said
    assert "extended Jacobian J^E#: repeatable." in said and "h(x) = h(x0) (eq. (12))" in said


def test_your_own_arm():
    text = run("02_your_own_arm.py")
    assert "3 joints, task of 2 coordinates" in text and "success=True" in text
    ext = next(line for line in text.splitlines() if line.startswith("extended"))
    pinv = next(line for line in text.splitlines() if line.startswith("pseudoinverse"))
    assert max(numbers(ext)) < 1e-12 and min(numbers(pinv)) > 1e-4


def test_e2_synthesis():
    """At degree 6 the Ritz minimum is within 0.1% of E2 = 1.8152 (degree 16, tested in
    tests/engine/test_variational.py); the synthesized map is repeatable."""
    text = run("03_e2_synthesis.py")
    e2 = float(re.search(r"SynthesisResult\(E2 = ([\d.]+), degree 6", text).group(1))
    assert abs(e2 - 1.8152) < 2e-3
    assert "E2 = 119.25" in text  # (the paper's cubic on the same box)
    drift = text.splitlines()[-1]
    assert (
        drift.startswith("Extended inverse with the synthesized h") and max(numbers(drift)) < 1e-9
    )


def test_atlas():
    text = run("04_atlas.py")
    assert "12 of 12 runs" in text  # (the progress, as chunks end)
    assert "AtlasResult(pseudoinverse/extended, 1 path x 12 starts x 1 cycle" in text
    pinv = next(line for line in text.splitlines() if line.startswith("pseudoinverse"))
    ext = next(line for line in text.splitlines() if line.startswith("extended"))
    assert "12 of 12 runs completed" in pinv and numbers(pinv)[0] > 0.1
    assert numbers(ext)[-1] < 1e-12


@pytest.mark.slow
def test_dask_atlas():
    """A local Dask cluster gives the numbers of a run in this process."""
    pytest.importorskip("distributed", reason="the atlas extra (Dask) is not installed")
    text = run("05_dask_atlas.py")
    assert "1 path x 16 starts x 2 cycles, 16 of 16 runs completed" in text
    assert "The same numbers as in this process: True" in text


def test_the_readmes_first_python_example_runs_with_one_import():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    code = re.search(r"```python\n(.*?)```", readme, flags=re.S).group(1)
    imports = [line for line in code.splitlines() if line.startswith(("import ", "from "))]
    assert imports == [
        "import jik.engine as jik  # help(jik) lists the API; examples/ holds runnable scripts"
    ]
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("SolveResult(pseudoinverse, continuous, success=True")


def test_the_readmes_real_arm_example_runs():
    """The Panda example: the pseudoinverse drifts, the synthesized extended inverse does not."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    (code,) = [c for c in re.findall(r"```python\n(.*?)```", readme, flags=re.S) if "panda" in c]
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    drift, kept = (float(v) for v in out.stdout.splitlines()[0].split())
    assert drift > 1e-2 and kept < 1e-12
    assert out.stdout.splitlines()[1] == "within the joint limits"
