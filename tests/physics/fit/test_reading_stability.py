"""Reading stability (docs/measurements.md#reading-stability): the sun's bound on an onshore
heat flux, the weak prior on 1/L, a fit on a bound flagged and never kept, "too few data", and a
measured stability (a bulk Richardson number from temperatures, a sonic's L) as a datum."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

from floris_ekman_veer import EkmanABL
from floris_ekman_veer.atmosphere import richardson
from floris_ekman_veer.atmosphere.constants import BUSINGER_DYER_GAMMA
from floris_ekman_veer.atmosphere.fit.stability_data import DEFAULT_STABILITY_PRIOR
from floris_ekman_veer.atmosphere.sunlight import (
    CLEAR_SKY_HEAT_FLUX_FRACTION,
    max_heat_flux,
    utc_times,
)

#: The issue's model record of known truth (7 heights, 0.1 m/s and 0.5 deg of noise): L -88.9
#: m, H 55.6 W/m^2, I_u(90 m) 0.153.
Z7 = np.array([30.0, 50.0, 70.0, 90.0, 110.0, 130.0, 150.0])
S7 = np.array([5.569, 5.747, 5.905, 6.139, 6.389, 6.238, 6.435])
D7 = np.array([259.582, 261.164, 260.838, 260.294, 259.676, 260.028, 258.63])
SITE7 = dict(latitude=52.0, roughness_length=0.05)


def test_the_sun_allows_no_heat_flux_at_night_and_a_share_of_the_clear_sky_by_day():
    """At 53.3 N 1.8 W: midnight 0 W/m^2; a June noon half the Haurwitz (1945) clear-sky
    irradiance, sin(elevation) 0.95 -> 1098 sin(e) exp(-0.057/sin(e)) = 990 W/m^2, so about
    495; a December noon (elevation 13.3 deg) 0.5 x 1098 x 0.23 x exp(-0.248) = 98 W/m^2."""
    times = utc_times(["2025-06-21 00:00", "2025-06-21 12:07", "2025-12-21 12:05"], "UTC")
    cap = max_heat_flux(times, 53.3, -1.8)
    assert cap[0] == 0.0
    for value, elevation in ((cap[1], 60.15), (cap[2], 13.3)):
        sine = np.sin(np.deg2rad(elevation))
        expected = CLEAR_SKY_HEAT_FLUX_FRACTION * 1098.0 * sine * np.exp(-0.057 / sine)
        assert value == pytest.approx(expected, rel=0.02)
    # the stamps' zone is asked for, never guessed; an offset and a zone name agree
    with pytest.raises(ValueError, match="needs the time zone of the records' time stamps"):
        utc_times(["2025-06-21 12:00"], None)
    np.testing.assert_array_equal(utc_times(["2025-06-21 13:00"], "+01:00"),
                                  utc_times(["2025-06-21 12:00"], "UTC"))
    np.testing.assert_array_equal(utc_times(["2025-06-21 13:00"], "Europe/London"),
                                  utc_times(["2025-06-21T13:00+01:00"], None))
    with pytest.raises(ValueError, match="time_zone 'Mars/Olympus' is no time zone"):
        utc_times(["2025-06-21 12:00"], "Mars/Olympus")


def test_the_bulk_richardson_number_is_that_of_independent_businger_dyer_profiles():
    """Ri_b of :func:`model_richardson_number` equals (g/theta) Delta theta Delta z / Delta U^2
    of Businger-Dyer profiles written out here (u* = 0.4 m/s, theta 288 K), u* cancelling; its
    inverse gives 1/L back; neutral: 0."""
    u_star, theta, kappa, g = 0.4, 288.0, 0.41, 9.81
    t_heights, u_heights = (10.0, 78.0), (40.0, 80.0)
    gamma = BUSINGER_DYER_GAMMA

    def psi(zeta, heat):
        if zeta >= 0:
            return -5.0 * zeta
        x = (1.0 - gamma * zeta) ** 0.25
        if heat:
            return 2.0 * np.log((1.0 + x * x) / 2.0)
        return 2 * np.log((1 + x) / 2) + np.log((1 + x * x) / 2) - 2 * np.arctan(x) + np.pi / 2

    for length in (-15.0, -80.0, -600.0, 900.0, 150.0, 40.0):
        theta_star = u_star**2 * theta / (kappa * g * length)
        rise = theta_star / kappa * (np.log(t_heights[1] / t_heights[0])
                                     - psi(t_heights[1] / length, True)
                                     + psi(t_heights[0] / length, True))
        shear = u_star / kappa * (np.log(u_heights[1] / u_heights[0])
                                  - psi(u_heights[1] / length, False)
                                  + psi(u_heights[0] / length, False))
        ri = g / theta * rise * (t_heights[1] - t_heights[0]) / shear**2
        model = richardson.model_richardson_number(1.0 / length, t_heights, u_heights)
        assert model == pytest.approx(ri, rel=1e-10)
        assert richardson.potential_temperature_difference(
            *t_heights, u_star, length, theta) == pytest.approx(rise, rel=1e-10)
        assert richardson.inverse_obukhov_length(ri, t_heights, u_heights) == pytest.approx(
            1.0 / length, rel=1e-8)
    assert richardson.model_richardson_number(0.0, t_heights, u_heights) == 0.0


def test_a_flat_record_is_fitted_under_the_prior_not_on_the_bound():
    """The issue's 7-height record (truth L -88.9 m, 55.6 W/m^2): from the data alone its
    convective fit runs to the 800 W/m^2 bound, which is flagged and not kept; under the weak
    prior on 1/L it is fitted inside the domain, near the truth (L -47 m, within its
    uncertainty), the heat flux and I_u near the truth's."""
    alone = EkmanABL.fit_profile(Z7, S7, D7, stability="convective", on_misfit="flag",
                                 **SITE7).profile_fit
    assert alone.bound == "sensible heat flux 800 W/m^2" and not alone.fits
    assert alone.reason(0)[0] == "physical bound"
    prior = EkmanABL.fit_profile(Z7, S7, D7, stability_prior=DEFAULT_STABILITY_PRIOR,
                                 on_misfit="flag", **SITE7)
    fit = prior.profile_fit
    assert fit.fits and fit.bound == "" and fit.stability_class == "convective"
    assert fit.obukhov_length == pytest.approx(-47.0, rel=0.05)
    sigma = np.sqrt(fit.covariance[1, 1]) / 100.0  # of 1/L [1/m]
    assert abs(1.0 / fit.obukhov_length - 1.0 / -88.9) < 1.5 * sigma
    assert sigma < DEFAULT_STABILITY_PRIOR  # the data tell more than the prior
    assert float(prior.sensible_heat_flux) < 150.0
    assert float(prior.turbulence_intensity(90.0)) == pytest.approx(0.153, abs=0.01)


