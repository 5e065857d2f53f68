"""The cups' calibration certificates (studies/site/readings.py's calibrated_cups,
docs/measurements.md#the-sites-neutral-baseline): each cup's readings re-calibrated from the
logger's generic transfer function to its certificate's before anything else; refused naming a
cup the records lack or an entry out of range."""

import numpy as np
import pandas as pd
import pytest

from floris_ekman_veer import fit_site
from floris_ekman_veer.studies.site.columns import mast_columns
from floris_ekman_veer.studies.site.readings import CERTIFICATE_UNCERTAINTY, calibrated_cups
from instrumented_mast_year import BOOMS, CERTIFICATE_ERROR, LOGGER_TRANSFER, mast_year

CERTIFICATE = {"slope": 0.0455, "offset": 0.25, "logger_slope": 0.046, "logger_offset": 0.2}


def test_a_certificate_replaces_the_loggers_transfer_function():
    records = pd.DataFrame({"speed_40m": [10.0, 0.0, 5.0], "speed_40m_std": [1.0, 0.0, 0.5],
                            "speed_80m": [12.0, 0.0, 6.0]})
    columns = mast_columns(records)
    out, table = calibrated_cups(records, columns, {"speed_40m": CERTIFICATE})
    # v = 0.046 f + 0.2 logged: f = (10 - 0.2) / 0.046, the certificate's 0.0455 f + 0.25.
    frequency = (10.0 - 0.2) / 0.046
    assert out["speed_40m"].iloc[0] == pytest.approx(0.0455 * frequency + 0.25, rel=1e-14)
    assert out["speed_40m_std"].iloc[0] == pytest.approx(0.0455 / 0.046, rel=1e-14)
    # A cup reading 0 is stopped or dead: no speed is made of the offsets; other cups untouched.
    assert out["speed_40m"].iloc[1] == 0.0
    pd.testing.assert_series_equal(out["speed_80m"], records["speed_80m"])
    assert table.loc["speed_40m", "source"] == "certificate"
    assert table.loc["speed_40m", "uncertainty"] == CERTIFICATE_UNCERTAINTY
    assert table.loc["speed_80m", "source"] == "logged" and table.loc["speed_80m", "uncertainty"] == 0.01
    # Without certificates the records are not copied.
    assert calibrated_cups(records, columns)[0] is records


@pytest.mark.parametrize("calibrations, match", [
    ({"speed_60m": CERTIFICATE}, r"cup_calibrations names cup 'speed_60m', which the records "
                                 r"lack \(their cups: \['speed_40m', 'speed_80m'\]\)"),
    ({"speed_40m": {"slope": 0.0455, "offset": 0.25}},
     r"cup_calibrations\['speed_40m'\] lacks \['logger_slope', 'logger_offset'\]"),
    ({"speed_40m": {**CERTIFICATE, "slope": -1.0}},
     r"cup_calibrations\['speed_40m'\]\['slope'\] must be > 0"),
    ({"speed_40m": {**CERTIFICATE, "uncertainty": 0.5}},
     r"\['uncertainty'\] must be a relative uncertainty in \[0, 0.1\); got 0.5"),
    ({"speed_40m": {**CERTIFICATE, "gain": 1.0}}, r"has unknown entries \['gain'\]"),
    ([CERTIFICATE], r"cup_calibrations must be \{cup column"),
])
def test_bad_certificates_are_named(calibrations, match):
    records = pd.DataFrame({"speed_40m": [10.0] * 3, "speed_80m": [12.0] * 3})
    with pytest.raises(ValueError, match=match):
        fit_site(records, 80.0, latitude=53.3, roughness_length=0.05,
                 cup_calibrations=calibrations)


def test_the_fixtures_certificates_are_its_cups_within_their_stated_uncertainty():
    """The instrumented year's certificates: the logger's transfer function over each cup's drawn
    calibration, off by the certificate's own error, which each states as its uncertainty;
    drawn from the seed's second stream (the records are those without certificates)."""
    year = mast_year(periods=24)
    truth = year.attrs["true_cup_calibration"]
    certificates = year.attrs["cup_calibration_certificates"]
    assert set(certificates) == set(truth)
    for column, certificate in certificates.items():
        assert certificate["uncertainty"] == CERTIFICATE_ERROR
        assert (certificate["logger_slope"], certificate["logger_offset"]) == LOGGER_TRANSFER
        # slope and offset scale together: the logged speed over the cup's own calibration
        assert certificate["offset"] / certificate["slope"] == pytest.approx(
            LOGGER_TRANSFER[1] / LOGGER_TRANSFER[0], rel=1e-12)
        error = LOGGER_TRANSFER[0] / (certificate["slope"] * truth[column]) - 1.0
        assert abs(error) < 4.0 * CERTIFICATE_ERROR
    # A certified reading is the true speed times the cup's random error only.
    site = fit_site(year, 80.0, on_misfit="drop", booms=BOOMS, latitude=53.3,
                    roughness_length=0.05, cup_calibrations=certificates)
    table = site.summary().cup_calibrations
    assert (table["source"] == "certificate").all() and len(table) == 6
    assert "cup calibrations applied" in str(site.summary())
