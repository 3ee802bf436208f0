"""A run's findings in sentences (jik.engine.findings) and why the unicycle's map of
characteristics became undefined (jik.engine.reproductions.unicycle.undefined_why)."""

from __future__ import annotations

import doctest
from types import SimpleNamespace

import numpy as np
import pytest

import jik.engine as jik
from jik.engine.augmentations import h_change
from jik.engine.findings import NAMES, drift_sentence, gamma_note, pseudoinverse_why
from jik.engine.practical_findings import (
    damped_findings,
    leg_end_errors,
    posture_findings,
    rest_words,
    weighted_findings,
)
from jik.engine.registry import POSE_A, POSE_B
from jik.engine.reproductions.unicycle import paper_start, undefined_why


def _runs():
    """Manipulator 2 on the paper's closed path, two cycles, with both inverses."""
    arm = jik.Manipulator2()
    x0, path = [0, 0, np.pi / 2], [(1, 1), (1, 2), (0, 2)]
    pinv = jik.repeatability(jik.Pseudoinverse(arm), x0, path, cycles=2)
    ext = jik.repeatability(jik.ExtendedInverse(arm, jik.PaperCubic()), x0, path, cycles=2)
    return arm, pinv, ext


def test_the_pseudoinverse_drifts_and_the_extended_inverse_comes_back_in_words():
    """Table 1's finding said by the engine: J^P# not repeatable, with its drift growing;
    J^E# repeatable within round-off, because h stayed at h(x0) (eq. (12))."""
    _, pinv, ext = _runs()
    said = jik.run_findings("J^P#", pinv.drift, True, "", closed=True, unit="[m]")
    assert said == [(drift_sentence("J^P#", pinv.drift, "[m]"), "finding")]
    assert said[0][0].startswith("J^P#: not repeatable. After 2 cycles the joints end ‖x − x0‖ =")
    assert f"growing from {pinv.drift[0]:.3g} after cycle 1" in said[0][0]
    text = drift_sentence("J^E#", ext.drift, "[m]")
    assert text.startswith("J^E#: repeatable. After each of 2 cycles the joints came back")
    assert "(‖x − x0‖ below 1e-06)" in text
    assert "no memory of the start" in pseudoinverse_why(pinv.drift)
    assert "happens to come back" in pseudoinverse_why(ext.drift)
    assert pseudoinverse_why([]) is None
    h = np.full(20, 0.5) + 1e-12 * np.arange(20)  # (h kept to round-off along the run)
    why = jik.extended_why(h, ext.drift, True, True, "continuous", 1.0)
    assert why == [
        (
            "Why: J^E# adds the equation h(x) = h(x0) (eq. (12)); h changed by only 1.9e-11 "
            "along its run, so each task point has one configuration on that level set, and "
            "the closed task path gave a closed joint path.",
            "why",
        )
    ]
    (exact,) = jik.extended_why(np.full(5, 0.5), [], True, False, "continuous", 1.0)
    assert "; h did not change along its run." in exact[0]  # (not "changed by only 0")


def test_a_run_that_lost_h_says_so_and_discrete_mode_says_why():
    """h changed by 0.1 along a discrete run that did not come back: not conserved, the
    discrete step keeps h to first order only, and near gamma = 2 a note on the iteration."""
    h = np.linspace(0.0, 0.1, 5)
    why = jik.extended_why(h, [0.2, 0.4], True, True, "discrete", 1.8)
    assert [role for _, role in why] == ["why", "note"]
    assert why[0][0].startswith("h was not conserved: it changed by 0.1 along")
    assert "the joints did not come back" in why[0][0]
    assert "keeps h only approximately" in why[1][0]
    assert "1 − γ = -0.8 per step" in gamma_note("discrete", 1.8)
    assert gamma_note("discrete", 1.0) is None and gamma_note("continuous", 1.8) is None
    assert jik.extended_why(None, [], True, False, "continuous", 1.0) == []
    assert jik.extended_why(np.zeros(3), [], False, False, "continuous", 1.0) == []  # (stopped)


