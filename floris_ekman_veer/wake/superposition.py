"""The momentum-conserving superposition of wakes of Zong & Porte-Agel (2020): the farm coupling's
alternative to summing the deficits (docs/coupling.md#wakes-deep-in-an-array). Beyond the paper,
which models one wake.

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
weight 1, the wake unchanged. Pure numpy.
"""

from __future__ import annotations

import numpy as np


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
