"""The compiled kernel of one wake step on the rotor cells
(docs/performance.md#the-compiled-kernel).

:func:`integrate_wake` does, for every rotor a wake reaches and every sub-point row of it that
the wake reaches (plugin/rotor/rotor.py chooses them), in one pass over the row's sub-points: the
deficit of Eq. (du_model) (wake/fused.py ``point_deficit``, the per-height factors of
``curl_polynomial`` once per row), its superposition on the wakes so far by FLORIS's rule and
the moment it removes (plugin/rotor/rotor_wakes.py ``superposed``, ``removed_moment``), the sums over
the rotor cells and the wake's overlap as the area of the disk (FLORIS's count, or the part
inside the wake radius). The rotors are shared among threads
(plugin/rotor/rotor_threads.py); each rotor's sums run in the same order on any thread, so the
results are the same bit for bit with 1 or N threads. Compiled once per installation
(``cache=True``, wake/fused.py ``JIT``). With the cumulative wake, :func:`cumulative_step` runs
the step's upstream sums (plugin/rotor/upstream_wakes.py) and the kernel in one hand-over to
the threads, leaving out the rotors the rotor's bound of the centre puts out of reach
(docs/performance.md#the-cumulative-default).
"""

from __future__ import annotations

import inspect

import numba
import numpy as np

from floris_ekman_veer.plugin.rotor.rotor_threads import in_share, split_over_threads
from floris_ekman_veer.plugin.rotor.rotor_wakes import removed_moment, superposed
from floris_ekman_veer.plugin.rotor.upstream_wakes import centres_and_deficits
from floris_ekman_veer.wake.deficit import CURL_ALPHA
from floris_ekman_veer.wake.fused import (
    GAUSSIAN_SHAPE,
    JIT,
    WAKE_TABLE,
    centre_offset,
    centre_offset_bound,
    curl_polynomial,
    grown_centre_offset,
    image_factor,
    point_exponent,
    rotor_centre_offset_bound,
    shaped_deficit,
    time_growth,
)

#: The kernel's tables. Per wake and rotor within reach: the velocity model's (its ``wake_table``,
#: wake/fused.py WAKE_TABLE, of which the kernel reads the first seven: C(x), k_w x,
#: 0.4 R sqrt(A*) |cos beta|, sin^2 beta, t_hat's prefactor (0: no curl), 1 if the polar angle
#: is measured from the yaw-only centre, the radial shape exponent) and the solver's
#: (PAIR_COLUMNS). Per condition (turbine i's, CONDITION_COLUMNS): the solver's and the
#: deflection model's (its ``kernel_table``: the centre's t_hat prefactor, R sqrt(A*), the image
#: vortex's hub height, the veer and ground-image switches).
WAKE_COLUMNS = WAKE_TABLE[:7]
PAIR_COLUMNS = ("x", "offset", "radius_j", "moment", "reach_squared", "overlap_edge",
                "velocity_scale")
CENTRE_COLUMNS = ("strength", "r_tube", "image_height", "veer", "ground_image")
CONDITION_COLUMNS = ("cos", "sin", "friction_velocity", "radius", "hub_height",
                     *(f"centre_{k}" for k in CENTRE_COLUMNS))

@numba.njit(**JIT)
def _rotor_rows(per_condition, kind_u, kind_v, kind_heights, split_row, split_height, split_u,
                split_v, slowest, image, drift_ratio):
    # Per condition and kind of rotor: the slowest U(z) > 0 over the row slots (the strip a
    # layer top cuts as its two parts, plugin/rotor/strip_split.py) and the largest
    # image factor, for rotor_centre_offset_bound (inf and 0 where no row flows), and per row
    # slot V/U of the veer's drift x V/U (NaN where U <= 0: no flow).
    rows = kind_u.shape[2]
    for f in range(kind_u.shape[0]):
        (cos_a, sin_a, _, _, _, _, r_tube, image_height, _, ground_image) = per_condition[f]
        for kk in range(kind_u.shape[1]):
            lowest, factor = np.inf, 0.0
            cut = split_row[f, kk] if split_row.shape[0] > 0 else -1
            for r in range(rows + 1 if cut >= 0 else rows):
                if r == rows or r == cut:  # (the parts above and below the layer top)
                    part = 1 if r == rows else 0
                    z, u, v = split_height[f, kk, part], split_u[f, kk, part], split_v[f, kk, part]
                else:
                    z, u, v = kind_heights[kk, r], kind_u[f, kk, r], kind_v[f, kk, r]
                local_u = u * cos_a + v * sin_a
                if local_u > 0.0:
                    lowest = min(lowest, local_u)
                    drift_ratio[f, kk, r] = (v * cos_a - u * sin_a) / local_u
                else:
                    drift_ratio[f, kk, r] = np.nan
                if ground_image:
                    factor = max(factor, image_factor(z, image_height, r_tube))
            slowest[f, kk], image[f, kk] = lowest, factor


