"""The repeatability atlas: engine.atlas, atlas_run, atlas_backends and self_motion."""

import dataclasses
import math
import re
import subprocess
import sys
import tracemalloc

import numpy as np
import pytest
from scipy.optimize import brentq

from jik.engine import atlas_run
from jik.engine.atlas import AtlasPlan, arc_lengths, plan_atlas
from jik.engine.atlas_backends import backend_for
from jik.engine.atlas_run import iter_atlas, run_atlas
from jik.engine.augmentations import PaperCubic
from jik.engine.exceptions import InvalidInputError, RunCancelled
from jik.engine.inverses import ExtendedInverse, Pseudoinverse, extended_singularity
from jik.engine.kinematics import Manipulator1, Manipulator2
from jik.engine.progress import ProgressCallbacks
from jik.engine.repeatability import open_loop, repeatability
from jik.engine.robot_spec import robot_from_dict
from jik.engine.self_motion import trace
from jik.engine.solver import solve_batch

X0 = (0.0, 0.0, math.pi / 2)
#: Table 1's loop from its start's task point (0, 1).
LOOP = [(0.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)]


def manipulator2_inverses():
    kin = Manipulator2()
    return [Pseudoinverse(kin), ExtendedInverse(kin, PaperCubic())]


def small_plan(**kw) -> AtlasPlan:
    args = dict(cycles=2, n_starts=24, arc=(-3.0, 3.0), reference=X0, sampling="sample", seed=7)
    return plan_atlas(manipulator2_inverses(), LOOP, **{**args, **kw})


@pytest.fixture(scope="module")
def reference_atlas():
    """Two inverses, two paths (a shift and a scale), 24 sampled starts, two cycles."""
    plan = small_plan(shifts=[(0.0, 0.0), (0.3, -0.2)], scales=[0.5], chunk=5)
    return plan, run_atlas(plan)


def test_each_row_of_a_family_names_its_path_s_scale_and_shift(reference_atlas):
    """A family's table carries each path's scale and shift, and they make that path from the
    base path (scaled about its first point, then moved); an atlas of one path given as is has
    no such columns."""
    plan, res = reference_atlas
    table = res.columns()
    assert list(table)[:5] == ["algorithm", "path", "scale", "shift_1", "shift_2"]
    base = np.array(LOOP)
    for j in (0, 1):
        rows = table["path"] == j
        (scale,) = set(table["scale"][rows])
        (shift,) = set(zip(table["shift_1"][rows], table["shift_2"][rows], strict=True))
        assert (scale, shift) == (0.5, ((0.0, 0.0), (0.3, -0.2))[j])
        made = base[0] + np.array(shift) + scale * (base - base[0])
        np.testing.assert_allclose(plan.paths[j], made, rtol=0, atol=1e-15)
    single = run_atlas(small_plan(n_starts=2, cycles=1))
    assert "scale" not in single.columns() and single.family is None


def test_drift_at_sampled_starts_equals_single_start_repeatability(reference_atlas):
    """Each run of the atlas is repeatability() from that start around that path: drift and
    leg ends agree to 1e-10 (a single start guesses its legs' Picard sweeps, a batch does not)."""
    plan, res = reference_atlas
    assert res.drift.shape == (2, 2, 24, 2) and res.leg_ends.shape == (2, 2, 24, 8, 3)
    checked = 0
    for a, inverse in enumerate(plan.inverses):
        for j in range(2):
            for i in (0, 5, 11, 23):
                one = repeatability(inverse, res.starts[j, i], plan.paths[j, 1:], cycles=2)
                assert one.success == res.success[a, j, i]
                if not one.success:
                    assert res.failures[(a, j, i)] == one.message
                    continue
                np.testing.assert_allclose(res.drift[a, j, i], one.drift, rtol=0, atol=1e-10)
                np.testing.assert_allclose(res.leg_ends[a, j, i], one.legs, rtol=0, atol=1e-10)
                checked += 1
    assert checked >= 12
    assert res.drift[0].min() > 1e-3  # the pseudoinverse drifts everywhere here


