"""The sun's bound on an onshore record's surface heat flux (docs/measurements.md#reading-stability):
the solar elevation and the clear-sky global irradiance at each time stamp (pvlib: the NREL solar
position algorithm of Reda & Andreas 2004 and the clear-sky model of Haurwitz 1945), and from
them the largest sensible heat flux a land surface can give: none while the sun is below the
horizon (a convective layer needs the ground heated), by day a fraction of the clear-sky
irradiance (`CLEAR_SKY_HEAT_FLUX_FRACTION`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

#: The largest share of the clear-sky global irradiance a land surface returns as sensible heat
#: flux. Net radiation at midday is about 0.6-0.7 of the global irradiance (Stull 1988, An
#: Introduction to Boundary Layer Meteorology, Sec. 7.6: albedo 0.1-0.25 and the net long-wave
#: loss), and the sensible heat flux at most about 0.6 of the net radiation over a dry surface
#: (Bowen ratio 1.5; over grass 0.2-0.4 of it, Stull 1988 Fig. 7.4): 0.5 bounds both, with room.
CLEAR_SKY_HEAT_FLUX_FRACTION = 0.5
#: [deg] The sun's elevation below which a record is night: the upper limb on the horizon
#: with refraction (the apparent elevation 0).
NIGHT_ELEVATION = 0.0
#: The site types ``fit_site`` knows: onshore (the sun bounds the heat flux) and offshore
#: (the sea-air temperature difference drives it, day or night: no bound from the sun).
SITE_TYPES = ("onshore", "offshore")


def utc_times(labels, time_zone):
    """The time stamps ``labels`` as a UTC DatetimeIndex: stamps that carry their offset as
    they are, naive stamps in ``time_zone`` (an IANA name such as "Europe/London" or "UTC", or
    a fixed offset such as "+01:00"); ValueError naming what is missing or wrong. The time zone
    is never guessed: naive stamps without ``time_zone`` are refused."""
    try:
        times = pd.DatetimeIndex(pd.to_datetime(pd.Series(list(labels)), errors="raise"))
    except (ValueError, TypeError) as error:
        raise ValueError(f"fit_site: site_type='onshore' needs the records' time stamps (the sun's "
                         f"position); the record names do not read as times ({error}); give a "
                         "time column or site_type='offshore' / None") from None
    if times.tz is not None:
        return times.tz_convert("UTC")
    if time_zone is None:
        raise ValueError("fit_site: site_type='onshore' needs the time zone of the records' time "
                         "stamps (time_zone='UTC', 'Europe/London', '+01:00' ...): the sun's "
                         "position depends on it and it is never guessed; or give stamps that "
                         "carry their offset")
    try:
        if isinstance(time_zone, str) and time_zone[:1] in "+-":
            hours, _, minutes = time_zone[1:].partition(":")
            offset = pd.Timedelta(hours=int(hours), minutes=int(minutes or 0))
            return (times - (offset if time_zone[0] == "+" else -offset)).tz_localize("UTC")
        return times.tz_localize(time_zone, ambiguous="NaT", nonexistent="NaT").tz_convert("UTC")
    except Exception as error:  # (pytz and zoneinfo raise several kinds)
        raise ValueError(f"fit_site: time_zone {time_zone!r} is no time zone ({error}); give an "
                         "IANA name such as 'UTC' or 'Europe/London', or an offset '+01:00'"
                         ) from None


def solar_elevation_and_clear_sky(times_utc, latitude, longitude):
    """([deg] the sun's apparent elevation, [W/m^2] the clear-sky global horizontal irradiance)
    at UTC times (pvlib: NREL SPA, Haurwitz 1945), arrays of the times' length."""
    import pvlib

    position = pvlib.solarposition.get_solarposition(pd.DatetimeIndex(times_utc),
                                                     float(latitude), float(longitude))
    zenith = position["apparent_zenith"]
    clear_sky = pvlib.clearsky.haurwitz(zenith)["ghi"].to_numpy(float)
    return position["apparent_elevation"].to_numpy(float), np.nan_to_num(clear_sky)


def max_heat_flux(times_utc, latitude, longitude,
                  fraction=CLEAR_SKY_HEAT_FLUX_FRACTION):
    """[W/m^2] per time the largest sensible heat flux of an onshore record: 0 while the sun is
    at or below :data:`NIGHT_ELEVATION` (no convective state), else ``fraction`` of the
    clear-sky global irradiance; NaN stamps (an ambiguous local hour) get no bound (inf)."""
    times_utc = pd.DatetimeIndex(times_utc)
    known = ~np.asarray(times_utc.isna())
    bound = np.full(times_utc.size, np.inf)
    if np.any(known):
        elevation, clear_sky = solar_elevation_and_clear_sky(times_utc[known], latitude,
                                                             longitude)
        bound[known] = np.where(elevation > NIGHT_ELEVATION, fraction * clear_sky, 0.0)
    return bound