@numba.njit(inline="always", **JIT)
def _beyond_rotor_bound(ratio, veer, x, offset, rotor_bound, half_chord, dz, reach_squared):
    """Whether a row slot lies out of a wake's reach whatever its exact centre, by the rotor's
    bound of the centre (wake/fused.py ``rotor_centre_offset_bound``) beside the veer's drift
    x (V/U) at the slot (``ratio`` V/U; NaN where no flow: never), the drift's rounding
    otherwise than x V / U covered by a billionth of it; ``half_chord`` the slot's half-width
    on the rotor [m], ``dz`` its height above the wake's centre [m]."""
    if not ratio == ratio:
        return False
    drift = veer * (x * ratio)
    nearest = max(abs(offset - drift) - 1e-9 * abs(drift) - rotor_bound - half_chord, 0.0)
    # (NaN, from an overflow, skips nothing)
    return nearest * nearest + dz * dz >= reach_squared


@numba.njit(nogil=True, **JIT)
def _may_reach(pair, per_condition, condition, kind, kind_heights, split_row, split_height,
               row_chord, slowest, image, drift_ratio, may_reach, rotor_bound, first, stride):
    # Per pair of the share: the rotor's bound of the centre and whether a row slot lies within
    # the wake's reach by it, as the kernel tests its slots before the rows' own bounds
    # (``_integrate``).
    split = split_row.shape[0] > 0
    rows = row_chord.size
    for k in range(pair.shape[0]):
        if not in_share(k, first, stride):
            continue
        x, offset, radius_j, _, reach_squared, _, _ = pair[k]
        f, kk = condition[k], kind[k]
        (_, _, u_star, radius, hub_height, strength_c, r_tube, _, veer, _) = per_condition[f]
        rotor_bound[k] = rotor_centre_offset_bound(x, slowest[f, kk], strength_c, r_tube, radius,
                                                   u_star, image[f, kk])
        cut = split_row[f, kk] if split else -1
        may_reach[k] = False
        for r in range(rows + 1 if cut >= 0 else rows):
            # (the slots as the kernel takes them: the extra slot is the cut strip's part
            # above the layer top, the strip's row its part below)
            g = cut if r == rows else r
            height = (kind_heights[kk, r] if r != cut and r != rows
                      else split_height[f, kk, 1 if r == rows else 0])
            if not _beyond_rotor_bound(drift_ratio[f, kk, r], veer, x, offset, rotor_bound[k],
                                       radius_j * row_chord[g], height - hub_height,
                                       reach_squared):
                may_reach[k] = True
                break


