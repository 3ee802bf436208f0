"""The same atlas on a Dask cluster (``pip install ".[atlas]"``): a local one, or yours.

The chunks of an atlas are plain functions of picklable data; a Dask cluster runs them, and the
numbers are those of a run here. ``--scheduler tcp://host:8786`` uses an existing cluster;
the default starts a local cluster of two worker processes.

    python examples/05_dask_atlas.py [--starts N] [--scheduler ADDRESS]
"""

import argparse

import numpy as np

import jik.engine as jik

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--starts", type=int, default=256, help="starts on the curve (default 256)")
parser.add_argument("--scheduler", default="local:2", help="a Dask address (default local:2)")
args = parser.parse_args()

arm = jik.Manipulator2()
loop = [(0, 1), (1, 1), (1, 2), (0, 2)]
plan = jik.plan_atlas(
    [jik.Pseudoinverse(arm)],
    loop,
    cycles=2,
    n_starts=args.starts,
    arc=(-1.0, 1.0),
    reference=[0.0, 0.0, np.pi / 2],
    chunk=32,
)

if __name__ == "__main__":  # (Dask's local workers are processes that import this file)
    on_dask = jik.run_atlas(plan, backend=f"dask:{args.scheduler}")
    here = jik.run_atlas(plan)
    print(on_dask)
    same = np.array_equal(on_dask.drift, here.drift, equal_nan=True)
    print(f"The same numbers as in this process: {same}")
