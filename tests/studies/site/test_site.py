"""floris_ekman_veer.fit_site (docs/measurements.md#from-the-fit-to-floris): mast records in a
DataFrame become per-record atmospheres of a FLORIS run that gives back the fitted profiles;
annual energy and optimize_yaw run on it; the shipped synthetic mast is what its script makes."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from floris import FlorisModel
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

import floris_ekman_veer
from floris_ekman_veer import EkmanABL, fit_site, optimize_yaw
from floris_ekman_veer.plugin.inflow.inflow import solved_atmosphere
from tests.conftest import make_config

REPO = Path(__file__).resolve().parents[3]
MAST = REPO / "inputs" / "site" / "synthetic_mast.csv"
HEIGHTS = np.arange(30.0, 151.0, 20.0)
SITE = dict(latitude=52.0, roughness_length=0.05)


def records_of(hub_speeds, obukhov_lengths, hub_directions, noise=0.0, seed=0):
    abl = EkmanABL.from_reference_wind(np.asarray(hub_speeds, float), 90.0,
                                       obukhov_length=np.asarray(obukhov_lengths, float), **SITE)
    speeds = abl.speed(HEIGHTS[:, None]).T
    turn = abl.wind_angle(HEIGHTS[:, None]).T - abl.wind_angle(90.0)[:, None]
    directions = np.asarray(hub_directions, float)[:, None] - turn
    rng = np.random.default_rng(seed)
    speeds = speeds + noise * rng.normal(0.0, 0.1, speeds.shape)
    directions = directions + noise * rng.normal(0.0, 0.5, directions.shape)
    table = {"time": [f"2026-06-01 {h:02d}:00" for h in range(len(speeds))]}
    table |= {f"speed_{z:.0f}m": speeds[:, j] for j, z in enumerate(HEIGHTS)}
    table |= {f"direction_{z:.0f}m": np.mod(directions[:, j], 360.0) for j, z in enumerate(HEIGHTS)}
    return pd.DataFrame(table), abl


def row_model():
    config = make_config("gch", atmosphere=SITE | {"obukhov_length": 200.0})
    config["wake"]["model_strings"].update(velocity_model="ekman_veer",
                                           deflection_model="ekman_veer")
    config["wake"]["wake_deflection_parameters"]["ekman_veer"] = {"veer": True}
    config["wake"]["enable_secondary_steering"] = False
    config["wake"]["enable_yaw_added_recovery"] = False
    config["wake"]["enable_transverse_velocities"] = False
    config["flow_field"]["wind_shear"] = 0.0  # the atmosphere gives the shear; no GCH term reads it
    return FlorisModel(config)


# FLORIS's default sosfs with the incoming-speed deficits is row_model's set-up: its
# ModelSettingsWarning is tested in tests/plugin/wake_models/test_models.py::test_summed_wakes_are_asked_for_with_incoming_deficits.
ROW_MODEL_SETTINGS = pytest.mark.filterwarnings(
    "ignore:wake.model_strings.combination_model:floris_ekman_veer.ModelSettingsWarning")


def test_package_exports_fit_site():
    assert floris_ekman_veer.fit_site is fit_site and "fit_site" in floris_ekman_veer.__all__


@ROW_MODEL_SETTINGS
def test_floris_run_gives_back_the_fitted_profiles():
    records, truth = records_of([8.0, 10.0, 6.0], [np.inf, 150.0, 300.0], [270.0, 265.0, 280.0])
    site = fit_site(records, 90.0, stability_input="obukhov_length", **SITE)
    # FLORIS's inputs per record: the true hub wind (noise-free data), I_u of the ABL.
    np.testing.assert_allclose(site.wind_speeds, [8.0, 10.0, 6.0], rtol=1e-6)
    np.testing.assert_allclose(site.wind_directions, [270.0, 265.0, 280.0], atol=1e-5)
    np.testing.assert_allclose(site.turbulence_intensities,
                               truth.turbulence_intensity(90.0), rtol=1e-5)
    assert site.atmosphere["obukhov_length"] == pytest.approx([np.inf, 150.0, 300.0], rel=1e-5)
    assert site.labels == list(records["time"]) and site.dropped == []
    fmodel = row_model()
    site.apply(fmodel)
    fmodel.run()
    # The ABL FLORIS solves per condition is the fitted one: same G, same veer.
    abl = solved_atmosphere(fmodel.core.flow_field)
    np.testing.assert_allclose(np.ravel(abl.geostrophic_wind), truth.geostrophic_wind, rtol=1e-6)
    np.testing.assert_allclose(np.ravel(abl.wind_direction_change(30.0, 150.0)),
                               truth.wind_direction_change(30.0, 150.0), atol=1e-5)
    np.testing.assert_allclose(fmodel.core.flow_field.wind_directions, site.wind_directions)
    series = site.time_series()
    np.testing.assert_allclose(series.wind_speeds, site.wind_speeds)
    np.testing.assert_allclose(series.turbulence_intensities, site.turbulence_intensities)


@ROW_MODEL_SETTINGS
# The records' turbulence intensities, which ekman_veer does not read (a notice tested in
# tests/plugin/wake_models/test_floris_input_messages.py), go to the GCH comparison.
@pytest.mark.filterwarnings("ignore:flow_field.turbulence_intensities:floris_ekman_veer.ModelSettingsWarning")
def test_annual_energy_and_optimize_yaw_run_per_record():
    records, _ = records_of([8.0, 8.0, 9.0], [np.inf, 150.0, 150.0], [270.0, 270.0, 272.0],
                            noise=1.0, seed=5)
    site = fit_site(records, 90.0, speed_noise=0.1, direction_noise=0.5, **SITE)
    fmodel = row_model()
    site.apply(fmodel)
    df_opt = optimize_yaw(fmodel, YawOptimizationSR, minimum_yaw_angle=-25.0,
                          maximum_yaw_angle=25.0, Ny_passes=[5], progress=False)
    assert len(df_opt) == 3 and np.all(df_opt.farm_power_opt >= df_opt.farm_power_baseline)
    # A record's optimum is that of its own atmosphere alone (conditions do not mix).
    alone = row_model()
    alone.set(wind_directions=site.wind_directions[1:2], wind_speeds=site.wind_speeds[1:2],
              turbulence_intensities=site.turbulence_intensities[1:2])
    classes, record_classes = site.stability()
    assert record_classes == list(records["time"]) and len(classes) == 3
    from floris_ekman_veer.plugin.inflow.inflow import set_atmosphere
    set_atmosphere(alone, classes[record_classes[1]]["atmosphere"],
                   wind_directions=site.wind_directions[1:2], wind_speeds=site.wind_speeds[1:2],
                   turbulence_intensities=site.turbulence_intensities[1:2])
    alone_opt = optimize_yaw(alone, YawOptimizationSR, minimum_yaw_angle=-25.0,
                             maximum_yaw_angle=25.0, Ny_passes=[5], progress=False)
    np.testing.assert_allclose(df_opt.yaw_angles_opt[1], alone_opt.yaw_angles_opt[0])
    assert df_opt.farm_power_opt[1] == pytest.approx(alone_opt.farm_power_opt[0], rel=1e-12)
    energy = site.annual_energy(fmodel, YawOptimizationSR, models=("ekman_veer",),
                                minimum_yaw_angle=-25.0, maximum_yaw_angle=25.0, Ny_passes=[5],
                                progress=False)
    year = energy.table[energy.table.stability == "all"].iloc[0]
    # Equal frequencies: the year's energy is 8760 h x the mean of the records' farm powers.
    hours = 8760.0
    assert year.aep_baseline_gwh == pytest.approx(
        hours * df_opt.farm_power_baseline.mean() / 1e9, rel=1e-9)
    assert year.aep_steered_gwh == pytest.approx(hours * df_opt.farm_power_opt.mean() / 1e9,
                                                 rel=1e-9)
    assert year.aep_steered_gwh > year.aep_baseline_gwh


def test_misfits_are_refused_or_dropped_by_record():
    records, _ = records_of([8.0, 9.0], [200.0, 200.0], [270.0, 270.0])
    speed_columns = [c for c in records if c.startswith("speed_")]
    records.loc[1, speed_columns] = records.loc[1, speed_columns].to_numpy()[::-1]
    with pytest.raises(ValueError, match=r"record 2026-06-01 01:00 fits no atmosphere"):
        fit_site(records, 90.0, **SITE)
    site = fit_site(records, 90.0, on_misfit="drop", **SITE)
    assert site.dropped == ["2026-06-01 01:00"] and site.labels == ["2026-06-01 00:00"]
    assert site.atmosphere["stability_parameter"] == [
        pytest.approx(float(site.profile_fit.stability_parameter[0]))]


@ROW_MODEL_SETTINGS
def test_bad_tables_are_refused():
    records, _ = records_of([8.0], [200.0], [270.0])
    with pytest.raises(ValueError, match=r"speed columns at two heights or more"):
        fit_site(records[["time", "speed_30m"]], 90.0, **SITE)
    with pytest.raises(ValueError, match=r"columns \['speed_-30m'\] are named like measurements"):
        fit_site(records.rename(columns={"speed_30m": "speed_-30m"}), 90.0, **SITE)
    with pytest.raises(ValueError, match=r"must be a pandas DataFrame"):
        fit_site(records.to_numpy(), 90.0, **SITE)
    with pytest.raises(ValueError, match=r"reference_height must be a number > 0"):
        fit_site(records, -90.0, **SITE)
    with pytest.raises(ValueError, match=r"on_misfit must be one of"):
        fit_site(records, 90.0, on_misfit="flag", **SITE)
    site = fit_site(records, 90.0, **SITE)
    fmodel = row_model()
    fmodel.set(reference_wind_height=100.0)
    with pytest.raises(ValueError, match=r"reference_wind_height is 100.0 m but the site"):
        site.apply(fmodel)


def test_shipped_synthetic_mast_is_labelled_and_fitted():
    header = MAST.read_text().splitlines()[0]
    assert "SYNTHETIC" in header and "not measurements" in header
    records = pd.read_csv(MAST, comment="#")
    site = fit_site(records, 90.0, speed_noise=0.1, direction_noise=0.5, stability="either",
                    **SITE)
    fit = site.profile_fit
    assert len(records) == 24 and np.all(fit.fits)
    np.testing.assert_allclose(site.wind_speeds, records["true_hub_speed"], rtol=0.02)
    true = records["true_obukhov_length"].to_numpy()
    stable = (true > 0) & (true < 1000)
    convective = true < 0
    # Stable nights: L within 15 %; the convective afternoon: convective (its L is loose, 30-190
    # m for -105..-40 m: 30-150 m of speeds barely pin it); the near-neutral hours (L infinite
    # or 2 km): |L| beyond 300 m (one, 07:00, fitted convective with L = -379 m).
    np.testing.assert_allclose(fit.obukhov_length[stable], true[stable], rtol=0.15)
    assert np.all(fit.stability_class[stable] == "stable")
    assert np.all(fit.stability_class[convective] == "convective")
    assert np.all(np.abs(fit.obukhov_length[~stable & ~convective]) > 300.0)


def test_hub_speed_with_veer_or_shear_is_an_atmosphere():
    """One of rotor veer and shear with the hub speed determines u* and L: the veer is met
    exactly and the shear follows (docs/measurements.md#simpler-site-inputs)."""
    from floris_ekman_veer.studies.site.shear_and_veer import atmosphere_from_shear_and_veer

    bottom, top = 27.0, 153.0
    for veer in (2.0, 10.0, 20.0):
        abl = atmosphere_from_shear_and_veer(8.0, 90.0, 126.0, veer=veer, **SITE)
        assert float(abl.wind_direction_change(bottom, top)) == pytest.approx(veer, abs=1e-6)
        assert float(abl.speed(90.0)) == pytest.approx(8.0, rel=1e-8)
        # The same state from the hub speed and its Obukhov length (the other simple input).
        again = EkmanABL.from_reference_wind(8.0, 90.0, obukhov_length=float(
            abl.profile_fit.obukhov_length), **SITE)
        assert float(again.geostrophic_wind) == pytest.approx(float(abl.geostrophic_wind),
                                                              rel=1e-7)
    # More veer, more stable: L falls, the shear across the rotor grows.
    lengths = [float(atmosphere_from_shear_and_veer(8.0, 90.0, 126.0, veer=v, **SITE)
                     .profile_fit.obukhov_length) for v in (2.0, 5.0, 10.0)]
    assert lengths[0] > lengths[1] > lengths[2]
    # A shear exponent alone: the model's shear between the tips within 0.01 of it.
    for shear in (0.2, 0.3):
        abl = atmosphere_from_shear_and_veer(8.0, 90.0, 126.0, shear_exponent=shear, **SITE)
        model_shear = np.log(float(abl.speed(top) / abl.speed(bottom))) / np.log(top / bottom)
        assert model_shear == pytest.approx(shear, abs=0.01)
    # Below the neutral shear of this roughness (0.156) the atmosphere is convective (L of
    # either sign by default); no stable one is left.
    low = atmosphere_from_shear_and_veer(8.0, 90.0, 126.0, shear_exponent=0.1, **SITE)
    assert low.profile_fit.stability_class == "convective"
    model_shear = np.log(float(low.speed(top) / low.speed(bottom))) / np.log(top / bottom)
    assert model_shear == pytest.approx(0.1, abs=0.01)
    with pytest.raises(ValueError, match="fits no atmosphere"):
        atmosphere_from_shear_and_veer(8.0, 90.0, 126.0, shear_exponent=0.1, stability="stable",
                                       **SITE)
    # Both: at z0 = 0.05 m shear 0.3 goes with about 7.5 deg of veer, not 20.
    with pytest.raises(ValueError, match="fits no atmosphere"):
        atmosphere_from_shear_and_veer(8.0, 90.0, 126.0, shear_exponent=0.3, veer=20.0, **SITE)
    both = atmosphere_from_shear_and_veer(8.0, 90.0, 126.0, shear_exponent=0.3, veer=7.5, **SITE)
    assert both.profile_fit.fits
    with pytest.raises(ValueError, match="needs shear_exponent, veer or both"):
        atmosphere_from_shear_and_veer(8.0, 90.0, 126.0, **SITE)
    vector = atmosphere_from_shear_and_veer(8.0, 90.0, 126.0, veer=[2.0, 10.0], **SITE)
    np.testing.assert_allclose(vector.profile_fit.obukhov_length, lengths[::2], rtol=1e-6)


@pytest.mark.study
def test_site_fit_example_reduced(tmp_path):
    """examples/site_fit.py on four records: the fit, the FLORIS run from the YAML it writes,
    annual energy with and without steering, the figure."""
    import site_fit  # examples/ is on pytest's pythonpath (pyproject.toml)

    result = site_fit.run_example(reduced=True, models=("ekman_veer", "gch"))
    table, energy = result["table"], result["energy"].table
    assert len(table) == 4 and np.all(table["misfit"] < 2.0)
    year = energy[energy["stability"] == "all"].set_index("model")
    assert set(year.index) == {"ekman_veer", "gch"}
    assert np.all(year["aep_steered_gwh"] >= year["aep_baseline_gwh"])
    path = site_fit.write_input(result["site"], tmp_path)
    again = FlorisModel(path)  # the YAML, with its per-record atmosphere lists, runs as written
    again.run()
    np.testing.assert_allclose(again.get_farm_power() / 1e3, table["farm_power_kw"], rtol=1e-12)
    assert site_fit.plot_profiles(result["site"], tmp_path).stat().st_size > 10_000
