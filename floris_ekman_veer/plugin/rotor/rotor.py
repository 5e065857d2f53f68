"""One turbine's wake on the rotor cells it reaches, for the velocity models' call on a turbine
grid (docs/coupling.md#rotor-average).

:func:`rotor_cell_deficit` integrates the wake over the cells of plugin/rotor/rotor_cells.py that it can
reach: the culling of the rotors and sub-point rows out of reach, the wake's centre at the rows,
the compiled kernel that superposes the wake on the others at the rows' sub-points and sums the
cells (plugin/rotor/rotor_kernel.py) and the wake-added turbulence. Pure geometry and numpy (numba in
the kernel): no FLORIS import.
"""

from __future__ import annotations

import warnings

import attrs
import numpy as np

from floris_ekman_veer.plugin.rotor.convection import removed_moments
from floris_ekman_veer.plugin.rotor.rotor_cells import (
    ROWS_PER_POINT,
    grid_offsets,
    row_interpolation,
)
from floris_ekman_veer.plugin.rotor.rotor_cells import WAKE_MODELS  # noqa: F401  (models.py's import)
from floris_ekman_veer.plugin.rotor.rotor_kernel import (
    CONDITION_COLUMNS,
    PAIR_COLUMNS,
    cumulative_step,
    integrate_wake,
    near_pairs,
)
from floris_ekman_veer.plugin.rotor.rotor_wakes import (
    WAKE_OVERLAP_VELOCITY,
    crespo_hernandez_parameters,
)
from floris_ekman_veer.plugin.rotor.rotor_wakes import RotorWakes  # noqa: F401  (models.py's import)
from floris_ekman_veer.wake.added_turbulence import (
    crespo_hernandez_overlap,
    ishihara_qian_added_turbulence,
)
from floris_ekman_veer.wake.deficit import WIDTH_FACTOR, axial_induction, stream_tube_area_ratio
from floris_ekman_veer.wake.fused import DEFERRED_ORDER, WAKE_TABLE

#: A wake starts this far [m] behind its rotor plane. FLORIS passes x_i as the mean of the rotor's
#: points (turbine grids) and rotates sampled points (points and planar grids), so a turbine's own
#: rotor points can lie a round-off (~1e-13 m) downstream of x_i, where the wake is already 2a
#: deep: without the margin a turbine sits in its own wake (tests/plugin/wake_models/test_models.py). FLORIS's gauss
#: model uses the same 0.1 m.
ROTOR_PLANE_MARGIN = 0.1

#: A sub-point row of a rotor is integrated in a wake where the deficit, with the widest width
#: the wake can have, exceeds this fraction of U_h somewhere on the row; elsewhere the wake is 0
#: (a power change of at most 3e-5 of a turbine that sees no other wake, far less where wakes
#: combine).
NEGLIGIBLE_DEFICIT = 1e-5

#: The velocity models' ``wake_expansion`` choices (plugin/wake_models/models.py): the paper's ambient k_w,
#: and the two that add the upstream wakes' turbulence at a rotor (its largest, as FLORIS
#: combines it; all of them, their variances summed), tracked here on a turbine grid.
WAKE_EXPANSIONS = ("ambient", "local_turbulence", "array_turbulence")
ADDED_TURBULENCE = {"local_turbulence": "max", "array_turbulence": "quadrature"}

#: The velocity models' ``turbulence_overlap`` choices: the part of a rotor a wake's added
#: turbulence is weighted with, the area where its velocity exceeds WAKE_OVERLAP_VELOCITY
#: (FLORIS's count) or where the rotor lies inside the wake radius 2 sigma (Niayifar &
#: Porte-Agel 2016, docs/coupling.md#wakes-deep-in-an-array).
TURBULENCE_OVERLAPS = ("wake_velocity", "wake_radius")

