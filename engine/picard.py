"""Chebyshev-Picard integration of the continuation path, the fast route for eq. (7).

Along the exact solution of (7) the task error is e(theta) = e0 exp(-gamma theta), eq. (5).
With sigma = 1 - exp(-gamma theta) in [0, 1), the same trajectory solves the homotopy ODE

    dx/dsigma = -J#(x) e0,   x(0) = x0,   sigma in [0, 1],                       (*)

whose end point x(1) is the limit x_d = lim x(theta). (*) is integrated by Picard iteration on
Chebyshev-Lobatto nodes over adaptive segments of [0, 1] ("modified Chebyshev-Picard iteration"):
every sweep evaluates J# at all nodes of all batch members in one vectorized call, so one leg costs
about twenty evaluations instead of several hundred for a step-by-step Runge-Kutta method.
Segments are halved when the iteration does not contract or the Chebyshev tail shows the path
is not resolved; members that cannot be resolved are handed back to the caller (DOP853 fallback).

A member may come with a guess: the nodes of an earlier, nearby path (the same leg of the
previous cycle of a closed path, say). A segment whose nodes are among the guess's starts its
sweeps from the guess's values there, shifted to the segment's start, instead of from a constant.
The sweeps, their convergence test and the resolution test are the same, so the result is the same
fixed point to the sweep tolerance; only the number of sweeps falls (on a repeatable algorithm's
second cycle, from about eight per leg to one or two).

:func:`picard_chain` makes such guesses for a chain of legs, each starting where the one before
ends (a closed path): all legs are swept together, each from the current end of the one before.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np
from numpy.polynomial import chebyshev as C

from .validation import FloatArray

#: Chebyshev degree per segment.
DEGREE = 32
#: Picard sweeps per segment before it is halved.
MAX_SWEEPS = 40
#: Convergence of a sweep and resolution of a segment (relative to 1 + |x|).
SWEEP_TOL = 1e-13
TAIL_TOL = 1e-12
#: Segments shorter than this are given up (the path is near a singularity).
MIN_SEGMENT = 1e-4
#: A guess's node is used for a segment's node when their sigma differ by at most this.
GUESS_MATCH = 1e-12

#: A guess for one member: sigma (k,) ascending, ending at 1, and x there (k, p).
Guess = tuple[FloatArray, FloatArray]
#: Sweeps of :func:`picard_chain` before it gives up.
CHAIN_SWEEPS = 80


@lru_cache(maxsize=4)
def chebyshev_operators(n: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Lobatto nodes on [-1, 1], cumulative integration matrix S, values-to-coefficients T.

    ``S @ f`` gives the integral from -1 to each node of the interpolant of the node values f.
    """
    t = -np.cos(np.pi * np.arange(n + 1) / n)  # ascending from -1 to 1
    V = C.chebvander(t, n)  # (n+1, n+1): T_k(t_j)
    T = np.linalg.inv(V)  # values -> coefficients (well conditioned at Lobatto nodes)
    S = C.chebval(t, C.chebint(T, lbnd=-1)).T  # (n+1, n+1)
    return t, S, T


def _seeded(guess: Guess, a: float, h: float, unit: FloatArray, start: FloatArray):
    """The guess's values at the nodes of the segment [a, a + h], moved to begin at ``start``;
    None when the guess does not have all of them."""
    gs, gx = guess
    sig = a + h * unit
    j = np.searchsorted(gs, sig - GUESS_MATCH)
    if j[-1] >= len(gs) or not np.max(np.abs(gs[j] - sig)) <= GUESS_MATCH:
        return None
    return gx[j] - gx[j[0]] + start


