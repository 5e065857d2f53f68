"""A SYNTHETIC year of met-mast records with the effects of real instruments, seeded
(docs/measurements.md#a-real-mast): the year examples/site_report.py fits and the fixture of
tests/studies/site/test_mast_instruments.py.

The mast is the usual one of a wind-resource campaign (IEC 61400-12-1 Annex G; the IEA Wind
Task 43 data model's measurement points): cup anemometers on two booms at 40, 60 and 80 m, one
boom pointing to 135 deg and one to 315 deg (:data:`BOOMS`), each cup logging its mean speed
and its standard deviation (``speed_<h>m_<boom>`` and ``speed_<h>m_<boom>_std``), and wind vanes
a few metres lower, at 38, 58 and 78 m (``direction_<h>m``), and temperatures at 10 and 78 m
(``temperature_<h>m`` [deg C]). The site: onshore, 53.3 N 1.8 W, its time stamps in UTC
(:data:`SITE`, :data:`LONGITUDE`, :data:`TIME_ZONE`), the roughness length varying by
direction sector (:data:`SECTOR_ROUGHNESS`, 12 sectors of 30 deg: ``true_roughness_length``),
and the turbulence of the terrain :data:`TERRAIN_TURBULENCE` = 1.2 times the model's (hills and
hedges upwind: the measured TI 20 % above the model's neutral I_u). Hourly by default;
``freq="10min", periods=105120`` gives two years of 10-minute means.

The atmosphere of each record is the package's own EkmanABL (``from_reference_wind`` at 80 m),
in one of three classes (``true_class``) with their Obukhov length (``true_obukhov_length``),
inside the atmosphere's physical domain: where the drawn L would imply a heat flux beyond
:data:`MAX_HEAT_FLUX` (with u* of the neutral log law) |L| is enlarged to meet it, and a record
whose |L| then exceeds 500 m is neutral (the fit's class convention):

* ``stable``: nights (the sun below the horizon, pvlib's solar position) with an 80 m wind
  below 11 m/s, L = 20 to 200 m (log-uniform; at least 4 m/s where L < 60 m: a night's light
  wind is stable, not collapsing);
* ``convective``: sunny days with the sun at least 10 deg high (a day is sunny with
  probability 0.75 in summer and 0.2 in winter) with an 80 m wind below 11 m/s, L = -10 to
  -150 m (log-uniform), the heat flux at most :data:`SUN_HEAT_FLUX_FRACTION` of the clear-sky
  irradiance (a winter day's convection is weak);
* ``neutral``: every other record (cloudy days, transitions, and every wind from 11 m/s up,
  mechanically mixed), L infinite or |L| = 3 to 20 km, either sign.

The 80 m wind speed is Weibull (k 2, scale 8 m/s) with hour-to-hour persistence (an AR(1)
Gaussian copula, correlation 0.9 per hour), its direction a random walk (6 deg per hour);
``calm`` records (every true speed below 1 m/s) are marked in ``true_calm``.

The instruments, each effect seeded and recorded (module constants):

* cups: calibration bias per cup (0.5 % standard deviation), 1 % + 0.05 m/s random error per
  record, rounded to 0.01 m/s; the cup in the mast's wake (the wind from the boom's
  orientation + 180 deg) reads low by up to 25 % (a Gaussian deficit 12 deg wide, IEC
  61400-12-1 Annex G's lattice-mast wake) and its standard deviation is raised;
* calibration certificates: each cup's own (``table.attrs["cup_calibration_certificates"]``,
  as ``fit_site``'s ``cup_calibrations`` takes them): the logger's generic transfer function
  :data:`LOGGER_TRANSFER` (slope per Hz, offset) divided by the cup's drawn calibration, off by
  the certificate's own error (:data:`CERTIFICATE_ERROR`, relative, standard: the part that
  differs between cups calibrated in one accredited tunnel, MEASNET's repeatability; drawn from
  a second stream of the seed, so the records are those without certificates), which each
  certificate states as its uncertainty;
* spikes: :data:`SPIKE_FRACTION` of the cup readings jump up by 3 to 10 m/s (logger noise);
* standard deviations: the model's I_u at the cup's height times its speed, times the
  terrain's :data:`TERRAIN_TURBULENCE`, with a 10 % sampling error (log-normal);
* temperatures: at :data:`TEMPERATURE_HEIGHTS`, on a seasonal and daily cycle, their
  potential temperature difference that whose bulk Richardson number with the record's own
  40-80 m speed difference is the Businger-Dyer one of its L (Paulson 1970's psi_h and psi_m,
  the fit's forms), each sensor with a 0.05 K error, rounded to 0.01 K;
* vanes: offsets :data:`VANE_OFFSETS` (the reading minus the true direction; the 78 m vane is
  aligned), 1 deg random error, rounded to 0.1 deg;
* icing: :data:`N_ICING` winter nights on which one vane sticks at its last reading for 6 to
  36 hours (``true_stuck_<h>m``: the vane at h m is stuck);
* missing values: 0.5 % of each column NaN.

    python examples/instrumented_mast_year.py   # prints what it makes
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.atmosphere.richardson import model_richardson_number, psi_m
from floris_ekman_veer.atmosphere.sunlight import solar_elevation_and_clear_sky

SEED = 2026
SITE = dict(latitude=53.3)
LONGITUDE = -1.8
#: The time zone of the time stamps.
TIME_ZONE = "UTC"
#: Roughness length [m] per 30 deg sector, sectors centred on 0, 30, ..., 330 deg.
SECTOR_ROUGHNESS = (0.05, 0.1, 0.2, 0.3, 0.2, 0.1, 0.05, 0.03, 0.02, 0.02, 0.03, 0.05)
#: The measured turbulence over the model's I_u (terrain upwind).
TERRAIN_TURBULENCE = 1.2
#: Heights [m] of the two temperature sensors, their error [K].
TEMPERATURE_HEIGHTS = (10.0, 78.0)
TEMPERATURE_ERROR = 0.05
#: A convective record's heat flux is at most this share of the clear-sky irradiance.
SUN_HEAT_FLUX_FRACTION = 0.3
REFERENCE_HEIGHT = 80.0
CUP_HEIGHTS = (40.0, 60.0, 80.0)
VANE_HEIGHTS = (38.0, 58.0, 78.0)
#: Boom orientations [deg, clockwise from north: the direction from the mast to the cup].
BOOMS = {"a": 135.0, "b": 315.0}
#: Vane offsets [deg]: what the vane reads minus the true direction.
VANE_OFFSETS = {38.0: -4.1, 58.0: 2.6, 78.0: 0.0}
WEIBULL_SHAPE, WEIBULL_SCALE = 2.0, 8.0
#: Mast wake: deficit at its centre and its angular standard deviation [deg].
SHADOW_DEFICIT, SHADOW_WIDTH = 0.25, 12.0
CUP_BIAS, CUP_ERROR, CUP_OFFSET_ERROR = 0.005, 0.01, 0.05
VANE_ERROR = 1.0
#: The logger's generic transfer function of the cups (slope [m/s per Hz], offset [m/s]: a
#: class-1 cup's consensus one) and the certificates' relative standard error of the slope.
LOGGER_TRANSFER = (0.046, 0.2)
CERTIFICATE_ERROR = 0.0015
STD_SAMPLING_ERROR = 0.1
SPIKE_FRACTION = 0.002
N_ICING = 6
MISSING_FRACTION = 0.005
#: Sensible heat flux [W/m^2] the drawn stratification may imply (stable, convective).
MAX_HEAT_FLUX = (-150.0, 250.0)
#: Wind [m/s] at 80 m from which every record is neutral (mechanical mixing).
NEUTRAL_SPEED = 11.0


def _persistent_normal(rng, n, correlation):
    """Standard normal series with lag-one correlation ``correlation`` (AR(1))."""
    out = np.empty(n)
    out[0] = rng.normal()
    shocks = rng.normal(0.0, np.sqrt(1.0 - correlation**2), n)
    for i in range(1, n):  # (a recursion; 1e5 steps take a few tens of ms)
        out[i] = correlation * out[i - 1] + shocks[i]
    return out


def shadow_deficit(wind_direction, boom_orientation):
    """Relative speed deficit of a cup on a boom pointing to ``boom_orientation`` in the mast's
    wake: largest when the wind comes from the mast's side (``boom_orientation + 180``)."""
    off = (np.asarray(wind_direction) - boom_orientation - 180.0 + 180.0) % 360.0 - 180.0
    return SHADOW_DEFICIT * np.exp(-0.5 * (off / SHADOW_WIDTH) ** 2)


