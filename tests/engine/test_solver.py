import math

import numpy as np
import pytest

from jik.engine.augmentations import E2Optimal, PaperCubic
from jik.engine.exceptions import AlgorithmicSingularityError, InvalidInputError
from jik.engine.inverses import ExtendedInverse, Pseudoinverse
from jik.engine.kinematics import Manipulator1, Manipulator2
from jik.engine.reproductions.table1 import (
    ERRATUM,
    PATH,
    PRINTED,
    ROWS_NOTE,
    corner_letters,
    differing,
    is_experiment,
    not_table1,
    notes,
    row_labels,
)
from jik.engine.reproductions.table1 import run as table1
from jik.engine.solver import solve, solve_batch

X0 = np.array([0.0, 0.0, math.pi / 2])


def test_table1_pseudoinverse_column_to_four_decimals():
    """Table 1's pseudoinverse column, all twelve printed numbers."""
    rows = np.array(table1()["pseudoinverse"])
    np.testing.assert_allclose(rows, PRINTED["pseudoinverse"], atol=5e-5)


def test_table1_extended_column_closes_the_path():
    rows = np.array(table1()["extended"])
    np.testing.assert_allclose(rows[-1], X0, atol=1e-9)


def test_table1_cells_that_differ_from_the_print_in_the_fourth_decimal():
    """The pseudoinverse's twelve numbers print as the paper's; the cubic (38)'s first two
    leg ends differ in every coordinate (docs/paper-errata.md), x0 and the last two do not;
    a second cycle's rows are not compared, and a cell off by 1e-4 is."""
    result = table1()
    assert not differing("pseudoinverse", result["pseudoinverse"]).any()
    mask = differing("extended", result["extended"] + result["extended"][1:])
    np.testing.assert_array_equal(mask, [[r in (1, 2)] * 3 for r in range(5)])
    off = np.array(PRINTED["pseudoinverse"][:2])
    off[1, 2] += 1e-4
    np.testing.assert_array_equal(differing("pseudoinverse", off), [[0, 0, 0], [0, 0, 1]])
    with pytest.raises(InvalidInputError, match="algorithm must be one of") as info:
        differing("posture", result["pseudoinverse"])
    assert info.value.field == "algorithm"


def test_table1_notes_count_the_differing_cells_and_say_what_the_settings_change():
    """Under jik's columns beside the print: the count of differing cells (the cubic (38)'s
    six), the labels, the other algorithms' columns, the erratum or the map used instead, and
    how far a discrete run (or one that stopped before a cycle) ends from the print."""
    result = table1()
    said = notes(result, "paper_cubic", "continuous", 1.0, others="DLS")
    assert "(pseudoinverse: 0 of 15, extended Jacobian: 6 of 15)" in said[0]
    assert said[1:4] == [ROWS_NOTE, said[2], ERRATUM] and said[2].startswith(
        "Then jik's columns of DLS"
    )
    assert said[-1].startswith("Continuous mode, as in the paper")
    off = {a: np.asarray(PRINTED[a]) + 0.01 for a in PRINTED}
    said = notes(off, "e2_synthesized", "discrete", 0.5)
    assert "augmenting map e2_synthesized;" in said[2]
    assert "step γ = 0.5 ends its legs elsewhere (up to 0.01 from the printed values)" in said[-1]
    short = {a: np.asarray(PRINTED[a])[:2] for a in PRINTED}
    assert "stopped before the end of the first cycle" in notes(short, "h", "discrete", 1.0)[-1]


def test_a_table_of_leg_ends_says_why_it_is_not_table1():
    assert not_table1(True, "J^P# and J^E#") == (
        "Not Table 1: the paper's Table 1 compares J^P# and J^E# on this experiment; choose "
        "both to compare with the printed values."
    )
    assert "from x0 = (0, 0, π/2) on the closed path (1, 1), (1, 2)" in not_table1(False, "")


def test_corner_letters_start_at_k_x0_on_a_closed_path_as_table1_does():
    """Table 1's path (1, 1), (1, 2), (0, 2), (0, 1) from k(x0) = (0, 1): A is the start, so
    the corners are B, C, D, A; a path that does not close there, or one target, from A."""
    assert corner_letters(PATH, (0.0, 1.0), closed=True) == ["B", "C", "D", "A"]
    assert corner_letters(PATH, (0.0, 1.0), closed=False) == ["A", "B", "C", "D"]
    assert corner_letters(PATH[:3], (0.0, 1.0), closed=True) == ["A", "B", "C"]
    assert corner_letters(np.zeros((28, 2)), (5.0, 5.0), True)[25:] == ["Z", "P27", "P28"]


