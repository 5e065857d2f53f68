"""EkmanABL.fit_profile (docs/measurements.md): profiles the model itself generates are recovered,
noise-free and with measurement noise, neutral and stable, in both hemispheres; records are
fitted independently of each other in one vectorised call; data no atmosphere of the model fits
are refused with the record named."""

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from floris_ekman_veer import EkmanABL

MAST = np.arange(30.0, 151.0, 20.0)  # 30, 50, ..., 150 m
FINE = np.linspace(30.0, 150.0, 61)
SITE = dict(latitude=52.0, roughness_length=0.05)
#: (hub speed at 90 m [m/s], Obukhov length [m]): neutral, weakly and moderately stable.
CASES = [(8.0, np.inf), (12.0, np.inf), (8.0, 300.0), (10.0, 100.0), (6.0, 150.0)]
OFFSET = 250.0  # the true direction rotation [deg]


def truth(speed, obukhov_length, **site):
    return EkmanABL.from_reference_wind(speed, 90.0, obukhov_length=obukhov_length,
                                        **(site or SITE))


def measured(abl, heights=MAST):
    return abl.speed(heights), np.mod(OFFSET - abl.wind_angle(heights), 360.0)


def profile_errors(fit, abl):
    """Max relative speed error and max direction-change error [deg] over 30-150 m, per record."""
    speed_error = np.max(np.abs(fit.speed(FINE) / abl.speed(FINE) - 1.0), axis=-1)
    change = fit.direction(FINE) - fit.direction(FINE[:1])
    direction_error = np.max(np.abs(
        (change - abl.wind_direction_change(FINE[0], FINE) + 180.0) % 360.0 - 180.0), axis=-1)
    return speed_error, direction_error


@pytest.mark.parametrize("speed, obukhov_length", CASES)
def test_noise_free_profiles_are_recovered(speed, obukhov_length):
    abl = truth(speed, obukhov_length)
    s, d = measured(abl)
    fitted = EkmanABL.fit_profile(MAST, s, d, **SITE)
    fit = fitted.profile_fit
    speed_error, direction_error = profile_errors(fit, abl)
    assert speed_error < 0.005 and direction_error < 0.3
    # The unknowns themselves: the data determine them (to the solver's precision).
    assert fit.geostrophic_wind == pytest.approx(float(abl.geostrophic_wind), rel=1e-6)
    assert fit.friction_velocity == pytest.approx(float(abl.friction_velocity), rel=1e-6)
    assert fit.stability_parameter == pytest.approx(float(abl.stability_parameter), rel=1e-5,
                                                    abs=1e-6)
    assert fit.direction_offset == pytest.approx(
        np.mod(OFFSET + float(abl.wind_angle(90.0)) - float(abl.wind_angle(90.0)), 360.0))
    assert fit.misfit < 1e-6 and fit.fits and fit.converged
    assert fit.speed_residual < 1e-7 and fit.direction_residual < 1e-6
    # The returned EkmanABL is that atmosphere, solved from G as any other.
    assert float(fitted.boundary_layer_height) == pytest.approx(
        float(abl.boundary_layer_height), rel=1e-5)


@pytest.mark.parametrize("speed, obukhov_length", CASES)
def test_noisy_profiles_are_recovered(speed, obukhov_length):
    """0.1 m/s and 0.5 deg of Gaussian noise (seeded), 20 records of one atmosphere: 19 of 20
    within 2 % and 1.5 deg everywhere in 30-150 m (the noise at 7 heights leaves 1-in-20 outliers
    of a few tenths beyond, docs/measurements.md#recovery), the typical record well inside."""
    abl = truth(speed, obukhov_length)
    s, d = measured(abl)
    rng = np.random.default_rng(20261202)
    noisy_s = s + rng.normal(0.0, 0.1, (20, s.size))
    noisy_d = d + rng.normal(0.0, 0.5, (20, d.size))
    fit = EkmanABL.fit_profile(MAST, noisy_s, noisy_d, speed_noise=0.1, direction_noise=0.5,
                               **SITE).profile_fit
    speed_error, direction_error = profile_errors(fit, abl)
    assert np.sum(speed_error < 0.02) >= 19 and np.sum(direction_error < 1.5) >= 19
    assert np.max(speed_error) < 0.03 and np.max(direction_error) < 2.0
    assert np.median(speed_error) < 0.01 and np.median(direction_error) < 0.6
    # The residual reported is that of the noise: misfit ~ 1, rms ~ the stated noise.
    assert 0.7 < np.mean(fit.misfit) < 1.3
    assert 0.06 < np.mean(fit.speed_residual) < 0.11
    assert 0.3 < np.mean(fit.direction_residual) < 0.55
    assert np.all(fit.fits)


