"""The atmosphere around each FLORIS Core solve: the Core entry points that (directly or through
the full-flow solvers) initialise flow fields run with the Core's atmosphere active for the
inflow (plugin/inflow/inflow.py), the rotor averages and wake models of its turbines (plugin/rotor/rotor.py)
and the veer-aware rotor (plugin/rotor/yawed_rotor.py); the package's warnings of the solve are said
once; conditions at rest keep no flow; and full-flow grids of the package's wake models never
reverse the flow. Also ``FlorisModel.set_for_viz``, which keeps one condition: that condition's
atmosphere with it.
"""

from __future__ import annotations

import contextlib
import functools

import numpy as np
from floris.core import Core, FlowField

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer.plugin.wake_models import input_checks
from floris_ekman_veer.plugin.inflow.atmosphere_block import atmosphere_of, replaced_atmosphere
from floris_ekman_veer.plugin.inflow.inflow import ACTIVE_ATMOSPHERE
from floris_ekman_veer.plugin.rotor.rotor_cells import TURBINE_MOMENTS, WAKE_MODELS, turbine_moments
from floris_ekman_veer.plugin.inflow.shallow import warn_shallow
from floris_ekman_veer.plugin.inflow.solve_cache import solve
from floris_ekman_veer.plugin.rotor.yawed_rotor import veer_aware


def with_core_atmosphere(method):
    """Run a Core method with the Core's atmosphere (or None) active for flow-field set-ups,
    after checking the operation (yaw) and, for ``solve_for_points``, the sample coordinates
    (:mod:`floris_ekman_veer.plugin.wake_models.input_checks`)."""
    points = method.__name__ == "solve_for_points"
    full_flow = points or method.__name__ == "solve_for_viz"

    @functools.wraps(method)
    def wrapper(self: Core, *args, **kwargs):
        atmosphere = atmosphere_of(self)
        if input_checks.uses_package(self, atmosphere):
            input_checks.check_operation(self)
            if points:
                input_checks.check_points(*args, **kwargs)
        with contextlib.ExitStack() as stack:
            # The atmosphere, which rotor average each turbine takes, and how the solver
            # combines wakes and adds turbulence (plugin/rotor/rotor.py), for the solve only.
            for variable, value in ((ACTIVE_ATMOSPHERE, atmosphere),
                                    (TURBINE_MOMENTS,
                                     turbine_moments(self.farm.turbine_definitions)),
                                    (WAKE_MODELS, self.wake)):
                stack.callback(variable.reset, variable.set(value))
            # The package's per-wake warnings are said once, summarised, at the end of a solve.
            stack.enter_context(package_warnings.run_scope(self.flow_field.wind_speeds,
                                                           self.flow_field.reference_wind_height))
            rest = stack.enter_context(_at_rest(self, atmosphere))
            if method.__name__ != "steady_state_atmospheric_condition":
                # (run() initialises the domain first: said there, once)
                warn_shallow(self, atmosphere)
            # The operation models see the Core's ambient V (the veer-aware rotor).
            stack.enter_context(veer_aware(self))
            result = method(self, *args, **kwargs)
        if rest is not None:
            result = _still(self.flow_field, rest, result)
        if full_flow and input_checks.uses_wake_models(self):
            result = _without_reversed_flow(self.flow_field, result)
        return result

    return wrapper


@contextlib.contextmanager
def _at_rest(core: Core, atmosphere):
    """The conditions at rest of a Core's solve (None if there are none), FLORIS's divisions by
    their zero inflow quiet: their flow is set to 0 afterwards (:func:`_still`)."""
    rest = None
    if atmosphere is not None and core.flow_field.n_findex:
        abl = solve(atmosphere, core.flow_field.wind_speeds, core.flow_field.reference_wind_height)
        rest = abl.at_rest if np.any(abl.at_rest) else None
    if rest is None:
        yield None
        return
    with np.errstate(divide="ignore", invalid="ignore"):
        yield rest


def _still(flow_field: FlowField, rest, result):
    """No flow in the conditions at rest (FLORIS's own models divide by their zero inflow)."""
    for name in ("u_sorted", "v_sorted", "w_sorted", "u", "v", "w"):
        field = getattr(flow_field, name, None)
        if isinstance(field, np.ndarray) and field.ndim and field.shape[0] == rest.size:
            field[rest] = 0.0
    if isinstance(result, np.ndarray) and result.ndim and result.shape[0] == rest.size:
        result[rest] = 0.0
    return result


def _without_reversed_flow(flow_field: FlowField, result):
    """Superposed wakes at most stop the flow: u >= min(U(z), 0) on a full-flow grid (points,
    planes) of the package's wake models.

    Each wake's deficit is limited to the local inflow U(z) (the U_h-scaled Gaussian tail exceeds
    it next to the ground, docs/wake_model.md#which-velocity-goes-where), but FLORIS's
    sum-of-squares superposition of two such stopped wakes would give (1 - sqrt(2)) U(z). Where
    the inflow itself runs against the reference direction (collapsed layers a few metres deep,
    docs/atmosphere.md) the wake models add no deficit and u stays U(z). Rotor points lie far
    above that layer, so turbine grids need no bound.
    """
    floor = np.minimum(flow_field.u_initial_sorted, 0.0)
    flow_field.u_sorted = np.maximum(flow_field.u_sorted, floor)
    return None if result is None else np.maximum(result, floor[:, :, 0, 0])


def slicing_set_for_viz(method):
    """FlorisModel.set_for_viz keeps one condition: keep that condition's atmosphere too."""

    @functools.wraps(method)
    def wrapper(self, findex: int, solver_settings: dict) -> None:
        spec = atmosphere_of(self.core)
        if spec is None or spec.n_conditions is None:
            return method(self, findex, solver_settings)
        with replaced_atmosphere(self.core, spec.sliced(slice(findex, findex + 1))):
            return method(self, findex, solver_settings)

    return wrapper
