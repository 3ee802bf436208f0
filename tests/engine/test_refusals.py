"""The front door's refusals: every public function that refuses an argument raises
InvalidInputError whose ``field`` names it; the kinematics check ``x`` at their public methods,
and the inverses check what they are built from."""

import math
import pickle
from pathlib import Path

import numpy as np
import pytest

import jik.engine as jik
from jik.engine.exceptions import InvalidInputError
from jik.engine.kinematics import Kinematics
from jik.engine.limits import run_report
from jik.engine.self_motion import trace
from jik.engine.solve_rules import refused_starts

ROOT = Path(__file__).resolve().parents[2]
X0 = [0.0, 0.0, math.pi / 2]
PATH = [(1, 1), (1, 2), (0, 2)]
LOOP = [(0, 1), *PATH]
BOX = {"x2": (0, 1), "x3": (1, 2)}
ARM = jik.Manipulator2()
P = jik.Pseudoinverse(ARM)
NAMES = ARM.variable_names
PANDA_TASK = jik.load_robot("panda").kinematics.pose_task
#: A task undefined for x1 <= 0 whose Jacobian is finite there (log(-1) is NaN, 1/x1 is not).
LOG_ARM = jik.FormulaKinematics(["x1", "x2", "x3"], ["log(x1)", "x2 + x3"])

