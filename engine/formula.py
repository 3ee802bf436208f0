"""A whitelist grammar for formulas (task components, augmenting maps), parsed into sympy.

A user's text is never handed to eval, exec, sympify or parse_expr: a tokenizer and a
recursive-descent parser accept exactly

    expression := term (("+" | "-") term)*
    term       := unary (("*" | "/") unary)*
    unary      := ("-" | "+") unary | power
    power      := atom ("**" unary)?               (right-associative: 2**3**2 = 2**9)
    atom       := number | name | function "(" expression ("," expression)* ")"
                  | "(" expression ")"

with numbers such as ``2``, ``0.5``, ``1e-3``, the constant ``pi``, the declared variables and
parameters, and the functions sin cos tan exp log sqrt atan2 abs; each node becomes a sympy
object built directly. Bounds keep the work small whatever the text: its length, the number of
nodes, the nesting depth (of parentheses and signs, and of function calls, whose derivatives
grow with each), the size of exact constants, and constant exponents with
|value| <= ``MAX_EXPONENT`` (also after sympy combines powers, as (x**8)**4 = x**32). Numbers and
parameter values are exact rationals, so sympy never evaluates a function of a float while the
expression is built.

:mod:`jik.engine.formula_kinematics` builds robots and augmenting maps from such formulas.
"""

from __future__ import annotations

import keyword
import re
from collections.abc import Mapping
from dataclasses import dataclass
from fractions import Fraction

import sympy as sp

from .exceptions import FormulaError, InvalidInputError

#: Longest formula text accepted [characters].
MAX_LENGTH = 2000
#: Most nodes (numbers, names, operators, calls) in one formula.
MAX_NODES = 500
#: Deepest nesting of parentheses, calls and unary signs.
MAX_DEPTH = 40
#: Deepest nesting of function calls (``exp(x/exp(x/...))``): each level multiplies the size of
#: the derivatives by the chain rule.
MAX_CALLS_NESTED = 8
#: Largest |exponent| of a power with a constant exponent.
MAX_EXPONENT = 16
#: Largest size of an exact constant's numerator or denominator [bits].
MAX_CONSTANT_BITS = 1024
#: Largest |decimal exponent| of a number literal, as in 1e300.
MAX_DECIMAL_EXPONENT = 300
#: Most variables, task components or parameters.
MAX_NAMES = 32

FUNCTIONS = {
    "sin": (sp.sin, 1),
    "cos": (sp.cos, 1),
    "tan": (sp.tan, 1),
    "exp": (sp.exp, 1),
    "log": (sp.log, 1),
    "sqrt": (sp.sqrt, 1),
    "atan2": (sp.atan2, 2),
    "abs": (sp.Abs, 1),
}
CONSTANTS = {"pi": sp.pi}

_TOKEN = re.compile(
    r"(?P<space>[ \t\r\n]+)"
    r"|(?P<number>(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)"
    r"|(?P<name>[A-Za-z][A-Za-z0-9_]*)"
    r"|(?P<op>\*\*|[-+*/(),])"
)
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,31}")


@dataclass(frozen=True)
class _Token:
    kind: str  # "number", "name", "op" or "end"
    text: str
    position: int


#: Values a formula must not hold, in the user's words (SymPy's zoo is 1/0).
REFUSED_VALUES = (
    (sp.zoo, "an undefined constant: a division by zero"),
    (sp.nan, "an undefined constant such as 0/0"),
    (sp.oo, "an infinite constant"),
    (-sp.oo, "an infinite constant"),
    (sp.I, "a complex constant such as sqrt(-1)"),
)


def _tokens(text: str, field: str) -> list[_Token]:
    out, i = [], 0
    while i < len(text):
        m = _TOKEN.match(text, i)
        if m is None:
            c = text[i]
            hint = "; write powers as **" if c == "^" else ""
            raise FormulaError(
                f"{field}: unexpected character {c!r} at position {i}{hint}", field, i
            )
        if m.lastgroup != "space":
            out.append(_Token(str(m.lastgroup), m.group(), i))
        i = m.end()
    out.append(_Token("end", "", len(text)))
    return out


