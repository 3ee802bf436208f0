import importlib
import math

import numpy as np
import pytest

from jik.engine.augmentations import E1Optimal, E2Optimal, PaperCubic
from jik.engine.exceptions import AlgorithmicSingularityError, InvalidInputError, RunCancelled
from jik.engine.inverses import ExtendedInverse, Pseudoinverse
from jik.engine.kinematics import Manipulator1, Manipulator2
from jik.engine.progress import ProgressCallbacks
from jik.engine.repeatability import Resume, repeatability
from jik.engine.solver import solve
from tests.helpers import count_picard_sweeps

RNG = np.random.default_rng(1983)


def random_closed_paths(kin, x0, n_points=3, radius=0.4):
    """Task points around k(x0); the return leg to k(x0) is appended by repeatability()."""
    return kin.forward(x0) + RNG.uniform(-radius, radius, (n_points, kin.r))


@pytest.mark.parametrize(
    ("kin", "h", "low", "high"),
    [
        (Manipulator1(), E2Optimal(), (0.0, 0.0, 0.5), (1.0, 1.0, 1.5)),
        (Manipulator1(), E1Optimal(), (0.0, 0.0, 0.5), (1.0, 1.0, 1.5)),
        (Manipulator2(), PaperCubic(), (-0.2, -0.2, 1.3), (0.2, 0.2, 1.8)),
    ],
    ids=["m1-e2_optimal", "m1-e1_optimal", "m2-paper_cubic"],
)
def test_extended_inverse_is_repeatable_on_random_closed_paths(kin, h, low, high):
    """Extended Jacobian: drift below 1e-8 after 10 cycles on random closed paths."""
    inv = ExtendedInverse(kin, h)
    x0 = RNG.uniform(low, high, (8, 3))
    paths = np.stack([random_closed_paths(kin, x) for x in x0])
    res = repeatability(inv, x0, paths, cycles=10)
    assert np.all(res.success), res.message
    assert res.drift.shape == (8, 10)
    assert res.drift.max() < 1e-8, res.drift


def test_pseudoinverse_drifts_on_table1_path_and_drift_grows():
    x0 = np.array([0, 0, math.pi / 2])
    res = repeatability(
        Pseudoinverse(Manipulator2()), x0, [(1, 1), (1, 2), (0, 2), (0, 1)], cycles=3
    )
    assert res.success
    assert res.drift[0] > 0.3 and np.all(np.diff(res.drift) > 0)
    assert res.legs.shape == (12, 3) and res.cycle_end.shape == (3, 3)


def test_return_leg_is_appended_when_path_is_open():
    kin = Manipulator2()
    x0 = np.array([0, 0, math.pi / 2])
    res = repeatability(ExtendedInverse(kin, PaperCubic()), x0, [(1, 1), (1, 2)], cycles=2)
    assert res.targets.shape == (3, 2)
    np.testing.assert_allclose(res.targets[-1], kin.forward(x0))
    assert res.legs.shape == (6, 3)


def test_batch_of_starts_matches_single_runs():
    kin = Manipulator1()
    inv = ExtendedInverse(kin, E2Optimal(0.5, 1.0))
    x0 = RNG.uniform(0, 1, (5, 3)) + [0, 0, 0.5]
    path = np.array([(0.5, 1.0), (0.8, 1.5)])
    batch = repeatability(inv, x0, path, cycles=2)
    for i in (0, 4):
        one = repeatability(inv, x0[i], path, cycles=2)
        np.testing.assert_allclose(batch.legs[i], one.legs, atol=1e-9)