def test_table1_erratum_states_what_the_cubic_38_gives():
    """The erratum's first leg ends are run()'s, with (38)'s exact gradient and with the printed
    j32, j33 of (39), to the four decimals it prints; the rows' labels are the paper's."""
    for printed_gradient in (False, True):
        leg = table1(printed_gradient)["extended"][1]
        assert "(" + ", ".join(f"{v:.4f}" for v in leg) + ")" in ERRATUM
    assert row_labels(5) == ["A  x0", "B  x1f", "C  x2f", "D  x3f", "A  x4f"]
    assert row_labels(7)[5:] == ["B  x5f", "C  x6f"]
    assert row_labels(0) == []


def test_table1_experiment_is_its_arm_start_and_path():
    """Table 1's run: l = 1, x0 = (0, 0, pi/2), the closed path; not another of these."""
    assert is_experiment(1.0, X0, PATH)
    assert not is_experiment(1.5, X0, PATH)
    assert not is_experiment(1.0, X0 + [0.1, 0, 0], PATH)
    assert not is_experiment(1.0, X0, PATH[:3])
    assert not is_experiment(1.0, X0, np.add(PATH, 0.01))
    assert not is_experiment(1.0, X0[:2], PATH)  # (another robot's start: not an error)


@pytest.mark.parametrize("gamma", [0.05, 1.0, 30.0])
def test_continuous_result_does_not_depend_on_gamma(gamma):
    """gamma only rescales theta: same end point, theta scaled by 1/gamma."""
    inv = Pseudoinverse(Manipulator2())
    ref = solve(inv, X0, [1, 1], gamma=1.0)
    res = solve(inv, X0, [1, 1], gamma=gamma)
    np.testing.assert_allclose(res.x, ref.x, atol=1e-12)
    np.testing.assert_allclose(res.trajectory.theta * gamma, ref.trajectory.theta, rtol=1e-12)


def test_continuous_error_decays_exponentially_eq5():
    """Along (7) the task error obeys e(theta) = e0 exp(-gamma theta), eq. (5)."""
    res = solve(Pseudoinverse(Manipulator2()), X0, [0, 2], gamma=2.0)
    tr = res.trajectory
    assert res.success and res.error < 1e-10
    np.testing.assert_allclose(
        tr.error, tr.error[0] * np.exp(-2.0 * tr.theta), rtol=1e-7, atol=1e-12
    )


def test_extended_conserves_h_along_continuous_flow():
    res = solve(ExtendedInverse(Manipulator2(), PaperCubic()), X0, [1, 1])
    assert res.success
    np.testing.assert_allclose(res.trajectory.h, res.trajectory.h[0], atol=1e-10)


def test_discrete_mode_approaches_continuous_as_gamma_goes_to_zero():
    """x <- x - gamma J# e is Euler's method for (7): its end point error is O(gamma)."""
    inv = Pseudoinverse(Manipulator2())
    ref = solve(inv, X0, [1, 1]).x
    gaps = []
    for gamma in (0.2, 0.1, 0.05, 0.025):
        res = solve(inv, X0, [1, 1], gamma=gamma, mode="discrete", max_iterations=5000)
        assert res.success, res.message
        gaps.append(np.linalg.norm(res.x - ref))
    ratios = np.array(gaps[:-1]) / np.array(gaps[1:])
    assert np.all(ratios > 1.8) and np.all(ratios < 2.2), gaps
    assert gaps[-1] < 5e-3


def test_discrete_newton_step_converges_fast():
    res = solve(Pseudoinverse(Manipulator2()), X0, [1, 1], gamma=1.0, mode="discrete")
    assert res.success and res.nit < 10 and res.error < 1e-10


def test_already_at_target_no_motion():
    """Already at the target: no motion."""
    kin = Manipulator2()
    res = solve(Pseudoinverse(kin), X0, kin.forward(X0))
    assert res.success and res.nit == 0 and "no motion" in res.message
    np.testing.assert_array_equal(res.x, X0)


