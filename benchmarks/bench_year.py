"""A year of per-record atmospheres: the study's cost against plain FLORIS runs (issue: year perf).

Hand-run script (not a test), from the repository root, e.g.
``python -m benchmarks.bench_year --side 3 --records 8760 --repeats 3``,
``... --lines ekman_veer,gch --records 52560``, or a steered year
``... --lines none --steered 96 --steered-chunk 24 --dask-workers 2``.

Lines (``--lines``, comma-separated; default all but the steered run), each timed interleaved
with the others in one process (each repeat runs every line once, in turn), best of
``--repeats``; peak memory by tracemalloc (one more call of each line under tracemalloc, untimed,
as tracing slows the timed ones) and the process's peak resident memory at the end:

* ``plain``: FLORIS's gauss (no atmosphere, one scalar TI) over the records' conditions,
  ``run()`` once, unchunked: the reference of the ratios;
* ``inflow``: the same gauss model and conditions on the Ekman inflow of a single atmosphere (the
  inflow hook's cost);
* ``plain_gch``: FLORIS's GCH (no atmosphere), ``run()`` once: GCH's own cost against gauss;
* ``gch_one``: that GCH model on the Ekman inflow of a single atmosphere;
* ``ekman_veer_one``: the ekman_veer model on the records' conditions with a single atmosphere,
  ``run()`` once;
* ``ekman_veer`` and ``gch``: ``annual_energy`` of the records, each record with the atmosphere
  of its stability class (``records=``; ``--classes`` distinct atmospheres, = ``--records`` for
  one per record as ``fit_site`` gives), one vectorised FLORIS model per chunk of
  ``--chunk-size`` conditions.

The AEP lines are reported against plain gauss and against the same model on one atmosphere
(``ekman_veer_one``, ``gch_one``; GCH itself costs more than gauss, so its ratio to gauss mixes the
two costs).

``--steered N``: ``annual_energy(..., YawOptimizationSR)`` of the first N records (``--steered-
models``, default ekman_veer), in chunks of ``--steered-chunk`` (default the study's, 1,024) with
its progress bar, the optimiser over ``--steering-chunk`` conditions at a time (default the
study's: 4,608 conditions x turbines over the farm's turbines, at most a chunk), run once; the
time of a year is extrapolated linearly, t(8,760) = t(N) x 8,760 / N (the chunks are independent
and alike, so the time is proportional to their number; docs/performance.md). Printed with it:
the process's CPU time, the records the optimiser ran on (the others, every turbine at rated,
skip it), the conditions FLORIS evaluated per record (every ``FlorisModel.run`` of the study:
the load does not change them) and the study's peak resident memory. With
``--dask-workers W`` the same study runs again on a ``LocalCluster`` of W single-threaded worker
processes (``client=``), its numbers are checked bitwise against the serial run, and the
speed-up serial / cluster is printed (the cluster's start-up not counted).

The records are synthetic: directions uniform, speeds 5-14 m/s at 90 m, the stability of each
record one of ``--classes`` Obukhov lengths, 100-2000 m (stable nights to near-neutral days).
State the machine's load (``uptime``) with the numbers.
"""

from __future__ import annotations

import argparse
import os
import time
import tracemalloc
from pathlib import Path

import numpy as np
from floris import FlorisModel, TimeSeries

import floris_ekman_veer
from floris_ekman_veer import annual_energy
from floris_ekman_veer.studies.comparison import builtin_model
from floris_ekman_veer.plugin.inflow.inflow import atmosphere_of, set_atmosphere

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