def test_a_path_that_repeats_a_point_has_a_leg_of_no_length():
    """A leg from where the path already is: its solve records the start alone, and the next
    cycle does not take that as a guess (it was refused as "guess[0] must have ... m >= 2",
    found by schemathesis: the path [(3, -3), (3, -3), (3, 3)] of Manipulator 2)."""
    kin = Manipulator2()
    inv = ExtendedInverse(kin, PaperCubic())
    x0 = np.array([0.3, 0.5, 1.0])
    twice = [(1, 1), (1, 1), (1, 2)]
    once = repeatability(inv, x0, [(1, 1), (1, 2)], cycles=2)
    run = repeatability(inv, x0, twice, cycles=2)
    np.testing.assert_allclose(run.legs[[0, 2, 3, 5, 6, 7]], once.legs, atol=1e-9)
    np.testing.assert_array_equal(run.legs[1], run.legs[0])


@pytest.mark.parametrize("algorithm", ["pseudoinverse", "extended"])
def test_one_start_guesses_later_cycles_and_agrees_with_the_batch(algorithm, monkeypatch):
    """A single start guesses its legs (cycle_guesses); a batch does not. The legs agree to
    the sweep tolerance. The repeatable extended inverse runs its later cycles in one or two
    sweeps a leg (guessed by the cycle before), the pseudoinverse every leg (guessed by a chain
    of its cycle)."""
    kin = Manipulator2()
    inv = Pseudoinverse(kin) if algorithm == "pseudoinverse" else ExtendedInverse(kin, PaperCubic())
    x0 = np.array([0, 0, math.pi / 2])
    path = [(1, 1), (1, 2), (0, 2), (0, 1)]
    sweeps = count_picard_sweeps(monkeypatch)
    one = repeatability(inv, x0, path, cycles=3)
    monkeypatch.undo()
    batch = repeatability(inv, np.array([x0, x0]), path, cycles=3)
    np.testing.assert_allclose(one.legs, batch.legs[0], atol=1e-12)
    if algorithm == "extended":
        assert max(sweeps[4:]) <= 2 and sum(sweeps[:4]) >= 20, sweeps
    else:
        assert max(sweeps[:12]) <= 2, sweeps


def test_record_keeps_every_leg_trajectory():
    kin = Manipulator2()
    res = repeatability(Pseudoinverse(kin), [0, 0, math.pi / 2], [(1, 1), (0, 1)], record=True)
    assert len(res.leg_results) == 2
    np.testing.assert_allclose(res.leg_results[0].trajectory.y[-1], [1, 1], atol=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"cycles": 0}, "cycles must be between 1 and 1000"),
        ({"cycles": 1001}, "cycles must be between"),
        ({"path": np.zeros((101, 2))}, "at most 100"),
        ({"path": [[1, 2, 3]]}, "path must have shape"),
    ],
)
def test_bad_input(kwargs, match):
    args = {"path": [(1, 1)], "cycles": 1} | kwargs
    with pytest.raises(InvalidInputError, match=match):
        repeatability(Pseudoinverse(Manipulator2()), [0, 0, 1.0], args["path"], args["cycles"])


# -- the one engine loop's progress (legs, cancellation, a discrete leg's pieces), resume, stop --

TABLE1_X0 = np.array([0, 0, math.pi / 2])
TABLE1_PATH = [(1, 1), (1, 2), (0, 2), (0, 1)]


def _inverse(algorithm: str):
    if algorithm == "pseudoinverse":
        return Pseudoinverse(Manipulator2())
    return ExtendedInverse(Manipulator2(), PaperCubic())


def _same_legs(a, b) -> None:
    """Two SolveResults of a leg, bit for bit."""
    assert (a.success, a.nit, a.message) == (b.success, b.nit, b.message)
    np.testing.assert_array_equal(a.x, b.x)
    for name in ("theta", "x", "y", "error", "h"):
        np.testing.assert_array_equal(getattr(a.trajectory, name), getattr(b.trajectory, name))


