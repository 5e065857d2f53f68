"""Cost and accuracy of optimize_yaw's both-signs search against FLORIS's serial refine
(docs/yaw_steering.md#finding-the-optimum). Hand-run script, not a test:

    python -m benchmarks.bench_yaw_search [--repeats 3] [--skip-shortfall]

1. Cost: the 3 x 3 night farm (inputs/farm_night.yaml, NREL 5 MW at 7 D, -0.25 K/h), 24
   conditions (wind 255-285 deg in 12 steps x 8 and 9 m/s, TI 6 %; at 7 m/s the night's layer
   is below the rotor top), yaw -25..25 deg: FLORIS's
   YawOptimizationSR run once as FLORIS runs it (Ny_passes [5, 4]) and
   optimize_yaw(fmodel, YawOptimizationSR, search="both_signs") with the same options,
   interleaved in this process, best of ``--repeats``; with the FLORIS runs and the conditions
   they evaluated (counted in YawOptimization._calculate_farm_power), and the mean and the
   lowest per-condition farm-power gain of the both-signs optimum over FLORIS's.
2. Cost on the 3-turbine rows of the shortfall table: each row's time (interleaved, best of
   ``--repeats``), FLORIS runs and evaluated conditions, for FLORIS's run and the both-signs
   search.
3. Rebuild: the 3 x 3 night farm with an Obukhov length per condition, both signs, with the
   optimiser subsets' condition rebuild and with FLORIS's full Core rebuild per evaluation
   (plugin/floris_tools/optimizer_conditions.py ``_reinitialize_conditions``): time and bitwise comparison.
4. Shortfall: 3-turbine rows held out from the yaw study (tests/studies/yaw/test_yaw_search.py): the farm
   power of FLORIS's single run and of the both-signs search against a brute-force search on a
   1-degree grid of all three yaws refined by Nelder-Mead (the reference the tests build), for
   bounds -25..25 deg.
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np
from floris import FlorisModel
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

import floris_ekman_veer  # noqa: F401
from floris_ekman_veer import optimize_yaw
from floris_ekman_veer.plugin.inflow.inflow import atmosphere_of, set_atmosphere
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning

ROOT = Path(__file__).resolve().parents[1]
from tests.studies.yaw import test_yaw_search as reference  # the tests' brute-force reference

OPTIONS = dict(minimum_yaw_angle=-25.0, maximum_yaw_angle=25.0, Ny_passes=[5, 4])


def night_farm() -> FlorisModel:
    directions, speeds = np.meshgrid(np.linspace(255.0, 285.0, 12), [8.0, 9.0])
    fmodel = FlorisModel(ROOT / "inputs" / "farm_night.yaml")
    fmodel.set(wind_directions=directions.ravel(), wind_speeds=speeds.ravel(),
               turbulence_intensities=np.full(directions.size, 0.06))
    return fmodel


#: Counts FLORIS runs and evaluated conditions of every yaw optimiser.
counting = reference.counting_conditions


def floris_single(fmodel):
    return YawOptimizationSR(fmodel, **OPTIONS).optimize(print_progress=False)


def both_signs(fmodel):
    return optimize_yaw(fmodel, YawOptimizationSR, progress=False, **OPTIONS)


def cost(repeats: int):
    fmodel = night_farm()
    methods = {"FLORIS YawOptimizationSR, one run": floris_single,
               "optimize_yaw, both signs": both_signs}
    times = {name: [] for name in methods}
    counts, frames = {}, {}
    for _ in range(repeats):
        for name, method in methods.items():
            with counting() as count:
                start = time.perf_counter()
                frames[name] = method(fmodel)
                times[name].append(time.perf_counter() - start)
            counts[name] = dict(count)
    floris_time = min(times["FLORIS YawOptimizationSR, one run"])
    power = {name: frame["farm_power_opt"].to_numpy(float) for name, frame in frames.items()}
    print(f"cost: 3 x 3 night farm, {fmodel.core.flow_field.n_findex} conditions, -25..25 deg, "
          f"best of {repeats}, interleaved")
    floris_conditions = counts["FLORIS YawOptimizationSR, one run"]["conditions"]
    print("| search | time [s] | x FLORIS's run | FLORIS runs | evaluated conditions "
          "| x FLORIS's | farm power vs FLORIS's: mean, lowest [%] |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name in methods:
        gain = 100.0 * (power[name] / power["FLORIS YawOptimizationSR, one run"] - 1.0)
        print(f"| {name} | {min(times[name]):.2f} | {min(times[name]) / floris_time:.2f} | "
              f"{counts[name]['runs']} | {counts[name]['conditions']:,} | "
              f"{counts[name]['conditions'] / floris_conditions:.2f} | "
              f"{gain.mean():+.3f}, {gain.min():+.3f} |")
    print("times per repeat [s]: " + "; ".join(
        f"{name}: {', '.join(f'{t:.2f}' for t in values)}" for name, values in times.items()))


def cost_rows(repeats: int):
    """Item 1 on single rows: the held-out 3-turbine rows of the shortfall table, each timed
    interleaved with FLORIS's run, best of ``repeats``."""
    rows = reference.NIGHT_ROWS + reference.ROWS
    print(f"\ncost on the held-out 3-turbine rows, -25..25 deg, best of {repeats}, interleaved")
    print("| row | FLORIS's run: time [s], FLORIS runs, conditions | both signs: time [s], "
          "FLORIS runs, conditions | x FLORIS's: time, conditions |")
    print("|---|---|---|---:|")
    totals = np.zeros(4)
    for spec in rows:
        fmodel = reference.row(*spec)
        times = {"floris": [], "both": []}
        counts = {}
        for _ in range(repeats):
            for name, method in (("floris", floris_single), ("both", both_signs)):
                with counting() as count:
                    start = time.perf_counter()
                    method(fmodel)
                    times[name].append(time.perf_counter() - start)
                counts[name] = dict(count)
        best = {name: min(values) for name, values in times.items()}
        totals += [best["floris"], counts["floris"]["conditions"], best["both"],
                   counts["both"]["conditions"]]
        spacing, atmosphere, direction, speed = spec
        print(f"| {spacing} D, {atmosphere}, {direction:.0f} deg, {speed:.0f} m/s | "
              f"{best['floris']:.2f}, {counts['floris']['runs']}, "
              f"{counts['floris']['conditions']} | {best['both']:.2f}, {counts['both']['runs']}, "
              f"{counts['both']['conditions']} | {best['both'] / best['floris']:.2f}, "
              f"{counts['both']['conditions'] / counts['floris']['conditions']:.2f} |")
    print(f"| all {len(rows)} rows | {totals[0]:.2f}, {totals[1]:.0f} | {totals[2]:.2f}, "
          f"{totals[3]:.0f} | {totals[2] / totals[0]:.2f}, {totals[3] / totals[1]:.2f} |")


