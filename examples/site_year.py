"""A year of hourly mast records through the site workflow in one call
(docs/measurements.md#a-year-of-records).

Fits the SYNTHETIC year of ``tests/data/mast_year.csv.gz`` (8,760 hourly records of a 150 m mast
at 52 N with calm hours, zero readings, backing fronts, convective afternoons, stable nights and
neutral days, written by ``tests/data/generate_mast_year.py``) with ``fit_site(...,
on_misfit="drop")``, prints what was left out and why (``SiteAtmosphere.summary()``) against the
generator's truth, then runs the fitted hours through the 3 x 3 NREL 5 MW farm of
``inputs/farm_night.yaml`` as one vectorised FLORIS model (``site.apply``), and prints the times.

    python examples/site_year.py
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from floris import FlorisModel

import floris_ekman_veer

YEAR = Path(__file__).resolve().parents[1] / "tests" / "data" / "mast_year.csv.gz"
SITE = dict(latitude=52.0, roughness_length=0.05, speed_noise=0.1, direction_noise=0.5)


def main() -> None:
    records = pd.read_csv(YEAR)
    start = time.perf_counter()
    site = floris_ekman_veer.fit_site(records, 90.0, on_misfit="drop", **SITE)
    fit_seconds = time.perf_counter() - start
    cpu_seconds = time.process_time()
    summary = site.summary().exclusions
    print(f"fit_site on {len(records)} records: {fit_seconds:.1f} s ({cpu_seconds:.1f} s of CPU "
          "with the imports)")
    print(summary.drop(columns="example").to_string())
    kind = pd.Series("fitted", index=records.index, name="fit_site")
    kind[site.excluded.index] = site.excluded["kind"]
    print("\nthe generator's truth (rows) against what fit_site made of each record (columns):")
    print(pd.crosstab(records["true_kind"], kind).to_string())
    print("\none reason per kind, as fit_site writes it:")
    for name, example in summary["example"].items():
        if example:
            print(f"  {name}: {example}")

    fmodel = FlorisModel(floris_ekman_veer.example_input("farm_night"))
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", floris_ekman_veer.FlorisEkmanVeerWarning)
        site.apply(fmodel)
        fmodel.run()
    run_seconds = time.perf_counter() - start
    power = fmodel.get_farm_power()
    print(f"\nFLORIS ekman_veer on the {power.size} fitted hours (3 x 3 NREL 5 MW, one vectorised "
          f"run): {run_seconds:.1f} s; energy of those hours {np.sum(power) / 1e9:.2f} GWh "
          f"(finite: {bool(np.all(np.isfinite(power)))})")


if __name__ == "__main__":
    main()