def picard_path(
    inverse,
    x0: FloatArray,
    e0: FloatArray,
    max_sweeps_total: int,
    guess: Sequence[Guess | None] | None = None,
    check_start: bool = False,
):
    """Integrate (*) for a batch; see module docstring.

    Parameters
    ----------
    inverse : Inverse
    x0 : ndarray, shape (n, p)
    e0 : ndarray, shape (n, r)
        k(x0) - y_d.
    max_sweeps_total : int
        Cap on Picard sweeps per member.
    guess : sequence of (sigma (k,), x (k, p)) or None, optional
        Per member, the nodes of a nearby path with sigma ascending and its last node at
        sigma = 1 (see module docstring), or None.
    check_start : bool
        Raise ``inverse.singular_error`` at a start configuration where J# is undefined. The
        first sweep evaluates J# there (every segment's first node is its start), so this costs
        nothing; without it such a member is halved down to MIN_SEGMENT and fails.

    Returns
    -------
    x1 : ndarray, shape (n, p)
        x(sigma = 1).
    ok : ndarray of bool, shape (n,)
        Members integrated to sigma = 1 (others: x1 is the last accepted point, sigma_end < 1).
    sigma_end : ndarray, shape (n,)
    sweeps : ndarray of int, shape (n,)
    records : list of (member ids, sigma (k,), x (k, p))
        Accepted nodes with sigma < 1, in order.
    """
    n, p = x0.shape
    t, S, T = chebyshev_operators(DEGREE)
    unit = (t + 1.0) / 2.0  # node positions in [0, 1] of a segment
    nn = t.size
    a = np.zeros(n)
    H = np.ones(n)
    xa = x0.copy()
    X = np.repeat(x0[:, None, :], nn, axis=1)  # (n, nn, p) current iterate
    sweeps_seg = np.zeros(n, dtype=int)
    sweeps = np.zeros(n, dtype=int)
    done = np.zeros(n, dtype=bool)
    failed = np.zeros(n, dtype=bool)
    records = []
    guesses = [None] * n if guess is None else list(guess)

    def seed(ids) -> None:
        """Start the new segments of members ``ids`` from their guesses where those fit."""
        for i in ids:
            g = guesses[i]
            values = None if g is None else _seeded(g, a[i], H[i], unit, xa[i])
            if values is not None:
                X[i] = values

    if guess is not None:
        seed(range(n))
    first = check_start
    while True:
        act = np.flatnonzero(~done & ~failed)
        if act.size == 0:
            break
        # The working set: the active members' iterates, errors and segment data, compact.
        # Sweeps run on it without any indexing until something happens to one member (it
        # converges, meets a singularity, or reaches a sweep limit).
        m = act.size
        Xw = X[act]  # (m, nn, p)
        Ew = np.repeat(e0[act], nn, axis=0)  # (m * nn, r)
        base = xa[act, None, :]  # (m, 1, p)
        half = (H[act] / 2.0)[:, None, None]
        # sweeps this working set may run before a per-segment or total limit is reached
        room = int(np.min(np.minimum(MAX_SWEEPS - sweeps_seg[act], max_sweeps_total - sweeps[act])))
        k = 0
        while True:
            v, bad = inverse.apply_masked(Xw.reshape(m * nn, p), Ew)
            if first:  # (every member, at its start: node 0)
                first = False
                at_start = bad.reshape(m, nn)[:, 0]
                if at_start.any():
                    error = inverse.singular_error(x0[act[np.argmax(at_start)]])
                    error.field = "x0"
                    raise error
            Xn = base - half * (S @ v.reshape(m, nn, p))  # S (nn, nn) @ (m, nn, p)
            # (ndarray methods and in-place ufuncs: this loop is mostly per-call overhead)
            change = np.abs(Xn - Xw)
            change /= np.abs(Xn) + 1.0
            diff = change.max(axis=(1, 2))
            Xw = Xn
            k += 1
            if k >= room or bad.any() or not diff.min() >= SWEEP_TOL:  # (NaN is an event)
                break
        bad = bad.reshape(m, nn).any(axis=1)
        X[act] = Xw
        sweeps_seg[act] += k
        sweeps[act] += k
        bad |= ~np.isfinite(diff)
        conv = (diff < SWEEP_TOL) & ~bad
        if np.any(conv):
            ci = act[conv]
            coef = T @ X[ci]  # (k, nn, p) Chebyshev coefficients
            tail = np.max(np.abs(coef[:, -2:, :]), axis=(1, 2))
            resolved = tail < TAIL_TOL * (1.0 + np.max(np.abs(coef), axis=(1, 2)))
            acc = ci[resolved]
            if acc.size:
                sig = a[acc, None] + H[acc, None] * unit[None, :]  # (k, nn)
                keep = sig < 1.0
                mem = np.broadcast_to(acc[:, None], sig.shape)
                # the first node repeats the previous segment's last one
                keep[:, 0] = a[acc] == 0.0
                records.append((mem[keep], sig[keep], X[acc][keep]))
                xa[acc] = X[acc, -1]
                a[acc] += H[acc]
                fast = sweeps_seg[acc] < MAX_SWEEPS // 2
                H[acc] = np.where(fast, 2 * H[acc], H[acc])
                fin = a[acc] >= 1.0 - 1e-15
                done[acc[fin]] = True
                a[acc[fin]] = 1.0
                H[acc] = np.minimum(H[acc], np.maximum(1.0 - a[acc], 0.0))
                sweeps_seg[acc] = 0
                X[acc] = xa[acc, None, :]
                if guess is not None:
                    seed(acc[~fin])
            halve_res = ci[~resolved]
        else:
            halve_res = np.zeros(0, dtype=int)
        stuck = act[bad | ((sweeps_seg[act] >= MAX_SWEEPS) & ~conv)]
        halve = np.concatenate([halve_res, stuck])
        if halve.size:
            H[halve] /= 2.0
            sweeps_seg[halve] = 0
            X[halve] = xa[halve, None, :]
            if guess is not None:
                seed(halve)
            failed[halve[H[halve] < MIN_SEGMENT]] = True
        failed |= ~done & (sweeps >= max_sweeps_total)
    return xa, done, a, sweeps, records