def test_a_failed_run_says_where_it_stopped_after_its_completed_cycles():
    said = jik.run_findings("J^E#", [1e-15], False, "cycle 2, leg 1: singular", True, "[rad]")
    assert [role for _, role in said] == ["finding", "failure"]
    assert said[1][0] == "J^E# stopped (after 1 completed cycle): cycle 2, leg 1: singular"
    assert jik.run_findings("J^P#", [], True, "converged", False, "") == [
        ("J^P#: converged.", "finding")
    ]


def test_the_unicycle_runs_of_the_paper_are_named_and_their_undefined_map_explained():
    """Start B's discrete extended run leaves the domain of the characteristics map: the
    sentence says which step crossed lambda10 = 0 and that this is Figs. 13-14's run."""
    assert paper_start(POSE_A) == "A" and paper_start(POSE_B) == "B"
    assert paper_start((0.0, 0.0, 0.0)) is None and paper_start(()) is None
    why, note = undefined_why(POSE_B, 1.0, (0.0659, -0.0777), "iteration 3", discrete=True)
    assert "iteration 3 took lambda10 from 0.0659 to -0.0777, across lambda10 = 0" in why
    assert "(sec. 6.2, Figs. 13 (J^P#) and 14 (J^E#))" in note
    assert note.endswith("the extended run from q0 = B converges.")
    (alone,) = undefined_why((1.0, 2.0, 0.0), 1.0, (0.5, 0.4), "the run's last step", False)
    assert "the run's last step took lambda10 from 0.5 to 0.4. From there" in alone


def test_the_posture_inverse_drifts_less_than_the_pseudoinverse_but_is_not_repeatable():
    """Its sentence compares its drift after the last cycle with the pseudoinverse's and the
    extended Jacobian's after as many cycles; gain 0 is the pseudoinverse."""
    arm, pinv, ext = _runs()
    x0, path = [0, 0, np.pi / 2], [(1, 1), (1, 2), (0, 2)]
    post = jik.repeatability(jik.PostureInverse(arm, rest=x0, gain=1.0), x0, path, cycles=2)
    ((text, role),) = posture_findings(
        "J^N#", 1.0, "x_rest = x0", post.drift, "[m]", pinv.drift, ext.drift
    )
    assert role == "why" and text.startswith("J^N#, gain k = 1, x_rest = x0: after 2 cycles")
    assert f"less than the pseudoinverse's {pinv.drift[1]:.3g}" in text
    assert f"but does not reach the extended Jacobian's {ext.drift[1]:.3g}" in text
    ((zero, _),) = posture_findings("J^N#", 0.0, "x_rest = x0", [0.5], "[m]")
    assert zero == (
        "J^N#, gain k = 0, x_rest = x0: after 1 cycle it is the pseudoinverse (k = 0), "
        "drift 0.5 [m]."
    )
    assert posture_findings("J^N#", 1.0, "x_rest = x0", [], "[m]") == []


def test_damped_least_squares_says_its_worst_leg_end_and_where_the_pseudoinverse_stalled():
    run = SimpleNamespace(error=np.array([1.0, 0.2, 0.8, 0.5]), leg=np.array([0, 0, 1, 1]))
    run.success = False
    stalled = SimpleNamespace(error=np.array([1.0, 1.22]), success=False)
    np.testing.assert_allclose(leg_end_errors(run.error, run.leg), [0.2, 0.5])
    ((text, _),) = damped_findings("DLS", 0.1, 0.05, 1e-10, run, stalled)
    assert text.startswith("DLS (λ = 0.1, adaptive, where σ_min(J) < 0.05): task error at")
    assert "up to 0.5 (leg 2; tolerance 1e-10)" in text
    assert text.endswith("where the pseudoinverse stalled at task error 1.22, it got to 0.5.")
    run.success = True
    assert damped_findings("DLS", 0.1, 0.0, 1e-10, run, stalled)[0][0].endswith(
        "; it went through where the pseudoinverse stopped."
    )


