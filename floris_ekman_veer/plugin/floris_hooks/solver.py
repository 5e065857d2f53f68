"""The solver of the package's velocity models on FLORIS's turbine grid: FLORIS's sequential
solver, restricted to the rotors each wake reaches (docs/coupling.md#solver).

FLORIS's ``sequential_solver`` visits the turbines in its order and, at each, evaluates the wake
models and updates the combined wake, the wake-added turbulence and the velocities on every point
of every rotor of the farm, upstream ones included. On a turbine grid the ``ekman_veer`` and
``bastankhah2014`` velocity models already integrate a wake only on the rotor cells it can reach
(plugin/rotor/rotor.py: downstream, within the lateral and vertical reach the wake's
``width_bound`` and ``amplitude_bound`` give) and return 0 elsewhere; this solver makes the rest of
each step, FLORIS's part, follow them: the combination, the wake-added turbulence and the
velocity update are evaluated on the rotors (condition, turbine) where turbine i's wake is not
zero (the turbulence where it overlaps a rotor, as FLORIS counts the overlap), gathered from and
scattered back into the farm's arrays, vectorised over conditions.

Each step calls the same functions as FLORIS's ``sequential_solver``, in its order, with the same
arguments on those rotors: FLORIS's thrust and induction of turbine i (the veer-aware rotor,
plugin/rotor/yawed_rotor.py), the deflection and velocity models, the combination model, the
turbulence model with FLORIS's area overlap and 15 D reach, and the combination of turbulence
intensities. No physics is repeated here, so a change of the models carries over. Where a
wake is zero on a rotor, FLORIS's update leaves that rotor's values unchanged bit for bit
(hypot(w, 0) = w, sqrt(0 + TI_0^2) = TI_0 <= TI), so the results are FLORIS's own
[`test_solver_equals_floris_sequential_solver`].

Used by FLORIS's solver dispatch (``floris.core.core``, and the turbine-grid solve inside
FLORIS's full-flow solver) when the velocity model is one of the package's on a turbine grid
without GCH's terms (secondary steering, transverse velocities, yaw-added recovery, which read
and write whole-farm fields); FLORIS's own solver otherwise. Its rotors' incoming speeds and array
turbulence are handed to the wakes of FLORIS's other grids (cubature grids, planes, points:
plugin/rotor/turbine_states.py, docs/coupling.md#one-physics-on-every-grid).
"""

from __future__ import annotations

import copy
import functools

import numpy as np
from floris.core import TurbineCubatureGrid, TurbineGrid, axial_induction, thrust_coefficient
from floris.core import core as floris_core
from floris.core import solver as floris_solver

from floris_ekman_veer.plugin.floris_hooks import patching
from floris_ekman_veer.plugin.inflow import inflow
from floris_ekman_veer.plugin.inflow.ambient import is_rotor_grid
from floris_ekman_veer.plugin.rotor import turbine_states
from floris_ekman_veer.plugin.rotor.rotor import ADDED_TURBULENCE, condition_column
from floris_ekman_veer.plugin.rotor.rotor_wakes import crespo_hernandez_parameters
from floris_ekman_veer.plugin.rotor.yawed_rotor import sharing_interpolants, sharing_thrust
from floris_ekman_veer.plugin.wake_models.models import EkmanWakeModel
from floris_ekman_veer.wake.added_turbulence import crespo_hernandez_overlap

#: GCH's switches: each makes FLORIS's solver read or write whole-farm fields per turbine.
WHOLE_FARM_TERMS = ("enable_secondary_steering", "enable_transverse_velocities",
                    "enable_yaw_added_recovery")


def uses_rotor_solver(grid, model_manager) -> bool:
    """Whether :func:`rotor_solver` solves this grid and these wake models."""
    return (isinstance(model_manager.velocity_model, EkmanWakeModel) and is_rotor_grid(grid)
            and not any(getattr(model_manager, flag, False) for flag in WHOLE_FARM_TERMS))


#: The farm's per-turbine operation arrays FLORIS's solver hands the turbine functions (sorted).
_SORTED_OPERATION = ("yaw_angles", "tilt_angles", "power_setpoints", "awc_modes", "awc_amplitudes",
                     "correct_cp_ct_for_tilt", "turbine_type_map")