#: The velocity models' ``wake_turbulence`` choices: the form of a wake's added turbulence,
#: FLORIS's turbulence model (Crespo & Hernandez 1996 as FLORIS has it) weighted with the
#: overlap, or Ishihara & Qian (2018, wake/added_turbulence.py) averaged over the rotor's
#: sub-points, its radial profile being its own overlap (docs/coupling.md#wakes-deep-in-an-array).
WAKE_TURBULENCES = ("crespo_hernandez", "ishihara_qian")

#: The velocity models' ``deficit_velocity`` choices: the speed a wake's C(x) scales with.
DEFICIT_VELOCITIES = ("incoming", "free_stream")

#: A sheared band thinner than this many sub-row spacings (its Gaussian width across the band)
#: is no longer integrated to 1 % in power by the rotor cells (benchmarks/bench_rotor_average.py).
MIN_BAND_PER_ROW = 0.4


@attrs.define(frozen=True)
class TurbineWake:
    """Turbine i's quantities at the points where its wake is evaluated (the grid's points, or
    the sub-points of the rotor cells it reaches), as the velocity models take them (radians,
    metres)."""

    dx: np.ndarray
    dy: np.ndarray
    dz: np.ndarray
    yaw: np.ndarray
    ct: np.ndarray
    radius: np.ndarray
    hub_speed: np.ndarray
    k_w: np.ndarray
    local_u: np.ndarray
    local_v: np.ndarray
    friction_velocity: np.ndarray


def rotor_cell_deficit(
    model, x_i, y_i, hub_height_i, deflection_field_i, yaw, ct, radius_i,
    turbulence_intensity_i, axial_induction_i, u_initial, ambient, wakes,
):
    """:func:`reached_rotor_cell_deficit`'s d_k; the rotors the wake reached (a superset of
    those where d_k is not 0) are left in ``wakes.reached`` for the solver
    (plugin/floris_hooks/solver.py), which updates only those."""
    result, wakes.reached = reached_rotor_cell_deficit(
        model, x_i, y_i, hub_height_i, deflection_field_i, yaw, ct, radius_i,
        turbulence_intensity_i, axial_induction_i, u_initial, ambient, wakes)
    return result


def condition_column(value, n_findex) -> np.ndarray:
    """(n_findex,) of a per-condition value FLORIS hands as (n_findex, 1, 1, 1) (a view), or
    of a scalar (broadcast)."""
    if np.shape(value) == (n_findex, 1, 1, 1):
        return np.asarray(value)[:, 0, 0, 0]
    return np.broadcast_to(value, (n_findex, 1, 1, 1))[:, 0, 0, 0]


#: No rotor reached: (f, j) empty.
_NONE = (np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp))


