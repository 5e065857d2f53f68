"""Model M-3 of the paper: the Gaussian wake of Bastankhah & Porte-Agel (2014), without yaw or veer.

    Delta u / U_inf = C(x) exp[-(dy^2 + dz^2) / (2 sigma^2)],
    sigma/D = k* x/D + 0.2 sqrt(beta_BP),   beta_BP = (1 + sqrt(1 - C_T)) / (2 sqrt(1 - C_T)),
    C(x) = 1 - sqrt(1 - C_T / (8 (sigma/D)^2))                                   (docs/wake_model.md#m-3)

Near the rotor the far-wake C(x) is undefined (negative root argument for sigma/D < sqrt(C_T/8))
and, where it is defined but sigma/D < 1/sqrt(8), it exceeds the momentum-theory deficit
2a = 1 - sqrt(1 - C_T) of the fully expanded stream tube. C is therefore capped at 2a: the far-wake
expression is evaluated at max(sigma/D, 1/sqrt(8)), where it equals 2a exactly, so C(x) is
continuous and the cap covers the whole undefined region. beta_BP is the un-yawed A* of Eq.
(A_star), so this is exactly the paper's model at beta = 0 with k_w = k* (potential core
included).
"""

from __future__ import annotations

import numpy as np

from floris_ekman_veer._validation import positive

from .deficit import unyawed_thrust_coefficient

def bastankhah2014_wake(x, *, ct, diameter, k_star):
    """The Gaussian's width sigma (m) and its magnitude C(x) at x (C capped at 2a, module
    docstring): Delta u / U_inf = C exp(-(dy^2 + dz^2) / (2 sigma^2)) for x > 0
    (:func:`bastankhah2014_deficit`)."""
    x = np.asarray(x, dtype=float)
    ct = unyawed_thrust_coefficient(ct)
    diameter = positive(diameter, "diameter")
    k_star = positive(k_star, "k_star")
    root = np.sqrt(1.0 - ct)
    beta_bp = 0.5 * (1.0 + root) / root
    # Upstream points carry no wake; evaluating them at the rotor plane keeps every term finite.
    sigma_d = k_star * np.maximum(x, 0.0) / diameter + 0.2 * np.sqrt(beta_bp)
    # The cap: 8 (sigma/D)^2 floored at 1 (sigma/D = 1/sqrt(8)) makes q = C_T there, C = 2a.
    q = ct / np.maximum(8.0 * sigma_d**2, 1.0)
    # = 1 - sqrt(1 - q) without the cancellation for small q; q <= C_T < 1.
    return sigma_d * diameter, q / (1.0 + np.sqrt(1.0 - q))


def bastankhah2014_deficit(x, dy, dz, *, ct, diameter, k_star):
    """Normalised deficit Delta u / U_inf of the Bastankhah & Porte-Agel (2014) Gaussian wake.

    Parameters
    ----------
    x : streamwise distance behind the rotor (m); the deficit is 0 for x <= 0.
    dy, dz : y - y_T and z - z_h, distances from the (undeflected) rotor axis (m).
    ct : thrust coefficient in [0, 1).
    diameter : rotor diameter D > 0 (m).
    k_star : wake growth rate k* > 0.

    C(x) is capped at 2a = 1 - sqrt(1 - C_T) close to the rotor (module docstring).
    """
    x = np.asarray(x, dtype=float)
    dy = np.asarray(dy, dtype=float)
    dz = np.asarray(dz, dtype=float)
    sigma, magnitude = bastankhah2014_wake(x, ct=ct, diameter=diameter, k_star=k_star)
    gaussian = np.exp(-(dy**2 + dz**2) / (2.0 * sigma**2))
    return np.where(x > 0.0, magnitude * gaussian, 0.0)
