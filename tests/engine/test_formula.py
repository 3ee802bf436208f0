"""Formulas: the whitelist grammar, hostile input, and robots and maps given by formulas."""

import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from jik.engine import formula_kinematics
from jik.engine.augmentations import PaperCubic
from jik.engine.characteristics import CharacteristicsMap
from jik.engine.exceptions import FormulaError, InvalidInputError
from jik.engine.formula import parse_formula
from jik.engine.formula_kinematics import FormulaKinematics, FormulaMap
from jik.engine.inverses import ExtendedInverse, Pseudoinverse
from jik.engine.kinematics import Manipulator2
from jik.engine.repeatability import repeatability
from jik.engine.solver import solve
from jik.engine.variational import (
    MANIPULATOR2_REGION,
    default_manipulator2_synthesis,
    synthesize_e2,
)
from tests.helpers import central_difference

RNG = np.random.default_rng(2029)
x1, x2 = sp.symbols("x1 x2", real=True)
NAMES = {"x1": x1, "x2": x2, "l": sp.Integer(2)}
M2 = {"variables": ["x1", "x2", "x3"], "task": ["x2 + l*cos(x3)", "x1 + l*sin(x3)"]}
X0 = np.array([0.0, 0.0, math.pi / 2])
PATH = np.array([[1.0, 1.0], [1.0, 2.0], [0.0, 2.0], [0.0, 1.0]])


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("-x1**2", -(x1**2)),
        ("2**3**2", sp.Integer(512)),
        ("x1/x2/2", x1 / x2 / 2),
        ("x1 - x2 - 1", x1 - x2 - 1),
        ("x1**-2", x1**-2),
        ("2*-x1", -2 * x1),
        ("+x1", x1),
        ("1e-3 * x1 + .5", x1 / 1000 + sp.Rational(1, 2)),
        ("l*cos(x2) + atan2(x1, x2)", 2 * sp.cos(x2) + sp.atan2(x1, x2)),
        ("sqrt(abs(x1)) * exp(log(tan(x2))) + pi", sp.sqrt(sp.Abs(x1)) * sp.tan(x2) + sp.pi),
        ("x1**0.5", sp.sqrt(x1)),
        ("((x1))", x1),
    ],
)
def test_grammar_builds_the_expression(text, expected):
    assert sp.simplify(parse_formula(text, NAMES) - expected) == 0


HOSTILE = [
    ("__import__('os')", "unexpected character '_' at position 0"),
    ("x1.real", "unexpected character '.' at position 2"),
    ("x1.__class__", "unexpected character '.' at position 2"),
    ("lambda x: x", "unexpected character ':' at position 8"),
    ("lambda + x1", "unknown name 'lambda'"),
    ("[x1 for x1 in x2]", "unexpected character '['"),
    ("(x1 for x1 in x2)", "missing ')' at position 4"),
    ("x1**10**10", "exponent out of range (|exponent| <= 16, got 10000000000)"),
    ("x1**1e300", "exponent out of range (|exponent| <= 16, got 1.00000e+300)"),
    ("2**(16**16)", "exponent out of range"),
    ("x1**x2", "exponents must be constants"),
    ("(x1**8)**4", "exceeds 16 once powers are combined"),
    ("x1 + " * 20000 + "x1", "formula too long (100002 characters"),
    ("y + 1", "unknown name 'y'"),
    ("open(x1)", "unknown name 'open'"),
    ("(" * 200 + "x1" + ")" * 200, "nested too deeply"),
    ("sin(" * 60 + "x1" + ")" * 60, "nested too deeply"),
    ("-" * 1000 + "x1", "nested too deeply"),
    ("x1 ^ 2", "write powers as **"),
    ("1/0", "the formula has an undefined constant: a division by zero"),
    ("x1/0", "the formula has an undefined constant: a division by zero"),
    ("sqrt(-1)", "has a complex constant such as sqrt(-1)"),
    ("1e999999999", "number out of range"),
    ("9" * 400, "constant too large"),
    ("sin(x1, x2)", "sin takes 1 argument(s), got 2"),
    ("x1 x2", "unexpected 'x2' at position 3"),
    ("x1 +", "formula ends too early at the end"),
    ("", "empty formula"),
    ("'x1'", "unexpected character"),
    ("x1; x2", "unexpected character ';'"),
    ("x1 = 1", "unexpected character '='"),
]


@pytest.mark.parametrize(("text", "message"), HOSTILE, ids=lambda v: str(v)[:30])
def test_hostile_formulas_are_refused_naming_field_and_position(text, message):
    with pytest.raises(FormulaError) as err:
        parse_formula(text, NAMES, field="task.1")
    assert message in str(err.value)
    assert str(err.value).startswith("task.1: ")
    assert err.value.field == "task.1"
    assert err.value.position is not None and 0 <= err.value.position <= len(text)