def reached_rotor_cell_deficit(
    model, x_i, y_i, hub_height_i, deflection_field_i, yaw, ct, radius_i,
    turbulence_intensity_i, axial_induction_i, u_initial, ambient, wakes,
):
    """d_k of every rotor cell of the grid after turbine i's wake (the module docstring), for a
    velocity model's call on a turbine grid (docs/coupling.md#rotor-average), and the rotors
    (f, j) the wake reached.

    Only the sub-point rows of the rotors downstream of turbine i that its wake can reach
    (the deficit above NEGLIGIBLE_DEFICIT U_h somewhere on the row, with the widest possible
    width) are integrated; the wake is 0 elsewhere. The wake is superposed on the others at
    the sub-points (``wakes``, :class:`RotorWakes`) and each reached cell returns the
    increment FLORIS's combination turns into the combined cell deficit; the rest 0.

    ``model`` is the velocity model (plugin/wake_models/models.py): its ``expansion_rate`` (k_w),
    ``width_bound`` and ``amplitude_bound`` (how far its wake reaches), ``kernel_table`` (the
    deficit's per-wake factors for the kernel, plugin/rotor/rotor_kernel.py), ``wake_expansion`` and
    ``deficit_velocity``
    (with "incoming" the wake's velocity is scaled by turbine i's U_i / U_i,0 of the wakes
    superposed so far, docs/coupling.md#wakes-deep-in-an-array). ``ambient`` is the grid's
    :class:`~floris_ekman_veer.plugin.inflow.ambient.Ambient` with its ``rotor``, ``wakes`` the solve's
    :class:`RotorWakes`; yaw in radians, ct the model's thrust coefficient.
    """
    rotor = ambient.rotor
    cells = rotor.cells
    n_findex, n_turbines = rotor.x.shape
    result = np.zeros((n_findex, n_turbines, cells.n**2))
    dx = rotor.x - x_i[:, 0, 0]
    f, j = np.nonzero(dx > ROTOR_PLANE_MARGIN)
    if f.size == 0:
        return result.reshape(u_initial.shape), _NONE
    abl = ambient.abl
    hub_speed, cos_a, sin_a = ambient.hub_frame(hub_height_i)
    added_rule = ADDED_TURBULENCE.get(model.wake_expansion)
    track = (added_rule is not None and wakes.rule is not None
             and wakes.turbulence_model is not None)
    cumulative = wakes.superposition == "cumulative"
    # The cumulative wake's thrust needs turbine i's incoming speed whatever the deficit's scale.
    incoming = ((model.deficit_velocity == "incoming" or cumulative)
                and wakes.rule is not None)
    if track or incoming:
        # Turbine i among the rotors, per condition (the solver's sorted index where it hands
        # it: the rotor at turbine i's centre).
        source = (np.full(n_findex, wakes.source) if wakes.source is not None else
                  np.argmin((rotor.x - x_i[:, 0, 0]) ** 2 + (rotor.y - y_i[:, 0, 0]) ** 2,
                            axis=1))
        if cumulative:
            # No later wake reaches turbine i (the solver steps downstream): free its kept wakes.
            wakes.convection.release(np.arange(n_findex) * n_turbines + source)
    # U_i / U_i,0 of turbine i: its wake's C(x) scales with the speed it stands in
    # (docs/coupling.md#wakes-deep-in-an-array); 1 for an unwaked rotor.
    speed_fraction = 1.0
    if incoming:
        conditions = np.arange(n_findex)
        speed_fraction = wakes.incoming_fraction(
            conditions * n_turbines + source,
            u_initial.reshape(n_findex, n_turbines, -1)[conditions, source],
        )[:, None, None, None]
    if track:
        # The turbulence at turbine i with the overlaps as areas (RotorWakes).
        turbulence = wakes.turbulence[np.arange(n_findex), source][:, None, None, None]
    else:
        # FLORIS's turbulence at turbine i may vary over its rotor points (wake-added
        # turbulence is counted per point); its wake takes one expansion rate, from the
        # rotor's mean.
        turbulence = np.mean(turbulence_intensity_i, axis=(2, 3), keepdims=True)
    k_w = model.expansion_rate(abl, hub_height_i, hub_speed, turbulence,
                              ambient.floris_turbulence)
    # Turbine i's quantities, one per condition; the wake's factors per rotor downstream.
    column = lambda a: condition_column(a, n_findex)  # noqa: E731
    source_wake = {"k_w": k_w, "radius": radius_i, "ct": ct, "yaw": yaw,
                   "friction_velocity": abl.friction_velocity, "hub_speed": hub_speed}
    source_wake = {k: column(v) for k, v in source_wake.items()}
    x_pair = dx[f, j]
    # The velocity model's table (plugin/rotor/rotor_kernel.py): the deficit's factors that
    # depend on the wake only, its width and amplitude bounds and its centre deficit.
    # (Where a near wake's order is costly, first a bound of its width: the rotors kept below
    # get their exact table.)
    table = model.wake_table(x_pair, *(v[f] for v in source_wake.values()), bound_only=True)
    centre_table = getattr(deflection_field_i, "kernel_table", None)
    # The rotors the wake reaches, with the deficit C(x) exp(-gap^2 / (2 sigma^2)) below
    # NEGLIGIBLE_DEFICIT beyond gap^2 = 2 sigma^2 ln(C / NEGLIGIBLE_DEFICIT) (sigma the widest
    # width). With the ekman_veer deflection, also those out of reach by the centre at the
    # grid's points (heights z_h, z_h +- R/2) widened by its spread plus R/4 on either side
    # (the centre at the rows beyond +-R/2, twice the linear extrapolation, and between them)
    # are not integrated and their rows not evaluated.
    points = np.zeros((1, 1, 0))
    if centre_table is not None and cells.n > 1:
        points = np.ascontiguousarray(np.asarray(deflection_field_i)[:, :, 0, :])
    speed_fraction = column(speed_fraction)
    edge_factor = 0.0
    if track and model.turbulence_overlap == "wake_radius":
        # The wake's velocity at its radius 2 sigma, exp(-2) times its centre's (Niayifar &
        # Porte-Agel 2016), per rotor reached: the overlap counts the disk inside that radius.
        edge_factor = np.exp(-2.0)
    reach = (points, rotor, column(y_i), column(hub_height_i), NEGLIGIBLE_DEFICIT,
             WAKE_OVERLAP_VELOCITY, edge_factor, source_wake["hub_speed"], speed_fraction)
    near, pair = near_pairs(f, j, x_pair, table, *reach)
    deferred = np.flatnonzero(table[near, WAKE_TABLE.index("shape")] == DEFERRED_ORDER)
    if deferred.size:
        # The exact table of the rotors the bound kept (its other rows are exact already:
        # only the deferred ones are evaluated again), and those it reaches (a subset).
        f, j, x_pair, table = f[near], j[near], x_pair[near], table[near]
        table[deferred] = model.wake_table(x_pair[deferred],
                                           *(v[f[deferred]] for v in source_wake.values()))
        near, pair = near_pairs(f, j, x_pair, table, *reach)
    if near.size == 0:
        return result.reshape(u_initial.shape), _NONE
    f, j, x_pair, table = f[near], j[near], x_pair[near], table[near]
    centre = None
    convecting = wakes.superposition == "momentum_conserving"
    # (The momentum-conserving superposition and Ishihara & Qian's turbulence read the
    # wake's centre at every row of the rotors reached.)
    ishihara_qian = track and model.wake_turbulence == "ishihara_qian"
    every_row = convecting or ishihara_qian
    # The strip a layer top cuts, integrated as its parts below and above the top
    # (plugin/rotor/strip_split.py).
    split = rotor.split.any
    if centre_table is None:
        # Another deflection model: its centre at the point rows, interpolated in height.
        # (A sum over the n points, not a matrix product: BLAS would block the product by
        # the number of pairs, i.e. by the batch.)
        centre = np.sum(deflection_field_i[f, j, 0, :, None]
                        * row_interpolation(cells.n, cells.row_z), axis=1)
        if split:
            centre = rotor.split.at_rows(deflection_field_i[f, j, 0, :], centre, f,
                                         rotor.kind[f, j], grid_offsets(cells.n))
        centre_table = {"strength": 0.0, "r_tube": 1.0, "image_height": 0.0, "veer": 0.0,
                        "ground_image": 0.0}
    else:
        centre_table = centre_table()
    flat = f * n_turbines + j
    kind = rotor.kind[f, j]
    # The solver's part of the kernel's tables per condition (turbine i's).
    per_condition = {"cos": column(cos_a), "sin": column(sin_a),
                     "friction_velocity": source_wake["friction_velocity"],
                     "radius": source_wake["radius"], "hub_height": column(hub_height_i),
                     **{f"centre_{k}": v for k, v in centre_table.items()}}
    condition_table = _columns(per_condition, CONDITION_COLUMNS, (n_findex,))
    scale, edge = PAIR_COLUMNS.index("velocity_scale"), PAIR_COLUMNS.index("overlap_edge")
    moment = pair[:, PAIR_COLUMNS.index("moment")]
    per_pair = {k: v[f] for k, v in source_wake.items()}
    per_pair.update(speed_fraction=speed_fraction[f], cos=column(cos_a)[f],
                    sin=column(sin_a)[f], offset=pair[:, PAIR_COLUMNS.index("offset")])
    if cumulative:
        # Bastankhah et al. (2021): the wake's centre deficit C_n [m/s] through the upstream
        # wakes kept at each rotor (plugin/rotor/upstream_wakes.py), evaluated where the
        # deflection's centre is (the veer-sheared centres differ with height) at the store's
        # fixed heights of the rotor, whatever n, and interpolated to the kernel's sub-point
        # rows; the kernel scales the model's shape row by row to C_n at the row's height; the
        # wakes are summed. FLORIS's other grids evaluate C_n point by point.
        single = model.centre_deficit(x_pair,
                                      *(per_pair[k] for k in ("k_w", "radius", "ct", "yaw")))
        width_squared = (table[:, WAKE_TABLE.index("kx")]
                         + table[:, WAKE_TABLE.index("xi0")]) ** 2
        offsets, centres = _centres_at_deficit_heights(
            wakes.convection.heights, rotor, f, j, kind, x_pair, deflection_field_i, centre,
            condition_table)
        lateral, height = y_i[f, 0, 0, 0], hub_height_i[f, 0, 0, 0]
        incoming_speed = per_pair["hub_speed"] * per_pair["speed_fraction"]
        # (with a split, the cut strip's parts interpolated from the heights in the same pass)
        slots = ((rotor.split.row[f, kind],
                  rotor.split.weights_from(wakes.convection.heights)[f, kind])
                 if split else (None, None))
        sums = wakes.convection.sum_arguments(
            flat, width_squared, lateral, offsets, height, single, per_pair["hub_speed"],
            incoming_speed,
            model.core_deficit(source_wake["ct"], source_wake["yaw"])[f] * incoming_speed,
            *slots, centres=centres)
        pair[:, scale] = 1.0 / np.where(single > 0.0, single, 1.0)
        # The sums and the kernel in one pass over the rotors (plugin/rotor/rotor_kernel.py);
        # only the rotors whose rows the wake may reach: the kernel reaches none of the others'
        # rows by the bound of their centre, and only the rows reached read C_n (about a
        # quarter of a step's rotors on the 10 x 10 farm). The overlap's edge: the wake's
        # velocity at its radius, exp(-2) C_n, with C_n the mean over the rows.
        (deficit, _), (removed, overlap, reached, centre), _ = cumulative_step(
            table, pair, condition_table, centre, flat, kind, rotor, wakes, track, every_row,
            split, sums, edge_factor=(np.exp(-2.0) if track and model.turbulence_overlap
                                      == "wake_radius" else None))
    if convecting:
        # Zong & Porte-Agel (2020): the sub-points sum U_c,i u_i (plugin/rotor/convection.py),
        # U_c,i = U_in,i - u_c,i / 2 with the wake's centre deficit u_c,i.
        centre_speed = model.centre_deficit(
            x_pair, *(per_pair[k] for k in ("k_w", "radius", "ct", "yaw"))
        ) * pair[:, scale]
        wake_convection = pair[:, scale] - 0.5 * centre_speed
        pair[:, scale] = pair[:, scale] * wake_convection
        pair[:, edge] = pair[:, edge] * wake_convection
    if not cumulative:
        removed, overlap, reached, centre = integrate_wake(
            table, pair, condition_table, centre, flat, kind, rotor, wakes, track,
            every_row=every_row, split=split)
    # (the centre at the row slots, for the paths that read every row; the shared rows'
    # for the resolution check: the cut strip's row holds its part below the top)
    slot_centre, centre = centre, centre[:, :cells.rows]
    reached = np.flatnonzero(reached)
    if reached.size == 0:
        return result.reshape(u_initial.shape), _NONE
    if cumulative:
        wakes.convection.keep(flat[reached], deficit[reached], width_squared[reached],
                              lateral[reached], offsets[reached], height[reached])
    if convecting:
        removed = _momentum_conserving(
            wakes, rotor, reached, flat, f, j, kind, moment, slot_centre, split, per_pair, y_i,
            hub_height_i,
            table[:, WAKE_TABLE.index("kx")] + table[:, WAKE_TABLE.index("xi0")], centre_speed,
            wake_convection)
    _check_resolution(x_pair, f, j, reached, source_wake, centre, rotor)
    # (The rotors' cells by flat index: one index array, not two.)
    rows = flat[reached]
    u_cell = u_initial.reshape(n_findex * n_turbines, -1).take(rows, axis=0)
    result.reshape(n_findex * n_turbines, -1)[rows] = wakes.cell_returns(
        rows, removed[reached], u_cell, moment[reached][:, None])
    if ishihara_qian:
        added = _ishihara_qian(x_pair[reached], per_pair, reached, slot_centre[reached],
                               split, rotor, f[reached], j[reached], kind[reached],
                               hub_height_i[f[reached], 0, 0, 0],
                               ambient.floris_turbulence, x_i.shape[0])
        wakes.add_turbulence(f[reached], j[reached], added, np.broadcast_to(
            ambient.floris_turbulence, (x_i.shape[0], 1, 1, 1))[f[reached], 0, 0, 0],
            added_rule)
    elif track:
        _add_turbulence(wakes, f[reached], j[reached], x_i, radius_i,
                        axial_induction_i, overlap[reached], ambient, added_rule)
    return result.reshape(u_initial.shape), (f[reached], j[reached])


