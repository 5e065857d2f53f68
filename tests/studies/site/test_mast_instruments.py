"""A real mast's instruments through fit_site (docs/measurements.md#a-real-mast): vanes at their
own heights, vane offsets, stuck vanes, two booms with mast shadow, cup spikes, the cups'
standard deviations; the seeded year of examples/instrumented_mast_year.py fitted with the
defaults; the site report (summary, energy by class and month, one warning per class)."""

import warnings

import numpy as np
import pandas as pd
import pytest

import floris_ekman_veer
from floris_ekman_veer import fit_site
from floris_ekman_veer.studies.site.baseline import neutral_baseline
from floris_ekman_veer.studies.site.columns import mast_columns
from floris_ekman_veer.studies.site.offsets import estimate_vane_offsets, turning_forms_between
from floris_ekman_veer.studies.site.readings import (calibrated_cups, measured_turbulence,
                                                     read_instruments)
from instrumented_mast_year import (BOOMS, CUP_HEIGHTS, LONGITUDE, N_ICING, TERRAIN_TURBULENCE,
                                     SECTOR_ROUGHNESS, TIME_ZONE, VANE_HEIGHTS, VANE_OFFSETS,
                                     mast_year,
                                     shadow_deficit)

#: The site as its engineer knows it: onshore at 53.3 N 1.8 W, the stamps in UTC; one roughness
#: length for all sectors (the generator's are 0.02 to 0.3 m).
SITE = dict(latitude=53.3, roughness_length=0.05, site_type="onshore", longitude=LONGITUDE,
            time_zone=TIME_ZONE)
#: The fit's inputs alone (stages 1-3 take no site type).
FIT_INPUTS = dict(latitude=53.3, roughness_length=0.05)


@pytest.fixture(scope="module")
def year():
    return mast_year()


@pytest.fixture(scope="module")
def instruments(year):
    """The site fit's stages 1-3 (studies/site/pipeline.py), called one by one."""
    columns = mast_columns(year, BOOMS)
    readings = read_instruments(year, columns, booms=BOOMS)
    return estimate_vane_offsets(readings, year, columns, 80.0, FIT_INPUTS, booms=BOOMS)


@pytest.fixture(scope="module")
def site(year):
    """The year fitted as a site engineer would: the defaults, the mast's booms and its cups'
    calibration certificates."""
    # Five northerly records turn by less than a degree within 0 to 2 pi, as directions in
    # radians would; the year's other northerly winds show the wind turning through north: no
    # DirectionUnitsWarning (package warnings are errors in the suite).
    return fit_site(year, 80.0, on_misfit="drop", booms=BOOMS,
                    cup_calibrations=year.attrs["cup_calibration_certificates"], **SITE)


# ---------------------------------------------------------------------------- the generator
def test_the_generator_is_seeded_and_makes_what_it_documents(year):
    again = mast_year()
    pd.testing.assert_frame_equal(again, year)
    assert len(year) == 8760
    assert {f"speed_{h:.0f}m_{b}" for h in CUP_HEIGHTS for b in BOOMS} <= set(year.columns)
    assert {f"speed_{h:.0f}m_{b}_std" for h in CUP_HEIGHTS for b in BOOMS} <= set(year.columns)
    assert {f"direction_{h:.0f}m" for h in VANE_HEIGHTS} <= set(year.columns)
    kinds = year["true_class"].value_counts()
    assert set(kinds.index) == {"convective", "neutral", "stable"} and kinds.min() > 500
    # Convective middays, stable nights: the diurnal cycle a fit should find.
    hour = pd.to_datetime(year["time"]).dt.hour
    assert (year["true_class"][hour == 13] == "convective").mean() > 0.2
    assert (year["true_class"][hour.isin([0, 1, 2, 3])] == "stable").mean() > 0.6
    # (|L| drawn from 10-150 m, enlarged where the heat flux would exceed the sun's share)
    assert year.loc[year["true_class"] == "convective", "true_obukhov_length"].between(-500, -10).all()
    assert year.loc[year["true_class"] == "stable", "true_obukhov_length"].between(20, 200).all()
    # Icing: N_ICING runs of one vane repeating its reading.
    stuck = pd.concat([year[f"true_stuck_{h:.0f}m"] for h in VANE_HEIGHTS], ignore_index=True)
    assert (stuck.astype(int).diff() == 1).sum() == N_ICING
    # The mast's wake: the cup on the boom at 135 deg reads low when the wind comes from 315.
    assert shadow_deficit(315.0, 135.0) == pytest.approx(0.25) and shadow_deficit(45.0, 135.0) < 1e-6
    wake = np.abs((year["true_direction_80m"] - 315.0 + 180.0) % 360.0 - 180.0) < 5.0
    ratio = (year["speed_80m_a"] / year["speed_80m_b"])[wake]
    assert 0.72 < ratio.median() < 0.8
    # Ten-minute records for two years: the same generator.
    ten = mast_year(periods=200, freq="10min")
    assert pd.to_datetime(ten["time"]).diff().iloc[1] == pd.Timedelta("10min")


