"""The mast's own metadata: an IEA Wind Task 43 WRA data model file (JSON, schema v1.x
structure) read by fit_site (studies/site/wra_file.py, docs/measurements.md#the-masts-own-metadata):
its columns, booms, location and logger UTC offset used; a file that contradicts the records or
the call refused naming both."""

import json

import numpy as np
import pandas as pd
import pytest

from floris_ekman_veer import fit_site
from floris_ekman_veer.studies.site.wra_file import read_wra_file

from instrumented_mast_year import mast_year


def point(name, kind, height, columns, boom=None, dead_band=None, certificate=None):
    """A measurement point; ``certificate``: a cup's calibration (fit_site's cup_calibrations
    entry) written as the schema's sensor calibration, with the logger's transfer function."""
    mounting = {"date_from": "2025-01-01T00:00:00", "boom_orientation_deg": boom}
    if dead_band is not None:
        mounting["vane_dead_band_orientation_deg"] = dead_band
    logger = (0.0458, 0.2) if certificate is None else (certificate["logger_slope"],
                                                        certificate["logger_offset"])
    out = {"name": name, "measurement_type_id": kind, "height_m": height,
           "height_reference_id": "ground_level", "mounting_arrangement": [mounting],
           "logger_measurement_config": [{
               "date_from": "2025-01-01T00:00:00", "slope": logger[0], "offset": logger[1],
               "column_name": [{"column_name": c, "statistic_type_id": s, "is_ignored": False}
                               for c, s in columns]}]}
    if certificate is not None:
        # (the certificate's uncertainty in m/s per reference bin, as the schema gives it)
        out["sensor"] = [{"oem": "cup maker", "model": "class 1", "serial_number": name,
                          "sensor_type_id": "anemometer", "calibration": [{
                              "measurement_type_id": "wind_speed", "slope": certificate["slope"],
                              "offset": certificate["offset"], "calibration_uncertainty": [
                                  {"reference_bin": v, "reference_unit": "m/s",
                                   "uncertainty": certificate["uncertainty"] * v}
                                  for v in (4.0, 8.0, 12.0, 16.0)]}]}]
    return out


def task43_file(tmp_path, heights=(80, 60, 40), latitude=53.3, certificates=None):
    """A Task 43 file of the instrumented mast: two cups per height on booms at 135 and 315 deg
    (logger names Spd_<h>mA_Avg, ..._SD), vanes at 78, 58 and 38 m (Dir_<h>m_Avg), thermometers
    at 10 and 78 m (T_<h>m_Avg); ``certificates``: the cups' calibrations by the generator's
    column names (``speed_80m_a``...)."""
    points = []
    for h in heights:
        for boom, angle in (("A", 135.0), ("B", 315.0)):
            certificate = (certificates or {}).get(f"speed_{h}m_{boom.lower()}")
            points.append(point(f"Spd_{h}m{boom}", "wind_speed", float(h),
                                [(f"Spd_{h}m{boom}_Avg", "avg"), (f"Spd_{h}m{boom}_SD", "sd"),
                                 (f"Spd_{h}m{boom}_Max", "max")], boom=angle,
                                certificate=certificate))
    for h in (78, 58, 38):
        points.append(point(f"Dir_{h}m", "wind_direction", float(h), [(f"Dir_{h}m_Avg", "avg")],
                            boom=315.0, dead_band=135.0))
    for h in (10, 78):
        points.append(point(f"T_{h}m", "air_temperature", float(h), [(f"T_{h}m_Avg", "avg")]))
    model = {"author": "test", "organisation": "floris-ekman-veer", "date": "2026-01-01",
             "version": "1.2.0-2023.01", "plant_name": "upland", "plant_type": "onshore_wind",
             "measurement_location": [{
                 "uuid": "00000000-0000-0000-0000-000000000001", "name": "M1",
                 "latitude_ddeg": latitude, "longitude_ddeg": -1.9,
                 "measurement_station_type_id": "mast",
                 "logger_main_config": [{"logger_model_name": "logger", "date_from":
                                         "2025-01-01T00:00:00", "offset_from_utc_hrs": 1.0}],
                 "measurement_point": points}]}
    path = tmp_path / "mast.json"
    path.write_text(json.dumps(model))
    return path


