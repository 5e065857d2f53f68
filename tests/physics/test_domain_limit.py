"""A fixed stability across wind speeds (docs/atmosphere.md#a-fixed-stability-across-wind-speeds):
the reference-wind solve refuses the states outside the physical domain naming every speed, or,
with ``outside_domain="limit"``, carries those that leave it by their heat flux with the
stability limited toward neutral to the bound, in the stability input the caller gave."""

from __future__ import annotations

import numpy as np
import pytest

from floris_ekman_veer.atmosphere.constants import air_heat_capacity
from floris_ekman_veer.atmosphere.domain_limit import LIMIT_MARGIN
from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.atmosphere.inputs.input_ranges import SENSIBLE_HEAT_FLUX_RANGE

FORCING = dict(coriolis_parameter=1e-4, roughness_length=0.1, brunt_vaisala_frequency=6.1e-3,
               reference_potential_temperature=265.0)
SPEEDS = np.arange(3.0, 25.01, 1.0)
LOW, HIGH = SENSIBLE_HEAT_FLUX_RANGE


@pytest.mark.parametrize(("stability", "first_outside"), [
    (dict(obukhov_length=100.0), 20.0),         # inputs/farm_night.yaml
    (dict(stability_parameter=148.49), 20.0),   # inputs/farm_sbl6.yaml, Table 1's SBL-6
    (dict(cooling_rate=-1.0), 21.0),            # the LES's SBL-6 forcing at 90 m
    (dict(obukhov_length=-100.0, mixed_layer_height=1500.0), 14.0),  # a convective afternoon
])
def test_the_limit_puts_the_heat_flux_at_the_bound_beyond_the_speed_that_leaves(stability,
                                                                             first_outside):
    """Refused by default naming every speed from the first outside; limited, those speeds sit
    at the bound they cross (within LIMIT_MARGIN), the stability is handed back in the input
    given and reproduces the state, |L| grows with the wind beyond, and the speeds inside are
    the refusing solve's bit for bit."""
    outside = SPEEDS >= first_outside
    with pytest.raises(ValueError, match=rf"{outside.sum()} of {SPEEDS.size} conditions leave it: "
                                         rf"wind speeds {first_outside:g}(,| to)"):
        EkmanABL.from_reference_wind(SPEEDS, 90.0, **stability, **FORCING)
    abl = EkmanABL.from_reference_wind(SPEEDS, 90.0, outside_domain="limit", **stability,
                                       **FORCING)
    np.testing.assert_array_equal(abl.domain_limited, outside)
    flux = abl.sensible_heat_flux
    bound = LOW if flux[-1] < 0 else HIGH
    np.testing.assert_allclose(flux[outside], bound * (1 - LIMIT_MARGIN), rtol=1e-9)
    assert np.all(np.abs(flux[~outside]) < abs(bound))
    assert np.all(np.diff(np.abs(abl.obukhov_length[outside])) > 0)
    # The given input's name, one value per condition: the given one inside.
    (name, given), = ((k, v) for k, v in stability.items() if k != "mixed_layer_height")
    assert abl.stability_input == name
    np.testing.assert_array_equal(abl.stability_value[~outside], given)
    again = EkmanABL.from_reference_wind(
        SPEEDS[outside], 90.0, **{**stability, name: abl.stability_value[outside]}, **FORCING)
    np.testing.assert_allclose(again.friction_velocity, abl.friction_velocity[outside],
                               rtol=1e-10)
    inside = EkmanABL.from_reference_wind(SPEEDS[~outside], 90.0, **stability, **FORCING)
    np.testing.assert_array_equal(inside.friction_velocity, abl.friction_velocity[~outside])


def test_the_limited_night_is_the_fixed_heat_flux_night_at_the_bound():
    """Beyond the speed that leaves, a limited L = 100 m night is the ABL of a fixed
    sensible_heat_flux at the bound (L ~ u*^3 / H): the same state, independently solved."""
    limited = EkmanABL.from_reference_wind(SPEEDS[-4:], 90.0, outside_domain="limit",
                                           obukhov_length=100.0, **FORCING)
    fixed_flux = EkmanABL.from_reference_wind(SPEEDS[-4:], 90.0,
                                              sensible_heat_flux=LOW * (1 - LIMIT_MARGIN),
                                              **FORCING)
    for name in ("friction_velocity", "boundary_layer_height", "obukhov_length",
                 "cross_isobaric_angle"):
        np.testing.assert_allclose(getattr(limited, name), getattr(fixed_flux, name),
                                   rtol=1e-9, err_msg=name)
    # H = rho c_p Q0 by hand: Q0 = -u*^3 Theta0 / (kappa g L).
    u_star, length = limited.friction_velocity, limited.obukhov_length
    np.testing.assert_allclose(
        -air_heat_capacity(265.0) * u_star**3 * 265.0 / (0.41 * 9.81 * length),
        LOW * (1 - LIMIT_MARGIN), rtol=1e-6)


def test_a_heating_rate_is_limited_to_the_upper_bound():
    """C_r = +2 K/h over a 1500 m mixed layer implies H = rho c_p C_r z_i / (1 + A_e), about
    900 W/m^2, at every speed: every condition is carried at 800 W/m^2 with C_r scaled to it."""
    abl = EkmanABL.from_reference_wind(SPEEDS[::5], 90.0, outside_domain="limit",
                                       cooling_rate=2.0, mixed_layer_height=1500.0, **FORCING)
    assert np.all(abl.domain_limited)
    np.testing.assert_allclose(abl.sensible_heat_flux, HIGH * (1 - LIMIT_MARGIN), rtol=1e-9)
    np.testing.assert_allclose(abl.stability_value, 2.0 * HIGH / (
        air_heat_capacity(265.0) * 2.0 / 3600.0 * 1500.0 / 1.2), rtol=1e-6)


def test_inside_the_domain_nothing_is_limited():
    abl = EkmanABL.from_reference_wind(SPEEDS, 90.0, outside_domain="limit", cooling_rate=-0.25,
                                       **FORCING)
    assert not np.any(abl.domain_limited)
    plain = EkmanABL.from_reference_wind(SPEEDS, 90.0, cooling_rate=-0.25, **FORCING)
    np.testing.assert_array_equal(abl.friction_velocity, plain.friction_velocity)


@pytest.mark.parametrize("bad", ["clip", None, 1])
def test_a_bad_policy_is_refused(bad):
    with pytest.raises(ValueError, match=r"outside_domain must be one of \['refuse', 'limit'\]"):
        EkmanABL.from_reference_wind(10.0, 90.0, outside_domain=bad, obukhov_length=100.0,
                                     **FORCING)
