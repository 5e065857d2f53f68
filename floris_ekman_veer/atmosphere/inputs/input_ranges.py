"""The valid ranges of the atmosphere's inputs and their checks (docs/atmosphere.md#input-ranges):
each input's range as the error messages state it (`VALID_RANGES`), the bounds that catch unit
mistakes, and the checks that name the input, its range and the offending entries."""

from __future__ import annotations

import numpy as np

from floris_ekman_veer._validation import finite_real, require_at
from floris_ekman_veer.atmosphere.constants import EARTH_ROTATION_RATE
from floris_ekman_veer.atmosphere.turbulence import (
    ALPHA_PRIME,
    MERGE_EXPONENT,
    MIXING_LAYER_FLOOR,
    TOWNSEND_PERRY_A1,
    TOWNSEND_PERRY_B1,
)

#: Below this |latitude| the f-plane Ekman balance degenerates (f_c -> 0 at the equator).
MIN_ABS_LATITUDE = 1.0
#: Valid range of |f_c| [1/s]: 2 Omega sin(1 deg) (the equatorial limit above) to 2 Omega (a pole).
MIN_CORIOLIS_PARAMETER = 2.0 * EARTH_ROTATION_RATE * np.sin(np.deg2rad(MIN_ABS_LATITUDE))
MAX_CORIOLIS_PARAMETER = 2.0 * EARTH_ROTATION_RATE
#: Sensible heat flux bounds [W/m^2]: beyond the strongest nocturnal (about -100) and desert
#: afternoon (about +600) surface fluxes; they catch kW/m^2 and other unit mistakes.
SENSIBLE_HEAT_FLUX_RANGE = (-300.0, 800.0)
_EITHER_SIGN = "negative for convective (unstable) layers"
#: Physical bounds of the thermal inputs (docs/atmosphere.md#input-ranges): they catch unit
#: mistakes (a potential temperature in degrees Celsius, a lapse rate in K/km, a cooling rate in
#: K/day) that the model would otherwise solve into boundary layers millimetres deep.
#: Theta0 [K]: near-surface potential temperatures on Earth (-73 to +77 degrees C).
POTENTIAL_TEMPERATURE_RANGE = (200.0, 350.0)
#: Free-atmosphere lapse rate dTheta/dz [K/m]: 0 (neutral) to 0.1 K/m, ten times the
#: troposphere's typical 3-10 K/km and the strongest inversions' order of magnitude.
MAX_LAPSE_RATE = 0.1
#: Surface cooling rate C_r [K/h]: 0 to -10 K/h, beyond the strongest clear-sky nocturnal
#: cooling (a few K/h; the paper's strongest case, SBL-6, is -1 K/h).
MIN_COOLING_RATE = -10.0
#: The shallowest boundary layer the model accepts [m]: 10 m, below which no rotor and no
#: measurement mast stands inside the Ekman-surface-layer profile (its surface layer, 0.2 h,
#: would be 2 m deep); shallower solutions raise ValueError (docs/atmosphere.md#shallow-boundary-layer).
MIN_BOUNDARY_LAYER_HEIGHT = 10.0
#: The deepest convective mixed layer accepted [m]: afternoon layers over land reach 1-2 km, over
#: deserts 4-5 km (Stull 1988, An Introduction to Boundary Layer Meteorology; Garratt
#: 1992, The Atmospheric Boundary Layer); a z_i in feet or above the troposphere's
#: lower half is refused (docs/atmosphere.md#physical-domain).
MAX_MIXED_LAYER_HEIGHT = 5000.0
#: The strongest geostrophic wind accepted [m/s]: above the 50-60 m/s of the deepest
#: extratropical storms at the boundary-layer top; the gradient winds of tropical cyclones are
#: cyclostrophic, outside the f-plane Ekman balance (docs/atmosphere.md#physical-domain).
MAX_GEOSTROPHIC_WIND = 75.0
#: The largest cross-isobaric angle of a convective layer [deg]: the laminar Ekman layer's 45 deg
#: (Ekman 1905) bounds the turning of a layer mixed at least as strongly; convective layers turn
#: the wind less than neutral ones (docs/atmosphere.md#physical-domain).
MAX_CONVECTIVE_CROSS_ISOBARIC_ANGLE = 45.0
#: The largest ambient turbulence factor accepted (docs/atmosphere.md#ambient-turbulence): a
#: site's streamwise turbulence is typically 0.8-1.5 times the model's neutral I_u (terrain,
#: upwind roughness), and on weak-wind stable nights the meandering of submeso motions can make
#: it several times the model's (Mahrt 2014); 10 is beyond both and catches a factor given in
#: percent (120).
MAX_TURBULENCE_FACTOR = 10.0
#: Valid range of every EkmanABL input, as the error messages and docs/atmosphere.md#input-ranges
#: state it. Every input is a real number or an array of them (strings and booleans are refused).
VALID_RANGES = {
    "geostrophic_wind": "> 0 m/s",
    "coriolis_parameter": (
        f"{MIN_CORIOLIS_PARAMETER:.4g} <= |f_c| <= 2 Omega = {MAX_CORIOLIS_PARAMETER:.4g} 1/s "
        "(|latitude| 1 to 90 deg, negative in the south; the Ekman balance has no solution at "
        "the equator, f_c = 0)"
    ),
    "latitude": (
        f"{MIN_ABS_LATITUDE:g} <= |latitude| <= 90 deg, negative in the south (the Ekman model "
        "has no solution at the equator, where f_c = 0)"
    ),
    "roughness_length": "> 0 m",
    "reference_potential_temperature": (
        f"{POTENTIAL_TEMPERATURE_RANGE[0]:g} to {POTENTIAL_TEMPERATURE_RANGE[1]:g} K (a potential "
        "temperature in kelvin, not degrees Celsius)"
    ),
    "brunt_vaisala_frequency": ">= 0 1/s",
    "lapse_rate": (
        f"0 to {MAX_LAPSE_RATE:g} K/m (a neutral or stably stratified free atmosphere; in K/m, "
        "not K/km)"
    ),
    "stability_parameter": f"finite; >= 0 stable or neutral, < 0 convective ({_EITHER_SIGN})",
    "cooling_rate": (
        f"{MIN_COOLING_RATE:g} to {-MIN_COOLING_RATE:g} K/h, the surface's rate of temperature "
        "change in kelvin per hour (negative: cooling, a stable layer; positive: heating, a "
        "convective layer)"
    ),
    "surface_heat_flux": (
        "the kinematic upward heat flux Q0 [K m/s] with rho c_p Q0 within "
        f"{SENSIBLE_HEAT_FLUX_RANGE[0]:g} to {SENSIBLE_HEAT_FLUX_RANGE[1]:g} W/m^2 (-0.227 to "
        "0.606 K m/s at the default 265 K; negative: stable; positive: convective — for W/m^2 "
        "use sensible_heat_flux)"
    ),
    "sensible_heat_flux": (
        f"{SENSIBLE_HEAT_FLUX_RANGE[0]:g} to {SENSIBLE_HEAT_FLUX_RANGE[1]:g} W/m^2, the upward "
        "surface sensible heat flux (negative at night: stable; positive by day: convective)"
    ),
    "obukhov_length": (
        "> 0 m stable, < 0 m convective (unstable), inf or -inf neutral; not 0 and not NaN"
    ),
    "mixed_layer_height": (
        f"{MIN_BOUNDARY_LAYER_HEIGHT:g} to {MAX_MIXED_LAYER_HEIGHT:g} m, the convective "
        "mixed-layer depth z_i (used where the layer is convective; default: the neutral height "
        "of Eq. h_hat_model)"
    ),
    "turbulence_factor": (
        f"> 0 and <= {MAX_TURBULENCE_FACTOR:g}, the site's ambient streamwise turbulence over the "
        "model's I_u of Eq. Iu_model (1 = the paper's; a ratio, not a percentage)"
    ),
    **{name: "> 0 and finite (a model constant)"
       for name in ("von_karman", "c_g", "stress_decay", "c_tn", "c_cn", "c_ns",
                    "businger_dyer_gamma")},
    "matching_fraction": "in (0, 1)",
}