#: (call, expected field): each call refuses one argument.
REFUSALS = {
    "solve x0 wrong length": (lambda: jik.solve(P, [0, 0], [1, 1]), "x0"),
    "solve x0 NaN": (lambda: jik.solve(P, [0, np.nan, 1], [1, 1]), "x0"),
    "solve x0 text": (lambda: jik.solve(P, "abc", [1, 1]), "x0"),
    "solve x0 a batch": (lambda: jik.solve(P, [X0, X0], [1, 1]), "x0"),
    "solve y_d wrong length": (lambda: jik.solve(P, X0, [1, 1, 1]), "y_d"),
    "solve y_d infinite": (lambda: jik.solve(P, X0, [np.inf, 1]), "y_d"),
    "solve y_d a batch": (lambda: jik.solve(P, X0, [[1, 1], [1, 2]]), "y_d"),
    # (beyond MAX_COORDINATE the error's norm overflowed: 20,000 steps at error inf)
    "solve y_d beyond the coordinate bound": (lambda: jik.solve(P, X0, [1e200, 1]), "y_d"),
    "solve x0 beyond the coordinate bound": (lambda: jik.solve(P, [1e7, 0, 1], [1, 1]), "x0"),
    "solve_batch more starts than targets": (
        lambda: jik.solve_batch(P, [X0] * 3, [[1, 1]] * 2),
        "y_d",
    ),
    "solve k undefined at x0": (
        lambda: jik.solve(jik.Pseudoinverse(LOG_ARM), [-1, 0, 0], [1, 1]),
        "x0",
    ),
    "solve k undefined at x0, discrete": (
        lambda: jik.solve(jik.Pseudoinverse(LOG_ARM), [-1, 0, 0], [1, 1], mode="discrete"),
        "x0",
    ),
    "repeatability path beyond the coordinate bound": (
        lambda: jik.repeatability(P, X0, [(1, 1), (2e6, 1)]),
        "path",
    ),
    "solve gamma": (lambda: jik.solve(P, X0, [1, 1], gamma=-1), "gamma"),
    "solve mode": (lambda: jik.solve(P, X0, [1, 1], mode="euler"), "mode"),
    "solve method": (lambda: jik.solve(P, X0, [1, 1], method="rk4"), "method"),
    "solve tol 0": (lambda: jik.solve(P, X0, [1, 1], tol=0), "tol"),
    "solve gamma a number as text": (lambda: jik.solve(P, X0, [1, 1], gamma="1"), "gamma"),
    "solve gamma a boolean": (lambda: jik.solve(P, X0, [1, 1], gamma=True), "gamma"),
    "solve tol a number as text": (lambda: jik.solve(P, X0, [1, 1], tol="1e-10"), "tol"),
    "solve x0 numbers as text": (lambda: jik.solve(P, ["0", "0", "1.5"], [1, 1]), "x0"),
    "solve y_d numbers as text": (lambda: jik.solve(P, X0, np.array(["1", "1"])), "y_d"),
    # (numpy reads a boolean among numbers as 0 or 1: a JSON true, or YAML's yes, ran as 1.0)
    "solve x0 a boolean among numbers": (lambda: jik.solve(P, [True, 0, 1.5], [1, 1]), "x0"),
    "solve_batch y_d a boolean in a row": (
        lambda: jik.solve_batch(P, X0, [[1, 1], [1, np.True_]]),
        "y_d",
    ),
    "repeatability path a boolean": (lambda: jik.repeatability(P, X0, [(1, 1), (1, True)]), "path"),
    "robot x0 a boolean": (
        lambda: jik.robot_from_dict(
            {"name": "planar_chain", "joints": "RRR", "lengths": [1, 1, 1], "x0": [True, 1, 1]}
        ),
        "x0",
    ),
    "E1Optimal C1 a number as text": (lambda: jik.E1Optimal(C1="1"), "C1"),
    "synthesize_e2 region bound as text": (
        lambda: jik.synthesize_e2(ARM, {"x2": ("0", 1), "x3": (1, 2)}, degree=2),
        "region.x2",
    ),
    "solve tol tiny": (lambda: jik.solve(P, X0, [1, 1], tol=1e-20), "tol"),
    "solve tol huge": (lambda: jik.solve(P, X0, [1, 1], tol=1e300), "tol"),
    "solve max_iterations": (lambda: jik.solve(P, X0, [1, 1], max_iterations=-5), "max_iterations"),
    "solve guess in discrete mode": (
        lambda: jik.solve(
            P, X0, [1, 1], mode="discrete", gamma=0.5, guess=jik.solve(P, X0, [1, 1]).trajectory
        ),
        "guess",
    ),
    "solve guess a result": (
        lambda: jik.solve(P, X0, [1, 1], guess=jik.solve(P, X0, [1, 1])),
        "guess",
    ),
    "solve guess a list": (
        lambda: jik.solve(P, X0, [1, 1], guess=[jik.solve(P, X0, [1, 1]).trajectory]),
        "guess",
    ),
    "solve_batch guess a number": (lambda: jik.solve_batch(P, [X0], [1, 1], guess=5), "guess"),
    "solve_batch guess text": (lambda: jik.solve_batch(P, [X0], [1, 1], guess="abc"), "guess"),
    "solve_batch guess count": (
        lambda: jik.solve_batch(P, [X0], [1, 1], guess=[None] * 2),
        "guess",
    ),
    "solve_batch guess member": (
        lambda: jik.solve_batch(P, [X0, X0], [1, 1], guess=[None, 5]),
        "guess.1",
    ),
    "solve not an inverse": (lambda: jik.solve("pseudoinverse", X0, [1, 1]), "inverse"),
    "solve_batch x0 3-D": (lambda: jik.solve_batch(P, np.zeros((2, 2, 3)), [1, 1]), "x0"),
    "solve_batch counts differ": (lambda: jik.solve_batch(P, [X0, X0], [[1, 1]] * 3), "y_d"),
    "repeatability cycles -1": (lambda: jik.repeatability(P, X0, PATH, cycles=-1), "cycles"),
    "repeatability cycles 1e9": (lambda: jik.repeatability(P, X0, PATH, cycles=10**9), "cycles"),
    "repeatability cycles 2.5": (lambda: jik.repeatability(P, X0, PATH, cycles=2.5), "cycles"),
    "repeatability path 3-D points": (lambda: jik.repeatability(P, X0, [(1, 1, 1)]), "path"),
    "repeatability path empty": (lambda: jik.repeatability(P, X0, []), "path"),
    "repeatability path no points": (lambda: jik.repeatability(P, X0, np.zeros((0, 2))), "path"),
    "repeatability path NaN": (lambda: jik.repeatability(P, X0, [(1, np.nan)]), "path"),
    "repeatability path too long": (lambda: jik.repeatability(P, X0, [(1, 1)] * 101), "path"),
    "repeatability paths per start": (
        lambda: jik.repeatability(P, [X0, X0], [PATH] * 3),
        "path",
    ),
    "repeatability x0 wrong width": (lambda: jik.repeatability(P, np.zeros((2, 5)), PATH), "x0"),
    "repeatability x0 3-D": (lambda: jik.repeatability(P, np.zeros((2, 2, 3)), PATH), "x0"),
    "repeatability mode": (lambda: jik.repeatability(P, X0, PATH, mode="euler"), "mode"),
    "repeatability tol": (lambda: jik.repeatability(P, X0, PATH, tol=-1), "tol"),
    "repeatability max_iterations": (
        lambda: jik.repeatability(P, X0, PATH, max_iterations=0),
        "max_iterations",
    ),
    "repeatability Resume legs text": (
        lambda: jik.repeatability(P, jik.Resume(np.array(X0), "abc"), PATH, cycles=2),
        "x0",
    ),
    "repeatability Resume legs not whole cycles": (
        lambda: jik.repeatability(P, jik.Resume(np.array(X0), np.zeros((5, 3))), PATH, cycles=2),
        "x0",
    ),
    "repeatability Resume legs NaN": (
        lambda: jik.repeatability(P, jik.Resume(np.array(X0), np.full((4, 3), np.nan)), PATH),
        "x0",
    ),
    "repeatability close a text": (lambda: jik.repeatability(P, X0, PATH, close="no"), "close"),
    "repeatability record a text": (lambda: jik.repeatability(P, X0, PATH, record="no"), "record"),
    "solve record a text": (lambda: jik.solve(P, X0, [1, 1], record="no"), "record"),
    "run_atlas keep_leg_ends a text": (
        lambda: jik.run_atlas(jik.plan_atlas(P, LOOP, starts=[X0]), keep_leg_ends="no"),
        "keep_leg_ends",
    ),
    "Manipulator2 l": (lambda: jik.Manipulator2(l=-1), "l"),
    "forward wrong width": (lambda: ARM.forward(np.zeros(5)), "x"),
    "jacobian NaN": (lambda: ARM.jacobian(np.array([np.nan, 0, 0])), "x"),
    "Pseudoinverse of a name": (lambda: jik.Pseudoinverse("manipulator2"), "kinematics"),
    "DampedInverse of a name": (lambda: jik.DampedInverse("manipulator2", 0.1), "kinematics"),
    "WeightedInverse of None": (lambda: jik.WeightedInverse(None, [[0, 1]] * 3), "kinematics"),
    "PostureInverse rest": (lambda: jik.PostureInverse(ARM, rest=[0, 0]), "rest"),
    "ExtendedInverse of a formula text": (
        lambda: jik.ExtendedInverse(ARM, "x3"),
        "augmenting_map",
    ),
    "ExtendedInverse with two degrees of redundancy": (
        lambda: jik.ExtendedInverse(
            jik.PlanarChain("RRRR", [1, 1, 1, 1]), jik.FormulaMap("x1", ["x1", "x2", "x3", "x4"])
        ),
        "kinematics",
    ),
    "ExtendedInverse map on another space": (
        lambda: jik.ExtendedInverse(ARM, jik.FormulaMap("a", ["a", "b"])),
        "augmenting_map",
    ),
    "VectorExtendedInverse of texts": (
        lambda: jik.VectorExtendedInverse(jik.PlanarChain("RRRR", [1] * 4), ["x1", "x2"]),
        "augmenting_maps.0",
    ),
    "synthesize_e2 unknown variable": (
        lambda: jik.synthesize_e2(ARM, {"x7": (0, 1), "x3": (1, 2)}),
        "region.x7",
    ),
    "synthesize_e2 reversed box": (
        lambda: jik.synthesize_e2(ARM, {"x2": (1, 0), "x3": (1, 2)}),
        "region.x2",
    ),
    "synthesize_e2 bound not a number": (
        lambda: jik.synthesize_e2(ARM, {"x2": (0, "a"), "x3": (1, 2)}),
        "region.x2",
    ),
    "synthesize_e2 one variable": (lambda: jik.synthesize_e2(ARM, {"x2": (0, 1)}), "region"),
    "synthesize_e2 degree": (lambda: jik.synthesize_e2(ARM, BOX, degree=10000), "degree"),
    "synthesize_e2 degrees per variable": (
        lambda: jik.synthesize_e2(ARM, BOX, degree=[4, 4, 4]),
        "degree",
    ),
    "synthesize_e2 redundancy": (
        lambda: jik.synthesize_e2(jik.PlanarChain("RRRR", [1] * 4), {"x1": (0, 1), "x2": (0, 1)}),
        "kinematics",
    ),
    "error_functional_e2 nodes 0": (
        lambda: jik.error_functional_e2(ARM, jik.PaperCubic(), BOX, nodes=0),
        "nodes",
    ),
    "error_functional_e1 too many points": (
        lambda: jik.error_functional_e1(ARM, jik.PaperCubic(), {"x1": (0, 1), **BOX}, nodes=400),
        "nodes",
    ),
    "error_functional_e2 nodes huge": (
        lambda: jik.error_functional_e2(ARM, jik.PaperCubic(), BOX, nodes=100000),
        "nodes",
    ),
    "plan_atlas n_starts without arc": (
        lambda: jik.plan_atlas(P, LOOP, n_starts=64, reference=X0),
        "arc",
    ),
    "plan_atlas n_starts without reference": (
        lambda: jik.plan_atlas(P, LOOP, n_starts=64, arc=(-1, 1)),
        "reference",
    ),
    "plan_atlas no starts at all": (lambda: jik.plan_atlas(P, LOOP), "starts"),
    "plan_atlas tol tiny": (lambda: jik.plan_atlas(P, LOOP, starts=[X0], tol=1e-20), "tol"),
    "plan_atlas first point out of reach": (
        lambda: jik.plan_atlas(
            P, [(5, 5), (1, 1)], n_starts=4, arc=(-1, 1), reference=X0, box=[(-3, 3)] * 3
        ),
        "path",
    ),
    "make_inverse unknown parameter": (
        lambda: jik.make_inverse(ARM, "damped", algorithm_parameters={"gain": 1, "zeta": 2}),
        "gain",
    ),
    "make_inverse parameter out of range": (
        lambda: jik.make_inverse(ARM, "damped", algorithm_parameters={"damping": -1}),
        "damping",
    ),
    "plan_atlas n_starts negative": (
        lambda: jik.plan_atlas(P, LOOP, n_starts=-4, arc=(-1, 1), reference=X0),
        "n_starts",
    ),
    "map_grid unknown variable": (
        lambda: jik.map_grid(jik.PaperCubic(), NAMES, {"x9": (0, 1), "x2": (0, 1)}),
        "region.x9",
    ),
    "map_grid NaN bound": (
        lambda: jik.map_grid(jik.PaperCubic(), NAMES, {"x2": (np.nan, 1), "x3": (0, 1)}),
        "region.x2",
    ),
    "map_grid n huge": (lambda: jik.map_grid(jik.PaperCubic(), NAMES, BOX, n=10**5), "n"),
    "map_grid n text": (lambda: jik.map_grid(jik.PaperCubic(), NAMES, BOX, n="a"), "n"),
    "inert_variables reversed box": (
        lambda: jik.inert_variables(ARM, jik.PaperCubic(), [(0, 1), (1, 0), (0, 1)]),
        "box",
    ),
    "trace box wrong shape": (lambda: trace(ARM, X0, (-1, 1), box=[(0, 1)]), "box"),
    "trace box NaN": (lambda: trace(ARM, X0, (-1, 1), box=[(-9, np.nan)] * 3), "box"),
    "trace bound_free_joints": (
        lambda: trace(ARM, X0, (-1, 1), bound_free_joints="no"),
        "bound_free_joints",
    ),
    "manifold_starts box": (lambda: jik.manifold_starts(ARM, X0, 4, box=[(0, 1)]), "box"),
    # (x0 outside the box: every start was left out, an empty array and no word of why)
    "manifold_starts x0 outside the box": (
        lambda: jik.manifold_starts(ARM, [5, 0.8, 0.9], 5, [(-3, 3)] * 3),
        "x0.0",
    ),
    "refused_starts x0 NaN": (lambda: refused_starts(P, [[0, np.nan, 1]]), "x0"),
    "refused_starts x0 wrong length": (lambda: refused_starts(P, [[0, 1]]), "x0"),
    "pose_of y wrong length": (lambda: PANDA_TASK.pose_of(np.zeros(5)), "y"),
    "run_report not a result": (lambda: run_report(ARM, "abc"), "result"),
    "error_functional_e1 robot by name": (
        lambda: jik.error_functional_e1("manipulator2", jik.PaperCubic(), BOX),
        "kinematics",
    ),
    "error_functional_e2 map as text": (
        lambda: jik.error_functional_e2(ARM, "x3 - x2", BOX),
        "augmenting_map",
    ),
    "synthesize_e2 robot by name": (lambda: jik.synthesize_e2("manipulator2", BOX), "kinematics"),
    "synthesize_e2 dirichlet text": (
        lambda: jik.synthesize_e2(ARM, BOX, degree=2, dirichlet="x2"),
        "dirichlet",
    ),
    "synthesize_e2 dirichlet gives text": (
        lambda: jik.synthesize_e2(ARM, BOX, degree=2, dirichlet=lambda x: "a"),
        "dirichlet",
    ),
    "synthesize_e2 dirichlet gives a value per point as text": (
        lambda: jik.synthesize_e2(ARM, BOX, degree=2, dirichlet=lambda x: ["1"] * len(x)),
        "dirichlet",
    ),
    "synthesize_e2_nd robot None": (lambda: jik.synthesize_e2_nd(None, BOX), "kinematics"),
    "synthesize_e2_nd no redundancy": (
        lambda: jik.synthesize_e2_nd(jik.PlanarChain("RR", [1, 1]), {"x1": (0, 1)}),
        "kinematics",
    ),
    "inert_variables robot by name": (
        lambda: jik.inert_variables("manipulator2", None, [(0, 1)] * 3),
        "kinematics",
    ),
    "inert_variables map as text": (
        lambda: jik.inert_variables(ARM, "x1", [(0, 1)] * 3),
        "amap",
    ),
    "manifold_starts robot by name": (
        lambda: jik.manifold_starts("manipulator2", X0, 4, [(0, 1)] * 3),
        "kinematics",
    ),
    "map_grid map as text": (lambda: jik.map_grid("x2 * x3", NAMES, BOX), "amap"),
    "CharacteristicsMap robot by name": (
        lambda: jik.CharacteristicsMap("unicycle", [0, 0, 0, 0], 0),
        "kinematics",
    ),
    "CharacteristicsMap without second derivatives": (
        lambda: jik.CharacteristicsMap(ARM, X0, 0),
        "kinematics",
    ),
    "UnicycleCharacteristics a 0": (lambda: jik.UnicycleCharacteristics(a=0), "a"),
    "UnicycleCharacteristics on_undefined": (
        lambda: jik.UnicycleCharacteristics(on_undefined="skip"),
        "on_undefined",
    ),
    "Robot.inverse unknown augmentation": (
        lambda: jik.load_robot("manipulator2").inverse("extended", "nope"),
        "augmentation",
    ),
    "E1Optimal C1 0": (lambda: jik.E1Optimal(C1=0), "C1"),
    "E2Optimal a and b 0": (lambda: jik.E2Optimal(0, 0), "a"),
    "CharacteristicsMap two degrees of redundancy": (
        lambda: jik.CharacteristicsMap(jik.PlanarChain("RRRR", [1] * 4), [0] * 4, 0),
        "kinematics",
    ),
    "synthesize_e2 dirichlet of wrong length": (
        lambda: jik.synthesize_e2(ARM, BOX, degree=2, dirichlet=lambda x: np.zeros(2)),
        "dirichlet",
    ),
    "robot_units robot by name": (lambda: jik.robot_units("panda"), "kinematics"),
    "repeatable drift text": (lambda: jik.repeatable("abc"), "drift"),
    "repeatability progress a function": (
        lambda: jik.repeatability(P, X0, PATH, progress=lambda leg: None),
        "progress",
    ),
    "run_atlas progress a function": (
        lambda: jik.run_atlas(jik.plan_atlas(P, LOOP, starts=[X0]), progress=print),
        "progress",
    ),
    "iter_atlas progress a function": (
        lambda: next(jik.iter_atlas(jik.plan_atlas(P, LOOP, starts=[X0]), progress=print)),
        "progress",
    ),
    "synthesize_e2 progress a function": (
        lambda: jik.synthesize_e2(ARM, BOX, degree=2, progress=print),
        "progress",
    ),
    "synthesize_e2_nd progress a function": (
        lambda: jik.synthesize_e2_nd(ARM, BOX, degree=2, nodes=64, progress=print),
        "progress",
    ),
    "h_change h text": (lambda: jik.h_change("abc"), "h"),
    "run_atlas an inverse for its plan": (lambda: jik.run_atlas(P), "plan"),
    "iter_atlas a dict for its plan": (lambda: next(jik.iter_atlas({"path": LOOP})), "plan"),
    "load_robot a number": (lambda: jik.load_robot(3), "robot"),
    "load_robot a dict": (lambda: jik.load_robot({"name": "panda"}), "robot"),
    "error_functional_e2 fixed text": (
        lambda: jik.error_functional_e2(ARM, jik.PaperCubic(), BOX, fixed="abc"),
        "fixed",
    ),
    "synthesize_e2 fixed text": (lambda: jik.synthesize_e2(ARM, BOX, fixed="abc"), "fixed"),
    "run_atlas a number for its backend": (lambda: jik.run_atlas(_plan(), 3), "backend"),
    "AtlasResult.columns runs text": (lambda: jik.run_atlas(_plan()).columns(runs="a"), "runs"),
    "repeatability record for a batch": (
        lambda: jik.repeatability(P, [X0, X0], PATH, record=True),
        "record",
    ),
    "solve a method in discrete mode": (
        lambda: jik.solve(P, X0, [1, 1], mode="discrete", gamma=0.5, method="picard"),
        "method",
    ),
    "plan_atlas reference beyond the bound": (
        lambda: jik.plan_atlas(P, LOOP, n_starts=4, arc=(-1, 1), reference=[0, 0, 1e300]),
        "reference",
    ),
    "plan_atlas path beyond the bound": (
        lambda: jik.plan_atlas(P, [(0, 1), (1e300, 1)], n_starts=4, arc=(-1, 1), reference=X0),
        "path",
    ),
}