def test_on_leg_sees_every_leg_in_order():
    """One start: every leg's SolveResult with its trajectory, the run's legs in order. A batch:
    each leg's BatchSolveResult and the members that ran it."""
    seen = []
    res = repeatability(
        _inverse("extended"),
        TABLE1_X0,
        TABLE1_PATH,
        cycles=2,
        record=True,
        progress=ProgressCallbacks(seen.append),
    )
    assert [(leg.cycle, leg.index) for leg in seen] == [(c, j) for c in range(2) for j in range(4)]
    for k, leg in enumerate(seen):
        assert leg.stopped_by is None and leg.members.tolist() == [0]
        assert leg.result is res.leg_results[k]
        np.testing.assert_array_equal(leg.result.x, res.legs[k])
        np.testing.assert_array_equal(leg.result.trajectory.x[-1], res.legs[k])
    starts = np.array([TABLE1_X0, TABLE1_X0 + [0.1, 0.0, 0.2], TABLE1_X0 - [0.0, 0.1, 0.1]])
    seen.clear()
    batch = repeatability(
        _inverse("pseudoinverse"), starts, TABLE1_PATH, progress=ProgressCallbacks(seen.append)
    )
    assert len(seen) == batch.legs.shape[1] == 5  # (the last point is not k(x0) for two of them)
    for k, leg in enumerate(seen):
        assert leg.members.tolist() == [0, 1, 2] and len(leg.result) == 3
        np.testing.assert_array_equal(leg.result.x, batch.legs[:, k])


@pytest.mark.parametrize("batch", [False, True])
def test_cancelled_stops_between_legs(batch):
    """progress.cancelled() is polled before every leg: True before the third raises
    RunCancelled there, after two legs."""
    polls, seen = [], []
    x0 = np.array([TABLE1_X0, TABLE1_X0]) if batch else TABLE1_X0
    progress = ProgressCallbacks(
        seen.append, is_cancelled=lambda: polls.append(1) or len(polls) == 3
    )
    with pytest.raises(RunCancelled, match="before cycle 1, leg 3"):
        repeatability(_inverse("extended"), x0, TABLE1_PATH, cycles=3, progress=progress)
    assert len(polls) == 3 and len(seen) == 2


def _chunks(monkeypatch, iterations: int) -> None:
    """Discrete legs with a progress run as solves of ``iterations`` iterations."""
    module = importlib.import_module("jik.engine.repeatability")

    monkeypatch.setattr(module, "POLL_ITERATIONS", iterations)


def test_cancelled_stops_between_the_chunks_of_a_discrete_leg(monkeypatch):
    _chunks(monkeypatch, 5)
    polls, fractions = [], []
    progress = ProgressCallbacks(
        on_advance=lambda done, total: fractions.append(done / total),
        is_cancelled=lambda: polls.append(1) or len(polls) == 4,
    )
    with pytest.raises(RunCancelled, match="in cycle 1, leg 1"):
        repeatability(
            _inverse("extended"),
            TABLE1_X0,
            TABLE1_PATH,
            gamma=0.3,
            mode="discrete",
            progress=progress,
        )
    assert len(polls) == 4 and len(fractions) == 2  # before the leg, then after chunks 1-3


@pytest.mark.parametrize("algorithm", ["pseudoinverse", "extended"])
@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"mode": "discrete", "gamma": 0.5},
        {"mode": "discrete", "gamma": 0.3, "progress": ProgressCallbacks()},
    ],
)
def test_resume_equals_a_run_from_the_start_bit_for_bit(algorithm, kwargs, monkeypatch):
    """Two cycles, then two more from their end (Resume.of: the legs and, in continuous mode,
    the last cycle's trajectories as Picard guides): the numbers of four cycles from x0 (with
    a progress in discrete mode: legs in pieces of 7 iterations)."""
    _chunks(monkeypatch, 7)
    inv = _inverse(algorithm)
    cold = repeatability(inv, TABLE1_X0, TABLE1_PATH, cycles=4, record=True, **kwargs)
    part = repeatability(inv, TABLE1_X0, TABLE1_PATH, cycles=2, record=True, **kwargs)
    seen = []
    kwargs = kwargs | {"progress": ProgressCallbacks(seen.append)}
    rest = repeatability(inv, Resume.of(part), TABLE1_PATH, cycles=4, record=True, **kwargs)
    assert cold.success and rest.success and rest.message == cold.message
    for name in ("legs", "cycle_end", "drift"):
        np.testing.assert_array_equal(getattr(rest, name), getattr(cold, name), name)
    assert [leg.cycle for leg in seen] == [2] * 4 + [3] * 4
    assert len(rest.leg_results) == 8
    for a, b in zip(rest.leg_results, cold.leg_results[8:], strict=True):
        _same_legs(a, b)


