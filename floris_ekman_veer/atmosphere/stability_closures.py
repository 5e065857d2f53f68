"""The stability closures (docs/atmosphere.md#stability-closures): the relations between the
stability parameter mu = u*/(kappa f_c L), the Obukhov length L, the kinematic surface heat flux
Q0 and the surface cooling rate C_r, each written once here with the one `GRAVITY`, for the ABL
and for the profile fit alike."""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.atmosphere.constants import ENTRAINMENT_RATIO, GRAVITY, air_heat_capacity


def obukhov_length(friction_velocity, coriolis_magnitude, stability_parameter, von_karman):
    """L [m] = u*/(kappa |f_c| mu): > 0 stable, < 0 convective, +-inf neutral (the sign of the
    zero)."""
    with np.errstate(divide="ignore", over="ignore"):
        return friction_velocity / (von_karman * coriolis_magnitude * stability_parameter)


def surface_heat_flux(stability_parameter, coriolis_magnitude, friction_velocity,
                      reference_potential_temperature):
    """The kinematic surface heat flux Q0 = -mu |f_c| u*^2 Theta0/g [K m/s] (upward > 0), that
    is -u*^3/(kappa (g/Theta0) L)."""
    return (-np.asarray(stability_parameter, dtype=float) * coriolis_magnitude
            * friction_velocity**2 * reference_potential_temperature / GRAVITY)


def cooling_rate(surface_heat_flux, boundary_layer_height, convective):
    """The surface cooling rate C_r [K/h] of a heat flux Q0 [K m/s]: Q0 = C_r h where cooling
    (paper Section 2.5), Q0 = C_r z_i/(1 + A_e) where ``convective`` (the mixed layer of depth
    z_i = ``boundary_layer_height`` warms at C_r, docs/atmosphere.md#convective-boundary-layer)."""
    return (surface_heat_flux / boundary_layer_height * 3600.0
            * np.where(convective, 1.0 + ENTRAINMENT_RATIO, 1.0))


def stability_from_sensible_heat_flux(sensible_heat_flux, friction_velocity, coriolis_magnitude,
                                      reference_potential_temperature):
    """mu of a surface sensible heat flux H [W/m^2] at u*: -(g/Theta0) H/(rho c_p |f_c| u*^2)."""
    return (-(GRAVITY / reference_potential_temperature) * sensible_heat_flux
            / (air_heat_capacity(reference_potential_temperature) * coriolis_magnitude
               * friction_velocity**2))


def stability_from_heat_flux(surface_heat_flux, friction_velocity, coriolis_magnitude,
                             reference_potential_temperature):
    """mu of a kinematic surface heat flux Q0 [K m/s] at u*: -(g/Theta0) Q0/(|f_c| u*^2)."""
    return (-(GRAVITY / reference_potential_temperature) * surface_heat_flux
            / (coriolis_magnitude * friction_velocity**2))


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
