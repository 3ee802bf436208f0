"""The box of a synthesis given none (:func:`jik.engine.robot_synthesis.default_box`)."""

from __future__ import annotations

import math

import pytest

from jik.engine.registry import ROBOTS
from jik.engine.robot_synthesis import default_box


def test_the_design_region_when_it_has_that_many_variables():
    assert default_box(ROBOTS["manipulator2"], 2) == {"x2": (-1.0, 1.0), "x3": (0.0, math.pi)}
    assert default_box(ROBOTS["manipulator1"], 3) == {
        "x1": (0.0, 1.0),
        "x2": (0.0, 1.0),
        "x3": (0.5, 1.5),
    }


def test_else_a_tenth_of_each_range_about_the_default_start():
    """Manipulator 2's three variables (its design region has two): x0 = (0, 0, pi/2), each
    range 6 or 3 pi wide."""
    box = default_box(ROBOTS["manipulator2"], 3)
    assert list(box) == ["x1", "x2", "x3"]
    assert box["x1"] == pytest.approx((-0.6, 0.6))
    assert box["x3"] == pytest.approx((math.pi / 2 - 0.3 * math.pi, math.pi / 2 + 0.3 * math.pi))


def test_fixed_variables_stay_out_and_the_box_stays_in_the_range():
    """A fixed variable of the design region leaves it; the unicycle (no design region) takes
    its last variables, each clipped to its range."""
    assert list(default_box(ROBOTS["manipulator2"], 2, fixed={"x3"})) == ["x1", "x2"]
    spec = ROBOTS["unicycle"]
    box = default_box(spec, 2)
    assert list(box) == list(spec.variable_names[-2:])
    for name, (lo, hi) in box.items():
        low, high = spec.x_range[spec.variable_names.index(name)]
        assert low <= lo < hi <= high
