"""The physical domain of a solved atmosphere (docs/atmosphere.md#physical-domain): one set of
bounds on the implied sensible heat flux, geostrophic wind and convective cross-isobaric angle,
checked whichever stability input and driver gave the state, and reported without raising."""

from __future__ import annotations

import numpy as np
import pytest

from floris_ekman_veer import EkmanABL
from floris_ekman_veer.atmosphere.constants import GRAVITY, air_heat_capacity
from floris_ekman_veer.atmosphere.physical_domain import (
    PHYSICAL_DOMAIN,
    physical_domain,
)

SITE = dict(latitude=10.0, roughness_length=0.1)


def test_the_outside_fuzz_reproducers_are_refused_naming_the_implied_quantity():
    """15 m/s at 90 m, latitude 10, z0 = 0.1 m: L = -5 m with z_i = 500 m implies 24.8 kW/m^2
    (and G = 164.5 m/s, a rotor shear of 4.05); L = -1e5 m with z_i = 500 m G = 92.9 m/s
    (28.8 m/s neutral); with z_i = 1500 m the convective layer turns the wind by 46.6 deg."""
    with pytest.raises(ValueError, match=r"the surface sensible heat flux H they imply is "
                       r"2\.477e\+04 W/m\^2, outside -300 to 800 W/m\^2"):
        EkmanABL.from_reference_wind(15, 90, obukhov_length=-5, mixed_layer_height=500, **SITE)
    with pytest.raises(ValueError, match=r"the geostrophic wind G they imply is 92\.92 m/s, "
                       r"outside 0 to 75 m/s"):
        EkmanABL.from_reference_wind(15, 90, obukhov_length=-1e5, mixed_layer_height=500, **SITE)
    with pytest.raises(ValueError, match=r"cross-isobaric angle alpha_0 of the convective layer "
                       r"they imply is -46\.63 deg, outside -45 to 45 deg.*deeper mixed_layer_height"):
        EkmanABL.from_reference_wind(15, 90, obukhov_length=-1e5, mixed_layer_height=1500, **SITE)
    neutral = EkmanABL.from_reference_wind(15, 90, **SITE)
    assert float(neutral.geostrophic_wind) == pytest.approx(28.84, abs=0.01)
    assert bool(neutral.physical_domain().inside)


def test_the_physical_domain_is_one_whichever_stability_input():
    """A state implying H = 1,000 W/m^2 is refused naming H whether it is given by L, mu, the
    kinematic flux Q0 or H itself (the last two by their input range, the same bounds); a state
    at H = 700 W/m^2 is accepted by every input, and gives back the same H."""
    g = 12.0
    inside = EkmanABL(geostrophic_wind=g, sensible_heat_flux=700.0, **SITE)
    mu, length = float(inside.stability_parameter), float(inside.obukhov_length)
    rho_cp = float(air_heat_capacity(265.0))
    for given in (dict(obukhov_length=length), dict(stability_parameter=mu),
                  dict(surface_heat_flux=700.0 / rho_cp)):
        abl = EkmanABL(geostrophic_wind=g, **given, **SITE)
        assert float(abl.sensible_heat_flux) == pytest.approx(700.0, rel=1e-9)
    # 1,000 W/m^2 through each input: the same bound, named as H (or as the input's own range,
    # which quotes the same W/m^2 bounds)
    q0 = 1000.0 / rho_cp
    u_star = float(EkmanABL(geostrophic_wind=g, surface_heat_flux=0.6, **SITE).friction_velocity)
    for given, pattern in [
        (dict(sensible_heat_flux=1000.0), r"sensible_heat_flux must be -300 to 800 W/m\^2"),
        (dict(surface_heat_flux=q0), r"rho c_p Q0 within -300 to 800 W/m\^2"),
        (dict(obukhov_length=-u_star**3 * 265.0 / (0.41 * GRAVITY * q0)),
         r"sensible heat flux H they imply is \S+ W/m\^2, outside -300 to 800"),
        (dict(stability_parameter=mu * 1000.0 / 700.0 * 1.5),
         r"sensible heat flux H they imply is \S+ W/m\^2, outside -300 to 800"),
    ]:
        with pytest.raises(ValueError, match=pattern):
            EkmanABL(geostrophic_wind=g, **given, **SITE)