def test_parser_never_evaluates_text(monkeypatch):
    """eval, exec, sympify and parse_expr are never called on the text."""
    import builtins

    def forbidden(*args, **kwargs):
        raise AssertionError("called")

    monkeypatch.setattr(builtins, "eval", forbidden)
    monkeypatch.setattr(builtins, "exec", forbidden)
    monkeypatch.setattr(sp, "sympify", forbidden)
    monkeypatch.setattr(sp, "parse_expr", forbidden)
    assert parse_formula("x1*l + sin(x2)", NAMES) == 2 * x1 + sp.sin(x2)


PIECES = [
    "x1",
    "x2",
    "l",
    "pi",
    "sin",
    "atan2",
    "(",
    ")",
    ",",
    "+",
    "-",
    "*",
    "/",
    "**",
    " ",
    "1",
    "0",
    ".",
    "e",
    "9",
    "__",
    "[",
    "'",
    "^",
    "lambda",
    "abs",
]


@settings(max_examples=400, deadline=None)
@given(st.one_of(st.text(max_size=60), st.lists(st.sampled_from(PIECES), max_size=40).map("".join)))
def test_fuzz_parser_fails_only_with_invalid_input(text):
    """Random text: the parser returns an expression or raises InvalidInputError, nothing else."""
    try:
        e = parse_formula(text, NAMES, field="h")
    except InvalidInputError as exc:
        assert str(exc).startswith("h")
    else:
        assert isinstance(e, sp.Expr)
        assert e.free_symbols <= {x1, x2}


def test_formula_robot_derivatives_match_finite_differences():
    kin = FormulaKinematics(
        ["a", "b", "c", "d"],
        [
            "a*cos(b) + exp(-c**2)/(1 + d**2)",
            "sqrt(1 + a**2) * atan2(c, 2 + sin(d))",
            "k*log(2 + cos(a*b)) + abs(d) - tan(c/3)",
        ],
        {"k": 0.7},
    )
    x = RNG.uniform(-1.5, 1.5, (30, 4))
    x[:, 3] = np.abs(x[:, 3]) + 0.1  # away from the kink of abs
    np.testing.assert_allclose(kin.jacobian(x), central_difference(kin.forward, x), atol=1e-8)
    np.testing.assert_allclose(kin.hessian(x), central_difference(kin.jacobian, x), atol=1e-7)
    assert kin.forward(x[0]).shape == (3,) and kin.jacobian(x[0]).shape == (3, 4)


def test_formula_map_gradient_matches_finite_differences():
    h = FormulaMap("x3 - x1*x2 + c*sin(x1)**3", ["x1", "x2", "x3"], {"c": -0.4})
    x = RNG.uniform(-2, 2, (30, 3))
    np.testing.assert_allclose(h.gradient(x), central_difference(h.value, x), atol=1e-8)
    np.testing.assert_allclose(
        h.value(x[0]), x[0, 2] - x[0, 0] * x[0, 1] - 0.4 * np.sin(x[0, 0]) ** 3
    )
    assert h.value(x).shape == (30,) and h.gradient(x[0]).shape == (3,)


def test_constant_entries_broadcast_over_the_batch():
    kin = FormulaKinematics(["u", "v"], ["u + 2*v"])
    J = kin.jacobian(np.zeros((4, 5, 2)))
    assert J.shape == (4, 5, 1, 2)
    np.testing.assert_array_equal(J[..., 0, :], np.broadcast_to([1.0, 2.0], (4, 5, 2)))


@pytest.mark.parametrize(
    ("kwargs", "field", "text"),
    [
        ({"variables": ["x1", "x1"], "task": ["x1"]}, "variables", "distinct"),
        ({"variables": ["x1", "sin"], "task": ["x1"]}, "variables.1", "reserved"),
        ({"variables": ["x1", "_x"], "task": ["x1"]}, "variables.1", "starting with a letter"),
        ({"variables": ["x1", "for"], "task": ["x1"]}, "variables.1", "reserved"),
        ({"variables": ["x1", "x2"], "task": ["x1", "x2"]}, "task", "r < p"),
        ({"variables": ["x1", "x2"], "task": "x1"}, "task", "non-empty list"),
        ({"variables": ["x1", "x2"], "task": ["x1 + y"]}, "task.0", "unknown name 'y'"),
        (
            {"variables": ["x1", "x2"], "task": ["x1", "x2"][:1], "parameters": {"l": "1"}},
            "parameters.l",
            "must be a number",
        ),
        (
            {"variables": ["x1", "x2"], "task": ["x1"], "parameters": {"x1": 1.0}},
            "parameters.x1",
            "also a variable",
        ),
        ({"variables": "x1 x2", "task": ["x1"]}, "variables", "list of names"),
    ],
)
def test_bad_formula_robots_name_the_field(kwargs, field, text):
    with pytest.raises(InvalidInputError) as err:
        FormulaKinematics(**kwargs)
    assert err.value.field == field
    assert text in str(err.value)


