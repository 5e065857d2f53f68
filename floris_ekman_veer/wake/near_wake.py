"""The near wake inside the potential core, x < x0: a super-Gaussian profile that carries the
rotor's thrust (docs/wake_model.md#near-wake). Beyond the paper, which holds the Gaussian's
centre at 2a on its initial width there (Eq. Cx) without conserving momentum.

Blondel & Cathelain (2020, Wind Energ. Sci. 5, 1225, "An alternative form of the super-Gaussian
wind turbine wake model", their Eqs. 4-9) write the wake as

    Delta u / U_h = C exp(-r_tilde^n / (2 sigma_tilde^2)),   r_tilde = r / D, sigma_tilde = sigma / D,

top-hat near the rotor (n large) and Gaussian far downstream (n = 2), with the centre deficit C
from the momentum integral: C = 2^(2/n - 1) - sqrt(2^(4/n - 2) - n C_T / (16 Gamma(2/n)
sigma_tilde^(4/n))), Bastankhah & Porte-Agel's (2014) C at n = 2. Here the width is the paper's
sigma_tilde (Eq. sigma_tilde, with C_T cos^3 beta as Eq. Cx has it) and C the paper's potential
core value 2a; the order n(x) is the one for which that momentum integral gives 2a. At x0 the
paper's Gaussian itself gives 2a (Eq. x0_transition), so n(x0) = 2 and the wake is the paper's
from x0 on; towards the rotor the narrower sigma_tilde needs a flatter, wider profile to carry
the thrust (n about 5 at the rotor for C_T = 0.8, Blondel & Cathelain's calibrated n(0) = 5.5).
No constant is added or fitted.

In the form exp(-(rho^2 / (2 s^2))^(n/2)) of a Gaussian of width s raised to n/2, the same
profile has s = sigma m with the width factor m = (2 sigma_tilde^2)^(1/n - 1/2) (m = 1 at n = 2):
the per-wake factors (n, m) of :func:`near_wake_shape` scale the paper's sigma(theta, x) and
shape its profile. Pure numpy.
"""

from __future__ import annotations

import numpy as np
from scipy.special import gamma

from .deficit import axial_induction, potential_core_length, sigma_tilde_squared

#: The velocity model's ``near_wake`` choices: the super-Gaussian of this module, or the
#: paper's Gaussian with its centre held at 2a.
NEAR_WAKES = ("super_gaussian", "potential_core")

#: The Gaussian's order: the paper's profile.
GAUSSIAN_ORDER = 2.0

#: Bisection steps of :func:`super_gaussian_order` (the interval halves each step: 2^-60 of
#: the bracket, below float64 resolution).
BISECTION_STEPS = 60


def _momentum_excess(n, c, loading, width_squared):
    # Blondel & Cathelain's momentum integral with centre deficit c, written as
    # n C_T' / (16 Gamma(2/n) s^(4/n)) - c (2^(2/n) - c): zero at the order that carries the
    # thrust, positive where the profile is too narrow to carry it.
    return (n * loading / (16.0 * gamma(2.0 / n) * width_squared ** (2.0 / n))
            - c * (2.0 ** (2.0 / n) - c))


def super_gaussian_order(centre_deficit, loading, width_squared):
    """The order n >= 2 of Blondel & Cathelain's super-Gaussian whose momentum integral gives
    the centre deficit ``centre_deficit`` (C) with the thrust ``loading`` (C_T cos^3 beta) and the
    squared normalised width ``width_squared`` (sigma_tilde^2 / D^2): the root of
    n C_T' / (16 Gamma(2/n) sigma_tilde^(4/n)) = C (2^(2/n) - C).

    2 where the Gaussian already carries the thrust (at and beyond x0). The root lies below
    n_max = 2 / (1 + log2 C), where Blondel & Cathelain's (smaller) root branch ends
    (2^(2/n - 1) = C); for C <= 1/2 there is no such end and the bracket is [2, 64]. Vectorised
    bisection over broadcast arrays.
    """
    c, loading, width_squared = np.broadcast_arrays(
        *(np.asarray(v, dtype=float) for v in (centre_deficit, loading, width_squared)))
    lower = np.full(c.shape, GAUSSIAN_ORDER)
    above_half = c > 0.5
    upper = np.where(above_half, 2.0 / (1.0 + np.log2(np.where(above_half, c, 1.0))), 64.0)
    needed = _momentum_excess(lower, c, loading, width_squared) > 0.0
    for _ in range(BISECTION_STEPS):
        middle = 0.5 * (lower + upper)
        too_narrow = _momentum_excess(middle, c, loading, width_squared) > 0.0
        lower = np.where(too_narrow, middle, lower)
        upper = np.where(too_narrow, upper, middle)
    return np.where(needed, 0.5 * (lower + upper), GAUSSIAN_ORDER)


def near_wake_shape(x, k_w, radius, ct, yaw):
    """(n, m): the super-Gaussian order and the width factor of the wake at x (module docstring).

    (2, 1), the paper's Gaussian, for x >= x0 (Eq. x0_transition) and wherever the Gaussian
    carries the thrust; inside the core n > 2 and m = (2 sigma_tilde^2 / D^2)^(1/n - 1/2).
    Arguments broadcast as in :func:`floris_ekman_veer.wake.deficit.max_deficit`.
    """
    x = np.maximum(np.asarray(x, dtype=float), 0.0)
    yaw = np.asarray(yaw, dtype=float)
    diameter = 2.0 * np.asarray(radius, dtype=float)
    inside = x < potential_core_length(k_w, radius, ct, yaw)
    width_squared = sigma_tilde_squared(x, k_w, radius, ct, yaw) / diameter**2
    loading = np.asarray(ct, dtype=float) * np.cos(yaw) ** 3
    centre = 2.0 * axial_induction(ct, yaw)
    inside, width_squared, loading, centre = np.broadcast_arrays(
        inside, width_squared, loading, centre)
    order = np.full(inside.shape, GAUSSIAN_ORDER)
    # The root only where it differs from 2 (planes hold few points inside a core).
    order[inside] = super_gaussian_order(centre[inside], loading[inside], width_squared[inside])
    factor = np.ones(inside.shape)
    shaped = order != GAUSSIAN_ORDER
    factor[shaped] = (2.0 * width_squared[shaped]) ** (1.0 / order[shaped] - 0.5)
    return order, factor
