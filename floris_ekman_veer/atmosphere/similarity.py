"""Similarity functions of the Ekman-surface-layer model (paper Section 2.5; docs/atmosphere.md):
the Coriolis parameter, the ABL-height law Eq. (h_hat_model), the surface layer's stability term
(the paper's log-linear law, Businger-Dyer-Paulson where convective), the stress shape
Eq. (eqn:avoidnumbers1) and the geostrophic drag law's coefficients Eqs. (A_model_GDL),
(B_model_GDL)."""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.atmosphere.constants import BUSINGER_DYER_GAMMA, EARTH_ROTATION_RATE
from floris_ekman_veer.atmosphere.inputs.input_ranges import MIN_ABS_LATITUDE, checked


def coriolis_parameter_from_latitude(latitude):
    """f_c = 2 Omega sin(phi) [1/s]; latitude in degrees, negative in the south."""
    latitude = checked(
        "latitude", latitude, lambda lat: (np.abs(lat) >= MIN_ABS_LATITUDE) & (np.abs(lat) <= 90.0)
    )
    return 2.0 * EARTH_ROTATION_RATE * np.sin(np.deg2rad(latitude))


def boundary_layer_height_hat(stability_parameter, zilitinkevich_number, c_tn, c_cn, c_ns):
    """h_hat = h f_c/u* from 1/h_hat^2 = 1/C_TN^2 + mu_N/C_CN^2 + mu/C_NS^2, Eq. (h_hat_model)."""
    # np.power, not **: on a numpy scalar (one condition) ** takes C's pow, whose last bit can
    # differ from numpy's array loop; np.power gives a condition the same bits alone as in a batch.
    return np.power(1.0 / c_tn**2 + zilitinkevich_number / c_cn**2 + stability_parameter / c_ns**2,
                    -0.5)


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