def _plan():
    return jik.plan_atlas(P, LOOP, n_starts=4, arc=(-1, 1), reference=X0)


@pytest.mark.parametrize("case", REFUSALS, ids=str)
def test_a_refused_argument_is_the_errors_field(case):
    call, field = REFUSALS[case]
    with pytest.raises(InvalidInputError) as info:
        call()
    assert info.value.field == field, str(info.value)


def test_a_path_point_of_another_size_is_named_with_its_index():
    """A path whose points differ in size names the first point of the wrong size (it was
    called "not numeric", quoting the whole path)."""
    with pytest.raises(InvalidInputError, match=r"^path\[1\] must have 2 numbers, got 3$") as e:
        jik.repeatability(P, X0, [(1, 1), (1, 2, 3)])
    assert e.value.field == "path.1"


def test_plan_atlas_names_both_missing_arguments():
    """n_starts alone: the message names arc and reference, and what each is."""
    with pytest.raises(InvalidInputError) as info:
        jik.plan_atlas(P, LOOP, n_starts=64)
    assert info.value.field == "arc"
    assert str(info.value).startswith("n_starts needs arc and reference: arc = (lo, hi)")
    assert "reference, a configuration (3 numbers" in str(info.value)


def test_a_practical_inverse_without_its_default_says_how_to_give_it():
    """A planar chain has neither joint limits nor a home: make_inverse names the argument that
    gives each (make_inverse takes no ``limits=`` or ``rest=``), and the message's call works."""
    chain = jik.PlanarChain(joints="RRR", lengths=[1.0, 0.8, 0.6])
    for algorithm, field, given in (
        ("weighted", "limits", {"algorithm_parameters": {"limits": [[-2.0, 2.0]] * 3}}),
        ("posture", "rest", {"algorithm_parameters": {"rest": [0.3, 1.0, 1.0]}}),
        ("posture", "rest", {"x0": [0.3, 1.0, 1.0]}),
    ):
        with pytest.raises(InvalidInputError) as info:
            jik.make_inverse(chain, algorithm)
        assert info.value.field == field
        assert f"algorithm_parameters={{'{field}': [" in str(info.value)
        assert ("x0=[...]" in str(info.value)) == (field == "rest")
        assert jik.make_inverse(chain, algorithm, **given).name == algorithm