def _centres_at_deficit_heights(heights, rotor, f, j, kind, x, deflection_field, centre,
                                per_condition):
    """The wake's centre offset [m] at the cumulative wake's ``heights`` (rotor radii) of the
    rotors (f, j) it reaches, (pairs, K), and the inputs of the pass that evaluates it: the
    ekman_veer deflection's compiled centre there (``centre`` None; the kernel's
    ``per_condition`` table, with the ambient at those heights, RotorAmbient.deficit_u,
    deficit_v), evaluated by the upstream sums' pass into the array returned (the inputs:
    those of upstream_wakes.centres_at_heights); another deflection model's,
    which FLORIS gives at its points only, interpolated linearly from them in height as the
    rows' ``centre`` is (constant beyond the outer points; the inputs None)."""
    if centre is not None:
        points = deflection_field[f, j, 0, :]
        return np.sum(points[:, :, None] * row_interpolation(rotor.cells.n, heights),
                      axis=1), None
    return (np.empty((f.size, np.size(heights))),
            (x, f, kind, rotor.deficit_heights, rotor.deficit_u, rotor.deficit_v, per_condition))


def _add_turbulence(wakes, f, j, x_i, radius_i, axial_induction_i, overlap, ambient, rule):
    """FLORIS's wake-added turbulence at rotors (f, j) from turbine i, with the overlap
    the area fraction of the disk (RotorWakes), within 15 D downstream as FLORIS has it,
    combined by ``rule`` (RotorWakes.add_turbulence)."""
    column = lambda a: condition_column(a, x_i.shape[0])[f]  # noqa: E731
    x_j, x_source = ambient.rotor.x[f, j], column(x_i)
    diameter = 2.0 * column(radius_i)
    ambient_turbulence = column(ambient.floris_turbulence)
    parameters = crespo_hernandez_parameters(wakes.turbulence_model)
    if parameters is not None:
        # FLORIS's formula compiled, the same bits (wake/added_turbulence.py; x_j > x_source).
        added = crespo_hernandez_overlap(ambient_turbulence, x_j[:, None], x_source, diameter,
                                         column(axial_induction_i), overlap, parameters)[:, 0]
    else:
        added = wakes.turbulence_model.function(
            ambient_turbulence, x_j, x_source, diameter, column(axial_induction_i))
        added = overlap * np.nan_to_num(np.asarray(added, dtype=float), posinf=0.0) * (
            x_j <= x_source + 15.0 * diameter)
    wakes.add_turbulence(f, j, added, ambient_turbulence, rule)