def test_no_convective_state_where_the_sun_allows_no_heat_flux():
    """The same record at night (max_heat_flux 0): the fit takes no convective state."""
    fit = EkmanABL.fit_profile(Z7, S7, D7, stability_prior=DEFAULT_STABILITY_PRIOR,
                               max_heat_flux=0.0, on_misfit="flag", **SITE7).profile_fit
    assert fit.stability_class != "convective" and fit.obukhov_length > 0
    day = EkmanABL.fit_profile(Z7, S7, D7, stability_prior=DEFAULT_STABILITY_PRIOR,
                               max_heat_flux=20.0, stability="convective", on_misfit="flag",
                               **SITE7)
    assert float(day.sensible_heat_flux) <= 20.0
    assert "the sun allows, 20 W/m^2" in day.profile_fit.bound and not day.profile_fit.fits


def test_a_measured_stability_is_a_datum():
    """Two speeds (two data, two unknowns: "too few data" alone) with a sonic's 1/L, or with
    the Businger-Dyer bulk Richardson number of the true L, give one degree of freedom and the
    true L of either sign back (to the datum's noise: 2 %)."""
    heights = np.array([40.0, 100.0])
    lengths = np.array([-60.0, -200.0, 200.0, 80.0])
    true = EkmanABL.from_reference_wind(8.0, 90.0, obukhov_length=lengths, latitude=52.0,
                                        roughness_length=0.05)
    speeds = true.speed(heights[:, None]).T
    site = dict(latitude=52.0, roughness_length=0.05, speed_noise=0.1)
    sonic = EkmanABL.fit_profile(heights, speeds, inverse_obukhov_length=(1.0 / lengths, 1e-5),
                                 **site).profile_fit
    np.testing.assert_allclose(sonic.obukhov_length, lengths, rtol=0.02)
    np.testing.assert_array_equal(sonic.degrees_of_freedom, 1)
    ri = richardson.model_richardson_number(1.0 / lengths, (10.0, 78.0), (40.0, 80.0))
    temperatures = EkmanABL.fit_profile(
        heights, speeds, bulk_richardson=(ri, 1e-3 + 0.001 * np.abs(ri), (10.0, 78.0),
                                          (40.0, 80.0)), **site).profile_fit
    np.testing.assert_allclose(temperatures.obukhov_length, lengths, rtol=0.02)
    with pytest.raises(ValueError, match=r"bulk_richardson must be \(value, noise"):
        EkmanABL.fit_profile(heights, speeds, bulk_richardson=(ri, 0.1), **site)
    with pytest.raises(ValueError, match="stability_prior must be a number > 0"):
        EkmanABL.fit_profile(heights, speeds, stability_prior=-1.0, **site)
    with pytest.raises(ValueError, match="max_heat_flux"):
        EkmanABL.fit_profile(heights, speeds, max_heat_flux=-5.0, **site)


