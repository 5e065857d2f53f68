"""Checks of a FLORIS Core's layout, conditions, turbines and operation for this package's models.

Called by the inflow hook (:mod:`floris_ekman_veer.plugin.inflow.inflow`): :func:`check_core` when a
Core is built (FlorisModel(), ``set()``, ``copy()``; before FLORIS builds its grid, which is where
an empty layout would otherwise fail), :func:`check_operation` and :func:`check_points` when a
Core solves. They act only on a Core that uses the package (an atmosphere block, an ``ekman_veer``
or ``bastankhah2014`` model, or an ``actuator-disk`` turbine): plain FLORIS inputs are left to
FLORIS, unchanged. Each error is a ValueError naming the input's path, the offending value (and
its condition or turbine index) and the valid range (docs/coupling.md#input-validation).
"""

from __future__ import annotations

import sys

import numpy as np

import floris_ekman_veer.warnings as package_warnings

from floris_ekman_veer._validation import number, require_each
from floris_ekman_veer.plugin.wake_models.names import (
    ATMOSPHERE_PATH,
    DEFLECTION_MODEL_NAME,
    GAUSSIAN_2014_NAME,
    VELOCITY_MODEL_NAME,
)
from floris_ekman_veer.plugin.rotor.turbine import OPERATION_MODEL_NAME, disk_parameters


def uses_wake_models(core) -> bool:
    """Whether the Core's velocity or deflection model is one of this package's."""
    strings = core.wake.model_strings
    return (
        str(strings.get("velocity_model", "")).lower() in (VELOCITY_MODEL_NAME, GAUSSIAN_2014_NAME)
        or str(strings.get("deflection_model", "")).lower() == DEFLECTION_MODEL_NAME
    )


def reads_wind_shear(core) -> bool:
    """Whether FLORIS's GCH terms that read ``flow_field.wind_shear`` are on (secondary steering
    and the transverse velocities take the vortex strength from the power law's shear)."""
    wake = core.wake
    return bool(wake.enable_secondary_steering or wake.enable_transverse_velocities)


def uses_package(core, atmosphere) -> bool:
    """Whether the Core uses an atmosphere, a wake model or a turbine of this package."""
    return (
        atmosphere is not None
        or uses_wake_models(core)
        or any(_is_disk(t) for t in core.farm.turbine_definitions)
    )


def _is_disk(turbine: dict) -> bool:
    return turbine.get("operation_model") == OPERATION_MODEL_NAME


def _is_positive(value) -> bool:
    return np.isfinite(value) and value > 0.0


def _turbine_path(farm, index: int) -> str:
    # The entry of farm.turbine_type turbine `index` came from (one entry may serve them all).
    return f"farm.turbine_type[{index if len(farm.turbine_type) > 1 else 0}]"


def check_core(core, atmosphere=None) -> None:
    """Layout, conditions and turbine definitions of a Core that uses the package, and the FLORIS
    flow inputs its ``atmosphere`` (the validated atmosphere of the input, or None) replaces."""
    _check_layout(core.farm)
    check_reference_height(core.flow_field)
    _check_conditions(core.flow_field)
    _check_turbines(core.farm)
    warn_ignored_flow_inputs(core, atmosphere)
    warn_deficit_superposition(core)


def warn_ignored_flow_inputs(core, atmosphere) -> None:
    """With an atmosphere, FLORIS's ``flow_field.wind_shear`` is not used for the inflow (the
    atmosphere gives the inflow's shear; only FLORIS's GCH terms read it, :func:`reads_wind_shear`),
    and ``flow_field.wind_veer`` is not used by the ekman_veer models
    (the atmosphere gives the veer; FLORIS's gauss models still read it as they do without the
    package, docs/user_guide.md#floris-inputs-the-atmosphere-replaces): one
    :class:`~floris_ekman_veer.warnings.ModelSettingsWarning` per value per study, so that a
    value the user set is never silently without effect. Zero (the shipped inputs') is silent.
    FLORIS's ``turbulence_intensities``: :func:`notice_unused_turbulence`."""
    if atmosphere is None:
        return
    flow_field = core.flow_field
    shear, veer = float(flow_field.wind_shear), float(flow_field.wind_veer)
    if shear != 0.0 and not reads_wind_shear(core):
        package_warnings.warn(
            f"flow_field.wind_shear = {shear:g} is not used: the atmosphere ({ATMOSPHERE_PATH}) "
            "gives the inflow's shear; set wind_shear: 0.0 to say so "
            "(docs/user_guide.md#floris-inputs-the-atmosphere-replaces)",
            package_warnings.ModelSettingsWarning, items=(("wind_shear", shear),))
    if veer != 0.0 and uses_wake_models(core):
        package_warnings.warn(
            f"flow_field.wind_veer = {veer:g} deg is not used by the "
            f"{VELOCITY_MODEL_NAME} models: the atmosphere ({ATMOSPHERE_PATH}) gives the veer; set "
            "wind_veer: 0.0 to say so (FLORIS's gauss models read it, "
            "docs/user_guide.md#floris-inputs-the-atmosphere-replaces)",
            package_warnings.ModelSettingsWarning, items=(("wind_veer", veer),))


