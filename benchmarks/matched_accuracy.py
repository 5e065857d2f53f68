"""Each model at the rotor points its farm power needs, then speed at the same answer (hand-run
study, not a test):

    python -m benchmarks.matched_accuracy [--conditions 100] [--repeats 3] [--no-speed]
                                          [--tolerance 1.0] [--speed-only SETTINGS]

Convergence (printed first): on veer-sheared multi-wake cases (the layouts of LAYOUTS, none of
them a layout of the shipped tests, in the stable Ekman inflows of ATMOSPHERES, unyawed and
yawed), every model's farm power at each rotor-point setting against its own answer on
REFERENCE x REFERENCE points, computed separately (the reference):

    M-1      the package's ekman_veer (the farm input as shipped: fls, crespo_hernandez) on
             ``solver.turbine_grid_points`` n (n x n rotor cells, plugin/rotor/rotor_cells.py;
             n = REFERENCE: 400 cells of 160 sub-rows, the disk integral);
    gauss    FLORIS gauss (no GCH terms) on the same inflow, FLORIS's n x n turbine grid (its
             points span +-R/2 whatever n: its own limit is the mean over that square);
    PyWake   Niayifar_PorteAgel_2016 with Jimenez deflection (benchmarks/bench_peers.py) on its
             uniform site with the power-law shear of the atmosphere's rotor layer (alpha from
             the Ekman profile between hub -+ R at 9 m/s; PyWake has no veer), rotor averages
             ``GridRotorAvg n x n`` on FLORIS's +-R/2 points (reference: the same at 20 x 20),
             ``EqGridRotorAvg(n)`` (the n x n square grid inside the disk) and ``CGIRotorAvg(n)``
             (reference of both: EqGridRotorAvg(20), 316 points).

Error of a setting on a case: the largest |P_farm / P_farm,ref - 1| over the case's conditions.
The table prints it per case and the setting each model needs: the fewest points whose error is
below ``--tolerance`` percent on every case, and every finer setting's too. The reference's own
convergence: the largest change from REFERENCE - 4 to REFERENCE points.

Speed (then): the 10 x 10 farm of bench_peers.py (NREL 5 MW at 7 D, ``--conditions`` random
yawed conditions, FLORIS models on the SBL-6 farm input) with every model at the setting it
needs (a model that needs more than it was tried on: its finest tried, a lower bound of its
cost) and at 3 x 3; interleaved, best of ``--repeats``, wall and CPU, and each CPU time over
M-1's. ``--speed-only`` times given settings without the convergence.
"""

from __future__ import annotations

import argparse
import copy
import os
import sys
import warnings

import numpy as np

from benchmarks import bench_models, bench_peers

import numba  # noqa: E402
import numexpr  # noqa: E402
from floris import FlorisModel  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

REFERENCE = 20
ATMOSPHERES = {"night": "farm_night.yaml", "SBL-6": "farm_sbl6.yaml"}
M1_POINTS = (1, 2, 3, 4, 5)
GAUSS_POINTS = (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 12)
PYWAKE_SETTINGS = ([("grid", n) for n in (1, 2, 3, 4, 5, 6, 7, 8, 10)]
                   + [("eqgrid", n) for n in (2, 3, 4, 5, 6, 8, 10)]
                   + [("cgi", n) for n in (4, 7, 9, 21)])

_RNG = np.random.default_rng(41)
#: label -> (x, y) in rotor diameters, wind directions [deg] of its conditions. None of these is
#: a layout of tests/plugin/rotor/multiwake_reference.py (the shipped tests' side by side, rows
#: of 5 at 4 and 5 D, the 3 x 3 at 7 D).
LAYOUTS = {
    "row of 6 at 6 D, 264-276 deg": (
        (np.arange(6) * 6.0, np.zeros(6)), np.arange(264.0, 276.1, 3.0)),
    "staggered 3 x 2 (6 D, 3 D, shift 0.5 D), 255-285 deg": (
        (np.repeat([0.0, 6.0, 12.0], 2), np.array([0.0, 3.0, 0.5, 3.5, 0.0, 3.0])),
        np.arange(255.0, 285.1, 7.5)),
    "4 x 4 at 5 D x 4 D, 250-290 deg": (
        (np.repeat(np.arange(4) * 5.0, 4), np.tile(np.arange(4) * 4.0, 4)),
        np.arange(250.0, 290.1, 10.0)),
    "8 random in 20 D x 20 D, 0-315 deg": (
        (_RNG.uniform(0.0, 20.0, 8), _RNG.uniform(0.0, 20.0, 8)), np.arange(0.0, 316.0, 45.0)),
}
SPEEDS = (7.0, 9.0, 11.0)  # [m/s] at hub height, cycled over a case's conditions
YAW_LIMIT = 25.0  # [deg] yawed cases: every turbine uniform in +-YAW_LIMIT per condition


