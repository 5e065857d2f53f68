"""Streamwise turbulence intensity and wake expansion rate from the ABL state.

Paper Section 2.3: the Townsend-Perry logarithmic law for the streamwise variance,
Eq. (upup_var) ``<u'u'>/u*^2 = -A1 ln(z/h) + B1``, gives the turbulence intensity
Eq. (Iu_model) and, through ``k_w = alpha' I_u`` merged smoothly with the
mixing-layer floor of stable flows, the wake expansion rate Eq. (kw_CNBL_SBL_model).

These are pure numpy functions of the ABL scalars (u*, h, U_h); `EkmanABL` exposes them
as methods, and the FLORIS wake model calls `wake_expansion_rate` with its own (user
configurable) constants.
"""

from __future__ import annotations

import numpy as np

#: Townsend-Perry constant A1 (paper Section 2.3).
TOWNSEND_PERRY_A1 = 1.25
#: Flow-dependent intercept B1 of the variance law, fitted to the paper's LES.
TOWNSEND_PERRY_B1 = 0.6
#: Proportionality k_w = alpha' I_u (paper: 0.33, within the 0.3-0.35 of field data).
ALPHA_PRIME = 0.33
#: Expansion rate of the wake's own mixing layer, the floor in low-turbulence flows.
MIXING_LAYER_FLOOR = 0.021
#: Exponent of the smooth maximum in Eq. (kw_CNBL_SBL_model).
MERGE_EXPONENT = 6.0
#: Panofsky et al. (1977) convective scaling sigma_u/u* = (12 - 0.5 z_i/L)^(1/3): the neutral
#: term and the buoyant coefficient (docs/atmosphere.md#convective-turbulence).
PANOFSKY_NEUTRAL = 12.0
PANOFSKY_BUOYANT = 0.5


def convective_variance(mixed_layer_height, obukhov_length):
    """The buoyant excess of the streamwise variance over the paper's law, <u'u'>_c/u*^2 =
    (12 - 0.5 z_i/L)^(2/3) - 12^(2/3) for L < 0 (Panofsky et al. 1977, the part of their
    sigma_u/u* = (12 - 0.5 z_i/L)^(1/3) that convection adds to its neutral value), 0 for L >= 0
    or infinite (docs/atmosphere.md#convective-turbulence). It vanishes continuously as 1/L -> 0."""
    z_i = np.asarray(mixed_layer_height, dtype=float)
    inverse = 1.0 / np.asarray(obukhov_length, dtype=float)
    unstable = inverse < 0
    # np.power: the same bits for a numpy scalar (one condition) as in an array of conditions
    excess = np.power(PANOFSKY_NEUTRAL - PANOFSKY_BUOYANT * z_i * np.where(unstable, inverse, 0.0),
                      2.0 / 3.0) - PANOFSKY_NEUTRAL ** (2.0 / 3.0)
    return np.where(unstable, excess, 0.0)


def turbulence_top(boundary_layer_height, A1=TOWNSEND_PERRY_A1, B1=TOWNSEND_PERRY_B1):
    """z_t = h exp(B1/A1) (1.62 h with the paper's constants), where Eq. (upup_var) gives zero
    variance (docs/atmosphere.md#shallow-boundary-layer)."""
    return np.asarray(boundary_layer_height, dtype=float) * np.exp(B1 / A1)