def test_records_are_fitted_independently_in_one_call():
    """A batch of different atmospheres gives each record the fit it gets alone."""
    abls = [truth(u, L) for u, L in CASES]
    data = [measured(a) for a in abls]
    rng = np.random.default_rng(3)
    s = np.array([x for x, _ in data]) + rng.normal(0, 0.1, (len(CASES), MAST.size))
    d = np.array([y for _, y in data]) + rng.normal(0, 0.5, (len(CASES), MAST.size))
    batch = EkmanABL.fit_profile(MAST, s, d, **SITE).profile_fit
    for i in range(len(CASES)):
        alone = EkmanABL.fit_profile(MAST, s[i], d[i], **SITE).profile_fit
        assert batch.obukhov_length[i] == pytest.approx(alone.obukhov_length, rel=1e-8)
        assert batch.geostrophic_wind[i] == pytest.approx(alone.geostrophic_wind, rel=1e-10)
        assert batch.misfit[i] == pytest.approx(alone.misfit, rel=1e-6)


def test_southern_hemisphere_mirrors_the_northern():
    north, south = truth(8.0, 100.0), truth(8.0, 100.0, latitude=-52.0, roughness_length=0.05)
    s, d = measured(north)
    mirrored = np.mod(-d, 360.0)  # backing with height in the south
    fit_n = EkmanABL.fit_profile(MAST, s, d, **SITE).profile_fit
    fit_s = EkmanABL.fit_profile(MAST, s, mirrored, latitude=-52.0,
                                 roughness_length=0.05).profile_fit
    assert fit_s.obukhov_length == pytest.approx(fit_n.obukhov_length, rel=1e-6)
    assert fit_s.geostrophic_wind == pytest.approx(float(south.geostrophic_wind), rel=1e-6)
    # The northern data in the south (veering) are refused.
    with pytest.raises(ValueError, match=r"record 0 .*veers with height.*southern hemisphere"):
        EkmanABL.fit_profile(MAST, s, d, latitude=-52.0, roughness_length=0.05)


def test_roughness_length_can_be_fitted():
    abl = truth(9.0, 200.0, latitude=52.0, roughness_length=0.2)
    s, d = measured(abl)
    fit = EkmanABL.fit_profile(MAST, s, d, latitude=52.0, fit_roughness=True).profile_fit
    assert fit.fitted == ("friction_velocity", "obukhov_length", "roughness_length")
    assert fit.roughness_length == pytest.approx(0.2, rel=1e-5)
    assert fit.obukhov_length == pytest.approx(200.0, rel=1e-4)


def test_speeds_only_and_missing_values():
    abl = truth(10.0, 150.0)
    s, d = measured(abl)
    speeds_only = EkmanABL.fit_profile(MAST, s, **SITE).profile_fit
    assert speeds_only.obukhov_length == pytest.approx(150.0, rel=1e-4)
    assert np.isnan(speeds_only.direction_residual)
    gappy_s, gappy_d = s.copy(), d.copy()
    gappy_s[2], gappy_d[4] = np.nan, np.nan
    gappy = EkmanABL.fit_profile(MAST, gappy_s, gappy_d, **SITE).profile_fit
    assert gappy.obukhov_length == pytest.approx(150.0, rel=1e-4)