def test_batch_equals_individual_solves():
    kin = Manipulator1()
    inv = ExtendedInverse(kin, E2Optimal(0.2, 1.0))
    rng = np.random.default_rng(5)
    x0 = rng.uniform(0, 1, (7, 3))
    yd = kin.forward(x0) + rng.uniform(-0.5, 0.5, (7, 2))
    batch = solve_batch(inv, x0, yd)
    assert np.all(batch.success)
    for i in range(7):
        one = solve(inv, x0[i], yd[i])
        np.testing.assert_allclose(batch.x[i], one.x, atol=1e-9)
        tr = batch[i].trajectory
        np.testing.assert_allclose(tr.x[-1], batch.x[i])
        assert tr.theta[0] == 0 and np.all(np.diff(tr.theta) > 0)


def test_a_batch_member_counted_from_the_end_is_that_member_with_its_trajectory():
    """batch[-1] is batch[n - 1], trajectory and all, as for a list; past the end, IndexError."""
    kin = Manipulator2()
    x0 = np.array([X0, [0.1, 0.2, 1.4], [0.3, 0.1, 1.2]])
    batch = solve_batch(Pseudoinverse(kin), x0, [1, 1])
    last, first = batch[-1], batch[-3]
    np.testing.assert_array_equal(last.trajectory.x, batch[2].trajectory.x)
    np.testing.assert_array_equal(batch.trajectory(-2).x, batch.trajectory(1).x)
    np.testing.assert_array_equal(first.x0, x0[0])
    assert len(last.trajectory.x) > 2 and [r.x0[0] for r in batch] == [0.0, 0.1, 0.3]
    with pytest.raises(IndexError, match="member 3 of a batch of 3 solves"):
        batch[3]
    with pytest.raises(IndexError):
        batch.trajectory(-4)


@pytest.mark.parametrize("key", [slice(1, None), slice(None, None, -1), slice(0, 3, 2)])
@pytest.mark.parametrize("record", [True, False])
def test_a_slice_of_a_batch_is_the_batch_of_those_members(key, record):
    """batch[1:] is a BatchSolveResult of those members (it raised TypeError), each the same
    SolveResult, trajectory and all, as the whole batch's member; an empty slice, none."""
    kin = Manipulator2()
    x0 = np.array([X0, [0.1, 0.2, 1.4], [0.3, 0.1, 1.2]])
    batch = solve_batch(Pseudoinverse(kin), x0, [[1, 1], [1, 2], [0, 2]], record=record)
    part, members = batch[key], range(3)[key]
    assert isinstance(part, type(batch)) and len(part) == len(members)
    for k, i in enumerate(members):
        assert part[k].message == batch[i].message and part[k].status == batch[i].status
        np.testing.assert_array_equal(part[k].x0, x0[i])
        np.testing.assert_array_equal(part[k].x, batch[i].x)
        if record:
            np.testing.assert_array_equal(part[k].trajectory.x, batch[i].trajectory.x)
            np.testing.assert_array_equal(part[k].trajectory.error, batch[i].trajectory.error)
        else:
            assert part[k].trajectory is None
    assert len(batch[5:]) == 0


def test_iteration_cap_gives_failure_with_message():
    res = solve(
        Pseudoinverse(Manipulator2()), X0, [1, 1], gamma=0.01, mode="discrete", max_iterations=3
    )
    assert not res.success and res.status == "max_steps"
    assert "did not converge within 3 iterations" in res.message
    assert solve(Pseudoinverse(Manipulator2()), X0, [1, 1]).status == "converged"


@pytest.mark.parametrize("cap", [1, 3, 10])
def test_the_continuous_cap_counts_picard_sweeps_and_dop853_steps_together(cap):
    """max_iterations caps a continuous solve's steps (Picard's sweeps, then DOP853's steps
    for the members Picard leaves): 40 seeded targets of Manipulator 2, none past the cap, and
    the message counts what nit says (DOP853 got a cap of its own: nit reached twice it)."""
    rng = np.random.default_rng(5)
    targets = rng.uniform(-1.5, 1.5, (40, 2))
    for inv in (Pseudoinverse(Manipulator2()), ExtendedInverse(Manipulator2(), PaperCubic())):
        batch = solve_batch(inv, np.tile(X0, (40, 1)), targets, max_iterations=cap)
        nit = np.array([r.nit for r in batch])
        assert nit.max() <= cap
        stopped = [r for r in batch if r.status == "max_steps"]
        assert stopped and all(r.nit == cap for r in stopped)
        assert all(f"within {cap} step" in r.message for r in stopped)


