"""Stage 1 of the site fit (pipeline.py), from the mast's own metadata: an IEA Wind Task 43 WRA
data model file (JSON, schema v1.x; docs/measurements.md#the-masts-own-metadata).

What the file says that the fit uses: the location (``latitude_ddeg``, ``longitude_ddeg``), the
logger's offset from UTC (``logger_main_config[].offset_from_utc_hrs``), and per measurement
point of type ``wind_speed``, ``wind_direction``, ``air_temperature`` or ``air_pressure`` its
``height_m``, its boom
(``mounting_arrangement[].boom_orientation_deg``; a vane's ``vane_dead_band_orientation_deg``)
and the logger's columns with their statistics (``logger_measurement_config[].column_name[]``:
``column_name`` and ``statistic_type_id``, ``avg`` the mean, ``sd`` the standard deviation).
:func:`read_wra_file` reads them; :meth:`MastMetadata.named_records` gives the records the
column names of columns.py (cups on several booms at one height named ``b<orientation>``, e.g.
``speed_80m_b0``) with their booms, and refuses records that contradict the file (a column it
names missing, naming both the measurement point and the records' columns).

A cup's calibration certificate is read where the file gives one: the last calibration of the
point's last sensor (``sensor[].calibration[]``: ``slope``, ``offset`` and
``calibration_uncertainty[]``, the ``uncertainty`` [m/s] at each ``reference_bin`` [m/s], taken
relative at the bin nearest :data:`CERTIFICATE_SPEED`), with the logger's generic transfer
function it replaces (``logger_measurement_config[].slope`` and ``offset``, the last
configuration's): ``fit_site``'s ``cup_calibrations`` (readings.py).
"""

from __future__ import annotations

import json
from pathlib import Path

import attrs
import numpy as np
import pandas as pd

#: The file's measurement types the fit reads, as the columns' quantities (temperatures and
#: pressures are stability data, stability.py: a file that names them gives them to the fit as
#: the records' ``temperature_<h>m`` / ``pressure_<h>m`` columns would).
QUANTITIES = {"wind_speed": "speed", "wind_direction": "direction",
              "air_temperature": "temperature", "air_pressure": "pressure"}
#: The file's statistics the fit reads, as the columns' suffixes ("" the mean).
STATISTICS = {"avg": "", "sd": "_std"}
#: [m/s] the certificate's uncertainty is read at its reference bin nearest this speed: the
#: strong winds of the site's neutral baseline (baseline.py).
CERTIFICATE_SPEED = 12.0


@attrs.frozen(eq=False)
class MastMetadata:
    """A mast as its Task 43 file describes it (module docstring).

    Attributes:
        latitude, longitude: [deg] of the measurement location.
        utc_offset_hours: the logger's time stamps minus UTC [h] (None: not in the file).
        columns: per logger column its name in columns.py (``speed_80m_b0``, ``speed_80m_b0_std``,
            ``direction_78m``), the measurement point's name and height.
        booms: ``{boom: orientation_deg}`` of the cups on several booms at one height.
        vane_dead_bands: ``{vane height: dead-band orientation deg}`` where the file gives it.
        cup_calibrations: ``{cup column (columns.py's name): certificate}`` of the cups whose
            calibration the file gives (module docstring), as ``fit_site``'s ``cup_calibrations``.
    """

    latitude: float
    longitude: float
    utc_offset_hours: float | None
    columns: pd.DataFrame
    booms: dict
    vane_dead_bands: dict
    cup_calibrations: dict = attrs.field(factory=dict)

    @property
    def time_zone(self) -> str | None:
        """The logger's offset from UTC as ``fit_site``'s ``time_zone`` ("+01:00"), or None."""
        if self.utc_offset_hours is None:
            return None
        minutes = int(round(abs(self.utc_offset_hours) * 60.0))
        sign = "+" if self.utc_offset_hours >= 0 else "-"
        return f"{sign}{minutes // 60:02d}:{minutes % 60:02d}"

    def named_records(self, records: pd.DataFrame) -> pd.DataFrame:
        """``records`` with the file's logger columns named as columns.py reads them; ValueError
        naming the measurement point and the records' columns where a column of the file is
        missing from the records."""
        missing = self.columns[~self.columns["column"].isin(records.columns)
                               & ~self.columns["name"].isin(records.columns)]
        if len(missing):
            row = missing.iloc[0]
            raise ValueError(
                f"fit_site: the mast's metadata file names column {row['column']!r} (measurement "
                f"point {row['point']!r} at {row['height']:g} m) that the records do not hold "
                f"(nor as {row['name']!r}); the records' columns: {list(records.columns)}. Give "
                "the records and the file of one mast")
        return records.rename(columns=dict(zip(self.columns["column"], self.columns["name"])))