def test_atmosphere_block_gives_back_the_fit():
    """Every stability input of the block, driven by the fitted speed at 90 m, is the fitted
    state (docs/measurements.md#from-the-fit-to-floris)."""
    abls = [truth(u, L) for u, L in CASES]
    s = np.array([measured(a)[0] for a in abls])
    d = np.array([measured(a)[1] for a in abls])
    fit = EkmanABL.fit_profile(MAST, s, d, **SITE).profile_fit
    hub = fit.speed([90.0])[:, 0]
    for name in ("stability_parameter", "obukhov_length", "cooling_rate"):
        block = fit.atmosphere(name, reference_height=90.0)
        assert isinstance(block[name], list) and len(block[name]) == len(CASES)
        again = EkmanABL.from_reference_wind(hub, 90.0, **block)
        np.testing.assert_allclose(again.geostrophic_wind, fit.geostrophic_wind, rtol=1e-7)
        np.testing.assert_allclose(again.friction_velocity, fit.friction_velocity, rtol=1e-7)
    # The heat-flux closure has a second, deeper state with 10 m/s at 90 m for L = 100 m (G
    # 12.04 instead of 11.36 m/s): the reference-wind solve would take it, and the block says so.
    flux = fit.atmosphere("surface_heat_flux")
    again = EkmanABL.from_reference_wind(hub, 90.0, **flux)
    assert again.geostrophic_wind[3] == pytest.approx(12.036, abs=1e-3)
    np.testing.assert_allclose(np.delete(again.geostrophic_wind, 3),
                               np.delete(fit.geostrophic_wind, 3), rtol=1e-7)
    with pytest.raises(ValueError, match=r"surface_heat_flux.*record 3 .*12.04 instead of 11.36"):
        fit.atmosphere("surface_heat_flux", reference_height=90.0)
    one = EkmanABL.fit_profile(MAST, s[2], d[2], **SITE).profile_fit.atmosphere("obukhov_length")
    assert one == {"latitude": 52.0, "roughness_length": 0.05,
                   "obukhov_length": pytest.approx(300.0, rel=1e-5)}


def test_backing_in_the_north_is_refused_with_the_record_named():
    abl = truth(8.0, 300.0)
    s, d = measured(abl)
    backing = np.mod(d[0] - 0.1 * (MAST - MAST[0]), 360.0)  # 12 deg of backing over 120 m
    with pytest.raises(ValueError, match=r"record 2026-01-01 00:10 fits no atmosphere.*backs "
                                         r"with height by 12 deg.*northern hemisphere veers"):
        EkmanABL.fit_profile(MAST, [s, s], [d, backing], labels=["2026-01-01 00:00",
                                                                  "2026-01-01 00:10"], **SITE)
    # Within the noise it is accepted: a neutral model layer backs slightly near the ground.
    slight = np.mod(d[0] - 0.01 * (MAST - MAST[0]), 360.0)
    flagged = EkmanABL.fit_profile(MAST, [s, s], [d, slight], **SITE).profile_fit
    assert np.all(flagged.fits)


def test_speeds_falling_with_height_are_refused():
    abl = truth(8.0, np.inf)
    s, d = measured(abl)
    with pytest.raises(ValueError, match=r"record 0 .*speed falls from .* at 30 m to .* at 150 m"):
        EkmanABL.fit_profile(MAST, s[::-1], d, **SITE)


def test_flag_keeps_the_fits_and_marks_the_misfits():
    abl = truth(8.0, 300.0)
    s, d = measured(abl)
    fit = EkmanABL.fit_profile(MAST, [s, s[::-1]], [d, d], on_misfit="flag", **SITE).profile_fit
    assert fit.fits.tolist() == [True, False]
    assert fit.misfit[1] > 5.0 and fit.misfit[0] < 1e-6