def test_paths_of_the_family_scale_about_the_first_point_and_shift(reference_atlas):
    plan, res = reference_atlas
    base = np.array(LOOP)
    np.testing.assert_allclose(plan.paths[0], base[0] + 0.5 * (base - base[0]))
    np.testing.assert_allclose(plan.paths[1], plan.paths[0] + [0.3, -0.2])
    kin = plan.inverses[0].kinematics
    for j in range(2):
        np.testing.assert_allclose(
            kin.forward(res.starts[j]), plan.paths[j, :1].repeat(24, 0), rtol=0, atol=1e-13
        )


@pytest.mark.parametrize(("n_starts", "chunk"), [(8, 16), (64, 16), (600, 38), (10**5, 2048)])
def test_a_default_chunking_reports_progress_within_a_small_atlas(n_starts, chunk):
    """By default a chunk holds at most 2048 starts, and an atlas of 256 runs or more has 16
    chunks or more: a 64-start atlas tells its progress 4 times, not once at the end."""
    from jik.engine.atlas import auto_chunk

    assert auto_chunk(n_starts) == chunk
    if n_starts == 64:
        plan = small_plan(n_starts=64, cycles=1)
        assert plan.chunk == 16
        told: list[tuple[int, int]] = []
        run_atlas(plan, progress=ProgressCallbacks(on_advance=lambda d, t: told.append((d, t))))
        assert told == [(16, 64), (32, 64), (48, 64), (64, 64)]