def test_unreachable_pass_through_algorithmic_singularity_stops_with_message():
    """(36) with a = 1, b = 0 is singular on x1 = 0: driving x1 across 0 must stop, not hang;
    where it stops, h is defined and [J; dh] singular: status "singular", not "undefined"."""
    inv = ExtendedInverse(Manipulator1(), E2Optimal(a=1.0, b=0.0))
    res = solve(inv, [0.5, 0.2, 1.0], [-0.5, 0.2])
    assert not res.success and res.status in ("singular", "stalled")
    assert "singular" in res.message or "stalled" in res.message
    assert solve(inv, [0.5, 0.2, 1.0], [-0.5, 0.2], mode="discrete", gamma=0.5).status == (
        "singular"
    )


@pytest.mark.parametrize(
    "kwargs",
    [{}, {"method": "picard"}, {"method": "dop853"}, {"mode": "discrete", "gamma": 0.5}],
)
def test_singular_start_raises_typed_error(kwargs):
    """Continuous Picard finds a singular start in its first sweep (it evaluates J# there);
    DOP853 alone and discrete mode check it first."""
    inv = ExtendedInverse(Manipulator1(), E2Optimal(a=1.0, b=0.0))
    with pytest.raises(AlgorithmicSingularityError, match=r"x = \(0, 0.2, 1\)"):
        solve(inv, [0.0, 0.2, 1.0], [1.0, 1.0], **kwargs)
    # in a batch, moving or already at its target
    at_target = inv.kinematics.forward(np.array([0.0, 0.2, 1.0]))
    for y in ([1.0, 1.0], at_target):
        with pytest.raises(AlgorithmicSingularityError, match=r"x = \(0, 0.2, 1\)"):
            solve_batch(inv, [[0.5, 0.5, 1.0], [0.0, 0.2, 1.0]], [[1.0, 1.0], y], **kwargs)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"x0": [0, 0]}, "x0 must have shape"),
        ({"x0": [0, np.nan, 1]}, "x0 contains NaN"),
        ({"y_d": [1, 2, 3]}, "target y_d must have shape"),
        ({"y_d": [np.inf, 1]}, "NaN or infinite"),
        ({"gamma": 0}, "gamma must be > 0"),
        ({"gamma": -1}, "gamma must be > 0"),
        ({"gamma": 2.5, "mode": "discrete"}, "gamma must be < 2"),
        ({"gamma": 2e6}, "gamma must be between 1e-06 and 1e"),
        ({"mode": "magic"}, "mode must be"),
        ({"x0": [X0, X0]}, r"solve takes one start x0 \(p,\).*solve_batch"),
        ({"y_d": [[1, 1]]}, r"shapes \(3,\) and \(1, 2\); solve_batch solves a batch"),
        ({"tol": 0}, "tol must be > 0"),
        ({"max_iterations": 0}, "max_iterations must be between"),
    ],
)
def test_bad_input_is_rejected_with_a_clear_message(kwargs, match):
    args = {"x0": X0, "y_d": [1, 1]} | kwargs
    with pytest.raises(InvalidInputError, match=match):
        solve(Pseudoinverse(Manipulator2()), args.pop("x0"), args.pop("y_d"), **args)


@pytest.mark.parametrize("method", ["picard", "dop853"])
def test_methods_agree(method):
    """Chebyshev-Picard and DOP853 follow the same trajectory of (7)."""
    inv = ExtendedInverse(Manipulator2(), PaperCubic())
    ref = solve(inv, X0, [1, 2], method="auto")
    res = solve(inv, X0, [1, 2], method=method)
    assert res.success
    np.testing.assert_allclose(res.x, ref.x, atol=1e-9)


def test_unknown_method_is_rejected():
    with pytest.raises(InvalidInputError, match="method must be"):
        solve(Pseudoinverse(Manipulator2()), X0, [1, 1], method="euler")