@numba.njit(nogil=True, **JIT)
def _integrate(wake, pair, per_condition, compute_centre, every_row, centre, condition, kind,
               kind_u, kind_v, kind_heights, split_row, split_height, split_u, split_v,
               split_fraction, row_chord, sub_y, weight, cell, width, rule, combined, block,
               track, row_scale, slowest, image, drift_ratio, may_reach, rotor_bounds, removed,
               overlap, reached, first, stride):
    per_row = row_scale.shape[0] > 0
    # (the rotors' bounds of the centre and the rotors they leave in reach given: empty, none)
    given = may_reach.shape[0] > 0
    split = split_row.shape[0] > 0
    rows = row_chord.size
    exponents = np.empty(sub_y.shape[1])
    for k in range(wake.shape[0]):
        if not in_share(k, first, stride) or (given and not may_reach[k]):
            continue
        amplitude, kx, xi0, sin2b = wake[k, 0], wake[k, 1], wake[k, 2], wake[k, 3]
        strength, polar_veer, shape = wake[k, 4], wake[k, 5], wake[k, 6]
        x, offset, radius_j, moment, reach_squared, overlap_edge, scale = pair[k]
        f, kk = condition[k], kind[k]
        (cos_a, sin_a, u_star, radius, hub_height, strength_c, r_tube, image_height, veer,
         ground_image) = per_condition[f]
        reach = 4.0 * radius
        area = 0.0
        # The strip the layer top cuts on this rotor (-1: none): its part above the top is
        # integrated in the extra row slot ``rows`` at the strip's sub-points.
        cut = split_row[f, kk] if split else -1
        slots = rows + 1 if cut >= 0 else rows
        # A bound of the centre's rows' bounds (wake/fused.py rotor_centre_offset_bound): most
        # rows are out of reach by it, with the drift x (V/U) (rounded otherwise than x V / U:
        # a billionth of it is added to the bound), before the row's own bound, which skips
        # them too (a subset of its rows: the same bits).
        rotor_bound = 0.0
        rotor_skip = compute_centre and not every_row
        if rotor_skip:
            rotor_bound = (rotor_bounds[k] if given else rotor_centre_offset_bound(
                x, slowest[f, kk], strength_c, r_tube, radius, u_star, image[f, kk]))
        # Rows whose centre the cheap bound put out of reach: their exact centre is evaluated
        # only if the rotor is reached (the first and last rows', for the resolution check of
        # plugin/rotor/rotor.py), or at every row where the caller reads them all
        # (``every_row``: the bound is not used).
        skipped_first = skipped_last = False
        for r in range(slots):
            # Slot r: a whole strip, or a part of the strip the layer top cuts (0 below the top,
            # in the strip's row; 1 above it, in the extra slot), at the strip's sub-points g.
            # (Written out here: an inlined helper returning the row's tuple cost the kernel
            # 2.5 x its time, measured.)
            g = r
            part = -1
            if r == rows:
                part, g = 1, cut
            elif r == cut:
                part = 0
            if part < 0:
                height, u, v = kind_heights[kk, r], kind_u[f, kk, r], kind_v[f, kk, r]
            else:
                height = split_height[f, kk, part]
                u, v = split_u[f, kk, part], split_v[f, kk, part]
            dz = height - hub_height
            if rotor_skip and _beyond_rotor_bound(drift_ratio[f, kk, r], veer, x, offset,
                                                  rotor_bound, radius_j * row_chord[g], dz,
                                                  reach_squared):
                skipped_first |= r == 0
                skipped_last |= r == rows - 1
                continue
            local_u = u * cos_a + v * sin_a
            local_v = v * cos_a - u * sin_a
            # No flow (at and below z0): no wake, no t_hat.
            flowing = local_u > 0.0
            speed = local_u if flowing else 1.0
            growth = 0.0
            if compute_centre:
                if flowing:
                    # Out of reach whatever the exact centre (wake/fused.py centre_offset_bound):
                    # the row is skipped without the exponential.
                    drift, bound = centre_offset_bound(
                        x, height, local_u, local_v, strength_c, r_tube,
                        image_height, radius, u_star, veer, ground_image)
                    nearest = max(abs(offset - drift) - bound - radius_j * row_chord[g], 0.0)
                    if not (every_row or nearest * nearest + dz * dz < reach_squared):
                        skipped_first |= r == 0
                        skipped_last |= r == rows - 1
                        continue
                    growth = time_growth(x, speed, radius, u_star)
                    centre[k, r] = grown_centre_offset(
                        growth, x, height, local_u, local_v, strength_c, r_tube,
                        image_height, veer, ground_image)
                else:
                    centre[k, r] = 0.0
            lateral = offset - centre[k, r]
            # Only the rows the wake reaches are integrated (plugin/rotor/rotor.py
            # NEGLIGIBLE_DEFICIT): the row's nearest point within reach.
            gap = max(abs(lateral) - radius_j * row_chord[g], 0.0) ** 2 + dz * dz
            if not gap < reach_squared:
                continue
            reached[k] = True
            ambient_u = u if flowing else 0.0
            if not (compute_centre and flowing):
                growth = time_growth(x, speed, radius, u_star)
            q0, q1, q2, q3, q4 = curl_polynomial(strength * growth, CURL_ALPHA)
            # The yaw-only centre lies y_c,veer = x V / U (Eq. yc_veer) beside the full one.
            polar_shift = polar_veer * (x * (local_v if flowing else 0.0) / speed)
            index = block[k] + r
            # A part of a cut strip weighs its share of the strip's area.
            fraction = split_fraction[f, kk, part] if part >= 0 else 1.0
            # The row's exponents first, then its deficits, then the superposition in the
            # sub-points' order: short loops the compiler vectorises (wake/fused.py
            # point_exponent) or pipelines.
            for s in range(width[g]):
                dy = lateral + radius_j * sub_y[g, s]
                exponents[s] = point_exponent(dy, dz, dy + polar_shift, kx, xi0, sin2b,
                                              q0, q1, q2, q3, q4)
            if shape == GAUSSIAN_SHAPE:  # (the branch out of the loop)
                for s in range(width[g]):
                    exponents[s] = shaped_deficit(exponents[s], amplitude, GAUSSIAN_SHAPE)
            else:
                for s in range(width[g]):
                    exponents[s] = shaped_deficit(exponents[s], amplitude, shape)
            # The cumulative wake's amplitude at the row's height (plugin/rotor/rotor.py).
            row_amplitude = scale * row_scale[k, r] if per_row else scale
            for s in range(width[g]):
                dy = lateral + radius_j * sub_y[g, s]
                du = exponents[s] * row_amplitude
                old = np.float64(combined[index, s]) if rule else 0.0
                new = superposed(rule, old, du)
                w = weight[g, s] * fraction  # (x 1.0 for a whole strip: the same bits)
                removed[k, cell[g, s]] += removed_moment(w, ambient_u, old, new, moment)
                if rule:
                    combined[index, s] = new
                # The overlap: wake velocity above ``overlap_edge`` (FLORIS's 0.05 m/s, or the
                # wake's velocity at its radius 2 sigma: plugin/rotor/rotor.py) within 2 D of
                # the wake's rotor laterally, as the area of the disk where it holds.
                if track and du > overlap_edge and abs(dy + centre[k, r]) < reach:
                    area += w
        overlap[k] = area
        if reached[k] and (skipped_first or skipped_last):
            for r in (0, rows - 1):
                if (r == 0 and skipped_first) or (r > 0 and skipped_last):
                    height, u, v = kind_heights[kk, r], kind_u[f, kk, r], kind_v[f, kk, r]
                    if r == cut:  # (the part below the top)
                        height = split_height[f, kk, 0]
                        u, v = split_u[f, kk, 0], split_v[f, kk, 0]
                    centre[k, r] = centre_offset(x, height, u * cos_a + v * sin_a,
                                                 v * cos_a - u * sin_a, strength_c, r_tube,
                                                 image_height, radius, u_star, veer,
                                                 ground_image)


