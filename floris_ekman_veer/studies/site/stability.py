"""Stage 4's stability inputs (pipeline.py): what a mast tells of each record's stability beyond
its wind profile, as ``fit_site`` gives it to the fit (docs/measurements.md#reading-stability): the sun's bound on an onshore site's heat flux
(from the time stamps, the site's latitude and longitude and the stamps' time zone), the
temperatures' bulk Richardson number, a sonic anemometer's Obukhov length or heat flux, and the
measured turbulence as its departure from the site's own neutral turbulence in its sector."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from floris_ekman_veer.atmosphere.richardson import measured_richardson
from floris_ekman_veer.atmosphere.fit.stability_data import DEFAULT_STABILITY_PRIOR
from floris_ekman_veer.atmosphere.sunlight import SITE_TYPES, max_heat_flux, utc_times
from floris_ekman_veer.studies.site.baseline import NeutralBaseline

TEMPERATURE_COLUMN = re.compile(r"^temperature_(\d+(?:\.\d+)?)m$")
PRESSURE_COLUMN = re.compile(r"^pressure(?:_(\d+(?:\.\d+)?)m)?$")
#: Columns of a sonic anemometer: its Obukhov length [m], its sensible heat flux [W/m^2] and
#: (with the heat flux) its friction velocity [m/s].
SONIC_COLUMNS = ("obukhov_length", "sensible_heat_flux", "friction_velocity")
#: [K] The default error of one temperature sensor (an aspirated resistance thermometer of a
#: wind-resource mast, IEC 61400-12-1 Annex G's 0.1 K class, its pair matched to about 0.05 K).
TEMPERATURE_NOISE = 0.05
#: The noise of a sonic's 1/L relative to its value, and absolute [1/m] (the 10-minute
#: flux's sampling error, about 20 %).
SONIC_NOISE = (0.2, 0.001)
#: The relative sampling error of a 10-minute or hourly turbulence intensity, in quadrature
#: with the terrain's scatter in its sector.
TURBULENCE_SAMPLING_NOISE = 0.1
_KAPPA, _GRAVITY, _HEAT_CAPACITY = 0.41, 9.81, 1.2 * 1005.0


def checked_site_type(site_type, longitude, time_zone, inputs):
    """ValueError naming what an onshore site's sun bound needs and is not given."""
    if site_type is None:
        return
    if site_type not in SITE_TYPES:
        raise ValueError(f"fit_site: site_type must be one of {list(SITE_TYPES)} or None; got "
                         f"{site_type!r}")
    if site_type == "onshore":
        if "latitude" not in inputs:
            raise ValueError("fit_site: site_type='onshore' needs the site's latitude (the "
                             "sun's position)")
        if (isinstance(longitude, bool) or not isinstance(longitude, (int, float, np.integer, np.floating))
                or not -180.0 <= longitude <= 360.0):
            raise ValueError("fit_site: site_type='onshore' needs the site's longitude [deg, "
                             f"east positive] (the sun's position); got {longitude!r}")


def sun_bound(labels, site_type, latitude, longitude, time_zone):
    """[W/m^2] per record the heat flux the sun allows (`sunlight.max_heat_flux`), or None
    (offshore, or no site type: no bound from the sun)."""
    if site_type != "onshore":
        return None
    return max_heat_flux(utc_times(labels, time_zone), float(np.median(latitude)),
                         float(longitude))


def _column_heights(records, pattern):
    found = {}
    for column in records.columns:
        if (m := pattern.match(str(column))):
            found[float(m.group(1)) if m.group(1) else None] = column
    return found


def temperature_richardson(records, instruments):
    """``bulk_richardson=(value, noise, temperature heights, speed heights)`` of the records'
    ``temperature_<h>m`` columns [deg C] (the lowest and the highest; ``pressure_<h>m`` or
    ``pressure`` [hPa] optional: theta = T (1000/p)^0.286, else T + g z/c_p) and the cups'
    lowest and highest speeds, or None without two temperatures."""
    temperatures = _column_heights(records, TEMPERATURE_COLUMN)
    if len(temperatures) < 2:
        return None
    low, high = min(temperatures), max(temperatures)
    pressures = _column_heights(records, PRESSURE_COLUMN)
    theta = []
    for z in (low, high):
        kelvin = pd.to_numeric(records[temperatures[z]], errors="coerce").to_numpy(float) + 273.15
        column = pressures.get(z, pressures.get(None))
        if column is not None:
            pressure = pd.to_numeric(records[column], errors="coerce").to_numpy(float)
            theta.append(kelvin * (1000.0 / pressure) ** 0.286)
        else:
            theta.append(kelvin + _GRAVITY / 1005.0 * z)
    cups = instruments.cup_heights
    speeds = instruments.speeds[:, [0, -1]]
    value, noise = measured_richardson(np.stack(theta, axis=1), (low, high), speeds,
                                       TEMPERATURE_NOISE, 0.1 + 0.02 * np.abs(speeds))
    return value, np.where(np.isfinite(value), noise, 1.0), (low, high), (float(cups[0]),
                                                                       float(cups[-1]))


