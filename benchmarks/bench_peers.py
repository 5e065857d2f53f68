"""The ekman_veer model (M-1) against FLORIS's own models and PyWake's NiayifarGaussian on the same
farms and conditions, in one process (hand-run script, not a test):

    pip install '.[peers]'    # PyWake, optional
    python -m benchmarks.bench_peers [--sides 3,10,20] [--conditions 100] [--repeats 3]
                                     [--profile] [--threads N]

Farms: side x side NREL 5 MW at 7 D, ``--conditions`` random yawed conditions (seeded as in
benchmarks/bench_models.py: direction uniform in [0, 360) deg, 7-12 m/s at 90 m, TI 0.06, every
turbine yawed uniformly in [-20, 20] deg). Contenders:

    gauss            FLORIS gauss velocity and deflection, no GCH terms (the reference);
    M-1              ekman_veer velocity and deflection (veer, curl, yaw), the shipped input
                     (the cumulative wake of Bastankhah et al. 2021, the default);
    M-1 summed       the same with ``wake_superposition: combination_model`` (the wakes summed:
                     what the cumulative default costs on top, docs/performance.md);
    empirical_gauss  FLORIS's empirical Gaussian (velocity, deflection, wake-induced mixing);
    GCH              FLORIS gauss with GCH's terms on;
    cc               FLORIS's cumulative-curl model (its own sums, gauss deflection);
    PyWake 3x3       PyWake's Niayifar_PorteAgel_2016 (NiayifarGaussianDeficit, linear sum,
                     Crespo-Hernandez) with Jimenez yaw deflection, on 3 x 3 rotor points at
                     +-R/2 (FLORIS's turbine grid);
    PyWake centre    the same at the rotor centre;
    foxes grid9      foxes's "Niayifar" (Bastankhah 2014 with k = 0.3837 TI + 0.003678, linear
                     sum) with Crespo-Hernandez added turbulence (same k, max), Jimenez
                     deflection projected on the rotor ("JimenezProj"), rotor model "grid9"
                     (3 x 3 points), partial wakes at the rotor points, numpy engine (one
                     process); foxes centre: the same at the rotor centre ("centre").

The FLORIS models run on the SBL-6 Ekman inflow of ``inputs/farm_sbl6.yaml``, FLORIS's own on its
3 x 3 turbine grid, M-1 on the input's rotor cells (the shipped 3 x 3); PyWake and foxes on a
uniform site at the same hub-height wind (their cost does not depend on the profile). PyWake's power and thrust curves are FLORIS's NREL 5 MW table; foxes's its own
NREL 5 MW table ("NREL5MW").

Timed: one run of each contender (``FlorisModel.run()``; PyWake's call with ``time=True`` and
the turbines' power read), wall (perf_counter) and CPU (process_time: all threads) per run,
the contenders interleaved (each repeat runs every contender once, in turn) so that a load on
the shared machine weighs on all alike, best of ``--repeats`` after a warm-up (farms up to
10 x 10); ratios to FLORIS gauss of the same farm. Peak memory: tracemalloc's peak above the level before one run,
measured in a separate run. Scaling: the exponent b of a least-squares fit of
CPU time = a n_turbines^b over the farms. ``--profile`` adds a cProfile of M-1 on the 10 x 10
farm on one thread (top functions by internal time). ``--quick`` (for 20 x 20 x 100): one repeat,
no warm-up, no peak-memory run. ``--threads`` sets numexpr's threads (FLORIS's gauss sums
run on them) and numba's (the package's rotor-cell kernel, plugin/rotor/rotor_kernel.py); default: each
library's own, all cores.
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import time
import tracemalloc
import warnings
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np

from benchmarks import bench_models  # the farm, the inputs and the conditions

import numba  # noqa: E402
import numexpr  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

FLORIS_CONTENDERS = ("gauss", "M-1", "M-1 summed", "empirical_gauss", "GCH", "cc")
PYWAKE_CONTENDERS = ("PyWake 3x3", "PyWake centre")
FOXES_CONTENDERS = ("foxes grid9", "foxes centre")
#: FLORIS's own models other than gauss/GCH: model strings on the farm input.
OTHER_FLORIS = {
    "empirical_gauss": dict(velocity_model="empirical_gauss", deflection_model="empirical_gauss",
                            turbulence_model="wake_induced_mixing"),
    "cc": dict(velocity_model="cc", deflection_model="gauss", turbulence_model="crespo_hernandez",
               combination_model="sosfs"),
}
#: Farms up to this side get an untimed warm-up run of every contender (larger farms come after
#: them in the process and find the caches warm).
WARM_UP_SIDE = 10


def floris_model(name: str, directions, speeds, yaw):
    """A FlorisModel of one FLORIS contender, set for the conditions."""
    if name not in OTHER_FLORIS and name != "M-1 summed":
        return bench_models.build(name, directions, speeds, yaw)
    side = int(round(np.sqrt(yaw.shape[1])))
    from floris import FlorisModel

    if name == "M-1 summed":
        config = bench_models.configuration("M-1", side)
        config["wake"]["wake_velocity_parameters"]["ekman_veer"][
            "wake_superposition"] = "combination_model"
    else:
        config = bench_models.configuration("gauss", side)
        config["wake"]["model_strings"].update(OTHER_FLORIS[name])
        # FLORIS's default parameters of the models (the farm input holds gauss's).
        defaults = FlorisModel.get_defaults()["wake"]
        for block in ("wake_velocity_parameters", "wake_deflection_parameters",
                      "wake_turbulence_parameters"):
            for model, parameters in defaults[block].items():
                config["wake"][block].setdefault(model, parameters)
    fmodel = FlorisModel(config)
    fmodel.set(wind_directions=directions, wind_speeds=speeds,
               turbulence_intensities=np.full(len(directions), 0.06), yaw_angles=yaw)
    return fmodel


def pywake_wind_farm(rotor, shear=None):
    """PyWake's Niayifar_PorteAgel_2016 (NiayifarGaussianDeficit, linear sum, Crespo-Hernandez)
    with Jimenez yaw deflection on FLORIS's NREL 5 MW table, uniform site at TI 0.06, the rotor
    average ``rotor`` (a py_wake rotor_avg_model) and ``shear`` (a py_wake shear model or None)."""
    import floris
    from py_wake.deflection_models import JimenezWakeDeflection
    from py_wake.literature.gaussian_models import Niayifar_PorteAgel_2016
    from py_wake.site import UniformSite
    from py_wake.wind_turbines import WindTurbine
    from py_wake.wind_turbines.power_ct_functions import PowerCtTabular

    table = load_yaml(Path(floris.__file__).parent / "turbine_library" / "nrel_5MW.yaml")
    table = table["power_thrust_table"]
    turbine = WindTurbine("NREL 5 MW", 126.0, 90.0, PowerCtTabular(
        table["wind_speed"], table["power"], "kW", table["thrust_coefficient"]))
    return Niayifar_PorteAgel_2016(UniformSite(ti=0.06, shear=shear), turbine,
                                   deflectionModel=JimenezWakeDeflection(), rotorAvgModel=rotor)


def floris_like_grid(n: int):
    """PyWake's GridRotorAvg on FLORIS's n x n turbine-grid points (+-R/2)."""
    from py_wake.rotor_avg_models import GridRotorAvg

    offsets = np.linspace(-0.5, 0.5, n)  # in rotor radii
    lateral, vertical = np.meshgrid(offsets, offsets)
    return GridRotorAvg(lateral.ravel(), vertical.ravel())


def pywake_model(name: str, directions, speeds, yaw):
    """A callable running PyWake's NiayifarGaussian on the same farm and conditions."""
    from py_wake.rotor_avg_models import RotorCenter

    wind_farm = pywake_wind_farm(floris_like_grid(3) if name == "PyWake 3x3" else RotorCenter())
    side = int(round(np.sqrt(yaw.shape[1])))
    x, y = np.meshgrid(np.arange(side) * bench_models.SPACING,
                       np.arange(side) * bench_models.SPACING)

    def run():
        result = wind_farm(x.ravel(), y.ravel(), wd=directions, ws=speeds, yaw=yaw.T, tilt=0,
                           time=True)
        return result.Power.values

    return run