def test_texts_for_objects_say_how_to_make_them():
    """A robot's or a formula's name where an object belongs: the message shows the call."""
    with pytest.raises(InvalidInputError, match=r"robot_from_dict\(\{'name': 'manipulator2'\}\)"):
        jik.Pseudoinverse("manipulator2")
    with pytest.raises(InvalidInputError, match=r"FormulaMap\('x3', \['x1', 'x2', 'x3'\]\)"):
        jik.ExtendedInverse(ARM, "x3")


def test_a_urdf_file_without_its_folder_says_how_to_give_one(tmp_path):
    """urdf_file is relative to a folder: from Python, robot_from_dict's base_dir names it."""
    (tmp_path / "arm4.urdf").write_text((ROOT / "tests/data/arm4.urdf").read_text())
    arm = {"name": "urdf", "urdf_file": "arm4.urdf", "end_link": "tool"}
    with pytest.raises(InvalidInputError, match="which robot_from_dict takes as base_dir") as info:
        jik.robot_from_dict(arm)
    assert info.value.field == "urdf_file"
    assert jik.robot_from_dict(arm, base_dir=tmp_path).kinematics.p == 4


def _ur5e():
    return jik.robot_from_dict({"name": "ur5e"}).kinematics


def _robots():
    """One kinematics of each kind, built-in, user-defined and URDF."""
    return [
        jik.Manipulator1(),
        jik.Manipulator2(),
        jik.PlanarChain("RRR", [1, 1, 1]),
        jik.PlanarChain("RPR", [1, 1, 1], orientation=True),
        jik.FormulaKinematics(["a", "b", "c"], ["a + cos(c)", "b + sin(c)"]),
        _ur5e(),
        jik.Unicycle(),
    ]