#: TI given within this of the atmosphere's I_u at hub height are taken as its own (I_u written
#: to the three decimals a TI is usually given to; a gauss run on them sees the same turbulence).
OWN_TURBULENCE_MATCH = 5e-4 + 1e-12


def notice_unused_turbulence(core, abl, atmosphere) -> None:
    """``flow_field.turbulence_intensities``, which FLORIS requires, is not the ekman_veer wake
    model's ambient turbulence (it takes I_u at hub height from the solved atmosphere ``abl``):
    said once per study and atmosphere, as the unused ``wind_shear`` is, whatever TI are given
    (one constant value too: a gauss run beside it reads that value, so a comparison on "the same
    inflow" would differ in its turbulence unknowingly), unless they are the atmosphere's own I_u
    at a hub height, as the package's comparisons give them (studies/comparison.py)."""
    if str(core.wake.model_strings.get("velocity_model", "")).lower() != VELOCITY_MODEL_NAME:
        return
    given = np.asarray(core.flow_field.turbulence_intensities, dtype=float).ravel()
    moving = ~np.asarray(abl.at_rest, dtype=bool).ravel()
    if not np.any(moving):
        return
    own_by_hub = []
    for hub in np.unique(np.asarray(core.farm.hub_heights, dtype=float)):
        if hub >= np.max(abl.roughness_length):
            own = np.ravel(abl.turbulence_intensity(hub, reference_height=hub))
            if np.all(np.abs(given[moving] - own[moving]) <= OWN_TURBULENCE_MATCH):
                return
            own_by_hub.append(own[moving])
    seen = package_warnings.values_seen(f"turbulence_intensities on {atmosphere!r}",
                                        np.unique(given[moving]))
    own_text = (f" (its I_u at hub height here: "
                f"{package_warnings.range_text(np.concatenate(own_by_hub), '').strip()})"
                if own_by_hub else "")
    added_text = ("; only FLORIS's wake-added turbulence model reads them (wake_expansion: "
                  f"{core.wake.velocity_model.wake_expansion})"
                  if getattr(core.wake.velocity_model, "wake_expansion", "ambient") != "ambient"
                  else "")
    package_warnings.warn(
        "flow_field.turbulence_intensities "
        f"({package_warnings.range_text(seen, '').strip()}) are not used as the ambient "
        f"turbulence by the {VELOCITY_MODEL_NAME} wake model: it takes I_u at hub height from "
        f"the atmosphere ({ATMOSPHERE_PATH}; per condition in validity_report's "
        f"turbulence_intensity){own_text}{added_text}. FLORIS's gauss and other models read "
        "them as the ambient turbulence: for a "
        "comparison on the same inflow give them the atmosphere's I_u "
        "(docs/user_guide.md#floris-inputs-the-atmosphere-replaces)",
        package_warnings.ModelSettingsWarning, items=(("turbulence_intensities",),))


def warn_deficit_superposition(core) -> None:
    """``deficit_velocity: incoming`` (the package's default) scales each waked rotor's wake with
    its incoming speed, as Niayifar & Porte-Agel (2016) do with the deficits summed (FLORIS's
    combination ``fls``); squares summed (``sosfs``) or the largest (``max``) of such deficits
    would let deep-array wakes recover too fast: one
    :class:`~floris_ekman_veer.warnings.ModelSettingsWarning` per combination per study
    (docs/coupling.md#wakes-deep-in-an-array). Silent with ``fls`` or ``free_stream``."""
    velocity = getattr(core.wake, "velocity_model", None)
    if getattr(velocity, "deficit_velocity", None) != "incoming":
        return
    combination = str(core.wake.model_strings.get("combination_model", "")).lower()
    if combination != "fls":
        package_warnings.warn(
            f"wake.model_strings.combination_model = {combination!r} with "
            f"{velocity.input_path}.deficit_velocity = 'incoming': the wakes of waked rotors "
            "scale with their incoming speed and are meant to be summed; set combination_model: "
            "fls, or deficit_velocity: free_stream to scale them with the free stream "
            "(docs/coupling.md#wakes-deep-in-an-array)",
            package_warnings.ModelSettingsWarning, items=(("combination_model", combination),))