# ------------------------------------------------------------------------ the instruments
def test_cups_out_of_the_mast_wake_are_chosen_and_both_averaged_where_clear():
    frame = pd.DataFrame({"speed_40m_a": [7.0, 5.0, 7.0, 7.0], "speed_40m_b": [6.0, 6.0, 6.9, 9.5],
                          "speed_80m": [8.0, 8.0, 8.0, 8.0],
                          "direction_40m": [135.0, 315.0, 45.0, 45.0],
                          "direction_80m": [135.0, 315.0, 45.0, 45.0]})
    columns = mast_columns(frame, {"a": 135.0, "b": 315.0})
    got = read_instruments(frame, columns, booms={"a": 135.0, "b": 315.0},
                           direction_offsets=None)
    # From 135 deg the cup on boom b (315) is behind the mast: a is used; from 315, b is used
    # (a reads 17 % low behind the mast); from 45 neither is in the wake: the mean; a pair
    # 2.5 m/s apart there disagrees and is named.
    np.testing.assert_allclose(got.speeds[:, 0], [7.0, 6.0, 6.95, np.nan])
    flags = got.flags
    assert list(flags["row"]) == [3] and flags["kind"].iloc[0] == "cups disagree"
    assert "speed_40m_a 7, speed_40m_b 9.5" in flags["reason"].iloc[0]


def test_stuck_vanes_are_found_and_their_records_named(year, instruments):
    flags = instruments.flags[instruments.flags["kind"] == "stuck vane"]
    found = {(r, c) for r, c in zip(flags["row"], flags["column"])}
    true = {(r, f"direction_{h:.0f}m") for h in VANE_HEIGHTS
            for r in np.flatnonzero(year[f"true_stuck_{h:.0f}m"])}
    # Every icing reading found (a run interrupted by a missing value may lose its last one),
    # and no chance repeat of a turning vane taken for one.
    assert len(true - found) <= 2 and found <= true
    assert flags["reason"].str.contains(r"in \d+ records in a row .*\(icing\)").all()


