"""Generate inputs/site/synthetic_mast.csv: SYNTHETIC met-mast records, made by the model itself.

One day of hourly records (24) of a 150 m mast at 52 N over grass (z0 = 0.05 m): a stable night
(Obukhov length 133 to 400 m), a near-neutral morning and evening (L = inf and 2,000 m) and a
convective afternoon, 10:00 to 16:00 (L = -40 m at 13:00 and -40 m / sin(pi (hour - 9) / 8) on
either side, -105 m at 10:00 and 16:00: surface heating, the model's convective layer of
docs/atmosphere.md#convective-boundary-layer with its default mixed-layer depth), the hub-height
(90 m) wind 5 to 11 m/s from 255 to 290 degrees. Each record's profile is the EkmanABL of those inputs
(``EkmanABL.from_reference_wind``), sampled at 30, 50, ..., 150 m, plus Gaussian measurement noise
of 0.1 m/s and 0.5 deg (seeded). The true inputs are kept in the columns ``true_*`` so that the
fit can be checked against them; they are not measurements.

    python inputs/site/generate_synthetic_mast.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))
from floris_ekman_veer.atmosphere.ekman import EkmanABL  # noqa: E402

OUTPUT = HERE / "synthetic_mast.csv"
HEIGHTS = np.arange(30.0, 151.0, 20.0)
SITE = dict(latitude=52.0, roughness_length=0.05)
HUB_HEIGHT = 90.0
SPEED_NOISE, DIRECTION_NOISE = 0.1, 0.5  # m/s, deg
SEED = 2026


def true_records() -> pd.DataFrame:
    hours = np.arange(24)
    night = (hours < 6) | (hours >= 19)
    # Stability deepest before dawn (L = 133 m at 04:00), weaker towards dusk and dawn.
    depth = np.clip(np.cos((hours - 4) / 24 * 2 * np.pi), 0.0, 1.0)
    obukhov = np.where(night, 400.0 / (1.0 + 2.0 * depth), np.inf)
    obukhov[(hours == 8) | (hours == 17)] = 2000.0
    afternoon = (hours >= 10) & (hours <= 16)
    obukhov[afternoon] = -40.0 / np.sin(np.pi * (hours[afternoon] - 9) / 8.0)
    hub_speed = 8.0 + 3.0 * np.sin((hours - 10) / 24 * 2 * np.pi)
    hub_direction = 272.0 + 15.0 * np.sin((hours - 2) / 24 * 2 * np.pi)
    time = pd.date_range("2026-06-01 00:00", periods=24, freq="h")
    return pd.DataFrame({"time": time.strftime("%Y-%m-%d %H:%M"), "true_obukhov_length": obukhov,
                         "true_hub_speed": hub_speed, "true_hub_direction": hub_direction})


def main() -> None:
    truth = true_records()
    abl = EkmanABL.from_reference_wind(truth["true_hub_speed"].to_numpy(), HUB_HEIGHT,
                                       obukhov_length=truth["true_obukhov_length"].to_numpy(),
                                       **SITE)
    speeds = abl.speed(HEIGHTS[:, None]).T
    # Meteorological direction: the hub direction, turning with the model's veer.
    angle = abl.wind_angle(HEIGHTS[:, None]).T - abl.wind_angle(HUB_HEIGHT)[:, None]
    directions = truth["true_hub_direction"].to_numpy()[:, None] - angle
    rng = np.random.default_rng(SEED)
    speeds = speeds + rng.normal(0.0, SPEED_NOISE, speeds.shape)
    directions = np.mod(directions + rng.normal(0.0, DIRECTION_NOISE, directions.shape), 360.0)
    columns = {f"speed_{h:.0f}m": np.round(speeds[:, j], 3) for j, h in enumerate(HEIGHTS)}
    columns |= {f"direction_{h:.0f}m": np.round(directions[:, j], 2) for j, h in enumerate(HEIGHTS)}
    table = pd.concat([truth[["time"]], pd.DataFrame(columns), truth.drop(columns="time")], axis=1)
    with open(OUTPUT, "w") as file:
        file.write(
            "# SYNTHETIC met-mast records, not measurements: profiles of the floris-ekman-veer\n"
            "# EkmanABL model (latitude 52, z0 0.05 m; stable night, convective afternoon) plus\n"
            "# noise of 0.1 m/s and 0.5 deg, made by\n"
            "# inputs/site/generate_synthetic_mast.py; true_* columns are the model inputs.\n"
        )
        table.to_csv(file, index=False)
    print(f"wrote {OUTPUT} ({len(table)} records)")


if __name__ == "__main__":
    main()