def _columns(values, names, shape):
    """The kernel's table (shape..., names) of ``values`` (arrays or scalars by name)."""
    table = np.empty((*shape, len(names)))
    for k, name in enumerate(names):
        table[..., k] = values[name]
    return table


#: A wake joins a rotor's combined convection velocity where its deficit on the rotor exceeds
#: this fraction of U_0 (PyWake's WeightedSum: weaker wakes add linearly); Zong & Porte-Agel's
#: U_c is that of the wakes that overlap there.
CONVECTION_THRESHOLD = 0.01


def _momentum_conserving(wakes, rotor, reached, flat, f, j, kind, moment, centre, split,
                         per_pair, y_i, hub_height_i, width, centre_speed, wake_convection):
    """The cells' removed moment (pairs, n^2), as the kernel returns it, of the rotors reached by
    turbine i's wake after Zong & Porte-Agel's superposition (plugin/rotor/convection.py): the
    wake's Gaussian equivalent (centre deficit, width k_w x + xi0 of the kernel's table, centre
    at the rows' mean) joins the rotor's where its deficit on the rotor exceeds
    CONVECTION_THRESHOLD U_0, U_c is updated and the whole rotor's moment recomputed, less what
    the cells already removed. ``centre`` (pairs, row slots); ``split``: the strip a layer top
    cuts is integrated as its parts (plugin/rotor/strip_split.py)."""
    cells = wakes.cells
    pick = lambda a: np.broadcast_to(a, flat.shape)[reached]  # noqa: E731
    pairs = flat[reached]
    f, j, kind = f[reached], j[reached], kind[reached]
    hub_speed, width = pick(per_pair["hub_speed"]), pick(width)
    centre_speed, wake_convection = pick(centre_speed), pick(wake_convection)
    if split:
        strips, fraction, heights, u, v = rotor.split.pair_rows(
            cells, rotor.kind_heights, rotor.kind_u, rotor.kind_v, f, kind)
        centre, chord = centre[reached], cells.row_chord[strips]
    else:
        centre, chord = centre[reached][:, :cells.rows], cells.row_chord
        heights, u, v = rotor.kind_heights[kind], rotor.kind_u[f, kind], rotor.kind_v[f, kind]
    centre_y = y_i[f, 0, 0, 0] + centre[:, :cells.rows].mean(axis=1)
    centre_z = hub_height_i[f, 0, 0, 0]
    # The rotor's nearest sub-point row to the wake's centre line (veer shears it row by row).
    radius_j = rotor.radius[f, j][:, None]
    lateral = np.maximum(np.abs(pick(per_pair["offset"])[:, None] - centre)
                         - radius_j * chord, 0.0)
    gap_squared = lateral**2 + (heights - centre_z[:, None]) ** 2
    if split:
        gap_squared = np.where(fraction > 0.0, gap_squared, np.inf)  # (empty slots)
    gap_squared = np.min(gap_squared, axis=1)
    joins = (centre_speed * np.exp(-gap_squared / (2.0 * width**2))
             > CONVECTION_THRESHOLD * hub_speed)
    state = wakes.convection
    state.add(pairs[joins], (wake_convection * centre_speed)[joins], width[joins] ** 2,
              centre_y[joins], centre_z[joins], hub_speed[joins])
    # A rotor no wake has joined yet: its wakes add linearly (weight 1 for this one).
    convection = np.where(state.count[pairs] > 0, state.velocity[pairs], wake_convection)
    flowing = u * pick(per_pair["cos"])[:, None] + v * pick(per_pair["sin"])[:, None] > 0.0
    total = removed_moments(cells, wakes.combined, pairs, convection,
                            np.where(flowing, u, 0.0), moment[reached],
                            (strips, fraction) if split else None)
    removed = np.zeros((flat.size, cells.n**2))
    removed[reached] = total - wakes.removed[pairs] / cells.n**2
    return removed


