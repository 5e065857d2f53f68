"""Ekman inflow for every FLORIS wake model: FLORIS's flow-field initialisation with the
atmosphere's profile, defined once in the input dictionary (plugin/inflow/atmosphere_block.py).

FLORIS 4.7 builds its inflow as a power law (times optional speed multipliers) and has no
extension point for another profile: ``FlowField.initialize_velocity_field`` is wrapped by
:func:`initialize_velocity_field` (a row of the patch table, plugin/floris_hooks/patches.py). The Core
entry points that initialise flow fields make the Core's atmosphere active in
:data:`ACTIVE_ATMOSPHERE` (plugin/inflow/core_solve.py); without one the wrapper calls FLORIS's own
method and nothing else.

What the hook sets
------------------
* ``u_initial_sorted`` (and ``u_sorted``) = the hub-aligned streamwise component U(z) of the
  analytic profile at every grid height, in the frame rotated so that V(reference_wind_height) = 0:
  FLORIS's wind direction is read as the direction at its reference height, and
  U(reference_wind_height) equals FLORIS's wind speed. In the roughness sublayer (below about
  e z0) the profile falls linearly to 0 at the ground (docs/atmosphere.md#roughness-sublayer), so
  U > 0 at every z > 0 and no FLORIS model meets a zero inflow above the ground (FLORIS's gauss
  models divide by u_initial; at z = 0 U = 0, as with FLORIS's power law). Points below the
  ground get 0.
  ``wind_shear`` is ignored (the atmosphere defines the shear); 2-D/3-D heterogeneous speed
  multipliers, if also given, multiply the profile. On a ``turbine_grid`` each rotor point gets
  instead the mean of the profile over its rotor cell, <U^m>^(1/m) with m = 3 (power curves) or
  1 (the actuator disk) (:mod:`floris_ekman_veer.plugin.rotor.rotor`, docs/coupling.md#rotor-average).
* ``dudz_initial_sorted`` = dU/dz of that same hub-aligned U, by a centred difference of the
  analytic profile (relative step 1e-4: relative error about 1e-8; EkmanABL exposes no analytic
  gradient), 0 below the ground. GCH's secondary steering uses it.
* ``v_initial_sorted`` stays zero. FLORIS's solvers read ``v`` as *wake-induced* transverse
  velocity: GCH derives an effective yaw from the rotor-averaged ``v`` of each turbine (secondary
  steering) and feeds ``v``/``w`` into yaw-added recovery, so ambient veer in ``v_initial`` would
  be mistaken for the sidewash of a yawed rotor. Measured (GCH, NREL 5 MW row at 7 D, 8 m/s at
  90 m, f_c = 1e-4 1/s, z0 = 0.1 m, N = 6.1e-3 1/s; powers with V(z) in ``v_initial`` vs without):
  cooling rate -1 K/h (h = 71 m, 36 deg of veer across the rotor): downstream turbines +96 % and
  +67 % at zero yaw; -0.25 K/h (h = 197 m, 25 deg): +2.7 %, and +7.8 % with the first turbine
  yawed 20 deg; neutral (0 K/h, 0.5 deg of backing): +0.1 to +1.1 %. Unwaked turbines do not
  change (wind direction 300 deg: 0 %), i.e. the effect is purely a spurious wake steering. See
  ``tests/plugin/inflow/test_inflow.py::test_ambient_v_would_change_gch``. The veer reaches this package's own
  deflection model through :func:`solved_atmosphere` instead.
* Turbulence intensities remain FLORIS's inputs (see
  :func:`floris_ekman_veer.studies.comparison.builtin_inflow_settings` for values consistent with
  the atmosphere).

For wake models
---------------
``solved_atmosphere(flow_field)`` returns the EkmanABL solved for that flow field's conditions
(attributes shaped ``(n_findex, 1, 1, 1)``); call it from ``prepare_function(grid, flow_field)``.
The ABL is solved when the model is built (to validate the input) and cached by content, so each
flow-field initialisation reuses it: one solve per distinct (atmosphere, wind speeds, reference
height), never per turbine or per model. Deep copies made by the full-flow solvers are re-initialised
through the same hook and get their own entry.

The inflow's names are also read from here (the atmosphere block, the solve, the profile and the
patches' installation), so that a study or a user imports one module.
"""

from __future__ import annotations

import contextvars
import functools
import weakref

import numpy as np
from floris.core import FlowField, TurbineGrid

from floris_ekman_veer.plugin.floris_hooks import patching
from floris_ekman_veer.plugin.inflow.atmosphere_block import (
    ATMOSPHERE_KEY,
    CONFIG_PATH,
    PARAMETER_BLOCK,
    AtmosphereSpec,
    atmosphere_groups,
    atmosphere_of,
    farm_atmosphere,
    set_atmosphere,
)
from floris_ekman_veer.plugin.inflow.inflow_profile import (
    ambient_rows,
    ambient_velocity,
    inflow_profile,
)
from floris_ekman_veer.plugin.rotor.rotor_cells import turbine_grid_inflow
from floris_ekman_veer.plugin.inflow.shallow import warn_shallow
from floris_ekman_veer.plugin.inflow.solve_cache import solve

