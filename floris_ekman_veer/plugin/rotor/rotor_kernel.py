"""The compiled kernel of one wake step on the rotor cells
(docs/performance.md#the-compiled-kernel).

:func:`integrate_wake` does, for every rotor a wake reaches and every sub-point row of it that
the wake reaches (plugin/rotor/rotor.py chooses them), in one pass over the row's sub-points: the
deficit of Eq. (du_model) (wake/fused.py ``point_deficit``, the per-height factors of
``curl_polynomial`` once per row), its superposition on the wakes so far by FLORIS's rule and
the moment it removes (plugin/rotor/rotor_wakes.py ``superposed``, ``removed_moment``), the sums over
the rotor cells and the wake's overlap as the area of the disk (FLORIS's count, or the part
inside the wake radius). The rotors run in parallel
(numba's ``prange``, on numba's threads: NUMBA_NUM_THREADS, all cores by default); each rotor's
sums run in the same order on any thread, so the results are the same bit for bit with 1 or N
threads. Compiled once per installation (``cache=True``, wake/fused.py ``JIT``).
"""

from __future__ import annotations

import os
import threading

import numba
import numpy as np

from floris_ekman_veer.plugin.rotor.rotor_wakes import removed_moment, superposed
from floris_ekman_veer.wake.deficit import CURL_ALPHA
from floris_ekman_veer.wake.fused import JIT, centre_offset, curl_polynomial, point_deficit

#: The per-wake columns of the kernel's tables, one row per (wake, rotor within reach): the
#: velocity model's (``kernel_table``: C(x), k_w x, 0.4 R sqrt(A*) |cos beta|, sin^2 beta, t_hat's
#: prefactor (0: no curl), 1 if the polar angle is measured from the yaw-only centre, the
#: radial shape exponent), the deflection model's (its ``kernel_table``: the centre's t_hat
#: prefactor, R sqrt(A*), the image vortex's hub height, the veer and ground-image switches)
#: and the solver's.
WAKE_COLUMNS = ("amplitude", "kx", "xi0", "sin2b", "strength", "polar_veer", "shape")
CENTRE_COLUMNS = ("strength", "r_tube", "image_height", "veer", "ground_image")
PAIR_COLUMNS = ("x", "velocity_scale", "cos", "sin", "friction_velocity", "radius",
                "offset", "radius_j", "hub_height", "moment", "reach_squared", "overlap_edge")

#: numba's threading layer where the user has not chosen one: one that survives a fork
#: (FLORIS's ParFlorisModel forks workers; GNU OpenMP's pool does not survive it).
if "NUMBA_THREADING_LAYER" not in os.environ:
    numba.config.THREADING_LAYER = "forksafe"

#: One parallel kernel at a time per process: numba's fork-safe workqueue layer is not
#: thread-safe, and solves in several threads of a process (a Dask worker's) would share it.
_LAUNCH = threading.Lock()