def _check_layout(farm) -> None:
    x = np.asarray(farm.layout_x, dtype=float)
    y = np.asarray(farm.layout_y, dtype=float)
    if x.size == 0:
        raise ValueError("farm.layout_x and farm.layout_y must hold at least one turbine; got none")
    require_each(np.isfinite(x), "farm.layout_x", "finite [m]", x, "turbine")
    require_each(np.isfinite(y), "farm.layout_y", "finite [m]", y, "turbine")
    z = np.empty(x.size)
    radius = np.empty(x.size)
    for index, turbine in enumerate(farm.turbine_definitions):
        path = _turbine_path(farm, index)
        z[index] = number(turbine["hub_height"], f"{path}.hub_height", "finite and > 0 [m]",
                          _is_positive)
        radius[index] = 0.5 * number(turbine["rotor_diameter"], f"{path}.rotor_diameter",
                                     "finite and > 0 [m]", _is_positive)
    below = np.flatnonzero(z < radius)
    if below.size:
        i = below[0]
        raise ValueError(
            f"{_turbine_path(farm, i)}.hub_height must be >= rotor_diameter / 2 = {radius[i]:.6g} m "
            f"(a rotor above the ground); got {z[i]:.6g} m at turbine {i}: its blades would reach "
            f"{radius[i] - z[i]:.4g} m below the ground"
        )
    # Coincident hubs (two turbines in one place) are no farm: FLORIS would give each the power
    # of a lone turbine. Rotors that merely intersect for some wind direction or yaw (hubs closer
    # than the sum of their radii) occur in the trial layouts of FLORIS's layout optimisers and
    # its plots with added turbines, so they run; in a layout the user gives they are warned.
    distance = np.sqrt(
        (x[:, None] - x) ** 2 + (y[:, None] - y) ** 2 + (z[:, None] - z) ** 2
    )
    coincident = np.triu(distance < COINCIDENT_DISTANCE, k=1)
    if np.any(coincident):
        i, j = np.argwhere(coincident)[0]
        raise ValueError(
            f"farm.layout_x/layout_y: turbines {i} and {j} are {distance[i, j]:.6g} m apart (hub "
            f"to hub), less than {COINCIDENT_DISTANCE:g} m: two turbines cannot stand in one place"
        )
    clash = np.triu(distance < radius[:, None] + radius, k=1)
    if np.any(clash) and not _floris_trial_layout():
        pairs = np.argwhere(clash)
        listed = ", ".join(f"{i} and {j} ({distance[i, j]:.4g} m)" for i, j in pairs[:3])
        more = f" and {len(pairs) - 3} more pairs" if len(pairs) > 3 else ""
        package_warnings.warn(
            f"farm.layout_x/layout_y: the rotors of turbines {listed}{more} would intersect for "
            "some wind direction or yaw (hubs closer than the sum of their rotor radii), which no "
            "wake model describes: check the layout",
            package_warnings.TurbinePlacementWarning,
            items=[(int(i), int(j), round(float(distance[i, j]), 3)) for i, j in pairs],
        )


#: Hubs closer than this [m] are one place.
COINCIDENT_DISTANCE = 1e-3
#: FLORIS modules whose layouts are trials, not the user's: its layout optimisers and the plots
#: that add a turbine at each point of a plane.
_TRIAL_LAYOUT_MODULES = ("floris.optimization.layout_optimization", "floris.flow_visualization")


def _floris_trial_layout() -> bool:
    """Whether FLORIS's layout optimisation or flow visualisation is setting this layout."""
    frame = sys._getframe(1)
    while frame is not None:
        if str(frame.f_globals.get("__name__", "")).startswith(_TRIAL_LAYOUT_MODULES):
            return True
        frame = frame.f_back
    return False


