"""The bound on a call's memory (jik.engine.validation.MEMORY_LIMIT): batches, repeatability
runs and atlases whose estimate exceeds it are refused before they allocate, naming the field
and what to do instead; the estimates bound the measured peaks; a streamed atlas holds a chunk."""

import math
import tracemalloc

import numpy as np
import pytest

import jik.engine as jik
from jik.engine import validation
from jik.engine.exceptions import InvalidInputError
from jik.engine.repeatability import closed_path
from jik.engine.solve_rules import run_bytes, solve_bytes

X0 = np.array([0.0, 0.0, math.pi / 2])
PATH = [(1.0, 1.0), (1.0, 2.0), (0.0, 2.0)]
LOOP = [(0.0, 1.0), *PATH]
P = jik.Pseudoinverse(jik.Manipulator2())


def _starts(n: int):
    """n copies of X0 without n copies in memory (a read-only view)."""
    return np.broadcast_to(X0, (n, 3))


def _refused(call, field: str, *phrases: str) -> str:
    with pytest.raises(InvalidInputError) as info:
        call()
    text = str(info.value)
    assert info.value.field == field, text
    assert text.startswith(f"{field}: ") and "jik.engine.validation.MEMORY_LIMIT" in text
    for phrase in phrases:
        assert phrase in text, text
    return text


def test_a_repeatability_batch_beyond_the_bound_is_refused_before_it_allocates():
    """10^7 starts (a notebook's process reached 23 GB) and 10^6 (a raw numpy MemoryError):
    refused at once, saying how many starts fit and what to do instead."""
    tracemalloc.start()
    for n in (10**7, 10**6):
        text = _refused(
            lambda n=n: jik.repeatability(P, _starts(n), PATH),
            "x0",
            f"{n} starts of a repeatability run (1 cycle x 4 legs)",
            "smaller batches",
            "iter_atlas",
        )
        fit = int(text.split("at most ")[1].split()[0])
        assert 10**5 < fit < 10**6
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 100e6  # (the check's own pass over x0: 10^7 x 3 booleans)


def test_a_solve_batch_beyond_the_bound_is_refused():
    """3 * 10^6 recorded starts: refused, with record=False as advice; y_d names a batch of
    targets from one start."""
    _refused(
        lambda: jik.solve_batch(P, _starts(3 * 10**6), [1, 1], record=True),
        "x0",
        "with record=True",
        "record=False",
    )
    targets = np.broadcast_to(np.array([1.0, 1.0]), (10**7, 2))
    _refused(lambda: jik.solve_batch(P, X0, targets, record=False), "y_d")


def test_the_bound_is_the_callers_to_raise(monkeypatch):
    """MEMORY_LIMIT is read at each call: lowered, 2000 starts are refused; the estimate
    scales with the starts, so 4 times fewer pass."""
    need = 2000 * run_bytes(P.kinematics, 1, 4, "continuous", False, 1.0, 1e-10, 20000)
    monkeypatch.setattr(validation, "MEMORY_LIMIT", int(need / 2))
    _refused(lambda: jik.repeatability(P, _starts(2000), PATH), "x0", "at most 1000 fit")
    res = jik.repeatability(P, _starts(500), PATH)
    assert res.success.all()


ROBOTS = {
    "manipulator2": jik.Manipulator2(),
    "chain-RRRR": jik.PlanarChain("RRRR", [1, 1, 1, 1]),
    "chain-10R": jik.PlanarChain("R" * 10, [0.3] * 10),
    "panda-xyz": jik.robot_from_dict({"name": "panda"}).kinematics,
}


def _peak(call) -> int:
    tracemalloc.start()
    try:
        call()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("name", ROBOTS)
