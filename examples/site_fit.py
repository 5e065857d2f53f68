"""The atmosphere from a met mast: fit, FLORIS run, wake steering (docs/measurements.md).

Run it from anywhere (after ``pip install .``, or from a checkout):

    python examples/site_fit.py [--output DIR] [--with-gch]

1. Reads ``inputs/site/synthetic_mast.csv``: 24 hourly records of speed and direction at 30, 50,
   ..., 150 m: a stable night, a near-neutral morning and evening, a convective afternoon. The
   records are SYNTHETIC: profiles of the package's own EkmanABL with 0.1 m/s and 0.5 deg of noise (made by ``inputs/site/generate_synthetic_mast.py``, true inputs in its
   ``true_*`` columns), standing in for a mast or a lidar.
2. Fits every record (``floris_ekman_veer.fit_site``: ``EkmanABL.fit_profile`` in one call) at a
   site at 52 N with z0 = 0.05 m, L of either sign (``stability="either"``), and prints the
   fitted Obukhov length, stability class, hub wind and misfit against the true inputs.
3. Runs a row of three NREL 5 MW turbines at 7 D along 270 deg (the turbines, solver and wake
   models of ``inputs/farm_sbl6.yaml``) on the 24 records, each with its fitted atmosphere (one FLORIS
   TimeSeries run), and gives the annual energy of that climate with and without wake steering
   (``floris_ekman_veer.annual_energy``: FLORIS's YawOptimizationSR per record); with
   ``--with-gch`` also for FLORIS's GCH on the same inflow; the year and its parts by fitted
   stability class (convective, neutral, stable: ``ProfileFit.stability_class``).
4. Writes the figure of measured vs fitted profiles and the FLORIS input with the per-record
   atmosphere block (PNG and YAML to DIR, default ./output).

``run_example(reduced=True)`` is the same on four records (tests/studies/site/test_site.py).
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

REPOSITORY = Path(__file__).resolve().parent.parent
import floris_ekman_veer  # noqa: F401  (registers the models and the Ekman inflow hook)

import pandas as pd  # noqa: E402
import yaml  # noqa: E402
from floris import FlorisModel  # noqa: E402
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

from floris_ekman_veer import fit_site  # noqa: E402

MAST = REPOSITORY / "inputs" / "site" / "synthetic_mast.csv"
FARM_INPUT = REPOSITORY / "inputs" / "farm_sbl6.yaml"
# Site and study settings (inputs, not results).
SITE = dict(latitude=52.0, roughness_length=0.05)
NOISE = dict(speed_noise=0.1, direction_noise=0.5)     # the instruments' noise [m/s], [deg]
HUB_HEIGHT = 90.0                                      # FLORIS's reference wind height [m]
SPACING = 7.0 * 126.0                                  # row spacing [m]
YAW = dict(minimum_yaw_angle=-25.0, maximum_yaw_angle=25.0, Ny_passes=[5, 4])
SHOWN = ("2026-06-01 04:00", "2026-06-01 12:00", "2026-06-01 21:00")  # records in the figure


def run_example(reduced: bool = False, models=("ekman_veer",)) -> dict:
    records = pd.read_csv(MAST, comment="#")
    if reduced:
        records = records.iloc[[3, 12, 21, 23]].reset_index(drop=True)
    start = time.perf_counter()
    site = fit_site(records, HUB_HEIGHT, stability_input="obukhov_length", stability="either",
                    **NOISE, **SITE)
    fit_seconds = time.perf_counter() - start
    fit = site.profile_fit
    table = pd.DataFrame({
        "time": site.labels,
        "L_fit_m": fit.obukhov_length, "L_true_m": records["true_obukhov_length"],
        "class": fit.stability_class,
        "hub_speed_fit": site.wind_speeds, "hub_speed_true": records["true_hub_speed"],
        "hub_direction_fit": site.wind_directions,
        "hub_direction_true": records["true_hub_direction"],
        "veer_rotor_deg": np.asarray(site.abl.wind_direction_change(27.0, 153.0)),
        "h_m": fit.boundary_layer_height, "misfit": fit.misfit,
    })
    # The input a YAML file would hold (write_input); site.apply(fmodel) sets the same on a
    # model built otherwise.
    fmodel = FlorisModel(floris_input(site))
    fmodel.run()
    table["farm_power_kw"] = fmodel.get_farm_power() / 1e3
    with warnings.catch_warnings():
        # Records with a boundary layer shallower than the rotor are reported by the model build
        # (site.apply); the optimiser's re-builds would repeat it.
        warnings.simplefilter("ignore")
        energy = site.annual_energy(fmodel, YawOptimizationSR, models=models,
                                    progress=False, **YAW)
    return dict(site=site, table=table, energy=energy, fmodel=fmodel, fit_seconds=fit_seconds,
                by_class=energy_by_class(energy.table))


def energy_by_class(energy) -> pd.DataFrame:
    """The annual energy per model and fitted stability class (convective, neutral, stable), as
    ``annual_energy`` of a fitted site gives it, with the hours a year of each class (365 per
    record) and the steering gain of that part of the year."""
    by_class = energy[energy["stability"] != "all"].rename(columns={"stability": "fitted_class"})
    by_class = by_class.assign(hours=by_class["n_conditions"] * 365)
    order = {"convective": 0, "neutral": 1, "stable": 2}
    return by_class[["model", "fitted_class", "aep_baseline_gwh", "aep_steered_gwh", "hours",
                     "gain_percent"]].sort_values(
        ["model", "fitted_class"], key=lambda c: c.map(order) if c.name == "fitted_class" else c)


def plot_profiles(site, output: Path) -> Path:
    import matplotlib.pyplot as plt

    fit = site.profile_fit
    z = np.linspace(10.0, 200.0, 96)
    speed, direction = fit.speed(z), fit.direction(z)
    fig, (ax_s, ax_d) = plt.subplots(1, 2, figsize=(9.0, 4.8), sharey=True)
    for label in [s for s in SHOWN if s in site.labels] or site.labels[:3]:
        i = site.labels.index(label)
        line, = ax_s.plot(speed[i], z, label=f"{label} fit (L = {fit.obukhov_length[i]:.0f} m)")
        ax_s.plot(fit.speeds[i], fit.heights[i], "o", color=line.get_color())
        ax_d.plot(direction[i], z, color=line.get_color())
        ax_d.plot(fit.directions[i], fit.heights[i], "o", color=line.get_color())
    ax_s.set_xlabel("wind speed [m/s]")
    ax_d.set_xlabel("wind direction [deg]")
    ax_s.set_ylabel("height [m]")
    ax_s.legend(fontsize=7, title="synthetic mast (dots), fit (lines)", title_fontsize=7,
                loc="lower right")
    fig.suptitle("Ekman-surface-layer fit to synthetic mast records (52 N, z0 = 0.05 m)")
    fig.tight_layout()
    path = output / "site_fit_profiles.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def floris_input(site) -> dict:
    """The FLORIS input of the run: the farm input, the row, the records as conditions and the
    per-record atmosphere block (plain lists: YAML-safe)."""
    config = load_yaml(FARM_INPUT)
    config["name"] = "site_fit"
    config["description"] = ("3 NREL 5MW in a row at 7 D, synthetic mast records with their "
                             "fitted atmospheres, ekman_veer wake model")
    config["farm"]["layout_x"] = [0.0, SPACING, 2.0 * SPACING]
    config["farm"]["layout_y"] = [0.0, 0.0, 0.0]
    config["flow_field"].update(
        wind_directions=site.wind_directions.tolist(), wind_speeds=site.wind_speeds.tolist(),
        turbulence_intensities=site.turbulence_intensities.tolist(),
        reference_wind_height=site.reference_height,
    )
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"] = site.atmosphere
    return config


def write_input(site, output: Path) -> Path:
    path = output / "site_fit_input.yaml"
    path.write_text(yaml.safe_dump(floris_input(site), sort_keys=False))
    return path


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=Path("output"))
    parser.add_argument("--with-gch", action="store_true",
                        help="also FLORIS's GCH on the same inflow (doubles the run time)")
    args = parser.parse_args(argv)
    args.output.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    result = run_example(models=("ekman_veer", "gch") if args.with_gch else ("ekman_veer",))
    pd.set_option("display.width", 200)
    print(f"fitted {len(result['table'])} records in {result['fit_seconds']:.2f} s\n")
    print(result["table"].round(3).to_string(index=False))
    year = result["energy"].table
    print("\nannual energy of the 24-record climate, 3 x NREL 5 MW at 7 D:")
    print(year[year["stability"] == "all"][["model", "aep_baseline_gwh", "aep_steered_gwh",
                                             "gain_percent"]].round(4).to_string(index=False))
    print("\nthe same by fitted stability class (hours a year: 365 per record of the class):")
    print(result["by_class"].round(4).to_string(index=False))
    print(f"\nwrote {plot_profiles(result['site'], args.output)}")
    print(f"wrote {write_input(result['site'], args.output)}")
    print(f"total {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
