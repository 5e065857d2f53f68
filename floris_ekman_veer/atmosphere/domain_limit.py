"""What a reference-wind solve does with states outside the physical domain
(docs/atmosphere.md#a-fixed-stability-across-wind-speeds): refuse them, naming every speed that
leaves it and what to give instead, or, when asked by name, carry them with their stability
limited toward neutral to the domain's heat-flux bound.

A fixed Obukhov length L (or stability parameter mu, or a strong cooling rate) implies a surface
heat flux H that grows like u*^3 / L: from some wind speed on no surface produces it. With
``outside_domain="limit"`` each such condition is solved instead with the stability that puts
its H at the bound it crosses (-300 W/m^2 stable, +800 W/m^2 convective, within
`LIMIT_MARGIN`): beyond that speed the condition is the fixed-heat-flux layer at the bound,
whose L grows with u*^3, continuous with the given stability where it leaves the domain. The
stability is handed back in the input the user gave (the equivalent L, mu or C_r per
condition), so that the conditions inside keep their state bit for bit.
"""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.atmosphere.constants import ENTRAINMENT_RATIO
from floris_ekman_veer.atmosphere.inputs.input_ranges import SENSIBLE_HEAT_FLUX_RANGE
from floris_ekman_veer.atmosphere.inputs.stability_inputs import STABILITY_INPUTS

#: What a reference-wind solve does with conditions whose state leaves the physical domain:
#: "refuse" (the default: ValueError naming them) or "limit" (their stability limited toward
#: neutral to the heat-flux bound).
OUTSIDE_DOMAIN_POLICIES = ("refuse", "limit")

#: A limited condition's heat flux lies this fraction inside the bound, so that its state is
#: inside the domain after the re-solve's round-off.
LIMIT_MARGIN = 1e-9


def check_policy(outside_domain, name="outside_domain") -> str:
    """The policy, or ValueError naming ``name``, the value and the choices."""
    if not isinstance(outside_domain, str) or outside_domain not in OUTSIDE_DOMAIN_POLICIES:
        raise ValueError(f"{name} must be one of {list(OUTSIDE_DOMAIN_POLICIES)} (what to do "
                         "with conditions whose state leaves the physical domain, "
                         f"docs/atmosphere.md#a-fixed-stability-across-wind-speeds); got "
                         f"{outside_domain!r}")
    return outside_domain


def heat_flux_outside(abl) -> np.ndarray:
    """The conditions of a solved ``abl`` that leave the physical domain by the heat flux bound
    alone (bool, the state's shape): those ``limit`` carries."""
    check = abl.physical_domain()
    shape = np.shape(abl.friction_velocity)
    binding = np.broadcast_to(np.asarray(check.binding, dtype=object), shape)
    return np.asarray(binding == "sensible_heat_flux", dtype=bool)


def limited_stability(solve, abl, outside, speed, height, inputs):
    """The given stability input per condition, with each condition of ``outside`` replaced by
    the value that puts its heat flux at the bound it crosses (module docstring).

    ``solve(speed, height, inputs)`` is the reference-wind solve (refusing states outside),
    ``abl`` the solved atmosphere of ``inputs`` (states outside included), ``outside`` its
    conditions to limit (bool, the state's shape). Returns (name, values) of the stability input.
    """
    name = abl.stability_input
    shape = outside.shape
    low, high = SENSIBLE_HEAT_FLUX_RANGE
    flux = np.broadcast_to(abl.sensible_heat_flux, shape)[outside]
    bound = np.where(flux < 0.0, low, high) * (1.0 - LIMIT_MARGIN)
    pick = lambda value: (value if np.ndim(value) == 0  # noqa: E731
                          else np.broadcast_to(np.asarray(value, dtype=float), shape)[outside])
    others = {k: pick(v) for k, v in inputs.items()
              if v is not None and k not in STABILITY_INPUTS}
    at_bound = solve(pick(speed), pick(height), {**others, "sensible_heat_flux": bound})
    values = np.broadcast_to(np.asarray(abl.stability_value, dtype=float), shape).copy()
    values[outside] = _stability_value(at_bound, name)
    return name, values


def _stability_value(abl, name):
    """The value of stability input ``name`` that gives ``abl``'s state (inverse closures,
    docs/atmosphere.md#stability-closures)."""
    if name == "obukhov_length":
        return abl.obukhov_length
    if name == "stability_parameter":
        return abl.stability_parameter
    if name == "cooling_rate":
        # Cooling: Q0 = C_r h (paper Section 2.5); heating: Q0 = C_r z_i / (1 + A_e).
        q0, depth = abl.surface_heat_flux, abl.boundary_layer_height
        per_second = np.where(q0 < 0.0, q0 / depth, q0 * (1.0 + ENTRAINMENT_RATIO) / depth)
        return 3600.0 * per_second
    # The heat flux inputs are bounded by the domain's own range: they never leave it by H.
    raise ValueError(f"{name} cannot leave the physical domain by its heat flux")