UNICYCLE_START = [0.5, -0.25, 0.3, -0.25]
UNICYCLE_TARGET = [1.0, 0.0, -math.pi / 2]


def test_undefined_h_at_a_trial_point_does_not_abort_the_run():
    """The map raises where h is undefined, but trial points of the integrator must not:
    from pose A the continuous extended run converges with h conserved."""
    from jik.engine.registry import make_inverse, robot_spec

    kin = robot_spec("unicycle").build(q0=[5.0, 0.0, math.pi / 2])
    res = solve(make_inverse(kin, "extended"), UNICYCLE_START, UNICYCLE_TARGET, gamma=0.1)
    assert res.success, res.message
    np.testing.assert_allclose(res.trajectory.h, res.trajectory.h[0], atol=1e-9)


def test_run_into_undefined_h_stops_with_message_and_nan():
    """From pose B the discrete extended run leaves the domain of h: stop, say why, NaN h; its
    status "undefined" (J^E# undefined because h is, not [J; dh] singular), alone or in
    chunks."""
    from jik.engine.registry import make_inverse, robot_spec
    from jik.engine.solve_chunks import solve_in_chunks

    kin = robot_spec("unicycle").build(q0=[-5.0, 5.0, math.pi / 2])
    inverse = make_inverse(kin, "extended")
    res = solve(inverse, UNICYCLE_START, UNICYCLE_TARGET, gamma=0.1, mode="discrete")
    assert not res.success and res.status == "undefined"
    chunks = solve_in_chunks(inverse, UNICYCLE_START, UNICYCLE_TARGET, chunk=5, gamma=0.1)
    assert chunks.status == "undefined"
    assert "'characteristics' is undefined" in res.message and "stopped" in res.message
    assert np.isnan(res.trajectory.h[-1]) and np.all(np.isfinite(res.trajectory.h[:-1]))


# -- warm start (guess): the same fixed point, fewer Picard sweeps ------------------------------


def test_guess_of_the_same_leg_gives_the_same_path_in_one_or_two_sweeps():
    """The extended inverse is repeatable: a closed path's second cycle repeats the first, and
    with the first cycle's leg as its guess a leg takes one or two sweeps instead of ~ten."""
    inv = ExtendedInverse(Manipulator2(), PaperCubic())
    cold = solve(inv, X0, [1, 2])
    warm = solve(inv, X0, [1, 2], guess=cold.trajectory)
    assert cold.nit >= 6 and warm.nit <= 2, (cold.nit, warm.nit)
    assert warm.success
    np.testing.assert_allclose(warm.x, cold.x, atol=1e-12)
    np.testing.assert_allclose(warm.trajectory.theta, cold.trajectory.theta, atol=1e-12)
    np.testing.assert_allclose(warm.trajectory.x, cold.trajectory.x, atol=1e-12)


@pytest.mark.parametrize("shift", [1e-3, 0.1, 0.6])
@pytest.mark.parametrize("algorithm", ["pseudoinverse", "extended"])
def test_guess_from_a_nearby_or_distant_start_changes_nothing_but_the_work(algorithm, shift):
    """Picard only starts from the guess: its convergence and resolution tests are the cold
    start's, so the end point agrees to the sweep tolerance however good the guess is."""
    kin = Manipulator2()
    inv = Pseudoinverse(kin) if algorithm == "pseudoinverse" else ExtendedInverse(kin, PaperCubic())
    other = solve(inv, X0 + shift, [1.0 - shift, 2.0])
    cold = solve(inv, X0, [1, 2])
    warm = solve(inv, X0, [1, 2], guess=other.trajectory)
    assert warm.success
    np.testing.assert_allclose(warm.x, cold.x, atol=1e-11)
    np.testing.assert_allclose(kin.forward(warm.x), [1, 2], atol=1e-10)


def test_guess_with_another_gamma_is_harmless():
    """The guess's theta is read with this solve's gamma: a wrong one matches no node, and the
    solve starts cold."""
    inv = Pseudoinverse(Manipulator2())
    cold = solve(inv, X0, [1, 2])
    warm = solve(inv, X0, [1, 2], gamma=3.0, guess=cold.trajectory)
    assert warm.nit == cold.nit
    np.testing.assert_allclose(warm.x, cold.x, atol=1e-12)