def cases():
    """(label, atmosphere input, layout in D, directions, speeds, yaw (n, turbines))."""
    rng = np.random.default_rng(7)
    for atmosphere, input_name in ATMOSPHERES.items():
        for layout_label, (layout, directions) in LAYOUTS.items():
            speeds = np.resize(np.array(SPEEDS), directions.size)
            for yawed in (False, True):
                yaw = np.zeros((directions.size, layout[0].size))
                if yawed:
                    yaw = rng.uniform(-YAW_LIMIT, YAW_LIMIT, yaw.shape)
                label = f"{atmosphere}, {layout_label}, {'yawed' if yawed else 'unyawed'}"
                yield label, input_name, layout, directions, speeds, yaw


def floris_config(model: str, input_name: str, layout) -> dict:
    """The farm input ``input_name`` (M-1) or FLORIS gauss on its inflow, on ``layout`` [D]."""
    config = load_yaml(bench_models.REPOSITORY / "inputs" / input_name)
    diameter = 126.0  # the farm inputs' NREL 5 MW
    config["farm"]["layout_x"] = [float(v) * diameter for v in layout[0]]
    config["farm"]["layout_y"] = [float(v) * diameter for v in layout[1]]
    if model == "gauss":
        wake = config["wake"]
        # as bench_peers's gauss: the input's combination (fls), crespo_hernandez
        wake["model_strings"].update(velocity_model="gauss", deflection_model="gauss")
        for flag in ("enable_secondary_steering", "enable_yaw_added_recovery",
                     "enable_transverse_velocities"):
            wake[flag] = False
    return config


def floris_farm_powers(config: dict, points: int, directions, speeds, yaw) -> np.ndarray:
    fmodel = on_grid(FlorisModel(copy.deepcopy(config)), points)
    fmodel.set(wind_directions=directions, wind_speeds=speeds,
               turbulence_intensities=np.full(len(directions), 0.06), yaw_angles=yaw)
    fmodel.run()
    return fmodel.get_farm_power()


def on_grid(fmodel: FlorisModel, points: int) -> FlorisModel:
    """``fmodel`` on an n x n turbine grid (FlorisModel's constructor refuses n > 3 from an
    input; ``set`` takes it)."""
    fmodel.set(solver_settings={"type": "turbine_grid", "turbine_grid_points": int(points)})
    return fmodel


def pywake_rotor(setting):
    from py_wake.rotor_avg_models import CGIRotorAvg, EqGridRotorAvg, RotorCenter

    kind, n = setting
    if kind == "grid":
        return RotorCenter() if n == 1 else bench_peers.floris_like_grid(n)
    return EqGridRotorAvg(n) if kind == "eqgrid" else CGIRotorAvg(n)


def pywake_label(setting) -> str:
    kind, n = setting
    return {"grid": f"GridRotorAvg {n}x{n} (+-R/2)", "eqgrid": f"EqGridRotorAvg({n})",
            "cgi": f"CGIRotorAvg({n})"}[kind]


def power_law_shear(input_name: str):
    """PyWake's PowerShear with the exponent of the input's Ekman profile over the NREL 5 MW's
    rotor layer (27-153 m) at 9 m/s at hub height."""
    from py_wake.site.shear import PowerShear

    config = floris_config("M-1", input_name, ((0.0,), (0.0,)))
    fmodel = FlorisModel(config)
    fmodel.set(wind_directions=[270.0], wind_speeds=[9.0], turbulence_intensities=[0.06])
    u = fmodel.sample_flow_at_points(np.full(2, -500.0), np.zeros(2), np.array([27.0, 153.0]))
    alpha = float(np.log(u[0, 1] / u[0, 0]) / np.log(153.0 / 27.0))
    return PowerShear(h_ref=90.0, alpha=alpha), alpha