def test_resume_a_batch_equals_a_run_from_the_start():
    starts = np.random.default_rng(27).uniform(0, 1, (4, 3)) + [0, 0, 0.5]
    inv = ExtendedInverse(Manipulator1(), E2Optimal(0.5, 1.0))
    path = np.array([(0.5, 1.0), (0.8, 1.5)])
    cold = repeatability(inv, starts, path, cycles=3)
    part = repeatability(inv, starts, path, cycles=1)
    rest = repeatability(inv, Resume(starts, part.legs), path, cycles=3)
    np.testing.assert_array_equal(rest.legs, cold.legs)
    np.testing.assert_array_equal(rest.drift, cold.drift)


def test_discrete_chunks_equal_an_unchunked_run(monkeypatch):
    """Legs run as solves of 7 iterations (so that a caller can cancel between them) give the
    iterates, counts and messages of one solve per leg; the progress grows within a leg."""
    _chunks(monkeypatch, 7)
    inv = _inverse("extended")
    one = repeatability(
        inv, TABLE1_X0, TABLE1_PATH, cycles=2, gamma=0.3, mode="discrete", record=True
    )
    fractions: list[float] = []
    chunked = repeatability(
        inv,
        TABLE1_X0,
        TABLE1_PATH,
        cycles=2,
        gamma=0.3,
        mode="discrete",
        record=True,
        progress=ProgressCallbacks(on_advance=lambda d, t: fractions.append(d)),
    )
    assert one.success and chunked.message == one.message
    np.testing.assert_array_equal(chunked.legs, one.legs)
    np.testing.assert_array_equal(chunked.drift, one.drift)
    for a, b in zip(chunked.leg_results, one.leg_results, strict=True):
        _same_legs(a, b)
    assert len(fractions) == sum(-(-r.nit // 7) - 1 for r in one.leg_results) > 0
    assert all(0 <= f <= 0.99 for f in fractions)


def test_a_leg_that_raises_stops_the_run_with_the_legs_before_it(monkeypatch):
    """A progress that stops at errors: a leg whose solve raises (here the second, patched to)
    ends the run there: the legs before it are kept, the stopped leg is its start alone, the
    message names it. By default (no progress, or one that does not stop) the error
    propagates."""
    module = importlib.import_module("jik.engine.repeatability")

    calls = []
    original = module.solve

    def second_raises(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise AlgorithmicSingularityError("h is undefined here", args[1])
        return original(*args, **kwargs)

    monkeypatch.setattr(module, "solve", second_raises)
    inv = _inverse("extended")
    seen = []
    res = repeatability(
        inv,
        TABLE1_X0,
        TABLE1_PATH,
        cycles=2,
        record=True,
        progress=ProgressCallbacks(seen.append, stop_at_error=True),
    )
    assert not res.success
    assert res.message.startswith("cycle 1, leg 2 stopped: h is undefined here at x = ")
    assert np.all(np.isfinite(res.legs[0])) and np.all(np.isnan(res.legs[1:]))
    assert len(seen) == 2 and seen[1].stopped_by is not None
    stop = seen[1].result
    assert not stop.success and stop.nit == 0 and stop.message == str(seen[1].stopped_by)
    assert stop.status == "raised" and seen[0].result.status == "converged"
    np.testing.assert_array_equal(stop.trajectory.x, res.legs[:1])
    np.testing.assert_array_equal(stop.trajectory.theta, [0.0])
    assert stop.trajectory.h is not None and len(res.leg_results) == 2
    for progress in (None, ProgressCallbacks(seen.append)):
        calls.clear()
        with pytest.raises(AlgorithmicSingularityError, match="h is undefined here"):
            repeatability(inv, TABLE1_X0, TABLE1_PATH, cycles=2, progress=progress)


def test_a_singular_start_stops_the_first_leg():
    """(36) with a = 1, b = 0 is singular on x1 = 0: a run from there stops before it moves."""
    inv = ExtendedInverse(Manipulator1(), E2Optimal(a=1.0, b=0.0))
    stop = ProgressCallbacks(stop_at_error=True)
    for kwargs in ({}, {"mode": "discrete", "gamma": 0.5}):
        with pytest.raises(AlgorithmicSingularityError):
            repeatability(inv, [0.0, 0.2, 1.0], [(1.0, 1.0)], **kwargs)
        res = repeatability(inv, [0.0, 0.2, 1.0], [(1.0, 1.0)], progress=stop, **kwargs)
        assert not res.success and res.message.startswith("cycle 1, leg 1 stopped: the extended")
        assert np.all(np.isnan(res.legs))
    # A batch's legs are one solve for all starts: its errors propagate whatever the progress.
    with pytest.raises(AlgorithmicSingularityError):
        repeatability(inv, [[0.0, 0.2, 1.0], [0.5, 0.2, 1.0]], [(1.0, 1.0)], progress=stop)


def test_open_legs_are_solves_to_their_targets():
    """close=False: the path's points as given, no return leg (one leg: one solve)."""
    inv = _inverse("pseudoinverse")
    res = repeatability(inv, TABLE1_X0, [(1, 1)], close=False, record=True)
    assert res.targets.shape == (1, 2)
    _same_legs(res.leg_results[0], solve(inv, TABLE1_X0, [1, 1]))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"resume": "legs", "cycles": 3}, r"whole cycles of 4 legs"),
        ({"resume": "legs", "cycles": 1}, r"1 to 1 whole cycles"),
        ({"resume": "nan", "cycles": 3}, "resume.legs contains NaN"),
        ({"resume": "guides", "cycles": 3}, "one trajectory .or None. per leg, 4"),
    ],
)
def test_a_bad_resume_is_refused(kwargs, match):
    legs = np.tile(TABLE1_X0, (8, 1))
    kwargs = dict(kwargs)
    resume = {
        "legs": Resume(TABLE1_X0, legs[:7] if kwargs.get("cycles") == 3 else legs),
        "nan": Resume(TABLE1_X0, np.where(legs > 1, np.nan, legs)),
        "guides": Resume(TABLE1_X0, legs, [None]),
    }[kwargs.pop("resume")]
    with pytest.raises(InvalidInputError, match=match):
        repeatability(_inverse("pseudoinverse"), resume, TABLE1_PATH, **kwargs)


