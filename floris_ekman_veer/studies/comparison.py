"""Fair comparisons with FLORIS's built-in wake models on the same Ekman atmosphere.

FLORIS's built-in models (gauss/GCH, cc, jensen, turbopark, empirical_gauss) know an inflow only
through a few scalars. From one atmosphere (the ``ekman_veer.atmosphere`` block) and FLORIS's
reference wind, :func:`builtin_inflow_settings` gives each of them the best information it can use:

``turbulence_intensities``
    I_u(z_h) of the atmosphere (Townsend-Perry, paper Eq. Iu_model, normalised by the hub-height
    speed): every built-in model reads the ambient TI (wake expansion, added turbulence). Above h
    the variance law is continued to its zero at h exp(B1/A1) (docs/atmosphere.md#shallow-boundary-layer).
``wind_veer``
    The direction change across the rotor layer, ``EkmanABL.wind_direction_change(z_h - R,
    z_h + R)`` [deg], positive = veering (clockwise with height, the northern-hemisphere sense).
    What the built-ins do with it (FLORIS 4.7, docs/coupling.md#floris-inflow): gauss (hence GCH) and
    empirical_gauss rotate their elliptical Gaussian cross-section by this single angle (positive
    tilts the wake's top towards -y, the shape northern-hemisphere veer gives; the gauss deflection
    also narrows sigma_y0 by cos(wind_veer)). No built-in shifts a wake with height, which is
    what veer does (this package's deflection model, y_c,veer = x V(z)/U(z)). cc, jensen,
    turbopark and turboparkgauss ignore ``wind_veer`` entirely.
    Caution: at the large rotor-layer veer of strongly stable nights (30-40 degrees) the
    cos(wind_veer) narrowing makes gauss's initial wake so thin and deep that, with the low
    I_u of such nights, its deficit reaches u = 0 on part of a downstream rotor (measured with
    ``inputs/farm_sbl6.yaml`` at 9 m/s, ``examples/farm_main.py --gauss-wind-veer``: 39 degrees
    of veer, the second-row turbine's power falls from 495 kW to 107 kW). Compare with and without it (``wind_veer = 0``) before reading such a
    gauss result as the effect of veer.
``wind_shear``
    A rotor-equivalent power-law exponent: the weighted least-squares fit of
    ln(U(z)/U(z_ref)) = alpha ln(z/z_ref) to the hub-aligned U over the rotor, each height weighted
    by the rotor's chord there (sqrt(R^2 - (z - z_h)^2), i.e. by disk area), anchored at FLORIS's
    reference height as FLORIS's power law is. Only used when the inflow hook is not: with the
    atmosphere block present FLORIS's power law is replaced by the exact profile (and
    ``wind_shear`` is ignored).

FLORIS holds one ``wind_veer`` and one ``wind_shear`` per model, while the atmosphere gives one per
condition; :func:`fair_builtin_set_kwargs` reduces them over conditions (mean by default). For
exact per-condition values build one model per condition.

The comparison this package makes (``annual_energy``, ``examples/yaw_study.py``) is
:func:`comparison_set_kwargs`: I_u(z_h) per condition and ``wind_veer = 0``, for the reason in
the caution above; the fair scalars are shown beside it only as a flagged reference.

The alternative without the hook, :func:`native_inflow_set_kwargs`, exports the profile to
FLORIS's own 3-D ``heterogeneous_inflow_config`` (speed multipliers U(z)/U_ref on an x, y, z box,
with ``wind_shear = 0``). Its limits: it carries the speed only (no V, so no veer at all); the
multipliers are bound to the model's current conditions (n_findex rows: re-export after changing
wind speeds, and UncertainFlorisModel, which expands conditions, and the yaw optimisers, which tile
them, break or misassign them); FLORIS then computes dU/dz = 0 (GCH's secondary steering loses the
shear); U is linear between the z levels (exact at the levels, which include every rotor-grid
height); points outside the box get multiplier 1 (uniform flow); and FLORIS's 3-D interpolation
costs far more than the hook (benchmarks/bench_inflow.py times both; the README's Speed section).
"""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.plugin.inflow.inflow import (
    CONFIG_PATH,
    AtmosphereSpec,
    ambient_velocity,
    atmosphere_of,
    solve,
)

#: Heights sampled across the rotor for the shear fit.
SHEAR_FIT_POINTS = 41