def check_reference_height(flow_field) -> None:
    """FLORIS's reference_wind_height: > 0 m, or -1 (FLORIS: the hub height)."""
    height = number(flow_field.reference_wind_height, "flow_field.reference_wind_height",
                    "finite and > 0 [m], or -1 for the hub height")
    if not (height > 0.0 or abs(height + 1.0) < 1e-6):
        raise ValueError(
            "flow_field.reference_wind_height must be > 0 m (the height of flow_field.wind_speeds) "
            f"or -1 (FLORIS: the hub height); got {height!r}"
        )


def _check_conditions(flow_field) -> None:
    directions = np.asarray(flow_field.wind_directions, dtype=float)
    speeds = np.asarray(flow_field.wind_speeds, dtype=float)
    intensities = np.asarray(flow_field.turbulence_intensities, dtype=float)
    require_each(np.isfinite(directions), "flow_field.wind_directions", "finite [deg]",
                 directions)
    require_each(np.isfinite(speeds) & (speeds >= 0), "flow_field.wind_speeds",
                 "finite and >= 0 [m/s]", speeds)
    require_each(np.isfinite(intensities) & (intensities >= 0),
                 "flow_field.turbulence_intensities", "finite and >= 0", intensities)
    heterogeneous = getattr(flow_field, "heterogeneous_inflow_config", None) or {}
    multipliers = heterogeneous.get("speed_multipliers")
    if multipliers is not None:
        values = np.asarray(multipliers, dtype=float)
        # (a NaN would reach the thrust as "ct must be >= 0 ... got nan")
        require_each(np.isfinite(values) & (values > 0),
                     "flow_field.heterogeneous_inflow_config.speed_multipliers",
                     "finite and > 0", np.atleast_1d(values))


def _check_turbines(farm) -> None:
    for index, turbine in enumerate(farm.turbine_definitions):
        if not _is_disk(turbine):
            continue
        path = _turbine_path(farm, index)
        _, diameter = disk_parameters(turbine["power_thrust_table"], f"{path}.power_thrust_table")
        if diameter != float(turbine["rotor_diameter"]):
            raise ValueError(
                f"{path}.power_thrust_table.rotor_diameter ({diameter:g} m) must equal "
                f"{path}.rotor_diameter ({turbine['rotor_diameter']!r} m): FLORIS does not pass "
                "the diameter to operation models"
            )


def check_operation(core) -> None:
    """At least one condition to solve; yaw angles of a Core whose wakes are this package's
    (|yaw| < 90 deg, finite)."""
    if not core.flow_field.n_findex:
        raise ValueError(
            "flow_field.wind_directions, wind_speeds and turbulence_intensities are empty: there "
            "is no condition to run; give at least one with fmodel.set(wind_directions=..., "
            "wind_speeds=..., turbulence_intensities=...) or fmodel.set(wind_data=...)"
        )
    if not uses_wake_models(core):
        return
    yaw = np.asarray(core.farm.yaw_angles, dtype=float)
    if yaw.ndim == 2:
        require_each(np.isfinite(yaw) & (np.abs(yaw) < 90.0), "yaw_angles",
                     "finite and in (-90, 90) degrees for the ekman_veer wake models", yaw,
                     ("condition", "turbine"))


def check_points(x, y, z) -> None:
    """Sample coordinates of ``sample_flow_at_points`` (finite)."""
    for name, value in (("x", x), ("y", y), ("z", z)):
        value = np.atleast_1d(np.asarray(value, dtype=float))
        require_each(np.isfinite(value), f"sample_flow_at_points {name}", "finite [m]", value,
                     "point")


def zero_power_speed(turbine_definitions) -> float:
    """The highest wind speed at which every turbine's power curve still gives no power (the
    last zero-power entry below its first positive one; the smallest over the turbines), or 0
    when a turbine has no tabulated power curve (the actuator disk): conditions this slow are
    below every cut-in (docs/user_guide.md#calm-and-weak-winds)."""
    speeds = []
    for turbine in turbine_definitions:
        table = turbine.get("power_thrust_table") or {}
        wind_speed, power = table.get("wind_speed"), table.get("power")
        if wind_speed is None or power is None:
            return 0.0
        wind_speed, power = np.asarray(wind_speed, dtype=float), np.asarray(power, dtype=float)
        order = np.argsort(wind_speed)
        wind_speed, power = wind_speed[order], power[order]
        producing = np.flatnonzero(power > 0.0)
        if producing.size == 0 or producing[0] == 0:
            return 0.0
        speeds.append(wind_speed[producing[0] - 1])
    return float(min(speeds)) if speeds else 0.0