def foxes_model(name: str, directions, speeds, yaw):
    """A callable running foxes's Niayifar model on the same farm and conditions."""
    import foxes
    import foxes.variables as FV
    import pandas as pd
    from foxes.input.farm_layout import add_grid

    book = foxes.models.ModelBook()
    yaw_setter = foxes.models.turbine_models.SetFarmVars()
    yaw_setter.add_var(FV.YAWM, np.asarray(yaw, dtype=float))
    book.turbine_models["set_yawm"] = yaw_setter
    book.wake_models["crespo_hernandez"] = foxes.models.wake_models.ti.CrespoHernandezTIWake(
        superposition="ti_max", ka=0.3837, kb=0.003678, ti_var=FV.AMB_TI)
    states = foxes.input.states.StatesTable(
        pd.DataFrame({"wd": directions, "ws": speeds}),
        output_vars=[FV.WS, FV.WD, FV.TI, FV.RHO], var2col={FV.WS: "ws", FV.WD: "wd"},
        fixed_vars={FV.RHO: 1.225, FV.TI: 0.06})
    side = int(round(np.sqrt(yaw.shape[1])))
    farm = foxes.WindFarm()
    # add_grid numbers the turbines x fastest, as the meshgrid of the other contenders.
    add_grid(farm, xy_base=[0.0, 0.0], step_vectors=[[bench_models.SPACING, 0.0],
                                                     [0.0, bench_models.SPACING]],
             steps=(side, side), turbine_models=["NREL5MW", "set_yawm", "yawm2yaw"],
             verbosity=0)
    algorithm = foxes.algorithms.Downwind(
        farm, states, wake_models=["Niayifar", "crespo_hernandez"],
        rotor_model="grid9" if name == "foxes grid9" else "centre", wake_frame="rotor_wd",
        wake_deflection="JimenezProj", partial_wakes="rotor_points", mbook=book, verbosity=0)

    def run():
        with foxes.Engine.new("numpy", verbosity=0):
            return algorithm.calc_farm()[FV.P].values

    return run


