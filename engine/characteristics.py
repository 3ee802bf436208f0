"""Synthesis of an augmenting map by characteristics, one degree of redundancy (section 4).

The one-form omega annihilates J^T (omega J^T = 0) and is normalised by one component,
``omega[fixed_index] = 1`` (:mod:`jik.engine.one_form`). A linear homotopy Phi_s contracts every
configuration onto a reference leaf along the components transverse to the leaves, eqs. (21),
(22), (45); the augmenting map h is the end point z(0) of the characteristic (28) started at
z(1) = z, eq. (29). Its exact gradient comes from the variational equations along the same
characteristic (both solved in :mod:`jik.engine.collocation`).

This module is the map: its cache and warm starts, its batches with progress, and what it does
where h is undefined.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .augmentations import AugmentingMap
from .collocation import (
    COLLOCATION_NODES,
    LinearHomotopy,
    collocation,
    moments_ignore,
    solve_characteristics,
)
from .exceptions import InvalidInputError, OneFormUndefinedError, format_vector
from .inverses import require_kinematics
from .kinematics import Kinematics
from .one_form import check_index
from .progress import Progress, check_cancelled, check_progress
from .unicycle import Unicycle
from .validation import FloatArray, as_vector, count, finite

#: Warm-start Newton from the previous characteristics when x moved by at most this (max norm).
WARM_RADIUS = 0.5


class CharacteristicsMap(AugmentingMap):
    """Augmenting map h(y, z) = z(0) of the characteristic (28), eq. (29), with its exact gradient.

    Parameters
    ----------
    kinematics : Kinematics
        p = r + 1, with ``hessian`` (needed for d omega).
    reference : array_like, shape (p,)
        A point of the reference leaf (its z component is ignored).
    fixed_index : int
        0-based index of the leaf coordinate z; omega is normalised with omega_z = 1.
    nodes : int
        Collocation nodes in s (default :data:`COLLOCATION_NODES`).
    on_undefined : {"raise", "nan"}
        What :meth:`value` and :meth:`gradient` do where omega is undefined along the
        characteristic (or Newton fails): raise :class:`OneFormUndefinedError`, or return NaN
        (the extended inverse then reports an algorithmic singularity there).

    Notes
    -----
    With Phi_s(y, z) = x_ref + s y (transverse), z (leaf), X(Phi_s) = s Y where Y = X(x), so
    eq. (28) reads dz/ds = -F(Phi_s)/s = -omega(Phi_s(y, z)) Y: regular at s = 0. The
    variational equations for S = dz(s)/d(y, z(1)) are
    dS/ds = G_z S + G_y, S(1) = (0, ..., 1), with G_z = -(d omega/dz) Y and
    G_y = -s (d omega/dy) Y - omega_y; then dh = S(0).
    """

    name = "characteristics"
    solves_per_point = True

    def __init__(
        self,
        kinematics: Kinematics,
        reference,
        fixed_index: int,
        nodes: int = COLLOCATION_NODES,
        on_undefined: str = "raise",
    ) -> None:
        self.kinematics = kinematics = require_kinematics(kinematics)
        if not (hasattr(kinematics, "derivatives") or hasattr(kinematics, "hessian")):
            raise InvalidInputError(
                f"{kinematics.name} has no second derivatives (hessian()), which the one-form's "
                "d omega needs: a planar chain, a formula robot (the paper's manipulators as "
                "formulas too) and the unicycle have them",
                "kinematics",
            )
        self.p = kinematics.p
        self.fixed_index = check_index(kinematics, fixed_index)
        self.homotopy = LinearHomotopy(as_vector(reference, self.p, "reference"), fixed_index)
        self.nodes = count(nodes, "collocation nodes", 4, 200, "nodes")
        if on_undefined not in ("raise", "nan"):
            raise InvalidInputError(
                f"on_undefined must be 'raise' or 'nan', got {on_undefined!r}", "on_undefined"
            )
        self.on_undefined = on_undefined
        self._cache: tuple | None = None
        #: Where the last characteristic() failed first: (Phi_s or None, s or None, x), or None.
        self._where: Any = None

    def moments_ignore(self, f: int) -> bool:
        """Whether the kinematics' quadrature moments ignore the leaf coordinate x[f].

        True for the unicycle with z = lambda10 or lambda11 (q3 depends on lambda20, lambda21
        only): Newton, which varies only z, then reuses the moments of the base points.
        """
        return moments_ignore(self.kinematics, f)

    def characteristic(
        self, x, guess=None
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Solve the characteristic (28) through each x, batched.

        Parameters
        ----------
        x : array_like, shape (..., p)
        guess : ndarray, shape (..., n), optional
            Initial z(s) at the n = ``nodes`` nodes for Newton (default: z(s) = z(1)).

        Returns
        -------
        s : ndarray, shape (n,)
            Collocation nodes, s[0] = 0, s[-1] = 1.
        z : ndarray, shape (..., n)
            z(s) at the nodes; h(x) = z[..., 0].
        S : ndarray, shape (..., n, p)
            dz(s)/dx at the nodes (variational equations); dh = S[..., 0, :].
        failed : ndarray of bool, shape (...,)
            Where omega is undefined along the characteristic or Newton failed.

        Notes
        -----
        Every Newton iteration evaluates omega and d omega at all nodes; the last update is at
        most NEWTON_TOL (relative), so the variational system, linearised at that last
        evaluation, gives dh consistent with h to about NEWTON_TOL. Members whose last three
        Chebyshev coefficients of z(s) exceed TAIL_TOL (a steep characteristic, e.g. one that
        passes near a zero of the normalising kernel component) are solved again on the nested
        Lobatto grid of 2n - 1 nodes (REFINE_LEVELS); results are returned on the n base nodes.
        Batches of more than MAX_MEMBERS are solved MAX_MEMBERS members at a time (the
        constants are :mod:`jik.engine.collocation`'s).
        """
        x = self.kinematics.check(x)
        shape = x.shape[:-1]
        n = self.nodes
        g = None if guess is None else np.array(guess, dtype=float).reshape(-1, n)
        Z, S, failed, self._where = solve_characteristics(
            self.kinematics, self.homotopy, x.reshape(-1, self.p), n, g
        )
        s0 = collocation(n)[0]
        return s0, Z.reshape(*shape, n), S.reshape(*shape, n, self.p), failed.reshape(shape)

    def evaluate(self, x) -> tuple[FloatArray, FloatArray, FloatArray]:
        """h(x) (...,), dh/dx (..., p) and the failure mask (...,), without raising.

        Notes
        -----
        The last result is cached (the solver asks for h and dh at the same x), and Newton is
        warm-started from the last characteristics, extrapolated to first order with their
        sensitivities, when the batch has the same shape and moved by at most WARM_RADIUS; a
        warm start that fails is retried cold.
        """
        x = self.kinematics.check(x)
        last = self._cache
        if last is not None and last[0].shape == x.shape and np.array_equal(last[0], x):
            return last[1]
        guess = None
        if last is not None and last[0].shape == x.shape:
            dx = x - last[0]
            if np.max(np.abs(dx), initial=0.0) <= WARM_RADIUS:
                guess = last[3] + np.einsum("...nk,...k->...n", last[4], dx)
        _, Z, S, failed = self.characteristic(x, guess)
        if guess is not None and np.any(failed):
            _, Z, S, failed = self.characteristic(x)
        h = np.where(failed, np.nan, Z[..., 0])
        dh = np.where(failed[..., None], np.nan, S[..., 0, :])
        out = (h, dh, failed)
        self._cache = (x.copy(), out, self._where, Z, S)
        return out

    def evaluate_batches(
        self,
        x,
        batch: int = 45,
        progress: Progress | None = None,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """:meth:`evaluate` of a large set of points, ``batch`` members at a time.

        Parameters
        ----------
        x : array_like, shape (n, p)
        batch : int
            Members per Newton solve (each one cold, from z(s) = z(1): the result never depends
            on the order of the batches).
        progress : Progress, optional
            Told ``advance(batches_done, batches_total)`` after each batch, then asked whether to
            go on (:meth:`Progress.cancelled`: True raises ``RunCancelled``); what it raises
            stops the evaluation there.

        Returns
        -------
        h : ndarray, shape (n,)
        dh : ndarray, shape (n, p)
        failed : ndarray of bool, shape (n,)

        Notes
        -----
        Each member's characteristic (28) is its own Newton solve; a batch only shares the
        iterations, which go on until its slowest member converges. Batches bound that, so that
        a few slow members do not hold up the rest, and give the caller a place to report
        progress and to stop.
        """
        x = self.kinematics.check(x)
        progress = check_progress(progress)
        xb = x.reshape(-1, self.p)
        size = count(batch, "batch", 1, 1_000_000)
        total = -(-len(xb) // size)
        h, dh = np.empty(len(xb)), np.empty((len(xb), self.p))
        failed = np.empty(len(xb), dtype=bool)
        for k in range(total):
            part = slice(k * size, (k + 1) * size)
            _, Z, S, bad = self.characteristic(xb[part])
            h[part] = np.where(bad, np.nan, Z[:, 0])
            dh[part] = np.where(bad[:, None], np.nan, S[:, 0, :])
            failed[part] = bad
            if progress is not None:
                progress.advance(k + 1, total)
                check_cancelled(progress, f"h evaluation cancelled after batch {k + 1} of {total}")
        shape = x.shape[:-1]
        return h.reshape(shape), dh.reshape(*shape, self.p), failed.reshape(shape)

    def _raise_if(self, failed) -> None:
        if self.on_undefined == "raise" and np.any(failed):
            assert self._cache is not None  # evaluate() ran first and filled it
            phi, s, x = self._cache[2]
            if phi is None:
                raise OneFormUndefinedError(
                    "h(x) is undefined: its characteristic (28) could not be resolved (Newton "
                    "on the collocation system did not converge or z(s) is unresolved): it runs "
                    f"into a near-zero of the kernel component {self.fixed_index} (0-based) of "
                    f"{self.kinematics.name}, where omega and dz/ds blow up",
                    x,
                    "x",
                )
            raise OneFormUndefinedError(
                f"h(x) is undefined: along its characteristic (28), at s = {s:.3g}, "
                f"Phi_s = {format_vector(phi)}, the kernel component {self.fixed_index} "
                f"(0-based) of {self.kinematics.name} vanishes, so omega cannot be normalised",
                x,
                "x",
            )

    def value(self, x: FloatArray) -> FloatArray:
        """h(x) = z(0), eq. (29): (..., p) -> (...,)."""
        h, _, failed = self.evaluate(x)
        self._raise_if(failed)
        return h

    def gradient(self, x: FloatArray) -> FloatArray:
        """dh/dx from the variational equations: (..., p) -> (..., p)."""
        _, dh, failed = self.evaluate(x)
        self._raise_if(failed)
        return dh

    def value_masked(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """h(x) with NaN and a mask where it is undefined, whatever ``on_undefined`` says."""
        h, _, failed = self.evaluate(x)
        return h, np.asarray(failed, dtype=bool)

    def gradient_masked(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """dh/dx with NaN rows and a mask where h is undefined, whatever ``on_undefined`` says.

        The solver evaluates trial points (Runge-Kutta stages, Picard nodes) off the final path;
        one undefined trial point must stop that member only, not raise for the whole batch.
        """
        _, dh, failed = self.evaluate(x)
        return dh, np.asarray(failed, dtype=bool)


class UnicycleCharacteristics(CharacteristicsMap):
    """The unicycle's augmenting map of section 6.1: reference leaf E_{a,0} = a e1 + R e2.

    y1 = l10 - a, y2 = l20, y3 = l21, z = l11 (eq. (45), (46)); omega is normalised with
    omega2 = 1 (1-based), i.e. ``fixed_index = 1``.

    Parameters
    ----------
    kinematics : Unicycle
        The unicycle (its q0 and T define omega and so h).
    a : float
        Reference leaf parameter, a != 0 (omega is undefined at lambda10 = 0).
    """

    name = "characteristics"

    def __init__(
        self,
        kinematics: Unicycle | None = None,
        a: float = 1.0,
        nodes: int = COLLOCATION_NODES,
        on_undefined: str = "raise",
    ) -> None:
        self.a = finite(a, "a")
        if self.a == 0:
            raise InvalidInputError(
                "a must be nonzero: omega is undefined on lambda10 = 0, so the reference "
                "leaf E_{a,0} = a e1 + R e2 needs a != 0",
                "a",
            )
        kinematics = Unicycle() if kinematics is None else kinematics
        super().__init__(kinematics, (self.a, 0.0, 0.0, 0.0), 1, nodes, on_undefined)

    @property
    def parameters(self) -> dict[str, float]:
        return {"a": self.a}


__all__ = ["CharacteristicsMap", "UnicycleCharacteristics"]
