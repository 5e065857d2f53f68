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
published ones, unchanged; in numpy.

FLORIS's Crespo-Hernandez form (Crespo & Hernandez 1996, as FLORIS's ``CrespoHernandez`` model
has it, with its exponents as parameters) is compiled here for the solver on a turbine grid
(:func:`crespo_hernandez_overlap`): the same formula, operation by operation, so the same bits
as FLORIS's own call [`test_compiled_crespo_hernandez_is_floris_s`].
"""

from __future__ import annotations

import numba
import numpy as np

from .fused import JIT


@numba.njit(inline="always", **JIT)
def crespo_hernandez(ambient_turbulence, x, x_source, diameter, axial_induction, constant, ai,
                     initial, downstream):
    """FLORIS's ``CrespoHernandez.function`` at one point (floris/core/wake_turbulence/
    crespo_hernandez.py): constant a^ai I_0^initial (dx / D)^downstream downstream of the
    rotor (dx = x - x_source > -0.1 m), 0 upstream; dx within 0.1 m of the rotor is taken as
    dx + 1 m, as FLORIS does."""
    delta_x = x - x_source
    upstream = 1.0 if delta_x <= 0.1 else 0.0
    downstream_mask = 1.0 if delta_x > -0.1 else 0.0
    delta_x = delta_x * downstream_mask + 1.0 * upstream
    return (constant * axial_induction**ai * ambient_turbulence**initial
            * (delta_x / diameter) ** downstream) * downstream_mask


@numba.njit(**JIT)
def _crespo_hernandez_overlap(ambient_turbulence, x, x_source, diameter, axial_induction,
                              overlap, y, y_source, lateral, constant, ai, initial, downstream,
                              out):
    for p in range(x.shape[0]):
        for m in range(x.shape[1]):
            added = crespo_hernandez(ambient_turbulence[p], x[p, m], x_source[p], diameter[p],
                                     axial_induction[p], constant, ai, initial, downstream)
            # numpy's nan_to_num(added, posinf=0.0), as FLORIS's solver takes it
            if np.isnan(added) or added == np.inf:
                added = 0.0
            elif added == -np.inf:
                added = -np.finfo(np.float64).max
            # FLORIS's solver's factors, in its order (each 1 or 0).
            added = overlap[p] * added * (1.0 if x[p, m] > x_source[p] else 0.0)
            if lateral:
                added = added * (1.0 if abs(y_source[p] - y[p, m]) < 2 * diameter[p] else 0.0)
            out[p, m] = added * (1.0 if x[p, m] <= 15 * diameter[p] + x_source[p] else 0.0)


def crespo_hernandez_overlap(ambient_turbulence, x, x_source, diameter, axial_induction,
                             overlap, parameters, y=None, y_source=None):
    """The wake-added turbulence of wakes at points as FLORIS's sequential solver weights it:
    ``overlap`` times :func:`crespo_hernandez` (NaN and +inf as 0), downstream of the source,
    within 2 D of it laterally (with the points' ``y`` (pairs, points) and the sources'
    ``y_source``) and within 15 D downstream; per wake and rotor (pairs,) the ambient
    turbulence, the source's x, diameter and axial induction, and the rotor's overlap; ``x``
    (pairs, points) the rotor's points; ``parameters`` FLORIS's (constant, ai, initial,
    downstream). Returns (pairs, points)."""
    x = np.ascontiguousarray(x, dtype=float)
    out = np.empty(x.shape)
    per_pair = [np.ascontiguousarray(a, dtype=float).reshape(-1) for a in (
        ambient_turbulence, x_source, diameter, axial_induction, overlap)]
    lateral = y is not None
    y = np.ascontiguousarray(y, dtype=float) if lateral else x
    y_source = (np.ascontiguousarray(y_source, dtype=float).reshape(-1) if lateral
                else per_pair[1])
    _crespo_hernandez_overlap(per_pair[0], x, *per_pair[1:], y, y_source, lateral,
                              *(float(v) for v in parameters), out)
    return out


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
