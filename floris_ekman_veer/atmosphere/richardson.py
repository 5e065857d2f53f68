"""A measured stability from temperatures (docs/measurements.md#reading-stability): the bulk
Richardson number of two temperatures and two speeds, and the Obukhov length it implies through
the same Businger-Dyer surface-layer forms as the model's (Businger et al. 1971, Dyer 1974;
integrated by Paulson 1970): psi_m = psi_h = -5 z/L stable (the paper's log-linear law), and
Paulson's psi_m, psi_h = 2 ln((1 + (1 - gamma z/L)^(1/2))/2) convective.

With theta* = u*^2 theta/(kappa g L), the surface layer's differences are
Delta theta = theta*/kappa F_h and Delta U = u*/kappa F_m, F = ln(z2/z1) - psi(z2/L) + psi(z1/L),
so the bulk Richardson number Ri_b = (g/theta) Delta theta Delta z_T / Delta U^2 equals
Delta z_T F_h / (L F_m^2), u* cancelling. The fit takes the measured Ri_b as a datum against
this function of its 1/L (rather than an L inverted from it: a stable Ri_b nears its
Businger-Dyer limit, Delta z_T^2 / (5 Delta z_U^2), for L of a few tens of metres, where the
inverse runs away); :func:`inverse_obukhov_length` gives the L it implies, by bisection."""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.atmosphere.constants import BUSINGER_DYER_GAMMA
from floris_ekman_veer.atmosphere.similarity import unstable_psi_m

GRAVITY = 9.81
KAPPA = 0.41
#: [1/m] The range of 1/L the inversion searches: |L| >= 2 m.
INVERSE_LENGTH_RANGE = (-0.5, 0.5)
#: The model error of a measured bulk Richardson number against the Businger-Dyer one,
#: relative to its value and absolute: the forms' own scatter (about 20 % in phi, Hogstrom
#: 1988, Boundary-Layer Meteorol. 42, 55-78) and the layer's departure from them above the
#: surface layer (the Ekman layer above 0.2 h); in quadrature with the sensors' noise.
RICHARDSON_MODEL_ERROR = (0.2, 0.005)


def psi_h(zeta, gamma=BUSINGER_DYER_GAMMA):
    """The heat's stability function: -5 zeta stable, Paulson's 2 ln((1 + y)/2),
    y = (1 - gamma zeta)^(1/2), convective."""
    zeta = np.asarray(zeta, float)
    y = np.sqrt(1.0 - gamma * np.minimum(zeta, 0.0))
    return np.where(zeta >= 0, -5.0 * np.maximum(zeta, 0.0), 2.0 * np.log(0.5 * (1.0 + y)))


def psi_m(zeta, gamma=BUSINGER_DYER_GAMMA):
    """The momentum's: -5 zeta stable, Paulson's integral of Businger-Dyer convective."""
    zeta = np.asarray(zeta, float)
    return np.where(zeta >= 0, -5.0 * np.maximum(zeta, 0.0), unstable_psi_m(zeta, gamma))


def _difference(psi, z1, z2, inverse_length):
    return np.log(z2 / z1) - psi(z2 * inverse_length) + psi(z1 * inverse_length)


def potential_temperature_difference(z1, z2, friction_velocity, obukhov_length, theta):
    """[K] theta(z2) - theta(z1) of the Businger-Dyer surface layer of u* [m/s] and L [m]
    (inf: neutral, 0) at a mean potential temperature theta [K]."""
    inverse = 1.0 / np.asarray(obukhov_length, float)
    u_star = np.asarray(friction_velocity, float)
    theta_star = u_star**2 * np.asarray(theta, float) * inverse / (KAPPA * GRAVITY)
    return theta_star / KAPPA * _difference(psi_h, z1, z2, inverse)


def bulk_richardson_number(delta_theta, delta_speed, theta, temperature_heights):
    """Ri_b = (g/theta) Delta theta Delta z_T / Delta U^2."""
    z1, z2 = temperature_heights
    return GRAVITY / theta * delta_theta * (z2 - z1) / delta_speed**2


def model_richardson_number(inverse_length, temperature_heights, speed_heights):
    """Ri_b of the Businger-Dyer layer of 1/L: Delta z_T F_h / (L F_m^2) (module docstring)."""
    (t1, t2), (u1, u2) = temperature_heights, speed_heights
    return ((t2 - t1) * inverse_length * _difference(psi_h, t1, t2, inverse_length)
            / _difference(psi_m, u1, u2, inverse_length) ** 2)


def inverse_obukhov_length(richardson, temperature_heights, speed_heights, iterations=60):
    """[1/m] the 1/L whose Businger-Dyer layer has the bulk Richardson number ``richardson``
    (arrays; NaN in, NaN out), by bisection in :data:`INVERSE_LENGTH_RANGE`; a Richardson
    number beyond the range's ends gives its end (a collapsed or a free-convective layer)."""
    ri = np.asarray(richardson, float)
    low = np.full(ri.shape, INVERSE_LENGTH_RANGE[0])
    high = np.full(ri.shape, INVERSE_LENGTH_RANGE[1])
    for _ in range(iterations):  # (vectorised over records; 60 halvings reach 1e-19 1/m)
        middle = 0.5 * (low + high)
        above = model_richardson_number(middle, temperature_heights, speed_heights) > ri
        high = np.where(above, middle, high)
        low = np.where(above, low, middle)
    return np.where(np.isfinite(ri), 0.5 * (low + high), np.nan)


def measured_richardson(temperatures, temperature_heights, speeds, temperature_noise,
                        speed_noise):
    """(Ri_b, its noise) per record from two potential temperatures [K] (n, 2) at
    ``temperature_heights`` [m] and two speeds [m/s] (n, 2): the noise from the sensors'
    (``temperature_noise`` [K] each, ``speed_noise`` [m/s] (n, 2)) by linearisation, with
    :data:`RICHARDSON_MODEL_ERROR` in quadrature. NaN where a datum is missing or the speed
    does not grow with height (no shear: no bulk Richardson number)."""
    theta = np.asarray(temperatures, float)
    speeds = np.asarray(speeds, float)
    delta_theta = theta[:, 1] - theta[:, 0]
    delta_speed = speeds[:, 1] - speeds[:, 0]
    mean = 0.5 * (theta[:, 0] + theta[:, 1])
    ok = np.isfinite(delta_theta) & np.isfinite(delta_speed) & (delta_speed > 0)
    shear = np.where(ok, delta_speed, 1.0)
    ri = np.where(ok, bulk_richardson_number(delta_theta, shear, mean, temperature_heights),
                  np.nan)
    scale = GRAVITY / mean * (temperature_heights[1] - temperature_heights[0]) / shear**2
    sigma_speed = np.hypot(*np.asarray(speed_noise, float).T)
    relative, absolute = RICHARDSON_MODEL_ERROR
    noise = np.sqrt((scale * np.sqrt(2.0) * temperature_noise) ** 2
                    + (2.0 * ri * sigma_speed / shear) ** 2 + (relative * ri) ** 2
                    + absolute**2)
    return ri, np.where(ok, noise, np.nan)