def test_the_weighted_inverse_says_whether_its_joints_stayed_within_the_box():
    limits = np.array([[-1.0, 1.0], [0.0, 2.0]])
    inside = np.array([[0.0, 1.0], [0.9, 0.5]])
    ((text, role),) = weighted_findings("W", inside, limits, ("a", "b"))
    assert role == "why" and "closest: a, 0.1 from a limit." in text
    ((text, role),) = weighted_findings("W", inside - 0.6, limits, ("a", "b"))
    assert role == "failure" and text.endswith(": b.")


def test_a_result_says_its_own_findings_with_its_settings():
    """RepeatabilityResult.findings: Table 1's path on Manipulator 2, three cycles. J^E# (11)
    with the cubic (38) comes back to x0 and says why (h kept at h(x0), eq. (12), from h after
    each leg); J^P# (8) drifts and says why; both in the unit given."""
    arm = jik.Manipulator2()
    x0, path = [0, 0, np.pi / 2], [(1, 1), (1, 2), (0, 2)]
    ext = jik.repeatability(jik.ExtendedInverse(arm, jik.PaperCubic()), x0, path, cycles=3)
    legs = np.vstack([x0, ext.legs])  # (1 + 3 * 4, 3)
    np.testing.assert_allclose(ext.h, jik.PaperCubic().value(legs), rtol=0, atol=1e-15)
    (found, why) = ext.findings("[m and rad mixed]")
    assert found == (
        drift_sentence(NAMES["extended"], ext.drift, "[m and rad mixed]"),
        "finding",
        "extended",
    )
    assert found.text.startswith("extended Jacobian J^E#: repeatable. After each of 3 cycles")
    assert why.role == "why" and why.text.startswith("Why: J^E# adds the equation h(x) = h(x0)")
    assert "the closed task path gave a closed joint path" in why.text
    pinv = jik.repeatability(jik.Pseudoinverse(arm), x0, path, cycles=3)
    assert pinv.h is None
    (found, why) = pinv.findings()
    assert found.text == (
        f"pseudoinverse J^P#: not repeatable. After 3 cycles the joints end ‖x − x0‖ = "
        f"{pinv.drift[-1]:.3g} away from x0, growing from {pinv.drift[0]:.3g} after cycle 1."
    )
    assert why == (pseudoinverse_why(pinv.drift), "why", "pseudoinverse")


def test_the_findings_example_runs():
    """RepeatabilityResult.findings' docstring example prints what it says."""
    (test,) = doctest.DocTestFinder().find(jik.RepeatabilityResult.findings, "findings")
    runner = doctest.DocTestRunner()
    runner.run(test)
    assert runner.summarize(verbose=False) == (0, 4)


def test_a_discrete_run_near_gamma_two_says_h_was_lost_and_why():
    """The discrete iteration with gamma = 1.89 (its result's own mode and gamma): J^E#
    overshoots, loses h(x0) and does not come back; the result says so, that the discrete
    algorithm keeps h only approximately, and that gamma is near 2 (1 - gamma = -0.89)."""
    arm = jik.Manipulator2()
    inverse = jik.ExtendedInverse(arm, jik.PaperCubic())
    run = jik.repeatability(
        inverse, [0, 0, np.pi / 2], [(1, 1), (1, 2), (0, 2)], 3, mode="discrete", gamma=1.89
    )
    said = run.findings()
    assert [f.role for f in said] == ["finding", "why", "note", "note"]
    assert said[0].text.startswith("extended Jacobian J^E#: not repeatable. After 3 cycles")
    assert said[1].text.startswith("h was not conserved: it changed by ")
    assert "so the joints did not come back" in said[1].text
    assert said[2].text.startswith("The discrete algorithm x ← x − γ J^E# e keeps h only")
    assert said[3] == (gamma_note("discrete", 1.89), "note", None)
    assert "1 − γ = -0.89 per step" in said[3].text


