"""Synthesis of the augmenting map h by the error functional E2 (paper, eqs. (16)-(20)).

The Ritz method minimises E2 over polynomial maps h(x2, x3) of Manipulator 2 on a box; the
synthesized map makes the extended Jacobian inverse repeatable and, by construction, as close
to the pseudoinverse as such a map can be there. The paper's cubic (38) is compared on the
same box.

    python examples/03_e2_synthesis.py [--degree N]
"""

import argparse

import numpy as np

import jik.engine as jik

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--degree", type=int, default=16, help="Legendre degree (default 16)")
args = parser.parse_args()

arm = jik.Manipulator2()
region = {"x2": (-1.0, 1.0), "x3": (0.0, np.pi)}
low = sorted({2, 4, max(2, args.degree // 2)} - {args.degree})
result = jik.synthesize_e2(arm, region, degree=args.degree, convergence_degrees=low)
print(result)
for step in result.convergence:
    print(f"  degree {step['degree']:2d}: {step['unknowns']:4d} unknowns, E2 = {step['e2']:.6f}")

cubic = jik.error_functional_e2(arm, jik.PaperCubic(), region)
print(f"The paper's cubic (38) on the same box: E2 = {cubic.value:.6f}")

# The synthesized map drives the extended inverse: repeatable on Table 1's loop.
x0, path = [0.0, 0.0, np.pi / 2], [(1, 1), (1, 2), (0, 2)]
run = jik.repeatability(jik.ExtendedInverse(arm, result.augmenting_map), x0, path, cycles=3)
print(f"Extended inverse with the synthesized h, largest drift in 3 cycles: {run.drift.max():.1e}")