def _variance_factor(height, boundary_layer_height, A1, B1, convective=0.0):
    """sqrt(max(A1 ln(h/z) + B1, 0) + c(z)), Eq. (upup_var) continued to its zero above h, plus
    the convective excess c (`convective_variance`, 0 in neutral and stable layers), uniform in
    the mixed layer (Panofsky et al. 1977) and tapered linearly from h to h exp(B1/A1) above it.

    Inside the ABL (z < h) this is the paper's law unchanged. At z = h the law still gives
    <u'u'> = B1 u*^2, while the geostrophic flow above is laminar: stopping the law at h would
    make I_u, the wake expansion and therefore farm power jump when a weakening wind lowers h
    through a hub height. The law is instead continued to where its own variance vanishes,
    z_t = h exp(B1/A1) (`turbulence_top`), and is zero above: continuous in z, h and u*, with
    no new constant (docs/atmosphere.md#shallow-boundary-layer).
    """
    height = np.asarray(height, dtype=float)
    boundary_layer_height = np.asarray(boundary_layer_height, dtype=float)
    top = turbulence_top(boundary_layer_height, A1, B1)
    inside = height < top
    ratio = np.where(inside, boundary_layer_height / np.where(inside, height, 1.0), 1.0)
    depth = top - boundary_layer_height
    taper = np.clip(np.divide(top - height, depth, out=np.ones(np.broadcast(height, depth).shape),
                              where=depth > 0), 0.0, 1.0)
    variance = np.maximum(A1 * np.log(ratio) + B1, 0.0) + np.asarray(convective, float) * taper
    return np.where(inside, np.sqrt(variance), 0.0)


def streamwise_turbulence_intensity(
    height,
    friction_velocity,
    boundary_layer_height,
    reference_speed,
    A1: float = TOWNSEND_PERRY_A1,
    B1: float = TOWNSEND_PERRY_B1,
    convective=0.0,
    turbulence_factor=None,
):
    """I_u = [A1 ln(h/z) + B1]^(1/2) u*/U_ref, Eq. (Iu_model); above h the law is continued to
    its zero at h exp(B1/A1) and is 0 higher up (see `_variance_factor`). In a convective layer
    ``convective`` (`convective_variance`, with h = z_i) adds the buoyant variance of Panofsky
    et al. (1977) (docs/atmosphere.md#convective-turbulence).

    ``reference_speed`` is U_h in the paper (hub-height speed); any positive speed works.
    Heights must be positive (the caller checks them against the roughness length).
    ``turbulence_factor`` (beyond the paper; None: the paper's I_u) scales it to a site's
    ambient turbulence (docs/atmosphere.md#ambient-turbulence).
    """
    intensity = (
        _variance_factor(height, boundary_layer_height, A1, B1, convective)
        * np.asarray(friction_velocity, dtype=float)
        / np.asarray(reference_speed, dtype=float)
    )
    if turbulence_factor is None:
        return intensity
    return intensity * np.asarray(turbulence_factor, dtype=float)


def wake_expansion_rate(
    friction_velocity,
    boundary_layer_height,
    hub_height,
    hub_speed,
    A1: float = TOWNSEND_PERRY_A1,
    B1: float = TOWNSEND_PERRY_B1,
    alpha_prime: float = ALPHA_PRIME,
    floor: float = MIXING_LAYER_FLOOR,
    n: float = MERGE_EXPONENT,
    convective=0.0,
    turbulence_factor=None,
):
    """k_w = [floor^n + (alpha' I_u(z_h))^n]^(1/n), Eq. (kw_CNBL_SBL_model).

    The smooth maximum keeps k_w from falling below the mixing-layer spreading rate of
    weakly turbulent (stable) inflow, following Vahidi & Porte-Agel (2022).

    A hub at or above h (a boundary layer shallower than the rotor, weak-wind stable nights)
    is allowed: I_u follows the variance law continued above h (`_variance_factor`), so k_w
    falls continuously to the floor, reached for hubs at or above h exp(B1/A1), the limit of
    vanishing ambient turbulence (docs/atmosphere.md#shallow-boundary-layer).

    ``convective``: the buoyant variance of a convective layer (`convective_variance`), so
    that k_w = alpha' I_u keeps the paper's form there (docs/atmosphere.md#convective-turbulence).
    ``turbulence_factor``: I_u scaled to the site's ambient turbulence (beyond the paper;
    docs/atmosphere.md#ambient-turbulence), so that k_w = alpha' I_0 with the measured I_0.
    """
    hub_height = np.asarray(hub_height, dtype=float)
    turbulent = alpha_prime * streamwise_turbulence_intensity(
        hub_height, friction_velocity, boundary_layer_height, hub_speed, A1, B1, convective,
        turbulence_factor,
    )
    return np.power(floor**n + np.power(turbulent, n), 1.0 / n)