def test_repeatable_judges_the_cycles_that_ended():
    """Every finite drift below REPEATABLE_DRIFT: repeatable; one above: not; the NaN of the
    cycles after a failed leg are not judged; no cycle ended: no verdict (None)."""
    from jik.engine.repeatability import REPEATABLE_DRIFT, repeatable

    assert repeatable([1e-13, 2e-12]) is True
    assert repeatable([1e-13, 10 * REPEATABLE_DRIFT]) is False
    assert repeatable([1e-13, np.nan, np.nan]) is True
    assert repeatable([np.nan]) is None and repeatable([]) is None
    ext = repeatability(_inverse("extended"), TABLE1_X0, TABLE1_PATH, cycles=2)
    pinv = repeatability(_inverse("pseudoinverse"), TABLE1_X0, TABLE1_PATH, cycles=2)
    assert repeatable(ext.drift) is True and repeatable(pinv.drift) is False


@pytest.mark.parametrize("algorithm", ["pseudoinverse", "extended"])
def test_a_leg_is_capped_as_its_solve_is(algorithm):
    """max_iterations bounds a leg of a single start's run as it bounds the leg's solve: the
    chain that guesses a cycle's legs sweeps no more often than a leg may step. A cap that
    the first leg's solve cannot meet stops the run there; the default cap gives the run."""
    kin = Manipulator2()
    inv = Pseudoinverse(kin) if algorithm == "pseudoinverse" else ExtendedInverse(kin, PaperCubic())
    x0 = np.array([0, 0, math.pi / 2])
    path = [(1, 1), (1, 2), (0, 2), (0, 1)]
    leg = solve(inv, x0, path[0], max_iterations=3)
    assert leg.status == "max_steps"
    run = repeatability(inv, x0, path, cycles=2, max_iterations=3)
    assert not run.success
    assert run.message.startswith("cycle 1, leg 1"), run.message
    assert repeatability(inv, x0, path, cycles=2).success


