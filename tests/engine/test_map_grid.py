"""h on a plane of a box (engine.map_grid): the two variables h varies most with, h's values
at the grid's points, NaN where a map raises."""

import numpy as np
import pytest

from jik.engine.augmentations import PaperCubic
from jik.engine.exceptions import JikError
from jik.engine.functionals import check_region
from jik.engine.kinematics import Manipulator2
from jik.engine.map_grid import axes_along, grid_axes, map_grid, slice_values, varying_most

NAMES = ("x1", "x2", "x3")
BOX = {"x1": (-1.0, 1.0), "x2": (0.4, 2.0), "x3": (0.4, 2.0)}


def test_the_grid_spans_the_two_variables_h_depends_on():
    """The paper's cubic (38) is h(x2, x3): x1, on which it does not depend, is no axis."""
    amap = PaperCubic()
    grid = map_grid(amap, NAMES, BOX, n=5)
    assert grid is not None and list(grid.axes) == ["x2", "x3"]
    np.testing.assert_allclose(grid.axes["x2"], np.linspace(0.4, 2.0, 5), atol=0)
    assert grid.h.shape == (5, 5)


def test_the_grid_holds_h_at_its_points_the_others_at_the_box_centre_or_fixed():
    amap = PaperCubic()
    box = {"x2": BOX["x2"], "x3": BOX["x3"]}
    grid = map_grid(amap, NAMES, box, fixed={"x1": 0.7}, n=4)
    assert grid is not None
    for i, a in enumerate(grid.axes["x2"]):
        for j, b in enumerate(grid.axes["x3"]):
            assert grid.h[i, j] == pytest.approx(
                float(amap.value(np.array([0.7, a, b]))), abs=1e-14
            )


def test_a_robots_grid_holds_the_others_where_e1_e2_and_the_syntheses_do():
    """Manipulator 2's cubic (38) over a box of x1, x2: x3 is held at the robot's start pi/2
    (held_values), the plane on which E1, E2 and the syntheses of that box take h, not at 0
    (where h's extended Jacobian is singular); a fixed value still wins, and a map of names
    alone holds them at 0."""
    kin, amap = Manipulator2(1.0), PaperCubic()
    box = {"x1": (-1.0, 1.0), "x2": (0.4, 2.0)}
    x3 = check_region(kin, box)[1]["x3"]
    assert x3 == pytest.approx(np.pi / 2)
    for robot, fixed, at in ((kin, None, x3), (kin, {"x3": 0.3}, 0.3), (NAMES, None, 0.0)):
        grid = map_grid(amap, robot, box, fixed=fixed, n=3)
        assert grid is not None
        want = [
            [float(amap.value(np.array([a, b, at]))) for b in grid.axes["x2"]]
            for a in grid.axes["x1"]
        ]
        np.testing.assert_allclose(grid.h, want, atol=1e-14)


def test_axes_of_a_box_of_three_follow_the_largest_partial_derivatives():
    """A gradient largest along x1, then x3, zero along x2: the axes are x1 and x3."""

    class OfX1(PaperCubic):
        def gradient(self, x):
            g = np.zeros(np.shape(x))
            g[..., 0] = 1.0
            g[..., 2] = 0.5
            return g

    assert grid_axes(OfX1(), NAMES, BOX, np.zeros(3)) == ["x1", "x3"]


def test_varying_most_weighs_by_the_spread_and_leaves_out_where_h_is_undefined():
    """Mean |dh/dx_i| over the defined rows (a NaN row left out, a never-defined variable
    last); with a spread, each times spread_i + 1: a variable the configurations move along
    overtakes a steeper one they do not."""
    dh = np.array([[1.0, 0.0, 0.5, np.nan], [1.0, 0.0, 0.5, np.nan], [np.nan] * 4])
    assert varying_most(dh) == (0, 2)
    assert varying_most(dh, np.array([0.0, 0.0, 2.0, 9.0])) == (0, 2)
    assert varying_most(dh, np.array([0.0, 5.0, 2.0, 9.0])) == (0, 2)
    assert varying_most(dh[:, [1, 3, 2]], np.array([0.0, 9.0, 0.0])) == (0, 2)
    steep = np.array([[0.3, -1.0, 0.6]])
    assert varying_most(steep) == (1, 2)
    assert varying_most(steep, np.array([3.0, 0.0, 0.0])) == (0, 1)
    assert varying_most(np.full((2, 3), np.nan)) == (0, 1)


def test_a_map_that_raises_somewhere_is_nan_there_and_evaluated_elsewhere():
    class Partial(PaperCubic):
        def value(self, x):
            x = np.asarray(x, dtype=float)
            if x.ndim > 1 or x[1] > 1.0:
                raise JikError("undefined here")
            return super().value(x)

    grid = map_grid(Partial(), NAMES, {"x2": (0.5, 1.5), "x3": (0.5, 1.5)}, n=3)
    assert grid is not None
    assert np.isnan(grid.h[2]).all() and np.isfinite(grid.h[:2]).all()
    assert repr(grid).endswith("3 x 3 points, h in [-1.139, -0.1031], undefined at 3)")


def test_a_grid_prints_on_one_line_as_what_it_holds():
    """As the other results: its box, its size and h's range, not its arrays."""
    grid = map_grid(PaperCubic(), NAMES, BOX, n=101)
    assert repr(grid) == (
        "MapGrid(x2 in [0.4, 2] x x3 in [0.4, 2], 101 x 101 points, h in [-2.292, 0.001372])"
    )


def test_a_box_of_one_variable_has_no_grid():
    assert map_grid(PaperCubic(), NAMES, {"x2": (0.4, 2.0)}) is None


def test_a_slice_holds_h_at_its_points_and_its_axes_follow_the_runs():
    """The cubic (38) on a slice over (x2, x3) at x1 = 0.3: H[b, a] is h at x2 = u[a],
    x3 = v[b]; along configurations that move x2 and x3, those are the axes; a map that
    solves per point is evaluated in batches, each reported."""
    h = PaperCubic()
    u, v, H = slice_values(h, [0.3, 0.0, 0.0], (1, 2), ((-1.0, 1.0), (0.5, 2.0)), 5)
    np.testing.assert_allclose(u, np.linspace(-1, 1, 5))
    np.testing.assert_allclose(H[3, 1], h.value(np.array([0.3, u[1], v[3]])))
    x = np.column_stack([np.zeros(9), np.linspace(-1, 1, 9), np.linspace(0.5, 2, 9)])
    assert axes_along(h, x) == (1, 2)

    class Batched(PaperCubic):
        solves_per_point = True

        def evaluate_batches(self, x, batch, progress):
            for k in range(0, len(x), batch):
                progress.advance(k // batch + 1, -(-len(x) // batch))
            return self.value(x), self.gradient(x), np.zeros(len(x), bool)

    told = []
    slow = slice_values(
        Batched(),
        [0.3, 0.0, 0.0],
        (1, 2),
        ((-1.0, 1.0), (0.5, 2.0)),
        5,
        10,
        lambda done, total: told.append((done, total)),
    )
    np.testing.assert_allclose(slow[2], H)
    assert told == [(1, 3), (2, 3), (3, 3)]
    assert axes_along(Batched(), x, 4, lambda *_: None) == (1, 2)