def timed(run):
    gc.collect()
    wall, cpu = time.perf_counter(), time.process_time()
    run()
    return time.perf_counter() - wall, time.process_time() - cpu


def peak_memory(run) -> float:
    """Peak traced memory [MB] of one run above the level before it."""
    gc.collect()
    tracemalloc.start()
    before, _ = tracemalloc.get_traced_memory()
    tracemalloc.reset_peak()
    run()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return (peak - before) / 1e6


def farm_table(side: int, n: int, seed: int, repeats: int, contenders, with_memory=True,
               warm_up=True):
    """Best-of wall and CPU times and peak memory of every contender on one farm."""
    directions, speeds, yaw = bench_models.conditions(n, seed, side)
    runs = {}
    for name in contenders:
        if name in FLORIS_CONTENDERS:
            runs[name] = floris_model(name, directions, speeds, yaw).run
        elif name in FOXES_CONTENDERS:
            runs[name] = foxes_model(name, directions, speeds, yaw)
        else:
            runs[name] = pywake_model(name, directions, speeds, yaw)
    if warm_up and side <= WARM_UP_SIDE:
        for run in runs.values():
            run()  # warm-up (first-call caches: the same in every farm of the process)
    best = {name: (np.inf, np.inf) for name in runs}
    for repeat in range(repeats):
        for name, run in runs.items():
            wall, cpu = timed(run)
            best[name] = (min(best[name][0], wall), min(best[name][1], cpu))
            print(f"  {side} x {side}, repeat {repeat + 1}/{repeats}: {name} {wall:.2f} s "
                  f"wall, {cpu:.2f} s CPU", file=sys.stderr, flush=True)
    memory = {name: peak_memory(run) if with_memory else np.nan for name, run in runs.items()}
    return best, memory


