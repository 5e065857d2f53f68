"""Cost of one ``FlorisModel.run()`` against the number of turbines (hand-run study, not a test):

    python -m benchmarks.bench_scaling [--turbines 16 49 100 225 400] [--conditions 10 100]
                                       [--repeats 2] [--seed 1]

Square farms of NREL 5 MW at 7 D (4 x 4 to 20 x 20), the wake settings and SBL-6 atmosphere of
``inputs/farm_sbl6.yaml`` (Ekman inflow for every model), turbine_grid 3 x 3, random conditions as
in ``bench_models.py`` (direction uniform in [0, 360) deg, 7-12 m/s, every turbine yawed in
[-20, 20] deg; jensen and ``none`` unyawed: FLORIS's jensen takes no yaw, its ``none`` deflection
refuses it). Models: M-1, M-2 (bench_models.py), FLORIS's gauss and GCH (bench_models.py),
jensen (jensen velocity, no deflection) and FLORIS's empty model (``none`` velocity and
deflection: the solver's floor, every turbine unwaked). Per farm size the models run interleaved,
best of ``--repeats``; the table gives the seconds per run and, per model and number of
conditions, the exponent b of a least-squares fit time = a n_turbines^b.
"""

from __future__ import annotations

import argparse
import copy
import os
import sys
import time
import warnings

import numpy as np

from benchmarks.bench_models import REPOSITORY, configuration  # noqa: F401
from floris import FlorisModel

MODELS = ("M-1", "M-2", "gauss", "GCH", "jensen", "none")
SPACING = 7 * 126.0


def scaled_configuration(model: str, side: int) -> dict:
    base = "M-1" if model in ("jensen", "none") else model
    config = configuration(base)
    x, y = np.meshgrid(np.arange(side) * SPACING, np.arange(side) * SPACING)
    config["farm"]["layout_x"] = x.ravel().tolist()
    config["farm"]["layout_y"] = y.ravel().tolist()
    strings = config["wake"]["model_strings"]
    if model == "jensen":
        strings.update(velocity_model="jensen", deflection_model="none")
    elif model == "none":
        strings.update(velocity_model="none", deflection_model="none")
    return config


def build(model: str, side: int, n_conditions: int, seed: int) -> FlorisModel:
    rng = np.random.default_rng(seed)
    directions = rng.uniform(0.0, 360.0, n_conditions)
    speeds = rng.uniform(7.0, 12.0, n_conditions)
    yaw = rng.uniform(-20.0, 20.0, (n_conditions, side * side))
    if model in ("jensen", "none"):
        yaw = np.zeros_like(yaw)
    fmodel = FlorisModel(copy.deepcopy(scaled_configuration(model, side)))
    fmodel.set(wind_directions=directions, wind_speeds=speeds,
               turbulence_intensities=np.full(n_conditions, 0.06), yaw_angles=yaw)
    return fmodel


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--turbines", type=int, nargs="+", default=[16, 49, 100, 225, 400])
    parser.add_argument("--conditions", type=int, nargs="+", default=[10, 100])
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    sides = [int(round(np.sqrt(n))) for n in args.turbines]
    print(f"Square farms of NREL 5 MW at 7 D, SBL-6 Ekman inflow, turbine_grid 3 x 3; run() "
          f"[s], models interleaved, best of {args.repeats}; {os.cpu_count()} CPUs\n")
    times = {}
    for n_conditions in args.conditions:
        for side in sides:
            models = {m: build(m, side, n_conditions, args.seed) for m in MODELS}
            for fmodel in models.values():
                fmodel.run()  # warm-up
            best = dict.fromkeys(MODELS, np.inf)
            for _ in range(args.repeats):
                for model, fmodel in models.items():
                    start = time.perf_counter()
                    fmodel.run()
                    best[model] = min(best[model], time.perf_counter() - start)
            times[n_conditions, side**2] = best
            print(f"  {side**2} turbines x {n_conditions} conditions: "
                  + ", ".join(f"{m} {t:.3f}" for m, t in best.items()), file=sys.stderr,
                  flush=True)
    turbines = [s * s for s in sides]
    print("| conditions | turbines | " + " | ".join(MODELS) + " |")
    print("|---:|---:|" + "---:|" * len(MODELS))
    for n_conditions in args.conditions:
        for n in turbines:
            print(f"| {n_conditions} | {n} | "
                  + " | ".join(f"{times[n_conditions, n][m]:.3f}" for m in MODELS) + " |")
        exponents = [np.polyfit(np.log(turbines),
                                np.log([times[n_conditions, n][m] for n in turbines]), 1)[0]
                     for m in MODELS]
        print(f"| {n_conditions} | exponent b | " + " | ".join(f"{b:.2f}" for b in exponents)
              + " |")


if __name__ == "__main__":
    main()
