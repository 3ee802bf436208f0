"""A run's findings in sentences (jik.engine.findings) and why the unicycle's map of
characteristics became undefined (jik.engine.reproductions.unicycle.undefined_why)."""

from __future__ import annotations

import numpy as np

import jik.engine as jik
from jik.engine.findings import drift_sentence, gamma_note, pseudoinverse_why
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
    assert "iteration 3 took λ10 from 0.0659 to -0.0777, across λ10 = 0" in why
    assert "(sec. 6.2, Figs. 13 (J^P#) and 14 (J^E#))" in note
    assert note.endswith("the extended run from q0 = B converges.")
    (alone,) = undefined_why((1.0, 2.0, 0.0), 1.0, (0.5, 0.4), "the run's last step", False)
    assert "the run's last step took λ10 from 0.5 to 0.4. From there" in alone
