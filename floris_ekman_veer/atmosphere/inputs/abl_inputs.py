"""The checks of `EkmanABL`'s keyword inputs (docs/atmosphere.md#input-ranges): the model
constants, the Coriolis parameter (or latitude), the free atmosphere's stratification and the
one stability input, each returned as the ABL stores it or refused with a ValueError naming the
input, its valid range (`VALID_RANGES`) and the offending entries."""

from __future__ import annotations

import numpy as np

from floris_ekman_veer._validation import real_array, require_at
from floris_ekman_veer.atmosphere.constants import (
    GRAVITY,
    PAPER_BRUNT_VAISALA_FREQUENCY,
    air_heat_capacity,
)
from floris_ekman_veer.atmosphere.inputs.input_ranges import (
    MAX_CORIOLIS_PARAMETER,
    MAX_LAPSE_RATE,
    MIN_COOLING_RATE,
    MIN_CORIOLIS_PARAMETER,
    VALID_RANGES,
    checked,
    within_heat_flux_range,
)
from floris_ekman_veer.atmosphere.similarity import coriolis_parameter_from_latitude
from floris_ekman_veer.atmosphere.inputs.stability_inputs import STABILITY_INPUTS


def checked_model_constants(**constants) -> dict:
    """The model constants (von_karman, c_g, stress_decay, c_tn, c_cn, c_ns, matching_fraction)
    as floats: each one number > 0, the matching fraction in (0, 1)."""
    for name, value in constants.items():
        ok = (lambda v: (v > 0) & (v < 1)) if name == "matching_fraction" else (lambda v: v > 0)
        if np.ndim(checked(name, value, ok)) != 0:
            raise ValueError(
                f"{name} must be a single number ({VALID_RANGES[name]}); got {value!r}")
    return {name: float(value) for name, value in constants.items()}


def checked_coriolis_parameter(coriolis_parameter, latitude):
    """The signed f_c [1/s] of exactly one of ``coriolis_parameter`` or ``latitude``."""
    if (coriolis_parameter is None) == (latitude is None):
        raise ValueError(
            "give exactly one of coriolis_parameter [1/s] or latitude [deg]; got "
            f"coriolis_parameter={coriolis_parameter!r}, latitude={latitude!r}"
        )
    if latitude is not None:
        return coriolis_parameter_from_latitude(latitude)
    return checked(
        "coriolis_parameter", coriolis_parameter,
        lambda f: (np.abs(f) >= MIN_CORIOLIS_PARAMETER) & (np.abs(f) <= MAX_CORIOLIS_PARAMETER),
    )


def free_atmosphere_frequency(brunt_vaisala_frequency, lapse_rate, reference_potential_temperature):
    """N [1/s] of at most one of ``brunt_vaisala_frequency`` or ``lapse_rate`` [K/m]
    (N = sqrt(g/Theta0 gamma)); default the paper's N_inf."""
    if brunt_vaisala_frequency is not None and lapse_rate is not None:
        raise ValueError(
            "give at most one of brunt_vaisala_frequency [1/s] or lapse_rate [K/m]"
        )
    if lapse_rate is not None:
        gamma = checked("lapse_rate", lapse_rate, lambda g: (g >= 0) & (g <= MAX_LAPSE_RATE))
        return np.sqrt(GRAVITY / reference_potential_temperature * gamma)
    if brunt_vaisala_frequency is None:
        brunt_vaisala_frequency = PAPER_BRUNT_VAISALA_FREQUENCY
    return checked("brunt_vaisala_frequency", brunt_vaisala_frequency, lambda n: n >= 0)


def checked_stability_input(values, reference_potential_temperature):
    """(name, value) of the one stability input given among ``values`` (by the names of
    `STABILITY_INPUTS`, None where not given); default neutral, ("stability_parameter", 0)."""
    given = {name: values[name] for name in STABILITY_INPUTS if values[name] is not None}
    if len(given) > 1:
        raise ValueError(
            "give at most one stability input among stability_parameter, cooling_rate, "
            f"surface_heat_flux, obukhov_length, sensible_heat_flux; got {sorted(given)}"
        )
    name = next(iter(given), "stability_parameter")
    value = real_array(name, given.get(name, 0.0), VALID_RANGES[name])
    # L = +-inf is the neutral limit of the Obukhov length; everything else must be finite.
    ok = {
        "stability_parameter": np.isfinite,
        "cooling_rate": lambda v: np.isfinite(v) & (np.abs(v) <= -MIN_COOLING_RATE),
        "surface_heat_flux": lambda v: within_heat_flux_range(
            v * air_heat_capacity(reference_potential_temperature)),
        "obukhov_length": lambda v: (v != 0) & ~np.isnan(v),
        "sensible_heat_flux": within_heat_flux_range,
    }[name]
    require_at(ok(value), name, VALID_RANGES[name], value)
    return name, value