def picard_chain(inverse, x0: FloatArray, y: FloatArray, max_sweeps: int = CHAIN_SWEEPS):
    """Guesses for legs of eq. (7) solved one after another: leg j from the end of leg j - 1
    to y[j].

    Solved leg by leg, L legs cost L times the sweeps of one (about ten for the pseudoinverse,
    whose legs in a later cycle are not those of the cycle before). Here each sweep of (*)
    updates every leg at once on the segment [0, 1], leg j from the current end of leg j - 1
    (and e0 = k(that end) - y[j]): one vectorized evaluation of J# a sweep for all legs, and
    about L more sweeps than one leg needs, as each leg settles a sweep after the one before.

    Nothing is checked but the sweeps' convergence (:data:`SWEEP_TOL`): the result is a guess
    for :func:`picard_path` (through ``engine.solver.solve(guess=)``), which sweeps each leg
    again from it with its own tests and gives its own fixed point; a guess only saves sweeps.

    Parameters
    ----------
    inverse : Inverse
    x0 : ndarray, shape (p,)
        Start of the first leg.
    y : ndarray, shape (L, r)
        Targets of the legs.
    max_sweeps : int

    Returns
    -------
    (sigma (DEGREE + 1,), X (L, DEGREE + 1, p)) : the nodes of [0, 1] and each leg's values
    there, or None when a leg meets a singular J#, a value is not finite, or the sweeps do not
    settle within ``max_sweeps``.
    """
    t, S, _ = chebyshev_operators(DEGREE)
    nn, p, L = t.size, x0.shape[-1], len(y)
    forward = inverse.kinematics.forward
    X = np.broadcast_to(x0, (L, nn, p)).copy()
    for _ in range(max_sweeps):
        starts = np.concatenate([x0[None], X[:-1, -1]])  # (L, p)
        e0 = forward(starts) - y
        v, bad = inverse.apply_masked(X.reshape(L * nn, p), np.repeat(e0, nn, axis=0))
        if bad.any():
            return None
        Xn = starts[:, None, :] - 0.5 * (S @ v.reshape(L, nn, p))  # segment [0, 1]: half = 0.5
        change = np.abs(Xn - X)
        change /= np.abs(Xn) + 1.0
        X = Xn
        if not change.max() >= SWEEP_TOL:  # (NaN: not settled)
            return ((t + 1.0) / 2.0, X) if np.all(np.isfinite(X)) else None
    return None
