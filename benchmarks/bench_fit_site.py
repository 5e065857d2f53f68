"""Time ``fit_site`` with the defaults on a year of records. Hand-run script, not a test:

    python -m benchmarks.bench_fit_site [n_records] [option=value ...]

Records: the SYNTHETIC year of ``tests/data/mast_year.csv.gz`` (8,760 hourly records,
docs/measurements.md#a-year-of-records); more records (e.g. 105,120, a year of 10-minute
records) repeat it with fresh noise (0.1 m/s on the speeds, 0.5 deg on the directions, seed 7)
and 5-minute time stamps. Fitted with ``fit_site(records, 90.0, latitude=52.0,
roughness_length=0.05, on_misfit="drop", **options)`` (e.g. ``stability=stable``). Printed: the
wall and CPU time of the call, the records per kind (``SiteAtmosphere.summary()``) and the
warnings it gave.
"""

import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

import floris_ekman_veer

YEAR = Path(__file__).resolve().parents[1] / "tests" / "data" / "mast_year.csv.gz"


def records(n: int) -> pd.DataFrame:
    year = pd.read_csv(YEAR)
    repeats = -(-n // len(year))
    table = pd.concat([year] * repeats, ignore_index=True).iloc[:n].copy()
    if repeats > 1:
        rng = np.random.default_rng(7)
        speed = [c for c in table.columns if c.startswith("speed_")]
        direction = [c for c in table.columns if c.startswith("direction_")]
        values = table[speed].to_numpy()
        # (a zero reading stays a zero reading)
        table[speed] = np.where(values > 0, values + rng.normal(0.0, 0.1, values.shape), values)
        table[speed] = table[speed].where(~(table[speed] <= 0), 0.0)
        table[direction] = np.mod(table[direction].to_numpy()
                                  + rng.normal(0.0, 0.5, (n, len(direction))), 360.0)
        table["time"] = pd.date_range("2025-01-01", periods=n, freq="5min").strftime(
            "%Y-%m-%d %H:%M")
    return table


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 8760
    options = dict(a.split("=", 1) for a in sys.argv[2:])
    table = records(n)
    wall, cpu = time.perf_counter(), time.process_time()
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        site = floris_ekman_veer.fit_site(table, 90.0, latitude=52.0, roughness_length=0.05,
                                          on_misfit="drop", **options)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    print(f"fit_site on {n} records {options or '(defaults)'}: {wall:.1f} s wall, {cpu:.1f} s "
          "of CPU")
    print(site.summary()["records"].to_string())
    for warning in seen:
        print(f"{warning.category.__name__}: {str(warning.message)[:120]}")


if __name__ == "__main__":
    main()
