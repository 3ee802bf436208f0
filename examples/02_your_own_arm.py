"""Your own arm: a planar 3R chain, its repeatability, and an augmenting map given by a formula.

A chain of revolute joints with the end point as the task has one degree of redundancy. A
formula h(x) makes the extended Jacobian inverse (11) repeatable; ``robot_from_dict`` builds the
same robot from JSON-friendly data (what ``jik repeatability --robot arm.json`` reads).

    python examples/02_your_own_arm.py [--cycles N]
"""

import argparse

import numpy as np

import jik.engine as jik

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--cycles", type=int, default=5, help="cycles of the path (default 5)")
args = parser.parse_args()

arm = jik.PlanarChain(joints="RRR", lengths=[1.0, 0.8, 0.6])
x0 = np.array([0.3, 1.0, 1.0])
print(f"{arm.p} joints, task of {arm.r} coordinates; k(x0) = {arm.forward(x0).round(4)}")

# One solve to a target: the result prints on one line.
print(jik.solve(jik.Pseudoinverse(arm), x0, [1.0, 1.5]))

# The same arm with an augmenting map h, from a dict (a JSON or YAML robot file holds this).
robot = jik.robot_from_dict(
    {
        "name": "planar_chain",
        "joints": "RRR",
        "lengths": [1.0, 0.8, 0.6],
        "augmentations": [{"name": "formula", "h": "x3 - x2"}],
    }
)
path = [(1.0, 1.3), (1.0, 1.7), (0.6, 1.7)]
for algorithm in ("pseudoinverse", "extended"):
    run = jik.repeatability(robot.inverse(algorithm), x0, path, cycles=args.cycles)
    print(f"{algorithm:14s} drift after each cycle: " + " ".join(f"{d:.2e}" for d in run.drift))