def test_guess_per_member_in_a_batch():
    inv = ExtendedInverse(Manipulator2(), PaperCubic())
    starts = np.array([X0, X0 + 0.05])
    cold = solve_batch(inv, starts, [1, 2])
    warm = solve_batch(inv, starts, [1, 2], guess=[cold.trajectory(0), None])
    assert warm.nit[0] <= 2 and warm.nit[1] == cold.nit[1]
    np.testing.assert_allclose(warm.x, cold.x, atol=1e-12)


@pytest.mark.parametrize(
    ("guess", "kwargs", "match"),
    [
        ("good", {"mode": "discrete"}, "continuous mode only"),
        ([None, None], {}, "2 trajectories for 1 start"),
        ("text", {}, r"guess\[0\] must be a Trajectory"),
        ("short", {}, r"x of shape \(m, 3\), m >= 2"),
        ("nan", {}, "NaN or infinite"),
        ("backwards", {}, "theta must be increasing"),
    ],
)
def test_bad_guess_is_rejected_with_a_clear_message(guess, kwargs, match):
    from dataclasses import replace

    inv = Pseudoinverse(Manipulator2())
    tr = solve(inv, X0, [1, 2]).trajectory
    bad = (
        {
            "good": tr,
            "text": ["not a trajectory"],
            "short": replace(tr, x=tr.x[:, :2]),
            "nan": replace(tr, x=np.where(np.arange(len(tr.x))[:, None] == 3, np.nan, tr.x)),
            "backwards": replace(tr, theta=tr.theta[::-1]),
        }.get(guess, guess)
        if isinstance(guess, str)
        else guess
    )
    with pytest.raises(InvalidInputError, match=match):
        solve_batch(inv, X0, [1, 2], guess=bad, **kwargs)


# Table 1's closed path (sec. 5.2) from X0, three cycles: 12 legs, each from the end of the last.
TABLE1_LEGS = np.tile([[1.0, 1.0], [1.0, 2.0], [0.0, 2.0], [0.0, 1.0]], (3, 1))


@pytest.mark.parametrize("gamma", [1.0, 0.5])
@pytest.mark.parametrize("algorithm", ["pseudoinverse", "extended"])
def test_chain_guesses_give_each_leg_in_one_or_two_sweeps_and_the_same_path(
    algorithm, gamma, monkeypatch
):
    """chain_guesses sweeps the legs of a closed path together; solved one after another from
    them, each leg takes one or two sweeps (about ten cold for the pseudoinverse) and ends where
    the cold solve ends, to the sweep tolerance; its trajectory is the cold one."""
    from jik.engine.picard_guesses import chain_guesses
    from tests.helpers import count_picard_sweeps

    kin = Manipulator2()
    inv = Pseudoinverse(kin) if algorithm == "pseudoinverse" else ExtendedInverse(kin, PaperCubic())
    guesses = chain_guesses(inv, X0, TABLE1_LEGS, gamma=gamma)
    assert guesses is not None and len(guesses) == len(TABLE1_LEGS)
    np.testing.assert_allclose(guesses[0].x[0], X0, atol=1e-15)
    sweeps = count_picard_sweeps(monkeypatch)
    runs = {}
    for name, guessed in (("cold", False), ("chained", True)):
        x, ends, paths = X0, [], []
        for j, target in enumerate(TABLE1_LEGS):
            res = solve(inv, x, target, gamma=gamma, guess=guesses[j] if guessed else None)
            assert res.success, res.message
            x = res.x
            ends.append(x)
            paths.append(res.trajectory)
        runs[name] = (np.array(ends), paths)
    cold, chained = sweeps[: len(TABLE1_LEGS)], sweeps[len(TABLE1_LEGS) :]
    assert max(chained) <= 2 and sum(cold) >= 3 * len(TABLE1_LEGS), (cold, chained)
    np.testing.assert_allclose(runs["chained"][0], runs["cold"][0], atol=1e-12)
    for a, b in zip(runs["chained"][1], runs["cold"][1], strict=True):
        np.testing.assert_allclose(a.theta, b.theta, atol=1e-9)
        np.testing.assert_allclose(a.x, b.x, atol=1e-12)
    if algorithm == "pseudoinverse":  # Table 1's column (four decimals): the first cycle
        np.testing.assert_allclose(runs["chained"][0][:4], PRINTED[algorithm][1:], atol=6e-5)