def sector_roughness(direction):
    """[m] the roughness length of the sector the wind comes from."""
    sector = np.round(np.mod(np.asarray(direction, float), 360.0) / 30.0).astype(int) % 12
    return np.asarray(SECTOR_ROUGHNESS)[sector]


def mast_year(seed: int = SEED, periods: int = 8760, freq: str = "h") -> pd.DataFrame:
    """The records (module docstring): one row per record, the instruments' columns and the
    generator's truth (``true_class``, ``true_obukhov_length``, ``true_calm``,
    ``true_stuck_<h>m``, ``true_direction_80m``, ``true_roughness_length``), in time order; each
    cup's drawn calibration factor in ``table.attrs["true_cup_calibration"]`` and its certificate
    in ``table.attrs["cup_calibration_certificates"]``."""
    rng = np.random.default_rng(seed)
    time = pd.date_range("2025-01-01 00:00", periods=periods, freq=freq)
    n = time.size
    step = (time[1] - time[0]) / pd.Timedelta("1h") if n > 1 else 1.0
    hour = (time.hour + time.minute / 60.0).to_numpy()
    doy = time.day_of_year.to_numpy()
    summer = np.cos(2.0 * np.pi * (doy - 172) / 365.0)  # 1 mid-summer, -1 mid-winter

    # The wind at 80 m: persistent Weibull speed, random-walk direction.
    z = _persistent_normal(rng, n, 0.9 ** step)
    speed = np.maximum(WEIBULL_SCALE * (-np.log(stats.norm.sf(z))) ** (1.0 / WEIBULL_SHAPE), 0.3)
    direction = np.mod(240.0 + np.cumsum(rng.normal(0.0, 6.0 * np.sqrt(step), n)), 360.0)

    # Classes: nights stable, sunny middays convective, strong winds and the rest neutral.
    elevation, clear_sky = solar_elevation_and_clear_sky(time.tz_localize(TIME_ZONE),
                                                         SITE["latitude"], LONGITUDE)
    night = elevation <= 0.0
    days = np.unique(doy)
    sunny_day = rng.uniform(size=days.size) < 0.475 + 0.275 * np.cos(2 * np.pi * (days - 172) / 365)
    sunny = sunny_day[np.searchsorted(days, doy)]
    light = speed < NEUTRAL_SPEED
    kind = np.full(n, "neutral", dtype=object)
    kind[night & light] = "stable"
    kind[sunny & (elevation >= 10.0) & light] = "convective"
    length = np.where(rng.uniform(size=n) < 0.5, np.inf,
                      rng.choice([-1.0, 1.0], n) * np.exp(rng.uniform(np.log(3e3), np.log(2e4), n)))
    stable, convective = kind == "stable", kind == "convective"
    length[stable] = np.exp(rng.uniform(np.log(20.0), np.log(200.0), stable.sum()))
    length[convective] = -np.exp(rng.uniform(np.log(10.0), np.log(150.0), convective.sum()))
    speed = np.where(stable & (length < 60.0), np.maximum(speed, 4.0), speed)
    # Inside the atmosphere's physical domain (docs/atmosphere.md#physical-domain): |L| grows
    # with the wind where the heat flux it implies (u* of the surface layer) would exceed
    # MAX_HEAT_FLUX; a strong wind's stratification is weak. The class is then that of L.
    roughness = sector_roughness(direction)
    most = np.minimum(MAX_HEAT_FLUX[1], SUN_HEAT_FLUX_FRACTION * np.maximum(clear_sky, 1.0))
    for _ in range(4):  # (u* of the Businger-Dyer surface layer of L: a few fixed-point steps)
        u_star = 0.41 * speed / (np.log(REFERENCE_HEIGHT / roughness)
                                 - psi_m(REFERENCE_HEIGHT / length))
        heat_flux = -1.2 * 1005.0 * 290.0 * u_star**3 / (0.41 * 9.81 * length)
        factor = np.clip(heat_flux / most, 1.0, None) * np.clip(
            heat_flux / MAX_HEAT_FLUX[0], 1.0, None)
        length = np.where(np.isfinite(length), length * factor, length)
    kind = np.where(np.abs(length) > 500.0, "neutral", kind).astype(object)

    abl = EkmanABL.from_reference_wind(speed, REFERENCE_HEIGHT, obukhov_length=length,
                                       roughness_length=roughness, **SITE)
    turning = abl.wind_angle(REFERENCE_HEIGHT)  # meteorological direction = const - wind_angle

    columns = {"time": time.strftime("%Y-%m-%d %H:%M")}
    calibration = {}
    for h in CUP_HEIGHTS:
        true = abl.speed(h)
        intensity = np.asarray(abl.turbulence_intensity(h), float)
        for name, orientation in BOOMS.items():
            deficit = shadow_deficit(direction, orientation)
            bias = 1.0 + rng.normal(0.0, CUP_BIAS)
            calibration[f"speed_{h:.0f}m_{name}"] = bias
            read = (true * (1.0 - deficit) * bias * (1.0 + rng.normal(0.0, CUP_ERROR, n))
                    + rng.normal(0.0, CUP_OFFSET_ERROR, n))
            spikes = rng.uniform(size=n) < SPIKE_FRACTION
            read[spikes] += rng.uniform(3.0, 10.0, spikes.sum())
            std = (TERRAIN_TURBULENCE * intensity * true * (1.0 + 3.0 * deficit)
                   * np.exp(rng.normal(0.0, STD_SAMPLING_ERROR, n)))
            columns[f"speed_{h:.0f}m_{name}"] = np.round(np.maximum(read, 0.0), 2)
            columns[f"speed_{h:.0f}m_{name}_std"] = np.round(std, 3)
    stuck = {h: np.zeros(n, dtype=bool) for h in VANE_HEIGHTS}
    vanes = {}
    for h in VANE_HEIGHTS:
        true = direction - (abl.wind_angle(h) - turning)
        vanes[h] = true + VANE_OFFSETS[h] + rng.normal(0.0, VANE_ERROR, n)
    # Icing: a winter night's vane holds its last reading for 6 to 36 hours.
    winter_nights = np.flatnonzero(night & (summer < -0.6) & (hour >= 18.0))
    for start in rng.choice(winter_nights, min(N_ICING, winter_nights.size), replace=False):
        h = VANE_HEIGHTS[rng.integers(len(VANE_HEIGHTS))]
        stop = min(n, start + int(round(rng.uniform(6.0, 36.0) / step)))
        vanes[h][start:stop] = vanes[h][start]
        stuck[h][start:stop] = True
    for h in VANE_HEIGHTS:
        columns[f"direction_{h:.0f}m"] = np.round(np.mod(vanes[h], 360.0), 1)
    # Temperatures: the rise of theta between the sensors whose bulk Richardson number with the
    # record's own 40-80 m speeds is the Businger-Dyer one of its L; T = theta - g z/c_p.
    low, high = TEMPERATURE_HEIGHTS
    surface = 9.0 + 6.0 * summer + 3.0 * np.cos(2.0 * np.pi * (hour - 14.0) / 24.0)
    shear = abl.speed(CUP_HEIGHTS[-1]) - abl.speed(CUP_HEIGHTS[0])
    richardson = model_richardson_number(1.0 / length, TEMPERATURE_HEIGHTS,
                                         (CUP_HEIGHTS[0], CUP_HEIGHTS[-1]))
    rise = richardson * shear**2 * (surface + 273.15) / (9.81 * (high - low))
    for h, theta in ((low, surface), (high, surface + rise)):
        columns[f"temperature_{h:.0f}m"] = np.round(
            theta - 9.81 / 1005.0 * h + rng.normal(0.0, TEMPERATURE_ERROR, n), 2)
    table = pd.DataFrame(columns)
    data = [c for c in table.columns if c != "time"]
    missing = rng.uniform(size=(n, len(data))) < MISSING_FRACTION
    table[data] = table[data].mask(missing)
    table["true_class"] = kind
    table["true_obukhov_length"] = length
    table["true_calm"] = np.all([abl.speed(h) < 1.0 for h in CUP_HEIGHTS], axis=0)
    for h in VANE_HEIGHTS:
        table[f"true_stuck_{h:.0f}m"] = stuck[h]
    table["true_direction_80m"] = np.mod(direction, 360.0)
    table["true_roughness_length"] = roughness
    # Each cup's drawn calibration (reading / truth): constant per cup, so kept beside the table
    # (what the cup's calibration certificate would say) rather than as a column.
    table.attrs["true_cup_calibration"] = calibration
    table.attrs["cup_calibration_certificates"] = certificates(calibration, seed)
    return table


