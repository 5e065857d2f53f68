"""The ambient profile on FLORIS's grids: hub-aligned U(z), V(z) and dU/dz of a solved ABL.

FLORIS's wind direction is read as the direction at its reference height, so the profile is
given in the frame rotated so that V(reference_wind_height) = 0, and U(reference_wind_height)
equals FLORIS's wind speed. In the roughness sublayer (below about e z0) the profile falls
linearly to 0 at the ground (docs/atmosphere.md#roughness-sublayer), so U > 0 at every z > 0;
points below the ground get 0. dU/dz is a centred difference of the analytic profile (relative
step 1e-4: relative error about 1e-8; EkmanABL exposes no analytic gradient), 0 below the
ground. The profile is evaluated only at the distinct heights of a grid, and small height sets
are kept for the next call with the same ABL (the rotor cells are evaluated for the inflow,
plugin/rotor/rotor.py, and again for the crossflow, plugin/rotor/yawed_rotor.py).
"""

from __future__ import annotations

import threading
import weakref
from collections import OrderedDict

import numpy as np

_CACHE_LOCK = threading.Lock()


def inflow_profile(abl, z, reference_height: float):
    """Hub-aligned streamwise velocity U(z) and dU/dz at heights ``z``.

    The frame is rotated so that V(reference_height) = 0; heights below the ground give
    U = dU/dz = 0 (see :func:`ambient_velocity`). ``z`` broadcasts against the ABL's ``(n_findex, 1, 1, 1)`` shape; the result
    has the broadcast shape. The profile is evaluated only at the distinct heights of ``z`` (a
    rotor grid of 100 turbines of one hub height has 3 of them, whatever n_findex and however
    FLORIS sorted the turbines) and gathered back, which gives the same numbers as evaluating at
    every point, at a fraction of the cost.
    """
    z = np.asarray(z, dtype=float)
    n_conditions = np.shape(abl.friction_velocity)[0] if np.ndim(abl.friction_velocity) else 1
    shape = np.broadcast_shapes(np.shape(abl.friction_velocity), z.shape)
    heights, inverse, reduced_shape = _distinct_heights(z)
    if n_conditions * heights.size >= z.size:
        U, dUdz = _profile_and_gradient(abl, z, reference_height)
        return np.broadcast_to(U, shape), np.broadcast_to(dUdz, shape)
    U, dUdz = _profile_and_gradient(abl, heights.reshape(1, 1, 1, -1), reference_height)
    rows = np.arange(n_conditions).reshape(-1, 1, 1, 1)
    inverse = inverse.reshape(reduced_shape)
    U = np.broadcast_to(U, (n_conditions, 1, 1, heights.size)).reshape(n_conditions, -1)
    dUdz = np.broadcast_to(dUdz, (n_conditions, 1, 1, heights.size)).reshape(n_conditions, -1)
    return (
        np.broadcast_to(U[rows, inverse], shape),
        np.broadcast_to(dUdz[rows, inverse], shape),
    )


def _distinct_heights(z: np.ndarray):
    """Distinct values of ``z`` after dropping the axes along which it is constant.

    Returns (sorted distinct heights, inverse indices, shape of the reduced array). Dropping
    constant axes first (the condition axis, the rotor's horizontal axis: cheap comparisons)
    keeps the sort small.
    """
    reduced = z
    for axis in range(z.ndim):
        if reduced.shape[axis] > 1:
            first = reduced.take([0], axis=axis)
            if np.array_equal(np.broadcast_to(first, reduced.shape), reduced):
                reduced = first
    heights, inverse = np.unique(reduced, return_inverse=True)
    return heights, inverse, reduced.shape


#: The last few (ABL, heights, reference height) -> (U, V) of :func:`ambient_velocity` on small
#: height sets, and of :func:`ambient_rows`: a solve's rotor cells are evaluated for the inflow
#: (plugin/rotor/rotor.py) and again for the crossflow (plugin/rotor/yawed_rotor.py) at the same heights.
_AMBIENT_CACHE: OrderedDict = OrderedDict()
_AMBIENT_CACHE_SIZE = 2
_AMBIENT_CACHED_HEIGHTS = 4096
_ROWS_CACHE: OrderedDict = OrderedDict()


def _cached(cache: OrderedDict, key, abl, compute):
    """``compute()`` (a pair of arrays, made read-only) under ``key`` for ``abl``, or the pair
    kept from the last call with the same key and the same ABL instance."""
    with _CACHE_LOCK:
        entry = cache.get(key)
    if entry is not None and entry[0]() is abl:
        return entry[1], entry[2]
    U, V = compute()
    U.flags.writeable = False
    V.flags.writeable = False
    with _CACHE_LOCK:
        cache[key] = (weakref.ref(abl), U, V)
        while len(cache) > _AMBIENT_CACHE_SIZE:
            cache.popitem(last=False)
    return U, V


