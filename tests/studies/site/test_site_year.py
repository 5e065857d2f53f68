"""A year of hourly mast records end to end (docs/measurements.md#a-year-of-records): the
synthetic year of tests/data/mast_year.csv.gz (every kind of record a mast logs: calm hours,
zero readings, backing fronts, convective afternoons, stable nights, neutral days) goes through
``fit_site`` in one call: every record the model describes is fitted, every other one is named
by its time stamp and a reason, and the summary table counts them; the fitted year runs as one
vectorised FLORIS model."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from floris import FlorisModel

import floris_ekman_veer
from floris_ekman_veer import fit_site
from floris_ekman_veer.studies.site.record_fit import EXCLUSION_KINDS
from tests.data.generate_mast_year import HEIGHTS, main as generate

YEAR = Path(__file__).resolve().parents[2] / "data" / "mast_year.csv.gz"
SITE = dict(latitude=52.0, roughness_length=0.05, speed_noise=0.1, direction_noise=0.5)
#: What each true kind of record becomes: the fit's kinds it may be given (a convective hour
#: with little shear deficit is a neutral fit, a front's slight backing may read as a misfit; a
#: convective hour whose stable fit is a layer below the heights that its data do not show, and
#: one neutral hour with two heights left whose exact stable fit is such a layer, are "no top").
#: L of either sign (the default): the convective hours are fitted, but for the strongest
#: winds, whose generator state (Businger-Dyer L = -15 to -60 m at 13-18 m/s, or L = 30 m
#: under 14-17 m/s at night) implies a heat flux beyond the atmosphere's input range: held on
#: that bound and refused ("physical bound").
EXPECTED = {
    "neutral": {"fitted", "misfit", "no top"}, "stable": {"fitted", "physical bound"},
    "calm": {"calm"}, "zero": {"zero reading"}, "backing": {"backing", "misfit", "fitted"},
    "convective": {"fitted", "backing", "misfit", "no top", "physical bound"},
}


@pytest.fixture(scope="module")
def records():
    return pd.read_csv(YEAR)


@pytest.fixture(scope="module")
def site(records):
    # Three northerly records of the year turn by less than a degree within 0 to 2 pi, as
    # directions in radians would; the year's other northerly winds (beyond 2 pi in degrees)
    # show the wind turning through north: no DirectionUnitsWarning (package warnings are
    # errors in the suite). Three convective afternoons come out as stable layers 30 m deep, the
    # vane offsets taken against the surface layer's neutral turning (the generator's vanes
    # turn as the model does: docs/measurements.md#vane-offsets): one warning names them.
    with pytest.warns(floris_ekman_veer.ShallowBoundaryLayerWarning,
                      match=r"3 of 8451 fitted records have their boundary layer top so far below"):
        return fit_site(records, 90.0, on_misfit="drop", **SITE)


def test_the_year_is_what_its_generator_writes(tmp_path, records):
    made = generate(tmp_path / "year.csv.gz")
    assert len(made) == 8760 == len(records)
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "year.csv.gz"), records)
    assert [f"speed_{h:.0f}m" for h in HEIGHTS] == [c for c in records if c.startswith("speed_")]
    counts = records["true_kind"].value_counts()
    assert counts["calm"] == 110 and counts["zero"] == 30 and counts["backing"] == 40
    assert counts["convective"] == 360 and counts["stable"] > 3000


def test_one_call_fits_every_fittable_record_and_names_the_others(records, site):
    excluded = site.excluded
    kind = pd.Series("fitted", index=records.index)
    kind[excluded.index] = excluded["kind"]
    # Every record is either fitted or left out with its time stamp, and never both.
    assert len(site.labels) + len(excluded) == len(records)
    assert set(site.labels).isdisjoint(excluded["time"])
    assert list(excluded["time"]) == list(records["time"].iloc[excluded.index])
    assert site.dropped == list(excluded["time"])
    assert set(excluded["kind"]) <= set(EXCLUSION_KINDS)
    for true_kind, allowed in EXPECTED.items():
        got = set(kind[records["true_kind"] == true_kind])
        assert got <= allowed, (true_kind, got)
    # Model profiles (neutral days, stable nights) with noise: all but a few in ten thousand
    # fitted (the chi-square test refuses 1e-6 of them; light winds with h inside the mast).
    model = records["true_kind"].isin(["neutral", "stable"])
    assert (kind[model] == "fitted").sum() >= model.sum() - 4
    stable = kind[records["true_kind"] == "stable"]
    assert (stable == "fitted").sum() >= stable.size - 3
    bound = excluded[excluded["kind"] == "physical bound"]["reason"]
    assert bound.str.contains(r"on the bound of the sensible heat flux (?:-300|800) W/m\^2").all()
    # The rare kinds are recognised as what they are; the convective hours are kept, convective,
    # where their fit lies inside the physical domain. A fit on a bound is never kept
    # (docs/measurements.md#reading-stability): the convective afternoons whose best fit, under
    # the weak prior on 1/L, still lies on the 800 W/m^2 bound are named "physical bound"
    # (measured: 231 of the 360 kept convective, 80 on the bound, 45 with no top in the mast).
    assert (kind[records["true_kind"] == "backing"] == "backing").sum() >= 36
    convective = records["true_kind"] == "convective"
    classes = pd.Series(site.profile_fit.stability_class, index=kind.index[kind == "fitted"])
    assert (classes.reindex(kind.index[convective]) == "convective").sum() >= 215
    assert (kind[convective] == "physical bound").sum() <= 90
    # The reasons a person reads: the column of a zero reading, the backing in degrees.
    zero = excluded[excluded["kind"] == "zero reading"]["reason"]
    assert zero.str.contains(r"zero speed reading \(0 m/s\) in speed_\d+m").all()
    backing = excluded[excluded["kind"] == "backing"]["reason"]
    assert backing.str.contains(r"backs with height by [\d.]+ deg from 30 m to 150 m").all()
    assert excluded[excluded["kind"] == "calm"]["reason"].str.startswith("calm: every speed").all()
    # stability="stable" (an option) refuses them, named as convective.
    stable_only = fit_site(records[convective], 90.0, on_misfit="drop", stability="stable",
                           **SITE).excluded
    assert (stable_only["kind"] == "convective").sum() >= 180
    assert stable_only[stable_only["kind"] == "convective"]["reason"].str.contains(
        r"unstable \(convective\) layer, outside the stable fit's classes .*stability=\"either\"").all()


def test_summary_counts_what_was_left_out_and_why(site):
    summary = site.summary().exclusions
    counts = site.excluded["kind"].value_counts()
    assert summary.loc["fitted", "records"] == len(site.labels)
    for kind, n in counts.items():
        assert summary.loc[kind, "records"] == n
        rows = site.excluded[site.excluded["kind"] == kind]
        assert summary.loc[kind, "first"] == rows["time"].iloc[0]
        assert summary.loc[kind, "example"] == rows["reason"].iloc[0]
    assert list(summary.index[:-1]) == [k for k in EXCLUSION_KINDS if k in counts]
    assert summary["records"].sum() == 8760


def test_raise_names_the_first_record_by_time_stamp_and_column(records):
    with pytest.raises(ValueError, match=r"record 2025-01-14 00:00 cannot be fitted: zero speed "
                                         r"reading \(0 m/s\) in speed_150m.*29 more record"):
        fit_site(records, 90.0, **SITE)


def test_the_fitted_year_runs_as_one_floris_model(site):
    fmodel = FlorisModel(floris_ekman_veer.example_input("farm_night"))
    with pytest.warns(floris_ekman_veer.FlorisEkmanVeerWarning):
        site.apply(fmodel)
        fmodel.run()
    power = fmodel.get_farm_power()
    assert power.shape == (len(site.labels),) and np.all(np.isfinite(power))
    # The atmosphere FLORIS solves per record is the fitted one.
    abl = floris_ekman_veer.plugin.inflow.inflow.solved_atmosphere(fmodel.core.flow_field)
    np.testing.assert_allclose(np.ravel(abl.geostrophic_wind),
                               site.profile_fit.geostrophic_wind, rtol=1e-3)


@pytest.mark.study
def test_the_fitted_year_gives_its_annual_energy_in_one_call(site):
    """fit_site(...).annual_energy(...) on the whole year: one call, every fitted record a
    condition of one vectorised study, its baseline the plain per-record FLORIS run's."""
    import warnings

    fmodel = FlorisModel(floris_ekman_veer.example_input("farm_night"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", floris_ekman_veer.FlorisEkmanVeerWarning)
        energy = site.annual_energy(fmodel)
        direct = FlorisModel(floris_ekman_veer.example_input("farm_night"))
        site.apply(direct)
        direct.run()
    for model in ("ekman_veer", "gch"):
        conditions = energy.conditions[model]
        assert len(conditions) == len(site.labels)
        assert np.all(np.isfinite(conditions["farm_power_baseline"]))
    np.testing.assert_allclose(
        energy.conditions["ekman_veer"]["farm_power_baseline"].sort_index().to_numpy(),
        direct.get_farm_power(), rtol=1e-12)
    year = energy.table[energy.table["stability"] == "all"].set_index("model")
    assert np.all(year["aep_baseline_gwh"] > 0.0)