__all__ = [
    "ACTIVE_ATMOSPHERE", "ATMOSPHERE_KEY", "CONFIG_PATH", "PARAMETER_BLOCK", "AtmosphereSpec",
    "ambient_rows", "ambient_velocity", "atmosphere_groups", "atmosphere_of", "farm_atmosphere",
    "inflow_profile", "initialize_velocity_field", "install_inflow_hook", "is_installed",
    "set_atmosphere", "solve", "solved_atmosphere", "uninstall_inflow_hook", "warn_shallow",
]

#: Put back every patch of the package (idempotent; ``registry.register()`` installs them first).
install_inflow_hook = patching.reinstall
#: Restore every patched FLORIS attribute (plain FLORIS, for tests and comparisons).
uninstall_inflow_hook = patching.uninstall
is_installed = patching.is_installed

#: The atmosphere (:class:`AtmosphereSpec`) of the Core being solved, None outside a solve or
#: without one (set by plugin/inflow/core_solve.py around each Core entry point).
ACTIVE_ATMOSPHERE: contextvars.ContextVar = contextvars.ContextVar("ekman_veer_atmosphere",
                                                                   default=None)
_SOLVED: dict = {}  # id(flow_field) -> (weakref to the flow field, EkmanABL)


def _remember(flow_field: FlowField, abl) -> None:
    key = id(flow_field)
    # FlowField is unhashable (attrs eq), so key on id and guard against id reuse with a weakref
    # whose callback drops the entry when the flow field is collected.
    _SOLVED[key] = (weakref.ref(flow_field, lambda _, key=key: _SOLVED.pop(key, None)), abl)


def solved_atmosphere(flow_field: FlowField):
    """The EkmanABL solved for ``flow_field``'s conditions (attributes ``(n_findex, 1, 1, 1)``).

    For wake models' ``prepare_function(grid, flow_field)``. Returns the instance built when the
    flow field was last initialised (no new solve). Raises ValueError if no atmosphere is
    configured.
    """
    entry = _SOLVED.get(id(flow_field))
    if entry is not None and entry[0]() is flow_field:
        return entry[1]
    spec = ACTIVE_ATMOSPHERE.get()
    if spec is None:
        raise ValueError(
            f"the ekman_veer models need {CONFIG_PATH} in the FLORIS input (EkmanABL inputs "
            "without the wind speed); none is configured"
        )
    abl = solve(spec, flow_field.wind_speeds, flow_field.reference_wind_height)
    _remember(flow_field, abl)
    return abl


def initialize_velocity_field(original):
    """``FlowField.initialize_velocity_field`` with the atmosphere's inflow, when one is active
    (FLORIS's own ``original`` otherwise)."""

    @functools.wraps(original)
    def wrapper(self: FlowField, grid) -> None:
        spec = ACTIVE_ATMOSPHERE.get()
        if spec is None:
            return original(self, grid)
        abl = solve(spec, self.wind_speeds, self.reference_wind_height)
        # FLORIS's own initialisation with zero shear sets v, w, the TI fields and
        # u_initial = wind speed x heterogeneous speed-ups; only u needs the profile. (dudz from a
        # zero shear is 0 * z**-1, which warns at z = 0; it is overwritten.)
        wind_shear = self.wind_shear
        self.wind_shear = 0.0
        try:
            with np.errstate(divide="ignore", invalid="ignore"):
                original(self, grid)
        finally:
            self.wind_shear = wind_shear
        U, dUdz = inflow_profile(abl, grid.z_sorted, self.reference_wind_height)
        if isinstance(grid, TurbineGrid):
            # Each rotor point carries the cubic mean of U over its rotor cell (plugin/rotor/rotor.py).
            # (U alone: the gradient's two extra profile evaluations would be discarded.)
            U = turbine_grid_inflow(
                lambda heights: ambient_rows(abl, heights, self.reference_wind_height)[0], grid
            )
        shape = self.u_initial_sorted.shape
        if np.any(abl.at_rest):
            moving = ~abl.at_rest.reshape(-1, 1, 1, 1)
            U, dUdz = np.where(moving, U, 0.0), np.where(moving, dUdz, 0.0)
        if self.het_map is not None:
            speeds = self.wind_speeds[:, None, None, None]
            speed_ups = np.divide(self.u_initial_sorted, speeds, out=np.ones(shape),
                                  where=speeds > 0)
            U, dUdz = speed_ups * U, speed_ups * dUdz
        self.u_initial_sorted = np.broadcast_to(U, shape).copy()
        self.dudz_initial_sorted = np.broadcast_to(dUdz, shape).copy()
        self.u_sorted = self.u_initial_sorted.copy()
        _remember(self, abl)

    return wrapper