def _ishihara_qian(x, per_pair, reached, centre, split, rotor, f, j, kind, hub_height,
                   ambient_turbulence, n_findex):
    """Ishihara & Qian's (2018) added turbulence of turbine i's wake at rotors (f, j), the mean
    over each rotor's sub-points (the wake's centre at the row slots, ``centre``: (pairs,
    slots); ``split``: the strip a layer top cuts as its parts, plugin/rotor/strip_split.py),
    not below 0 (the ground term lowers it below the hub), within 15 D downstream as FLORIS has
    Crespo-Hernandez (docs/coupling.md#wakes-deep-in-an-array)."""
    cells = rotor.cells
    radius_j = rotor.radius[f, j][:, None, None]
    if split:
        strips, fraction, heights, _, _ = rotor.split.pair_rows(
            cells, rotor.kind_heights, rotor.kind_u, rotor.kind_v, f, kind)
        sub_y, heights = cells.sub_y[strips], heights[:, :, None]
        weight = cells.weight[strips] * fraction[:, :, None]
    else:
        centre, sub_y = centre[:, :cells.rows], cells.sub_y
        heights = rotor.kind_heights[kind][:, :, None]
    lateral = (per_pair["offset"][reached][:, None] - centre)[:, :, None] + radius_j * sub_y
    r = np.hypot(lateral, heights - hub_height[:, None, None])
    diameter = 2.0 * per_pair["radius"][reached]
    ambient = np.broadcast_to(ambient_turbulence, (n_findex, 1, 1, 1))[f, 0, 0, 0]
    column = lambda a: a[:, None, None]  # noqa: E731
    added = ishihara_qian_added_turbulence(
        column(x), r, np.broadcast_to(heights, r.shape), column(per_pair["ct"][reached]),
        column(ambient), column(diameter), column(hub_height))
    if split:
        mean = np.einsum("prs,prs->p", added, weight)
    else:
        mean = np.einsum("prs,rs->p", added, cells.weight)
    return np.maximum(mean, 0.0) * (x <= 15.0 * diameter)


