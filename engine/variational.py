"""Synthesis of the E2-optimal augmenting map by a Ritz method, eqs. (19)-(20).

For one degree of redundancy, E2(h) = integral of (dh P dh^T - 2 dh K + 1) m dx, eq. (19), is a
convex quadratic functional of h whose Euler equation is the linear elliptic PDE (20),
div(m P grad h) = div(m K), with the natural boundary condition n . (m P grad h - m K) = 0 on
the boundary of the region. Instead of discretising (20), E2 is minimised directly over a tensor
Legendre basis on the box (a spectral Ritz-Galerkin method), with a tensor Gauss-Legendre rule:
the minimiser solves one dense symmetric positive definite linear system A c = b with

    A_st = integral of grad(phi_s) R grad(phi_t),  b_s = integral of grad(phi_s) . m K,

R = m P restricted to the integrated variables (the paper's R(x) = m(x) P(x), sec. 5.2).

Additive constant: E2 depends on dh only, so the natural-boundary minimiser is unique up to a
constant. The constant Legendre mode P_0...P_0 is left out of the basis, which pins the mean of h
over the box to zero (every other tensor Legendre polynomial has zero mean).

Orientation: K has the paper's orientation (last component positive for Manipulators 1 and 2).
The term -2 dh K makes E2 prefer dh K > 0, so the synthesised h increases along K.

Dirichlet data g (optional) are imposed at the tensor Gauss-Lobatto-Legendre nodes of the box's
boundary, which determine the trace of a tensor polynomial uniquely; the constrained minimiser is
found from the KKT system.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import cast

import numpy as np
from numpy.polynomial import legendre as L
from scipy import linalg

from .augmentations import Polynomial2
from .exceptions import InvalidInputError
from .exports import Columns, json_values
from .functionals import Region, check_region, error_functional_e2
from .inverses import pseudoinverse, require_kinematics
from .kinematics import Kinematics, Manipulator2
from .legendre_map import SynthesizedMap, legendre_vander, lgl_nodes
from .progress import Progress, check_cancelled, check_progress
from .validation import FloatArray, as_numbers, count

#: Extra Gauss points per variable beyond the basis degree (R is not polynomial, e.g. cos 2 x3).
EXTRA_NODES = 8
#: Default region of Manipulator 2 (sec. 5.2).
MANIPULATOR2_REGION: dict[str, tuple[float, float]] = {"x2": (-1.0, 1.0), "x3": (0.0, np.pi)}

#: Default Legendre degree per variable of :func:`synthesize_e2`, by the region's number of
#: variables: 16 over two (Manipulator 2's E2 4.9e-9 above its degree-40 minimum,
#: docs/paper-errata.md), 10 over three (11^3 unknowns, a 14 MB Ritz matrix; 17^3 at 16 take
#: 0.2 GB, and its dense solve takes most of the time).
DEFAULT_DEGREE = {2: 16, 3: 10}
#: Largest Legendre degree per variable over two and over three variables.
MAX_DEGREE = {2: 64, 3: 16}
#: Basis degree (per variable) of the Manipulator 2 synthesis: the default over two variables.
MANIPULATOR2_DEGREE = DEFAULT_DEGREE[2]


@dataclass(frozen=True)
class SynthesisResult(Columns):
    """The E2-optimal augmenting map on a box and what it achieves.

    Attributes
    ----------
    augmenting_map : SynthesizedMap
        Named ``"e2_synthesized"``; usable by ``ExtendedInverse`` directly.
    e2 : float
        E2 of the map on the region (Ritz value, same quadrature as the solve).
    polynomial : Polynomial2 or None
        Least-squares cubic (total degree 3, like (38)) of the map over the region, in the
        region's variables; None for a three-variable region.
    polynomial_e2 : float
        E2 of that cubic on the region (NaN when there is none).
    grid : dict
        ``{name_1: [...], name_2: [...], "h": [[...]]}``, h on a uniform grid of the first two
        region variables (``h[i][j]`` at ``name_1[i]``, ``name_2[j]``; others at the box centre).
    convergence : list of dict
        ``{"degree", "unknowns", "e2"}`` for the resolutions computed, the last the result.
    region, fixed : dict
        The box and the values of the variables not integrated over.
    degree : int
        The basis degree (the largest; each variable's: the map's ``parameters``).
    nodes : int
        Gauss-Legendre nodes per variable of the rule E2 was minimised on, ``degree +``
        :data:`EXTRA_NODES` (n nodes integrate degree 2 n - 1 exactly; dh P dh^T m, eq. (19), is
        of degree 2 ``degree`` in dh times the smooth m P): E2 on it (``error_functional_e2``
        with ``nodes``) is :attr:`e2`; 8 nodes leave Manipulator 2's degree-16 map's 3e-5 off.
    """

    augmenting_map: SynthesizedMap
    e2: float
    polynomial: Polynomial2 | None
    polynomial_e2: float
    grid: dict
    convergence: list[dict]
    region: dict[str, tuple[float, float]] = field(default_factory=dict)
    fixed: dict[str, float] = field(default_factory=dict)
    degree: int = 0

    @property
    def nodes(self) -> int:
        return self.degree + EXTRA_NODES

    def __repr__(self) -> str:
        box = ", ".join(f"{k} in [{lo:.4g}, {hi:.4g}]" for k, (lo, hi) in self.region.items())
        own = {k[len("degree_") :]: n for k, n in self.augmenting_map.parameters.items()}
        each = ", ".join(f"{k} {n}" for k, n in own.items())
        degree = f"degree {self.degree}" if len(set(own.values())) < 2 else f"degrees {each}"
        return f"SynthesisResult(E2 = {self.e2:.6g}, {degree}, {box})"

    def columns(self) -> dict[str, FloatArray]:
        """A row per resolution computed (:attr:`convergence`), the last the result:
        ``degree``, ``unknowns``, ``e2``."""
        return {
            key: np.array([row[key] for row in self.convergence])
            for key in ("degree", "unknowns", "e2")
        }

    def as_dict(self) -> dict:
        """JSON values (None for a divergent E2): e2, degree, the cubic fit's E2, region, fixed,
        convergence, the cubic's coefficients (not the basis's; :attr:`grid` holds h)."""
        return json_values(
            {
                **{key: getattr(self, key) for key in ("e2", "degree", "polynomial_e2")},
                "region": {k: list(v) for k, v in self.region.items()},
                "fixed": dict(self.fixed),
                "convergence": list(self.convergence),
                "polynomial_coefficients": self.polynomial_coefficients(),
            }
        )

    def polynomial_coefficients(self) -> dict[str, float]:
        """Cubic coefficients keyed like ``"x2^2 x3^1"`` (JSON-friendly)."""
        return {} if self.polynomial is None else self.polynomial.monomials()


class _Problem:
    """Quadrature data of E2 on a box: R = m P and f = m K restricted to the region's variables."""

    def __init__(self, kinematics: Kinematics, box: dict, fix: dict, nodes: Sequence[int]):
        self.names = names = tuple(kinematics.variable_names)
        self.box, self.fix = box, fix
        self.variables = [names.index(n) for n in box]
        lo, hi = np.array(list(box.values()), dtype=float).T
        self.scale, self.center = 2.0 / (hi - lo), 0.5 * (lo + hi)
        self.base = np.array([fix.get(n, 0.0) for n in names])
        rules = [L.leggauss(n) for n in nodes]
        self.t = [r[0] for r in rules]
        w = functools.reduce(np.multiply.outer, [r[1] for r in rules]) / np.prod(self.scale)
        self.x = x = self.points(
            np.stack(np.meshgrid(*self.t, indexing="ij"), axis=-1).reshape(w.size, -1)
        )
        kinematics.require_regular(x, "synthesis region (a quadrature point)", "region")
        J, K, m = kinematics.jacobian(x), kinematics.kernel(x), kinematics.manipulability(x)
        Jp = pseudoinverse(J)
        P = Jp @ np.swapaxes(Jp, -1, -2) + K[:, :, None] * K[:, None, :]  # (n, p, p)
        idx = np.array(self.variables)
        self.w = w.ravel()
        self.R = (m[:, None, None] * P)[:, idx][:, :, idx]  # (n, d, d)
        self.f = (m[:, None] * K)[:, idx]  # (n, d)
        self.constant = float(np.dot(self.w, m))  # E2 of h = const

    def points(self, t: FloatArray) -> FloatArray:
        """The configurations (n, p) at reference points t (n, d) of [-1, 1]^d of the box."""
        x = np.tile(self.base, (len(t), 1))
        x[:, self.variables] = self.center + t / self.scale
        return x

    def system(self, degrees: Sequence[int]) -> tuple[FloatArray, FloatArray]:
        """Stiffness A (nb, nb) and load b (nb,) over the full tensor basis (constant included),
        contracted one variable at a time (basis and rule are tensor products), added into A in
        place: the memory is that of A and one block, not the basis' gradients at all nodes."""
        d, sizes = len(degrees), tuple(n + 1 for n in degrees)
        bases = [legendre_vander(t, n) for t, n in zip(self.t, degrees, strict=True)]
        # grads[k][j]: the factor of variable j in d(phi)/dx_k, (nodes_j, n_j + 1)
        grads = [
            [dV * k_scale if j == k else V for j, (V, dV) in enumerate(bases)]
            for k, k_scale in enumerate(self.scale)
        ]
        nb, shape = int(np.prod(sizes)), [len(x) for x in self.t]
        A, rhs = np.zeros((nb, nb)), np.zeros(nb)
        A_st = A.reshape(sizes + sizes)  # a view, axes (s_1 .. s_d, t_1 .. t_d)
        s, t = list(range(0, 2 * d, 2)), list(range(1, 2 * d, 2))
        for a in range(d):
            for b in range(a, d):
                T = (self.w * self.R[:, a, b]).reshape(shape)
                for ga, gb in zip(grads[a], grads[b], strict=True):  # -> (s_1, t_1, ..., t_d)
                    T = np.tensordot(T, ga[:, :, None] * gb[:, None, :], (0, 0))
                A_st += T.transpose(s + t)
                if a != b:
                    A_st += T.transpose(t + s)
            T = (self.w * self.f[:, a]).reshape(shape)
            for ga in grads[a]:
                T = np.tensordot(T, ga, (0, 0))
            rhs += T.ravel()
        return A, rhs


