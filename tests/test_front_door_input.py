"""Bad input at the engine's front door: each public function below refuses it with an
InvalidInputError whose ``field`` names the argument (or, past a joint limit, with the typed
singularity its ``apply`` raises), never a raw numpy or scipy error nor a silent result."""

import re

import numpy as np
import pytest

import jik.engine as jik
from jik.app.compute.robot_requests import request_field
from jik.engine.exceptions import InvalidInputError, KinematicSingularityError

ARM = jik.PlanarChain("RRR", [1.0, 0.8, 0.6])
CHAIN4 = jik.PlanarChain("RRRR", [1.0] * 4)
LIMITS = [[-2.0, 2.0]] * 3


def refuses(call, field: str, text: str = "") -> InvalidInputError:
    """Run ``call``; it must raise InvalidInputError with ``field`` (and ``text`` in its
    message)."""
    with pytest.raises(InvalidInputError, match=re.escape(text) if text else None) as info:
        call()
    assert info.value.field == field, info.value
    return info.value


def test_the_weighted_matrix_raises_past_a_joint_limit_as_apply_does():
    """Past a joint limit J^W# is undefined: matrix raises the error apply raises."""
    inverse = jik.WeightedInverse(ARM, LIMITS)
    x = np.array([3.0, 0.5, 0.5])
    with pytest.raises(KinematicSingularityError, match="joint 1 is at or past its limits"):
        inverse.apply(x, np.ones(2))
    with pytest.raises(KinematicSingularityError, match="joint 1 is at or past its limits") as e:
        inverse.matrix(x)
    assert e.value.field == "x"
    inside = inverse.matrix(np.array([1.0, 0.5, 0.5]))  # (inside the limits: a right inverse)
    assert np.allclose(ARM.jacobian(np.array([1.0, 0.5, 0.5])) @ inside, np.eye(2), atol=1e-12)


@pytest.mark.parametrize("limits", ["abc", [[0, 1], [0], [0, 1]], [[{}, 1]] * 3])
def test_weighted_limits_that_are_not_pairs_of_numbers_are_refused(limits):
    refuses(lambda: jik.WeightedInverse(ARM, limits), "limits", "limits must be 3 pairs")


def test_rest_given_must_be_a_boolean():
    refuses(lambda: jik.PostureInverse(ARM, [0.1, 0.2, 0.3], rest_given="no"), "rest_given")


@pytest.mark.parametrize(
    ("amap", "x"),
    [
        (jik.PaperCubic(), np.zeros(2)),
        (jik.PaperCubic(), np.zeros(4)),
        (jik.E1Optimal(), np.zeros(2)),
        (jik.E2Optimal(), np.zeros((5, 2))),
        (jik.FormulaMap("x3-x2", ["x1", "x2", "x3"]), np.zeros(2)),
    ],
)
def test_a_map_refuses_configurations_of_another_width(amap, x):
    """h: R^3 -> R takes x of shape (..., 3) only, at value and gradient alike."""
    refuses(lambda: amap.value(x), "x", "x must have shape (..., 3)")
    refuses(lambda: amap.gradient(x), "x", "x must have shape (..., 3)")


def test_a_map_still_takes_batches_and_lets_nan_through():
    """Batches (..., p) work; a NaN configuration gives NaN where h depends on it."""
    h = jik.PaperCubic()
    assert h.value(np.zeros((4, 5, 3))).shape == (4, 5)
    assert h.gradient([[0.0, 0.1, 0.2]]).shape == (1, 3)
    assert np.isnan(h.value(np.array([0.0, np.nan, 0.0])))


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"seed": -1}, "seed"),
        ({"seed": "a"}, "seed"),
        ({"seed": 1.5}, "seed"),
        ({"seed": True}, "seed"),
        ({"spread": -1}, "spread"),
    ],
)
def test_manifold_starts_refuses_a_bad_seed_or_spread(kwargs, field):
    x0, box = [0.2, 0.5, 0.6, 0.7], [(-3, 3)] * 4
    refuses(lambda: jik.manifold_starts(CHAIN4, x0, 5, box, **kwargs), field)


@pytest.mark.parametrize("seed", [-1, "a", 1.5, True])
def test_synthesis_nd_refuses_a_bad_seed(seed):
    region = {"x2": (-1, 1), "x3": (-1, 1)}
    refuses(
        lambda: jik.synthesize_e2_nd(CHAIN4, region, degree=2, nodes=256, seed=seed),
        "seed",
        "seed must be",
    )


@pytest.mark.parametrize("kinematics", [5, ["x1", "x2"], "x1x2x3", ["x1", 2, "x3"]])
def test_map_grid_refuses_names_that_are_not_the_maps_variables(kinematics):
    region = {"x2": (-1, 1), "x3": (0, 3)}
    refuses(lambda: jik.map_grid(jik.PaperCubic(), kinematics, region), "kinematics")