def test_heating_and_cooling_rates_and_stable_inputs_meet_the_same_bound():
    """The cooling-rate closure (Q0 = C_r h stable, C_r z_i/(1 + A_e) heating) and a fixed stable
    mu are checked on the H they imply: SBL-6's mu = 148.49 implies -331 W/m^2 at 20 m/s at 90 m
    (refused), -145 W/m^2 at 16 m/s (accepted); 10 K/h of heating under a 3 km layer implies
    > 800 W/m^2."""
    sbl6 = dict(coriolis_parameter=1e-4, roughness_length=0.1, stability_parameter=148.49)
    assert float(EkmanABL.from_reference_wind(16.0, 90.0, **sbl6).sensible_heat_flux) == (
        pytest.approx(-145, abs=1))
    with pytest.raises(ValueError, match=r"H they imply is -331\.4 W/m\^2, outside -300 to 800"):
        EkmanABL.from_reference_wind(20.0, 90.0, **sbl6)
    with pytest.raises(ValueError, match=r"H they imply is \S+ W/m\^2, outside -300 to 800"):
        EkmanABL(geostrophic_wind=10.0, cooling_rate=10.0, mixed_layer_height=3000.0,
                 latitude=45.0, roughness_length=0.1)


def test_physical_domain_reports_the_binding_bound_without_raising():
    """physical_domain on arrays of states: the first bound each state leaves ("" inside), a
    margin > 0 exactly inside, the values by name; the angle bound holds only where mu < 0."""
    check = physical_domain(
        sensible_heat_flux=np.array([100.0, -400.0, 900.0, 100.0, 100.0, 100.0, np.nan]),
        geostrophic_wind=np.array([10.0, 10.0, 10.0, 80.0, 10.0, 10.0, 10.0]),
        cross_isobaric_angle=np.array([-20.0, -20.0, -20.0, -20.0, -50.0, -50.0, -20.0]),
        stability_parameter=np.array([-1.0, 1.0, -1.0, 0.0, -1.0, 5.0, -1.0]),
    )
    assert list(check.binding) == ["", "sensible_heat_flux", "sensible_heat_flux",
                                   "geostrophic_wind", "cross_isobaric_angle", "", "sensible_heat_flux"]
    np.testing.assert_array_equal(check.inside, check.binding == "")
    np.testing.assert_array_equal(check.margin > 0, check.inside)
    # the margins by hand: min over bounds of the relative slack
    assert check.margin[0] == pytest.approx(min(400 / 300, 700 / 800, 10 / 75, 65 / 45, 25 / 45))
    assert check.margin[1] == pytest.approx(-100 / 300)
    assert check.margin[3] == pytest.approx(-5 / 75)
    assert check.margin[4] == pytest.approx(-5 / 45)
    assert set(check.values) == set(PHYSICAL_DOMAIN)
    # on a solved atmosphere: per condition, the same numbers as the solved attributes
    abl = EkmanABL.from_reference_wind(np.array([4.0, 8.0, 12.0]), 90.0, latitude=50.0,
                                       roughness_length=0.1, sensible_heat_flux=300.0)
    on_abl = abl.physical_domain()
    assert on_abl.inside.shape == (3,) and np.all(on_abl.inside)
    np.testing.assert_array_equal(on_abl.values["geostrophic_wind"], abl.geostrophic_wind)
    np.testing.assert_allclose(on_abl.values["sensible_heat_flux"], 300.0, rtol=1e-9)


def test_mixed_layer_height_has_an_upper_bound():
    """z_i above 5 km (a depth in feet, say) is refused by its input range."""
    with pytest.raises(ValueError, match=r"mixed_layer_height must be 10 to 5000 m.*got 6000"):
        EkmanABL(geostrophic_wind=10.0, obukhov_length=-100.0, mixed_layer_height=6000.0,
                 latitude=45.0, roughness_length=0.1)
