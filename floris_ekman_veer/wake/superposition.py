"""Two published alternatives to summing the wakes' deficits in a farm: the momentum-conserving
superposition of Zong & Porte-Agel (2020) and the cumulative wake of Bastankhah et al. (2021)
(docs/coupling.md#wakes-deep-in-an-array). Beyond the paper, which models one wake.

Zong & Porte-Agel (2020, J. Fluid Mech. 889, A8, "A momentum-conserving wake superposition method
for wind farm power prediction", their Section 2) weight each wake's deficit u_i with the
ratio of its own convection velocity U_c,i to that of the combined wake U_c,

    U_0 - U = sum_i (U_c,i / U_c) u_i,

so that the combined wake carries the sum of the wakes' momentum deficits. The convection velocity
of a wake is its deficit-weighted mean velocity, U_c = int U (U_0 - U) dA / int (U_0 - U) dA over
the cross-plane; of a Gaussian deficit u_i = u_c,i exp(-r^2 / (2 sigma_i^2)) behind a rotor whose
incoming speed is U_in,i that is U_c,i = U_in,i - u_c,i / 2 (its velocity U_in,i - u_i, with
int g^2 dA / int g dA = 1/2). For the combined wake the plane integrals of the Gaussians give

    U_c = U_0 - Q / U_c,   Q = sum_ij s_i s_j G_ij / sum_i s_i 2 pi sigma_i^2,   s_i = U_c,i u_c,i,

G_ij = int g_i g_j dA (:func:`gaussian_product_integral`), a quadratic whose root near U_0,
(U_0 + sqrt(U_0^2 - 4 Q)) / 2, is the fixed point Zong & Porte-Agel iterate to
(:func:`convection_velocity`). One wake behind an unwaked rotor (U_in = U_0) gets U_c = U_c,1:
weight 1, the wake unchanged.

Bastankhah, Welch, Martinez-Tossas, King & Fleming (2021, J. Fluid Mech. 911, A53, "Analytical
solution for the cumulative wake of wind turbines in wind farms", their Eqs. 4.9-4.10) instead
give each wake n the centre deficit that carries its rotor's thrust through the wakes already
there: with the upstream wakes' centre deficits C_i at the same x,

    C_n = a - sqrt(a^2 - C_T U_n^2 D^2 / (8 sigma_n^2)),   a = U_0 - sum_i lambda_ni C_i,
    lambda_ni = 2 sigma_i^2 / (sigma_n^2 + sigma_i^2) exp(-d_ni^2 / (2 (sigma_n^2 + sigma_i^2))),

U_n the rotor's incoming speed, the deficits then summed (:func:`cumulative_deficit`; the factor
2 of Eq. 4.9 as PyWake's CumulativeWakeSum takes it, FLORIS's cc uses 1). The model's own
single-wake momentum term K = C_T D^2 / (8 sigma^2) is taken from its C(x) (K = 1 - (1 - C)^2), so
that without upstream wakes and U_n = U_0 the wake is the model's. Numpy, and Eq. 4.10 as one
compiled ufunc that the point-wise grids call on arrays and the turbine grid's compiled sum
(plugin/rotor/upstream_wakes.py) on numbers.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .fused import JIT

#: Wakes more than sqrt(2 * OVERLAP_EXPONENT_LIMIT) combined widths apart share nothing in
#: :func:`overlap_weight`: lambda below 2 exp(-16) = 2.3e-7 is negligible and taken as 0 (it
#: moves C_n by less than 2.3e-7 of the upstream deficits; farm powers by < 1e-7 relative,
#: docs/coupling.md), and a kept wake that far away at every height costs the cumulative sum
#: no exp (plugin/rotor/upstream_wakes.py; 40 before: 5 % of the sum's time).
OVERLAP_EXPONENT_LIMIT = 16.0


def gaussian_product_integral(sigma_squared_a, sigma_squared_b, distance_squared):
    """int g_a g_b dA over the cross-plane of two unit Gaussians exp(-r^2 / (2 sigma^2)) whose
    centres lie ``distance`` apart: 2 pi s_a s_b / (s_a + s_b) exp(-d^2 / (2 (s_a + s_b))),
    s = sigma^2 (pi sigma^2 for a Gaussian with itself)."""
    total = sigma_squared_a + sigma_squared_b
    return (2.0 * np.pi * sigma_squared_a * sigma_squared_b / total
            * np.exp(-distance_squared / (2.0 * total)))


def wake_convection_velocity(incoming_speed, centre_deficit):
    """U_c,i = U_in,i - u_c,i / 2 of a Gaussian wake with centre deficit u_c,i [m/s] behind a
    rotor whose incoming speed is U_in,i (the module docstring)."""
    return incoming_speed - 0.5 * centre_deficit


def convection_velocity(ambient_speed, momentum_ratio):
    """U_c of the combined wake, the root of U_c^2 - U_0 U_c + Q = 0 near U_0 with ``momentum_ratio``
    Q (the module docstring); where the wakes' momentum deficit exceeds what a real root allows
    (4 Q > U_0^2, wakes that stop the flow) U_c = U_0 / 2, the root's limit."""
    return 0.5 * (ambient_speed
                  + np.sqrt(np.maximum(ambient_speed**2 - 4.0 * momentum_ratio, 0.0)))


def overlap_weight(sigma_squared_new, sigma_squared_old, distance_squared):
    """lambda_ni of Bastankhah et al. (2021, Eq. 4.9, the module docstring): the share of an
    upstream wake i's centre deficit that wake n's momentum balance meets."""
    total = sigma_squared_new + sigma_squared_old
    exponent = distance_squared / (2.0 * total)
    return np.where(exponent < OVERLAP_EXPONENT_LIMIT,
                    2.0 * sigma_squared_old / total
                    * np.exp(-np.minimum(exponent, OVERLAP_EXPONENT_LIMIT)), 0.0)


@numba.vectorize(["float64(float64, float64, float64, float64, float64)"],
                 cache=JIT["cache"])
def cumulative_deficit(single_deficit, ambient_speed, incoming_speed, upstream, core_deficit):
    """C_n [m/s] of Bastankhah et al. (2021, Eq. 4.10, the module docstring): ``single_deficit``
    the model's C(x) / U_h of the wake alone, ``ambient_speed`` U_0, ``incoming_speed`` U_n,
    ``upstream`` sum_i lambda_ni C_i [m/s]; where the root is not real, or beyond it, the
    potential core's ``core_deficit`` [m/s] (2a U_n), as PyWake's CumulativeWakeSum bounds it.
    A ufunc: arrays broadcast."""
    momentum = 1.0 - (1.0 - single_deficit) ** 2
    a = ambient_speed - upstream
    root = a**2 - momentum * incoming_speed**2
    deficit = a - math.sqrt(max(root, 0.0))
    return deficit if root > 0.0 and deficit <= core_deficit else core_deficit