class _Parser:
    """Recursive descent over the tokens of one formula (grammar in the module docstring)."""

    def __init__(self, text: str, names: Mapping[str, sp.Expr], field: str) -> None:
        self.field = field
        self.names = names
        self.tokens = _tokens(text, field)
        self.i = 0
        self.depth = 0
        self.nodes = 0
        self.calls = 0

    def error(self, what: str, token: _Token | None = None) -> FormulaError:
        t = token or self.tokens[self.i]
        where = "at the end" if t.kind == "end" else f"at position {t.position}"
        return FormulaError(f"{self.field}: {what} {where}", self.field, t.position)

    def peek(self) -> _Token:
        return self.tokens[self.i]

    def take(self) -> _Token:
        t = self.tokens[self.i]
        self.i += 1
        return t

    def node(self, token: _Token) -> None:
        self.nodes += 1
        if self.nodes > MAX_NODES:
            raise self.error(f"formula too large (more than {MAX_NODES} nodes)", token)

    def enter(self, token: _Token) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.error(f"formula nested too deeply (more than {MAX_DEPTH} levels)", token)

    def parse(self) -> sp.Expr:
        if self.peek().kind == "end":
            raise self.error("empty formula")
        e = self.expression()
        if self.peek().kind != "end":
            raise self.error(f"unexpected {self.peek().text!r}")
        return e

    def expression(self) -> sp.Expr:
        self.enter(self.peek())
        e = self.term()
        while self.peek().text in ("+", "-"):
            op = self.take()
            self.node(op)
            rhs = self.term()
            e = self.constant(e + rhs if op.text == "+" else e - rhs, op)
        self.depth -= 1
        return e

    def term(self) -> sp.Expr:
        e = self.unary()
        while self.peek().text in ("*", "/"):
            op = self.take()
            self.node(op)
            rhs = self.unary()
            e = self.constant(e * rhs if op.text == "*" else e / rhs, op)
        return e

    def unary(self) -> sp.Expr:
        t = self.peek()
        if t.text in ("-", "+"):
            self.take()
            self.node(t)
            self.enter(t)
            e = self.unary()
            self.depth -= 1
            return -e if t.text == "-" else e
        return self.power()

    def power(self) -> sp.Expr:
        base = self.atom()
        if self.peek().text != "**":
            return base
        op = self.take()
        self.node(op)
        self.enter(op)
        exponent = self.unary()
        self.depth -= 1
        _check_exponent(exponent, lambda what: self.error(what, op))
        return self.constant(base**exponent, op)

    def atom(self) -> sp.Expr:
        t = self.take()
        self.node(t)
        if t.kind == "number":
            exponent = re.search(r"[eE]([+-]?[0-9]+)$", t.text)
            if exponent and abs(int(exponent[1])) > MAX_DECIMAL_EXPONENT:
                raise self.error(
                    f"number out of range (|decimal exponent| <= {MAX_DECIMAL_EXPONENT})", t
                )
            return self.constant(_number(t.text), t)
        if t.kind == "name":
            if t.text in FUNCTIONS:
                return self.call(t)
            if t.text in self.names:
                return self.names[t.text]
            if t.text in CONSTANTS:
                return CONSTANTS[t.text]
            known = ", ".join(sorted(self.names)) or "none"
            raise self.error(f"unknown name {t.text!r} (declared: {known}; and pi)", t)
        if t.text == "(":
            e = self.expression()
            if self.take().text != ")":
                raise self.error("missing ')'", self.tokens[self.i - 1])
            return e
        raise self.error(
            "expected a number, a name or '('" if t.kind != "end" else "formula ends too early", t
        )

    def call(self, name: _Token) -> sp.Expr:
        function, arity = FUNCTIONS[name.text]
        if self.take().text != "(":
            raise self.error(f"{name.text} must be called, as {name.text}(...)", name)
        self.calls += 1
        if self.calls > MAX_CALLS_NESTED:
            raise self.error(
                f"functions nested too deeply (more than {MAX_CALLS_NESTED} calls "
                "inside each other)",
                name,
            )
        args = [self.expression()]
        while self.peek().text == ",":
            self.take()
            args.append(self.expression())
        self.calls -= 1
        if self.take().text != ")":
            raise self.error("missing ')'", self.tokens[self.i - 1])
        if len(args) != arity:
            raise self.error(f"{name.text} takes {arity} argument(s), got {len(args)}", name)
        return self.constant(function(*args), name)

    def constant(self, e: sp.Expr, token: _Token) -> sp.Expr:
        """``e``, refused when it is an exact constant too large to keep exact."""
        if isinstance(e, sp.Rational) and (
            abs(int(e.p)).bit_length() > MAX_CONSTANT_BITS
            or int(e.q).bit_length() > MAX_CONSTANT_BITS
        ):
            raise self.error(f"constant too large (over {MAX_CONSTANT_BITS} bits)", token)
        return e