def test_recorded_legs_judge_h_at_every_point_as_the_dashboard_does():
    """With record=True the change of h is taken over every point of the legs, the dashboard's
    verdict's measure, not only at the legs' ends: the discrete overshoot at gamma = 1.89 moves
    h further between the ends than at them. Without, the sentence says where h was taken."""
    inverse = jik.ExtendedInverse(jik.Manipulator2(), jik.PaperCubic())
    path, x0 = [(1, 1), (1, 2), (0, 2)], [0, 0, np.pi / 2]
    runs = [
        jik.repeatability(inverse, x0, path, 3, mode="discrete", gamma=1.89, record=record)
        for record in (False, True)
    ]
    along = np.concatenate([leg.trajectory.h for leg in runs[1].leg_results])
    assert h_change(along) > h_change(runs[0].h)
    assert f"changed by {h_change(along):.3g} along" in runs[1].findings()[1].text
    ends = f"changed by {h_change(runs[0].h):.3g} from the extended Jacobian's start to its legs'"
    assert ends in runs[0].findings()[1].text


def test_a_batch_says_the_findings_of_the_start_asked_for():
    """A batch's findings are per start (``start``, checked); one start's takes none. A start
    whose leg failed says where it stopped."""
    arm = jik.Manipulator2()
    inverse = jik.ExtendedInverse(arm, jik.PaperCubic())
    path = [(1, 1), (1, 2), (0, 2)]
    batch = jik.repeatability(inverse, [[0, 0, np.pi / 2], [0.1, 0, 1.5]], path, cycles=2)
    assert batch.h.shape == (2, 1 + 2 * 4)
    one = jik.repeatability(inverse, [0.1, 0, 1.5], path, cycles=2)
    assert [f.text[:40] for f in batch.findings(start=1)] == [f.text[:40] for f in one.findings()]
    for bad, words in ((None, "a batch of 2 starts needs start"), (2, "between 0 and 1")):
        with pytest.raises(jik.InvalidInputError, match=words) as caught:
            batch.findings(start=bad)
        assert caught.value.field == "start"
    with pytest.raises(jik.InvalidInputError, match="takes no start"):
        one.findings(start=0)
    capped = jik.repeatability(
        jik.Pseudoinverse(arm),
        [0, 0, np.pi / 2],
        path,
        mode="discrete",
        gamma=1.9,
        max_iterations=10,
    )
    ((text, role, _),) = capped.findings()
    assert role == "failure" and text.startswith(
        "pseudoinverse J^P# stopped: cycle 1, leg 1 failed"
    )


def test_a_result_of_a_practical_inverse_says_what_its_parameters_did():
    """RepeatabilityResult.findings for the practical inverses, from the inverse the legs ran
    with: the posture inverse's drift with its rest and gain, damped least squares' worst task
    error at a leg's end (the same from recorded legs as from the legs' ends), the weighted
    inverse's joints against the limits it was given (no box note: they are the user's)."""
    arm = jik.Manipulator2()
    x0, path = [0, 0, np.pi / 2], [(1, 1), (1, 2), (0, 2)]
    post = jik.repeatability(jik.PostureInverse(arm, rest=x0, gain=1.0), x0, path, cycles=2)
    (_, why) = post.findings("[m]")
    assert why == (
        posture_findings(NAMES["posture"], 1.0, "x_rest = x0 (0, 0, 1.571)", post.drift, "[m]")[0]
        + ("posture",)
    )
    damped = jik.DampedInverse(arm, 0.05, 0.01)
    runs = [jik.repeatability(damped, x0, path, 2, record=record) for record in (False, True)]
    ends = [run.findings()[1].text for run in runs]
    assert ends[0].startswith("damped least squares J^DLS (λ = 0.05, adaptive, where σ_min(J)")
    errors = np.linalg.norm(arm.forward(runs[0].legs) - np.resize(runs[0].targets, (8, 2)), axis=1)
    cycle, leg = divmod(int(np.argmax(errors)), 4)
    assert f"up to {errors.max():.3g} (cycle {cycle + 1}, leg {leg + 1};" in ends[0]
    assert ends[0] == ends[1]
    limits = [[-4.0, 4.0]] * 3
    weighted = jik.repeatability(jik.WeightedInverse(arm, limits), x0, path, cycles=2)
    (_, why) = weighted.findings()
    assert why.role == "why" and why.text.startswith(
        "weighted least-norm J^W#: every joint stayed within its limits (x1 in [-4, 4]; x2 in"
    )
    assert "x_range" not in why.text
    batch = jik.repeatability(damped, [x0, [0.1, 0, 1.5]], path, cycles=2)
    assert batch.findings(start=0)[1].text == ends[0]


