"""Table 1 of the paper: Manipulator 2 driven around a closed square, pseudoinverse vs extended.

The path (1,1) -> (1,2) -> (0,2) -> back to (0,1) starts at x0 = (0, 0, pi/2), whose image is
(0, 1). The pseudoinverse (8) comes back to a different configuration (it is not repeatable);
the extended Jacobian inverse (11) with the paper's cubic (38) comes back to x0. More cycles show
the pseudoinverse's drift growing cycle after cycle; each run says what it found and why (for
the extended inverse: h stayed at h(x0), eq. (12)).

    python examples/01_table1.py [--cycles N]
"""

import argparse

import numpy as np

import jik.engine as jik

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--cycles", type=int, default=5, help="cycles of the path (default 5)")
args = parser.parse_args()

arm = jik.Manipulator2(l=1.0)
x0 = [0.0, 0.0, np.pi / 2]
path = [(1, 1), (1, 2), (0, 2), (0, 1)]
inverses = {
    "pseudoinverse": jik.Pseudoinverse(arm),
    "extended": jik.ExtendedInverse(arm, jik.PaperCubic()),
}

print("Table 1: the configuration after each leg of the first cycle")
runs = {
    name: jik.repeatability(inv, x0, path, cycles=args.cycles) for name, inv in inverses.items()
}
for name, run in runs.items():
    print(f"  {name}")
    for corner, x in zip(["A", "B", "C", "D", "A"], [x0, *run.legs[: len(path)]], strict=True):
        # (rounded first: a round-off of -1e-17 prints as 0.0000, as the paper's table does)
        print(f"    {corner}  " + "  ".join(f"{round(v, 4) + 0.0:8.4f}" for v in x))

print(f"\nDrift ||x - x0|| after each of {args.cycles} cycles")
for name, run in runs.items():
    print(f"  {name:14s} " + " ".join(f"{d:9.2e}" for d in run.drift))
    print(f"  {'':14s} {run}")

print("\nWhat each run found, and why (x1, x2 in m, x3 in rad)")
for run in runs.values():
    print("\n".join(f"  {finding.text}" for finding in run.findings("[m and rad mixed]")))