def _methods(kin):
    names = ["forward", "jacobian", "manipulability", "is_singular"]
    names += ["forward_jacobian"] * hasattr(kin, "forward_jacobian")
    return [getattr(kin, n) for n in names]


@pytest.mark.parametrize("kin", _robots(), ids=lambda k: f"{k.name}-p{k.p}-r{k.r}")
def test_every_kinematics_checks_x_at_its_public_methods(kin):
    """Wrong width (short, long, a matrix's rows), a scalar, NaN, inf and text: InvalidInputError
    with field "x", for forward, jacobian, forward_jacobian, manipulability and is_singular alike
    (Manipulators 1 and 2 give m(x) in closed form: a wrong width gave a number)."""
    p = kin.p
    bad = [np.zeros(p - 1), np.zeros(p + 2), np.zeros((4, p + 1)), 0.5, [np.nan] * p, "x1"]
    bad.append(np.r_[np.full(p - 1, 0.1), np.inf])
    for method in _methods(kin):
        for x in bad:
            with pytest.raises(InvalidInputError) as info:
                method(x)
            assert info.value.field == "x", (method.__name__, x)


@pytest.mark.parametrize("kin", _robots(), ids=lambda k: f"{k.name}-p{k.p}-r{k.r}")
def test_the_checked_methods_give_the_cores_numbers(kin):
    """A batch of good configurations (a list, or a float array with huge finite entries whose
    sum overflows): the checked method and the unchecked core agree, bit for bit."""
    x = np.random.default_rng(3).uniform(0.1, 0.6, (5, kin.p))
    np.testing.assert_array_equal(kin.forward(x.tolist()), kin.forward_unchecked(x))
    np.testing.assert_array_equal(kin.jacobian(x), kin.jacobian_unchecked(x))
    if not isinstance(kin, jik.Unicycle):  # (its quadrature refuses such controls)
        huge = np.full((2, kin.p), 1e308)
        with np.errstate(all="ignore"):
            np.testing.assert_array_equal(kin.forward(huge), kin.forward_unchecked(huge))


