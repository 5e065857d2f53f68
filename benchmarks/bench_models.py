"""Speed of the ekman_veer models relative to FLORIS's own gauss model, on the same farm and
conditions, in one run (hand-run script, not a test):

    python benchmarks/bench_models.py [--conditions 200] [--repeats 3] [--profile]

Farm: 10 x 10 NREL 5 MW at 7 D (882 m), solver turbine_grid with 3 x 3 rotor points, the wake
settings of ``inputs/farm_sbl6.yaml`` (sosfs combination, crespo_hernandez turbulence, no secondary
steering, no yaw-added recovery). Models:

    (a) FLORIS gauss velocity + deflection, power-law inflow (wind_shear 0.12), no atmosphere;
    (b) the same gauss on the Ekman inflow (the atmosphere block of inputs/farm_sbl6.yaml);
    (c) ekman_veer velocity + deflection (M-1) on that inflow.

Timed: ``FlorisModel.run()`` (best of ``--repeats`` wall times, at least 10 for the single
condition; conditions set beforehand: the ABL is solved and cached when the model is built), for
a wind rose of ``--conditions`` conditions
(directions every 360/(n/5) deg x speeds 8, 9, 10, 11, 12 m/s at 90 m, TI 0.06) and for one
condition (270 deg, 9 m/s); and ``calculate_horizontal_plane`` at hub height (200 x 200 points,
one condition). Prints a markdown table of times and the ratios (b)/(a), (c)/(a). ``--profile``
adds a cProfile of (c) on the wind rose (top functions by internal time).

Run from the repository root, or anywhere with the package installed.
"""

from __future__ import annotations

import argparse
import copy
import cProfile
import io
import os
import pstats
import sys
import time
from pathlib import Path

import numpy as np

REPOSITORY = Path(__file__).resolve().parent.parent
try:
    import floris_ekman_veer  # noqa: F401
except ImportError:
    sys.path.insert(0, str(REPOSITORY))
    import floris_ekman_veer  # noqa: F401

from floris import FlorisModel  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

FARM_INPUT = REPOSITORY / "inputs" / "farm_sbl6.yaml"
SIDE, SPACING = 10, 7 * 126.0
SPEEDS = (8.0, 9.0, 10.0, 11.0, 12.0)  # at 90 m; the SBL-6 ABL is deeper than the hub for all


def configuration(variant: str) -> dict:
    """FLORIS input of variant 'a' (gauss, power law), 'b' (gauss, Ekman) or 'c' (ekman_veer)."""
    config = load_yaml(FARM_INPUT)
    x, y = np.meshgrid(np.arange(SIDE) * SPACING, np.arange(SIDE) * SPACING)
    config["farm"]["layout_x"] = x.ravel().tolist()
    config["farm"]["layout_y"] = y.ravel().tolist()
    config["solver"] = {"type": "turbine_grid", "turbine_grid_points": 3}
    wake = config["wake"]
    if variant in "ab":
        wake["model_strings"]["velocity_model"] = "gauss"
        wake["model_strings"]["deflection_model"] = "gauss"
    if variant == "a":
        del wake["wake_velocity_parameters"]["ekman_veer"]
        config["flow_field"]["wind_shear"] = 0.12
    return config


def conditions(n: int):
    per_speed = max(n // len(SPEEDS), 1)
    directions = np.arange(per_speed) * 360.0 / per_speed
    wd, ws = np.meshgrid(directions, SPEEDS)
    return wd.ravel(), ws.ravel()


def best_time(function, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def build(variant: str, wd, ws) -> FlorisModel:
    fmodel = FlorisModel(copy.deepcopy(configuration(variant)))
    fmodel.set(wind_directions=wd, wind_speeds=ws, turbulence_intensities=np.full(len(wd), 0.06))
    return fmodel


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--conditions", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args(argv)

    wd, ws = conditions(args.conditions)
    cases = {
        f"{len(wd)} conditions x {SIDE * SIDE} turbines, run()": (wd, ws, "run"),
        f"1 condition x {SIDE * SIDE} turbines, run()": (np.array([270.0]), np.array([9.0]),
                                                         "run"),
        "horizontal plane 200 x 200, 1 condition": (np.array([270.0]), np.array([9.0]),
                                                   "plane"),
    }
    print(f"FLORIS wake-model benchmark: {SIDE} x {SIDE} NREL 5 MW at 7 D, turbine_grid 3 x 3, "
          f"best of {args.repeats} (single-condition run(): of {max(args.repeats, 10)}); "
          f"{os.cpu_count()} CPUs\n")
    rows = []
    for label, (directions, speeds, kind) in cases.items():
        times = {}
        for variant in "abc":
            fmodel = build(variant, directions, speeds)
            if kind == "run":
                fmodel.run()  # warm-up (first-call caches)
                # Sub-second runs are noisy on a shared machine: take more of them.
                repeats = args.repeats if len(directions) > 1 else max(args.repeats, 10)
                times[variant] = best_time(fmodel.run, repeats)
            else:
                def plane(fmodel=fmodel):
                    fmodel.calculate_horizontal_plane(height=90.0, x_resolution=200,
                                                      y_resolution=200)
                times[variant] = best_time(plane, args.repeats)
        rows.append((label, times))

    print("| case | (a) gauss, power law [s] | (b) gauss, Ekman inflow [s] | "
          "(c) ekman_veer [s] | (b)/(a) | (c)/(a) |")
    print("|---|---:|---:|---:|---:|---:|")
    for label, t in rows:
        print(f"| {label} | {t['a']:.3f} | {t['b']:.3f} | {t['c']:.3f} | "
              f"{t['b'] / t['a']:.2f} | {t['c'] / t['a']:.2f} |")

    if args.profile:
        fmodel = build("c", wd, ws)
        fmodel.run()
        profiler = cProfile.Profile()
        profiler.enable()
        fmodel.run()
        profiler.disable()
        stream = io.StringIO()
        stats = pstats.Stats(profiler, stream=stream)
        stats.sort_stats("tottime").print_stats(25)
        print(f"\ncProfile of (c) ekman_veer, {len(wd)} conditions x {SIDE * SIDE} turbines, "
              "one run(), by internal time:")
        print(stream.getvalue())


if __name__ == "__main__":
    main()
