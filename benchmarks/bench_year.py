"""A year of per-record atmospheres: the study's cost against plain FLORIS runs (issue: year perf).

Hand-run script (not a test), from the repository root:
``PYTHONPATH=. python benchmarks/bench_year.py [--records 8760] [--side 10] [--repeats 3]``.

Lines, each timed interleaved with its reference in one process (each repeat runs every line
once, in turn), best of ``--repeats``; peak memory by tracemalloc

(peak memory: one more call of each line under tracemalloc, untimed);

* ``plain gauss``: FLORIS's gauss (no atmosphere, one scalar TI) over the records' conditions,
  ``run()`` once, unchunked: the reference of the ratios;
* ``gauss on the Ekman inflow``: the same model and conditions with a single atmosphere block
  (the inflow hook's cost, the 3 x 3 line of the inflow issue);
* ``annual_energy ekman_veer`` and ``annual_energy gch``: ``annual_energy`` of the records,
  each record with its own atmosphere (``records=``, one class per distinct stability), one
  vectorised FLORIS model per chunk;
* with ``--steered``: ``annual_energy(..., YawOptimizationSR)`` of ekman_veer on the records
  (one run, with its progress bar).

The records are synthetic: directions uniform, speeds 5-14 m/s at 90 m, the stability of each
record one of ``--classes`` Obukhov lengths, 100-2000 m (stable nights to near-neutral days).
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
from pathlib import Path

import numpy as np
from floris import FlorisModel, TimeSeries

import floris_ekman_veer
from floris_ekman_veer import annual_energy
from floris_ekman_veer.studies.comparison import builtin_model
from floris_ekman_veer.plugin.inflow import atmosphere_of, set_atmosphere

INPUT = Path(__file__).resolve().parents[1] / "inputs" / "farm_night.yaml"
N_CLASSES = 6


def farm(side: int) -> FlorisModel:
    fmodel = FlorisModel(INPUT)
    diameter = float(fmodel.core.farm.rotor_diameters.flat[0])
    x, y = np.meshgrid(7.0 * diameter * np.arange(side), 7.0 * diameter * np.arange(side))
    fmodel.set(layout_x=x.ravel(), layout_y=y.ravel())
    return fmodel


def records(n: int, n_classes: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    series = TimeSeries(rng.uniform(0.0, 360.0, n), rng.uniform(5.0, 14.0, n),
                        turbulence_intensities=0.06)
    return series, rng.permutation(np.arange(n) % n_classes)


def timed(function) -> float:
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


def peak_memory(function) -> int:
    """tracemalloc's peak over one call (a separate call: tracing slows the timed ones)."""
    tracemalloc.start()
    function()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--records", type=int, default=8760)
    parser.add_argument("--side", type=int, default=10)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--classes", type=int, default=N_CLASSES,
                        help="distinct atmospheres (Obukhov lengths 100-2000 m); = --records "
                             "for one per record, as fit_site gives")
    parser.add_argument("--chunk-size", type=int, default=None)
    parser.add_argument("--steered", action="store_true")
    parser.add_argument("--memory", action=argparse.BooleanOptionalAction, default=True)
    parser.add_argument("--lines", default="plain,inflow,ekman_veer,gch")
    args = parser.parse_args()
    floris_ekman_veer.silence_warnings()

    fmodel = farm(args.side)
    series, classes = records(args.records, args.classes)
    block = atmosphere_of(fmodel.core).sliced(slice(None))
    stability = {f"L={length:.6g}": {"atmosphere": dict(block, obukhov_length=float(length))}
                 for length in np.geomspace(100.0, 2000.0, args.classes)}
    names = np.array(list(stability))[classes]
    directions, speeds, _, _ = series.unpack_for_reinitialize()
    gauss = builtin_model(fmodel, "gauss")
    gauss.set(wind_directions=directions, wind_speeds=speeds,
              turbulence_intensities=np.full(speeds.size, 0.06))
    plain = gauss.copy()
    set_atmosphere(plain, None)
    options = {} if args.chunk_size is None else {"chunk_size": args.chunk_size}

    lines = {
        "plain": ("plain FLORIS gauss (reference)", plain.run),
        "inflow": ("gauss on the Ekman inflow", gauss.run),
        "ekman_veer": ("annual_energy ekman_veer, per-record atmospheres",
                       lambda: annual_energy(fmodel, series, stability, records=names,
                                             models=["ekman_veer"], **options)),
        "gch": ("annual_energy gch, per-record atmospheres",
                lambda: annual_energy(fmodel, series, stability, records=names,
                                      models=["gch"], **options)),
    }
    chosen = [k for k in args.lines.split(",") if k in lines]
    print(f"{args.records} records ({args.classes} atmospheres), {args.side} x {args.side} farm, "
          f"best of {args.repeats}, interleaved")
    best = {k: np.inf for k in chosen}
    for repeat in range(args.repeats):
        for key in chosen:
            elapsed = timed(lines[key][1])
            best[key] = min(best[key], elapsed)
            print(f"  repeat {repeat}: {key} {elapsed:.2f} s", flush=True)
    best = {k: (t, peak_memory(lines[k][1]) if args.memory else np.nan) for k, t in best.items()}
    reference = best["plain"][0] if "plain" in best else np.nan
    print(f"| line | time [s] | / plain gauss | peak memory [MB] |")
    print("|---|---:|---:|---:|")
    for key in chosen:
        elapsed, peak = best[key]
        print(f"| {lines[key][0]} | {elapsed:.2f} | {elapsed / reference:.2f} | "
              f"{peak / 1e6:.0f} |")
    if args.steered:
        from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

        start = time.perf_counter()
        result = annual_energy(fmodel, series, stability, YawOptimizationSR, records=names,
                               models=["ekman_veer"], progress=True, **options)
        elapsed = time.perf_counter() - start
        year = result.table[result.table.stability == "all"].iloc[0]
        print(f"steered year (YawOptimizationSR, ekman_veer): {elapsed:.1f} s, gain "
              f"{year.gain_percent:+.2f} %")


if __name__ == "__main__":
    main()