def _sub_basis(full: Sequence[int], degrees: Sequence[int]) -> FloatArray:
    """Indices, in the tensor basis of degrees ``full``, of the tensor basis of ``degrees``.

    The Legendre basis is hierarchical, so the Ritz system of a lower degree is a principal
    submatrix of the highest-degree one (same quadrature): it is assembled only once.
    """
    grids = np.meshgrid(*[np.arange(n + 1) for n in degrees], indexing="ij")
    return np.ravel_multi_index(tuple(g.ravel() for g in grids), tuple(n + 1 for n in full))


def _solve(
    problem: _Problem,
    system: tuple[FloatArray, FloatArray, Sequence[int]],
    degrees: Sequence[int],
    dirichlet: Callable | None,
    kinematics: Kinematics,
) -> tuple[FloatArray, float]:
    """Ritz minimiser of E2: coefficients (n_1 + 1, ..., n_d + 1) and its E2 value."""
    A_full, b_full, full = system
    idx = None if list(degrees) == list(full) else _sub_basis(full, degrees)
    # (the final degree's system is A itself: the largest matrix is not copied)
    A, b = (A_full, b_full) if idx is None else (A_full[np.ix_(idx, idx)], b_full[idx])
    shape = tuple(n + 1 for n in degrees)
    if dirichlet is None:
        # Drop the constant mode: mean(h) = 0 over the box, A is then positive definite.
        c = np.zeros(A.shape[0])
        c[1:] = linalg.solve(A[1:, 1:], b[1:], assume_a="pos")
    else:
        nodes = [lgl_nodes(n) for n in degrees]
        grid = np.stack(np.meshgrid(*nodes, indexing="ij"), axis=-1).reshape(-1, len(degrees))
        on_boundary = np.any(np.isclose(np.abs(grid), 1.0), axis=1)
        tb = grid[on_boundary]  # (nc, d) reference boundary nodes
        C = functools.reduce(
            lambda X, Y: np.einsum("ni,nj->nij", X, Y).reshape(X.shape[0], -1),
            [L.legvander(tb[:, k], n) for k, n in enumerate(degrees)],
        )
        x = problem.points(tb)
        g = as_numbers(dirichlet(x), "dirichlet's values", "dirichlet").reshape(-1)
        if g.shape[0] != x.shape[0] or not np.all(np.isfinite(g)):
            raise InvalidInputError("dirichlet must give one finite value per point", "dirichlet")
        nc = C.shape[0]
        KKT = np.block([[A, C.T], [C, np.zeros((nc, nc))]])
        c = linalg.solve(KKT, np.concatenate([b, g]), assume_a="sym")[: A.shape[0]]
    e2 = problem.constant + float(c @ A @ c) - 2.0 * float(c @ b)
    return c.reshape(shape), e2