def builtin_inflow_settings(
    atmosphere: dict,
    wind_speeds,
    reference_height: float,
    hub_height: float,
    rotor_diameter: float,
) -> dict:
    """Per-condition inflow scalars for FLORIS's built-in models (see the module docstring).

    Args:
        atmosphere: EkmanABL inputs without the wind speed (the ``ekman_veer.atmosphere`` block;
            values may be per-condition lists), or its validated ``AtmosphereSpec`` (as
            ``inflow.atmosphere_of`` gives it: then the solve is the one the model's inflow hook
            makes, shared through the solve cache).
        wind_speeds: FLORIS's wind speeds [m/s] at ``reference_height``, one per condition.
        reference_height: FLORIS's ``reference_wind_height`` [m].
        hub_height: Hub height z_h [m] of the turbine the values are for.
        rotor_diameter: Rotor diameter D = 2R [m].

    Returns:
        dict of arrays of length n_conditions: ``turbulence_intensities`` (I_u(z_h)),
        ``wind_veer`` [deg] (direction change from z_h - R to z_h + R, positive veering),
        ``wind_shear`` (rotor-equivalent power-law exponent).
    """
    wind_speeds = np.atleast_1d(np.asarray(wind_speeds, dtype=float))
    spec = (atmosphere if isinstance(atmosphere, AtmosphereSpec)
            else AtmosphereSpec.from_mapping(atmosphere))
    abl = solve(spec, wind_speeds, reference_height)
    radius = 0.5 * rotor_diameter
    if hub_height - radius <= np.max(abl.roughness_length):
        raise ValueError(f"the rotor bottom z_h - R = {hub_height - radius} m must be above "
                         f"{CONFIG_PATH}.roughness_length")
    turbulence = abl.turbulence_intensity(hub_height, reference_height=hub_height)
    veer = abl.wind_direction_change(hub_height - radius, hub_height + radius)
    # Chord-weighted fit over the disk (end points have zero weight, so they are skipped).
    offsets = radius * np.linspace(-1.0, 1.0, SHEAR_FIT_POINTS)[1:-1]
    heights = (hub_height + offsets).reshape(1, 1, 1, -1)
    weights = np.sqrt(radius**2 - offsets**2)
    U, _ = abl.hub_aligned_velocity(heights, reference_height)
    U_ref, _ = abl.hub_aligned_velocity(reference_height, reference_height)
    x = np.log(heights / reference_height)
    y = np.log(U / U_ref)
    shear = np.sum(weights * x * y, axis=-1) / np.sum(weights * x * x, axis=-1)
    n = wind_speeds.size
    return {
        "turbulence_intensities": np.broadcast_to(turbulence, (n, 1, 1, 1)).reshape(n),
        "wind_veer": np.broadcast_to(veer, (n, 1, 1, 1)).reshape(n),
        "wind_shear": np.broadcast_to(shear, (n, 1, 1)).reshape(n),
    }


#: FLORIS's scalar ``wind_veer`` [deg] the built-ins get in every comparison of this package
#: (:func:`comparison_set_kwargs`): gauss rotates and, by cos(wind_veer), narrows its wake with
#: it, which at the rotor-layer veer of stable nights measures that narrowing, not veer (see the
#: module docstring); FLORIS's default, 0, leaves the veer to the Ekman inflow and the rotor.
COMPARISON_WIND_VEER = 0.0


def comparison_set_kwargs(atmosphere: dict, wind_speeds, reference_height: float,
                          hub_height: float, rotor_diameter: float) -> dict:
    """``set()`` keywords of the comparison with FLORIS's built-ins on the same Ekman inflow,
    the one ``annual_energy`` and ``examples/yaw_study.py`` use (docs/coupling.md#annual-energy):
    ``turbulence_intensities`` = I_u(z_h) of the atmosphere per condition (as in
    :func:`builtin_inflow_settings`) and ``wind_veer`` = :data:`COMPARISON_WIND_VEER`. FLORIS's
    ``wind_shear`` is left as the input gives it (with the atmosphere block the inflow is the
    exact U(z)). Elementwise per condition, so a condition's values do not depend on the
    others it is computed with.
    """
    settings = builtin_inflow_settings(atmosphere, wind_speeds, reference_height, hub_height,
                                       rotor_diameter)
    return {"turbulence_intensities": settings["turbulence_intensities"],
            "wind_veer": COMPARISON_WIND_VEER}


def _atmosphere_mapping(fmodel) -> dict:
    spec = atmosphere_of(fmodel.core)
    if spec is None:
        raise ValueError(f"the model has no {CONFIG_PATH}")
    return spec.sliced(slice(None))


def fair_builtin_set_kwargs(fmodel, turbine_index: int = 0, reduce=np.mean) -> dict:
    """``fmodel.set()`` keywords giving FLORIS's built-ins the atmosphere's TI, veer and shear.

    Values are for the hub height and rotor of turbine ``turbine_index`` of ``fmodel``, whose
    atmosphere, wind speeds and reference height they follow. ``turbulence_intensities`` is per
    condition; ``wind_veer`` and ``wind_shear``, single floats in FLORIS, are ``reduce``-d over
    conditions (default: mean). Apply them to the model with the atmosphere (the hook keeps the
    exact U(z) and ignores ``wind_shear``) or to a power-law copy
    (``inflow.set_atmosphere(copy, None, **kwargs)``).
    """
    flow_field, farm = fmodel.core.flow_field, fmodel.core.farm
    settings = builtin_inflow_settings(
        _atmosphere_mapping(fmodel),
        flow_field.wind_speeds,
        flow_field.reference_wind_height,
        float(farm.hub_heights.reshape(-1, farm.n_turbines)[0, turbine_index]),
        float(farm.rotor_diameters.reshape(-1, farm.n_turbines)[0, turbine_index]),
    )
    return {
        "turbulence_intensities": settings["turbulence_intensities"],
        "wind_veer": float(reduce(settings["wind_veer"])),
        "wind_shear": float(reduce(settings["wind_shear"])),
    }