def test_a_users_kinematics_gets_the_check():
    """A subclass written as STYLE.md shows it (forward and jacobian only) is checked too."""

    class Line(Kinematics):
        name, p, r = "line", 2, 1

        def forward(self, x):
            return x[..., :1] + x[..., 1:]

        def jacobian(self, x):
            return np.ones((*x.shape[:-1], 1, 2))

    with pytest.raises(InvalidInputError, match=r"x must have shape \(\.\.\., 2\)") as info:
        Line().forward(np.zeros(3))
    assert info.value.field == "x"
    np.testing.assert_array_equal(Line().forward([1.0, 2.0]), [3.0])


def test_refused_starts_say_why_each_start_of_a_batch_cannot_run():
    """Of three starts, the overflowing one (k(x0) = exp(800)) and the singular one (x2 = 0: the
    row of x2^2 in J vanishes) are refused, each with its reason; the good one is not."""
    from jik.engine.solve_rules import refused_starts

    arm = jik.FormulaKinematics(["x1", "x2", "x3"], ["exp(x1) + x3", "x2**2"])
    refused = refused_starts(
        jik.Pseudoinverse(arm), [[0.1, 0.5, 0.5], [800.0, 0.5, 0.5], [0.1, 0.0, 0.5]]
    )
    assert sorted(refused) == [1, 2]
    assert list(refused_starts(jik.Pseudoinverse(LOG_ARM), [[-1, 0, 0], [1, 0, 0]])) == [0]
    assert refused[1] == (
        "the kinematics are not finite at the start: k(x0) = (inf, 0.25), its Jacobian not "
        "finite (the task is undefined there, or overflows); choose a start where both are finite"
    )
    assert "J J^T is singular" in refused[2] and refused[2].endswith("; move the start")