def _number(text: str) -> sp.Rational:
    """A literal as an exact rational (``fractions.Fraction`` reads the decimal text)."""
    f = Fraction(text)
    return sp.Rational(f.numerator, f.denominator)


def _check_exponent(exponent: sp.Expr, error) -> None:
    if exponent.free_symbols:
        raise error(f"exponents must be constants with |value| <= {MAX_EXPONENT}")
    if isinstance(exponent, sp.Rational):
        value = float(exponent) if abs(exponent) <= MAX_EXPONENT else float("inf")
    else:
        value = complex(exponent.evalf(15)).real if exponent.is_real else float("nan")
    if not abs(value) <= MAX_EXPONENT:
        shown = str(exponent) if len(str(exponent)) <= 20 else str(sp.N(exponent, 6))
        raise error(f"exponent out of range (|exponent| <= {MAX_EXPONENT}, got {shown})")


def parse_formula(text, names: Mapping[str, sp.Expr], field: str = "formula") -> sp.Expr:
    """Parse one formula by the whitelist grammar of this module into a sympy expression.

    Parameters
    ----------
    text : str
        The formula, at most ``MAX_LENGTH`` characters.
    names : mapping name -> sympy expression
        The declared names (variables as symbols, parameters as numbers); any other name fails.
    field : str
        The input it comes from, for messages and ``FormulaError.field`` (``"task.0"``).

    Returns
    -------
    sympy.Expr
        Real-valued and finite as a sympy expression: a constant that is undefined (1/0,
        log(0)) or complex (sqrt(-1)) fails here; a formula undefined at some x gives NaN there.

    Raises
    ------
    FormulaError
        (an InvalidInputError) naming ``field`` and the position of the offending character.
    """
    if not isinstance(text, str):
        raise FormulaError(
            f"{field} must be a formula (a string), got {type(text).__name__}", field
        )
    if len(text) > MAX_LENGTH:
        raise FormulaError(
            f"{field}: formula too long ({len(text)} characters; at most {MAX_LENGTH})", field, 0
        )
    parser = _Parser(text, names, field)
    try:
        e = parser.parse()
    except (ArithmeticError, ValueError, TypeError, RecursionError) as exc:
        if isinstance(exc, FormulaError):
            raise
        raise FormulaError(
            f"{field}: cannot build the formula ({type(exc).__name__})", field, 0
        ) from None
    for constant, words in REFUSED_VALUES:
        if e.has(constant):
            raise FormulaError(f"{field}: the formula has {words}", field, 0)
    for pw in e.atoms(sp.Pow):
        if pw.exp.is_number and not abs(float(sp.re(pw.exp))) <= MAX_EXPONENT:
            raise FormulaError(
                f"{field}: exponent {pw.exp} of {pw} exceeds {MAX_EXPONENT} once "
                "powers are combined",
                field,
                0,
            )
    return e


def check_name(name, field: str) -> str:
    """A declared name: a letter, then letters, digits, _; not a function, pi or a keyword."""
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise InvalidInputError(
            f"{field} must be a name of at most 32 letters, digits and _ starting with a "
            f"letter, got {name!r}",
            field,
        )
    if name in FUNCTIONS or name in CONSTANTS or keyword.iskeyword(name):
        raise InvalidInputError(
            f"{field}: {name!r} is reserved (a function, pi or a keyword)", field
        )
    return name