def native_inflow_set_kwargs(fmodel, z=None, x_bounds=None, y_bounds=None) -> dict:
    """``set()`` keywords reproducing the Ekman U(z) with FLORIS's native 3-D heterogeneous inflow.

    For users who want no hook: apply to a copy without the atmosphere, e.g.
    ``native = fmodel.copy(); inflow.set_atmosphere(native, None, **native_inflow_set_kwargs(fmodel))``.
    See the module docstring for the limits (speed only, no V, bound to the current n_findex, zero
    dU/dz, breaks UncertainFlorisModel).

    Args:
        fmodel: A model with the atmosphere block and its conditions set.
        z: Heights [m] of the multiplier levels; default 0 to max(3 h, 2 x the top rotor tip),
            41 levels, plus every rotor-grid height of the model (so rotor points are exact).
        x_bounds, y_bounds: Extent of the box [m] in FLORIS's (inertial) x and y; default the
            layout's bounding box padded by 20 rotor diameters and 2 km (points outside get
            multiplier 1: keep flow planes inside).

    Returns:
        ``{"heterogeneous_inflow_config": {...}, "wind_shear": 0.0}``; the multipliers are
        U(z)/U(z_ref) per condition, shape (n_findex, n_points).
    """
    flow_field, farm, grid = fmodel.core.flow_field, fmodel.core.farm, fmodel.core.grid
    abl = solve(atmosphere_of(fmodel.core), flow_field.wind_speeds,
                flow_field.reference_wind_height)
    if z is None:
        top = max(3.0 * float(np.max(abl.boundary_layer_height)),
                  2.0 * float(np.max(farm.hub_heights + 0.5 * farm.rotor_diameters)))
        z = np.union1d(np.linspace(0.0, top, 41), np.unique(grid.z_sorted))
    z = np.unique(np.asarray(z, dtype=float))
    pad = 20.0 * float(np.max(farm.rotor_diameters)) + 2000.0
    if x_bounds is None:
        x_bounds = (float(np.min(farm.layout_x)) - pad, float(np.max(farm.layout_x)) + pad)
    if y_bounds is None:
        y_bounds = (float(np.min(farm.layout_y)) - pad, float(np.max(farm.layout_y)) + pad)
    # Four columns at the box corners: the multipliers vary with z only, and FLORIS's Delaunay
    # interpolation of such data is exactly linear in z within each layer.
    x, y, zz = np.meshgrid(x_bounds, y_bounds, z, indexing="ij")
    x, y, zz = x.ravel(), y.ravel(), zz.ravel()
    U, _ = ambient_velocity(abl, zz.reshape(1, 1, 1, -1), flow_field.reference_wind_height)
    multipliers = np.broadcast_to(U, (flow_field.n_findex, 1, 1, zz.size)).reshape(
        flow_field.n_findex, -1) / flow_field.wind_speeds[:, None]
    return {
        "heterogeneous_inflow_config": {
            "x": x.tolist(), "y": y.tolist(), "z": zz.tolist(),
            "speed_multipliers": multipliers.tolist(),
        },
        "wind_shear": 0.0,
    }


#: Wake set-ups of FLORIS 4.7's example inputs (gch.yaml, gauss.yaml and cc.yaml in its
#: examples folder): model names, their combination (sosfs) and the three GCH switches. Their parameter blocks are those
#: of the input they are applied to (FLORIS's defaults where it has none).
BUILTIN_WAKES = {
    "gch": ({"velocity_model": "gauss", "deflection_model": "gauss", "combination_model": "sosfs"},
            True),
    "gauss": ({"velocity_model": "gauss", "deflection_model": "gauss",
               "combination_model": "sosfs"}, False),
    "cc": ({"velocity_model": "cc", "deflection_model": "gauss", "combination_model": "sosfs"},
           True),
}
GCH_SWITCHES = ("enable_secondary_steering", "enable_yaw_added_recovery",
                "enable_transverse_velocities")


def builtin_model(fmodel, name: str):
    """A copy of ``fmodel`` running FLORIS's wake set-up ``name`` (a key of
    :data:`BUILTIN_WAKES`) on the same farm, conditions and atmosphere block (so the same Ekman
    inflow); its class (FlorisModel, ParFlorisModel...) is kept, operation set-points are not
    (as with ``FlorisModel.copy()``). Combine with :func:`fair_builtin_set_kwargs` for the inflow scalars."""
    if name not in BUILTIN_WAKES:
        raise ValueError(f"builtin_model: name must be one of {sorted(BUILTIN_WAKES)}, got {name!r}")
    model_strings, gch = BUILTIN_WAKES[name]
    # As FlorisModel.copy(), from the Core's dictionary, with the wake edited.
    config = fmodel.core.as_dict()
    config["wake"]["model_strings"].update(model_strings)
    config["wake"].update(dict.fromkeys(GCH_SWITCHES, gch))
    return type(fmodel)(config, **fmodel.secondary_init_kwargs)