def pywake_farm_powers(setting, shear, layout, directions, speeds, yaw) -> np.ndarray:
    wind_farm = bench_peers.pywake_wind_farm(pywake_rotor(setting), shear)
    result = wind_farm(np.asarray(layout[0]) * 126.0, np.asarray(layout[1]) * 126.0,
                       wd=directions, ws=speeds, yaw=yaw.T, tilt=0, time=True)
    return result.Power.values.sum(axis=0)


def convergence(tolerance: float):
    """Print the convergence tables; return the setting each model needs."""
    errors = {}  # (model, setting label) -> list of per-case errors
    reference_change = {}
    labels = []
    shears = {name: power_law_shear(name) for name in ATMOSPHERES.values()}
    for label, input_name, layout, directions, speeds, yaw in cases():
        labels.append(label)
        print(f"  {label}", file=sys.stderr, flush=True)
        for model, settings in (("M-1", M1_POINTS), ("gauss", GAUSS_POINTS)):
            config = floris_config(model, input_name, layout)
            reference = floris_farm_powers(config, REFERENCE, directions, speeds, yaw)
            near = floris_farm_powers(config, REFERENCE - 4, directions, speeds, yaw)
            reference_change.setdefault(model, []).append(np.max(np.abs(near / reference - 1)))
            for n in settings:
                powers = floris_farm_powers(config, n, directions, speeds, yaw)
                errors.setdefault((model, f"{n} x {n}"), []).append(
                    np.max(np.abs(powers / reference - 1.0)))
        shear = shears[input_name][0]
        run = lambda s: pywake_farm_powers(s, shear, layout, directions, speeds, yaw)  # noqa: E731
        references = {"grid": run(("grid", REFERENCE)), "eqgrid": run(("eqgrid", REFERENCE))}
        near = run(("grid", REFERENCE - 4)), run(("eqgrid", REFERENCE - 4))
        reference_change.setdefault("PyWake", []).append(max(
            np.max(np.abs(near[0] / references["grid"] - 1)),
            np.max(np.abs(near[1] / references["eqgrid"] - 1))))
        for setting in PYWAKE_SETTINGS:
            reference = references["grid" if setting[0] == "grid" else "eqgrid"]
            errors.setdefault(("PyWake", pywake_label(setting)), []).append(
                np.max(np.abs(run(setting) / reference - 1.0)))

    print("Cases:")
    for k, label in enumerate(labels):
        print(f"  C{k + 1}: {label}")
    print("PyWake's power-law shear: " + ", ".join(
        f"{name} alpha = {alpha:.3f}" for name, (_, alpha) in shears.items()))
    print(f"\nLargest |P_farm / P_farm,ref - 1| [%] per case, reference {REFERENCE} x "
          f"{REFERENCE} points of the same model (PyWake's EqGrid and CGI: EqGridRotorAvg"
          f"({REFERENCE}))\n")
    print("| model | setting | " + " | ".join(f"C{k + 1}" for k in range(len(labels)))
          + " | worst |")
    print("|---|---|" + "---:|" * (len(labels) + 1))
    for (model, setting), values in errors.items():
        print(f"| {model} | {setting} | " + " | ".join(f"{100 * v:.2f}" for v in values)
              + f" | {100 * max(values):.2f} |")
    print(f"\nThe references' own convergence: largest |P({REFERENCE - 4}) / P({REFERENCE}) - 1|: "
          + ", ".join(f"{m} {100 * max(v):.3f} %" for m, v in reference_change.items()))

    needed = {}
    for model, family in (("M-1", None), ("gauss", None), ("PyWake", "GridRotorAvg"),
                          ("PyWake", "EqGridRotorAvg"), ("PyWake", "CGIRotorAvg")):
        rows = [(s, max(v)) for (m, s), v in errors.items()
                if m == model and (family is None or s.startswith(family))]
        ok = [max(e for _, e in rows[k:]) < tolerance / 100 for k in range(len(rows))]
        chosen = next((rows[k] for k in range(len(rows)) if ok[k]), None)
        needed[(model, family)] = chosen
        print(f"{model} {family or ''}: needs {chosen[0] if chosen else 'more than tried'}"
              + (f" (worst {100 * chosen[1]:.2f} %)" if chosen else ""))
    return needed


