"""fit_profile with L of either sign (stability="convective" / "either"): the convective layer
of docs/atmosphere.md#convective-boundary-layer recovered from its own profiles, the class chosen
by the misfit, and the refusals (docs/measurements.md)."""

from __future__ import annotations


import numpy as np
import pytest

from floris_ekman_veer import EkmanABL

from benchmarks.fit_stability_classes import confusion  # the repository is on pytest's pythonpath

SITE = dict(coriolis_parameter=1e-4, brunt_vaisala_frequency=6.1e-3,
            reference_potential_temperature=265.0)
Z = np.array([30.0, 50.0, 70.0, 90.0, 110.0, 130.0, 150.0])


def profiles(lengths, speed=8.0):
    true = EkmanABL.from_reference_wind(speed, 90.0, obukhov_length=np.asarray(lengths),
                                        roughness_length=0.1, **SITE)
    return true, true.speed(Z[:, None]).T, 270.0 - true.wind_angle(Z[:, None]).T


def test_noise_free_profiles_of_either_sign_are_recovered_exactly():
    # (L = -35 m at 8 m/s: 595 W/m^2; -20 m, 1,282 W/m^2, lies outside the physical domain)
    lengths = [-1000.0, -300.0, -100.0, -50.0, -35.0, np.inf, 300.0, 100.0]
    true, speeds, directions = profiles(lengths)
    abl = EkmanABL.fit_profile(Z, speeds, directions, roughness_length=0.1, stability="either",
                               **SITE)
    fit = abl.profile_fit
    np.testing.assert_allclose(fit.obukhov_length, lengths, rtol=1e-6)
    np.testing.assert_allclose(fit.friction_velocity, true.friction_velocity, rtol=1e-8)
    np.testing.assert_allclose(abl.boundary_layer_height, true.boundary_layer_height, rtol=1e-8)
    assert list(fit.stability_class) == ["neutral"] + ["convective"] * 4 + ["neutral", "stable",
                                                                              "stable"]
    assert np.all(fit.misfit < 1e-4)


def test_a_convective_profile_beyond_the_heat_flux_bound_is_held_on_it():
    """A Businger-Dyer surface layer (Paulson 1970's psi_m) with u* = 0.7 m/s and L = -20 m
    implies 1,493 W/m^2, beyond the sensible heat flux the atmosphere accepts (800 W/m^2; the
    model's own solve refuses such a state): the fit's states stay inside the physical domain,
    its best one on that bound; with a speed noise that tells the shapes apart the record is
    refused and the bound named."""
    u_star, length, z0 = 0.7, -20.0, 0.1
    x = (1.0 - 16.0 * Z / length) ** 0.25
    psi = 2.0 * np.log((1.0 + x) / 2.0) + np.log((1.0 + x * x) / 2.0) - 2.0 * np.arctan(x) + np.pi / 2
    speeds = u_star / 0.41 * (np.log(Z / z0) - psi)
    assert u_star**3 / (0.41 * 9.81 / 265.0 * -length) * 1321.0 == pytest.approx(1493.0, abs=2.0)
    directions = np.full(Z.size, 270.0)
    fit = EkmanABL.fit_profile(Z, speeds, directions, roughness_length=z0, on_misfit="flag",
                               **SITE).profile_fit
    assert fit.stability_class == "convective"
    assert 0.99 * 800.0 < float(fit.abl.sensible_heat_flux) <= 800.0
    fine = EkmanABL.fit_profile(Z, speeds, directions, roughness_length=z0,
                                speed_noise=0.001, direction_noise=0.5, on_misfit="flag",
                                **SITE).profile_fit
    assert not fine.fits and float(fine.abl.sensible_heat_flux) <= 800.0
    kind, text = fine.reason(0)
    assert kind == "physical bound" and "sensible heat flux 800 W/m^2" in text
    with pytest.raises(ValueError, match=r"record 0 .*on the bound of the sensible heat flux "
                                         r"800 W/m\^2"):
        EkmanABL.fit_profile(Z, speeds, directions, roughness_length=z0, speed_noise=0.001,
                             direction_noise=0.5, stability="convective", **SITE)


def test_the_stable_only_fit_cannot_follow_a_convective_layer():
    """stability="stable" puts a convective profile at the neutral bound, with a worse misfit
    than the convective fit; "convective" recovers it."""
    _, speeds, directions = profiles([-50.0])
    stable = EkmanABL.fit_profile(Z, speeds[0], directions[0], roughness_length=0.1,
                                  on_misfit="flag", stability="stable", **SITE).profile_fit
    convective = EkmanABL.fit_profile(Z, speeds[0], directions[0], roughness_length=0.1,
                                      stability="convective", **SITE).profile_fit
    assert np.isinf(stable.obukhov_length) and stable.misfit > 0.5
    assert convective.obukhov_length == pytest.approx(-50.0, rel=1e-6)
    assert convective.stability_class == "convective"


def test_noisy_records_are_classed_by_the_misfit():
    """30 records per class, 0.1 m/s and 0.5 deg of noise (benchmarks/fit_stability_classes.py,
    which gives the table of 200 per class): every stable and neutral record in its class, at
    least 80 % of the convective ones (heat fluxes 20-700 W/m^2: the rest near-neutral, a weak
    heat flux in a strong wind being |L| > 500 m), none refused, the hub speed within 2 %."""
    table = confusion(30)
    assert table["stable"][0]["stable"] == 30 and table["neutral"][0]["neutral"] == 30
    assert table["convective"][0]["convective"] >= 24 and table["convective"][0]["stable"] == 0
    for counts, refused, error in table.values():
        assert refused == 0 and error <= 0.02


def test_a_convective_fit_gives_back_its_floris_block():
    """The fitted block (obukhov_length of either sign) driven by the fitted speed at 90 m is the
    fitted ABL again (checked by ProfileFit.atmosphere's reference_height)."""
    _, speeds, directions = profiles([-80.0, 200.0])
    fit = EkmanABL.fit_profile(Z, speeds, directions, roughness_length=0.1, stability="either",
                               **SITE).profile_fit
    block = fit.atmosphere("obukhov_length", reference_height=90.0)
    np.testing.assert_allclose(block["obukhov_length"], [-80.0, 200.0], rtol=1e-6)
    heat = fit.atmosphere("surface_heat_flux", reference_height=90.0)["surface_heat_flux"]
    assert heat[0] > 0 > heat[1]


def test_stability_option_and_refusal_messages():
    _, speeds, directions = profiles([-80.0])
    with pytest.raises(ValueError, match=r"fit_profile: stability must be one of \['stable', "
                                         r"'convective', 'either'\]; got 'sideways'"):
        EkmanABL.fit_profile(Z, speeds, directions, roughness_length=0.1, stability="sideways",
                             **SITE)
    with pytest.raises(ValueError, match=r"fit_profile fits the wind and the stability; "
                                         r"\['sensible_heat_flux'\] cannot be fixed inputs"):
        EkmanABL.fit_profile(Z, speeds, directions, roughness_length=0.1, stability="either",
                             sensible_heat_flux=100.0, **SITE)
    # speed falling with height: no atmosphere of either sign
    falling = np.linspace(10.0, 6.0, Z.size)
    with pytest.raises(ValueError, match=r"record 0 fits no atmosphere of the model, stable or "
                                         r"convective: misfit .* stable, .* convective"):
        EkmanABL.fit_profile(Z, falling, roughness_length=0.1, stability="either", **SITE)