def rebuild(repeats: int):
    """Item 4: the evaluations' model rebuild. The 3 x 3 night farm's 24 conditions, each with
    its own Obukhov length (one row-following run), both signs, with the optimiser subsets'
    condition rebuild and with FLORIS's full Core rebuild at every evaluation, interleaved, best
    of ``repeats``; the two results compared bit for bit."""
    from floris_ekman_veer.plugin.floris_tools import optimizer_conditions as optimization

    quick = optimization._reinitialize_conditions
    full = FlorisModel._reinitialize  # bound to each subset as the condition rebuild is
    lengths = np.resize([80.0, 100.0, 150.0, 300.0, 1000.0], 24)
    fmodel = night_farm()
    inputs = dict(atmosphere_of(fmodel.core).inputs)
    inputs.pop("cooling_rate", None)  # the input's own stability, replaced by an L per condition
    atmosphere = dict(inputs, obukhov_length=list(lengths))
    set_atmosphere(fmodel, atmosphere)
    times, frames = {"condition rebuild": [], "full rebuild": []}, {}
    for _ in range(repeats):
        for name, method in (("condition rebuild", quick), ("full rebuild", full)):
            optimization._reinitialize_conditions = method
            try:
                start = time.perf_counter()
                frames[name] = both_signs(fmodel)
                times[name].append(time.perf_counter() - start)
            finally:
                optimization._reinitialize_conditions = quick
    same = all(np.array_equal(np.vstack(frames["condition rebuild"][column]),
                              np.vstack(frames["full rebuild"][column]))
               for column in ("yaw_angles_opt", "farm_power_opt", "farm_power_baseline"))
    print(f"\nrebuild per evaluation: 3 x 3 night farm, 24 conditions of 5 Obukhov lengths, both "
          f"signs, best of {repeats}, interleaved")
    print("| optimiser subsets' set() | time [s] | times per repeat [s] |")
    print("|---|---:|---|")
    for name, values in times.items():
        print(f"| {name} | {min(values):.2f} | {', '.join(f'{t:.2f}' for t in values)} |")
    print(f"condition / full: {min(times['condition rebuild']) / min(times['full rebuild']):.2f}; "
          f"yaw angles and powers bitwise equal: {same}")


def shortfall():
    rows = reference.NIGHT_ROWS + reference.ROWS
    pairs, angles, tables = reference.brute_force_tables(rows)
    print("\nshortfall against the 1-degree grid refined by Nelder-Mead, yaw -25..25 deg")
    print("| row | reference yaws [deg] | reference [kW] | FLORIS's SR: yaws, shortfall [%] "
          "| both signs: yaws, shortfall [%] |")
    print("|---|---|---:|---|---|")
    for spec, table in zip(rows, tables):
        yaw, power = reference.refined_brute_force(spec, table, pairs, angles)
        found = {}
        for name, method in (("floris", floris_single), ("both", both_signs)):
            df = method(reference.row(*spec))
            found[name] = (np.vstack(df["yaw_angles_opt"])[0], float(df["farm_power_opt"].iloc[0]))
        spacing, atmosphere, direction, speed = spec
        cells = [f"[{', '.join(f'{a:.1f}' for a in y)}], {100.0 * (1.0 - p / power):.3f}"
                 for y, p in found.values()]
        print(f"| {spacing} D, {atmosphere}, {direction:.0f} deg, {speed:.0f} m/s | "
              f"[{', '.join(f'{a:.1f}' for a in yaw)}] | {power / 1e3:,.1f} | "
              f"{cells[0]} | {cells[1]} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--skip-shortfall", action="store_true")
    args = parser.parse_args()
    warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
    cost(args.repeats)
    cost_rows(args.repeats)
    rebuild(args.repeats)
    if not args.skip_shortfall:
        shortfall()


if __name__ == "__main__":
    main()
