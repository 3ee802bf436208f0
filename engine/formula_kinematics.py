"""Robots and augmenting maps given by formulas: k and h parsed by :mod:`jik.engine.formula`.

The Jacobian, the second derivatives (which the characteristics of section 4 need) and the
gradient of h come from sympy's ``diff`` of the parsed expressions and are evaluated batched by
numpy functions that sympy's ``lambdify`` generates from them (expressions built by the parser,
never text). Derivatives are bounded in size (:func:`derivatives`): a formula whose derivatives
grow much larger than itself (nested exponentials, ``exp(x1/exp(x2/exp(...)))``) is refused while
they are taken, naming its field, before sympy spends seconds or minutes simplifying and
compiling them.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from fractions import Fraction

import numpy as np
import sympy as sp

from .augmentations import AugmentingMap
from .exceptions import FormulaError, InvalidInputError
from .formula import MAX_NAMES, check_name, parse_formula
from .kinematics import Kinematics
from .validation import MAX_JOINTS, FloatArray, json_number

#: Largest average size (tree nodes) of a formula's first or second derivatives, per entry. The
#: derivative of an ordinary formula is about as large as the formula (a 16-link chain's
#: entries: about 200 nodes); of nested exponentials it grows with the nesting depth, and its
#: second derivatives with its square, as does the time sympy takes to build them.
MAX_DERIVATIVE_NODES = 1000


def _nodes(e: sp.Basic) -> int:
    return sum(1 for _ in sp.preorder_traversal(e))


def derivatives(
    exprs: Sequence[sp.Expr], symbols: Sequence[sp.Symbol], fields: Sequence[str], order: int = 1
) -> list[sp.Expr]:
    """d expr / d symbol (``order`` 1: (len(exprs), p) entries, row-major) or d^2 expr / d s_a
    d s_b (``order`` 2: (len(exprs), p, p)), within :data:`MAX_DERIVATIVE_NODES` per entry on
    average over each expression's entries.

    Raises
    ------
    FormulaError
        Naming ``fields[i]`` of the expression whose derivatives exceed the bound, as soon as
        they do (the entries after it are not computed).
    """
    out: list[sp.Expr] = []
    n = len(symbols) ** order
    for e, field in zip(exprs, fields, strict=True):
        used = 0
        firsts = [sp.diff(e, a) for a in symbols] if order == 2 else [e]
        for d in firsts:
            for a in symbols:
                entry = sp.diff(d, a)
                used += _nodes(entry)
                if used > MAX_DERIVATIVE_NODES * n:
                    which = "first" if order == 1 else "second"
                    raise FormulaError(
                        f"{field}: the formula's {which} derivatives are too large to build "
                        f"(more than {MAX_DERIVATIVE_NODES} terms per entry on average); nest "
                        "fewer functions",
                        field,
                        0,
                    )
                out.append(entry)
    return out


def _names(variables, parameters, what: str) -> tuple[list[str], dict[str, float]]:
    if isinstance(variables, str) or not isinstance(variables, Sequence):
        raise InvalidInputError(f"variables must be a list of names for {what}", "variables")
    if not 1 <= len(variables) <= MAX_JOINTS:
        raise InvalidInputError(
            f"variables: give 1 to {MAX_JOINTS} names, got {len(variables)}", "variables"
        )
    names = [check_name(v, f"variables.{i}") for i, v in enumerate(variables)]
    if len(set(names)) != len(names):
        raise InvalidInputError(f"variables must be distinct, got {names}", "variables")
    parameters = {} if parameters is None else parameters
    if not isinstance(parameters, Mapping) or len(parameters) > MAX_NAMES:
        raise InvalidInputError(
            f"parameters must be a mapping of at most {MAX_NAMES} names to numbers", "parameters"
        )
    values: dict[str, float] = {}
    for k, v in parameters.items():
        check_name(k, f"parameters.{k}")
        if k in names:
            raise InvalidInputError(f"parameter {k!r} is also a variable", f"parameters.{k}")
        values[k] = json_number(v, f"parameters.{k}")
    return names, values


def _scope(names: Sequence[str], values: Mapping[str, float]):
    """Variables as real symbols, parameters as exact rationals of their float values."""
    symbols = [sp.Symbol(n, real=True) for n in names]
    scope: dict[str, sp.Expr] = dict(zip(names, symbols, strict=True))
    for k, v in values.items():
        scope[k] = sp.Rational(*Fraction(v).as_integer_ratio())
    return symbols, scope


class _Batched:
    """Sympy expressions as one numpy function of x (..., p) -> (..., *shape), vectorized."""

    def __init__(self, exprs: Sequence[sp.Expr], symbols: Sequence[sp.Symbol], shape) -> None:
        self.shape = tuple(shape)
        self.size = len(exprs)
        # abs'' and sign' are DiracDelta: the derivative almost everywhere is 0 there.
        exprs = [e.replace(sp.DiracDelta, lambda *a: sp.Integer(0)) for e in exprs]
        self._exprs, self._symbols = list(exprs), list(symbols)
        self._f = sp.lambdify(self._symbols, self._exprs, modules="numpy", dummify=True, cse=True)

    def __getstate__(self) -> dict:
        """Pickled as its expressions (the generated function has no importable name): a
        process that receives it (an atlas's chunk in a worker) generates the function again."""
        return {"exprs": self._exprs, "symbols": self._symbols, "shape": self.shape}

    def __setstate__(self, state: dict) -> None:
        self.__init__(state["exprs"], state["symbols"], state["shape"])  # type: ignore[misc]

    def __call__(self, x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=float)
        with np.errstate(all="ignore"):
            values = self._f(*np.moveaxis(x, -1, 0))
        out = np.empty((*x.shape[:-1], self.size))
        for k, v in enumerate(values):  # entries, not configurations: constants broadcast
            out[..., k] = v
        return out.reshape((*x.shape[:-1], *self.shape))


class FormulaKinematics(Kinematics):
    """k: R^p -> R^r given by formulas in the variables and named parameters, eq. (4).

    Parameters
    ----------
    variables : sequence of str, length p
        Names of the joint variables, in order.
    task : sequence of str, length r < p
        The task components as formulas (grammar: :mod:`jik.engine.formula`).
    parameters : mapping str -> float, optional
        Named constants the formulas may use.

    Notes
    -----
    J = dk/dx and the second derivatives (:meth:`hessian`, which the characteristics of
    section 4 need) by sympy differentiation; all three are evaluated batched through numpy.
    The kernel K keeps the cofactor vector's orientation (``kernel_orientation = 1``); for
    Manipulator 2 written as a formula this is -K of the built-in class, so an E2-synthesized
    map comes out as -h (same E2, same extended inverse).
    """

    name = "formula"

    def __init__(
        self,
        variables: Sequence[str],
        task: Sequence[str],
        parameters: Mapping[str, float] | None = None,
    ) -> None:
        names, values = _names(variables, parameters, "a formula robot")
        if isinstance(task, str) or not isinstance(task, Sequence) or not task:
            raise InvalidInputError("task must be a non-empty list of formulas", "task")
        if len(task) >= len(names):
            raise InvalidInputError(
                f"task has {len(task)} components for {len(names)} variables: a redundant robot "
                "needs fewer task components than variables (r < p)",
                "task",
            )
        self.symbols, scope = _scope(names, values)
        self.expressions = [parse_formula(t, scope, f"task.{i}") for i, t in enumerate(task)]
        self.texts = list(task)
        self.values = values
        self.variable_names = tuple(names)
        self.p, self.r = len(names), len(task)
        self._forward = _Batched(self.expressions, self.symbols, (self.r,))
        self._fields = [f"task.{i}" for i in range(self.r)]
        self._first = derivatives(self.expressions, self.symbols, self._fields)

    @property
    def parameters(self) -> dict[str, object]:
        return dict(self.values)

    def _described(self) -> dict[str, object]:
        return {"variables": self.variable_names, "task": tuple(self.texts), **self.values}

    @functools.cached_property
    def symbolic_jacobian(self) -> sp.Matrix:
        """dk/dx as a sympy matrix (r, p)."""
        return sp.Matrix(self.r, self.p, self._first)

    @functools.cached_property
    def _jacobian(self) -> _Batched:
        return _Batched(list(self.symbolic_jacobian), self.symbols, (self.r, self.p))

    @functools.cached_property
    def _hessian(self) -> _Batched:
        exprs = derivatives(self.expressions, self.symbols, self._fields, order=2)
        return _Batched(exprs, self.symbols, (self.r, self.p, self.p))

    def forward(self, x: FloatArray) -> FloatArray:
        """k(x): (..., p) -> (..., r)."""
        return self._forward(x)

    def jacobian(self, x: FloatArray) -> FloatArray:
        """J(x): (..., p) -> (..., r, p), from the symbolic derivative."""
        return self._jacobian(x)

    def hessian(self, x: FloatArray) -> FloatArray:
        """d^2 k_i / dx_j dx_k: (..., p) -> (..., r, p, p)."""
        return self._hessian(x)


class FormulaMap(AugmentingMap):
    """An augmenting map h: R^p -> R given by a formula, eq. (9), with its symbolic gradient.

    Parameters
    ----------
    h : str
        The formula (grammar: :mod:`jik.engine.formula`).
    variables : sequence of str
        The robot's joint variable names, in order (p of them).
    parameters : mapping str -> float, optional
        Named constants the formula may use.
    field : str
        Where ``h`` comes from, for messages.
    """

    name = "formula"

    def __init__(
        self,
        h: str,
        variables: Sequence[str],
        parameters: Mapping[str, float] | None = None,
        field: str = "h",
    ) -> None:
        names, values = _names(variables, parameters, "a formula map")
        symbols, scope = _scope(names, values)
        self.text = h
        self.expression = parse_formula(h, scope, field)
        self.p = len(names)
        self.values = values
        self._value = _Batched([self.expression], symbols, ())
        gradient = derivatives([self.expression], symbols, [field])
        self._gradient = _Batched(gradient, symbols, (self.p,))

    @property
    def parameters(self) -> dict[str, float]:
        return dict(self.values)

    def __repr__(self) -> str:
        return f"FormulaMap({self.text!r})"

    def value(self, x: FloatArray) -> FloatArray:
        return self._value(x)

    def gradient(self, x: FloatArray) -> FloatArray:
        return self._gradient(x)
