"""The bracketed secant root finder of the atmosphere's solves (the geostrophic drag law's u*,
docs/atmosphere.md#stability-closures, and the reference-wind solve,
docs/atmosphere.md#reference-wind-solve): element-wise roots over whole arrays of conditions."""

from __future__ import annotations

import numpy as np

_SOLVER_TOLERANCE = 1e-14
_SOLVER_MAX_ITERATIONS = 200


def secant_root(residual, lo, hi, tolerance=_SOLVER_TOLERANCE):
    """Element-wise roots of a smooth increasing residual over full arrays: the bracket
    [lo, hi] is widened (doubling) until it holds the sign change, then secant steps are
    taken, replaced by bisection whenever they leave the bracket. -inf in the residual marks
    points known to lie below the root. Returns (x, converged).

    Used for the GDL's u*, which a good start puts within ~0.1 % of the root, so a handful of
    whole-array steps beat a general method's per-element bookkeeping.
    """
    r_lo, r_hi = residual(lo), residual(hi)
    for _ in range(40):
        walk_lo, walk_hi = r_lo >= 0, r_hi < 0
        if not np.any(walk_lo | walk_hi):
            break
        width = hi - lo
        lo, hi = np.where(walk_lo, lo - width, lo), np.where(walk_hi, hi + width, hi)
        r_lo, r_hi = residual(lo), residual(hi)
    bracketed = (r_lo < 0) & (r_hi >= 0)
    x_prev, r_prev, x, r = lo, r_lo, hi, r_hi
    for _ in range(_SOLVER_MAX_ITERATIONS):
        # Converged elements are frozen, so that each element's root does not depend on the
        # others solved with it (a chunk of conditions gives the numbers of the whole set).
        active = bracketed & (np.abs(r) > tolerance)
        if not np.any(active):
            break
        with np.errstate(divide="ignore", invalid="ignore"):
            secant = x - r * (x - x_prev) / (r - r_prev)
        inside = np.isfinite(secant) & (secant > lo) & (secant < hi)
        x_prev, r_prev = np.where(active, x, x_prev), np.where(active, r, r_prev)
        x = np.where(active, np.where(inside, secant, 0.5 * (lo + hi)), x)
        r = residual(x)
        below = active & (r < 0)
        lo, hi = np.where(below, x, lo), np.where(active & ~below, x, hi)
    return x, bracketed & (np.abs(r) <= tolerance)