def certificates(calibration, seed=SEED):
    """Each cup's calibration certificate (module docstring) from its drawn calibration
    (reading / truth): a logged speed v = s_L f + o_L is the truth s f + o with s = s_L / c and
    o = o_L / c, c the calibration; the certificate's own error drawn from the seed's second
    stream (``default_rng([seed, 1])``), its stated uncertainty :data:`CERTIFICATE_ERROR`."""
    rng = np.random.default_rng([seed, 1])
    slope, offset = LOGGER_TRANSFER
    out = {}
    for column, factor in calibration.items():
        certified = factor * (1.0 + rng.normal(0.0, CERTIFICATE_ERROR))
        out[column] = {"slope": slope / certified, "offset": offset / certified,
                       "logger_slope": slope, "logger_offset": offset,
                       "uncertainty": CERTIFICATE_ERROR}
    return out


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--periods", type=int, default=8760, help="number of hourly records")
    parser.add_argument("--csv", help="write the records to this CSV file (the package's "
                        "inputs/site/instrumented_mast_10_days.csv: --periods 240)")
    arguments = parser.parse_args()
    year = mast_year(periods=arguments.periods)
    if arguments.csv:
        year.to_csv(arguments.csv, index=False)
    stuck = sum(int(year[f"true_stuck_{h:.0f}m"].sum()) for h in VANE_HEIGHTS)
    print(f"{len(year)} records; classes {year['true_class'].value_counts().to_dict()}; calm "
          f"{int(year['true_calm'].sum())}; stuck vane readings {stuck}")
    print(year.head().to_string())