def sonic_inverse_length(records, instruments):
    """``inverse_obukhov_length=(value, noise)`` [1/m] of a sonic's ``obukhov_length`` column,
    or of its ``sensible_heat_flux`` with its ``friction_velocity`` (else u* of the neutral
    log law at the lowest cup, z0 0.05 m: an estimate, its error in the noise), or None."""
    if "obukhov_length" in records.columns:
        inverse = 1.0 / pd.to_numeric(records["obukhov_length"], errors="coerce").to_numpy(float)
    elif "sensible_heat_flux" in records.columns:
        heat = pd.to_numeric(records["sensible_heat_flux"], errors="coerce").to_numpy(float)
        if "friction_velocity" in records.columns:
            u_star = pd.to_numeric(records["friction_velocity"], errors="coerce").to_numpy(float)
        else:
            u_star = _KAPPA * instruments.speeds[:, 0] / np.log(instruments.cup_heights[0] / 0.05)
        with np.errstate(divide="ignore", invalid="ignore"):
            inverse = -_KAPPA * _GRAVITY * heat / (_HEAT_CAPACITY * 288.0 * u_star**3)
    else:
        return None
    relative, absolute = SONIC_NOISE
    return inverse, np.hypot(relative * np.nan_to_num(inverse), absolute)


def turbulence_departure(turbulence, baseline: NeutralBaseline):
    """(``turbulence_intensity=(height, value)``, ``turbulence_noise``): the measured TI divided
    by its sector's terrain excess turbulence of the site's neutral baseline (baseline.py: the
    median of the strong-wind records' measured TI over the model's neutral I_u), so that the
    fit reads only its departure from the site's own neutral turbulence, with a noise of the
    sampling error (:data:`TURBULENCE_SAMPLING_NOISE`) and the sectors' scatter of that ratio
    (the terrain) in quadrature."""
    height, measured = turbulence
    scatter = baseline.terrain_turbulence_scatters
    spread = float(np.nanmedian(scatter)) if np.any(np.isfinite(scatter)) else 0.2
    return ((height, measured / baseline.terrain_turbulence_ratios),
            float(np.hypot(TURBULENCE_SAMPLING_NOISE, spread)))


#: The fit's options this module gives, per record where they are arrays.
STABILITY_OPTIONS = ("max_heat_flux", "bulk_richardson", "inverse_obukhov_length")


def stability_options(fit_inputs, labels, instruments, records, site_type, longitude,
                      time_zone):
    """The fit's stability options of the site (those given in ``fit_inputs`` kept): the weak
    prior on 1/L, the sun's bound (onshore), the temperatures' bulk Richardson number and a
    sonic's 1/L, one value per record."""
    options = {"stability_prior": fit_inputs.get("stability_prior", DEFAULT_STABILITY_PRIOR)}
    cap = sun_bound(labels, site_type, fit_inputs.get("latitude"), longitude, time_zone)
    if cap is not None:
        options["max_heat_flux"] = cap
    if records is not None:
        richardson = temperature_richardson(records, instruments)
        if richardson is not None:
            options["bulk_richardson"] = richardson
        sonic = sonic_inverse_length(records, instruments)
        if sonic is not None:
            options["inverse_obukhov_length"] = sonic
    return {k: v for k, v in options.items() if k not in fit_inputs or k == "stability_prior"}


def stability_options_of(inputs, rows, n):
    """:data:`STABILITY_OPTIONS` in ``inputs`` for the records ``rows`` of ``n``."""
    chosen = {}
    for name in STABILITY_OPTIONS:
        if name not in inputs:
            continue
        value = inputs[name]
        if name == "max_heat_flux":
            chosen[name] = np.asarray(value)[rows] if np.ndim(value) == 1 else value
        else:
            chosen[name] = tuple(np.asarray(v)[rows] if np.ndim(v) == 1 and len(v) == n else v
                                 for v in value)
    return chosen