def logger_records(periods=400):
    """The instrumented year's first records with the logger's own column names."""
    year = mast_year(periods=periods)
    names = {"time": "time"}
    for h in (80, 60, 40):
        for boom, old in (("A", "a"), ("B", "b")):
            names[f"speed_{h}m_{old}"] = f"Spd_{h}m{boom}_Avg"
            names[f"speed_{h}m_{old}_std"] = f"Spd_{h}m{boom}_SD"
    for h in (78, 58, 38):
        names[f"direction_{h}m"] = f"Dir_{h}m_Avg"
    for h in (10, 78):
        names[f"temperature_{h}m"] = f"T_{h}m_Avg"
    return year[list(names)].rename(columns=names), year


def test_the_file_names_the_columns_booms_location_and_utc_offset(tmp_path):
    mast = read_wra_file(task43_file(tmp_path))
    assert mast.latitude == 53.3 and mast.longitude == -1.9 and mast.utc_offset_hours == 1.0
    assert mast.booms == {"b135": 135.0, "b315": 315.0}
    names = dict(zip(mast.columns["column"], mast.columns["name"]))
    assert names["Spd_80mA_Avg"] == "speed_80m_b135" and names["Spd_40mB_SD"] == "speed_40m_b315_std"
    assert names["Dir_38m_Avg"] == "direction_38m" and "Spd_80mA_Max" not in names
    assert mast.vane_dead_bands == {78.0: 135.0, 58.0: 135.0, 38.0: 135.0}


def test_fit_site_with_the_file_equals_fit_site_with_its_arguments(tmp_path):
    records, year = logger_records()
    with_file = fit_site(records, 80.0, on_misfit="drop", roughness_length=0.05,
                         metadata=task43_file(tmp_path))
    by_hand = fit_site(year, 80.0, on_misfit="drop", roughness_length=0.05, latitude=53.3,
                       booms={"a": 135.0, "b": 315.0})
    np.testing.assert_array_equal(with_file.wind_speeds, by_hand.wind_speeds)
    np.testing.assert_array_equal(with_file.turbulence_intensities, by_hand.turbulence_intensities)
    assert with_file.metadata.utc_offset_hours == 1.0
    # The file's thermometers reach the fit (the bulk Richardson datum) as the hand-given
    # temperature columns do: without them the two routes differed by up to 2 % in speed.
    assert np.any(with_file.wind_speeds != fit_site(
        year.drop(columns=["temperature_10m", "temperature_78m"]), 80.0, on_misfit="drop",
        roughness_length=0.05, latitude=53.3, booms={"a": 135.0, "b": 315.0}).wind_speeds)


def test_the_files_location_and_logger_clock_give_the_suns_bound_as_the_arguments_do(tmp_path):
    """site_type="onshore" with the file: its longitude and offset from UTC (+1 h) are the
    hand-given longitude=-1.9 and time_zone="+01:00"."""
    records, year = logger_records(240)
    with_file = fit_site(records, 80.0, on_misfit="drop", roughness_length=0.05,
                         metadata=task43_file(tmp_path), site_type="onshore")
    by_hand = fit_site(year, 80.0, on_misfit="drop", roughness_length=0.05, latitude=53.3,
                       booms={"a": 135.0, "b": 315.0}, site_type="onshore", longitude=-1.9,
                       time_zone="+01:00")
    np.testing.assert_array_equal(with_file.wind_speeds, by_hand.wind_speeds)
    np.testing.assert_array_equal(with_file.abl.obukhov_length, by_hand.abl.obukhov_length)
    with pytest.raises(ValueError, match=r"longitude=2.0 contradicts the mast's metadata file"):
        fit_site(records, 80.0, metadata=task43_file(tmp_path), longitude=2.0,
                 roughness_length=0.05)