def test_the_same_numbers_whatever_the_chunking(reference_atlas, monkeypatch):
    """Chunks of 5 (reference), 1 and all 48 runs at once, the last in batches of 7, give the
    same numbers (to 1e-12; they are in fact equal: each member's arithmetic in a batch is its
    own)."""
    _, res = reference_atlas
    monkeypatch.setattr(atlas_run, "BATCH", 7)
    for chunk in (1, 48):
        other = run_atlas(small_plan(shifts=[(0.0, 0.0), (0.3, -0.2)], scales=[0.5], chunk=chunk))
        np.testing.assert_allclose(other.drift, res.drift, rtol=0, atol=1e-12)
        np.testing.assert_allclose(other.leg_ends, res.leg_ends, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(other.success, res.success)
        assert other.failures == res.failures


@pytest.mark.parametrize("backend", ["processes:2", "dask:local:2"])
def test_process_pool_and_local_dask_cluster_equal_in_process(reference_atlas, backend):
    """The chunks run in other processes (a spawned pool; a 2-worker LocalCluster) give the
    in-process numbers to 1e-12."""
    plan, res = reference_atlas
    other = run_atlas(plan, backend)
    np.testing.assert_allclose(other.drift, res.drift, rtol=0, atol=1e-12)
    np.testing.assert_allclose(other.leg_ends, res.leg_ends, rtol=0, atol=1e-12)
    np.testing.assert_allclose(other.starts, res.starts, rtol=0, atol=0)
    assert other.failures == res.failures


def test_a_members_dop853_numbers_do_not_depend_on_its_batch():
    """DOP853 (the fallback near singularities) combines its stages term by term: a member's end
    point is the same alone and at any place in batches of any size (with BLAS sums they
    differed by up to 5e-10 in the drift of an atlas chunked two ways)."""
    inverse = manipulator2_inverses()[1]
    curve = trace(inverse.kinematics, X0, (-5.0, 5.0))
    starts = curve.points(np.linspace(-5.0, 5.0, 37))
    target = np.array([1.0, 1.3])
    whole = solve_batch(inverse, starts, target, method="dop853", record=False)
    for i in (0, 17, 36):
        for ids in ([i], list(range(i, 37)), list(range(i + 1)), [i, *range(37)]):
            part = solve_batch(inverse, starts[ids], target, method="dop853", record=False)
            assert np.array_equal(part.x[0 if ids[0] == i else ids.index(i)], whole.x[i])


def test_manipulator2_curve_is_parametrized_by_arc_length():
    """Manipulator 2 (37): on k(x) = y0, x3 is free and x1 = y2 - l sin x3, x2 = y1 - l cos x3;
    the unit kernel advances x3 by ds / m, m = sqrt(1 + l^2), so x3 = x3_base + s / m."""
    kin = Manipulator2(l=0.7)
    base = np.array([0.2, -0.1, 1.0])
    curve = trace(kin, base, (-4.0, 5.0))
    s = np.linspace(-4.0, 5.0, 37)
    x = curve.points(s)
    y0 = kin.forward(base)
    np.testing.assert_allclose(kin.forward(x), np.broadcast_to(y0, (37, 2)), rtol=0, atol=1e-13)
    np.testing.assert_allclose(x[:, 2], 1.0 + s / math.sqrt(1 + 0.7**2), rtol=0, atol=1e-10)


def test_manipulator1_curve_and_box():
    """Manipulator 1 (30): x1 = y1 and x2 = y2 - y1 x3 on the curve; K = (0, -x1, 1) / m with
    m = sqrt(1 + x1^2), so x3 = x3_base + s / m. A box cuts the arc where x3 leaves it."""
    kin = Manipulator1()
    base = np.array([0.5, 0.25, 1.0])
    curve = trace(kin, base, (-10.0, 10.0), box=[(-2, 2), (-2, 2), (-2, 2)])
    m = math.sqrt(1.25)
    # x2 = 0.75 - 0.5 x3 stays in [-2, 2] for x3 in [-2, 2]: the box's x3 faces end the arc.
    np.testing.assert_allclose(curve.arc, (-3 * m, m), rtol=0, atol=1e-9)
    x = curve.points(np.array([-3 * m + 1e-9, 0.3, m - 1e-9]))
    np.testing.assert_allclose(x[:, 0], 0.5, rtol=0, atol=1e-13)
    np.testing.assert_allclose(x[:, 1], 0.75 - 0.5 * x[:, 2], rtol=0, atol=1e-13)
    np.testing.assert_allclose(x[:, 2], [-2.0, 1.0 + 0.3 / m, 2.0], rtol=0, atol=1e-8)


def test_table1_start_is_the_base_of_its_loop():
    """s = 0 is where eq. (7) from the reference reaches the loop's first point: from Table 1's
    x0 to its own task point (0, 1), x0 itself; a grid includes both ends of the arc."""
    plan = small_plan(n_starts=5, sampling="grid", arc=(-2.0, 2.0))
    np.testing.assert_allclose(plan.manifolds[0].base, X0, atol=1e-15)
    np.testing.assert_allclose(plan.parameter(np.arange(5)), [-2, -1, 0, 1, 2], atol=1e-15)
    np.testing.assert_allclose(plan.starts(2, 3)[0], X0, atol=1e-14)


def test_sampled_arc_lengths_depend_only_on_index_and_seed():
    index = np.arange(5000)
    whole = arc_lengths(index, 5000, (-1.0, 2.0), "sample", 3)
    parts = np.concatenate(
        [
            arc_lengths(index[a:b], 5000, (-1.0, 2.0), "sample", 3)
            for a, b in ((0, 7), (7, 2100), (2100, 5000))
        ]
    )
    np.testing.assert_array_equal(whole, parts)
    assert whole.min() >= -1.0 and whole.max() <= 2.0 and np.ptp(whole) > 2.9
    assert not np.array_equal(whole, arc_lengths(index, 5000, (-1.0, 2.0), "sample", 4))


def test_a_start_singular_for_one_inverse_fails_alone():
    """A start where [J; dh] is singular (eq. (11) undefined) fails with the typed error's
    message; the other starts of its chunk give their single-start numbers."""
    kin = Manipulator2()
    inverse = ExtendedInverse(kin, PaperCubic())
    curve = trace(kin, X0, (-6.0, 6.0))

    def hadamard(s):
        x = curve.points(np.array([s]))
        J = np.concatenate([kin.jacobian(x), inverse.augmenting_map.gradient(x)[:, None]], 1)
        return float(np.linalg.det(J[0])), extended_singularity(J)[0]

    s = np.linspace(-6, 6, 121)
    d = np.array([hadamard(t)[0] for t in s])
    k = int(np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:]))[0])
    root = brentq(lambda t: hadamard(t)[0], s[k], s[k + 1], xtol=1e-15)
    assert hadamard(root)[1] < 1e-10
    starts = curve.points(np.array([0.0, root, 0.2, -0.3]))
    path = [(0.0, 1.0), (0.2, 1.1), (0.1, 1.2)]
    res = run_atlas(plan_atlas(inverse, path, starts=starts, cycles=1, chunk=4))
    assert not res.success[0, 0, 1]
    assert "singular" in res.failures[(0, 0, 1)]
    assert res.as_dict()["drift"][0][0][1] == [None]  # (a failed leg's NaN: JSON's null)
    for i in (0, 2, 3):
        one = repeatability(inverse, starts[i], path[1:], cycles=1)
        np.testing.assert_allclose(res.drift[0, 0, i], one.drift, rtol=0, atol=1e-10)