def test_vane_offsets_are_found_within_their_uncertainty(year, instruments, site):
    """The offsets are estimated against the surface layer's neutral turning (none between the
    vanes, offsets.py); the generator's vanes turn as the model's neutral layer does (about
    0.5 deg counterclockwise from 38 to 78 m), one of the forms the systematic uncertainty
    spans: each offset is the generator's plus the model's turning within three statistical
    errors, and the generator's within its statistical and systematic parts."""
    strong = instruments.speeds[:, -1] >= 12.0
    for table in (instruments.offsets, site.offsets):
        for height, offset in VANE_OFFSETS.items():
            row = table.loc[height]
            if not offset:
                assert row["offset_deg"] == 0.0 and row["source"] == "reference"
                continue
            assert row["source"] == "estimated" and row["records"] > 300
            assert 0.0 < row["uncertainty_deg"] < 0.15
            model = turning_forms_between(FIT_INPUTS, instruments.speeds[strong, -1], 80.0,
                                          height, 78.0).loc["model", "turning_deg"]
            assert row["offset_deg"] == pytest.approx(offset - model,
                                                      abs=3.0 * row["uncertainty_deg"])
            assert abs(row["offset_deg"] - offset) < 2.0 * np.hypot(row["uncertainty_deg"],
                                                                    row["systematic_deg"])
    # Beside the statistical error, the reference turning's systematic uncertainty: the
    # published forms' largest departure from the surface layer's (about 0.5 deg between 38 and
    # 78 m, 0.25 deg between 58 and 78 m at 12-18 m/s), larger than the statistical part.
    systematic = site.offsets["systematic_deg"]
    assert 0.4 < systematic.loc[38.0] < 0.6 and 0.15 < systematic.loc[58.0] < 0.3
    assert np.all(systematic.loc[[38.0, 58.0]] > site.offsets["uncertainty_deg"].loc[[38.0, 58.0]])
    # Given offsets are applied as given (the reading minus the truth).
    given = fit_site(mast_year(periods=48), 80.0, on_misfit="drop", booms=BOOMS,
                     direction_offsets={38: -4.1, 58: 2.6}, **SITE)
    assert given.offsets["offset_deg"].tolist() == [-4.1, 2.6, 0.0]
    assert given.offsets["source"].tolist() == ["given", "given", "reference"]
    with pytest.raises(ValueError, match=r"direction_offsets names a vane at 40 m"):
        fit_site(mast_year(periods=48), 80.0, booms=BOOMS, direction_offsets={40: 1.0}, **SITE)


def test_an_offset_known_by_construction_is_found_against_the_surface_layers_turning():
    """Strong-wind records whose wind does not turn between the vanes (the constant-stress
    surface layer's neutral turning, the reference chosen: docs/measurements.md#vane-offsets),
    speeds of the neutral log law, vanes offset by -3.0 and +1.5 deg with 0.7 deg noise: each
    offset found within three of its statistical errors, and the systematic part (the other
    published forms' departure) reported beside it."""
    rng = np.random.default_rng(7)
    n, z0, kappa = 300, 0.05, 0.41
    speed = rng.uniform(12.0, 18.0, n)
    u_star = kappa * speed / np.log(80.0 / z0)
    direction = rng.uniform(0.0, 360.0, n)
    offsets = {38.0: -3.0, 58.0: 1.5, 78.0: 0.0}
    records = {f"speed_{h:g}m": np.round(u_star / kappa * np.log(h / z0)
                                          * (1.0 + rng.normal(0.0, 0.005, n)), 2)
               for h in (40.0, 60.0, 80.0)}
    for h, offset in offsets.items():
        records[f"direction_{h:g}m"] = np.mod(direction + offset + rng.normal(0.0, 0.7, n), 360.0)
    records = pd.DataFrame(records)
    columns = mast_columns(records)
    found = estimate_vane_offsets(read_instruments(records, columns), records, columns, 80.0,
                                  FIT_INPUTS).offsets
    for h, offset in offsets.items():
        row = found.loc[h]
        if not offset:
            assert row["source"] == "reference"
            continue
        assert row["records"] >= 200 and 0.0 < row["uncertainty_deg"] < 0.1
        assert row["offset_deg"] == pytest.approx(offset, abs=3.0 * row["uncertainty_deg"])
        assert row["systematic_deg"] > 2.0 * row["uncertainty_deg"]


def test_cup_pairs_agree_within_their_calibration(instruments):
    pairs = instruments.cup_pairs
    assert list(pairs["height"]) == list(CUP_HEIGHTS)
    assert (np.abs(pairs["median_ratio"] - 1.0) < 0.03).all() and not pairs["disagree"].any()