def _cubic_fit(amap: SynthesizedMap, problem: _Problem) -> Polynomial2:
    """L2(region) least-squares fit of h by a cubic in two variables, like (38)."""
    va, vb = problem.variables  # two region variables (the caller checks d == 2)
    x = problem.x
    xa, xb = x[:, va], x[:, vb]
    powers = [(i, j) for i in range(4) for j in range(4) if i + j <= 3]
    M = np.stack([xa**i * xb**j for i, j in powers], axis=1)
    sw = np.sqrt(problem.w)
    coef, *_ = np.linalg.lstsq(M * sw[:, None], amap.value(x) * sw, rcond=None)
    coefficients = dict(zip(powers, coef.tolist(), strict=True))
    return Polynomial2(coefficients, (va, vb), amap.p)


def _plot_grid(amap: SynthesizedMap, problem: _Problem, n: int = 41) -> dict:
    names = list(problem.box)
    x0 = np.zeros(amap.p)
    for name, val in problem.fix.items():
        x0[problem.names.index(name)] = val
    for name, (lo, hi) in problem.box.items():
        x0[problem.names.index(name)] = 0.5 * (lo + hi)
    a, b = (np.linspace(problem.box[k][0], problem.box[k][1], n) for k in names[:2])
    x = np.broadcast_to(x0, (n, n, amap.p)).copy()
    x[..., problem.variables[0]] = a[:, None]
    x[..., problem.variables[1]] = b[None, :]
    return {names[0]: a.tolist(), names[1]: b.tolist(), "h": amap.value(x).tolist()}