def test_chain_guesses_refuse_bad_input_and_give_none_at_a_singularity():
    from jik.engine.picard_guesses import chain_guesses

    inv = Pseudoinverse(Manipulator2())
    for kwargs, match in [
        ({"x0": [[0, 0, 1]]}, "one configuration"),
        ({"x0": [0, np.nan, 1]}, "x0 contains NaN"),
        ({"y_d": [1.0, 2.0]}, r"legs' targets \(L, r\)"),
        ({"y_d": [[1.0, 2.0, 3.0]]}, "must have shape"),
        ({"gamma": 0.0}, "gamma must be > 0"),
    ]:
        args = {"x0": X0, "y_d": TABLE1_LEGS} | kwargs
        with pytest.raises(InvalidInputError, match=match):
            chain_guesses(inv, args.pop("x0"), args.pop("y_d"), **args)
    # (36) with a = 1, b = 0 is singular on x1 = 0, which the second leg has to cross.
    singular = ExtendedInverse(Manipulator1(), E2Optimal(a=1.0, b=0.0))
    assert chain_guesses(singular, [0.5, 0.2, 1.0], [[0.6, 0.2], [-0.5, 0.2]]) is None


# -- discrete mode in chunks (solve_in_chunks): the iterates of one solve ------------------------


def _same_run(a, b) -> None:
    """Two results of eq. (7) with the same numbers, bit for bit."""
    assert (a.success, a.nit, a.message, a.status) == (b.success, b.nit, b.message, b.status)
    np.testing.assert_array_equal(a.x, b.x)
    for name in ("theta", "x", "y", "error", "h"):
        np.testing.assert_array_equal(getattr(a.trajectory, name), getattr(b.trajectory, name))


