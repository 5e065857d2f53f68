"""fit_profile fits the convective mixed-layer depth z_i where the data reach it, and keeps its
default elsewhere (docs/measurements.md#mixed-layer-depth)."""

from __future__ import annotations

import numpy as np
import pytest

from floris_ekman_veer import EkmanABL

# A mixed layer shallow enough for a 150 m mast to reach lies inside the physical domain (a
# convective cross-isobaric angle within 45 deg, docs/atmosphere.md#physical-domain) only at
# light winds and high latitudes: f_c = 1.4e-4 1/s (74 deg), 3-5 m/s at 90 m.
SITE = dict(coriolis_parameter=1.4e-4, brunt_vaisala_frequency=6.1e-3,
            reference_potential_temperature=265.0, roughness_length=0.1)
Z = np.arange(30.0, 151.0, 20.0)


def model_records(lengths, depths, hub=4.0):
    true = EkmanABL.from_reference_wind(hub, 90.0, obukhov_length=np.asarray(lengths),
                                        mixed_layer_height=np.asarray(depths), **SITE)
    return true, true.speed(Z[:, None]).T, 270.0 - true.wind_angle(Z[:, None]).T


def test_a_mixed_layer_top_the_data_reach_is_recovered_exactly():
    """The model's own convective profiles, z_i = 100-150 m at or below the highest measurement
    (150 m), noise-free: L, u* and z_i come back to the solver's tolerance, z_i marked fitted;
    the block of the fit gives back the fitted ABL in FLORIS."""
    lengths, depths = [-50.0, -100.0, -60.0, -30.0, -80.0], [100.0, 120.0, 140.0, 150.0, 130.0]
    true, speeds, directions = model_records(lengths, depths)
    abl = EkmanABL.fit_profile(Z, speeds, directions, stability="either", **SITE)
    fit = abl.profile_fit
    assert list(fit.mixed_layer_height_fitted) == [True] * 5
    assert list(fit.stability_class) == ["convective"] * 5
    np.testing.assert_allclose(fit.mixed_layer_height, depths, rtol=1e-6)
    np.testing.assert_allclose(abl.boundary_layer_height, depths, rtol=1e-6)
    np.testing.assert_allclose(fit.obukhov_length, lengths, rtol=1e-6)
    np.testing.assert_allclose(fit.friction_velocity, true.friction_velocity, rtol=1e-6)
    assert np.all(fit.misfit < 1e-6)
    block = fit.atmosphere("obukhov_length", reference_height=90.0)
    np.testing.assert_allclose(block["mixed_layer_height"], depths, rtol=1e-6)


def test_a_noisy_mixed_layer_top_is_recovered_within_four_percent():
    """40 such records (z_i 100-150 m, L -300..-30 m, 3-5 m/s at 90 m) with 0.1 m/s and 0.5 deg
    of noise: at least 32 have z_i fitted (0.1 m/s is 2-3 % of these light winds), each within
    4 % of the true z_i, the hub speed
    within 4 %."""
    rng = np.random.default_rng(7)
    n = 40
    depths = rng.uniform(100.0, 150.0, n)
    lengths = -np.exp(rng.uniform(np.log(30.0), np.log(300.0), n))
    hub = rng.uniform(3.0, 5.0, n)
    true = EkmanABL.from_reference_wind(hub, 90.0, obukhov_length=lengths,
                                        mixed_layer_height=depths, **SITE)
    speeds = true.speed(Z[:, None]).T + rng.normal(0.0, 0.1, (n, Z.size))
    directions = 270.0 - true.wind_angle(Z[:, None]).T + rng.normal(0.0, 0.5, (n, Z.size))
    fit = EkmanABL.fit_profile(Z, speeds, directions, stability="either", on_misfit="flag",
                               speed_noise=0.1, direction_noise=0.5, **SITE).profile_fit
    fitted = np.asarray(fit.mixed_layer_height_fitted)
    assert fitted.sum() >= 32
    np.testing.assert_array_less(np.abs(fit.mixed_layer_height[fitted] / depths[fitted] - 1.0),
                                 0.04)
    np.testing.assert_array_less(np.abs(fit.speed([90.0])[:, 0] / hub - 1.0), 0.04)


def test_without_reach_the_default_mixed_layer_is_kept():
    """z_i = 1500 m above a 150 m mast is not fitted; nor is z_i where the data reach it but
    ``mixed_layer_height`` is given or ``fit_mixed_layer_height=False``. A convective fit that
    keeps the default has the neutral height of Eq. (h_hat_model) at its u* as z_i."""
    _, speeds, directions = model_records([-100.0, -60.0], [1500.0, 100.0])
    fit = EkmanABL.fit_profile(Z, speeds, directions, stability="convective", on_misfit="flag",
                               **SITE).profile_fit
    assert list(fit.mixed_layer_height_fitted) == [False, True]
    default = EkmanABL.from_reference_wind(fit.speed([90.0])[0, 0], 90.0,
                                           obukhov_length=fit.obukhov_length[0], **SITE)
    assert fit.mixed_layer_height[0] == pytest.approx(float(default.boundary_layer_height),
                                                      rel=1e-6)
    given = EkmanABL.fit_profile(Z, speeds, directions, stability="convective",
                                 on_misfit="flag", mixed_layer_height=500.0, **SITE).profile_fit
    assert not np.any(given.mixed_layer_height_fitted)
    convective = given.obukhov_length < 0
    assert np.any(convective)
    np.testing.assert_allclose(given.mixed_layer_height[convective], 500.0)
    assert np.all(np.isnan(given.mixed_layer_height[~convective]))
    off = EkmanABL.fit_profile(Z, speeds, directions, stability="convective", on_misfit="flag",
                               fit_mixed_layer_height=False, **SITE).profile_fit
    assert not np.any(off.mixed_layer_height_fitted)
    assert off.misfit[1] > 100 * fit.misfit[1]
    stable = EkmanABL.fit_profile(Z, speeds, directions, on_misfit="flag", stability="stable",
                                  **SITE).profile_fit
    assert np.all(np.isnan(stable.mixed_layer_height)) and not np.any(
        stable.mixed_layer_height_fitted)
    with pytest.raises(ValueError, match=r"fit_profile: fit_mixed_layer_height must be True or "
                                         r"False; got 'yes'"):
        EkmanABL.fit_profile(Z, speeds, directions, fit_mixed_layer_height="yes", **SITE)