def _turbine_operation(function, farm, flow_field, grid, i, functions_key, functions):
    """FLORIS's thrust coefficient or axial induction of sorted turbine i, as its sequential
    solver asks for it: (n_findex, 1, 1, 1)."""
    value = function(
        velocities=flow_field.u_sorted,
        turbulence_intensities=flow_field.turbulence_intensity_field_sorted,
        air_density=flow_field.air_density,
        **{name: getattr(farm, f"{name}_sorted") for name in _SORTED_OPERATION},
        tilt_interps=farm.turbine_tilt_interps,
        turbine_power_thrust_tables=farm.turbine_power_thrust_tables,
        ix_filter=[i],
        average_method=grid.average_method,
        cubature_weights=grid.cubature_weights,
        multidim_condition=flow_field.multidim_conditions,
        **{functions_key: functions},
    )
    return value[:, 0:1, None, None]


def rotor_solver(farm, flow_field, grid, model_manager) -> None:
    """FLORIS's ``sequential_solver`` on the rotors each wake reaches (module docstring).

    Same arguments and outputs as FLORIS's: ``flow_field.u_sorted``, the turbulence-intensity
    fields and (with ``enable_turbine_turbulence_grid``) the wake-mixing field.
    """
    # (FLORIS's turbines build their table's interpolant at every step: once per solve here.)
    with sharing_interpolants():
        _solve(farm, flow_field, grid, model_manager)