def timed(function) -> tuple[float, float]:
    """(wall, CPU) seconds of one call (CPU: this process's, all its threads; a load from
    other processes slows it less than the wall time)."""
    start, cpu = time.perf_counter(), time.process_time()
    function()
    return time.perf_counter() - start, time.process_time() - cpu


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
    parser.add_argument("--memory", action=argparse.BooleanOptionalAction, default=True)
    parser.add_argument("--lines", default=",".join(LINES),
                        help=f"comma-separated, of {list(LINES)} (or none)")
    parser.add_argument("--steered", type=int, default=0, metavar="N",
                        help="also run a steered study of the first N records")
    parser.add_argument("--steered-chunk", type=int, default=None, metavar="K")
    parser.add_argument("--steering-chunk", type=int, default=None, metavar="S")
    parser.add_argument("--steered-models", default="ekman_veer")
    parser.add_argument("--rated", action="store_true",
                        help="print the share of records with every turbine at rated (the "
                             "steered study's skip) and within a loss to rated of 1e-4, 1e-3")
    parser.add_argument("--dask-workers", type=int, default=0, metavar="W",
                        help="run the steered study on a LocalCluster of W processes too")
    args = parser.parse_args()
    floris_ekman_veer.silence_warnings()
    chosen = [k for k in args.lines.split(",") if k in LINES]
    unknown = [k for k in args.lines.split(",") if k not in LINES and k != "none"]
    if unknown:
        parser.error(f"--lines: unknown {unknown}; choose from {list(LINES)}")

    fmodel = farm(args.side)
    series, classes = records(args.records, args.classes)
    block = dict(atmosphere_of(fmodel.core).sliced(slice(None)))
    block.pop("cooling_rate", None)  # the input's own stability, replaced by each class's L
    stability = {f"L={length:.6g}": {"atmosphere": dict(block, obukhov_length=float(length))}
                 for length in np.geomspace(100.0, 2000.0, args.classes)}
    names = np.array(list(stability))[classes]
    directions, speeds, _, _ = series.unpack_for_reinitialize()
    conditions = dict(wind_directions=directions, wind_speeds=speeds,
                      turbulence_intensities=np.full(speeds.size, 0.06))
    # The single atmosphere of the "one atmosphere" lines: the input's own block.
    models = {}
    for name in ("gauss", "gch"):
        on_inflow = builtin_model(fmodel, name)
        on_inflow.set(**conditions)
        plain = on_inflow.copy()
        set_atmosphere(plain, None)
        models[name] = (plain, on_inflow)
    own = fmodel.copy()
    own.set(**conditions)
    options = {} if args.chunk_size is None else {"chunk_size": args.chunk_size}

    def study(model):
        return lambda: annual_energy(fmodel, series, stability, records=names, models=[model],
                                     progress=False, **options)

    run = {
        "plain": models["gauss"][0].run, "inflow": models["gauss"][1].run,
        "plain_gch": models["gch"][0].run, "gch_one": models["gch"][1].run,
        "ekman_veer_one": own.run, "ekman_veer": study("ekman_veer"), "gch": study("gch"),
    }
    print(f"{args.records} records ({args.classes} atmospheres), {args.side} x {args.side} farm, "
          f"best of {args.repeats}, interleaved; load {os.getloadavg()[0]:.1f} (1 min)",
          flush=True)
    best = {k: np.inf for k in chosen}
    best_cpu = dict(best)
    for repeat in range(args.repeats if chosen else 0):
        for key in chosen:
            elapsed, cpu = timed(run[key])
            best[key], best_cpu[key] = min(best[key], elapsed), min(best_cpu[key], cpu)
            print(f"  repeat {repeat}: {key} {elapsed:.2f} s (CPU {cpu:.2f} s)", flush=True)
    peaks = {k: peak_memory(run[k]) if args.memory else np.nan for k in chosen}
    if chosen:
        reference = best.get("plain", np.nan)
        reference_cpu = best_cpu.get("plain", np.nan)
        print("| line | time [s] | / plain gauss | CPU [s] | / plain gauss | "
              "/ same model, one atmosphere | peak traced memory [MB] |")
        print("|---|---:|---:|---:|---:|---:|---:|")
        for key in chosen:
            same = best.get(SAME_MODEL.get(key))
            same = "-" if same is None else f"{best[key] / same:.2f}"
            print(f"| {LINES[key]} | {best[key]:.2f} | {best[key] / reference:.2f} | "
                  f"{best_cpu[key]:.2f} | {best_cpu[key] / reference_cpu:.2f} | {same} | "
                  f"{peaks[key] / 1e6:.0f} |")
        if "gch" in best and "plain_gch" in best:
            print(f"annual_energy gch / plain FLORIS GCH: {best['gch'] / best['plain_gch']:.2f}")
    print(f"process peak resident memory: {peak_resident() / 1e6:.0f} MB; load "
          f"{os.getloadavg()[0]:.1f} (1 min)", flush=True)
    if args.rated:
        at_rated(fmodel, series, stability, names)
    if args.steered:
        steered(fmodel, series, stability, names, args)