def checked(name, value, ok, valid=None):
    """``value`` as a float array of real numbers with ``ok`` true everywhere (finite implied),
    else ValueError naming ``name``, its valid range (default its VALID_RANGES entry) and the
    offending entries."""
    valid = VALID_RANGES[name] if valid is None else valid
    array = finite_real(name, value, valid)
    require_at(ok(array), name, valid, array)
    return array


def within_heat_flux_range(sensible_heat_flux):
    """The physical domain's sensible heat flux bounds [W/m^2] (NaN outside)."""
    return (sensible_heat_flux >= SENSIBLE_HEAT_FLUX_RANGE[0]) & (
        sensible_heat_flux <= SENSIBLE_HEAT_FLUX_RANGE[1])


def require_broadcastable(named) -> None:
    """ValueError naming two inputs whose shapes do not broadcast together (numpy's rules: one
    number, or arrays of one shape with one entry per condition)."""
    shapes = {name: np.shape(value) for name, value in named.items()}
    try:
        np.broadcast_shapes(*shapes.values())
    except ValueError:
        names = list(shapes)
        for k, first in enumerate(names):
            for second in names[k + 1:]:
                try:
                    np.broadcast_shapes(shapes[first], shapes[second])
                except ValueError:
                    raise ValueError(
                        f"{first} (shape {shapes[first]}) and {second} (shape {shapes[second]}) "
                        "do not broadcast together: give single numbers, or arrays of one shape "
                        "(one entry per condition)"
                    ) from None
        raise ValueError(
            "the inputs' shapes do not broadcast together: "
            + ", ".join(f"{name} {shape}" for name, shape in shapes.items())
        ) from None


#: The constants of Eqs. (Iu_model) and (kw_CNBL_SBL_model) the profile methods take, with the
#: paper's values: each one positive number.
TURBULENCE_CONSTANTS = {"A1": TOWNSEND_PERRY_A1, "B1": TOWNSEND_PERRY_B1,
                        "alpha_prime": ALPHA_PRIME, "floor": MIXING_LAYER_FLOOR,
                        "n": MERGE_EXPONENT}


def checked_turbulence_constants(**constants):
    """``constants`` checked: known names (`TURBULENCE_CONSTANTS`), each one positive number."""
    unknown = sorted(set(constants) - set(TURBULENCE_CONSTANTS))
    if unknown:
        raise ValueError(f"unknown constant(s) {unknown}; the constants are "
                         f"{sorted(TURBULENCE_CONSTANTS)}")
    # the model block's ranges (docs/user_guide.md#valid-input-ranges): B1 may be 0, n >= 1
    lowest = {"B1": (0.0, ">="), "n": (1.0, ">=")}
    values = {}
    for name, value in constants.items():
        low, sign = lowest.get(name, (0.0, ">"))
        values[name] = float(checked(
            name, value,
            lambda v: (np.ndim(v) == 0) & ((v >= low) if sign == ">=" else (v > low)),
            f"one number {sign} {low:g} (the paper's {TURBULENCE_CONSTANTS[name]:g})"))
    return values