def _peak_streaming(n: int) -> int:
    plan = plan_atlas(
        Pseudoinverse(Manipulator2()),
        [(0.0, 1.0), (0.5, 1.2)],
        cycles=1,
        n_starts=n,
        arc=(-3.0, 3.0),
        reference=X0,
        chunk=256,
    )
    tracemalloc.start()
    for _task, _chunk in iter_atlas(plan):
        pass
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak


def test_streaming_memory_is_bounded_by_the_chunk_not_the_number_of_starts():
    """Streaming 32 times as many starts in chunks of 256 allocates no more at its peak (within
    60 kB for the allocator): a plan holds nothing of size N, chunks are dropped once read.
    Anything kept per start, even one float, would add 131 kB at 16384 starts."""
    small, large = _peak_streaming(512), _peak_streaming(16384)
    assert large < small + 60_000, (small, large)


def test_cancelled_stops_between_chunks():
    plan = small_plan(chunk=4)
    seen = []
    with pytest.raises(RunCancelled, match="after run 8 of 24"):
        run_atlas(
            plan,
            progress=ProgressCallbacks(
                on_advance=lambda done, total: seen.append(done),
                is_cancelled=lambda: len(seen) >= 2,
            ),
        )
    assert seen == [4, 8]


@pytest.mark.parametrize(
    ("kwargs", "field", "text"),
    [
        ({"cycles": 0}, "cycles", "cycles must be between 1 and 1000"),
        ({"chunk": 0}, "chunk", "chunk must be between 1"),
        ({"arc": (1.0, 2.0)}, "arc", "lo <= 0 <= hi"),
        ({"sampling": "sobol"}, "sampling", "'grid' or 'sample'"),
        ({"scales": [1.0, -2.0]}, "scales", "scales must be finite and > 0"),
        ({"shifts": [(0.0, 0.0, 1.0)]}, "shifts", "shape (..., 2)"),
        ({"scales": [1.0, 0.5, 1.0]}, "scales.2", "1 is given twice (entries 0 and 2)"),
        ({"shifts": [(0.0, 0.0), (0.1, 0.0), (0.1, 0.0)]}, "shifts.2", "(0.1, 0) is given twice"),
        ({"reference": (0.0, math.nan, 1.0)}, "reference", "NaN"),
        (
            {"box": [(-5.0, 5.0), (-5.0, 5.0), (2.0, 3.0)], "reference": (4.0, 4.0, 2.5)},
            "path",
            "the path's first point (0, 1) is out of reach in the box (x_range, joint limits): "
            "eq. (7) from the reference reaches it only where x3 = 3.82069 is not in [2, 3]",
        ),
        (  # (the reference itself outside the box: it is at fault, not the path)
            {"box": [(-5.0, 5.0), (-5.0, 5.0), (2.0, 3.0)]},
            "reference",
            "the reference (0, 0, 1.5708) lies outside the box (x_range, joint limits): eq. (7) "
            "from it reaches the path's first point (0, 1) only where x3 = 1.5708 is not in "
            "[2, 3]",
        ),
        ({"starts": [(0.0, 0.0, 1.0)]}, "starts.0", "not on the self-motion manifold"),
        ({"gamma": 0}, "gamma", "gamma must be > 0"),
        ({"mode": "discrete", "gamma": 2.5}, "gamma", "< 2 in discrete mode"),
    ],
)
def test_invalid_inputs_name_their_field(kwargs, field, text):
    with pytest.raises(InvalidInputError, match=re.escape(text)) as info:
        small_plan(**kwargs)
    assert info.value.field == field


@pytest.mark.parametrize(
    ("path", "text"), [([(0.0, 1.0)], "2 to 100 points"), ([(0.0, 1.0, 2.0)], "shape (..., 2)")]
)
def test_a_bad_path_is_named(path, text):
    with pytest.raises(InvalidInputError, match=re.escape(text)) as info:
        plan_atlas(manipulator2_inverses(), path, n_starts=2, arc=(0, 1), reference=X0)
    assert info.value.field == "path"