def test_a_file_that_contradicts_the_records_or_the_call_is_refused_naming_both(tmp_path):
    records, _ = logger_records(48)
    path = task43_file(tmp_path, heights=(80, 60, 40, 20))
    with pytest.raises(ValueError, match=r"names column 'Spd_20mA_Avg' \(measurement point "
                                         r"'Spd_20mA' at 20 m\) that the records do not hold"):
        fit_site(records, 80.0, metadata=path, roughness_length=0.05)
    path = task43_file(tmp_path)
    with pytest.raises(ValueError, match=r"latitude=52.0 contradicts the mast's metadata file "
                                         r".*at 53.3 deg"):
        fit_site(records, 80.0, metadata=path, latitude=52.0, roughness_length=0.05)
    with pytest.raises(ValueError, match=r"booms=\{'a': 135.0\} contradicts .* booms are "
                                         r"\{'b135': 135.0, 'b315': 315.0\}"):
        fit_site(records, 80.0, metadata=path, booms={"a": 135.0}, roughness_length=0.05)
    broken = tmp_path / "broken.json"
    broken.write_text("{not json")
    with pytest.raises(ValueError, match=r"no readable IEA Task 43 WRA data model JSON file"):
        fit_site(records, 80.0, metadata=broken, roughness_length=0.05)


def test_the_files_cup_calibrations_are_applied_as_the_arguments_are(tmp_path):
    """The file's sensor calibrations (slope, offset, uncertainty per reference bin) with the
    logger's transfer function (logger_measurement_config's slope and offset) are the cups'
    certificates: fitted with the file, the records are fitted as with ``cup_calibrations``
    given by hand; a certificate given that contradicts the file's, or one for a cup the
    records lack, is refused naming both."""
    records, year = logger_records(96)
    certificates = year.attrs["cup_calibration_certificates"]
    path = task43_file(tmp_path, certificates=certificates)
    mast = read_wra_file(path)
    assert mast.cup_calibrations["speed_80m_b315"]["slope"] == certificates["speed_80m_b"]["slope"]
    assert mast.cup_calibrations["speed_80m_b315"]["uncertainty"] == pytest.approx(
        certificates["speed_80m_b"]["uncertainty"], rel=1e-12)
    with_file = fit_site(records, 80.0, on_misfit="drop", roughness_length=0.05, metadata=path)
    by_hand = fit_site(year, 80.0, on_misfit="drop", roughness_length=0.05, latitude=53.3,
                       booms={"a": 135.0, "b": 315.0}, cup_calibrations=certificates)
    np.testing.assert_array_equal(with_file.wind_speeds, by_hand.wind_speeds)
    assert (with_file.cup_calibrations["source"] == "certificate").all()
    uncalibrated = fit_site(year, 80.0, on_misfit="drop", roughness_length=0.05, latitude=53.3,
                            booms={"a": 135.0, "b": 315.0})
    assert np.any(uncalibrated.wind_speeds != by_hand.wind_speeds)
    changed = {**certificates["speed_80m_b"], "slope": 0.05}
    with pytest.raises(ValueError, match=r"cup_calibrations\['Spd_80mB_Avg'\] = .* contradicts "
                                         r"the mast's metadata file .* whose certificate"):
        fit_site(records, 80.0, roughness_length=0.05, metadata=path,
                 cup_calibrations={"Spd_80mB_Avg": changed})
    with pytest.raises(ValueError, match=r"cup_calibrations names cup 'speed_20m_a', which the "
                                         r"records lack"):
        fit_site(year, 80.0, roughness_length=0.05, latitude=53.3,
                 booms={"a": 135.0, "b": 315.0},
                 cup_calibrations={"speed_20m_a": certificates["speed_80m_a"]})