def _solve(farm, flow_field, grid, model_manager) -> None:
    """:func:`rotor_solver`'s steps."""
    deflection_model_args = model_manager.deflection_model.prepare_function(grid, flow_field)
    deficit_model_args = model_manager.velocity_model.prepare_function(grid, flow_field)

    u_initial = flow_field.u_initial_sorted
    wake_field = np.zeros_like(u_initial, order="C")
    flow_field.u_sorted = u_initial - wake_field
    n_findex, n_turbines, n_y, n_z = u_initial.shape
    # The rotors' points by flat rotor index (condition * n_turbines + turbine): the gathers
    # of a step's rotors read these (one index array, not two).
    by_rotor = lambda a: np.reshape(a, (n_findex * n_turbines, n_y, n_z))  # noqa: E731
    u_initial_rotors, x_rotors, y_rotors = (by_rotor(a) for a in (u_initial, grid.x_sorted,
                                                                   grid.y_sorted))
    wake_rotors = by_rotor(wake_field)  # a view: the step's updates are written through it

    # As FLORIS: per turbine, or per rotor point with the turbulence grid; FLORIS's first
    # update makes it per rotor point in any case (its wake-added turbulence is a grid field).
    turbine_turbulence_intensity = np.repeat(
        flow_field.turbulence_intensities[:, None, None, None], n_turbines, axis=1)
    if model_manager.enable_turbine_turbulence_grid:
        turbine_turbulence_intensity = np.repeat(
            np.repeat(turbine_turbulence_intensity, grid.grid_resolution, axis=2),
            grid.grid_resolution, axis=3)
    ambient_turbulence_intensities = flow_field.turbulence_intensities.copy()[:, None, None, None]
    crespo_parameters = crespo_hernandez_parameters(model_manager.turbulence_model)

    # FLORIS's x_i, y_i, z_i: the mean of each rotor's points, for every turbine at once (each
    # rotor's points summed in the same order as one turbine's slice: the same bits).
    centres = [np.mean(a, axis=(2, 3), keepdims=True)
               for a in (grid.x_sorted, grid.y_sorted, grid.z_sorted)]

    for i in range(n_turbines):
        x_i, y_i, z_i = (centre[:, i:i+1] for centre in centres)
        # (FLORIS's axial induction computes the thrust coefficient again: shared, the same bits.)
        with sharing_thrust():
            ct_i = _turbine_operation(thrust_coefficient, farm, flow_field, grid, i,
                                      "thrust_coefficient_functions",
                                      farm.turbine_thrust_coefficient_functions)
            axial_induction_i = _turbine_operation(axial_induction, farm, flow_field, grid, i,
                                                   "axial_induction_functions",
                                                   farm.turbine_axial_induction_functions)
        turbulence_intensity_i = turbine_turbulence_intensity[:, i:i+1]
        yaw_angle_i = farm.yaw_angles_sorted[:, i:i+1, None, None]
        hub_height_i = farm.hub_heights_sorted[:, i:i+1, None, None]
        rotor_diameter_i = farm.rotor_diameters_sorted[:, i:i+1, None, None]
        effective_yaw_i = np.zeros_like(yaw_angle_i)
        effective_yaw_i += yaw_angle_i

        deflection_field = model_manager.deflection_model.function(
            x_i, y_i, effective_yaw_i, turbulence_intensity_i, ct_i, rotor_diameter_i,
            **deflection_model_args,
        )
        wakes = deficit_model_args.get("wakes")
        if wakes is not None:
            wakes.reached, wakes.source = None, i
        velocity_deficit = model_manager.velocity_model.function(
            x_i, y_i, z_i, axial_induction_i, deflection_field, yaw_angle_i,
            turbulence_intensity_i, ct_i, hub_height_i, rotor_diameter_i,
            **deficit_model_args,
        )

        if i == 0:
            turbine_turbulence_intensity = np.broadcast_to(
                turbine_turbulence_intensity, u_initial.shape).copy()
            turbulence_rotors = by_rotor(turbine_turbulence_intensity)  # a view, as wake_rotors
        # The rotors (f, j) turbine i's wake reaches: elsewhere FLORIS's update is the identity
        # (the model's list of them where it gives one: a rotor in it whose deficit is 0 is
        # left as it is by the update, bit for bit).
        if wakes is not None and wakes.reached is not None:
            f, j = wakes.reached
        else:
            f, j = np.nonzero(np.any(velocity_deficit.reshape(n_findex, n_turbines, -1),
                                     axis=2))
        if f.size == 0:
            continue
        rotors = f * n_turbines + j
        u_initial_fj = u_initial_rotors.take(rotors, axis=0)
        deficit = by_rotor(velocity_deficit).take(rotors, axis=0) * u_initial_fj  # (pairs, n, n)
        combined = model_manager.combination_model.function(wake_rotors.take(rotors, axis=0),
                                                            deficit)
        wake_rotors[rotors] = combined

        flow_field.u_sorted[f, j] = u_initial_fj - combined

        # Wake-added turbulence where the wake overlaps a rotor (elsewhere FLORIS adds 0).
        area_overlap = (np.sum(deficit > 0.05, axis=(1, 2))
                        / (grid.grid_resolution * grid.grid_resolution))
        hit = np.flatnonzero(area_overlap)
        if hit.size == 0:
            continue
        f, j, rotors, area_overlap = f[hit], j[hit], rotors[hit], area_overlap[hit, None, None]
        x = x_rotors.take(rotors, axis=0)
        per_pair = lambda a: condition_column(a, n_findex)[f, None, None]  # noqa: E731
        x_source, diameter = per_pair(x_i), per_pair(rotor_diameter_i)
        ambient = ambient_turbulence_intensities[f, 0]
        if crespo_parameters is not None:
            # FLORIS's Crespo-Hernandez and the factors below compiled, the same bits
            # (wake/added_turbulence.py).
            ti_added = crespo_hernandez_overlap(
                ambient, x.reshape(f.size, -1), x_source, diameter, per_pair(axial_induction_i),
                area_overlap, crespo_parameters, y_rotors.take(rotors, axis=0).reshape(f.size, -1),
                per_pair(y_i)).reshape(x.shape)
        else:
            ti_added = (
                area_overlap
                * np.nan_to_num(model_manager.turbulence_model.function(
                    ambient, x, x_source, diameter, per_pair(axial_induction_i),
                ), posinf=0.0)
                * (x > x_source)
                * (np.abs(per_pair(y_i) - y_rotors.take(rotors, axis=0)) < 2 * diameter)
                * (x <= 15 * diameter + x_source)
            )
        turbulence_rotors[rotors] = np.maximum(
            np.sqrt(ti_added**2 + ambient**2), turbulence_rotors.take(rotors, axis=0))

    flow_field.turbulence_intensity_field_sorted = turbine_turbulence_intensity
    if model_manager.enable_turbine_turbulence_grid:
        flow_field.turbulence_wake_mixing_sorted = (
            turbine_turbulence_intensity * flow_field.u_initial_sorted / flow_field.u_sorted
        )
    flow_field.turbulence_intensity_field_sorted_avg = np.mean(
        turbine_turbulence_intensity, axis=(2, 3), keepdims=True)
    if turbine_states.collecting():
        turbine_states.hand(_states(model_manager.velocity_model, deficit_model_args,
                                    flow_field.turbulence_intensity_field_sorted_avg))


