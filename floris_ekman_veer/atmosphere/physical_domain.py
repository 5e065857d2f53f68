"""The physical domain of a solved atmosphere (docs/atmosphere.md#physical-domain): the bounds of
the quantities a state implies (sensible heat flux, geostrophic wind, a convective layer's
cross-isobaric angle), where states lie in it, and why a state leaves it."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from floris_ekman_veer.atmosphere.inputs.input_ranges import (
    MAX_CONVECTIVE_CROSS_ISOBARIC_ANGLE,
    MAX_GEOSTROPHIC_WIND,
    SENSIBLE_HEAT_FLUX_RANGE,
)

#: The physical domain of a solved atmosphere, whichever stability input drives it
#: (`physical_domain`, docs/atmosphere.md#physical-domain): the implied quantity, its range and
#: its unit. The cross-isobaric angle's bound holds where the layer is convective (mu < 0).
PHYSICAL_DOMAIN = {
    "sensible_heat_flux": (SENSIBLE_HEAT_FLUX_RANGE[0], SENSIBLE_HEAT_FLUX_RANGE[1], "W/m^2"),
    "geostrophic_wind": (0.0, MAX_GEOSTROPHIC_WIND, "m/s"),
    "cross_isobaric_angle": (
        -MAX_CONVECTIVE_CROSS_ISOBARIC_ANGLE, MAX_CONVECTIVE_CROSS_ISOBARIC_ANGLE, "deg"
    ),
}


class DomainCheck(NamedTuple):
    """Where states lie in the `PHYSICAL_DOMAIN` (`physical_domain`); every array has the
    states' broadcast shape.

    - ``inside``: bool, True where every bound holds;
    - ``binding``: str, the name of the first bound a state leaves (in `PHYSICAL_DOMAIN`'s
      order), "" inside;
    - ``margin``: float, the smallest relative slack over the bounds, (value - bound)/|range
      end| on the side that binds: > 0 inside, <= 0 outside (a continuous constraint value for
      a fit that keeps its trial states inside);
    - ``values``: the implied quantities checked, by name.
    """

    inside: np.ndarray
    binding: np.ndarray
    margin: np.ndarray
    values: dict


def physical_domain(sensible_heat_flux, geostrophic_wind, cross_isobaric_angle,
                    stability_parameter) -> DomainCheck:
    """Which bound of the `PHYSICAL_DOMAIN` each state leaves, vectorised, without raising
    (docs/atmosphere.md#physical-domain): the surface sensible heat flux H [W/m^2], the
    geostrophic wind G [m/s] and, where the layer is convective (``stability_parameter`` mu < 0),
    the cross-isobaric angle [deg]. Arguments broadcast together; NaN counts as outside.
    `EkmanABL.physical_domain` applies it to a solved atmosphere, whichever stability input
    drove it; the constructor and `EkmanABL.from_reference_wind` refuse states outside."""
    values = {
        "sensible_heat_flux": np.asarray(sensible_heat_flux, dtype=float),
        "geostrophic_wind": np.asarray(geostrophic_wind, dtype=float),
        "cross_isobaric_angle": np.asarray(cross_isobaric_angle, dtype=float),
    }
    convective = np.asarray(stability_parameter, dtype=float) < 0
    shape = np.broadcast_shapes(convective.shape, *(v.shape for v in values.values()))
    binding = np.full(shape, "", dtype=object)
    margin = np.full(shape, np.inf)
    for name, value in values.items():
        low, high, _ = PHYSICAL_DOMAIN[name]
        with np.errstate(invalid="ignore"):
            slack = np.minimum(
                (value - low) / max(abs(low), 1.0) if low < 0 else (value - low) / high,
                (high - value) / high,
            )
        slack = np.where(np.isnan(slack), -np.inf, slack)
        if name == "cross_isobaric_angle":
            slack = np.where(convective, slack, np.inf)
        binding = np.where((binding == "") & (slack <= 0), name, binding)
        margin = np.minimum(margin, slack)
    inside = binding == ""
    return DomainCheck(inside[()], binding[()], margin[()],
                       {k: np.broadcast_to(v, shape)[()] for k, v in values.items()})


def outside_domain_reason(name, value):
    """Why a state leaves the physical domain: the implied quantity, its value and range."""
    low, high, unit = PHYSICAL_DOMAIN[name]
    what, hint = {
        "sensible_heat_flux": (
            "the surface sensible heat flux H they imply",
            "give weaker stability (|L| larger, |mu|, |Q0| or |C_r| smaller) or check its units",
        ),
        "geostrophic_wind": (
            "the geostrophic wind G they imply",
            "check the units of the wind speed and the roughness length",
        ),
        "cross_isobaric_angle": (
            "the cross-isobaric angle alpha_0 of the convective layer they imply",
            "the mixed layer is too shallow for its u*/f_c: give a deeper mixed_layer_height "
            "(or none: the neutral height) or a higher latitude",
        ),
    }[name]
    return (
        f"{what} is {value:.4g} {unit}, outside {low:g} to {high:g} {unit} "
        f"(docs/atmosphere.md#physical-domain): {hint}"
    )
