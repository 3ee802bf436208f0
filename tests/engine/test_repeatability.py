import math

import numpy as np
import pytest

from jik.engine.augmentations import E1Optimal, E2Optimal, PaperCubic
from jik.engine.exceptions import InvalidInputError
from jik.engine.inverses import ExtendedInverse, Pseudoinverse
from jik.engine.kinematics import Manipulator1, Manipulator2
from jik.engine.repeatability import repeatability
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