def test_a_failed_leg_says_where_it_stopped():
    """A run stopped by a failed leg keeps no leg end for it (NaN), but says where the leg
    stopped (stopped, as_dict's stopped_at): the extended inverse's stall at an algorithmic
    singularity of Manipulator 2, 2.7e-4 from its start. A batch says it per start (NaN for
    the starts that completed)."""
    inv = ExtendedInverse(Manipulator2(), PaperCubic())
    x0, path = np.array([0.0, -0.69, 0.675]), [(1, 1), (1, 2), (0, 2), (0, 1)]
    run = repeatability(inv, x0, path)
    assert not run.success and np.isnan(run.legs[0]).all()
    assert run.message.startswith("cycle 1, leg 1 failed: stalled")
    assert 1e-4 < np.linalg.norm(run.stopped - x0) < 1e-3
    assert run.as_dict()["stopped_at"] == run.stopped.tolist()
    # (h after a failed leg is not known: NaN, None in JSON; at x0 it is)
    assert (
        run.as_dict()["h"][0] == pytest.approx(float(inv.augmenting_value(x0)))
        and None in (run.as_dict()["h"])
    )
    batch = repeatability(inv, np.array([x0, [0.0, 0.0, math.pi / 2]]), path)
    assert list(batch.success) == [False, True]
    np.testing.assert_allclose(batch.stopped[0], run.stopped, atol=1e-9)
    assert np.isnan(batch.stopped[1]).all()


def test_a_resume_whose_legs_miss_their_targets_is_refused():
    """A Resume's legs must be legs of this run: configurations that do not reach the path's
    targets (here zeros, k = (1, 0)) are refused, not taken as cycles done."""
    inv, x0 = Pseudoinverse(Manipulator2()), [0.0, 0.0, math.pi / 2]
    path = [(1, 1), (1, 2), (0, 2)]
    with pytest.raises(InvalidInputError, match=r"resume.legs\[2\] ends 2.24 from its target"):
        repeatability(inv, Resume(x0, np.zeros((4, 3))), path, cycles=2)
    first = repeatability(inv, x0, path)
    resumed = repeatability(inv, Resume(x0, first.legs), path, cycles=3)
    np.testing.assert_allclose(resumed.drift, repeatability(inv, x0, path, cycles=3).drift)


def test_the_json_of_a_run_holds_h_after_every_leg():
    """eq. (12)'s evidence goes with the numbers: the extended inverse's as_dict holds h at x0
    and after each leg, constant to round-off; an inverse without a map has none."""
    x0, path = [0.0, 0.0, math.pi / 2], [(1, 1), (1, 2), (0, 2)]
    ext = repeatability(ExtendedInverse(Manipulator2(), PaperCubic()), x0, path, cycles=2)
    h = np.asarray(ext.as_dict()["h"])
    assert h.shape == (1 + 2 * 4,) and np.ptp(h) < 1e-12
    assert repeatability(Pseudoinverse(Manipulator2()), x0, path).as_dict()["h"] is None