def test_the_estimates_bound_the_measured_peaks(name):
    """The peak of Python's allocations (numpy's included) of a batched solve and of a
    repeatability run of 256 starts lies between a third of the estimate and the estimate."""
    kin = ROBOTS[name]
    inv = jik.Pseudoinverse(kin)
    rng = np.random.default_rng(7)
    x0 = np.full(kin.p, 0.3) + 1e-3 * rng.standard_normal((256, kin.p))
    y = kin.forward(np.full(kin.p, 0.3))
    path = y + 0.02 * np.eye(kin.r)[:2]  # (two small steps from the starts' task point)
    legs = closed_path(kin, x0[:1], path).shape[1]
    for record in (False, True):
        est = solve_bytes(kin, 256, "continuous", record)
        peak = _peak(lambda r=record: jik.solve_batch(inv, x0, path[0], record=r))
        assert est / 3 < peak < est, (record, peak, est)
    for cycles in (1, 3):
        est = 256 * run_bytes(kin, cycles, legs, "continuous", False, 1.0, 1e-10, 20000)
        peak = _peak(lambda c=cycles: jik.repeatability(inv, x0, path, cycles=c))
        assert est / 3 < peak < est, (cycles, peak, est)
    est = solve_bytes(kin, 256, "discrete", True, 0.5, 1e-10, 2000)
    peak = _peak(lambda: jik.solve_batch(inv, x0, path[0], mode="discrete", gamma=0.5))
    assert peak < est


def test_an_atlas_too_large_to_gather_is_refused_by_run_atlas_but_streams():
    """10^8 starts x 10 cycles of two algorithms (run_atlas raised numpy's MemoryError for
    14.9 GiB): planned, refused by run_atlas before any work, with or without the leg ends;
    iter_atlas streams it holding a chunk."""
    inverses = [P, jik.ExtendedInverse(P.kinematics, jik.PaperCubic())]
    plan = jik.plan_atlas(
        inverses, LOOP, cycles=10, n_starts=10**8, arc=(-1, 1), reference=X0, chunk=64
    )
    _refused(lambda: jik.run_atlas(plan), "n_starts", "iter_atlas", "keep_leg_ends=False")
    text = _refused(lambda: jik.run_atlas(plan, keep_leg_ends=False), "n_starts", "iter_atlas")
    assert "keep_leg_ends" not in text
    tracemalloc.start()
    task, chunk = next(iter(jik.iter_atlas(plan)))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert (chunk.lo, chunk.hi) == (0, 64) and chunk.drift.shape == (2, 64, 10)
    assert task.starts.shape == (64, 3)
    assert peak < 20e6


def test_explicit_starts_name_starts(monkeypatch):
    """An atlas of explicit starts too large to gather names ``starts``."""
    plan = jik.plan_atlas(P, LOOP, starts=[X0], scales=np.linspace(0.5, 1.0, 10**4))
    monkeypatch.setattr(validation, "MEMORY_LIMIT", 10**5)
    _refused(lambda: jik.run_atlas(plan), "starts", "10000 paths x 1 start")


def test_a_chunk_too_large_for_the_bound_is_refused_by_plan_atlas(monkeypatch):
    """1000 cycles of a 100-point loop: a chunk of 2048 runs would hold about 10 GiB;
    plan_atlas names chunk and how many runs fit, and the default chunking takes no more.
    Below the bound even one run does not fit: it names cycles."""
    loop = [(np.cos(t), np.sin(t)) for t in np.linspace(0, 2 * np.pi, 100, endpoint=False)]

    def plan(**kw):
        return jik.plan_atlas(P, loop, starts=np.zeros((40000, 3)), cycles=1000, **kw)

    text = _refused(lambda: plan(chunk=2048), "chunk", "2048 runs of a chunk", "a smaller chunk")
    fit = int(text.split("at most ")[1].split()[0])
    assert 100 < fit < 2048
    assert plan(chunk=fit).chunk == fit and plan().chunk == fit
    monkeypatch.setattr(validation, "MEMORY_LIMIT", 2**20)
    _refused(lambda: plan(chunk=1), "cycles", "1000 cycles of one run", "fewer cycles")


def test_a_map_singularity_search_holds_a_block_of_its_grid():
    """A seven-variable total-degree map (the Gen3's E2 synthesis) holds 64 kB per point in its
    gradient: the search of a 4^7 grid held 1 GB at once (a server's worker ran out of memory);
    it is evaluated a block at a time, the same points found."""
    from jik.engine.map_singularities import BLOCK, map_singularities
    from jik.engine.synthesis_nd import synthesize_e2_nd

    gen3 = jik.load_robot("gen3").kinematics
    x0 = jik.load_robot("gen3").spec.default_x0
    region = {n: (c - 0.3, c + 0.3) for n, c in zip(gen3.variable_names, x0, strict=True)}
    found = synthesize_e2_nd(gen3, region, nodes=1024)
    tracemalloc.start()
    try:
        map_singularities(gen3, found.maps[0], found.region, fixed=found.fixed, nodes=4)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert 4**7 > 4 * BLOCK and peak < 300e6, peak
