"""Symbolic derivations (sympy): J, K, m, P of a kinematics, the Euler equations (15) and (20).

For a kinematics given by sympy expressions, :func:`kinematics_quantities` derives the Jacobian,
the manipulability matrix M = J J^T, m = sqrt(det M), the unit kernel K (cofactor vector, with the
paper's orientation: last component positive) and P = J^P# J^P#^T + K K^T = (J^T J + K K^T)^(-1).
:func:`euler_equation_e2` is (20), :func:`euler_lagrange_e1` is (15) for the Lagrangian of (14).
:func:`manipulator1_findings` and :func:`manipulator2_findings` check the paper's printed formulas
against these derivations; every finding says what was checked and whether it holds.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import sympy as sp
from sympy.core.function import AppliedUndef

x1, x2, x3 = sp.symbols("x1 x2 x3", real=True)
X = (x1, x2, x3)


def kinematics_quantities(k: Sequence[sp.Expr], xs: Sequence[sp.Symbol]) -> dict[str, sp.Basic]:
    """J, M, m, K, P and R = m P of k: R^p -> R^(p-1), eqs. (8), (17)-(19).

    Parameters
    ----------
    k : sequence of r sympy expressions
    xs : sequence of p = r + 1 symbols

    Returns
    -------
    dict
        ``J`` (r, p), ``M`` = J J^T (r, r), ``m`` = sqrt(det M), ``K`` (p, 1) the unit kernel
        c / |c| from the cofactor vector c (J c = 0, |c| = m by Cauchy-Binet), its sign chosen so
        that the last component is positive when that component is a constant or sympy can tell
        its sign (the paper's orientation), ``P`` = J^P# J^P#^T + K K^T (p, p) and ``R`` = m P.
    """
    return dict(_quantities(tuple(k), tuple(xs)))


def _simp(e: sp.Expr) -> sp.Expr:
    return sp.trigsimp(sp.cancel(e)) if e.has(sp.sin, sp.cos) else sp.simplify(e)


@functools.lru_cache(maxsize=16)
def _quantities(k: tuple, xs: tuple) -> tuple:
    J = sp.Matrix(k).jacobian(list(xs))
    r, p = J.shape
    if p != r + 1:
        raise ValueError(f"one degree of redundancy needed, got r = {r}, p = {p}")
    # Cofactor vector (as engine.kinematics.kernel_cofactors): J c = 0 and |c| = m.
    minors = [J[:, [j for j in range(p) if j != i]].det() for i in range(p)]
    c = sp.Matrix([(-1) ** (r + i) * mi for i, mi in enumerate(minors)]).applyfunc(_simp)
    if c[-1].could_extract_minus_sign():
        c = -c
    m2 = _simp(sum(ci**2 for ci in c))  # det J J^T
    M = (J * J.T).applyfunc(_simp)
    A = M.adjugate()  # M^(-1) = A / m2, so J^P# = J^T A / m2
    P = (J.T * A * A.T * J / m2**2 + c * c.T / m2).applyfunc(_simp)
    m = sp.sqrt(m2)
    K = c / m
    return (("J", J), ("M", M), ("m", m), ("K", K), ("P", P), ("R", m * P))


def euler_equation_e2(q: dict, h: sp.Expr, xs: Sequence[sp.Symbol]) -> sp.Expr:
    """Left side of (20): sum_r d/dx_r (m P grad h - m K)_r for one degree of redundancy."""
    grad = sp.Matrix([sp.diff(h, v) for v in xs])
    flux = q["R"] * grad - q["m"] * q["K"]
    return sum(sp.diff(flux[i], v) for i, v in enumerate(xs))


def e1_lagrangian(q: dict, dh: sp.Matrix) -> sp.Expr:
    """Integrand of (14): dh P dh^T / (dh K)^2 - 1 (= ||J^P# - J^E#||_F^2)."""
    return (dh * q["P"] * dh.T)[0] / (dh * q["K"])[0] ** 2 - 1


def euler_lagrange_e1(q: dict, h: sp.Expr, xs: Sequence[sp.Symbol]) -> sp.Expr:
    """Left side of (15) for E1, eq. (14): sum_r d/dx_r (dL / d(dh/dx_r)) evaluated at h."""
    ps = sp.symbols(f"p1:{len(xs) + 1}", real=True)
    L = e1_lagrangian(q, sp.Matrix([ps]))
    sub = {p: sp.diff(h, v) for p, v in zip(ps, xs, strict=True)}
    return sum(sp.diff(sp.diff(L, p).subs(sub), v) for p, v in zip(ps, xs, strict=True))


def _finding(claim: str, holds: bool, detail: str = "") -> dict:
    return {"claim": claim, "holds": bool(holds), "detail": detail}


def _zero(expr) -> bool:
    """True when sympy simplifies ``expr`` (an expression or a matrix) to zero.

    A numeric evaluation at a few points rejects nonzero expressions before simplifying.
    """
    if isinstance(expr, sp.MatrixBase):
        return all(_zero(e) for e in expr)
    free = sorted(expr.free_symbols, key=str)
    if not expr.atoms(AppliedUndef) and len(free) <= 6:
        for point in ((0.31, 0.57, 0.83, 1.1, 0.7, 0.4), (0.9, -0.35, 1.7, 0.2, 1.3, 2.1)):
            v = complex(expr.subs(dict(zip(free, point, strict=False))).evalf())
            if abs(v) > 1e-9:
                return False
    return _simp(expr) == 0 or sp.simplify(expr) == 0


#: Manipulator 1 as printed in sec. 5.1 (for comparison with the derivations).
S1 = sp.sqrt(1 + x1**2)
PRINTED_P1 = sp.Matrix(
    [
        [1, -x3 / (1 + x1**2), -x1 * x3 / (1 + x1**2)],
        [
            -x3 / (1 + x1**2),
            (1 + x1**2 + x3**2 + x1**4) / (1 + x1**2) ** 2,
            (x1 * x3 - x1**3) / (1 + x1**2) ** 2,
        ],
        [
            -x1 * x3 / (1 + x1**2),
            (x1 * x3 - x1**3) / (1 + x1**2) ** 2,
            (1 + 2 * x1**2 + x1**2 * x3**2) / (1 + x1**2) ** 2,
        ],
    ]
)


def printed_34(h: sp.Expr) -> sp.Expr:
    """The left side of (34) as printed, for h(x1, x2, x3)."""
    d = functools.partial(sp.diff, h)
    s = S1
    return (
        s * d(x1, 2)
        + (1 + x1**2 + x3**2 + x1**4) / s**3 * d(x2, 2)
        + (1 + 2 * x1**2 + x1**2 * x3**2) / s**3 * d(x3, 2)
        - 2 * x3 / s * d(x1, x2)
        - 2 * x1 * x3 / s * d(x1, x3)
        + 2 * x1 * (x3**2 - x1**2) / s**3 * d(x2, x3)
        + 3 * x1 * x3 / s**3 * d(x2)
        + (2 * x1**2 * x3 - x3) / s**3 * d(x3)
    )


def printed_e1_ode(f: sp.Expr) -> sp.Expr:
    """The paper's ODE for h = x3 f(x1) before (31), as printed."""
    fp, fpp = sp.diff(f, x1), sp.diff(f, x1, 2)
    return 2 * x3 * (f**2 + 4 * (1 + x1**2) * fp**2 - f * (5 * x1 * fp + (1 + x1**2) * fpp))


@functools.lru_cache(maxsize=1)
def manipulator1_findings() -> list[dict]:
    """Check sec. 5.1 of the paper against derivations from k(x) = (x1, x2 + x1 x3), eq. (30)."""
    q = kinematics_quantities([x1, x2 + x1 * x3], X)
    a, b, C1, C2, k = sp.symbols("a b C1 C2 k", real=True)
    f = sp.Function("f")(x1)
    out = []
    M_printed = sp.diag(1, x3, 1 + x1**2 + x3**2)
    out.append(
        _finding(
            "printed M(x) of Manipulator 1 equals J J^T",
            M_printed.shape == q["M"].shape and _zero(M_printed - q["M"]),
            f"J J^T = {q['M'].tolist()} (2 x 2); the printed 3 x 3 "
            f"diag{M_printed.diagonal().tolist()} is garbled; det J J^T = 1 + x1^2 so "
            "m = sqrt(1 + x1^2) as printed",
        )
    )
    out.append(
        _finding(
            "K = (0, -x1, 1)/sqrt(1 + x1^2) and m = sqrt(1 + x1^2)",
            _zero(q["K"] - sp.Matrix([0, -x1, 1]) / S1) and _zero(q["m"] - S1),
            "orientation: last component of K positive",
        )
    )
    dP = sp.simplify(q["P"] - PRINTED_P1)
    out.append(
        _finding(
            "printed P(x) of sec. 5.1.2 equals (J^T J + K K^T)^(-1)",
            _zero(dP),
            f"P23 = P32 = {sp.factor(q['P'][1, 2])}; printed (x1 x3 - x1^3)/(1 + x1^2)^2 "
            f"(difference {sp.factor(dP[1, 2])}: x3 should be x3^2)",
        )
    )
    h = sp.Function("h")(*X)
    div_mK = sp.simplify(sum(sp.diff(q["m"] * q["K"][i], v) for i, v in enumerate(X)))
    eq20 = euler_equation_e2(q, h, X)
    out.append(
        _finding(
            "(20) for Manipulator 1 is (34) (div(m K) = 0)",
            _zero(sp.expand(eq20 - printed_34(h))) and div_mK == 0,
            f"div(m K) = {div_mK}; (34) uses the correct P23 although the printed P has a typo",
        )
    )
    h36 = x3 * (a * x1 + b) * S1
    out.append(_finding("(36) solves (20) for all a, b", _zero(euler_equation_e2(q, h36, X))))
    ode = sp.simplify(euler_equation_e2(q, x3 * f, X) / x3 * S1**3)
    correct35 = (
        sp.diff(f, x1, 2)
        - 2 * x1 / (1 + x1**2) * sp.diff(f, x1)
        + (2 * x1**2 - 1) / (1 + x1**2) ** 2 * f
    )
    printed35 = (
        sp.diff(x3 * f, x1, 2)
        - 2 * x3 / (1 + x1**2) * sp.diff(x3 * f, x1)
        + (2 * x1**2 - 1) / (1 + x1**2) ** 2 * f
    )
    f36 = (a * x1 + b) * S1
    out.append(
        _finding(
            "(35) as printed is the reduction of (34) for h = x3 f(x1)",
            _zero(printed35.subs(f, f36).doit()),
            "the reduction is (1 + x1^2)^2 times "
            f"[{sp.simplify(ode / (1 + x1**2) ** 2)}] = 0, i.e. "
            "f'' - 2 x1/(1 + x1^2) f' + (2 x1^2 - 1)/(1 + x1^2)^2 f = 0: the printed (35) has x3 "
            "for x1 in the f' coefficient and h for f; (36) does not solve (35) as printed",
        )
    )
    out.append(
        _finding(
            "f = (a x1 + b) sqrt(1 + x1^2) solves the corrected (35) for all a, b",
            _zero(correct35.subs(f, f36).doit())
            and _zero(sp.simplify(ode - (1 + x1**2) ** 2 * correct35)),
        )
    )
    el = euler_lagrange_e1(q, x3 * f, X)
    ratio = sp.simplify(el / printed_e1_ode(f))
    out.append(
        _finding(
            "the paper's E1 ODE (before (31)) is the Euler equation (15) of (14) for h = x3 f(x1)",
            _zero(ratio + 1 / f**3),
            f"(15) at h = x3 f equals {ratio} times the printed ODE",
        )
    )
    f31 = C1 * S1 * (x1 * S1 + sp.asinh(x1) + C2) ** sp.Rational(-1, 3)
    out.append(
        _finding(
            "(31) solves the paper's E1 ODE for all C1, C2",
            _zero(printed_e1_ode(f31).doit()),
            "f = C sqrt(1 + x1^2) is a solution too (the limit C2 -> oo of (31) with "
            "C1 ~ C2^(1/3))",
        )
    )
    dh = sp.Matrix([[sp.diff(x3 * f, v) for v in X]])
    L_family = e1_lagrangian(q, dh)
    form = x3**2 * (S1 * sp.diff(f, x1) / f - x1 / S1) ** 2 + x1**2 / (1 + x1**2)
    fam = C1 * S1 * sp.exp(k * sp.atan(x1))
    x3_term = sp.simplify(S1 * sp.diff(f31, x1) / f31 - x1 / S1)
    out.append(
        _finding(
            "E1 restricted to h = x3 f(x1) is minimised by (31)",
            _zero(x3_term) and _zero(L_family - form),
            "on the family the E1 integrand is x3^2 (sqrt(1+x1^2) f'/f - x1/sqrt(1+x1^2))^2 "
            f"+ x1^2/(1+x1^2) (identity checked: {_zero(L_family - form)}); it is minimised "
            "pointwise by f = C sqrt(1 + x1^2), i.e. (36) with a = 0, which makes the x3 term "
            "vanish. The Euler-Lagrange equation of the restricted (1-D) problem is "
            "((1 + x1^2) f'/f - x1)' = 0 with solutions f = C sqrt(1+x1^2) exp(k atan x1) "
            f"(checked: {_zero(sp.diff((1 + x1**2) * sp.diff(fam, x1) / fam - x1, x1))}); they "
            "solve the paper's ODE only for k = 0 (residual "
            f"{sp.factor(sp.simplify(printed_e1_ode(fam)))}). The paper's ODE is stationarity "
            "under variations vanishing on the boundary; the variation x3 df(x1) does not vanish "
            f"at the x3-faces of the region; for (31) the x3 term is {x3_term} != 0, so (31) is "
            "not the minimiser of E1 in the family over a box. E1 is invariant under h -> phi(h) "
            "(its integrand is homogeneous of degree 0 in dh), so its Euler equation is degenerate",
        )
    )
    g31 = x1 * S1 + sp.asinh(x1) + C2
    dhK31 = (sp.Matrix([[sp.diff(x3 * f31, v) for v in X]]) * q["K"])[0]
    out.append(
        _finding(
            "for (32), dh K = C1 (x1 sqrt(1+x1^2) + asinh(x1) + C2)^(-1/3): E1 is singular "
            "where it vanishes or blows up",
            _zero(dhK31 - C1 * g31 ** sp.Rational(-1, 3)),
            "E1 integrand = dh P dh^T/(dh K)^2 - 1; for h = x3 f(x1), dh K = f/sqrt(1 + x1^2): "
            "(32) is singular where x1 sqrt(1+x1^2) + asinh(x1) + C2 = 0 (for C2 in "
            "[-sqrt(2) - asinh(1), 0] this set meets x1 in [0, 1]), (33) at x1 = 3/2, (36) at "
            "x1 = -b/a",
        )
    )
    return out


@functools.lru_cache(maxsize=4)
def manipulator2_findings(l: float = 1.0) -> list[dict]:
    """Check sec. 5.2 against derivations from k(x) = (x2 + l cos x3, x1 + l sin x3), eq. (37)."""
    L = sp.nsimplify(l)
    q = kinematics_quantities([x2 + L * sp.cos(x3), x1 + L * sp.sin(x3)], X)
    out = []
    ell = sp.Symbol("l", positive=True)
    Jl = sp.Matrix([x2 + ell * sp.cos(x3), x1 + ell * sp.sin(x3)]).jacobian(X)
    printed_M = sp.Matrix(
        [
            [ell + ell**2 * sp.sin(x3) ** 2, -(ell**2) * sp.sin(x3) * sp.cos(x3)],
            [-(ell**2) * sp.sin(x3) * sp.cos(x3), ell + ell**2 * sp.cos(x3) ** 2],
        ]
    )
    out.append(
        _finding(
            "printed M(x) of Manipulator 2 equals J J^T (arm length l)",
            _zero(Jl * Jl.T - printed_M),
            f"J J^T = {(Jl * Jl.T).applyfunc(_simp).tolist()}: the diagonal starts with 1, not l "
            "(det J J^T = 1 + l^2)",
        )
    )
    out.append(
        _finding(
            "m = sqrt(1 + l^2) and K = (-l cos x3, l sin x3, 1)/m",
            _zero(q["m"] - sp.sqrt(1 + L**2))
            and _zero(q["K"] - sp.Matrix([-L * sp.cos(x3), L * sp.sin(x3), 1]) / sp.sqrt(1 + L**2)),
            "orientation: last component of K positive",
        )
    )
    r2 = sp.sqrt(2) / 2
    printed_R = r2 * sp.Matrix(
        [
            [(7 - sp.cos(2 * x3)) / 4, sp.cos(x3) * sp.sin(x3) / 2, -sp.cos(x3) / 2],
            [sp.cos(x3) * sp.sin(x3) / 2, (7 + sp.cos(2 * x3)) / 4, sp.sin(x3) / 2],
            [-sp.cos(x3) / 2, sp.sin(x3) / 2, sp.Rational(3, 2)],
        ]
    )
    if L == 1:
        R = q["R"]
        dR = R - printed_R
        out.append(
            _finding(
                "printed R(x) = m P of sec. 5.2 (l = 1)",
                _zero(dR),
                f"R = {R.tolist()}",
            )
        )
        out.append(
            _finding(
                "for h = h(x2, x3), R reduces to the printed 2 x 2 block",
                _zero(dR[1:, 1:]),
                "the reduced E2 integrand is (grad h R23 grad h - 2 grad h . (l sin x3, 1) + m), "
                "independent of x1",
            )
        )
    div_mK = sp.simplify(sum(sp.diff(q["m"] * q["K"][i], v) for i, v in enumerate(X)))
    out.append(
        _finding(
            "div(m K) = 0, so (20) is div(R grad h) = 0 as printed",
            div_mK == 0,
            "the only forcing is the natural boundary condition n . (R grad h - m K) = 0, so h is "
            "not determined by the printed PDE alone: h = 0 solves it; the E2 minimiser needs the "
            "natural boundary conditions",
        )
    )
    return out


def findings_summary(findings: list[dict]) -> dict:
    """``{"checked": n, "holding": n_true, "failing": [claims that do not hold]}``."""
    return {
        "checked": len(findings),
        "holding": sum(f["holds"] for f in findings),
        "failing": [f["claim"] for f in findings if not f["holds"]],
    }
