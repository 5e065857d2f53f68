"""Coupled Ekman-surface-layer ABL model (paper Section 2.5; Narasimhan et al., BLM 2024).

The unknowns u*, h, U_g, V_g (and alpha_0) follow from the ABL-height law
Eq. (h_hat_model) and the geostrophic drag law (GDL), Eqs. (GDL), (A_model_GDL),
(B_model_GDL), solved together for a given geostrophic wind G. The mean wind is then
Eq. (U_vel) (Monin-Obukhov surface layer below the matching height 0.2 h, Ekman layer
above) and Eq. (V_vel), closed below about e z0 by a roughness sublayer in which the wind
falls linearly to 0 at the ground (docs/atmosphere.md#roughness-sublayer).

Frames and signs (docs/conventions.md#frames-and-signs): x along the surface stress; in the northern
hemisphere kappa V_g/u* = -B < 0, so the signed cross-isobaric angle
alpha_0 = atan2(V_g, U_g) is negative; in the southern hemisphere V and V_g change sign.

Everything is vectorised: every input broadcasts by numpy rules, the solved scalars have
the broadcast shape of the inputs, and the profile methods broadcast heights against that
shape (give conditions shape ``(n, 1, 1, 1)`` to evaluate on FLORIS's 4-D grids).

Solver: with the stability closure written as mu(u*) (explicit for mu, Q0 or L; a cubic
for the cooling-rate closure Q0 = C_r h, solved by monotone Newton), the GDL reduces to one
scalar equation in ln u*, |(U_g, V_g)|(u*) = G, solved for all conditions at once by
fixed-point steps then bracketed secant steps on the physical branch U_g > 0. Driven by a
reference wind instead of G (`EkmanABL.from_reference_wind`), the same parametrisation by u*
makes the speed at the reference height explicit; its root is bracketed by the collapse threshold
(docs/atmosphere.md#reference-wind-solve).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer._validation import finite_real, real_array, require_at
from floris_ekman_veer.atmosphere.stability_inputs import STABILITY_INPUTS
from floris_ekman_veer.atmosphere.turbulence import (
    ALPHA_PRIME,
    MERGE_EXPONENT,
    MIXING_LAYER_FLOOR,
    TOWNSEND_PERRY_A1,
    TOWNSEND_PERRY_B1,
    convective_variance,
    streamwise_turbulence_intensity,
    wake_expansion_rate,
)

#: Gravitational acceleration [m/s^2] (paper Section 2.5).
GRAVITY = 9.81
#: Earth's rotation rate Omega [1/s] (paper Section 2.5).
EARTH_ROTATION_RATE = 7.27e-5
#: Below this |latitude| the f-plane Ekman balance degenerates (f_c -> 0 at the equator).
MIN_ABS_LATITUDE = 1.0
#: Valid range of |f_c| [1/s]: 2 Omega sin(1 deg) (the equatorial limit above) to 2 Omega (a pole).
MIN_CORIOLIS_PARAMETER = 2.0 * EARTH_ROTATION_RATE * np.sin(np.deg2rad(MIN_ABS_LATITUDE))
MAX_CORIOLIS_PARAMETER = 2.0 * EARTH_ROTATION_RATE
#: Paper's free-atmosphere Brunt-Vaisala frequency N_inf [1/s] (Table 1 caption).
PAPER_BRUNT_VAISALA_FREQUENCY = 6.1e-3
#: Paper's reference potential temperature Theta_0 [K] (Table 1 caption).
PAPER_POTENTIAL_TEMPERATURE = 265.0

#: Businger-Dyer unstable surface layer phi_m = (1 - gamma z/L)^(-1/4): gamma = 16 (Dyer 1974;
#: Businger et al. 1971's form), or 19.3 (Hogstrom 1988) through ``businger_dyer_gamma``
#: (docs/atmosphere.md#convective-boundary-layer).
BUSINGER_DYER_GAMMA = 16.0
HOGSTROM_GAMMA = 19.3
#: Entrainment heat flux at z_i as a fraction of the surface flux, -A_e Q0 (Tennekes 1973):
#: a mixed layer of depth z_i warms at (1 + A_e) Q0 / z_i.
ENTRAINMENT_RATIO = 0.2
#: Specific heat of dry air c_p [J/(kg K)], gas constant R_d [J/(kg K)] and the reference
#: pressure [Pa] of the potential temperature: rho c_p = c_p p0 / (R_d Theta0) turns a sensible
#: heat flux H [W/m^2] into the kinematic flux Q0 = H/(rho c_p) [K m/s].
SPECIFIC_HEAT_AIR = 1005.0
GAS_CONSTANT_DRY_AIR = 287.05
REFERENCE_PRESSURE = 1.0e5
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
#: The physical domain of a solved atmosphere, whichever stability input drives it
#: (`physical_domain`, docs/atmosphere.md#physical-domain): the implied quantity, its range and
#: its unit. The cross-isobaric angle's bound holds where the layer is convective (mu < 0).
PHYSICAL_DOMAIN = {
    "sensible_heat_flux": (SENSIBLE_HEAT_FLUX_RANGE[0], SENSIBLE_HEAT_FLUX_RANGE[1], "W/m^2"),
    "geostrophic_wind": (0.0, MAX_GEOSTROPHIC_WIND, "m/s"),
    "cross_isobaric_angle": (
        -MAX_CONVECTIVE_CROSS_ISOBARIC_ANGLE, MAX_CONVECTIVE_CROSS_ISOBARIC_ANGLE, "deg"
    ),
}
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
    **{name: "> 0 and finite (a model constant)"
       for name in ("von_karman", "c_g", "stress_decay", "c_tn", "c_cn", "c_ns",
                    "businger_dyer_gamma")},
    "matching_fraction": "in (0, 1)",
}

_SOLVER_TOLERANCE = 1e-14
_SOLVER_MAX_ITERATIONS = 200

# Marks a construction that only validates the inputs (EkmanABL.check_inputs).
_INPUTS_ONLY = object()


def _checked(name, value, ok, valid=None):
    """``value`` as a float array of real numbers with ``ok`` true everywhere (finite implied),
    else ValueError naming ``name``, its valid range (default its VALID_RANGES entry) and the
    offending entries."""
    valid = VALID_RANGES[name] if valid is None else valid
    array = finite_real(name, value, valid)
    require_at(ok(array), name, valid, array)
    return array


def _within_heat_flux_range(sensible_heat_flux):
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


class DomainCheck(NamedTuple):
    """Where states lie in the `PHYSICAL_DOMAIN` (`physical_domain`); every array has the
    states' broadcast shape.

    - ``inside``: bool, True where every bound holds;
    - ``binding``: str, the name of the first bound a state leaves (in `PHYSICAL_DOMAIN`'s
      order), "" inside;
    - ``margin``: float, the smallest relative slack over the bounds, (value - bound)/|range
      end| on the side that binds: > 0 inside, <= 0 outside (a continuous constraint value for
      a fit that keeps its trial states inside);
    - ``values``: the implied quantities checked, by name.
    """

    inside: np.ndarray
    binding: np.ndarray
    margin: np.ndarray
    values: dict


def physical_domain(sensible_heat_flux, geostrophic_wind, cross_isobaric_angle,
                    stability_parameter) -> DomainCheck:
    """Which bound of the `PHYSICAL_DOMAIN` each state leaves, vectorised, without raising
    (docs/atmosphere.md#physical-domain): the surface sensible heat flux H [W/m^2], the
    geostrophic wind G [m/s] and, where the layer is convective (``stability_parameter`` mu < 0),
    the cross-isobaric angle [deg]. Arguments broadcast together; NaN counts as outside.
    `EkmanABL.physical_domain` applies it to a solved atmosphere, whichever stability input
    drove it; the constructor and `EkmanABL.from_reference_wind` refuse states outside."""
    values = {
        "sensible_heat_flux": np.asarray(sensible_heat_flux, dtype=float),
        "geostrophic_wind": np.asarray(geostrophic_wind, dtype=float),
        "cross_isobaric_angle": np.asarray(cross_isobaric_angle, dtype=float),
    }
    convective = np.asarray(stability_parameter, dtype=float) < 0
    shape = np.broadcast_shapes(convective.shape, *(v.shape for v in values.values()))
    binding = np.full(shape, "", dtype=object)
    margin = np.full(shape, np.inf)
    for name, value in values.items():
        low, high, _ = PHYSICAL_DOMAIN[name]
        with np.errstate(invalid="ignore"):
            slack = np.minimum(
                (value - low) / max(abs(low), 1.0) if low < 0 else (value - low) / high,
                (high - value) / high,
            )
        slack = np.where(np.isnan(slack), -np.inf, slack)
        if name == "cross_isobaric_angle":
            slack = np.where(convective, slack, np.inf)
        binding = np.where((binding == "") & (slack <= 0), name, binding)
        margin = np.minimum(margin, slack)
    inside = binding == ""
    return DomainCheck(inside[()], binding[()], margin[()],
                       {k: np.broadcast_to(v, shape)[()] for k, v in values.items()})


def coriolis_parameter_from_latitude(latitude):
    """f_c = 2 Omega sin(phi) [1/s]; latitude in degrees, negative in the south."""
    latitude = _checked(
        "latitude", latitude, lambda lat: (np.abs(lat) >= MIN_ABS_LATITUDE) & (np.abs(lat) <= 90.0)
    )
    return 2.0 * EARTH_ROTATION_RATE * np.sin(np.deg2rad(latitude))


def boundary_layer_height_hat(stability_parameter, zilitinkevich_number, c_tn, c_cn, c_ns):
    """h_hat = h f_c/u* from 1/h_hat^2 = 1/C_TN^2 + mu_N/C_CN^2 + mu/C_NS^2, Eq. (h_hat_model)."""
    # np.power, not **: on a numpy scalar (one condition) ** takes C's pow, whose last bit can
    # differ from numpy's array loop; np.power gives a condition the same bits alone as in a batch.
    return np.power(1.0 / c_tn**2 + zilitinkevich_number / c_cn**2 + stability_parameter / c_ns**2,
                    -0.5)


def air_heat_capacity(reference_potential_temperature):
    """rho c_p [J/(m^3 K)] of dry air at the potential temperature's reference pressure:
    c_p p0/(R_d Theta0) (1321 at the paper's 265 K, 1216 at 288 K)."""
    return SPECIFIC_HEAT_AIR * REFERENCE_PRESSURE / (
        GAS_CONSTANT_DRY_AIR * np.asarray(reference_potential_temperature, dtype=float)
    )


def unstable_phi_m(zeta, gamma=BUSINGER_DYER_GAMMA):
    """phi_m(z/L) = (1 - gamma z/L)^(-1/4) for z/L <= 0: the Businger-Dyer dimensionless shear
    (Businger et al. 1971; Dyer 1974, gamma = 16; Hogstrom 1988, gamma = 19.3)."""
    return np.power(1.0 - gamma * np.minimum(zeta, 0.0), -0.25)  # (np.power: see h_hat)


def unstable_psi_m(zeta, gamma=BUSINGER_DYER_GAMMA):
    """psi_m(z/L) = int_0^zeta (1 - phi_m)/zeta' dzeta' for z/L <= 0, Paulson (1970)'s integral of
    the Businger-Dyer phi_m: 2 ln((1+x)/2) + ln((1+x^2)/2) - 2 atan(x) + pi/2, x = 1/phi_m."""
    x = np.power(1.0 - gamma * np.minimum(zeta, 0.0), 0.25)
    return (
        2.0 * np.log(0.5 * (1.0 + x)) + np.log(0.5 * (1.0 + x * x)) - 2.0 * np.arctan(x)
        + 0.5 * np.pi
    )


def stability_term(mu, xi, xi0, kappa, gamma=BUSINGER_DYER_GAMMA):
    """The stability part of the surface-layer U/u*, -(psi_m(z/L) - psi_m(z0/L))/kappa with
    z/L = kappa mu xi: 5 mu (xi - xi0) for mu >= 0 (the paper's Eq. U_vel, psi_m = -5 z/L) and
    the Businger-Dyer psi_m of `unstable_psi_m` for mu < 0 (docs/atmosphere.md#convective-boundary-layer)."""
    mu = np.asarray(mu, dtype=float)
    unstable = mu < 0
    stable = 5.0 * np.maximum(mu, 0.0) * (xi - xi0)
    if not unstable.any():
        # Nights and neutral days skip the Businger-Dyer evaluation, the profile's largest cost.
        return stable
    k_mu = kappa * np.minimum(mu, 0.0)
    convective = -(unstable_psi_m(k_mu * xi, gamma) - unstable_psi_m(k_mu * xi0, gamma)) / kappa
    return np.where(unstable, convective, stable)


def stress_shape(xi_over_h, h_hat, c_g, decay):
    """g and g' of Eq. (eqn:avoidnumbers1): g = c_g (1 - exp(-xi/(Gamma h_hat)))."""
    e = np.exp(-xi_over_h / decay)
    return c_g * (1.0 - e), c_g / (decay * h_hat) * e


def gdl_coefficients(
    stability_parameter, zilitinkevich_number, h_hat, rossby_number, kappa, c_g, decay, matching,
    gamma=BUSINGER_DYER_GAMMA,
):
    """GDL coefficients A and B, Eqs. (A_model_GDL) and (B_model_GDL).

    ``rossby_number`` is the surface Rossby number u*/(|f_c| z0) = 1/xi0_hat. The paper
    prints 0.2 and 0.8 = 1 - 0.2; ``matching`` is that fraction. For mu < 0 the paper's
    5 mu (0.2 h_hat - xi0) is the Businger-Dyer `stability_term` at the matching height, the
    same matching of the surface layer to the Ekman layer, so A = A_N + psi_m(0.2 h/L) - psi_m(z0/L):
    the stability part of Brutsaert (1999)'s bulk similarity function B_w with its alpha_t the
    matching fraction (docs/atmosphere.md#the-geostrophic-drag-law-of-a-convective-layer).
    """
    g_m, dg_m = stress_shape(matching, h_hat, c_g, decay)
    xi_m, xi0 = matching * h_hat, 1.0 / rossby_number
    a = -np.log(matching * h_hat) - kappa * (
        stability_term(stability_parameter, xi_m, xi0, kappa, gamma)
        + 0.3 * zilitinkevich_number * (xi_m - xi0)
        + dg_m * (1.0 - matching) ** 1.5
        - g_m * (1.5 / h_hat) * (1.0 - matching) ** 0.5
    )
    b = 1.5 * kappa / h_hat
    return a, b


def stability_from_cooling_rate(cooling_rate_per_second, friction_velocity, coriolis, theta0, a0, c_ns):
    """mu for the closure Q0 = C_r h (docs/atmosphere.md#stability-closures).

    mu = -(g/Theta0) C_r h_hat(mu) / (f_c^2 u*) with h_hat(mu) = (a0 + mu/C_NS^2)^(-1/2), i.e.
    mu^3/C_NS^2 + a0 mu^2 - c^2 = 0, c = -(g/Theta0) C_r/(f_c^2 u*) >= 0. The cubic is convex
    and increasing for mu > 0, so Newton started from an upper bound converges monotonically.
    """
    c2 = (-(GRAVITY / theta0) * cooling_rate_per_second / (coriolis**2 * friction_velocity)) ** 2
    inv_c2 = 1.0 / c_ns**2
    mu = np.minimum(np.cbrt(c2 / inv_c2), np.sqrt(c2 / a0))
    active = np.ones(np.shape(mu), dtype=bool)
    for _ in range(30):
        p = inv_c2 * mu**3 + a0 * mu**2 - c2
        dp = 3.0 * inv_c2 * mu**2 + 2.0 * a0 * mu
        d2p = 6.0 * inv_c2 * mu + 2.0 * a0
        # Halley's step: cubic convergence, and it stays above the root like Newton's here.
        denom = 2.0 * dp**2 - p * d2p
        step = np.divide(2.0 * p * dp, denom, out=np.zeros_like(mu), where=active & (denom > 0))
        mu = mu - step
        # Converged elements are frozen, so that a condition's mu does not depend on the others
        # solved with it (the same bits alone as in a batch).
        active &= np.abs(step) > 1e-14 * mu
        if not np.any(active):
            break
    return mu


def secant_root(residual, lo, hi, tolerance=_SOLVER_TOLERANCE):
    """Element-wise roots of a smooth increasing residual over full arrays: the bracket
    [lo, hi] is widened (doubling) until it holds the sign change, then secant steps are
    taken, replaced by bisection whenever they leave the bracket. -inf in the residual marks
    points known to lie below the root. Returns (x, converged).

    Used for the GDL's u*, which a good start puts within ~0.1 % of the root, so a handful of
    whole-array steps beat a general method's per-element bookkeeping.
    """
    r_lo, r_hi = residual(lo), residual(hi)
    for _ in range(40):
        walk_lo, walk_hi = r_lo >= 0, r_hi < 0
        if not np.any(walk_lo | walk_hi):
            break
        width = hi - lo
        lo, hi = np.where(walk_lo, lo - width, lo), np.where(walk_hi, hi + width, hi)
        r_lo, r_hi = residual(lo), residual(hi)
    bracketed = (r_lo < 0) & (r_hi >= 0)
    x_prev, r_prev, x, r = lo, r_lo, hi, r_hi
    for _ in range(_SOLVER_MAX_ITERATIONS):
        # Converged elements are frozen, so that each element's root does not depend on the
        # others solved with it (a chunk of conditions gives the numbers of the whole set).
        active = bracketed & (np.abs(r) > tolerance)
        if not np.any(active):
            break
        with np.errstate(divide="ignore", invalid="ignore"):
            secant = x - r * (x - x_prev) / (r - r_prev)
        inside = np.isfinite(secant) & (secant > lo) & (secant < hi)
        x_prev, r_prev = np.where(active, x, x_prev), np.where(active, r, r_prev)
        x = np.where(active, np.where(inside, secant, 0.5 * (lo + hi)), x)
        r = residual(x)
        below = active & (r < 0)
        lo, hi = np.where(below, x, lo), np.where(active & ~below, x, hi)
    return x, bracketed & (np.abs(r) <= tolerance)


class EkmanABL:
    """Coupled Ekman-surface-layer atmospheric boundary layer, solved for given G.

    Keyword inputs (all broadcast together; conditions may be arrays):

    - ``geostrophic_wind`` G [m/s], > 0.
    - Coriolis: ``coriolis_parameter`` f_c [1/s] (signed: negative in the southern
      hemisphere) or ``latitude`` [deg, negative = south]; |latitude| >= 1 degree, i.e.
      |f_c| >= 2 Omega sin(1 deg): the model has no solution at the equator.
    - ``roughness_length`` z0 [m], > 0.
    - Stability, at most one of, of either sign (negative mu or L, positive heat flux or
      heating rate: a convective layer, docs/atmosphere.md#convective-boundary-layer):
      ``stability_parameter`` mu = u*/(kappa f_c L); ``cooling_rate`` C_r [K/h] with
      Q0 = C_r h when cooling (paper Section 2.5), Q0 = C_r z_i/(1 + A_e) when heating;
      ``surface_heat_flux`` Q0 [K m/s]; ``sensible_heat_flux`` H [W/m^2] = rho c_p Q0;
      ``obukhov_length`` L [m] (+-inf = neutral). Default: neutral (mu = 0).
    - ``mixed_layer_height`` z_i [m], the depth of a convective layer (used where mu < 0;
      default the neutral height of Eq. h_hat_model at the same u*).
    - Free atmosphere, at most one of ``brunt_vaisala_frequency`` N [1/s] >= 0 or
      ``lapse_rate`` dTheta/dz [K/m] >= 0 (N = sqrt(g/Theta0 gamma)); default the paper's
      N_inf = 6.1e-3 1/s. Enters through the Zilitinkevich number mu_N = N/|f_c|.
    - ``reference_potential_temperature`` Theta0 [K], default the paper's 265 K.
    - Model constants: ``von_karman`` 0.41, ``c_g`` 1.43, ``stress_decay`` (Gamma) 0.83,
      ``c_tn`` 0.5, ``c_cn`` 1.6, ``c_ns`` 0.78, ``matching_fraction`` 0.2, and, beyond the
      paper, ``businger_dyer_gamma`` 16 (Dyer 1974; 19.3 for Hogstrom 1988).

    Solved attributes: ``friction_velocity`` [m/s], ``boundary_layer_height`` [m],
    ``cross_isobaric_angle`` [deg, signed, surface-stress frame], ``stability_parameter``
    (mu, also when derived from C_r, Q0 or L), ``zilitinkevich_number`` mu_N,
    ``geostrophic_components`` (U_g, V_g), ``coriolis_parameter`` (signed), and the
    dimensionless ``h_hat`` = h f_c/u* with the GDL coefficients ``gdl_a``, ``gdl_b`` (A, B).
    """

    #: The entrainment ratio A_e of the heating-rate closure (`ENTRAINMENT_RATIO`).
    entrainment_ratio = ENTRAINMENT_RATIO

    def __init__(
        self,
        *,
        geostrophic_wind,
        coriolis_parameter=None,
        latitude=None,
        roughness_length,
        stability_parameter=None,
        cooling_rate=None,
        surface_heat_flux=None,
        obukhov_length=None,
        sensible_heat_flux=None,
        mixed_layer_height=None,
        brunt_vaisala_frequency=None,
        lapse_rate=None,
        reference_potential_temperature=PAPER_POTENTIAL_TEMPERATURE,
        von_karman=0.41,
        c_g=1.43,
        stress_decay=0.83,
        c_tn=0.5,
        c_cn=1.6,
        c_ns=0.78,
        matching_fraction=0.2,
        businger_dyer_gamma=BUSINGER_DYER_GAMMA,
    ):
        self._set_constants(von_karman, c_g, stress_decay, c_tn, c_cn, c_ns, matching_fraction)
        self.businger_dyer_gamma = float(_checked(
            "businger_dyer_gamma", businger_dyer_gamma, lambda v: (v > 0) & (np.ndim(v) == 0)
        ))
        self._set_coriolis(coriolis_parameter, latitude)
        self.roughness_length = _checked("roughness_length", roughness_length, lambda z0: z0 > 0)
        self.reference_potential_temperature = _checked(
            "reference_potential_temperature", reference_potential_temperature,
            lambda t: (t >= POTENTIAL_TEMPERATURE_RANGE[0]) & (t <= POTENTIAL_TEMPERATURE_RANGE[1]),
        )
        self._set_free_atmosphere(brunt_vaisala_frequency, lapse_rate)
        self._set_stability_closure(
            stability_parameter, cooling_rate, surface_heat_flux, obukhov_length,
            sensible_heat_flux,
        )
        self.mixed_layer_height = None if mixed_layer_height is None else _checked(
            "mixed_layer_height", mixed_layer_height,
            lambda z: (z >= MIN_BOUNDARY_LAYER_HEIGHT) & (z <= MAX_MIXED_LAYER_HEIGHT),
        )
        given = {
            "coriolis_parameter" if latitude is None else "latitude": self.coriolis_parameter,
            "roughness_length": self.roughness_length,
            "reference_potential_temperature": self.reference_potential_temperature,
            "lapse_rate" if lapse_rate is not None else "brunt_vaisala_frequency":
                self.brunt_vaisala_frequency,
            self.stability_input: self._stability_value,
        }
        if self.mixed_layer_height is not None:
            given["mixed_layer_height"] = self.mixed_layer_height
        if geostrophic_wind is _INPUTS_ONLY:
            require_broadcastable(given)
            return
        self.geostrophic_wind = _checked("geostrophic_wind", geostrophic_wind, lambda g: g > 0)
        require_broadcastable({"geostrophic_wind": self.geostrophic_wind, **given})
        self._solve()

    @classmethod
    def check_inputs(cls, **inputs):
        """Validate EkmanABL keyword inputs without the geostrophic wind (types, ranges and
        exclusive choices, as the constructor does) and return the unsolved instance; raises
        ValueError naming the input, its valid range (`VALID_RANGES`) and, for arrays, the
        index of the offending entries."""
        if "geostrophic_wind" in inputs:
            raise ValueError("check_inputs takes the inputs without geostrophic_wind")
        return cls(geostrophic_wind=_INPUTS_ONLY, **inputs)

    @classmethod
    def _solved_at(cls, log_u_star, geostrophic_wind, **inputs):
        """The ABL of ``inputs`` and ``geostrophic_wind`` whose solve's root ln u* is already
        known: the state of Eq. (GDL) is explicit in u* for a given stability (the reference-wind
        solve's parametrisation, docs/atmosphere.md#reference-wind-solve), so a caller that
        found G from u* (the profile fit, docs/measurements.md#fit-time) sets the solution
        without solving for u* again. The caller vouches that the state is a model state (a
        physical GDL branch, a surface layer above z0, h at least the shallowest accepted)."""
        abl = cls.check_inputs(**inputs)
        abl.geostrophic_wind = np.asarray(geostrophic_wind, dtype=float)
        params, shape = abl._parameters(abl.geostrophic_wind, np.shape(log_u_star))
        abl._params = params
        abl._set_solution(np.broadcast_to(np.asarray(log_u_star, dtype=float), shape), params)
        return abl

    @staticmethod
    def valid_range(name):
        """The valid range of input ``name`` as the error messages state it (`VALID_RANGES`);
        ValueError naming the inputs for a name that is none of them."""
        if not isinstance(name, str) or name not in VALID_RANGES:
            raise ValueError(f"valid_range: name must be one of EkmanABL's inputs "
                             f"{sorted(VALID_RANGES)}; got {name!r}")
        return VALID_RANGES[name]

    # ----------------------------------------------------------------------------- inputs
    def _set_constants(self, kappa, c_g, decay, c_tn, c_cn, c_ns, matching):
        for name, value in dict(
            von_karman=kappa, c_g=c_g, stress_decay=decay, c_tn=c_tn, c_cn=c_cn, c_ns=c_ns,
            matching_fraction=matching,
        ).items():
            ok = (lambda v: (v > 0) & (v < 1)) if name == "matching_fraction" else (lambda v: v > 0)
            if np.ndim(_checked(name, value, ok)) != 0:
                raise ValueError(f"{name} must be a single number ({VALID_RANGES[name]}); got {value!r}")
        self.von_karman, self.c_g, self.stress_decay = float(kappa), float(c_g), float(decay)
        self.c_tn, self.c_cn, self.c_ns = float(c_tn), float(c_cn), float(c_ns)
        self.matching_fraction = float(matching)

    def _set_coriolis(self, coriolis_parameter, latitude):
        if (coriolis_parameter is None) == (latitude is None):
            raise ValueError(
                "give exactly one of coriolis_parameter [1/s] or latitude [deg]; got "
                f"coriolis_parameter={coriolis_parameter!r}, latitude={latitude!r}"
            )
        if latitude is not None:
            f_c = coriolis_parameter_from_latitude(latitude)
        else:
            f_c = _checked(
                "coriolis_parameter", coriolis_parameter,
                lambda f: (np.abs(f) >= MIN_CORIOLIS_PARAMETER) & (np.abs(f) <= MAX_CORIOLIS_PARAMETER),
            )
        self.coriolis_parameter = f_c
        self._f = np.abs(f_c)
        self._hemisphere = np.sign(f_c)

    def _set_free_atmosphere(self, brunt_vaisala_frequency, lapse_rate):
        if brunt_vaisala_frequency is not None and lapse_rate is not None:
            raise ValueError(
                "give at most one of brunt_vaisala_frequency [1/s] or lapse_rate [K/m]"
            )
        if lapse_rate is not None:
            gamma = _checked("lapse_rate", lapse_rate, lambda g: (g >= 0) & (g <= MAX_LAPSE_RATE))
            n_inf = np.sqrt(GRAVITY / self.reference_potential_temperature * gamma)
        else:
            if brunt_vaisala_frequency is None:
                brunt_vaisala_frequency = PAPER_BRUNT_VAISALA_FREQUENCY
            n_inf = _checked("brunt_vaisala_frequency", brunt_vaisala_frequency, lambda n: n >= 0)
        self.brunt_vaisala_frequency = n_inf
        self.zilitinkevich_number = n_inf / self._f

    def _set_stability_closure(self, mu, cooling_rate, heat_flux, obukhov_length, sensible):
        given = {
            name: value
            for name, value in zip(
                STABILITY_INPUTS, (mu, cooling_rate, heat_flux, obukhov_length, sensible)
            )
            if value is not None
        }
        if len(given) > 1:
            raise ValueError(
                "give at most one stability input among stability_parameter, cooling_rate, "
                f"surface_heat_flux, obukhov_length, sensible_heat_flux; got {sorted(given)}"
            )
        self.stability_input = name = next(iter(given), "stability_parameter")
        value = real_array(name, given.get(name, 0.0), VALID_RANGES[name])
        # L = +-inf is the neutral limit of the Obukhov length; everything else must be finite.
        ok = {
            "stability_parameter": np.isfinite,
            "cooling_rate": lambda v: np.isfinite(v) & (np.abs(v) <= -MIN_COOLING_RATE),
            "surface_heat_flux": lambda v: _within_heat_flux_range(
                v * air_heat_capacity(self.reference_potential_temperature)),
            "obukhov_length": lambda v: (v != 0) & ~np.isnan(v),
            "sensible_heat_flux": _within_heat_flux_range,
        }[name]
        require_at(ok(value), name, VALID_RANGES[name], value)
        self._stability_value = value

    # ----------------------------------------------------------------------------- solver
    def _neutral_h_hat(self, p):
        """h_hat of Eq. (h_hat_model) at mu = 0."""
        return boundary_layer_height_hat(0.0, p["mu_n"], self.c_tn, self.c_cn, self.c_ns)

    def _convective_h_hat(self, u_star, p):
        """z_i f/u* of a convective layer: the given mixed_layer_height, else the neutral height
        of Eq. (h_hat_model) (docs/atmosphere.md#convective-boundary-layer)."""
        return np.where(np.isnan(p["zi"]), self._neutral_h_hat(p), p["zi"] * p["f"] / u_star)

    def _closure_mu(self, u_star, p):
        """mu as a function of u* for the chosen stability input (docs/atmosphere.md#stability-closures)."""
        value, f, theta0 = p["value"], p["f"], p["theta0"]
        if self.stability_input == "stability_parameter":
            return value + 0.0 * u_star
        if self.stability_input == "surface_heat_flux":
            return -(GRAVITY / theta0) * value / (f * u_star**2)
        if self.stability_input == "sensible_heat_flux":
            return -(GRAVITY / theta0) * value / (air_heat_capacity(theta0) * f * u_star**2)
        if self.stability_input == "obukhov_length":
            return u_star / (self.von_karman * f * value)
        a0 = 1.0 / self.c_tn**2 + p["mu_n"] / self.c_cn**2
        cooling = stability_from_cooling_rate(
            np.minimum(value, 0.0) / 3600.0, u_star, f, theta0, a0, self.c_ns
        )
        # Heating: the mixed layer warms at C_r, Q0 = C_r z_i / (1 + A_e) (Tennekes 1973).
        z_i = self._convective_h_hat(u_star, p) * u_star / f
        heat_flux = np.maximum(value, 0.0) / 3600.0 * z_i / (1.0 + ENTRAINMENT_RATIO)
        return np.where(value > 0, -(GRAVITY / theta0) * heat_flux / (f * u_star**2), cooling)

    def _state(self, log_u_star, p):
        """ABL state for trial ln u* and condition parameters p: (u*, mu, h_hat, A, B, ln Ro - A)."""
        u_star = np.exp(log_u_star)
        mu = self._closure_mu(u_star, p)
        h_hat = np.where(
            mu < 0, self._convective_h_hat(u_star, p),
            boundary_layer_height_hat(np.maximum(mu, 0.0), p["mu_n"], self.c_tn, self.c_cn,
                                      self.c_ns),
        )
        rossby = u_star / (p["f"] * p["z0"])
        a, b = gdl_coefficients(
            mu, p["mu_n"], h_hat, rossby, self.von_karman, self.c_g,
            self.stress_decay, self.matching_fraction, self.businger_dyer_gamma,
        )
        return u_star, mu, h_hat, a, b, np.log(rossby) - a

    def _residual(self, log_u_star, p):
        """ln(|(U_g, V_g)| / G): zero at the GDL solution, increasing on the physical branch
        U_g > 0 (ln Ro > A); -inf below that branch."""
        _, _, _, _, b, along = self._state(log_u_star, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = log_u_star + 0.5 * np.log(along**2 + b**2) - np.log(self.von_karman * p["g"])
        return np.where(along > 0, r, -np.inf)

    def _failure(self, mask, reason, lead="the ABL solve did not converge"):
        idx = tuple(np.argwhere(mask)[0])
        details = ", ".join(
            f"{name}={np.broadcast_to(np.asarray(value, float), mask.shape)[idx]:.6g}"
            for name, value in dict(
                geostrophic_wind=self.geostrophic_wind,
                coriolis_parameter=self.coriolis_parameter,
                roughness_length=self.roughness_length,
                **{self.stability_input: self._stability_value},
                brunt_vaisala_frequency=self.brunt_vaisala_frequency,
                **({} if self.mixed_layer_height is None
                   else {"mixed_layer_height": self.mixed_layer_height}),
            ).items()
        )
        return ValueError(f"{lead} ({reason}) for inputs {details}")

    def _parameters(self, geostrophic_wind, shape=()):
        """The per-condition parameters of the solve, broadcast together (and to ``shape``)."""
        params = dict(
            g=geostrophic_wind, f=self._f, z0=self.roughness_length,
            value=self._stability_value, mu_n=self.zilitinkevich_number,
            theta0=self.reference_potential_temperature,
            zi=np.nan if self.mixed_layer_height is None else self.mixed_layer_height,
        )
        shape = np.broadcast_shapes(shape, *(np.shape(v) for v in params.values()))
        return {k: np.broadcast_to(v, shape) for k, v in params.items()}, shape

    def _surface_layer_exists(self, u_star, h_hat, p):
        """The state is a model state if the matching height (matching_fraction * h, which
        grows with u*) lies above z0; below it the stable boundary layer has collapsed."""
        return self.matching_fraction * h_hat * u_star / p["f"] > p["z0"]

    def _solve(self):
        params, shape = self._parameters(self.geostrophic_wind)
        flat = {k: v.ravel() for k, v in params.items()}
        # A few steps of the contracting fixed-point form (rate ~ 1/(ln Ro - A) ~ 0.1) put
        # u* within ~0.1 %; bracketed secant steps then converge on the physical branch.
        log_kg = np.log(self.von_karman * flat["g"])
        x = log_kg + np.log(0.05)
        for _ in range(3):
            _, _, _, _, b, along = self._state(x, flat)
            with np.errstate(divide="ignore", invalid="ignore"):
                x = np.where(along > 0, log_kg - 0.5 * np.log(along**2 + b**2), x + 0.5)
        x, converged = secant_root(lambda x: self._residual(x, flat), x - 0.01, x + 0.01)
        if not np.all(converged):
            raise self._failure(
                ~converged.reshape(shape),
                "no physical solution with U_g > 0: the cooling is too strong for this wind, "
                "the stable boundary layer collapses",
            )
        # The root is unique, but it is a model state only if the surface layer exists:
        # the matching height (matching_fraction * h, which grows with u*) above z0.
        u_star, _, h_hat, _, _, _ = self._state(x, flat)
        collapsed = ~self._surface_layer_exists(u_star, h_hat, flat)
        if np.any(collapsed):
            raise self._failure(
                collapsed.reshape(shape),
                "matching height matching_fraction * h at or below roughness_length z0: "
                "the stable boundary layer collapses",
            )
        self._params = {k: v.reshape(shape) for k, v in flat.items()}
        self._set_solution(x.reshape(shape), self._params)
        self._require_depth(lambda mask: self._failure(
            mask, f"the stable boundary layer collapses: h below {MIN_BOUNDARY_LAYER_HEIGHT:g} m, "
            "the shallowest the model accepts (docs/atmosphere.md#shallow-boundary-layer)",
            lead="no model ABL",
        ))
        self._require_domain(lambda mask, reason: self._failure(
            mask, reason, lead="the inputs leave the physical domain",
        ))

    def physical_domain(self) -> DomainCheck:
        """Where the solved states lie in the `PHYSICAL_DOMAIN` (`physical_domain`): the implied
        sensible heat flux, geostrophic wind and, where convective, cross-isobaric angle, per
        condition, without raising (docs/atmosphere.md#physical-domain)."""
        return physical_domain(self.sensible_heat_flux, self.geostrophic_wind,
                               self.cross_isobaric_angle, self.stability_parameter)

    def _require_domain(self, error):
        """Raise ``error(mask of the offending conditions, reason)`` at the first condition
        outside the physical domain, the reason naming the implied quantity, its value and range."""
        check = self.physical_domain()
        if np.all(check.inside):
            return
        outside = np.atleast_1d(~check.inside).reshape(np.shape(check.inside) or (1,))
        first = tuple(np.argwhere(outside)[0])
        name = np.atleast_1d(check.binding).reshape(outside.shape)[first]
        value = np.broadcast_to(np.atleast_1d(check.values[name]).reshape(
            np.shape(check.values[name]) or (1,)), outside.shape)[first]
        raise error(outside, _outside_domain(name, value))

    def _require_depth(self, error):
        """Raise ``error(mask of the offending conditions)`` where h < MIN_BOUNDARY_LAYER_HEIGHT."""
        shallow = np.asarray(self.boundary_layer_height) < MIN_BOUNDARY_LAYER_HEIGHT
        if np.any(shallow):
            raise error(np.atleast_1d(shallow).reshape(np.shape(shallow) or (1,)))

    def _set_solution(self, log_u_star, p):
        # The state of one condition is computed as an array of one, not as numpy scalars:
        # ``**`` on a numpy scalar takes C's pow, whose last bit can differ from numpy's array
        # loop, and a condition must give the same bits alone as in a batch.
        shape = np.shape(log_u_star)
        z_i = np.broadcast_to(p["zi"], shape)
        if shape == ():
            log_u_star = np.reshape(log_u_star, 1)
            p = {k: np.reshape(v, 1) for k, v in p.items()}
        u_star, mu, h_hat, a, b, along = (
            np.reshape(x, shape) for x in self._state(log_u_star, p))
        kappa = self.von_karman
        self.friction_velocity = u_star[()]
        self.stability_parameter = np.asarray(mu, dtype=float)[()]
        self.h_hat = h_hat[()]
        self.gdl_a, self.gdl_b = a[()], b[()]
        # A given z_i is the convective layer's depth itself: z_i f/u* times u*/f would round
        # it (10 m to 9.999999999999998 m, below the shallowest depth accepted).
        depth = h_hat * u_star / self._f
        if not np.all(np.isnan(z_i)):
            depth = np.where((mu < 0) & ~np.isnan(z_i), z_i, depth)
        self.boundary_layer_height = depth[()]
        u_g = u_star * along / kappa
        v_g = -self._hemisphere * u_star * b / kappa
        self.geostrophic_components = (u_g[()], v_g[()])
        self.cross_isobaric_angle = np.rad2deg(np.arctan2(v_g, u_g))[()]
        self.convective_variance = convective_variance(
            self.boundary_layer_height, self.obukhov_length
        )[()]

    # ----------------------------------------------------------------------------- stability
    @property
    def obukhov_length(self):
        """L [m] = u*/(kappa f mu): > 0 stable, < 0 convective, inf neutral."""
        mu = np.asarray(self.stability_parameter, dtype=float)
        with np.errstate(divide="ignore", over="ignore"):
            return (self.friction_velocity / (self.von_karman * self._f * mu))[()]

    @property
    def surface_heat_flux(self):
        """The kinematic surface heat flux Q0 = -u*^3/(kappa (g/Theta0) L) [K m/s] (upward > 0)."""
        return (-np.asarray(self.stability_parameter, dtype=float) * self._f
                * self.friction_velocity**2 * self.reference_potential_temperature / GRAVITY)[()]

    @property
    def sensible_heat_flux(self):
        """The surface sensible heat flux H = rho c_p Q0 [W/m^2] (upward > 0; `air_heat_capacity`)."""
        return (self.surface_heat_flux * air_heat_capacity(self.reference_potential_temperature))[()]

    @property
    def friction_rossby_number(self):
        """Ro = u*/(|f_c| z0), the paper's Table 1 friction Rossby number."""
        return (self.friction_velocity / (self._f * self.roughness_length))[()]

    # ----------------------------------------------------------------------------- profiles
    @property
    def roughness_sublayer_height(self):
        """z_s [m], the top of the roughness sublayer (docs/atmosphere.md#roughness-sublayer).

        The height where the tangent of the surface-layer law U(z) passes through the ground,
        z_s = z0 exp(1 + kappa (5 mu + 0.3 mu_N) z0 f_c/u*) (about e z0), capped at the matching
        height matching_fraction * h (reached only by a boundary layer near collapse). In a
        convective layer the tangent condition ln(z_s/z0) = phi_m(z_s/L) + psi_m(z_s/L)
        - psi_m(z0/L) + 0.3 kappa mu_N z0 f_c/u* is solved by fixed-point steps from e z0.
        """
        mu = np.asarray(self.stability_parameter, dtype=float)
        most_slope = 5.0 * np.maximum(mu, 0.0) + 0.3 * self.zilitinkevich_number
        xi0 = self.roughness_length * self._f / self.friction_velocity
        # (exponent capped where z_s would be > e^50 z0: far above the matching height anyway)
        tangent = self.roughness_length * np.exp(np.minimum(1.0 + self.von_karman * most_slope * xi0, 50.0))
        if np.any(mu < 0):
            # phi_m + psi_m varies slowly (1 at neutral), so these steps contract fast.
            inverse_l = self.von_karman * np.minimum(mu, 0.0) * self._f / self.friction_velocity
            gamma, z0 = self.businger_dyer_gamma, self.roughness_length
            offset = 0.3 * self.von_karman * self.zilitinkevich_number * xi0 - unstable_psi_m(
                z0 * inverse_l, gamma)
            z_s = tangent
            for _ in range(30):
                zeta = z_s * inverse_l
                z_s = z0 * np.exp(np.minimum(
                    unstable_phi_m(zeta, gamma) + unstable_psi_m(zeta, gamma) + offset, 50.0))
            tangent = np.where(mu < 0, z_s, tangent)
        return np.minimum(tangent, self.matching_fraction * self.boundary_layer_height)

    def _heights(self, z, name, ok=lambda z: z >= 0, valid=">= 0 m (at or above the ground)"):
        return _checked(name, z, ok, valid)

    def _direction_heights(self, z, name):
        return self._heights(z, name, lambda z: z > 0, "> 0 m (the wind has no direction at the ground)")

    def velocity(self, z):
        """(U, V)(z) [m/s] in the surface-stress frame, Eqs. (U_vel) and (V_vel); heights z >= 0.

        U: Monin-Obukhov law up to the matching height 0.2 h, Ekman layer up to h, U_g above;
        continuous at 0.2 h by construction of A (dU/dz jumps there). V: one expression on
        0 <= z <= h, V_g above; where g(xi) >= 1 (z > 0.9973 h, since c_g > 1)
        the sqrt(1 - g^2) terms take their physical limit 0 (docs/atmosphere.md#lateral-velocity-near-the-abl-top). The slight
        backing of V near the ground is a property of the published formula and is kept.

        Roughness sublayer (docs/atmosphere.md#roughness-sublayer): below z_s =
        `roughness_sublayer_height` (about e z0, where the log law's tangent passes through the
        ground) the wind is (z/z_s) (U, V)(z_s): zero at the ground, positive for z > 0, U
        continuous with its slope at z_s, the direction that of z_s. The log law alone would
        give U = 0 at z0 while V(z0) != 0, hence a wind at right angles to the surface stress
        and U < 0 below z0.
        """
        return self._velocity(self._heights(z, "z"))

    def _velocity(self, z):
        u_star, h_hat = self.friction_velocity, self.h_hat
        z_s = self.roughness_sublayer_height
        # Heights all above every condition's sublayer (rotor heights): scale 1, nothing to
        # replace (u * 1.0 is u exactly), without the full-size mask and quotient.
        scale = None
        if not np.min(z, initial=np.inf) >= np.max(z_s):
            sublayer = z < z_s
            scale = np.where(sublayer, z / z_s, 1.0)
            z = np.where(sublayer, z_s, z)
        xi = z * self._f / u_star
        xi0 = self.roughness_length * self._f / u_star
        # z/h; the profile formulas live on [0, h]. Taken as z/h (not xi/h_hat) so that
        # z = h gives eta = 1 exactly: sqrt(1 - eta) would turn round-off into ~1e-8 of U.
        eta = np.minimum(z / self.boundary_layer_height, 1.0)
        g, dg = stress_shape(eta, h_hat, self.c_g, self.stress_decay)
        # 1 - eta and its root once (U and V both take them: the same numbers, fewer passes).
        depth = 1.0 - eta
        stress = np.power(depth, 1.5)
        depth_root = np.sqrt(depth)
        u_g = self.geostrophic_components[0]
        # The sums below are accumulated in place, term by term in the order written
        # (-dg stress + 1.5 g / h_hat sqrt(1 - eta) + U_g/u*): the same roundings, fewer arrays.
        ekman_u = -dg * stress
        ekman_u += 1.5 * g / h_hat * depth_root
        ekman_u += u_g / u_star
        surface_u = np.log(xi / xi0)
        surface_u /= self.von_karman
        surface_u += stability_term(self.stability_parameter, xi, xi0, self.von_karman,
                                    self.businger_dyer_gamma)
        surface_u += 0.3 * self.zilitinkevich_number * (xi - xi0)
        u = np.where(eta <= self.matching_fraction, surface_u, ekman_u)
        u *= u_star

        one_minus_g2 = 1.0 - g**2
        real = one_minus_g2 > 0
        # (g < 1 everywhere but within 0.3 % of h below the top: no masking needed there)
        everywhere = bool(np.all(real))
        root = np.sqrt(one_minus_g2 if everywhere else np.where(real, one_minus_g2, 1.0))
        # kappa V_g/u* = -B = -3 kappa/(2 h_hat): writing V_g through B makes V(0) = 0 exact.
        veer_terms = g * dg / root * stress
        veer_terms += 1.5 / h_hat * (root * depth_root - 1.0)
        v = self._hemisphere * u_star * (veer_terms if everywhere
                                         else np.where(real, veer_terms, -1.5 / h_hat))
        return (u, v) if scale is None else (u * scale, v * scale)

    def wind_angle(self, z):
        """Mathematical flow angle atan2(V, U) [deg] in the surface-stress frame (z > 0)."""
        return self._wind_angle(z, "z")

    def _wind_angle(self, z, name):
        u, v = self._velocity(self._direction_heights(z, name))
        return np.rad2deg(np.arctan2(v, u))

    def hub_frame(self, reference_height):
        """(cos a, sin a) of the wind's angle a at ``reference_height`` (> 0) in the
        surface-stress frame: the rotation of :meth:`hub_aligned_velocity`, to compute once for
        many evaluations at the same reference height."""
        u_ref, v_ref = self._velocity(self._direction_heights(reference_height, "reference_height"))
        speed = np.hypot(u_ref, v_ref)
        return u_ref / speed, v_ref / speed

    def hub_aligned_velocity(self, z, reference_height, frame=None):
        """(U, V)(z) rotated so that V(reference_height) = 0 and U(reference_height) > 0.

        This is the frame of the wake model (docs/conventions.md#hub-aligned-frame): x along the
        wind at hub height. Heights z >= 0; reference_height > 0. ``frame``: the rotation
        :meth:`hub_frame` gives for ``reference_height`` (then not computed again).
        """
        cos_a, sin_a = self.hub_frame(reference_height) if frame is None else frame
        u, v = self.velocity(z)
        return u * cos_a + v * sin_a, v * cos_a - u * sin_a

    def speed(self, z):
        """Horizontal wind speed |(U, V)|(z) [m/s], heights z >= 0."""
        return np.hypot(*self.velocity(z))

    def wind_direction_change(self, z1, z2):
        """Change of wind direction from z1 to z2 [deg], positive = veering (clockwise with
        height, as the meteorological direction increases). Northern-hemisphere Ekman
        layers veer with height, so this is positive there for z2 > z1."""
        return self._wind_angle(z1, "z1") - self._wind_angle(z2, "z2")

    def _log_layer_heights(self, z, name):
        return self._heights(
            z, name, lambda z: z >= self.roughness_length,
            ">= roughness_length z0 (the Townsend-Perry law holds above the roughness)",
        )

    def turbulence_intensity(self, z, reference_height=None, A1=TOWNSEND_PERRY_A1, B1=TOWNSEND_PERRY_B1):
        """Streamwise turbulence intensity I_u(z), Eq. (Iu_model), for z >= z0.

        Normalised by the speed at ``reference_height`` (the paper's U_h) when given, else by
        the local speed |(U, V)(z)| (the two agree at the reference height). Above h the
        variance law is continued to its zero at h exp(B1/A1) and is zero higher up
        (docs/atmosphere.md#shallow-boundary-layer).
        """
        z = self._log_layer_heights(z, "z")
        A1, B1 = _turbulence_constants(A1=A1, B1=B1).values()
        if reference_height is None:
            reference_speed = np.hypot(*self._velocity(z))
        else:
            reference_speed = np.hypot(
                *self._velocity(self._log_layer_heights(reference_height, "reference_height"))
            )
        return streamwise_turbulence_intensity(
            z, self.friction_velocity, self.boundary_layer_height, reference_speed, A1, B1,
            self.convective_variance,
        )

    def wake_expansion_rate(self, hub_height, **constants):
        """k_w at a hub height, Eq. (kw_CNBL_SBL_model), with U_h = |(U, V)(z_h)|.

        ``constants`` may override A1, B1, alpha_prime, floor and n. A hub at or above h takes
        the continued law (docs/atmosphere.md#shallow-boundary-layer): the floor from
        h exp(B1/A1) up. Raises ValueError for a hub below the roughness length.
        """
        hub_height = self._log_layer_heights(hub_height, "hub_height")
        constants = _turbulence_constants(**constants)
        return wake_expansion_rate(
            self.friction_velocity, self.boundary_layer_height, hub_height,
            np.hypot(*self._velocity(hub_height)), convective=self.convective_variance,
            **constants,
        )

    # ----------------------------------------------------------------------------- drivers
    @classmethod
    def from_reference_wind(cls, speed, height, tolerance=1e-13, **inputs):
        """Solve the ABL whose wind speed at ``height`` is ``speed`` (instead of giving G).

        FLORIS drives farms by the wind speed at a reference height. The solve is one scalar
        root per condition in ln u* (docs/atmosphere.md#reference-wind-solve): for a given u*
        the closure, h_hat, A, B and hence G = (u*/kappa) sqrt((ln Ro - A)^2 + B^2) are
        explicit, so the speed at ``height`` is an explicit, increasing function of u*. Its
        domain is bounded below by the collapse threshold (the physical GDL branch ln Ro > A
        and a surface layer, matching_fraction * h > z0, exist only above some u*); trial
        states below it count as "below the root", the bracket widens upward without bound
        (the speed grows with u*), and bracketed secant steps, bisecting where the secant
        leaves the bracket, converge whenever a solution exists. When none does (the speed is
        below the slowest wind the atmosphere supports at that height), the ValueError gives
        the condition, the speed and height asked for and that slowest speed.
        Vectorised over arrays of speeds, heights and inputs (distinct conditions solved once).
        """
        if "geostrophic_wind" in inputs:
            raise ValueError("from_reference_wind takes speed and height instead of geostrophic_wind")
        speed = _checked("speed", speed, lambda s: s > 0, "> 0 m/s")
        tolerance = float(_checked(
            "tolerance", tolerance,
            lambda t: (np.ndim(t) == 0) & (t >= MIN_REFERENCE_WIND_TOLERANCE) & (t <= 1e-3),
            f"one number from {MIN_REFERENCE_WIND_TOLERANCE:g} to 1e-3, the tolerance on "
            "ln(speed) at the height (default 1e-13)",
        ))
        template = cls.check_inputs(**inputs)
        height = _checked("height", height, lambda h: h > 0, "> roughness_length z0")
        require_broadcastable({"speed": speed, "height": height, **{
            name: value for name, value in inputs.items() if value is not None
        }})
        z0 = template.roughness_length
        require_at(
            height > z0, "height", "> roughness_length z0",
            np.broadcast_to(height, np.broadcast_shapes(height.shape, np.shape(z0))),
        )

        # Conditions repeat (a wind rose has few distinct speeds): solve each distinct
        # (speed, height, atmosphere) once.
        per_condition = dict(
            coriolis_parameter=template.coriolis_parameter,
            roughness_length=template.roughness_length,
            brunt_vaisala_frequency=template.brunt_vaisala_frequency,
            reference_potential_temperature=template.reference_potential_temperature,
            **{template.stability_input: template._stability_value},
            **({} if template.mixed_layer_height is None
               else {"mixed_layer_height": template.mixed_layer_height}),
        )
        shape = np.broadcast_shapes(
            speed.shape, height.shape, *(np.shape(v) for v in per_condition.values())
        )
        columns = np.stack(
            [np.broadcast_to(a, shape).ravel() for a in (speed, height, *per_condition.values())],
            axis=1,
        )
        distinct, first, inverse = np.unique(columns, axis=0, return_index=True, return_inverse=True)
        constants = {
            k: getattr(template, k)
            for k in ("von_karman", "c_g", "stress_decay", "c_tn", "c_cn", "c_ns", "matching_fraction",
                      "businger_dyer_gamma")
        }
        rows = cls.check_inputs(
            **{k: distinct[:, 2 + i] for i, k in enumerate(per_condition)}, **constants
        )
        target, at = distinct[:, 0], distinct[:, 1]
        p, _ = rows._parameters(np.nan)

        def exists(log_u_star):
            u_star, _, h_hat, _, _, along = rows._state(log_u_star, p)
            return (along > 0) & rows._surface_layer_exists(u_star, h_hat, p)

        def log_speed_error(log_u_star):
            with np.errstate(all="ignore"):
                rows._set_solution(log_u_star, p)
                error = np.log(np.hypot(*rows._velocity(at))) - np.log(target)
            return np.where(exists(log_u_star) & np.isfinite(error), error, -np.inf)

        log_u_star, slowest = _largest_root(log_speed_error, exists, rows, target, at, p, tolerance)
        if np.any(np.isnan(log_u_star)):
            failing = np.flatnonzero(np.isnan(log_u_star))
            bad = failing[np.argmin(first[failing])]  # the first condition that fails
            raise _no_reference_wind(
                target[bad], at[bad], slowest[bad],
                np.unravel_index(first[bad], shape), shape, inputs,
            )
        rows._set_solution(log_u_star, p)
        u_star = rows.friction_velocity
        _, _, _, _, b, along = rows._state(log_u_star, p)
        g = (u_star * np.hypot(along, b) / rows.von_karman)[inverse.ravel()].reshape(shape)

        abl = template
        abl.geostrophic_wind = g
        abl._params, _ = abl._parameters(g, shape)
        abl._set_solution(log_u_star[inverse.ravel()].reshape(shape), abl._params)
        abl._require_depth(lambda mask: _reference_wind_refusal(
            abl, mask, speed, height, inputs,
            f"is h = {{h}} m deep, below the {MIN_BOUNDARY_LAYER_HEIGHT:g} m the model accepts (the "
            "stable boundary layer collapses; docs/atmosphere.md#shallow-boundary-layer): check the "
            "units of the inputs (cooling rate in K/h, heat flux in K m/s, lapse rate in K/m) or "
            "give weaker stratification",
        ))
        abl._require_domain(lambda mask, reason: _reference_wind_refusal(
            abl, mask, speed, height, inputs, f"leaves the physical domain: {reason}"))
        residual = np.abs(log_speed_error(log_u_star))
        #: |ln(speed at height / speed asked)| of each condition's solution
        abl.reference_wind_residual = residual[inverse.ravel()].reshape(shape)[()]
        missed = residual > tolerance
        if np.any(missed):
            package_warnings.warn(
                f"from_reference_wind: {np.count_nonzero(missed)} of {residual.size} distinct "
                f"conditions (wind speeds {package_warnings.speeds_text(target[missed])} at "
                f"{package_warnings.range_text(at[missed], 'm')}) meet their speed only to "
                f"{residual[missed].max():.2g} in ln speed, above the tolerance {tolerance:g}: "
                "the speed lies in the step of the profile where the top of the boundary layer "
                "crosses the height (docs/atmosphere.md#reference-wind-solve); the closest state "
                "is taken, its residual in reference_wind_residual",
                package_warnings.ReferenceWindWarning,
                items=tuple(zip(target[missed].round(6), at[missed].round(6))))
        return abl

    @classmethod
    def fit_profile(cls, heights, speeds, directions=None, **options_and_fixed_inputs):
        """The atmosphere whose profile best fits measured wind speeds [m/s] and meteorological
        directions [deg] at ``heights`` [m], per record (arrays (n_records, n_heights)): least
        squares in u* (hence G), the Obukhov length and optionally z0, the direction a free
        rotation; refuses records no atmosphere of the model fits. Options and fixed inputs:
        :func:`floris_ekman_veer.atmosphere.fit.fit_profile` (docs/measurements.md)."""
        from floris_ekman_veer.atmosphere import fit

        return fit.fit_profile(cls, heights, speeds, directions, **options_and_fixed_inputs)

    def __repr__(self):
        return (
            f"EkmanABL(G={self.geostrophic_wind!r}, u*={self.friction_velocity!r}, "
            f"h={self.boundary_layer_height!r}, mu={self.stability_parameter!r}, "
            f"alpha_0={self.cross_isobaric_angle!r} deg)"
        )


#: The constants of Eqs. (Iu_model) and (kw_CNBL_SBL_model) the profile methods take, with the
#: paper's values: each one positive number.
TURBULENCE_CONSTANTS = {"A1": TOWNSEND_PERRY_A1, "B1": TOWNSEND_PERRY_B1,
                        "alpha_prime": ALPHA_PRIME, "floor": MIXING_LAYER_FLOOR,
                        "n": MERGE_EXPONENT}


def _turbulence_constants(**constants):
    """``constants`` checked: known names (`TURBULENCE_CONSTANTS`), each one positive number."""
    unknown = sorted(set(constants) - set(TURBULENCE_CONSTANTS))
    if unknown:
        raise ValueError(f"unknown constant(s) {unknown}; the constants are "
                         f"{sorted(TURBULENCE_CONSTANTS)}")
    # the model block's ranges (docs/user_guide.md#valid-input-ranges): B1 may be 0, n >= 1
    lowest = {"B1": (0.0, ">="), "n": (1.0, ">=")}
    checked = {}
    for name, value in constants.items():
        low, sign = lowest.get(name, (0.0, ">"))
        checked[name] = float(_checked(
            name, value,
            lambda v: (np.ndim(v) == 0) & ((v >= low) if sign == ">=" else (v > low)),
            f"one number {sign} {low:g} (the paper's {TURBULENCE_CONSTANTS[name]:g})"))
    return checked


#: The tightest tolerance of the reference-wind solve (in ln speed): a few times the spacing of
#: doubles, below which no state is closer.
MIN_REFERENCE_WIND_TOLERANCE = 1e-15
#: Points of the scan in ln u* that brackets the largest root of the reference-wind solve.
_SCAN_POINTS = 64
#: Residual (in ln speed) accepted where round-off, not the method, stops the reference-wind solve.
_ROUNDOFF_ACCEPTANCE = 1e-7


def _largest_root(log_speed_error, exists, abl, target, height, p, tolerance):
    """ln u* of the deepest ABL whose speed at ``height`` is ``target`` (the reference-wind
    solve, docs/atmosphere.md#reference-wind-solve), NaN where no ABL reaches it, and the
    slowest speed the scanned states reach (for the message when none does).

    Bounds from the physics: below, the collapse threshold (the smallest u* with a physical
    GDL branch and a surface layer, found by bisection, the state being explicit in u*) or a
    twentieth of the log-law guess, whichever is larger; above, the guess raised until the
    speed exceeds the target (the speed grows without bound with u*). Near collapse the
    speed at a fixed height can fall while u* and h grow, so two states may give one speed: a
    scan of the bracket picks its last sign change (the state continuous with stronger winds),
    which bracketed secant steps then refine.
    """
    # Neutral log law at the reference height: within a factor ~2 of the root.
    guess = np.log(abl.von_karman * target / np.log(height / p["z0"]))
    # Collapse threshold: bisection between a collapsed state and an existing one (states
    # exist for all u* above it); e^-45 of the guess stands for "no threshold".
    high = guess.copy()
    for _ in range(60):
        missing = ~exists(high)
        if not np.any(missing):
            break
        high = np.where(missing, high + 1.0, high)
    low = np.minimum(guess - 3.0, high - 3.0)
    for _ in range(15):
        above = exists(low)
        if not np.any(above):
            break
        low = np.where(above, low - 3.0, low)
    for _ in range(100):
        active = high - low > 1e-13 * np.maximum(1.0, np.abs(high))  # the others are frozen
        if not np.any(active):
            break
        mid = 0.5 * (low + high)
        ok = exists(mid)
        high, low = np.where(active & ok, mid, high), np.where(active & ~ok, mid, low)
    threshold = high
    # Scan from a twentieth of the guess, or lower where the speed there still exceeds the target.
    lower = np.maximum(guess - 3.0, threshold)
    for _ in range(20):
        step = (lower > threshold) & (log_speed_error(lower) >= 0)
        if not np.any(step):
            break
        lower = np.where(step, np.maximum(lower - 3.0, threshold), lower)
    upper = np.maximum(guess + 0.5, lower + 0.5)
    for _ in range(60):
        short = log_speed_error(upper) < 0
        if not np.any(short):
            break
        upper = np.where(short, upper + 1.0, upper)
    grid = lower + (upper - lower) * np.linspace(0.0, 1.0, _SCAN_POINTS)[:, None]
    errors = log_speed_error(grid)
    slowest = target * np.exp(np.min(errors, axis=0))
    crossing = np.isfinite(errors[:-1]) & (errors[:-1] < 0) & (errors[1:] >= 0)
    found = np.any(crossing, axis=0)
    last = _SCAN_POINTS - 2 - np.argmax(crossing[::-1], axis=0)
    columns = np.arange(target.size)
    lo, hi = grid[last, columns], grid[last + 1, columns]
    root, converged = secant_root(log_speed_error, lo, hi, tolerance)
    # Where h crosses the height, U(height) has a square-root slope in u*: adjacent doubles of
    # ln u* then differ by ~sqrt(eps) in speed, and the secant steps end with the bracket at
    # machine precision and a residual above the tolerance; that state is taken if within
    # _ROUNDOFF_ACCEPTANCE in ln speed (a true step of the profile stays refused).
    converged |= np.abs(log_speed_error(root)) <= max(tolerance, _ROUNDOFF_ACCEPTANCE)
    return np.where(found & converged, root, np.nan), slowest


def _reference_wind_refusal(abl, mask, speed, height, inputs, reason):
    """The ValueError of a reference wind whose ABL the model refuses (too shallow, or outside
    the physical domain), at the first offending condition; ``{h}`` in ``reason`` is its depth."""
    index = tuple(np.argwhere(mask)[0]) if mask.ndim else ()
    shape = mask.shape
    varying = [i for i, n in zip(index, shape) if n > 1]
    where = "" if not varying else f" at condition {varying[0] if len(varying) == 1 else index}"
    pick = lambda v: float(np.broadcast_to(np.asarray(v, float), shape)[index])  # noqa: E731
    given = ", ".join(f"{k}={pick(v):.6g}" for k, v in inputs.items())
    return ValueError(
        f"from_reference_wind: the ABL with {pick(speed):.6g} m/s at {pick(height):.6g} m{where} "
        f"({given}) " + reason.replace("{h}", f"{pick(abl.boundary_layer_height):.3g}")
    )


def _outside_domain(name, value):
    """Why a state leaves the physical domain: the implied quantity, its value and range."""
    low, high, unit = PHYSICAL_DOMAIN[name]
    what, hint = {
        "sensible_heat_flux": (
            "the surface sensible heat flux H they imply",
            "give weaker stability (|L| larger, |mu|, |Q0| or |C_r| smaller) or check its units",
        ),
        "geostrophic_wind": (
            "the geostrophic wind G they imply",
            "check the units of the wind speed and the roughness length",
        ),
        "cross_isobaric_angle": (
            "the cross-isobaric angle alpha_0 of the convective layer they imply",
            "the mixed layer is too shallow for its u*/f_c: give a deeper mixed_layer_height "
            "(or none: the neutral height) or a higher latitude",
        ),
    }[name]
    return (
        f"{what} is {value:.4g} {unit}, outside {low:g} to {high:g} {unit} "
        f"(docs/atmosphere.md#physical-domain): {hint}"
    )


def _no_reference_wind(speed, height, slowest, index, shape, inputs):
    """The ValueError of a reference wind that no ABL of the inputs reaches, in the caller's
    terms: the speed and height asked for, the condition index and the inputs there, and the
    slowest wind these inputs support at that height."""
    varying = [i for i, n in zip(index, shape) if n > 1]
    where = (
        "" if not varying
        else f" at condition {varying[0] if len(varying) == 1 else tuple(int(i) for i in index)}"
    )
    given = ", ".join(
        f"{k}={np.broadcast_to(np.asarray(v, float), shape)[index]:.6g}" for k, v in inputs.items()
    )
    if slowest < speed:
        reason = (
            f"the speed at {height:.6g} m steps past it as the boundary-layer top crosses that "
            "height (V steps onto V_g at 0.9973 h, docs/atmosphere.md#lateral-velocity-near-the-abl-top); "
            "give a slightly different speed or height"
        )
    elif np.isfinite(slowest):
        reason = (
            f"the slowest wind these inputs support at {height:.6g} m is {slowest:.4g} m/s; "
            "at lower speeds the stable boundary layer collapses (its surface layer, "
            "matching_fraction * h, shrinks to the roughness length, or the geostrophic drag law "
            "loses its physical branch). Give a higher speed, a lower reference height or "
            "weaker stratification"
        )
    else:
        reason = "the stable boundary layer collapses at every speed for these inputs"
    return ValueError(
        f"from_reference_wind: no ABL has a wind speed of {speed:.6g} m/s at {height:.6g} m"
        f"{where} ({given}): {reason}"
    )


def friction_velocity_fixed_point(abl, iterations=200):
    """Re-solve u* of a solved `EkmanABL` by the fixed-point form of the GDL,
    u* <- kappa G / sqrt((ln(u*/(f_c z0)) - A)^2 + B^2) (docs/atmosphere.md#stability-closures), from u* = 0.05 G.

    An independent route to the same root, used to check the bracketed solver.
    """
    u_star = 0.05 * np.broadcast_to(abl.geostrophic_wind, np.shape(abl.friction_velocity)).astype(float)
    for _ in range(iterations):
        _, _, _, _, b, along = abl._state(np.log(u_star), abl._params)
        u_star = abl.von_karman * abl.geostrophic_wind / np.sqrt(along**2 + b**2)
    return u_star