def speed_settings(needed) -> dict:
    """The settings to time from the convergence: each model's needed one and the shipped 3 x 3;
    a model that met the tolerance on no setting tried is timed at its finest tried (a lower
    bound of its cost at the same answer)."""
    settings = {"M-1": {3}, "gauss": {3}, "PyWake": {("grid", 3)}}
    for model, tried in (("M-1", M1_POINTS), ("gauss", GAUSS_POINTS)):
        chosen = needed[(model, None)]
        settings[model].add(int(chosen[0].split()[0]) if chosen else tried[-1])
    for family in ("GridRotorAvg", "EqGridRotorAvg", "CGIRotorAvg"):
        chosen = needed[("PyWake", family)]
        if chosen:
            settings["PyWake"].add(next(s for s in PYWAKE_SETTINGS if pywake_label(s) == chosen[0]))
    return settings


def speed(settings: dict, n: int, repeats: int) -> None:
    """Interleaved best-of timings on the 10 x 10 farm of bench_peers at ``settings`` (model ->
    rotor points or PyWake settings)."""
    side = 10
    directions, speeds, yaw = bench_models.conditions(n, 1, side)
    x, y = np.meshgrid(np.arange(side) * bench_models.SPACING,
                       np.arange(side) * bench_models.SPACING)
    runs = {}
    for model in ("M-1", "gauss"):
        for p in sorted(settings.get(model, ())):  # a model --speed-only leaves out: none
            fmodel = on_grid(FlorisModel(bench_models.configuration(model, side)), p)
            fmodel.set(wind_directions=directions, wind_speeds=speeds,
                       turbulence_intensities=np.full(n, 0.06), yaw_angles=yaw)
            runs[f"{model} {p} x {p}"] = fmodel.run
    for setting in sorted(settings.get("PyWake", ())):
        wind_farm = bench_peers.pywake_wind_farm(pywake_rotor(setting))
        runs[f"PyWake {pywake_label(setting)}"] = (
            lambda w=wind_farm: w(x.ravel(), y.ravel(), wd=directions, ws=speeds, yaw=yaw.T,
                                  tilt=0, time=True).Power.values)
    for run in runs.values():
        run()  # warm-up
    best = {name: (np.inf, np.inf) for name in runs}
    for repeat in range(repeats):
        for name, run in runs.items():
            wall, cpu = bench_peers.timed(run)
            best[name] = (min(best[name][0], wall), min(best[name][1], cpu))
            print(f"  repeat {repeat + 1}: {name} {wall:.2f} s wall, {cpu:.2f} s CPU",
                  file=sys.stderr, flush=True)
    print(f"\nSpeed on 10 x 10 NREL 5 MW x {n} random yawed conditions, interleaved, best of "
          f"{repeats}; numexpr threads {numexpr.get_num_threads()}, numba threads "
          f"{numba.get_num_threads()}; load average {os.getloadavg()[0]:.1f} at the end\n")
    print("| contender | wall [s] | CPU [s] | " + " | ".join(
        f"CPU / {m}" for m in runs if m.startswith("M-1")) + " |")
    print("|---|---:|---:|" + "---:|" * sum(m.startswith("M-1") for m in runs))
    for name, (wall, cpu) in best.items():
        print(f"| {name} | {wall:.3f} | {cpu:.3f} | " + " | ".join(
            f"{cpu / best[m][1]:.2f}" for m in runs if m.startswith("M-1")) + " |")


def parse_settings(text: str) -> dict:
    """``--speed-only`` settings: 'M-1=2,3;gauss=3,12;PyWake=grid 3,eqgrid 8,cgi 7'."""
    settings = {}
    for part in text.split(";"):
        model, values = part.split("=")
        if model == "PyWake":
            settings[model] = {(v.split()[0], int(v.split()[1])) for v in values.split(",")}
        else:
            settings[model] = {int(v) for v in values.split(",")}
    return settings


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--conditions", type=int, default=100)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--tolerance", type=float, default=1.0, help="percent of farm power")
    parser.add_argument("--no-speed", action="store_true")
    parser.add_argument("--speed-only", default=None, metavar="SETTINGS",
                        help="time these settings without the convergence, e.g. "
                             "'M-1=2,3;gauss=3,12;PyWake=grid 3,eqgrid 8,cgi 7'")
    args = parser.parse_args(argv)
    print(f"load average {os.getloadavg()[0]:.1f} at the start\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # coarse-grid advice, the SBL-6 shallow-layer summary
        if args.speed_only:
            speed(parse_settings(args.speed_only), args.conditions, args.repeats)
            return
        settings = speed_settings(convergence(args.tolerance))
        if not args.no_speed:
            speed(settings, args.conditions, args.repeats)


if __name__ == "__main__":
    main()
