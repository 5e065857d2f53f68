"""A real mast's year as a site report (docs/measurements.md#a-real-mast).

Makes the SYNTHETIC year of examples/instrumented_mast_year.py (seeded: 8,760 hourly
records of a 40-80 m mast at 53.3 N with cups on two booms and their standard deviations, vanes
at 38, 58 and 78 m with offsets, mast shadow, icing, cup spikes, convective days and stable
nights), fits it with ``fit_site``'s defaults (only the site and the booms given), prints the
site report (``summary()``) and what it makes of the generator's truth (kept fraction, vane
offsets found, class confusion), writes the class mix by hour of day as a PNG, and gives the
year's energy on the 3 x 3 NREL 5 MW farm of ``inputs/farm_night.yaml`` by class and by month.

    python examples/site_report.py [--output DIR] [--periods N --freq 10min] [--no-energy]

``--periods 105120 --freq 10min`` makes two years of 10-minute records (the fit's time).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

import floris_ekman_veer

from instrumented_mast_year import BOOMS, LONGITUDE, SITE as MAST_SITE, TIME_ZONE, VANE_OFFSETS, mast_year

#: The site as its engineer knows it: onshore, its location and its stamps' time zone.
SITE = dict(MAST_SITE, site_type="onshore", longitude=LONGITUDE, time_zone=TIME_ZONE)


def arguments(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--output", type=Path, default=Path("output"),
                        help="directory for the figure (default ./output)")
    parser.add_argument("--periods", type=int, default=8760, help="records (default 8760)")
    parser.add_argument("--freq", default="h", help="their spacing (default h: hourly)")
    parser.add_argument("--no-energy", action="store_true", help="skip the annual energy")
    args = parser.parse_args(argv)
    args.output.mkdir(parents=True, exist_ok=True)
    return args


def truth_table(records: pd.DataFrame, site) -> tuple[pd.DataFrame, float, float]:
    """(the generator's classes against the fitted ones, the fraction of the generator's
    non-calm records fitted, the fraction of fitted records whose class is the generator's)."""
    truth = records["true_class"].to_numpy()[site.rows]
    table = pd.crosstab(pd.Series(truth, name="generator"),
                        pd.Series(site.stability_classes, name="fitted"))
    not_calm = ~records["true_calm"].to_numpy()
    kept = int(np.sum(not_calm[site.rows])) / int(np.sum(not_calm))
    return table, kept, float(np.mean(truth == site.stability_classes))


def main(argv=None) -> None:
    args = arguments(argv)
    records = mast_year(periods=args.periods, freq=args.freq)
    start = time.perf_counter()
    # (the farm's hub height, 10 m above the mast: the fitted profiles reach it)
    # (the cups' calibration certificates applied, as a site engineer does)
    site = floris_ekman_veer.fit_site(
        records, 90.0, on_misfit="drop", booms=BOOMS,
        cup_calibrations=records.attrs["cup_calibration_certificates"], **SITE)
    seconds = time.perf_counter() - start
    summary = site.summary()
    print(f"fit_site on {len(records):,} records: {seconds:.1f} s\n")
    print(summary)
    table, kept, matched = truth_table(records, site)
    print(f"\nagainst the generator's truth: {100 * kept:.1f} % of the non-calm records kept; "
          f"fitted class the generator's for {100 * matched:.1f} % of them")
    print(table.to_string())
    found = summary.offsets["offset_deg"]
    print("vane offsets found (given): " + ", ".join(
        f"{h:g} m {found[h]:+.2f} ({VANE_OFFSETS[h]:+.1f}) deg" for h in found.index))
    ax = summary.plot_class_by_hour()
    ax.set_title("Fitted stability class by hour of day (synthetic mast year)")
    path = args.output / "site_classes_by_hour.png"
    ax.figure.savefig(path, dpi=90, bbox_inches="tight")
    print(f"figure: {path}")
    if args.no_energy:
        return
    from floris import FlorisModel

    fmodel = FlorisModel(floris_ekman_veer.example_input("farm_night"))
    start = time.perf_counter()
    energy = site.annual_energy(fmodel)
    print(f"\nannual energy of the fitted records ({time.perf_counter() - start:.1f} s), by "
          "class:")
    print(energy.table.drop(columns=["aep_steered_gwh", "gain_percent"]).to_string(index=False))
    print("by month:")
    print(energy.by_month.drop(columns=["aep_steered_gwh", "gain_percent"]).to_string(
        index=False))


if __name__ == "__main__":
    main()