def read_wra_file(path) -> MastMetadata:
    """The mast's metadata from its Task 43 WRA data model file (module docstring); ValueError
    naming what the file lacks."""
    where = Path(path)
    try:
        model = json.loads(where.read_text())
    except (OSError, json.JSONDecodeError) as error:
        raise ValueError(f"fit_site: metadata {str(path)!r} is no readable IEA Task 43 WRA data "
                         f"model JSON file ({error})") from None
    locations = model.get("measurement_location") if isinstance(model, dict) else None
    if not locations:
        raise ValueError(f"fit_site: metadata {where.name!r} has no measurement_location")
    location = locations[0]
    latitude, longitude = location.get("latitude_ddeg"), location.get("longitude_ddeg")
    if not all(isinstance(v, (int, float)) for v in (latitude, longitude)):
        raise ValueError(f"fit_site: metadata {where.name!r}: measurement_location "
                         f"{location.get('name')!r} needs latitude_ddeg and longitude_ddeg")
    offsets = {c.get("offset_from_utc_hrs") for c in location.get("logger_main_config") or []
               if c.get("offset_from_utc_hrs") is not None}
    if len(offsets) > 1:
        raise ValueError(f"fit_site: metadata {where.name!r}: the logger's configurations give "
                         f"offsets from UTC {sorted(offsets)} h; the fit takes one")
    points, certificates = [], {}
    for point in location.get("measurement_point") or []:
        quantity = QUANTITIES.get(point.get("measurement_type_id"))
        if quantity is None:
            continue
        mounting = (point.get("mounting_arrangement") or [{}])[-1]
        if quantity == "speed":
            certificate = _certificate(point, where.name)
            if certificate is not None:
                certificates[point.get("name")] = certificate
        for config in point.get("logger_measurement_config") or []:
            for column in config.get("column_name") or []:
                suffix = STATISTICS.get(column.get("statistic_type_id"))
                if suffix is None or column.get("is_ignored"):
                    continue
                points.append({"point": point.get("name"), "quantity": quantity,
                               "height": float(point["height_m"]), "suffix": suffix,
                               "boom": mounting.get("boom_orientation_deg"),
                               "dead_band": mounting.get("vane_dead_band_orientation_deg"),
                               "column": column["column_name"]})
    table = pd.DataFrame(points, columns=["point", "quantity", "height", "suffix", "boom",
                                          "dead_band", "column"])
    if not (table["quantity"] == "speed").any():
        raise ValueError(f"fit_site: metadata {where.name!r} has no wind_speed measurement point "
                         "with a logger column")
    # Cups on several booms at one height are named by their booms' orientations.
    cups = table[(table["quantity"] == "speed") & (table["suffix"] == "")]
    shared = cups.groupby("height")["point"].nunique()
    booms, names = {}, []
    for row in table.itertuples():
        name = f"{row.quantity}_{row.height:g}m"
        if row.quantity == "speed" and shared.get(row.height, 1) > 1:
            if row.boom is None or not np.isfinite(row.boom):
                raise ValueError(f"fit_site: metadata {where.name!r}: measurement point "
                                 f"{row.point!r} shares {row.height:g} m with other cups but has "
                                 "no boom_orientation_deg")
            boom = f"b{row.boom:g}".replace(".", "p").replace("-", "m")
            booms[boom] = float(row.boom)
            name += f"_{boom}"
        names.append(name + row.suffix)
    table["name"] = names
    vanes = table[(table["quantity"] == "direction") & table["dead_band"].notna()]
    means = table[(table["quantity"] == "speed") & (table["suffix"] == "")]
    calibrations = {name: certificates[point] for point, name in zip(means["point"], means["name"])
                    if point in certificates}
    return MastMetadata(
        latitude=float(latitude), longitude=float(longitude),
        utc_offset_hours=float(offsets.pop()) if offsets else None,
        columns=table[["column", "name", "point", "height"]].reset_index(drop=True),
        booms=booms, vane_dead_bands=dict(zip(vanes["height"], vanes["dead_band"].astype(float))),
        cup_calibrations=calibrations)


def _certificate(point, file_name):
    """A wind-speed point's calibration certificate with the logger's transfer function it
    replaces (module docstring), or None where the file gives no calibration; ValueError where
    it gives one but not the logger's slope and offset."""
    sensors = [s for s in point.get("sensor") or [] if s.get("calibration")]
    if not sensors:
        return None
    calibration = sensors[-1]["calibration"][-1]
    if calibration.get("slope") is None or calibration.get("offset") is None:
        return None
    logger = [c for c in point.get("logger_measurement_config") or []
              if c.get("slope") is not None and c.get("offset") is not None]
    if not logger:
        raise ValueError(f"fit_site: metadata {file_name!r}: measurement point "
                         f"{point.get('name')!r} gives its cup's calibration but not the "
                         "logger's slope and offset (logger_measurement_config), which the "
                         "certificate replaces")
    certificate = {"slope": calibration["slope"], "offset": calibration["offset"],
                   "logger_slope": logger[-1]["slope"], "logger_offset": logger[-1]["offset"]}
    bins = [(b["reference_bin"], b["uncertainty"])
            for b in calibration.get("calibration_uncertainty") or []
            if b.get("reference_bin") and b.get("uncertainty") is not None
            and b.get("reference_unit") in (None, "m/s")]
    if bins:
        speed, uncertainty = min(bins, key=lambda b: abs(b[0] - CERTIFICATE_SPEED))
        certificate["uncertainty"] = uncertainty / speed
    return certificate