@pytest.mark.parametrize("kwargs, message", [
    (dict(obukhov_length=100.0), r"\['obukhov_length'\] cannot be fixed inputs"),
    (dict(cooling_rate=-1.0), r"\['cooling_rate'\] cannot be fixed inputs"),
    (dict(geostrophic_wind=10.0), r"\['geostrophic_wind'\] cannot be fixed"),
    (dict(latitude=None), r"latitude \[deg\] or coriolis_parameter"),
    (dict(roughness_length=None), r"needs roughness_length"),
    (dict(roughness_length=-0.1), r"roughness_length must be > 0 m"),
    (dict(latitude=0.0), r"latitude must be 1 <= \|latitude\|"),
    (dict(speed_noise=0.0), r"speed_noise must be a number > 0"),
    (dict(refusal_probability=1.0), r"refusal_probability must be a number in \(0, 1\)"),
    (dict(on_misfit="ignore"), r"on_misfit must be 'raise' or 'flag'"),
])
def test_bad_options_are_refused(kwargs, message):
    s, d = measured(truth(8.0, 300.0))
    inputs = {**SITE, **kwargs}
    inputs = {k: v for k, v in inputs.items() if v is not None}
    with pytest.raises(ValueError, match=message):
        EkmanABL.fit_profile(MAST, s, d, **inputs)


def test_bad_data_are_refused():
    s, d = measured(truth(8.0, 300.0))
    with pytest.raises(ValueError, match=r"speeds must be > 0 m/s"):
        EkmanABL.fit_profile(MAST, -s, d, **SITE)
    with pytest.raises(ValueError, match=r"speeds must be finite"):
        EkmanABL.fit_profile(MAST, np.where(MAST > 100, np.inf, s), d, **SITE)
    with pytest.raises(ValueError, match=r"heights must be > roughness_length"):
        EkmanABL.fit_profile(np.where(MAST > 100, MAST * 1e-4, MAST), s, d, **SITE)
    with pytest.raises(ValueError, match=r"heights must be \(n_heights,\)"):
        EkmanABL.fit_profile(MAST[:3], s, d, **SITE)
    with pytest.raises(ValueError, match=r"directions must have the shape of speeds"):
        EkmanABL.fit_profile(MAST, s, d[:3], **SITE)
    with pytest.raises(ValueError, match=r"speeds must be a real number"):
        EkmanABL.fit_profile(MAST, ["8"] * MAST.size, d, **SITE)
    with pytest.raises(ValueError, match=r"record 0 has 1 speeds and 0 direction changes"):
        EkmanABL.fit_profile(MAST, np.where(MAST > 30, np.nan, s), np.where(MAST > 30, np.nan, d),
                             **SITE)



# A drawn near-northerly profile with little veer has every direction within 0 to 2 pi, as
# radians would: the DirectionUnitsWarning it gets is tested in tests/studies/site/test_fit_robustness.py.
@pytest.mark.filterwarnings("ignore::floris_ekman_veer.DirectionUnitsWarning")
@given(
    speed=st.floats(4.0, 16.0),
    inverse_length=st.one_of(st.just(0.0), st.floats(1.0 / 3000.0, 1.0 / 40.0)),
    latitude=st.one_of(st.floats(-70.0, -25.0), st.floats(25.0, 70.0)),
    log_z0=st.floats(np.log(1e-3), np.log(0.5)),
    offset=st.floats(0.0, 360.0),
)
def test_any_model_profile_is_recovered(speed, inverse_length, latitude, log_z0, offset):
    """Noise-free profiles of any atmosphere in wide ranges (hub wind 4-16 m/s, L from 40 m to
    neutral, either hemisphere, z0 1 mm to 0.5 m, any direction) are recovered to 0.5 % and
    0.3 deg over 30-150 m, also where h lies inside the mast."""
    site = dict(latitude=latitude, roughness_length=float(np.exp(log_z0)))
    length = np.inf if inverse_length == 0.0 else 1.0 / inverse_length
    abl = EkmanABL.from_reference_wind(speed, 90.0, obukhov_length=length, **site)
    # Not a boundary-layer top within 0.5 % of a measurement height: there the profile's step
    # near h can hold the fit a fraction of a metre off (docs/measurements.md#recovery).
    assume(np.min(np.abs(float(abl.boundary_layer_height) / MAST - 1.0)) > 0.005)
    s = abl.speed(MAST)
    d = np.mod(offset - abl.wind_angle(MAST), 360.0)
    fit = EkmanABL.fit_profile(MAST, s, d, **site).profile_fit
    speed_error, direction_error = profile_errors(fit, abl)
    assert speed_error < 0.005 and direction_error < 0.3
    assert fit.misfit < 1e-4