def test_a_singular_configuration_names_its_input_as_invalid_input_does():
    """A singular start is ``x0``'s, a point handed to an inverse ``x``'s, a singular point of
    a synthesis region ``region``'s: ``error.field``, as an InvalidInputError's."""
    chain = jik.PlanarChain("RRR", [1, 1, 1])
    inverse, stretched = jik.Pseudoinverse(chain), [0.0, 0.0, 0.0]  # J loses rank there
    region = {"x2": (-1, 1)}  # (x1 = x3 = 0 held; 17 Gauss nodes have x2 = 0)
    cases = [
        (lambda: jik.solve(inverse, stretched, [1, 1]), "x0"),
        (lambda: jik.solve(inverse, stretched, [1, 1], mode="discrete", gamma=0.5), "x0"),
        (lambda: inverse.apply(np.array(stretched), np.array([1.0, 1.0])), "x"),
        (lambda: jik.error_functional_e2(chain, jik.PaperCubic(), region, nodes=17), "region"),
    ]
    for call, field in cases:
        with pytest.raises(jik.KinematicSingularityError) as info:
            call()
        assert info.value.field == field, str(info.value)
        np.testing.assert_allclose(info.value.configuration.shape, (3,))


def test_a_batch_without_starts_names_x0():
    """solve_batch with no start at all: the fault is x0's (it has 0 configurations), not the
    one target's; a count that differs otherwise names y_d."""
    inverse = jik.Pseudoinverse(jik.Manipulator2())
    with pytest.raises(jik.InvalidInputError, match="x0 has 0 configurations") as empty:
        jik.solve_batch(inverse, np.zeros((0, 3)), [1, 1])
    assert empty.value.field == "x0"
    with pytest.raises(jik.InvalidInputError) as counts:
        jik.solve_batch(inverse, np.zeros((2, 3)), np.ones((3, 2)))
    assert counts.value.field == "y_d"