def test_a_pair_that_disagrees_over_the_year_is_named(year, instruments):
    drifted = year.head(500).copy()
    drifted["speed_60m_b"] *= 1.06  # a cup calibrated 6 % high
    site = fit_site(drifted, 80.0, on_misfit="drop", booms=BOOMS, **SITE)
    pairs = site.summary().cup_pairs.set_index("height")
    assert pairs.loc[60.0, "disagree"] and not pairs.loc[40.0, "disagree"]
    # (the pair's own calibrations: their ratio over the year)
    own = instruments.cup_pairs.set_index("height").loc[60.0, "median_ratio"]
    assert pairs.loc[60.0, "median_ratio"] == pytest.approx(1.06 * own, abs=0.01)


def _roughness_rose(records, certificates=None):
    """Stages 1-3 of fit_site's default (roughness_length="estimate"), as pipeline.py runs them:
    the readings and the roughness rose of ``records`` with the cups' ``certificates``."""
    columns = mast_columns(records, BOOMS)
    records, calibrations = calibrated_cups(records, columns, certificates)
    readings = read_instruments(records, columns, booms=BOOMS)
    cups = [len(columns.cups[h]) for h in columns.cup_heights]
    per_height = calibrations.groupby("height")["uncertainty"].agg(
        lambda u: float(np.sqrt(np.sum(np.square(u))) / len(u)))
    return readings, neutral_baseline(readings, 80.0, {"latitude": 53.3}, cups_per_height=cups,
                                      calibration_uncertainty=per_height.to_numpy()).sectors


def test_the_roughness_rose_is_the_generators_within_the_cups_calibration(year):
    """The issue's criterion, with the defaults and the cups' certificates (as a site engineer
    applies them): the rose within a factor 1.5 of the generator's in every sector, and within
    three of its reported standard uncertainties (statistical and the certificates' in
    quadrature; at most 2.1 here). The 270-deg sector is the closest to the factor (1.49: its
    records' 80/40 m ratio reads 0.3 % low through the certificates' own errors, boom a's 40 m
    certificate 2.2 of its stated 0.15 % off), the 300-deg one next (1.42: its boom b cups'
    random errors read the ratio 0.6 % high, three standard errors of their median). Without
    certificates the reported uncertainty (the generic 1 % calibration) holds the truth within
    two of them (docs/measurements.md#the-sites-neutral-baseline)."""
    truth = np.asarray(SECTOR_ROUGHNESS)
    readings, logged = _roughness_rose(year)
    # The selection: every record from 12 m/s at 80 m is neutral in the generator (|L| > 3 km).
    strong = readings.speeds[:, -1] >= 12.0
    assert strong.sum() > 800
    assert (year["true_obukhov_length"].abs()[strong] > 3e3).all()
    assert (logged["records"] >= 20).all() and (logged["half_width_deg"] == 15.0).all()

    def standard_errors(rose):
        found = np.log(rose["roughness_length"].to_numpy() / truth)
        sigma = np.hypot(np.log(rose["roughness_factor"]),
                         np.log(rose["roughness_factor_calibration"])).to_numpy()
        return found, sigma

    # As logged: this seed's cups read the 80/40 m ratio 1.5 % low (2.9 % with boom b's cups
    # alone, from 285 to 345 deg), about a factor 3 (6) in z0, within the reported uncertainty.
    found, sigma = standard_errors(logged)
    assert (np.abs(found) < 2.0 * sigma).all()
    assert np.exp(np.mean(found)) < 0.5
    # With the certificates: the calibration factor is the certificates' (0.15 % a cup: 1.07 to
    # 1.16), the rose the generator's.
    _, certified = _roughness_rose(year, year.attrs["cup_calibration_certificates"])
    found, sigma = standard_errors(certified)
    assert (certified["roughness_factor_calibration"] < 1.2).all()
    assert abs(np.mean(found)) < np.log(1.25)
    assert (np.abs(found) < np.log(1.5)).all(), np.exp(found)
    assert (np.abs(found) < 3.0 * sigma).all()


