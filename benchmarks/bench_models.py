"""Speed and peak memory of the ekman_veer models against FLORIS's GCH and gauss on the same farm,
inflow and conditions, in one process (hand-run script, not a test):

    python -m benchmarks.bench_models [--conditions 100] [--repeats 3] [--seed 1] [--profile]

Farm: 10 x 10 NREL 5 MW at 7 D (882 m), the wake settings of ``inputs/farm_sbl6.yaml`` (sosfs
combination, crespo_hernandez turbulence) and its SBL-6 atmosphere (Ekman inflow for every
model), solver ``turbine_grid`` with 3 x 3 points (the shipped setting: for ekman_veer every
point carries its rotor cell's average, docs/coupling.md#rotor-average). ``--conditions`` random
conditions (seeded): wind direction uniform in [0, 360) deg, speed at 90 m uniform in [7, 12] m/s,
turbulence intensity 0.06, and every turbine yawed uniformly in [-20, 20] deg. Models:

    gauss   FLORIS gauss velocity and deflection, no secondary steering or yaw-added recovery;
    GCH     the same with FLORIS's GCH terms on (secondary steering, transverse velocities,
            yaw-added recovery), as in FLORIS's gch.yaml;
    M-1     ekman_veer velocity and deflection (veer, curl, yaw), the shipped input;
    M-2     the same with veer off.

Timed: ``FlorisModel.run()``, best of ``--repeats`` wall times after a warm-up run, the models
interleaved (each repeat runs every model once, in turn), so that a load on the shared machine
weighs on all models alike. Peak memory:
the largest traced allocation (tracemalloc, numpy arrays included) above the level before one
``run()``, measured in a separate run. Prints a markdown table with the ratios to GCH and to
gauss. ``--profile`` adds a cProfile of M-1 (top functions by internal time).

Run from the repository root, or anywhere with the package installed.
"""

from __future__ import annotations

import argparse
import copy
import cProfile
import gc
import io
import os
import pstats
import time
import tracemalloc
from pathlib import Path

import numpy as np

REPOSITORY = Path(__file__).resolve().parent.parent
import floris_ekman_veer  # noqa: F401

from floris import FlorisModel  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

FARM_INPUT = REPOSITORY / "inputs" / "farm_sbl6.yaml"
SIDE, SPACING = 10, 7 * 126.0
MODELS = ("gauss", "GCH", "M-1", "M-2")


def configuration(model: str, side: int = SIDE) -> dict:
    """FLORIS input of one benchmarked model on the side x side farm (Ekman inflow for all)."""
    config = load_yaml(FARM_INPUT)
    x, y = np.meshgrid(np.arange(side) * SPACING, np.arange(side) * SPACING)
    config["farm"]["layout_x"] = x.ravel().tolist()
    config["farm"]["layout_y"] = y.ravel().tolist()
    wake = config["wake"]
    if model in ("gauss", "GCH"):
        # FLORIS's models on FLORIS's usual 3 x 3 turbine grid (the farm input's is M-1's).
        config["solver"] = {"type": "turbine_grid", "turbine_grid_points": 3}
        wake["model_strings"]["velocity_model"] = "gauss"
        wake["model_strings"]["deflection_model"] = "gauss"
        for flag in ("enable_secondary_steering", "enable_yaw_added_recovery",
                     "enable_transverse_velocities"):
            wake[flag] = model == "GCH"
    if model == "M-2":
        wake["wake_deflection_parameters"]["ekman_veer"]["veer"] = False
    return config


def conditions(n: int, seed: int, side: int = SIDE):
    rng = np.random.default_rng(seed)
    directions = rng.uniform(0.0, 360.0, n)
    speeds = rng.uniform(7.0, 12.0, n)
    yaw = rng.uniform(-20.0, 20.0, (n, side * side))
    return directions, speeds, yaw


def build(model: str, directions, speeds, yaw) -> FlorisModel:
    side = int(round(np.sqrt(np.shape(yaw)[1])))
    fmodel = FlorisModel(copy.deepcopy(configuration(model, side)))
    fmodel.set(wind_directions=directions, wind_speeds=speeds,
               turbulence_intensities=np.full(len(directions), 0.06), yaw_angles=yaw)
    return fmodel


def best_time(function, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def peak_memory(fmodel: FlorisModel) -> float:
    """Peak traced memory [MB] of one run() above the level before it."""
    gc.collect()
    tracemalloc.start()
    before, _ = tracemalloc.get_traced_memory()
    tracemalloc.reset_peak()
    fmodel.run()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return (peak - before) / 1e6


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--conditions", type=int, default=100)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args(argv)

    directions, speeds, yaw = conditions(args.conditions, args.seed)
    print(f"{SIDE} x {SIDE} NREL 5 MW at 7 D, {args.conditions} random conditions (seed "
          f"{args.seed}), random yaw in [-20, 20] deg, turbine_grid 3 x 3, SBL-6 Ekman inflow; "
          f"best of {args.repeats}; {os.cpu_count()} CPUs\n")
    models = {model: build(model, directions, speeds, yaw) for model in MODELS}
    for fmodel in models.values():
        fmodel.run()  # warm-up (first-call caches)
    times = dict.fromkeys(MODELS, np.inf)
    for _ in range(args.repeats):
        for model, fmodel in models.items():
            times[model] = min(times[model], best_time(fmodel.run, 1))
    memory = {model: peak_memory(fmodel) for model, fmodel in models.items()}
    farm = {model: np.mean(fmodel.get_farm_power()) / 1e6 for model, fmodel in models.items()}
    print("| model | run() [s] | / GCH | / gauss | peak memory [MB] | / GCH | mean farm power [MW] |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for model in MODELS:
        print(f"| {model} | {times[model]:.3f} | {times[model] / times['GCH']:.2f} | "
              f"{times[model] / times['gauss']:.2f} | {memory[model]:.1f} | "
              f"{memory[model] / memory['GCH']:.2f} | {farm[model]:.2f} |")

    if args.profile:
        print_profile(build("M-1", directions, speeds, yaw), 25)


def print_profile(fmodel: FlorisModel, top: int) -> None:
    """cProfile of one ``run()`` after a warm-up, the ``top`` functions by internal time."""
    fmodel.run()
    profiler = cProfile.Profile()
    profiler.enable()
    fmodel.run()
    profiler.disable()
    stream = io.StringIO()
    pstats.Stats(profiler, stream=stream).sort_stats("tottime").print_stats(top)
    print(f"\ncProfile of one run() ({fmodel.core.farm.n_turbines} turbines, "
          f"{fmodel.core.flow_field.n_findex} conditions), by internal time:")
    print(stream.getvalue())

if __name__ == "__main__":
    main()