def test_a_map_without_a_real_value_at_the_start_is_refused():
    """h = log(-1 - x2**2) + x3 has a real gradient (a run would go) and no real value: what the
    extended inverse keeps, h(x) = h(x0), means nothing, so a repeatability run (or its first
    leg) and the check of a batch's starts refuse it (x0); h = log(x2) + x3 only where
    x2 <= 0."""
    nowhere = jik.FormulaMap("log(-1 - x2**2) + x3", NAMES)
    inverse = jik.ExtendedInverse(ARM, nowhere)
    with pytest.raises(jik.AlgorithmicSingularityError) as info:
        jik.repeatability(inverse, X0, PATH, cycles=2)
    assert info.value.field == "x0"
    assert str(info.value).startswith(
        "the augmenting map has no real value at the start (h(x0) = nan): the extended inverse "
        "(11) keeps h(x) = h(x0), which means nothing there"
    )
    # With a progress that stops a run at an error (the dashboard's), its first leg stops.
    stopping = jik.ProgressCallbacks(stop_at_error=True)
    run = jik.repeatability(inverse, X0, PATH, cycles=2, progress=stopping)
    assert not run.success and "no real value at the start" in run.message
    with pytest.raises(jik.AlgorithmicSingularityError):  # (a batch: refused)
        jik.repeatability(inverse, [X0, X0], PATH, cycles=2)
    somewhere = jik.ExtendedInverse(ARM, jik.FormulaMap("log(x2) + x3", NAMES))
    refused = refused_starts(somewhere, [[0, 0.5, 1.0], [0, -0.5, 1.0]])
    assert list(refused) == [1] and "no real value" in refused[1]
    assert not refused_starts(jik.Pseudoinverse(ARM), [[0, -0.5, 1.0]])


@pytest.mark.parametrize("mode", ["continuous", "discrete"])
def test_a_solve_from_a_start_without_a_real_map_value_is_refused_as_repeatability_does(mode):
    """h = log(x3) at x3 = -1: dh = 1/x3 is finite, so a run would go, but h(x) = h(x0) means
    nothing; solve refuses the start as repeatability does (the same error, field x0), and a
    batch with such a start is refused whole, as a repeatability batch is."""
    inverse = jik.ExtendedInverse(ARM, jik.FormulaMap("log(x3)", NAMES))
    gamma = 0.5 if mode == "discrete" else 1.0
    with pytest.raises(jik.AlgorithmicSingularityError) as run:
        jik.repeatability(inverse, [0, 0, -1.0], [(1, 1)], mode=mode, gamma=gamma)
    with pytest.raises(jik.AlgorithmicSingularityError) as one:
        jik.solve(inverse, [0, 0, -1.0], [1, 1], mode=mode, gamma=gamma)
    with pytest.raises(jik.AlgorithmicSingularityError) as batch:
        jik.solve_batch(inverse, [[0, 0, 1.0], [0, 0, -1.0]], [1, 1], mode=mode, gamma=gamma)
    for info in (one, batch):
        assert info.value.field == "x0" and str(info.value) == str(run.value)
        np.testing.assert_allclose(info.value.configuration, [0, 0, -1.0])
    assert jik.solve(inverse, [0, 0, 1.0], [1, 1], mode=mode, gamma=gamma).success


@pytest.mark.parametrize(
    "error",
    [
        jik.SingularConfigurationError,
        jik.KinematicSingularityError,
        jik.AlgorithmicSingularityError,
        jik.OneFormUndefinedError,
    ],
)
def test_a_singular_configuration_error_crosses_to_another_process_whole(error):
    """A notebook's multiprocessing pool whose worker met a singular start hung for good: its
    result thread could not unpickle the error (``__init__`` wants the configuration). It
    pickles with its message, configuration and field, the message not repeated."""
    raised = error("J loses rank", [0.0, 1.0, math.pi / 2], "x0")
    copy = pickle.loads(pickle.dumps(raised))
    assert type(copy) is error and str(copy) == str(raised) == "J loses rank at x = (0, 1, 1.5708)"
    assert copy.field == "x0" and np.array_equal(copy.configuration, raised.configuration)
    assert isinstance(copy, jik.JikError)