def _states(model, deficit_model_args, floris_turbulence) -> turbine_states.TurbineStates:
    """The rotors' states after a turbine-grid solve, as its wakes took them: U_i / U_i,0 and the
    turbulence of each rotor (plugin/rotor/turbine_states.py). A rotor's values are final once the
    wakes upstream of it are in, i.e. when its own wake was computed."""
    ambient, wakes = deficit_model_args["ambient"], deficit_model_args["wakes"]
    rotor = ambient.rotor
    n_findex, n_turbines = rotor.x.shape
    fraction = np.ones((n_findex, n_turbines))
    if ((model.deficit_velocity == "incoming" or wakes.superposition == "cumulative")
            and wakes.rule is not None):
        u_cells = deficit_model_args["u_initial"].reshape(n_findex * n_turbines, -1)
        fraction = wakes.incoming_fraction(np.arange(n_findex * n_turbines),
                                           u_cells).reshape(n_findex, n_turbines)
    tracked = (ADDED_TURBULENCE.get(model.wake_expansion) is not None
               and wakes.rule is not None and wakes.turbulence_model is not None)
    turbulence = (wakes.turbulence.copy() if tracked
                  else np.asarray(floris_turbulence)[:, :, 0, 0].copy())
    return turbine_states.TurbineStates(rotor.x, rotor.y, fraction, turbulence)


def hands_turbine_states(model) -> bool:
    """Whether the velocity model's wakes need the turbine grid's states on other grids: the
    rotors' incoming speeds (``deficit_velocity: incoming``, and the cumulative wake's thrust)
    or their array turbulence (``wake_expansion: array_turbulence``), which FLORIS's point-wise
    solvers do not carry.
    (``local_turbulence`` and ``free_stream`` they express themselves.)"""
    return isinstance(model, EkmanWakeModel) and (
        model.deficit_velocity == "incoming" or model.wake_expansion == "array_turbulence"
        or model.wake_superposition == "cumulative")


def turbine_grid_states(farm, flow_field, model_manager) -> turbine_states.TurbineStates:
    """The states of a turbine-grid solve of the same farm and conditions, on copies (as
    FLORIS's ``full_flow_sequential_solver`` makes its turbine-grid solve)."""
    turbine_farm, turbine_flow = copy.deepcopy(farm), copy.deepcopy(flow_field)
    grid = TurbineGrid(turbine_coordinates=turbine_farm.coordinates,
                       turbine_diameters=turbine_farm.rotor_diameters,
                       wind_directions=turbine_flow.wind_directions, grid_resolution=3)
    turbine_farm.expand_farm_properties(turbine_flow.n_findex, grid.sorted_coord_indices)
    turbine_flow.initialize_velocity_field(grid)
    turbine_farm.initialize(grid.sorted_indices)
    with turbine_states.handing():
        rotor_solver(turbine_farm, turbine_flow, grid, model_manager)
        return turbine_states.handed()


def _dispatching(original):
    """FLORIS's ``sequential_solver`` name in a FLORIS module: :func:`rotor_solver` where it
    applies (:func:`uses_rotor_solver`), FLORIS's own solver otherwise."""

    @functools.wraps(original)
    def sequential_solver(farm, flow_field, grid, model_manager):
        if uses_rotor_solver(grid, model_manager):
            return rotor_solver(farm, flow_field, grid, model_manager)
        if (isinstance(grid, TurbineCubatureGrid)
                and hands_turbine_states(model_manager.velocity_model)
                and not any(getattr(model_manager, flag, False) for flag in WHOLE_FARM_TERMS)):
            # The cubature points' wakes take the turbine grid's rotor states
            # (plugin/rotor/turbine_states.py), as the flow-field grids do.
            states = turbine_grid_states(farm, flow_field, model_manager)
            with turbine_states.handing():
                turbine_states.hand(states)
                return original(farm, flow_field, grid, model_manager)
        return original(farm, flow_field, grid, model_manager)

    sequential_solver.floris_solver = original
    return sequential_solver


def handing_full_flow(original):
    """FLORIS's ``full_flow_sequential_solver`` with a slot open for its turbine-grid solve's
    rotor states, which the flow-field grid's wakes then take (plugin/rotor/turbine_states.py)."""

    @functools.wraps(original)
    def full_flow_sequential_solver(farm, flow_field, flow_field_grid, model_manager):
        with turbine_states.handing():
            return original(farm, flow_field, flow_field_grid, model_manager)

    return full_flow_sequential_solver


def floris_sequential_solver():
    """FLORIS's own sequential solver (for comparisons)."""
    return getattr(floris_solver.sequential_solver, "floris_solver",
                   floris_solver.sequential_solver)


def install_solver_hook() -> None:
    """Dispatch FLORIS's sequential solver to :func:`rotor_solver` (idempotent): the name in
    ``floris.core.core`` (``Core.steady_state_atmospheric_condition``) and in
    ``floris.core.solver`` (the turbine-grid solve of FLORIS's full-flow solvers)."""
    for module in (floris_core, floris_solver):
        patching.patch(module, "sequential_solver", _dispatching)
