"""The site's own neutral baseline (studies/site/baseline.py,
docs/measurements.md#the-sites-neutral-baseline): the roughness rose and neutral turbulence per
sector from the strong-wind records, recovered from the model's own neutral profiles of known
roughness, applied by default, and refused where it cannot be estimated."""

import numpy as np
import pandas as pd
import pytest

from floris_ekman_veer import EkmanABL, fit_site
from floris_ekman_veer.studies.site.baseline import neutral_baseline
from floris_ekman_veer.studies.site.columns import mast_columns
from floris_ekman_veer.studies.site.readings import read_instruments

LATITUDE = 53.3
CUPS = (40.0, 60.0, 80.0)
#: The truth: the sectors about 0 to 150 deg smooth, those about 180 to 330 deg rough.
Z0_SMOOTH, Z0_ROUGH = 0.005, 0.2
EXCESS = 1.2  # the terrain's turbulence over the model's neutral


def neutral_records(per_sector=24, thin_sector=None, seed=1):
    """Model neutral profiles (strong winds 12-18 m/s at 80 m) in 12 sectors, z0 by sector,
    the cups' standard deviations EXCESS times the model's neutral I_u."""
    rng = np.random.default_rng(seed)
    centres = np.repeat(np.arange(0.0, 360.0, 30.0), per_sector)
    if thin_sector is not None:
        keep = (centres != thin_sector) | (np.arange(centres.size) % per_sector < 5)
        centres = centres[keep]
    direction = np.mod(centres + rng.uniform(-14.0, 14.0, centres.size), 360.0)
    z0 = np.where(centres < 180.0, Z0_SMOOTH, Z0_ROUGH)  # (by sector: 345-15 deg is smooth)
    speed = rng.uniform(12.0, 18.0, centres.size)
    abl = EkmanABL.from_reference_wind(speed, 80.0, obukhov_length=np.inf, latitude=LATITUDE,
                                       roughness_length=z0)
    columns = {"time": pd.date_range("2025-01-01", periods=centres.size, freq="h").astype(str)}
    for h in CUPS:
        u = np.asarray(abl.speed(h), float)
        columns[f"speed_{h:g}m"] = u
        columns[f"speed_{h:g}m_std"] = EXCESS * np.asarray(abl.turbulence_intensity(h), float) * u
        columns[f"direction_{h:g}m"] = np.mod(
            direction - (np.asarray(abl.wind_angle(h)) - np.asarray(abl.wind_angle(80.0))), 360.0)
    return pd.DataFrame(columns), z0, abl


def baseline_of(records, **options):
    columns = mast_columns(records)
    readings = read_instruments(records, columns, direction_offsets=None)
    return neutral_baseline(readings, 80.0, dict(latitude=LATITUDE), **options)


def test_the_roughness_rose_and_neutral_turbulence_are_recovered():
    records, z0, abl = neutral_records()
    baseline = baseline_of(records)
    sectors = baseline.sectors
    truth = np.where(sectors.index < 180.0, Z0_SMOOTH, Z0_ROUGH)
    # The model's own neutral profiles: the inversion gives their z0 back (the grid's
    # interpolation in ln z0 within 3 %), each sector from its own 24 records.
    np.testing.assert_allclose(sectors["roughness_length"], truth, rtol=0.03)
    assert (sectors["half_width_deg"] == 15.0).all() and (sectors["records"] == 24).all()
    assert (sectors["source"] == "estimated").all()
    # The neutral TI is what the cups log, EXCESS times the model's at the sector's z0.
    np.testing.assert_allclose(sectors["neutral_ti"] / sectors["model_neutral_ti"], EXCESS,
                               rtol=0.03)
    # Without noise the statistical factors hold only the neutral ratio's small change with
    # speed (12-18 m/s: 1.5-3 %); the calibration's is larger (1 % of the ratio with one cup
    # per height), and larger the smoother the surface, whose shear says less of its z0.
    assert np.all((sectors["roughness_factor"] > 1.0) & (sectors["roughness_factor"] < 1.05))
    calibration = sectors["roughness_factor_calibration"]
    assert np.all(calibration[truth == Z0_ROUGH] > 1.5)
    assert np.all(calibration[truth == Z0_SMOOTH] > 2.0 * calibration[truth == Z0_ROUGH].max())
    # Per record: its sector's values.
    np.testing.assert_allclose(baseline.roughness_lengths, z0, rtol=0.03)
    intensity = EXCESS * np.asarray(abl.turbulence_intensity(80.0), float)
    assert np.all(np.abs(baseline.turbulence_intensities / intensity - 1.0) < 0.1)


def test_a_thin_sector_takes_a_wider_window():
    records, _, _ = neutral_records(thin_sector=90.0)
    sectors = baseline_of(records).sectors
    assert sectors.loc[90.0, "half_width_deg"] > 15.0 and sectors.loc[90.0, "records"] >= 20
    assert (sectors.drop(index=90.0)["half_width_deg"] == 15.0).all()


def test_fit_site_applies_the_baseline_by_default_and_reports_it():
    records, z0, _ = neutral_records(per_sector=20)
    site = fit_site(records, 80.0, latitude=LATITUDE, on_misfit="drop", direction_offsets=None)
    np.testing.assert_allclose(site.neutral_roughness_lengths, z0[site.rows], rtol=0.03)
    np.testing.assert_allclose(np.asarray(site.abl.roughness_length, float),
                               site.neutral_roughness_lengths)
    assert site.neutral_turbulence_intensities.shape == site.rows.shape
    summary = site.summary()
    assert list(summary.baseline.index) == list(np.arange(0.0, 360.0, 30.0))
    assert "neutral baseline per sector" in str(summary)
    # A given roughness is applied as given, the turbulence still estimated.
    given = fit_site(records.head(60), 80.0, latitude=LATITUDE, roughness_length=0.03,
                     on_misfit="drop", direction_offsets=None)
    assert np.all(np.asarray(given.abl.roughness_length) == 0.03)
    assert (given.summary().baseline["source"] == "given").all()
    # Per sector: each record the given sector nearest its direction.
    rose = fit_site(records.head(60), 80.0, latitude=LATITUDE, on_misfit="drop",
                    roughness_length={0.0: 0.01, 180.0: 0.1}, direction_offsets=None)
    direction = records["direction_80m"].to_numpy()[rose.rows]
    nearest = np.where(np.abs((direction - 180.0 + 180.0) % 360.0 - 180.0) < 90.0, 0.1, 0.01)
    np.testing.assert_array_equal(rose.neutral_roughness_lengths, nearest)


@pytest.mark.parametrize("value, message", [
    ("guess", r"roughness_length must be 'estimate', a number \[m\] or"),
    ({400.0: 0.1}, r"sectors must be their centres in \[0, 360\) deg; got 400"),
    ({90.0: -1.0}, r"roughness_length\[90.0\] must be a number in \(0, 8\) m"),
    (9.0, r"roughness_length must be a number in \(0, 8\) m .* got 9.0"),
    ({}, r"names no sector"),
])
def test_bad_roughness_is_refused_naming_it(value, message):
    records, _, _ = neutral_records(per_sector=2)
    with pytest.raises(ValueError, match=message):
        fit_site(records, 80.0, latitude=LATITUDE, roughness_length=value)


def test_too_few_strong_winds_to_estimate_are_refused():
    records, _, _ = neutral_records(per_sector=1)
    with pytest.raises(ValueError, match=r"needs 20 records or more with 12 m/s or more at 80 m"
                                         r".* the records have 12\. Give the roughness length"):
        fit_site(records, 80.0, latitude=LATITUDE)