@numba.njit(**JIT)
def _near_pairs(f, j, x, table, width_column, amplitude_column, centre_column, negligible,
                points, rotor_y, rotor_z, rotor_radius, rotor_moment, y_i, hub_height,
                overlap_edge, edge_factor, hub_speed, speed_fraction, keep, pair):
    count = 0
    for p in range(f.size):
        fp, jp = f[p], j[p]
        width, amplitude = table[p, width_column], table[p, amplitude_column]
        reach_squared = 2.0 * width**2 * np.log(max(amplitude, negligible) / negligible)
        offset = rotor_y[fp, jp] - y_i[fp]
        radius_j = rotor_radius[fp, jp]
        if points.shape[2] > 0:
            top = bottom = points[fp, jp, 0]
            for h in range(1, points.shape[2]):
                top = max(top, points[fp, jp, h])
                bottom = min(bottom, points[fp, jp, h])
            margin = top - bottom + 0.25 * radius_j
            lateral_gap = max(max(offset - top, bottom - offset) - margin - radius_j, 0.0)
            vertical_gap = max(abs(rotor_z[fp, jp] - hub_height[fp]) - radius_j, 0.0)
            if not lateral_gap**2 + vertical_gap**2 < reach_squared:
                continue
        keep[count] = p
        edge = overlap_edge
        if edge_factor > 0.0:
            edge = edge_factor * table[p, centre_column] * hub_speed[fp] * speed_fraction[fp]
        pair[count, 0] = x[p]
        pair[count, 1] = offset
        pair[count, 2] = radius_j
        pair[count, 3] = rotor_moment[fp, jp]
        pair[count, 4] = reach_squared
        pair[count, 5] = edge
        pair[count, 6] = hub_speed[fp] * speed_fraction[fp]
        count += 1
    return count


