"""A repeatability atlas: the drift after each cycle over many starts on a self-motion curve.

Every start maps to the same task point (it lies on the self-motion curve of k(x0)); each is
driven around Table 1's loop by both inverses. The pseudoinverse's drift depends on the start;
the extended inverse's stays at round-off where it runs (the cubic (38) has algorithmic
singularities on part of the curve, where a run stops and says so). A progress object reports
the chunks as they end.

    python examples/04_atlas.py [--starts N] [--cycles N]
"""

import argparse

import numpy as np

import jik.engine as jik

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--starts", type=int, default=64, help="starts on the curve (default 64)")
parser.add_argument("--cycles", type=int, default=3, help="cycles of the loop (default 3)")
args = parser.parse_args()

arm = jik.Manipulator2()
inverses = [jik.Pseudoinverse(arm), jik.ExtendedInverse(arm, jik.PaperCubic())]
loop = [(0, 1), (1, 1), (1, 2), (0, 2)]
plan = jik.plan_atlas(
    inverses,
    loop,
    cycles=args.cycles,
    n_starts=args.starts,
    arc=(-1.0, 1.0),
    reference=[0.0, 0.0, np.pi / 2],
    chunk=16,
)


class Report(jik.Progress):
    def advance(self, done, total):
        print(f"  {int(done)} of {int(total)} runs")


atlas = jik.run_atlas(plan, progress=Report())
print(atlas)
for a, name in enumerate(atlas.algorithms):
    ok = atlas.success[a, 0]
    last = atlas.drift[a, 0, ok, -1]
    print(
        f"{name:14s} {ok.sum()} of {ok.size} runs completed; drift after cycle {args.cycles}: "
        f"min {last.min():.2e}, max {last.max():.2e}"
    )
# A run that stops says why (here: starts where the cubic (38) makes [J; dh] singular).
for (a, _, start), why in list(atlas.failures.items())[:2]:
    print(f"  {atlas.algorithms[a]} from s = {atlas.parameter[start]:+.3f}: {why}")
worst = int(np.argmax(atlas.drift[0, 0, :, -1]))
print(
    f"The pseudoinverse drifts most from s = {atlas.parameter[worst]:+.3f}, "
    f"x0 = {atlas.starts[0, worst].round(4)}"
)