@given(speed=st.floats(3.0, 14.0), inverse_length=st.floats(-0.1, 0.05),
       heights=st.lists(st.sampled_from([30.0, 50.0, 70.0, 90.0, 110.0, 130.0, 150.0]),
                        min_size=2, max_size=7, unique=True),
       vanes=st.integers(0, 7), seed=st.integers(0, 2**16), cap=st.sampled_from([0.0, 60.0,
                                                                                 np.inf]))
def test_no_kept_fit_lies_on_a_bound_or_has_no_degree_of_freedom(speed, inverse_length, heights,
                                                                 vanes, seed, cap):
    """Model records of any stability (L from -10 m), any subset of the heights and of the
    vanes, 0.1 m/s and 0.5 deg of noise, a heat-flux bound of 0 (night), 60 W/m^2 or none:
    fitted as fit_site fits them (the weak prior), no kept record lies on a bound or has no
    degree of freedom, and none is convective where the sun allows no heat flux."""
    rng = np.random.default_rng(seed)
    z = np.sort(np.asarray(heights))
    length = np.inf if inverse_length == 0 else 1.0 / inverse_length
    try:
        true = EkmanABL.from_reference_wind(speed, 90.0, obukhov_length=length, **SITE7)
    except ValueError:
        return  # (a state outside the physical domain: no record of the model)
    s = np.asarray(true.speed(z), float) + rng.normal(0.0, 0.1, z.size)
    d = 260.0 - np.asarray(true.wind_angle(z), float) + rng.normal(0.0, 0.5, z.size)
    d[min(vanes, z.size):] = np.nan
    if np.any(s <= 0):
        return
    fit = EkmanABL.fit_profile(z, s, d, stability_prior=DEFAULT_STABILITY_PRIOR,
                               max_heat_flux=cap, on_misfit="flag", **SITE7).profile_fit
    if fit.fits:
        assert fit.bound == "" and fit.degrees_of_freedom >= 1
        if cap == 0.0:
            assert fit.obukhov_length > 0
    else:
        kind = fit.reason(0)[0]
        assert kind != "misfit" or fit.refusal_misfit > fit.misfit_tolerance or fit.bound


def test_fit_site_asks_for_what_the_sun_needs():
    """site_type='onshore' needs the longitude and the time zone of naive stamps: ValueError
    naming them; a bad site type is named."""
    from floris_ekman_veer import fit_site

    records = pd.DataFrame({"time": ["2025-06-21 12:00"], "speed_30m": [5.5], "speed_90m": [6.1],
                            "speed_150m": [6.4]})
    with pytest.raises(ValueError, match="needs the site's longitude"):
        fit_site(records, 90.0, site_type="onshore", **SITE7)
    with pytest.raises(ValueError, match="needs the time zone"):
        fit_site(records, 90.0, site_type="onshore", longitude=-1.8, **SITE7)
    with pytest.raises(ValueError, match="site_type must be one of"):
        fit_site(records, 90.0, site_type="inland", **SITE7)