def near_pairs(f, j, x, table, points, rotor, y_i, hub_height, negligible, overlap_edge,
               edge_factor, hub_speed, speed_fraction):
    """The rotors (f, j) downstream of a wake that it can reach, and the kernel's PAIR_COLUMNS
    table of them, in one pass (plugin/rotor/rotor.py ``rotor_cell_deficit`` says why each
    is dropped): each rotor's reach^2 = 2 sigma_max^2 ln(C / ``negligible``) from the velocity
    model's ``table`` (WAKE_TABLE) and, with the wake's centre at the grid's point heights
    ``points`` (pairs' (n_findex, n_turbines, n), or n = 0: no culling), the rotors beyond it
    dropped. The overlap edge is ``overlap_edge``, or with ``edge_factor`` > 0 that times the
    wake's centre deficit, U_h and the incoming fraction (per condition). Returns the kept
    indices into the pairs and their table."""
    keep = np.empty(f.size, dtype=np.int64)
    pair = np.empty((f.size, len(PAIR_COLUMNS)))
    # (contiguous index arrays: one compiled signature)
    count = _near_pairs(
        np.ascontiguousarray(f), np.ascontiguousarray(j), x, table, WAKE_TABLE.index("width_bound"), WAKE_TABLE.index("amplitude_bound"),
        WAKE_TABLE.index("centre_deficit"), float(negligible), points, rotor.y, rotor.z,
        rotor.radius, rotor.moment, y_i, hub_height, float(overlap_edge), float(edge_factor),
        hub_speed, speed_fraction, keep, pair)
    return keep[:count], pair[:count]


#: No rotor left out by the rotor's bound (the kernel evaluates the bound itself).
_NO_REACH = (np.zeros(0, dtype=np.bool_), np.zeros(0))


def _split_arrays(rotor, split):
    """The layer top's cut strip per condition and kind (plugin/rotor/strip_split.py) as the
    compiled passes take them: its row, the parts' heights, U, V and area fractions; empty
    without a split."""
    if split:
        parts = rotor.split
        return parts.row, parts.height, parts.u, parts.v, parts.fraction
    return np.zeros((0, 0), dtype=np.int64), *(np.zeros((0, 0, 0)),) * 4


def rotor_row_bounds(per_condition, rotor, slots, split):
    """Per condition and kind of rotor (the wake's step): the slowest U(z) > 0 over the row
    slots, the largest ground-image factor and V/U per slot, for the rotor's bound of the centre
    (``rotor_centre_offset_bound``, the kernel's and ``_may_reach``'s)."""
    slowest, image = np.empty(rotor.kind_u.shape[:2]), np.empty(rotor.kind_u.shape[:2])
    drift_ratio = np.empty((*rotor.kind_u.shape[:2], slots))
    _rotor_rows(np.ascontiguousarray(per_condition), rotor.kind_u, rotor.kind_v,
                rotor.kind_heights, *_split_arrays(rotor, split)[:4], slowest, image,
                drift_ratio)
    return slowest, image, drift_ratio