@pytest.mark.parametrize(
    ("path", "legs"),
    [
        (LOOP, 4),  # path[1:] and back to k(x)
        ([*LOOP, LOOP[0]], 4),  # a last point repeating the first is the return leg
        ([(0.0, 1.0), (1.0, 1.0)], 2),
        ([(0.0, 1.0), (0.0, 1.0)], 2),  # two points stay two, closed or not
    ],
)
def test_a_cycle_has_the_legs_of_its_open_loop(path, legs):
    """A plan's legs of a cycle are open_loop's points, the rule an API counts work by."""
    plan = plan_atlas(manipulator2_inverses(), path, n_starts=2, arc=(0, 1), reference=X0)
    assert plan.legs == len(open_loop(np.asarray(path, dtype=float))) == legs


def test_the_engine_does_not_import_dask():
    """Dask is imported when a Dask backend is entered, not before: an atlas in-process or in a
    process pool runs without it installed."""
    code = (
        "import sys, math\n"
        "from jik.engine.atlas import plan_atlas\n"
        "from jik.engine.atlas_run import run_atlas\n"
        "from jik.engine.atlas_backends import backend_for\n"
        "from jik.engine.inverses import Pseudoinverse\n"
        "from jik.engine.kinematics import Manipulator2\n"
        "backend_for('dask:local:2')\n"
        "plan = plan_atlas(Pseudoinverse(Manipulator2()), [(0, 1), (1, 1)], n_starts=2,\n"
        "                  arc=(-1, 1), reference=(0, 0, math.pi / 2))\n"
        "run_atlas(plan)\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("option", ["threads:2", "processes:0", "processes:x", "dask:local:0"])
def test_a_bad_backend_is_named(option):
    with pytest.raises(InvalidInputError) as info:
        backend_for(option)
    assert info.value.field == "backend"


def test_a_process_pool_holds_its_workers_memory_limit():
    """ProcessPool(memory_mb=...): a chunk too large for a worker raises MemoryError there
    (the server's atlas jobs use the compute workers' limit) instead of taking the machine."""
    from jik.engine.atlas_backends import ProcessPool

    with ProcessPool(1, memory_mb=512) as pool, pytest.raises(MemoryError):
        list(pool.imap_unordered(np.ones, [300_000_000]))  # (2.4 GB)
    with ProcessPool(1, memory_mb=512) as pool:
        assert [a.sum() for a in pool.imap_unordered(np.ones, [1000])] == [1000.0]


def test_a_posture_atlas_without_rest_pulls_each_panda_run_toward_its_start():
    """The Panda has a home; without rest the atlas's posture inverse still pulls each run
    toward its own start (batched): each run is the run of the posture inverse with rest = that
    start, and the drift is of the pseudoinverse's order, not the radians of a pull home."""
    from jik.engine.registry import make_inverse
    from jik.engine.robot_spec import robot_from_dict

    robot = robot_from_dict({"name": "panda", "task": "pose"})
    kin, x0 = robot.kinematics, np.asarray(robot.spec.default_x0, dtype=float)
    path = np.vstack([kin.forward(x0), np.asarray(robot.spec.default_path, dtype=float)])
    posture = make_inverse(kin, "posture", spec=robot.spec, algorithm_parameters={"gain": 2.0})
    pinv = make_inverse(kin, "pseudoinverse", spec=robot.spec)
    plan = plan_atlas([posture, pinv], path, cycles=3, n_starts=6, reference=x0, arc=(-1.0, 1.0))
    res = run_atlas(plan)
    drift = np.asarray(res.drift)[:, 0, :, -1]  # (algorithm, start) after the last cycle
    assert np.max(drift[0]) < 1e-2 and np.mean(drift[0]) < np.mean(drift[1])
    starts = plan.starts(0, plan.n_starts)
    for i, s in enumerate(starts):
        own = make_inverse(
            kin, "posture", spec=robot.spec, algorithm_parameters={"gain": 2.0, "rest": list(s)}
        )
        one = repeatability(own, s, plan.targets(i, i + 1, starts[i : i + 1])[0], 3, close=False)
        np.testing.assert_allclose(
            np.asarray(res.drift)[0, 0, i], np.asarray(one.drift), rtol=1e-8, atol=1e-12
        )


@pytest.mark.parametrize(
    ("seconds_per_run", "chunk", "probed"),
    [(0.2, 5, 1 + 5), (0.001, 1000, 1 + 8), (1e-5, 2048, 1 + 8), (4.0, 1, 1)],
)
def test_sized_chunks_hold_about_a_second_of_runs(monkeypatch, seconds_per_run, chunk, probed):
    """The chunk holds about a second of runs, timed on the plan's first runs (a unicycle run
    costs about 0.2 s, a Manipulator 2 run about a millisecond), at most the plan's own chunk
    (by default a sixteenth of the atlas, at most 2048): a server's compute workers serve
    requests between chunks, far within their time limit. The probe runs about a second too: a
    run of 4 s (a Gen3 far out of reach) is a chunk alone, with no more runs probed.
    (The runs' cost is simulated by a clock that each run advances.)"""
    now, runs = [0.0], []

    def run_chunk(task):
        now[0] += seconds_per_run * (task.hi - task.lo)
        runs.append(task.hi - task.lo)

    monkeypatch.setattr(atlas_run, "run_chunk", run_chunk)
    monkeypatch.setattr(atlas_run, "perf_counter", lambda: now[0])
    plan = plan_atlas(
        Pseudoinverse(Manipulator2()), LOOP, n_starts=3000, arc=(-1.0, 1.0), reference=X0
    )
    assert plan.chunk == 188  # (the default: 16 chunks, so that progress moves)
    assert atlas_run.sized_chunks(plan).chunk == min(chunk, 188)
    assert sum(runs) == probed
    assert atlas_run.sized_chunks(dataclasses.replace(plan, chunk=2048)).chunk == chunk


@pytest.mark.parametrize(
    ("shifts", "field", "words"),
    [
        (
            [[0.0, 0.0], [10.0, 10.0]],
            "shifts.1",
            "shifts[1] moves the path's first point to (11, 11), out of reach",
        ),
        ([[1e7, 1e7]], "shifts", "beyond 1e+06 in magnitude"),
    ],
)
def test_a_shift_that_moves_the_path_out_of_reach_is_named(shifts, field, words):
    """The family's paths share a shift's first point: a shift that moves it out of the arm's
    reach (a planar 3R chain reaches 3) is refused naming that shift, not the path."""
    from jik.engine.planar_chain import PlanarChain

    arm = PlanarChain("RRR", [1.0, 1.0, 1.0])
    with pytest.raises(InvalidInputError) as refused:
        plan_atlas(
            Pseudoinverse(arm),
            [(1.0, 1.0), (1.5, 1.0), (1.5, 1.5)],
            n_starts=4,
            arc=(-0.5, 0.5),
            reference=[0.3, 0.5, 0.7],
            shifts=shifts,
            scales=[1.0, 0.5],
        )
    assert refused.value.field == field and words in str(refused.value), refused.value


@pytest.mark.parametrize(
    ("shifts", "scales", "field", "words"),
    [
        (None, [1, 2, 30], "scales.2", "scales[2] moves the path's point 1 to"),
        ([[0] * 6, [0, 0, 0, 0, 0, 3.0]], None, "shifts.1", "shifts[1] moves the path's point 1"),
        ([[0] * 6, [0, 0, 0, 0, 0, 3.0]], [1, 2], "shifts.1", "shifts[1] moves the path's point 1"),
        (
            [[0] * 6, [0, 0, 0, 0, 0, 0.1]],
            [1, 30],
            "scales.1",
            "scales[1] moves the path's point 1",
        ),
    ],
)
def test_a_shift_or_scale_that_turns_a_pose_past_the_cut_is_named(shifts, scales, field, words):
    """A scale or a shift that moves a later point of a pose path past a half turn of its
    rotation coordinates is refused when the atlas is planned (not when its runs meet it),
    naming that scale or shift and the point; a scale is named when it alone does it."""
    panda = robot_from_dict({"name": "panda", "task": "pose"})
    home = panda.kinematics.forward(np.asarray(panda.spec.default_x0))
    path = [home + [0, 0, 0, 0, 0, rz] for rz in (0.0, 0.15, -0.1)]
    with pytest.raises(InvalidInputError) as refused:
        plan_atlas(
            panda.inverse("pseudoinverse"),
            path,
            starts=[panda.spec.default_x0],
            shifts=shifts,
            scales=scales,
        )
    assert refused.value.field == field and str(refused.value).startswith(words), refused.value
    assert "rotation coordinates (rx, ry, rz) have length" in str(refused.value)
