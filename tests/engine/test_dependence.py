"""engine.dependence: the joint variables that J, h and dh ignore."""

from __future__ import annotations

import pytest

from jik.engine.augmentations import E2Optimal, PaperCubic, Polynomial2
from jik.engine.dependence import inert_variables
from jik.engine.exceptions import InvalidInputError
from jik.engine.kinematics import Manipulator1, Manipulator2

BOX = ((-2.0, 2.0), (-2.0, 2.0), (0.0, 3.0))


def test_inert_variables_are_those_j_h_and_dh_ignore():
    """Shifting x_k must leave J, h and dh unchanged; a map with a constant dh/dx_k still
    depends on x_k through its value."""
    m2 = Manipulator2()
    assert inert_variables(m2, PaperCubic(), BOX) == {0}  # J(x3), h(x2, x3)
    assert inert_variables(Manipulator1(), E2Optimal(0.5, 1.0), BOX) == {1}  # J(x1, x3), h(x1, x3)
    assert inert_variables(m2, Polynomial2({(1, 0): 1.0}, variables=(1, 2), p=3), BOX) == {0}
    # h = x1 + x2: dh = (1, 1, 0) does not change with x1 or x2, h does; J depends on x3
    h = Polynomial2({(1, 0): 1.0, (0, 1): 1.0}, variables=(0, 1), p=3)
    assert inert_variables(m2, h, BOX) == frozenset()
    assert inert_variables(m2, None, BOX) == frozenset()  # (a vector of maps: not probed)

    class Unprobeable(PaperCubic):  # a map that raises where it is probed: every variable counts
        def value_masked(self, x):
            raise ValueError("cannot evaluate here")

    assert inert_variables(m2, Unprobeable(), BOX) == frozenset()


@pytest.mark.parametrize("box", [BOX[:2], ((0, 1), (0, 1), (0, float("inf"))), "box", None])
def test_a_bad_box_is_named(box):
    with pytest.raises(InvalidInputError, match="box must be 3 finite pairs") as info:
        inert_variables(Manipulator2(), PaperCubic(), box)
    assert info.value.field == "box"