def integrate_wake(wake, pair, per_condition, centre, flat, kind, rotor, wakes, track,
                   every_row=False, split=False):
    """One wake superposed on the rotor rows it reaches. Returns (pairs, n^2) the moment removed
    in each cell, sum_{s in k} w_s (u_before^m - u_after^m), (pairs,) the overlap (the area
    fraction of the disk where the wake's velocity exceeds the pair's ``overlap_edge``; 0
    unless ``track``), (pairs,) whether
    the wake reached a row of the rotor, and (pairs, rows + 1) the wake's centre at the row
    slots (``RotorCells.slots``).

    ``wake`` (pairs, WAKE_TABLE) and ``pair`` (pairs, PAIR_COLUMNS): the tables, one row per
    rotor within reach; ``per_condition`` (n_findex, CONDITION_COLUMNS); ``centre`` (pairs,
    rows + 1) the wake's centre at the row slots, or None: the kernel evaluates it from the
    centre's columns of ``per_condition`` (the ekman_veer deflection); ``flat`` (pairs,) each
    rotor's flat index (condition * n_turbines + turbine),
    ``kind`` its kind (plugin/inflow/ambient.py ``RotorAmbient``); ``wakes`` the solve's
    :class:`~floris_ekman_veer.plugin.rotor.rotor_wakes.RotorWakes`, whose stored combination is
    updated in place. The centre the kernel evaluates is exact at every row of the rotors
    reached with ``every_row``; without, at their first and last rows and those it reaches (0
    at the rows a bound of the centre put out of reach). ``split``: the strip a layer top cuts
    is integrated as its two parts (``rotor.split``, plugin/rotor/strip_split.py; ``centre``
    then holds the parts at the cut strip's row and the extra slot); else the shared strips.
    The cumulative wake scales the rows by C_n at their heights: :func:`cumulative_step`.
    """
    arguments, outputs = _kernel_arguments(wake, pair, per_condition, centre, flat, kind, rotor,
                                           wakes, track, every_row, None, split)
    split_over_threads(_integrate, flat.size, *arguments)
    return outputs


def _kernel_arguments(wake, pair, per_condition, centre, flat, kind, rotor, wakes, track,
                      every_row, row_scale, split, bounds=None, reach=_NO_REACH):
    """The kernel's arguments (but the share's) and its outputs (:func:`integrate_wake`);
    ``row_scale`` (pairs, row slots) or None: a factor of the pair's ``velocity_scale`` per row
    slot (the cumulative wake's C_n at the row's height); ``bounds`` the step's :func:`rotor_row_bounds` where the caller has them; ``reach`` the
    rotors the rotor's bound leaves in reach and that bound, (pairs,) each, from
    ``_may_reach`` (empty: the kernel evaluates the bound; else the rotors left out are not
    visited: the same results)."""
    cells = wakes.cells
    n_pairs = flat.size
    removed = np.zeros((n_pairs, cells.n**2))
    overlap = np.zeros(n_pairs)
    reached = np.zeros(n_pairs, dtype=bool)
    compute_centre = centre is None
    centre = np.zeros((n_pairs, cells.slots)) if compute_centre else np.ascontiguousarray(centre)
    per_condition = np.ascontiguousarray(per_condition)
    split_arrays = _split_arrays(rotor, split)
    if bounds is None and compute_centre and not every_row:
        bounds = rotor_row_bounds(per_condition, rotor, cells.slots, split)
    elif bounds is None:  # (not read)
        bounds = (np.empty(rotor.kind_u.shape[:2]), np.empty(rotor.kind_u.shape[:2]),
                  np.empty((*rotor.kind_u.shape[:2], cells.slots)))
    slowest, image, drift_ratio = bounds
    arguments = (
        np.ascontiguousarray(wake), np.ascontiguousarray(pair), per_condition, compute_centre,
        bool(every_row), centre, flat // rotor.x.shape[1], kind, rotor.kind_u, rotor.kind_v,
        rotor.kind_heights, *split_arrays, cells.row_chord, cells.sub_y, cells.weight,
        cells.cell_grid, cells.row_width, wakes.rule_code, wakes.combined, flat * cells.slots,
        bool(track), np.zeros((0, 0)) if row_scale is None else np.ascontiguousarray(row_scale),
        slowest, image, drift_ratio, *reach, removed, overlap, reached)
    return arguments, (removed, overlap, reached, centre)


@numba.njit(inline="always", **JIT)
def _row_mean(values, rows):
    """The mean of ``values[:rows]`` summed as numpy sums a row (its pairwise sum: below 8 values
    in turn, else eight running sums combined pairwise, then the rest in turn), so that it is
    ``values[:rows].mean()``'s bits (rows <= 128)."""
    if rows < 8:
        total = 0.0
        for r in range(rows):
            total += values[r]
        return total / rows
    s0, s1, s2, s3 = values[0], values[1], values[2], values[3]
    s4, s5, s6, s7 = values[4], values[5], values[6], values[7]
    r = 8
    while r < rows - rows % 8:
        s0 += values[r]
        s1 += values[r + 1]
        s2 += values[r + 2]
        s3 += values[r + 3]
        s4 += values[r + 4]
        s5 += values[r + 5]
        s6 += values[r + 6]
        s7 += values[r + 7]
        r += 8
    total = ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7))
    while r < rows:
        total += values[r]
        r += 1
    return total / rows