def test_one_inf_reading_is_named_by_its_time_stamp_and_aborts_nothing(year):
    records = year.head(24).copy()
    records.loc[3, "speed_80m_a"] = np.inf
    records.loc[5, "direction_58m"] = -np.inf
    site = fit_site(records, 80.0, on_misfit="drop", booms=BOOMS, **SITE)
    bad = site.flags[site.flags["kind"] == "infinite reading"]
    assert list(bad["time"]) == [records["time"][3], records["time"][5]]
    assert records["time"][3] in site.labels and records["time"][5] in site.labels


def test_the_cups_turbulence_is_the_wakes_input_and_only_its_departure_the_fits(year):
    """The measured TI (the cups' standard deviation over their speed at 80 m) is FLORIS's
    turbulence intensity for each record; the fit sees it divided by the site's terrain excess
    (the generator's 1.2 over the model's I_u): its own I_u at 80 m is the measured TI over
    about 1.2, not the measured TI read as convection (docs/measurements.md#reading-stability).
    Without the standard deviations FLORIS gets the fitted I_u."""
    records = year.head(48)
    with_std = fit_site(records, 80.0, on_misfit="drop", booms=BOOMS, **SITE)
    columns = mast_columns(records, BOOMS)
    readings = estimate_vane_offsets(read_instruments(records, columns, booms=BOOMS), records,
                                     columns, 80.0, FIT_INPUTS, booms=BOOMS)
    height, measured = measured_turbulence(readings, 80.0)
    assert height == 80.0
    measured = measured[with_std.rows]
    given = np.isfinite(measured)
    assert given.sum() > 40
    np.testing.assert_allclose(with_std.turbulence_intensities[given], measured[given],
                               rtol=1e-12)
    fitted = np.asarray(with_std.abl.turbulence_intensity(80.0), float)[given]
    assert np.median(measured[given] / fitted) == pytest.approx(TERRAIN_TURBULENCE, rel=0.05)
    without = fit_site(records.drop(columns=[c for c in records if c.endswith("_std")]), 80.0,
                       on_misfit="drop", booms=BOOMS, **SITE)
    np.testing.assert_allclose(without.turbulence_intensities,
                               np.asarray(without.abl.turbulence_intensity(80.0), float),
                               rtol=1e-12)
    # The wake's input (docs/atmosphere.md#ambient-turbulence): the block's turbulence_factor
    # makes the ekman_veer wake's ambient I_u at 80 m the measured TI, so its k_w is
    # [floor^n + (alpha' TI_measured)^n]^(1/n); without the std columns the block has none and
    # the wake keeps the model's I_u.
    assert "turbulence_factor" not in without.atmosphere
    factor = np.asarray(with_std.atmosphere["turbulence_factor"])
    assert np.median(factor[given]) == pytest.approx(TERRAIN_TURBULENCE, rel=0.05)
    for site, ambient in ((with_std, np.where(given, measured, np.nan)), (without, None)):
        k_w, floris_ti, model_ti = _wake_expansion_at_80m(site)
        if ambient is None:
            ambient = model_ti
        np.testing.assert_allclose(floris_ti[given], ambient[given], rtol=1e-12)
        np.testing.assert_allclose(
            k_w[given], (0.021**6 + (0.33 * ambient[given]) ** 6) ** (1 / 6), rtol=1e-12)