@pytest.mark.parametrize("slot", ["on_leg", "on_advance", "is_cancelled"])
def test_progress_callbacks_must_be_functions(slot):
    refuses(lambda: jik.ProgressCallbacks(**{slot: 5}), slot, f"{slot} must be a function")


def test_errors_name_the_parameter_given():
    """VectorExtendedInverse's maps are ``augmenting_maps``, plan_atlas's scales ``scales``;
    the REST field of the former stays ``augmentation``."""
    refuses(lambda: jik.VectorExtendedInverse(CHAIN4, []), "augmenting_maps", "needs p - r = 2")
    assert request_field("augmenting_maps", ()) == "augmentation"
    inverse = jik.Pseudoinverse(jik.Manipulator2())
    path = [(0.0, 1.0), (1.0, 1.0), (1.0, 2.0)]
    x0 = [0.0, 0.0, np.pi / 2]
    refuses(lambda: jik.plan_atlas(inverse, path, starts=[x0], scales=[]), "scales")


@pytest.mark.parametrize("names", [["a"], ["a", 2], "ab"])
def test_robot_units_needs_one_name_per_task_coordinate(names):
    refuses(lambda: jik.robot_units(jik.Manipulator2(), names), "task_names", "2 strings")


@pytest.mark.parametrize(
    ("args", "field"),
    [
        (("pseudoinverse", "abc", True, "ok", True, "m"), "drift"),
        (("pseudoinverse", [[0.1, 0.2]], True, "ok", True, "m"), "drift"),
        (("pseudoinverse", [0.1], "yes", "ok", True, "m"), "success"),
        (("pseudoinverse", [0.1], True, "ok", True, None), "unit"),
    ],
)
def test_run_findings_refuses_what_is_not_a_run(args, field):
    refuses(lambda: jik.run_findings(*args), field)


@pytest.mark.parametrize("dtype", [np.int64, np.float32], ids=lambda t: t.__name__)
def test_numpy_numbers_are_numbers_for_lengths_offsets_and_parameters(dtype):
    """A notebook's lengths, offsets or formula parameters from numpy (np.ones(3, np.float32),
    np.int64(2)) were refused as "must be a number"; they are the same robot and map as with
    Python numbers. A boolean is still no number."""
    lengths, offsets = np.array([1, 1, 2], dtype=dtype), np.zeros(3, dtype=dtype)
    chain = jik.PlanarChain("RRR", lengths, offsets=offsets)
    assert repr(chain) == repr(jik.PlanarChain("RRR", [1.0, 1.0, 2.0], offsets=[0.0] * 3))
    task = ["x2 + l*cos(x3)", "x1 + l*sin(x3)"]
    robot = jik.FormulaKinematics(["x1", "x2", "x3"], task, parameters={"l": dtype(2)})
    x = np.array([0.1, 0.2, 0.3])
    assert np.array_equal(robot.forward(x), jik.Manipulator2(l=2.0).forward(x))
    h = jik.FormulaMap("x3 + a*x2", ["x1", "x2", "x3"], {"a": dtype(2)})
    assert h.value(x) == jik.FormulaMap("x3 + a*x2", ["x1", "x2", "x3"], {"a": 2.0}).value(x)
    refuses(lambda: jik.PlanarChain("RRR", [1.0, np.bool_(True), 1.0]), "lengths.1")


def test_an_atlas_arc_from_numpy_is_the_same_plan():
    """plan_atlas's arc as a numpy pair (np.array([-0.5, 0.5]), np.linspace's ends) was refused
    as "arc must be a pair"; it plans the same starts as the tuple. A pair of pairs is not."""
    m2 = jik.Pseudoinverse(jik.Manipulator2())
    path, x0 = [(1, 1), (1, 2), (0, 2)], [0.0, 0.0, np.pi / 2]

    def plan(arc):
        return jik.plan_atlas([m2], path, n_starts=4, arc=arc, reference=x0)

    assert np.array_equal(plan(np.array([-0.5, 0.5])).starts(0, 4), plan((-0.5, 0.5)).starts(0, 4))
    refuses(lambda: plan(np.zeros((2, 2))), "arc")


@pytest.mark.parametrize("arc", [np.array(0.5), np.zeros(3), 0.5], ids=["0-d", "three", "float"])
def test_an_atlas_arc_that_is_no_pair_is_refused_naming_arc(arc):
    """A numpy scalar as plan_atlas's arc (np.array(0.5), a slip for a half-width) met a
    TypeError (len() of unsized object) where any other wrong arc is refused naming arc."""
    m2 = jik.Pseudoinverse(jik.Manipulator2())
    path, x0 = [(1, 1), (1, 2), (0, 2)], [0.0, 0.0, np.pi / 2]
    refuses(lambda: jik.plan_atlas([m2], path, n_starts=4, arc=arc, reference=x0), "arc")