#: The benchmark's lines (``--lines``) and their labels.
LINES = {
    "plain": "plain FLORIS gauss (reference)",
    "inflow": "gauss on the Ekman inflow, one atmosphere",
    "plain_gch": "plain FLORIS GCH",
    "gch_one": "GCH on the Ekman inflow, one atmosphere",
    "ekman_veer_one": "ekman_veer, one atmosphere",
    "ekman_veer": "annual_energy ekman_veer, per-record atmospheres",
    "gch": "annual_energy gch, per-record atmospheres",
}
#: Each AEP line's reference of the same model on one atmosphere.
SAME_MODEL = {"ekman_veer": "ekman_veer_one", "gch": "gch_one", "inflow": "plain",
              "gch_one": "plain_gch"}


def peak_resident() -> float:
    """The process's peak resident set size [bytes] (Linux reports kB, macOS bytes)."""
    import resource
    import sys

    if sys.platform.startswith("linux"):
        # VmHWM follows a reset by reset_peak_resident (ru_maxrss does not).
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return float(line.split()[1]) * 1024
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return float(peak if sys.platform == "darwin" else peak * 1024)


def at_rated(fmodel, series, stability, names) -> None:
    """The records' baseline (one run, each record with its class's atmosphere): the share with
    every turbine at the maximum of its power table (which a steered study does not optimise)
    and, for a tolerance that was considered instead, within 1e-4 and 1e-3 of the record's
    power of it (the loss to rated summed over the turbines)."""
    from floris_ekman_veer.studies.energy import condition_chunks as energy

    model = fmodel.copy()
    atmosphere = {key: [stability[name]["atmosphere"][key] for name in names]
                  for key in next(iter(stability.values()))["atmosphere"]}
    directions, speeds, _, _ = series.unpack_for_reinitialize()
    set_atmosphere(model, atmosphere, wind_directions=directions, wind_speeds=speeds,
                   turbulence_intensities=np.full(speeds.size, 0.06))
    model.run()
    powers = model.get_turbine_powers()
    loss = np.sum(energy._rated_powers(model) - powers, axis=1)
    farm = np.sum(powers, axis=1)
    shares = ", ".join(f"{100 * np.mean(loss <= tol * farm):.2f} % within {tol:g}"
                       for tol in (1e-4, 1e-3))
    print(f"{speeds.size} records: {100 * np.mean(loss == 0.0):.2f} % with every turbine at "
          f"rated (loss to rated 0); {shares} of the record's power", flush=True)


def reset_peak_resident():
    """Reset the process's peak resident memory to its current one (Linux: ``5`` written to
    /proc/self/clear_refs) and return that [bytes]; None where it cannot be reset (then
    :func:`peak_resident` keeps the peak of the whole process)."""
    import gc

    gc.collect()
    try:
        with open("/proc/self/clear_refs", "w") as refs:
            refs.write("5")
        with open("/proc/self/status") as status:
            rss = next(line for line in status if line.startswith("VmRSS:"))
    except (OSError, StopIteration):
        return None
    return float(rss.split()[1]) * 1024