@pytest.mark.parametrize("chunk", [1, 7, 80])
def test_discrete_chunks_give_the_iterates_of_one_solve(chunk):
    """x <- x - gamma J# e has no memory: solves of `chunk` iterations, each from where the one
    before stopped, give the same iterates, count and message as one solve; between the chunks
    the progress fraction grows toward 1."""
    from jik.engine.solve_chunks import solve_in_chunks

    inv = ExtendedInverse(Manipulator2(), PaperCubic())
    one = solve(inv, X0, [1, 1], gamma=0.3, mode="discrete")
    fractions: list[float] = []
    res = solve_in_chunks(inv, X0, [1, 1], chunk=chunk, gamma=0.3, between=fractions.append)
    assert one.success and one.nit > 60
    _same_run(res, one)
    assert len(fractions) == -(-one.nit // chunk) - 1
    assert fractions == sorted(fractions) and all(0 <= f <= 0.99 for f in fractions)


def test_discrete_chunks_stop_at_the_iteration_cap_as_one_solve():
    from jik.engine.solve_chunks import solve_in_chunks

    inv = Pseudoinverse(Manipulator2())
    one = solve(inv, X0, [1, 1], gamma=0.01, mode="discrete", max_iterations=20)
    res = solve_in_chunks(inv, X0, [1, 1], chunk=7, gamma=0.01, max_iterations=20)
    assert not res.success and "did not converge within 20 iterations" in res.message
    _same_run(res, one)
    assert solve_in_chunks(inv, X0, [1, 1], chunk=7, gamma=0.01, record=False).trajectory is None


class _UndefinedNearTarget(Pseudoinverse):
    """A right inverse that raises (instead of masking) within `radius` of the target."""

    def __init__(self, kinematics, radius: float) -> None:
        super().__init__(kinematics)
        self.radius = radius

    def apply_masked(self, x, e):
        near = np.linalg.norm(e, axis=-1) < self.radius
        if np.any(near):
            raise AlgorithmicSingularityError("undefined near the target", x[np.argmax(near)])
        return super().apply_masked(x, e)


class _ThrownNearTarget(Pseudoinverse):
    """A right inverse whose step is huge within `radius` of the target: the run diverges."""

    def __init__(self, kinematics, radius: float) -> None:
        super().__init__(kinematics)
        self.radius = radius

    def apply_masked(self, x, e):
        v, bad = super().apply_masked(x, e)
        near = np.linalg.norm(e, axis=-1) < self.radius
        return np.where(near[..., None], 1e9 * v / np.linalg.norm(e, axis=-1)[..., None], v), bad


def test_a_run_that_diverges_in_a_later_chunk_counts_all_its_iterations():
    from jik.engine.solve_chunks import solve_in_chunks

    inv = _ThrownNearTarget(Manipulator2(), 1e-3)
    one = solve(inv, X0, [1, 1], gamma=0.3, mode="discrete")
    assert not one.success and one.message.startswith(f"diverged after {one.nit} iterations")
    assert one.status == "diverged"
    chunk = 5 if one.nit % 5 else 6  # (not at a chunk's end: see solve_in_chunks' Notes)
    assert one.nit > chunk
    _same_run(solve_in_chunks(inv, X0, [1, 1], chunk=chunk, gamma=0.3), one)


def test_a_typed_error_inside_a_chunk_keeps_every_iterate_before_it():
    """Where one solve raises (the map undefined on the way), the chunks stop with the iterates
    up to the error: the last chunk is redone one iteration at a time."""
    from jik.engine.solve_chunks import solve_in_chunks

    kin = Manipulator2()
    plain = solve(Pseudoinverse(kin), X0, [1, 1], gamma=0.3, mode="discrete")
    m = int(np.argmax(plain.trajectory.error < 1e-3))  # the first iterate where it raises
    with pytest.raises(AlgorithmicSingularityError):
        solve(_UndefinedNearTarget(kin, 1e-3), X0, [1, 1], gamma=0.3, mode="discrete")
    res = solve_in_chunks(_UndefinedNearTarget(kin, 1e-3), X0, [1, 1], chunk=7, gamma=0.3)
    assert not res.success and res.nit == m and res.status == "raised"
    assert res.message.startswith(f"stopped after {m} iterations: undefined near the target")
    np.testing.assert_array_equal(res.trajectory.x, plain.trajectory.x[: m + 1])
    np.testing.assert_array_equal(res.x, plain.trajectory.x[m])


def test_discrete_chunks_raise_at_a_singular_start_and_let_between_raise():
    from jik.engine.solve_chunks import solve_in_chunks

    singular = ExtendedInverse(Manipulator1(), E2Optimal(a=1.0, b=0.0))
    with pytest.raises(AlgorithmicSingularityError, match=r"x = \(0, 0.2, 1\)"):
        solve_in_chunks(singular, [0.0, 0.2, 1.0], [1.0, 1.0], chunk=5, gamma=0.5)

    class Stop(Exception):
        pass

    def between(fraction: float) -> None:
        raise Stop

    with pytest.raises(Stop):
        solve_in_chunks(
            Pseudoinverse(Manipulator2()), X0, [1, 1], chunk=5, gamma=0.3, between=between
        )
    for kwargs, match in [
        ({"chunk": 0}, "chunk must be between"),
        ({"x0": [X0, X0]}, r"one start \(p,\) and one target"),
        ({"gamma": 2.0}, "gamma must be < 2"),
    ]:
        args = {"x0": X0, "chunk": 5} | kwargs
        with pytest.raises(InvalidInputError, match=match):
            solve_in_chunks(Pseudoinverse(Manipulator2()), args.pop("x0"), [1, 1], **args)


def test_a_start_where_k_is_undefined_is_refused_not_already_at_the_target():
    """sqrt(a) at a = -1 is NaN: the task error is NaN, which is not below tol, so the start
    is refused as the discrete mode refuses it, not reported converged with no motion."""
    from jik.engine.exceptions import KinematicSingularityError
    from jik.engine.formula_kinematics import FormulaKinematics

    kin = FormulaKinematics(["a", "b", "c"], ["sqrt(a) + b", "c"])
    for mode in ("continuous", "discrete"):
        with pytest.raises(KinematicSingularityError, match=r"at x = \(-1, 0.5, 1\)"):
            solve(Pseudoinverse(kin), [-1.0, 0.5, 1.0], [2.0, 1.0], mode=mode, gamma=0.5)
    with pytest.raises(KinematicSingularityError):
        solve_batch(Pseudoinverse(kin), [[0.5, 0.5, 0.5], [-1.0, 0.5, 1.0]], [2.0, 1.0])