@pytest.fixture(scope="module")
def formula_m2():
    return FormulaKinematics(**M2, parameters={"l": 1.0})


def test_manipulator2_as_formula_solves_as_the_builtin(formula_m2):
    for inverse in (Pseudoinverse, lambda k: ExtendedInverse(k, PaperCubic())):
        ours = solve(inverse(formula_m2), X0, [1.3, 1.7])
        theirs = solve(inverse(Manipulator2()), X0, [1.3, 1.7])
        assert ours.success and theirs.success
        np.testing.assert_allclose(ours.x, theirs.x, atol=1e-9, rtol=0)


def test_manipulator2_as_formula_gives_table1_legs_and_e2_of_the_builtin(formula_m2):
    """3 cycles of Table 1's path with both inverses, and the E2 synthesis (h comes out as -h:
    the formula robot's kernel has the cofactor orientation, the opposite of the paper's)."""
    builtin = default_manipulator2_synthesis()
    ours = synthesize_e2(formula_m2, MANIPULATOR2_REGION, degree=16)
    assert ours.e2 == pytest.approx(builtin.e2, abs=1e-9)
    x = RNG.uniform(-1, 3, (50, 3))
    np.testing.assert_allclose(
        ours.augmenting_map.value(x), -builtin.augmenting_map.value(x), atol=1e-9
    )
    pairs = [
        (Pseudoinverse(formula_m2), Pseudoinverse(Manipulator2())),
        (
            ExtendedInverse(formula_m2, ours.augmenting_map),
            ExtendedInverse(Manipulator2(), builtin.augmenting_map),
        ),
    ]
    for a, b in pairs:
        ra, rb = (repeatability(inv, X0, PATH, cycles=3) for inv in (a, b))
        assert ra.success and rb.success
        np.testing.assert_allclose(ra.legs, rb.legs, atol=1e-9, rtol=0)


def test_characteristics_synthesis_runs_on_a_formula_robot(formula_m2):
    """Section 4's map by characteristics needs second derivatives: the formula robot has them
    (symbolic), so Manipulator 2 written as a formula gets a characteristics map; its exact
    gradient matches finite differences and its extended inverse is repeatable."""
    h = CharacteristicsMap(formula_m2, reference=[0.0, 0.0, 0.0], fixed_index=2)
    x = X0 + RNG.uniform(-0.2, 0.2, (5, 3))
    np.testing.assert_allclose(h.gradient(x), central_difference(h.value, x, 1e-5), atol=1e-8)
    rep = repeatability(ExtendedInverse(formula_m2, h), X0, PATH, cycles=2)
    assert rep.success and np.max(rep.drift) < 1e-9


def _nested_exponentials(depth: int) -> str:
    """exp(x1/exp(x2/exp(x3/...))): a short formula whose derivatives grow with ``depth``."""
    inner = "x3"
    for i in range(depth, 0, -1):
        inner = f"exp(x{i % 3 + 1}/{inner})"
    return inner


def test_exploding_derivatives_are_refused_naming_the_formula(monkeypatch):
    """Nested exponentials: the derivatives are refused once they outgrow the bound, naming the
    task component (not built for minutes: 30 s of sympy for depth 25 without the bounds);
    deeper nesting is refused by the parser."""
    with pytest.raises(FormulaError, match=r"task\.1: the formula's second derivatives") as info:
        robot = FormulaKinematics(["x1", "x2", "x3"], ["x1 + x2", _nested_exponentials(8)])
        robot.hessian(np.zeros((1, 3)))
    assert info.value.field == "task.1"
    with pytest.raises(FormulaError, match=r"task\.0: functions nested too deeply") as info:
        FormulaKinematics(["x1", "x2", "x3"], [_nested_exponentials(38)])
    assert info.value.position == 56  # (the ninth exp)
    monkeypatch.setattr(formula_kinematics, "MAX_DERIVATIVE_NODES", 5)
    with pytest.raises(FormulaError, match="h: the formula's first derivatives"):
        FormulaMap("x1 * sin(x2) * exp(x3)", ["x1", "x2", "x3"])


def test_ordinary_formulas_keep_their_derivatives_within_the_bound():
    """An 8-link chain written as a formula builds its Jacobian and Hessian."""
    names = [f"x{i}" for i in range(1, 9)]
    xs = [
        " + ".join(f"cos({'+'.join(names[: i + 1])})" for i in range(8)),
        " + ".join(f"sin({'+'.join(names[: i + 1])})" for i in range(8)),
    ]
    robot = FormulaKinematics([*names, "y"], xs)
    assert robot.hessian(np.zeros((2, 9))).shape == (2, 2, 9, 9)