def synthesize_e2(
    kinematics: Kinematics,
    region: Region,
    *,
    degree: int | Sequence[int] | None = None,
    dirichlet: Callable[[FloatArray], FloatArray] | None = None,
    fixed: Mapping[str, float] | None = None,
    progress: Progress | None = None,
    convergence_degrees: Sequence[int] = (),
) -> SynthesisResult:
    """Minimise E2, eq. (19), over augmenting maps h of the region's variables (Ritz method).

    Parameters
    ----------
    kinematics : Kinematics
        With one degree of redundancy (p - r = 1).
    region : mapping name -> (lo, hi)
        Two or three integrated joint variables (h depends on these only); the others are held
        at ``fixed`` (default: the robot's home, :func:`~.kinematics.held_values`).
    degree : int or sequence of int, optional
        Legendre degree per variable (the error decays exponentially with it for smooth data);
        default :data:`DEFAULT_DEGREE` of the region's number of variables.
    dirichlet : callable, optional
        ``g(x) (n, p) -> (n,)``: boundary values of h. Default: natural boundary conditions
        n . (m P grad h - m K) = 0, with mean(h) = 0 over the box pinning the constant.
    fixed : mapping name -> value, optional
    progress : Progress, optional
        Told ``advance(fraction, 1)`` as the work proceeds, and asked between the degrees
        whether to go on (:meth:`Progress.cancelled`: True raises ``RunCancelled``).
    convergence_degrees : sequence of int
        Lower degrees to solve as well, to show the convergence of E2 with resolution.

    Returns
    -------
    SynthesisResult
    """
    kinematics = require_kinematics(kinematics)
    if dirichlet is not None and not callable(dirichlet):
        raise InvalidInputError(
            f"dirichlet must be a function g(x) (n, p) -> (n,), got {type(dirichlet).__name__}",
            "dirichlet",
        )
    if kinematics.p - kinematics.r != 1:
        raise InvalidInputError(
            "synthesize_e2 needs one degree of redundancy (p - r = 1)", "kinematics"
        )
    box, fix = check_region(kinematics, region, fixed)
    progress = check_progress(progress)
    d = len(box)
    if d not in (2, 3):
        raise InvalidInputError(
            f"the region must have two or three variables, got {list(box)}", "region"
        )
    degree = DEFAULT_DEGREE[d] if degree is None else degree
    degs = [degree] * d if np.ndim(degree) == 0 else list(cast(Sequence[int], degree))
    if len(degs) != d:
        raise InvalidInputError(
            f"degree needs one value per region variable ({d}), got {degree}", "degree"
        )
    degs = [count(n, "degree", 1, MAX_DEGREE[d]) for n in degs]
    levels = sorted(
        {
            count(n, "convergence degree", 1, max(degs), "convergence_degrees")
            for n in convergence_degrees
        }
    )
    levels = [n for n in levels if n < min(degs)]
    plan = [[n] * d for n in levels] + [degs]
    cost = np.array([float(np.prod(np.add(q, 1))) ** 2 for q in plan])
    done = 0.0
    problem = _Problem(kinematics, box, fix, [n + EXTRA_NODES for n in degs])
    if progress is not None:
        progress.advance(0.05, 1.0)
    convergence = []
    system = (*problem.system(degs), degs)
    for q, c in zip(plan, cost, strict=True):
        check_cancelled(progress, f"E2 synthesis cancelled before degree {max(q)}")
        coef, e2 = _solve(problem, system, q, dirichlet, kinematics)
        convergence.append({"degree": max(q), "unknowns": int(np.prod(np.add(q, 1))), "e2": e2})
        done += c
        if progress is not None:
            progress.advance(0.05 + 0.85 * done / cost.sum(), 1.0)
    amap = SynthesizedMap(coef, box, problem.variables, kinematics.p)
    poly, poly_e2 = None, float("nan")
    if d == 2:
        poly = _cubic_fit(amap, problem)
        poly_e2 = error_functional_e2(kinematics, poly, box, nodes=32, fixed=fix).value
    result = SynthesisResult(
        augmenting_map=amap,
        e2=convergence[-1]["e2"],
        polynomial=poly,
        polynomial_e2=poly_e2,
        grid=_plot_grid(amap, problem),
        convergence=convergence,
        region=box,
        fixed=fix,
        degree=max(degs),
    )
    if progress is not None:
        progress.advance(1.0, 1.0)
    return result


def synthesize_manipulator2(l: float = 1.0, progress: Progress | None = None) -> SynthesisResult:
    """E2-optimal h(x2, x3) of Manipulator 2 on x2 in [-1, 1], x3 in [0, pi] (sec. 5.2).

    Natural boundary conditions, mean(h) = 0 over the box, x1 = 0 (the integrand does not
    depend on x1), Legendre degree ``MANIPULATOR2_DEGREE`` with the convergence in E2 shown
    at lower degrees.
    """
    return synthesize_e2(
        Manipulator2(l),
        MANIPULATOR2_REGION,
        degree=MANIPULATOR2_DEGREE,
        convergence_degrees=(2, 4, 6, 8, 12),
        progress=progress,
    )


@functools.lru_cache(maxsize=8)
def default_manipulator2_synthesis(l: float = 1.0) -> SynthesisResult:
    """:func:`synthesize_manipulator2`, cached (the API, CLI and dashboard share one result)."""
    return synthesize_manipulator2(l)