@numba.njit(parallel=True, **JIT)
def _integrate(wake, pair, centre_table, compute_centre, centre, condition, kind, kind_u,
               kind_v, kind_heights, row_chord, sub_y, weight, cell, width, rule, combined,
               block, track, row_scale, removed, overlap, reached):
    per_row = row_scale.shape[0] > 0
    for k in numba.prange(wake.shape[0]):
        amplitude, kx, xi0, sin2b, strength, polar_veer, shape = wake[k]
        (x, scale, cos_a, sin_a, u_star, radius, offset, radius_j, hub_height, moment,
         reach_squared, overlap_edge) = pair[k]
        strength_c, r_tube, image_height, veer, ground_image = centre_table[k]
        f, kk = condition[k], kind[k]
        reach = 4.0 * radius
        area = 0.0
        for r in range(row_chord.size):
            u, v = kind_u[f, kk, r], kind_v[f, kk, r]
            local_u = u * cos_a + v * sin_a
            local_v = v * cos_a - u * sin_a
            if compute_centre:
                centre[k, r] = centre_offset(x, kind_heights[kk, r], local_u, local_v,
                                             strength_c, r_tube, image_height, radius, u_star,
                                             veer, ground_image)
            lateral = offset - centre[k, r]
            dz = kind_heights[kk, r] - hub_height
            # Only the rows the wake reaches are integrated (plugin/rotor/rotor.py
            # NEGLIGIBLE_DEFICIT): the row's nearest point within reach.
            gap = max(abs(lateral) - radius_j * row_chord[r], 0.0) ** 2 + dz * dz
            if not gap < reach_squared:
                continue
            reached[k] = True
            # No flow (at and below z0): no wake.
            flowing = local_u > 0.0
            ambient_u = u if flowing else 0.0
            speed = local_u if flowing else 1.0
            q0, q1, q2, q3, q4 = curl_polynomial(
                strength * -np.expm1(-0.35 * (u_star / speed) * x / radius), CURL_ALPHA)
            # The yaw-only centre lies y_c,veer = x V / U (Eq. yc_veer) beside the full one.
            polar_shift = polar_veer * (x * (local_v if flowing else 0.0) / speed)
            index = block[k] + r
            # The cumulative wake's amplitude at the row's height (plugin/rotor/rotor.py).
            row_amplitude = scale * row_scale[k, r] if per_row else scale
            for s in range(width[r]):
                dy = lateral + radius_j * sub_y[r, s]
                du = point_deficit(dy, dz, dy + polar_shift, amplitude, kx, xi0, sin2b,
                                   q0, q1, q2, q3, q4, shape) * row_amplitude
                old = np.float64(combined[index, s]) if rule else 0.0
                new = superposed(rule, old, du)
                removed[k, cell[r, s]] += removed_moment(weight[r, s], ambient_u, old, new,
                                                         moment)
                if rule:
                    combined[index, s] = new
                # The overlap: wake velocity above ``overlap_edge`` (FLORIS's 0.05 m/s, or the
                # wake's velocity at its radius 2 sigma: plugin/rotor/rotor.py) within 2 D of
                # the wake's rotor laterally, as the area of the disk where it holds.
                if track and du > overlap_edge and abs(dy + centre[k, r]) < reach:
                    area += weight[r, s]
        overlap[k] = area


def integrate_wake(wake, pair, centre_table, centre, flat, kind, rotor, wakes, track,
                   row_scale=None):
    """One wake superposed on the rotor rows it reaches. Returns (pairs, n^2) the moment removed
    in each cell, sum_{s in k} w_s (u_before^m - u_after^m), (pairs,) the overlap (the area
    fraction of the disk where the wake's velocity exceeds the pair's ``overlap_edge``; 0
    unless ``track``), (pairs,) whether
    the wake reached a row of the rotor, and (pairs, rows) the wake's centre at the rows.

    ``wake``, ``pair`` and ``centre_table`` (pairs, WAKE_COLUMNS, PAIR_COLUMNS, CENTRE_COLUMNS):
    the tables, one row per rotor within reach; ``centre`` (pairs, rows) the wake's centre at
    the rows, or None: the kernel evaluates it from ``centre_table`` (the ekman_veer
    deflection); ``flat`` (pairs,) each rotor's flat index (condition * n_turbines + turbine),
    ``kind`` its kind (plugin/inflow/ambient.py ``RotorAmbient``); ``wakes`` the solve's
    :class:`~floris_ekman_veer.plugin.rotor.rotor_wakes.RotorWakes`, whose stored combination is
    updated in place; ``row_scale`` (pairs, rows) or None: a factor of the pair's
    ``velocity_scale`` per row (the cumulative wake's C_n at the row's height).
    """
    cells = wakes.cells
    n_pairs = flat.size
    removed = np.zeros((n_pairs, cells.n**2))
    overlap = np.zeros(n_pairs)
    reached = np.zeros(n_pairs, dtype=bool)
    compute_centre = centre is None
    centre = np.zeros((n_pairs, cells.rows)) if compute_centre else np.ascontiguousarray(centre)
    with _LAUNCH:
        _integrate(np.ascontiguousarray(wake), np.ascontiguousarray(pair),
                   np.ascontiguousarray(centre_table), compute_centre, centre,
                   flat // rotor.x.shape[1], kind, rotor.kind_u, rotor.kind_v,
                   rotor.kind_heights, cells.row_chord, cells.sub_y, cells.weight,
                   cells.cell_grid, cells.row_width, wakes.rule_code, wakes.combined,
                   flat * cells.rows, bool(track),
                   np.zeros((0, 0)) if row_scale is None else np.ascontiguousarray(row_scale),
                   removed, overlap, reached)
    return removed, overlap, reached, centre
