"""The turbulence a wake adds, as Ishihara & Qian (2018) write it: an alternative to FLORIS's
Crespo-Hernandez form for the farm coupling's wake-added turbulence
(docs/coupling.md#wakes-deep-in-an-array). Beyond the paper, which models one wake.

Ishihara & Qian (2018, J. Wind Eng. Ind. Aerodyn. 177, 275, "A new Gaussian-based analytical
wake model for wind turbines considering ambient turbulence intensities and thrust coefficient
effects", their added-turbulence model) fit the added streamwise turbulence intensity behind a rotor of
diameter D and hub height H, at x downstream and r from the wake axis, to LES and wind-tunnel
wakes (C_T 0.4-0.9, I_a 0.035-0.137):

    Delta I = [k1 exp(-(r - D/2)^2 / (2 sigma^2)) + k2 exp(-(r + D/2)^2 / (2 sigma^2))]
              / (d + e x/D + f (1 + x/D)^-2) - delta(z),

    k1 = cos^2(pi/2 (r/D - 1/2)), k2 = cos^2(pi/2 (r/D + 1/2)) for r <= D/2; k1 = 1, k2 = 0 beyond,
    sigma / D = k* x/D + epsilon, k* = 0.11 C_T^1.07 I_a^0.20, epsilon = 0.23 C_T^-0.25 I_a^0.17,
    d = 2.3 C_T^-1.2, e = 1.0 I_a^0.1, f = 0.7 C_T^-3.2 I_a^-0.45,
    delta(z) = I_a sin^2(pi (H - z) / H) below the hub (z < H), 0 above:

a ring peaked at the rotor's edge, the tip shear layer, that fills the axis as the wake widens,
less below the hub where the ground's own turbulence already is (delta). The constants are the
published ones, unchanged. Pure numpy.
"""

from __future__ import annotations

import numpy as np


def ishihara_qian_added_turbulence(x, r, z, thrust_coefficient, ambient_turbulence, diameter,
                                   hub_height):
    """Delta I of Ishihara & Qian (2018, the module docstring) at x [m] downstream,
    r [m] from the wake axis, height z [m], behind a rotor of ``diameter`` and ``hub_height``
    [m] with thrust coefficient C_T in an ambient streamwise turbulence intensity I_a
    (arrays broadcast)."""
    x_d = np.asarray(x, dtype=float) / diameter
    r_d = np.asarray(r, dtype=float) / diameter
    ct = np.asarray(thrust_coefficient, dtype=float)
    ia = np.asarray(ambient_turbulence, dtype=float)
    width = 0.11 * ct**1.07 * ia**0.20 * x_d + 0.23 * ct**-0.25 * ia**0.17
    inner = r_d <= 0.5
    k1 = np.where(inner, np.cos(0.5 * np.pi * (r_d - 0.5)) ** 2, 1.0)
    k2 = np.where(inner, np.cos(0.5 * np.pi * (r_d + 0.5)) ** 2, 0.0)
    ring = (k1 * np.exp(-((r_d - 0.5) ** 2) / (2.0 * width**2))
            + k2 * np.exp(-((r_d + 0.5) ** 2) / (2.0 * width**2)))
    decay = 2.3 * ct**-1.2 + 1.0 * ia**0.1 * x_d + 0.7 * ct**-3.2 * ia**-0.45 * (1.0 + x_d) ** -2
    below = np.asarray(z, dtype=float) < hub_height
    ground = np.where(below, ia * np.sin(np.pi * (hub_height - z) / hub_height) ** 2, 0.0)
    return ring / decay - ground
