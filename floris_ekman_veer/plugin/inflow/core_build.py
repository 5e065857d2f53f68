"""Checks when a FLORIS Core is built (FlorisModel(), set(), copy()): the atmosphere block, the
layout, conditions and turbines of a Core using the package, and what its solved conditions
imply (a rotor above a shallow boundary layer refused, hubs in the roughness sublayer, a
heterogeneous map, unused turbulence intensities), so that bad input fails early with the
offending key named (docs/coupling.md#input-validation)."""

from __future__ import annotations

import functools

import numpy as np
from floris.core import Core

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer.plugin.inflow import shallow
from floris_ekman_veer.plugin.wake_models import input_checks
from floris_ekman_veer.plugin.inflow.atmosphere_block import (
    CONFIG_PATH,
    PARAMETER_BLOCK,
    AtmosphereSpec,
    atmosphere_of,
)
from floris_ekman_veer.plugin.inflow.solve_cache import solve


def validating_post_init(method):
    """Validate the atmosphere, and the layout, conditions and turbines of a Core using the
    package (:func:`floris_ekman_veer.plugin.wake_models.input_checks.check_core`, before FLORIS builds
    its grid), when a Core is built (FlorisModel(), set(), copy())."""

    @functools.wraps(method)
    def wrapper(self: Core) -> None:
        spec = atmosphere_of(self)
        if input_checks.uses_package(self, spec):
            input_checks.check_core(self, spec)
        method(self)
        if spec is not None and self.flow_field.n_findex:
            _check_solved_conditions(self, spec)
        elif spec is not None:
            # No conditions yet (n_findex = 0): nothing to solve until set() gives them.
            shallow.policy(self.wake.wake_velocity_parameters.get(PARAMETER_BLOCK))

    return wrapper


def _check_solved_conditions(core: Core, spec: AtmosphereSpec) -> None:
    """At build: the shallow-boundary-layer policy ``raise`` (plugin/inflow/shallow.py; ``warn``
    counts them at the first run instead, :func:`floris_ekman_veer.plugin.inflow.shallow.warn_shallow`), hubs in the roughness
    sublayer and a heterogeneous map given with the atmosphere (warned)."""
    flow_field = core.flow_field
    height = shallow.reference_height(core)
    if height is None:
        return  # FLORIS refuses it
    abl = solve(spec, flow_field.wind_speeds, height)
    shallow.check_core(core, abl, height, "build")
    sublayer = np.max(np.where(abl.at_rest, 0.0, np.reshape(abl.roughness_sublayer_height, -1)))
    low = np.flatnonzero(np.asarray(core.farm.hub_heights, dtype=float) < sublayer)
    if low.size:
        package_warnings.warn(
            f"{low.size} turbine(s) (turbine {', '.join(str(i) for i in low[:5])}) have the hub "
            f"in the roughness sublayer (below {sublayer:.3g} m), where the wind "
            "falls linearly to 0 at the ground (docs/atmosphere.md#roughness-sublayer): no "
            "measured wake or turbine stands there",
            package_warnings.TurbinePlacementWarning,
            items=[("sublayer", int(i)) for i in low],
        )
    if flow_field.heterogeneous_inflow_config is not None:
        package_warnings.warn(
            f"flow_field.heterogeneous_inflow_config is given with {CONFIG_PATH}: each "
            "condition's ABL is solved from flow_field.wind_speeds (the speed before the map's "
            "speed-ups) and its profile U(z) is multiplied by the speed-ups at each point, so h, "
            "veer and turbulence are those of the unmultiplied wind everywhere "
            "(docs/user_guide.md#heterogeneous-inflow)",
            package_warnings.HeterogeneousInflowWarning,
        )