def _wake_expansion_at_80m(site):
    """(k_w of the ekman_veer wake of a rotor at 80 m, the ambient I_u the wake takes there, the
    fitted ABL's I_u there) per record of ``site``, as FLORIS solves the site's block."""
    from floris import FlorisModel

    from floris_ekman_veer.plugin.inflow.atmosphere_block import atmosphere_of
    from floris_ekman_veer.plugin.inflow.solve_cache import solve

    fmodel = FlorisModel(floris_ekman_veer.example_input("farm_night"))
    fmodel.set(reference_wind_height=80.0)
    site.apply(fmodel)
    abl = solve(atmosphere_of(fmodel.core), site.wind_speeds, 80.0)
    n = len(site.labels)
    speed = site.wind_speeds.reshape(n, 1, 1, 1)
    ambient = np.asarray(abl.turbulence_intensity(80.0, reference_height=80.0)).reshape(-1)
    k_w = fmodel.core.wake.velocity_model.expansion_rate(
        abl, np.full((n, 1, 1, 1), 80.0), speed, ambient.reshape(n, 1, 1, 1),
        ambient.reshape(n, 1, 1, 1))
    return (np.asarray(k_w).reshape(-1), ambient,
            np.asarray(site.abl.turbulence_intensity(80.0), float).reshape(-1))


@pytest.mark.parametrize("reference_height, match", [
    ("90", r"reference_height must be a number > 0 m \(not a string\); got '90'"),
    (1e4, r"reference_height must be at most 2 times the highest measurement \(80 m"),
    (True, r"reference_height must be a number"),
])
def test_bad_reference_heights_are_named(year, reference_height, match):
    with pytest.raises(ValueError, match=match):
        fit_site(year.head(5), reference_height, booms=BOOMS, **SITE)


def test_bad_columns_and_options_are_named(year):
    records = year.head(5)
    with pytest.raises(ValueError, match=r"time_column 'nope' is not a column of records"):
        fit_site(records, 80.0, booms=BOOMS, time_column="nope", **SITE)
    with pytest.raises(ValueError, match=r"columns \['speed_-30m'\] are named like measurements"):
        fit_site(records.assign(**{"speed_-30m": 1.0}), 80.0, booms=BOOMS, **SITE)
    with pytest.raises(ValueError, match=r"name booms without an orientation: give fit_site"):
        fit_site(records, 80.0, **SITE)
    with pytest.raises(ValueError, match=r"booms\['a'\] must be the boom's orientation"):
        fit_site(records, 80.0, booms={"a": "SE", "b": 315.0}, **SITE)
    with pytest.raises(ValueError, match=r"direction_offsets must be 'estimate', None or"):
        fit_site(records, 80.0, booms=BOOMS, direction_offsets=[1.0], **SITE)
    # Other statistics of a record (Task 43's min, max, a vane's sd) are left alone.
    plain = fit_site(records, 80.0, booms=BOOMS, on_misfit="drop", **SITE)
    more = fit_site(records.assign(speed_80m_a_max=30.0, speed_40m_b_min=0.0,
                                   direction_78m_std=3.0), 80.0, booms=BOOMS, on_misfit="drop",
                    **SITE)
    np.testing.assert_array_equal(more.wind_speeds, plain.wind_speeds)


# ------------------------------------------------------------------- the year, with defaults
def test_the_year_is_kept_its_offsets_found_and_its_classes_read(year, site):
    """The acceptance of docs/measurements.md#reading-stability: with the defaults, at least
    95 % of the non-calm records kept, the fitted classes the generator's for at least 90 % of
    the kept records, at most 5 % of the night's (21-04 h) records convective, none kept on a
    bound or without a degree of freedom."""
    not_calm = ~year["true_calm"].to_numpy()
    assert np.sum(not_calm[site.rows]) >= 0.95 * np.sum(not_calm)
    truth = year["true_class"].to_numpy()[site.rows]
    assert list(site.labels) == list(year["time"].iloc[site.rows])
    matched = np.mean(truth == site.stability_classes)
    assert matched >= 0.9
    # Each class is read, not one swallowing the others.
    for name in ("convective", "neutral", "stable"):
        assert np.mean(site.stability_classes[truth == name] == name) >= 0.8, name
    hour = pd.to_datetime(pd.Series(site.labels)).dt.hour.to_numpy()
    night = (hour >= 21) | (hour <= 4)
    assert np.mean(site.stability_classes[night] == "convective") <= 0.05
    fit = site.profile_fit
    assert np.all(fit.bound == "") and np.all(fit.degrees_of_freedom >= 1)