def exponent(turbines, seconds) -> float:
    """b of the least-squares fit seconds = a turbines^b."""
    return float(np.polyfit(np.log(turbines), np.log(seconds), 1)[0])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sides", default="3,10,20")
    parser.add_argument("--conditions", type=int, default=100)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--threads", type=int, default=None)
    everyone = FLORIS_CONTENDERS + PYWAKE_CONTENDERS + FOXES_CONTENDERS
    parser.add_argument("--contenders", default=",".join(everyone))
    parser.add_argument("--profile", action="store_true")
    parser.add_argument("--no-memory", action="store_true", help="skip the peak-memory runs")
    parser.add_argument("--quick", action="store_true",
                        help="one repeat, no warm-up, no peak-memory runs (20 x 20 x 100)")
    args = parser.parse_args(argv)
    if args.quick:
        args.repeats, args.no_memory = 1, True
    if args.threads:
        numexpr.set_num_threads(args.threads)
        numba.set_num_threads(args.threads)
    contenders = [c.strip() for c in args.contenders.split(",")]
    unknown = [c for c in contenders if c not in everyone]
    if unknown:
        parser.error(f"--contenders: unknown {unknown}; choose from {', '.join(everyone)}")
    peers = []
    for module, names in (("py_wake", PYWAKE_CONTENDERS), ("foxes", FOXES_CONTENDERS)):
        try:
            peers.append(f"{module} {version(module)}")
        except PackageNotFoundError:
            print(f"{module} is not installed (pip install '.[peers]'): left out\n")
            contenders = [c for c in contenders if c not in names]
    pywake = ", ".join(peers) or "no peer package"
    sides = [int(s) for s in args.sides.split(",")]
    load = os.getloadavg()
    print(f"NREL 5 MW farms at 7 D, {args.conditions} random yawed conditions (seed {args.seed}), "
          f"interleaved, best of {args.repeats}; {pywake}; numexpr threads "
          f"{numexpr.get_num_threads()}, numba threads {numba.get_num_threads()} of "
          f"{os.cpu_count()} CPUs; load average "
          f"{load[0]:.1f} at the start\n")
    results = {}
    print("| farm | contender | wall [s] | / gauss | CPU [s] | / gauss | peak memory [MB] |")
    print("|---|---|---:|---:|---:|---:|---:|", flush=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the SBL-6 night's shallow-layer summary
        for side in sides:
            best, memory = results[side] = farm_table(
                side, args.conditions, args.seed, args.repeats, contenders, not args.no_memory,
                not args.quick)
            for name in contenders:  # each farm's rows as soon as it is done
                wall, cpu = best[name]
                print(f"| {side} x {side} | {name} | {wall:.3f} | {wall / best['gauss'][0]:.2f}"
                      f" | {cpu:.3f} | {cpu / best['gauss'][1]:.2f} | {memory[name]:.1f} |",
                      flush=True)
    if len(sides) > 1:
        turbines = np.array(sides) ** 2
        print("\n| contender | exponent b, wall | exponent b, CPU |")
        print("|---|---:|---:|")
        for name in contenders:
            walls = [results[side][0][name][0] for side in sides]
            cpus = [results[side][0][name][1] for side in sides]
            print(f"| {name} | {exponent(turbines, walls):.2f} | {exponent(turbines, cpus):.2f} |")
    print(f"\nload average {os.getloadavg()[0]:.1f} at the end")

    if args.profile:
        # On one thread: cProfile sees the main thread only.
        numexpr.set_num_threads(1)
        numba.set_num_threads(1)
        directions, speeds, yaw = bench_models.conditions(args.conditions, args.seed, 10)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            bench_models.print_profile(floris_model("M-1", directions, speeds, yaw), 25)

if __name__ == "__main__":
    main()