def _check_resolution(x, f, j, reached, source_wake, centre, rotor):
    """Warn once per run when a wake band is thinner than the cells' sub-row spacing: at the
    rotors (f, j)[reached], x behind the wake's rotor, the wake's quantities per condition
    ``source_wake`` and its ``centre`` at the rows (pairs, rows)."""
    warned, cells = rotor.warned, rotor.cells
    if "rows" in warned:
        return
    k_w, radius, ct, yaw = (source_wake[k] for k in ("k_w", "radius", "ct", "yaw"))
    # The wake's width k_w x + 0.4 R sqrt(A*) cos(yaw): its second term once per condition.
    initial_width = WIDTH_FACTOR * radius * np.sqrt(stream_tube_area_ratio(ct, yaw)) * np.cos(yaw)
    f, j = f[reached], j[reached]
    width = k_w[f] * x[reached] + initial_width[f]
    radius_j = rotor.radius[f, j]
    height = radius_j * (cells.row_z[-1] - cells.row_z[0])
    shear = np.abs(centre[reached, -1] - centre[reached, 0]) / height
    thickness = width / np.sqrt(1.0 + shear**2)
    spacing = 2.0 * radius_j / cells.rows
    if np.any(thickness < MIN_BAND_PER_ROW * spacing):
        warned.add("rows")
        ratio = float(np.min(thickness / spacing))
        warnings.warn(
            f"a veer-sheared wake band is {ratio:.2f} sub-row spacings thin on a rotor, "
            f"below the {MIN_BAND_PER_ROW} that its rotor-cell average resolves to 1 % in "
            f"power: raise solver.turbine_grid_points (now {cells.n}; the cells' "
            f"sub-quadrature has {cells.rows} rows per rotor, {ROWS_PER_POINT} per grid "
            "point)",
            RuntimeWarning,
            stacklevel=4,
        )
