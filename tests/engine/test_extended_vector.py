"""The extended inverse with p - r > 1 augmenting maps: eq. (12) and repeatability."""

import numpy as np
import pytest

from jik.engine.augmentations import PaperCubic
from jik.engine.exceptions import AlgorithmicSingularityError, InvalidInputError
from jik.engine.extended_vector import VectorExtendedInverse
from jik.engine.formula_kinematics import FormulaMap
from jik.engine.inverses import ExtendedInverse, Pseudoinverse
from jik.engine.kinematics import Manipulator2
from jik.engine.planar_chain import PlanarChain
from jik.engine.repeatability import repeatability

RNG = np.random.default_rng(5)
CHAIN = PlanarChain("RRRRR", [0.6, 0.5, 0.4, 0.3, 0.2])
NAMES = CHAIN.variable_names
MAPS = [FormulaMap(h, NAMES) for h in ("x3 - x2", "x4 - x3", "x5 - x4 + 0.1*sin(x1)")]
X0 = np.array([0.2, 0.5, 0.6, 0.4, 0.3])


def test_one_map_is_the_extended_inverse_of_eq_11():
    kin, h = Manipulator2(), PaperCubic()
    x = RNG.uniform(-1, 1, (20, 3))
    e = RNG.normal(size=(20, 2))
    ours, theirs = VectorExtendedInverse(kin, [h]), ExtendedInverse(kin, h)
    np.testing.assert_allclose(ours.matrix(x), theirs.matrix(x), atol=1e-12)
    np.testing.assert_allclose(ours.apply(x, e), theirs.apply(x, e), atol=1e-12)


def test_right_inverse_annihilated_by_every_dh():
    """J J^E# = I_r and dh_i J^E# = 0 for i = 1 .. p - r, eq. (12)."""
    inv = VectorExtendedInverse(CHAIN, MAPS)
    x = X0 + RNG.uniform(-0.3, 0.3, (30, 5))
    JE = inv.matrix(x)
    np.testing.assert_allclose(
        CHAIN.jacobian(x) @ JE, np.broadcast_to(np.eye(2), (30, 2, 2)), atol=1e-12
    )
    dh = np.stack([m.gradient(x) for m in MAPS], axis=-2)
    np.testing.assert_allclose(dh @ JE, 0.0, atol=1e-12)
    assert inv.augmenting_value(x).shape == (30, 3)


def test_five_joint_arm_is_repeatable_with_three_maps():
    home = CHAIN.forward(X0)
    path = home + np.array([[0.15, 0.0], [0.15, 0.15], [0.0, 0.15]])
    pinv = repeatability(Pseudoinverse(CHAIN), X0, path, cycles=3)
    ext = repeatability(VectorExtendedInverse(CHAIN, MAPS), X0, path, cycles=3, record=True)
    assert pinv.success and ext.success
    assert pinv.drift[-1] > 1e-4
    assert np.max(ext.drift) < 1e-9
    h = np.concatenate([r.trajectory.h for r in ext.leg_results])  # conserved along (7)
    np.testing.assert_allclose(h, np.broadcast_to(h[0], h.shape), atol=1e-8)


def test_wrong_number_of_maps_and_singular_start():
    with pytest.raises(InvalidInputError, match="needs p - r = 3 augmenting maps, got 2"):
        VectorExtendedInverse(CHAIN, MAPS[:2])
    with pytest.raises(InvalidInputError, match=r"map 2 is defined on R\^3"):
        VectorExtendedInverse(CHAIN, [*MAPS[:2], PaperCubic()])
    same = [FormulaMap("x3", NAMES), FormulaMap("2*x3", NAMES), FormulaMap("x4", NAMES)]
    with pytest.raises(AlgorithmicSingularityError, match="singular"):
        VectorExtendedInverse(CHAIN, same).matrix(X0)


def test_map_undefined_tells_an_undefined_map_from_a_singular_extended_jacobian():
    """Where a map h_i is undefined (sqrt(x1) for x1 < 0) J^E# is undefined because h is:
    ``map_undefined`` says so (the solver's status "undefined"), for several maps and for one;
    the pseudoinverse has no map: never."""
    x = np.array([X0, [-0.2, *X0[1:]]])
    inv = VectorExtendedInverse(CHAIN, [FormulaMap("sqrt(x1)", NAMES), *MAPS[1:]])
    assert inv.map_undefined(x).tolist() == [False, True]
    assert Pseudoinverse(CHAIN).map_undefined(x).tolist() == [False, False]
    kin = Manipulator2()
    one = ExtendedInverse(kin, FormulaMap("sqrt(x1)", kin.variable_names))
    assert one.map_undefined(x[:, :3]).tolist() == [False, True]
    assert not ExtendedInverse(kin, PaperCubic()).map_undefined(x[:, :3]).any()


def test_the_error_names_the_undefined_map_or_says_singular():
    """The error said "singular or a map is undefined" either way; it names the map h_i
    undefined there, and says "singular" only where [J; dh] is."""
    inv = VectorExtendedInverse(CHAIN, [FormulaMap("sqrt(x1)", NAMES), *MAPS[1:]])
    with pytest.raises(
        AlgorithmicSingularityError, match=r"map h_1 = FormulaMap\('sqrt\(x1\)'\) is undef"
    ):
        inv.matrix([-0.2, *X0[1:]])
    same = [FormulaMap("x3", NAMES), FormulaMap("2*x3", NAMES), FormulaMap("x4", NAMES)]
    with pytest.raises(AlgorithmicSingularityError, match=r"\] of .* is singular \(") as info:
        VectorExtendedInverse(CHAIN, same).matrix(X0)
    assert "undefined" not in str(info.value)


def test_a_run_with_a_vector_of_maps_is_a_table_of_one_number_per_cell():
    """The trajectory of p - r = 3 maps has a column per map, h_1..h_3, each h_i(x) along the
    run, so that its table (and a DataFrame or CSV of it) holds numbers, not a list per cell."""
    from jik.engine.exports import csv_text
    from jik.engine.solver import solve

    inv = VectorExtendedInverse(CHAIN, MAPS)
    trajectory = solve(inv, X0, CHAIN.forward(X0) + 0.05).trajectory
    columns = trajectory.columns()
    assert list(columns)[-4:] == ["error", "h_1", "h_2", "h_3"]
    assert all(np.ndim(c) == 1 for c in columns.values())
    for i, h in enumerate(MAPS):
        np.testing.assert_allclose(columns[f"h_{i + 1}"], h.value(trajectory.x), atol=1e-12)
    header, first = "".join(csv_text([columns], "\n")).splitlines()[:2]
    assert header.split(",")[-3:] == ["h_1", "h_2", "h_3"]
    assert [float(v) for v in first.split(",")[-3:]] == pytest.approx(trajectory.h[0])