@numba.njit(nogil=True, **JIT)
def _cumulative_step(bounds, sums, edge_column, edge_factor, kernel, first, stride):
    # One wake step with the cumulative wake on one share of its rotors, in one hand-over to
    # the threads: the rotors the rotor's bound leaves in reach (``bounds``, ``_may_reach``'s
    # arguments; none with its mask empty), the centres at the K heights and the upstream sums
    # (``sums``, upstream_wakes.centres_and_deficits), the overlap edge from C_n at the rows
    # (``edge_column`` of the kernel's pair table, -1: none), the kernel (``kernel``). Each
    # rotor's work reads what its own share wrote before.
    (pair, _, _, _, _, _, _, row_chord, _, _, _, may_reach, _) = bounds
    if may_reach.size:
        _may_reach(*bounds, first, stride)
    centres_and_deficits(*sums, first, stride)
    if edge_column >= 0:
        row_deficit = sums[-1]
        for k in range(pair.shape[0]):
            if in_share(k, first, stride):
                pair[k, edge_column] = edge_factor * _row_mean(row_deficit[k], row_chord.size)
    _integrate(*kernel, first, stride)


# The compiled passes' arguments by name (but the share's), for the step's one hand-over.
_KERNEL = list(inspect.signature(_integrate.py_func).parameters)[:-2]
_BOUNDS = list(inspect.signature(_may_reach.py_func).parameters)[:-2]
_SUMS = list(inspect.signature(centres_and_deficits.py_func).parameters)[:-2]


def cumulative_step(wake, pair, per_condition, centre, flat, kind, rotor, wakes, track,
                    every_row, split, sums, edge_factor=None, leave_out=True):
    """:func:`integrate_wake` after the cumulative wake's upstream sums, in one hand-over to the
    threads (a wake step's other passes need none of the rows' results): ``sums`` the sums'
    pass (``UpstreamWakes.sum_arguments``: its arguments and outputs, C_n at the heights and
    at the row slots, which scale the kernel's rows); with ``edge_factor``, the pair's overlap
    edge that factor times the mean of C_n over the rows (the wake-radius overlap, per rotor:
    plugin/rotor/rotor.py). With the ekman_veer deflection's centre (``centre`` None) and not
    ``every_row``, the rotors the rotor's bound of the centre puts wholly out of reach (the
    kernel's own first test; ``leave_out``) are left out of the sums and the kernel: C_n 0 there
    and the same results elsewhere. Returns the sums' outputs, :func:`integrate_wake`'s, and the
    rotors left in (None: all)."""
    cells = wakes.cells
    (sum_arguments, (deficit, row_deficit)) = sums
    bounds = None
    reach = _NO_REACH
    if leave_out and centre is None and not every_row:
        bounds = rotor_row_bounds(per_condition, rotor, cells.slots, split)
        reach = (np.empty(flat.size, dtype=np.bool_), np.empty(flat.size))
        # (the sums read the mask the share's bounds wrote: their ``reach`` argument)
        at = _SUMS.index("reach")
        sum_arguments = (*sum_arguments[:at], reach[0], *sum_arguments[at + 1:])
    kernel, outputs = _kernel_arguments(wake, pair, per_condition, centre, flat, kind, rotor,
                                        wakes, track, every_row, row_scale=row_deficit,
                                        split=split, bounds=bounds, reach=reach)
    named = dict(zip(_KERNEL, kernel))
    bound_arguments = tuple(named[name] for name in _BOUNDS[:-2]) + reach
    split_over_threads(
        _cumulative_step, flat.size, bound_arguments, sum_arguments,
        -1 if edge_factor is None else PAIR_COLUMNS.index("overlap_edge"),
        0.0 if edge_factor is None else float(edge_factor), kernel)
    return (deficit, row_deficit), outputs, (None if bounds is None else reach[0])