def test_the_weighted_inverse_on_the_default_box_of_a_robot_without_limits_says_so():
    """A robot without joint limits (Manipulator 2) gives the weighted inverse its configuration
    box by default: its findings say so, as the dashboard's verdict does for the same run, and
    do not read as joint limits of the robot; limits the user gives stay without the note."""
    arm = jik.Manipulator2()
    x0, path = [0, 0, np.pi / 2], [(1, 1), (1, 2), (0, 2)]
    weighted = jik.make_inverse(arm, "weighted")
    (_, why) = jik.repeatability(weighted, x0, path, cycles=1).findings()
    assert why.text.startswith(
        "weighted least-norm J^W#: every joint stayed within its limits (x1 in [-3, 3]; x2 in "
        "[-3, 3]; x3 in [-3.14, 6.28]; the robot has no joint limits: its configuration box "
        "x_range); closest:"
    ), why.text


def test_a_drift_without_a_unit_reads_as_a_number_not_a_number_and_a_blank():
    """findings() without a unit (its default) writes the posture inverse's drift as the other
    sentences do, "drifts 0.0625, but", not "drifts 0.0625 , but"; gain 0 likewise."""
    arm = jik.Manipulator2()
    x0, path = [0, 0, np.pi / 2], [(1, 1), (1, 2), (0, 2)]
    post = jik.repeatability(jik.PostureInverse(arm, rest=x0), x0, path, cycles=2)
    (_, why) = post.findings()
    assert f"it drifts {post.drift[-1]:.3g}, but does not reach" in why.text
    ((zero, _),) = posture_findings("J^N#", 0.0, "x_rest = x0", [0.5], "")
    assert zero.endswith("it is the pseudoinverse (k = 0), drift 0.5.")
    ((text, _),) = posture_findings("J^N#", 1.0, "x_rest = x0", [0.5], "", [0.9])
    assert "it drifts 0.5, less than the pseudoinverse's 0.9" in text
    assert "slows the drift" in text


def test_a_posture_drift_above_the_pseudoinverse_s_is_not_said_to_be_slowed():
    """Where the posture inverse drifts more than the pseudoinverse (a high gain), its sentence
    says so and does not credit the pull with slowing the drift."""
    ((text, _),) = posture_findings("J^N#", 50.0, "x_rest = x0", [0.65], "", [0.001], [1e-12])
    assert "it drifts 0.65, not less than the pseudoinverse's 0.001" in text
    assert "slows" not in text
    assert "on this path the pull toward x_rest does not slow the drift" in text