def test_states_set_at_their_known_friction_velocity_are_the_solved_ones():
    """The fit's trial states are set at their u* (EkmanABL.solved_at, no re-solve,
    docs/measurements.md#fit-time): the same ABL as the solve from their G, stable, neutral and
    convective, both hemispheres, to the solver's tolerance."""
    lengths = np.array([-40.0, -300.0, np.inf, 400.0, 120.0, 60.0])
    f = np.array([1e-4, -1e-4, 1.2e-4, -0.8e-4, 1e-4, 1.1e-4])
    solved = EkmanABL.from_reference_wind(np.linspace(5.0, 12.0, 6), 90.0, obukhov_length=lengths,
                                          coriolis_parameter=f, roughness_length=0.1,
                                          mixed_layer_height=900.0)
    mu = np.asarray(solved.stability_parameter)
    at = EkmanABL.solved_at(np.log(solved.friction_velocity), solved.geostrophic_wind,
                             stability_parameter=mu, coriolis_parameter=f, roughness_length=0.1,
                             mixed_layer_height=900.0)
    again = EkmanABL(geostrophic_wind=solved.geostrophic_wind, stability_parameter=mu,
                     coriolis_parameter=f, roughness_length=0.1, mixed_layer_height=900.0)
    z = MAST[:, None]
    for name in ("friction_velocity", "boundary_layer_height", "cross_isobaric_angle"):
        np.testing.assert_allclose(getattr(at, name), getattr(again, name), rtol=1e-10)
    np.testing.assert_allclose(at.speed(z), again.speed(z), rtol=1e-10)
    np.testing.assert_allclose(at.wind_angle(z), again.wind_angle(z), atol=1e-8)
    np.testing.assert_allclose(at.turbulence_intensity(z), again.turbulence_intensity(z),
                               rtol=1e-10)


def test_directions_at_their_own_heights_are_fitted_there():
    """Vanes 2 m below the cups (the usual mast): each direction is the model's at its own
    height, so the model's own profile is recovered to the solver's precision, of either sign;
    the same directions given at the cups' heights (the 2 m ignored) are a different record."""
    vanes = MAST - 2.0
    for speed, length in ((8.0, 150.0), (8.0, -100.0)):
        abl = truth(speed, length)
        s = abl.speed(MAST)
        d = np.mod(OFFSET - abl.wind_angle(vanes), 360.0)
        fit = EkmanABL.fit_profile(MAST, s, d, direction_heights=vanes, **SITE).profile_fit
        assert fit.obukhov_length == pytest.approx(length, rel=1e-5)
        assert fit.friction_velocity == pytest.approx(float(abl.friction_velocity), rel=1e-7)
        assert fit.misfit < 1e-5 and fit.fits
        # the heights of both, the speeds missing at the vanes' and the directions at the cups'
        np.testing.assert_array_equal(fit.heights[0], np.sort(np.concatenate([vanes, MAST])))
        assert np.sum(np.isfinite(fit.speeds)) == MAST.size
        assert np.sum(np.isfinite(fit.directions)) == vanes.size
        np.testing.assert_allclose(fit.direction(vanes)[0], d, atol=1e-6)
    # per-record vane heights, and one vane fewer than cups
    abl = truth(8.0, 150.0)
    per_record = np.vstack([vanes[1:], vanes[1:] + 1.0])
    d = np.mod(OFFSET - abl.wind_angle(per_record), 360.0)
    fit = EkmanABL.fit_profile(MAST, np.vstack([abl.speed(MAST)] * 2), d,
                               direction_heights=per_record, **SITE).profile_fit
    np.testing.assert_allclose(fit.obukhov_length, 150.0, rtol=1e-5)
    with pytest.raises(ValueError, match=r"direction_heights must be \(n_direction_heights,\)"):
        EkmanABL.fit_profile(MAST, abl.speed(MAST), d[0], direction_heights=vanes, **SITE)
    with pytest.raises(ValueError, match="direction_heights is given but directions is None"):
        EkmanABL.fit_profile(MAST, abl.speed(MAST), direction_heights=vanes, **SITE)
