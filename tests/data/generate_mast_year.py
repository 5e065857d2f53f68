"""Generate tests/data/mast_year.csv.gz: a SYNTHETIC year of hourly met-mast records (8,760) with
every kind of record a real mast logs, for the site workflow's end-to-end test
(tests/studies/site/test_site_year.py, docs/measurements.md#a-year-of-records).

A 150 m mast at 52 N over grass (z0 = 0.05 m), cup anemometers and vanes at 30, 70, 110 and
150 m; the hub-height (90 m) wind speed is Weibull (k 2, scale 8.5 m/s), its direction a slow
random walk. Each record is one ``true_kind``:

* ``neutral``: a near-neutral day, the EkmanABL with Obukhov length inf or 500 to 5,000 m;
* ``stable``: a night (20:00 to 05:00), the EkmanABL with L = 30 to 400 m (a night's storm
  above 21 m/s at 90 m is neutral, L = 2,000 m: inside the physical domain);
* ``convective``: some summer afternoons (11:00 to 16:00): an unstable surface layer (Businger-
  Dyer, L = -15 to -60 m) with almost no turn of direction, a layer the model (CNBL and SBL
  only) does not have;
* ``backing``: a cold front passing: a model profile whose direction backs (turns
  anticlockwise) with height by 15 to 40 deg;
* ``calm``: speeds 0.1 to 0.7 m/s, each vane pointing anywhere;
* ``zero``: a stalled cup: one speed reads exactly 0 (and, in a few records, all four).

Plus measurement noise of 0.1 m/s and 0.5 deg (seeded) and 1 % of the values missing (NaN,
speed and direction of a height together). Speeds are rounded to 0.01 m/s and directions to
0.1 deg, so the file stays small. ``true_kind`` is the generator's truth, not a measurement.

    python tests/data/generate_mast_year.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
from floris_ekman_veer.atmosphere.ekman import EkmanABL  # noqa: E402

OUTPUT = HERE / "mast_year.csv.gz"
HEIGHTS = np.array([30.0, 70.0, 110.0, 150.0])
SITE = dict(latitude=52.0, roughness_length=0.05)
HUB_HEIGHT = 90.0
SPEED_NOISE, DIRECTION_NOISE = 0.1, 0.5  # m/s, deg
KAPPA = 0.41
SEED = 2025
#: Numbers of the rare kinds of record.
N_CALM, N_ZERO, N_ALL_ZERO, N_BACKING = 110, 25, 5, 40


def businger_dyer_speed(z, hub_speed, obukhov_length):
    """Unstable surface-layer speed u*/kappa (ln(z/z0) - psi_m(z/L)) scaled to hub_speed at
    HUB_HEIGHT (Businger-Dyer psi_m, L < 0)."""
    def shape(z):
        x = (1.0 - 16.0 * z / obukhov_length) ** 0.25
        psi = (2.0 * np.log((1.0 + x) / 2.0) + np.log((1.0 + x**2) / 2.0) - 2.0 * np.arctan(x)
               + np.pi / 2.0)
        return np.log(z / SITE["roughness_length"]) - psi

    return hub_speed * shape(z) / shape(HUB_HEIGHT)


def main(output: Path = OUTPUT) -> pd.DataFrame:
    rng = np.random.default_rng(SEED)
    time = pd.date_range("2025-01-01 00:00", periods=8760, freq="h")
    n = time.size
    hour = time.hour.to_numpy()
    hub_speed = np.clip(8.5 * rng.weibull(2.0, n), 2.0, 24.0)
    hub_direction = np.mod(250.0 + np.cumsum(rng.normal(0.0, 6.0, n)), 360.0)

    kind = np.where((hour >= 20) | (hour < 6), "stable", "neutral").astype(object)
    summer_days = rng.choice(np.arange(120, 250), 60, replace=False)
    afternoon = np.isin(time.day_of_year.to_numpy(), summer_days) & (hour >= 11) & (hour <= 16)
    kind[afternoon] = "convective"
    others = np.flatnonzero(~afternoon)
    rare = rng.choice(others, N_CALM + N_ZERO + N_ALL_ZERO + N_BACKING, replace=False)
    calm, zero = rare[:N_CALM], rare[N_CALM:N_CALM + N_ZERO]
    all_zero = rare[N_CALM + N_ZERO:N_CALM + N_ZERO + N_ALL_ZERO]
    backing = rare[N_CALM + N_ZERO + N_ALL_ZERO:]
    kind[calm] = "calm"
    kind[np.concatenate([zero, all_zero])] = "zero"
    kind[backing] = "backing"

    # Model profiles for every record (the rare kinds are made from them).
    obukhov = np.where(kind == "stable", np.exp(rng.uniform(np.log(30.0), np.log(400.0), n)),
                       np.where(rng.uniform(size=n) < 0.5, np.inf,
                                rng.uniform(500.0, 5000.0, n)))
    # A night's light wind is stable but not collapsing: at least 3 m/s where L < 60 m.
    hub_speed = np.where((kind == "stable") & (obukhov < 60.0), np.maximum(hub_speed, 3.0),
                         hub_speed)
    # A night's storm is near-neutral: above 21 m/s at 90 m a stable L of 30-400 m would imply
    # a surface cooling beyond -300 W/m^2, outside the physical domain
    # (docs/atmosphere.md#physical-domain); those records are neutral, L = 2,000 m.
    storm = (kind == "stable") & (hub_speed > 21.0)
    kind[storm] = "neutral"
    obukhov[storm] = 2000.0
    abl = EkmanABL.from_reference_wind(hub_speed, HUB_HEIGHT, obukhov_length=obukhov, **SITE)
    speeds = abl.speed(HEIGHTS[:, None]).T
    turn = abl.wind_angle(HEIGHTS[:, None]).T - abl.wind_angle(HUB_HEIGHT)[:, None]
    directions = hub_direction[:, None] - turn

    convective = np.flatnonzero(kind == "convective")
    length = -rng.uniform(15.0, 60.0, convective.size)
    speeds[convective] = businger_dyer_speed(HEIGHTS[None, :], hub_speed[convective, None],
                                             length[:, None])
    directions[convective] = hub_direction[convective, None] + rng.normal(0.0, 1.0, (convective.size, 1)) \
        * (HEIGHTS - HUB_HEIGHT) / 120.0
    back = rng.uniform(15.0, 40.0, backing.size)
    directions[backing] -= back[:, None] * (HEIGHTS - HEIGHTS[0]) / (HEIGHTS[-1] - HEIGHTS[0])
    speeds[calm] = np.sort(rng.uniform(0.1, 0.7, (calm.size, HEIGHTS.size)), axis=1)
    directions[calm] = rng.uniform(0.0, 360.0, (calm.size, HEIGHTS.size))

    speeds = speeds + rng.normal(0.0, SPEED_NOISE, speeds.shape)
    directions = directions + rng.normal(0.0, DIRECTION_NOISE, directions.shape)
    speeds[calm] = np.abs(speeds[calm]) + 0.05
    speeds[zero, rng.integers(0, HEIGHTS.size, zero.size)] = 0.0
    speeds[all_zero] = 0.0
    missing = rng.uniform(size=speeds.shape) < 0.01
    missing[np.concatenate([zero, all_zero])] = False
    speeds[missing] = np.nan
    directions[missing] = np.nan

    columns = {"time": time.strftime("%Y-%m-%d %H:%M")}
    columns |= {f"speed_{h:.0f}m": np.round(speeds[:, j], 2) for j, h in enumerate(HEIGHTS)}
    columns |= {f"direction_{h:.0f}m": np.round(np.mod(directions[:, j], 360.0), 1)
                for j, h in enumerate(HEIGHTS)}
    columns["true_kind"] = kind
    table = pd.DataFrame(columns)
    table.to_csv(output, index=False, compression={"method": "gzip", "mtime": 0})
    counts = table["true_kind"].value_counts().to_dict()
    print(f"wrote {output} ({len(table)} records: {counts})")
    return table


if __name__ == "__main__":
    main()