def steered(fmodel, series, stability, names, args) -> None:
    """The steered study of the first ``--steered`` records, serial and (``--dask-workers``) on
    a LocalCluster; times, the extrapolation to 8,760 records and the bitwise check."""
    from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

    from floris_ekman_veer.studies.energy import condition_chunks as energy

    n = min(args.steered, len(names))
    subset = TimeSeries(series.wind_directions[:n], series.wind_speeds[:n],
                        turbulence_intensities=0.06)
    kwargs = dict(records=names[:n], models=args.steered_models.split(","), progress=True)
    if args.steered_chunk is not None:
        kwargs["chunk_size"] = args.steered_chunk
    if args.steering_chunk is not None:
        kwargs["steering_chunk_size"] = args.steering_chunk
    optimised = []
    original = energy.optimize_yaw

    def counting(fmodel, *arguments, **options):
        optimised.append(fmodel.core.flow_field.n_findex)
        return original(fmodel, *arguments, **options)

    evaluated = []
    run = FlorisModel.run

    def counting_run(self, *arguments, **options):
        evaluated.append(self.core.flow_field.n_findex)
        return run(self, *arguments, **options)

    energy.optimize_yaw, FlorisModel.run = counting, counting_run
    resident = reset_peak_resident()
    try:
        start, cpu = time.perf_counter(), time.process_time()
        serial = annual_energy(fmodel, subset, stability, YawOptimizationSR, **kwargs)
        elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
    finally:
        energy.optimize_yaw, FlorisModel.run = original, run
    study_memory = ("" if resident is None else
                    f"; the study's peak resident memory {(peak_resident() - resident) / 1e6:.0f} MB "
                    "above the process's before it")
    year = serial.table[serial.table.stability == "all"]
    chunk = kwargs.get("chunk_size", energy.DEFAULT_CHUNK_SIZE)
    # (A package before steering_chunk_size ran the optimiser 256 conditions at a time.)
    steering = kwargs.get("steering_chunk_size", getattr(
        energy, "STEERING_TURBINE_CONDITIONS", 256 * fmodel.core.farm.n_turbines)
        // fmodel.core.farm.n_turbines)
    runs = len(args.steered_models.split(","))
    print(f"steered ({YawOptimizationSR.__name__}, {args.steered_models}, {n} records, chunks of "
          f"{chunk}, optimiser runs of at most {min(chunk, steering)}): {elapsed:.1f} s = "
          f"{elapsed / n:.3f} s per record (CPU {cpu:.1f} s = {cpu / n:.3f} s); a year of "
          f"8,760 records: {elapsed / n * 8760 / 60:.1f} min (t x 8,760 / {n}; CPU "
          f"{cpu / n * 8760 / 60:.1f} min); optimised {sum(optimised)} of {n * runs} records "
          f"(the others at rated); {sum(evaluated) / n:.1f} conditions evaluated per record in "
          f"{len(evaluated)} FLORIS runs; gain {', '.join(f'{g:+.3f} %' for g in year.gain_percent)}"
          f"{study_memory}; load {os.getloadavg()[0]:.1f} (1 min)", flush=True)
    if not args.dask_workers:
        return
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=args.dask_workers, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as client:
        # A first small study registers the package on the workers (not counted).
        annual_energy(fmodel, TimeSeries(subset.wind_directions[:1], subset.wind_speeds[:1],
                                         turbulence_intensities=0.06), stability,
                      records=names[:1], models=["ekman_veer"], progress=False, client=client)
        start = time.perf_counter()
        on_cluster = annual_energy(fmodel, subset, stability, YawOptimizationSR, client=client,
                                   **kwargs)
        on_time = time.perf_counter() - start
    same = all(
        np.array_equal(serial.conditions[m][c].to_numpy(), on_cluster.conditions[m][c].to_numpy())
        for m in serial.conditions for c in ("farm_power_baseline", "farm_power_steered"))
    print(f"on a LocalCluster of {args.dask_workers} processes: {on_time:.1f} s, speed-up "
          f"{elapsed / on_time:.2f} x; bitwise the serial numbers: {same}; load "
          f"{os.getloadavg()[0]:.1f} (1 min)")


if __name__ == "__main__":
    main()