def test_damped_least_squares_names_its_worst_leg_by_cycle_and_leg():
    """A run of 2 cycles of 3 legs whose worst leg end is its 4th leg says "cycle 2, leg 1", as
    the failures and the limits report count legs, not "leg 4" of a cycle of three."""
    run = SimpleNamespace(error=np.array([0.1, 0.2, 0.1, 0.9, 0.1, 0.1]), leg=np.arange(6))
    run.success = True
    ((text, _),) = damped_findings("DLS", 0.1, 0.0, 1e-10, run, legs=3)
    assert "up to 0.9 (cycle 2, leg 1; tolerance 1e-10)" in text
    ((text, _),) = damped_findings("DLS", 0.1, 0.0, 1e-10, run)
    assert "up to 0.9 (leg 4; tolerance 1e-10)" in text
    one = SimpleNamespace(error=np.array([0.5, 0.3]), leg=np.zeros(2, int), success=True)
    ((text, _),) = damped_findings("DLS", 0.1, 0.0, 1e-10, one, legs=1)
    assert "task error at its end 0.3 (tolerance 1e-10)" in text and "leg" not in text
    panda = jik.load_robot("panda")
    home = np.array(panda.spec.default_x0)
    loop = panda.kinematics.forward(home) + [[0.08, 0, 0, 0, 0, 0.2], [0.08, 0.08, 0, 0.15, 0, 0.2]]
    rep = jik.repeatability(panda.inverse("damped"), home, loop, cycles=2)
    legs = rep.targets.shape[0]
    ends = np.linalg.norm(
        panda.kinematics.forward(rep.legs) - np.resize(rep.targets, rep.legs.shape[:1] + (6,)),
        axis=1,
    )
    cycle, leg = divmod(int(np.argmax(ends)), legs)
    assert f"(cycle {cycle + 1}, leg {leg + 1};" in rep.findings()[1].text


def test_the_posture_inverses_default_rest_is_named_in_words():
    """rest_words: a default rest is the robot's home (a catalogue arm) or the start; a rest
    given is the start's words when it is the start, else its numbers, set."""
    arm = jik.Manipulator2()
    x0 = [0.0, 0.0, 1.5]
    default = jik.make_inverse(arm, "posture", x0=x0, robot="manipulator2")
    assert rest_words(default, x0) == "x_rest = x0 (0, 0, 1.5)"
    assert rest_words(jik.PostureInverse(arm, x0), x0) == "x_rest = x0 (0, 0, 1.5)"
    assert rest_words(jik.PostureInverse(arm, [0, 1, 2]), x0) == "x_rest = (0, 1, 2) (set)"
    panda = jik.load_robot("panda").kinematics
    home = jik.make_inverse(panda, "posture", robot="panda", x0=[0.0] * 7)
    assert rest_words(home, [0.0] * 7) == (
        "x_rest = the robot's home (0, -0.7854, 0, -2.356, 0, 1.571, 0.7854)"
    )


def test_one_cycle_is_said_as_one():
    """One cycle reads "After 1 cycle", not "After each of 1 cycle"; the result prints "1 cycle
    of 4 legs"."""
    arm = jik.Manipulator2()
    run = jik.repeatability(
        jik.ExtendedInverse(arm, jik.PaperCubic()), [0, 0, np.pi / 2], [(1, 1), (1, 2), (0, 2)], 1
    )
    assert run.findings()[0].text.startswith(
        "extended Jacobian J^E#: repeatable. After 1 cycle the joints came back to x0 within"
    )
    assert "1 cycle of 4 legs" in repr(run)


def test_the_weighted_inverse_of_an_arm_of_continuous_joints_names_no_box():
    """A URDF arm whose joints are all continuous has no limits and the weighted inverse takes
    none (weight 1 each), yet its findings said "x1 in [-inf, inf]; ... the robot has no joint
    limits: its configuration box x_range", a box it did not use."""
    pytest.importorskip("yourdfpy")
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "data" / "arm4.urdf").read_text()
    arm = jik.robot_from_dict(
        {"name": "urdf", "urdf": text.replace('"revolute"', '"continuous"'), "end_link": "tool"}
    )
    weighted = arm.inverse("weighted")
    assert np.isinf(weighted.limits).all() and not weighted.box
    x = np.array([[0.3, 0.5, 0.8, 0.6]])
    ((text, _),) = weighted_findings(
        "J^W#", x, weighted.limits, ["x1", "x2", "x3", "x4"], weighted.box
    )
    assert "x_range" not in text