def ambient_velocity(abl, z, reference_height: float):
    """Hub-aligned ambient (U, V)(z) on a FLORIS grid: the profile of
    :meth:`EkmanABL.hub_aligned_velocity` at z >= 0 (with its roughness sublayer,
    docs/atmosphere.md#roughness-sublayer, so U > 0 for every z > 0), and 0 below the ground
    (z < 0, where FLORIS's power law has no value either). Results for at most
    ``_AMBIENT_CACHED_HEIGHTS`` heights are kept for the next call with the same ABL and heights
    (read-only arrays). A row of heights ``(1, 1, 1, heights)`` for many conditions is
    evaluated by :func:`ambient_rows` (the same numbers)."""
    z = np.asarray(z, dtype=float)
    n_findex = _row_conditions(abl, z)
    if n_findex:
        return tuple(np.ascontiguousarray(values.T).reshape(n_findex, 1, 1, -1)
                     for values in ambient_rows(abl, z.reshape(-1), reference_height))
    if z.size > _AMBIENT_CACHED_HEIGHTS:
        return _ambient_velocity(abl, z, reference_height)
    key = (id(abl), z.shape, z.tobytes(), float(reference_height))
    return _cached(_AMBIENT_CACHE, key, abl,
                   lambda: _ambient_velocity(abl, z, reference_height))


#: Elements of the profile's work arrays per piece: a row of heights for many conditions (the
#: rotor cells' sub-point rows) is evaluated a few heights at a time, so that its temporaries
#: stay in cache instead of touching fresh memory for every one of the profile's operations.
_PROFILE_PIECE = 1 << 16


def _row_conditions(abl, z: np.ndarray) -> int:
    """n_findex if ``z`` is a row of heights (1, 1, 1, heights) that :func:`ambient_rows`
    evaluates for an ABL of n_findex conditions (attributes (n_findex, 1, 1, 1)) in pieces,
    else 0."""
    shape = np.shape(abl.friction_velocity)
    if len(shape) != 4 or shape[1:] != (1, 1, 1) or z.ndim != 4 or z.shape[:3] != (1, 1, 1):
        return 0
    return shape[0] if shape[0] * z.shape[3] > 2 * _PROFILE_PIECE else 0


def ambient_rows(abl, heights, reference_height: float):
    """:func:`ambient_velocity` at 1-D ``heights`` for every condition of an ABL with
    attributes (n_findex, 1, 1, 1): (U, V), each (heights, n_findex), read-only, kept for the
    next call with the same ABL and heights.

    The profile is elementwise in height and condition, so any grouping gives the same bits:
    it is evaluated ``_PROFILE_PIECE // n_findex`` heights at a time (at least one), with the
    conditions innermost (numpy's loops then run along the conditions, not along a few heights,
    and the temporaries stay in cache), the rotation to the hub frame computed once.
    """
    heights = np.asarray(heights, dtype=float).reshape(-1)
    key = (id(abl), heights.tobytes(), float(reference_height))
    return _cached(_ROWS_CACHE, key, abl, lambda: _rows_velocity(abl, heights, reference_height))


def _rows_velocity(abl, heights: np.ndarray, reference_height: float):
    n_findex = int(np.size(abl.friction_velocity))
    frame = abl.hub_frame(reference_height)
    U, V = np.empty((heights.size, n_findex)), np.empty((heights.size, n_findex))
    width = max(1, _PROFILE_PIECE // n_findex)
    for k in range(0, heights.size, width):
        # (heights, 1, 1, 1, 1) against the ABL's (n_findex, 1, 1, 1): (heights, n_findex, ...)
        u, v = _ambient_velocity(abl, heights[k:k + width].reshape(-1, 1, 1, 1, 1),
                                 reference_height, frame)
        U[k:k + width], V[k:k + width] = u.reshape(-1, n_findex), v.reshape(-1, n_findex)
    return U, V


def _ambient_velocity(abl, z, reference_height: float, frame=None):
    above = z >= 0.0
    if np.all(above):
        # Arrays also for a scalar height: callers cache them read-only.
        return tuple(np.asarray(a) for a in abl.hub_aligned_velocity(z, reference_height, frame))
    U, V = abl.hub_aligned_velocity(np.where(above, z, 0.0), reference_height, frame)
    return np.where(above, U, 0.0), np.where(above, V, 0.0)


# Relative height step of the centred difference for dU/dz: truncation ~ step^2 (1e-8 relative
# for the log law), round-off ~ 1e-16 U / (step z) (1e-12 relative at hub height).
_GRADIENT_STEP = 1e-4


def _profile_and_gradient(abl, z, reference_height):
    # dU/dz of the hub-aligned U by a centred difference of the profile (the ABL class exposes
    # no analytic gradient), with step 1e-4 max(z, z0): one-sided at the ground, where the
    # roughness sublayer's U is linear in z, and 0 below it. Across the kinks at 0.2 h and h
    # the difference averages the two slopes within +-1e-4 z of the kink.
    U, _ = ambient_velocity(abl, z, reference_height)
    step = _GRADIENT_STEP * np.maximum(z, np.asarray(abl.roughness_length))
    upper_z = z + step
    lower_z = np.maximum(z - step, 0.0)
    upper, _ = ambient_velocity(abl, upper_z, reference_height)
    lower, _ = ambient_velocity(abl, lower_z, reference_height)
    dUdz = np.where(z >= 0.0, (upper - lower) / (upper_z - lower_z), 0.0)
    return U, dUdz