def test_the_summary_reads_like_a_site_report(year, site, tmp_path):
    summary = site.summary()
    assert summary.records == 8760 and summary.fitted == len(site.labels)
    assert summary.kept_fraction == pytest.approx(len(site.labels) / 8760)
    assert summary.exclusions.loc["fitted", "records"] == len(site.labels)
    assert summary.exclusions["records"].sum() == 8760
    by_hour = summary.class_by_hour
    assert by_hour.shape == (24, 3) and by_hour.to_numpy().sum() == len(site.labels)
    # Convective by day, stable by night.
    share = by_hour.div(by_hour.sum(axis=1), axis=0)
    assert share.loc[13, "convective"] > 0.3 > share.loc[2, "convective"]
    assert share.loc[2, "stable"] > 0.6 > share.loc[13, "stable"]
    text = str(summary)
    assert "vane offsets applied" in text and "class mix by hour of day" in text
    assert "stuck vane" in text and "cups disagree" in text
    import matplotlib

    matplotlib.use("Agg")
    ax = summary.plot_class_by_hour()
    ax.figure.savefig(tmp_path / "classes.png")
    assert (tmp_path / "classes.png").stat().st_size > 1000


def test_annual_energy_of_a_fitted_year_is_by_class_and_month_with_one_warning_each(year):
    from floris import FlorisModel

    records = year.iloc[np.r_[0:60, 4400:4460]]  # January and July
    site = fit_site(records, 80.0, on_misfit="drop", booms=BOOMS, **SITE)
    fmodel = FlorisModel(floris_ekman_veer.example_input("farm_night"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        energy = site.annual_energy(fmodel, models=("ekman_veer",), chunk_size=16)
    table = energy.table.set_index("stability")
    assert set(table.index) == {"convective", "neutral", "stable", "all"}
    counts = pd.Series(site.stability_classes).value_counts()
    for name, n in counts.items():
        assert table.loc[name, "n_conditions"] == n
    # A typical year by calendar month: January and July hold data, each 60 hours of its 744
    # (coverage 60/744), the other months none; each month's energy is its mean power times
    # its hours, whatever its gaps.
    by_month = energy.by_month.set_index("month")
    assert list(by_month.index) == list(range(1, 13))
    assert by_month.loc[[1, 7], "years"].tolist() == [1, 1]
    np.testing.assert_allclose(by_month.loc[[1, 7], "coverage"], [60 / 744, 60 / 744])
    assert by_month.drop(index=[1, 7])["aep_baseline_gwh"].isna().all()
    power = energy.conditions["ekman_veer"]["farm_power_baseline"].to_numpy()
    months = pd.DatetimeIndex(site.timestamps()).month
    for month in (1, 7):
        assert by_month.loc[month, "aep_baseline_gwh"] == pytest.approx(
            power[months == month].mean() * 744 / 1e9, rel=1e-12)
    # Eight chunks, one warning per class, located at this line, with speeds to 0.01 m/s.
    ours = [w for w in caught if issubclass(w.category, floris_ekman_veer.FlorisEkmanVeerWarning)]
    assert len(ours) == len({w.category for w in ours}) >= 1
    assert all(w.filename == __file__ for w in ours)
    for w in ours:
        speeds = str(w.message).partition("wind speeds ")[2].partition(" m/s")[0]
        assert not any(len(v.partition(".")[2]) > 2 for v in speeds.replace(",", " ").split()
                       if v[0].isdigit()), speeds


def test_site_report_example_reduced(tmp_path, capsys):
    """examples/site_report.py on ten days of records: the report, the truth and the PNG."""
    import site_report  # examples/ is on pytest's pythonpath (pyproject.toml)

    site_report.main(["--output", str(tmp_path), "--periods", "240", "--no-energy"])
    out = capsys.readouterr().out
    assert "class mix by hour of day" in out and "vane offsets found (given)" in out
    assert (tmp_path / "site_classes_by_hour.png").stat().st_size > 10_000
