"""Convergence of the rotor average on single and multiple wakes (hand-run study, not a test):

    python -m benchmarks.bench_rotor_average [--reference 48x192] [--quick] [--multiwake]
                                             [--points N]

``--multiwake`` prints only the multi-wake table (below).

For one upstream turbine and one downstream rotor, the downstream rotor's average velocity from
each FLORIS rotor quadrature against a converged integral of the same wake over the rotor disk:

* reference: a polar quadrature of the disk (Gauss-Legendre in r^2 x uniform angles, default
  48 x 192 points, ``--reference``) of ``sample_flow_at_points`` (point values of the flow: the
  ambient profile minus the wake), disk normal to the wind, averaged as the turbine's operation
  model averages: the cubic mean <u^3>^(1/3) for the NREL 5 MW power curve, the plain mean <u>
  for the paper's actuator disk (Eq. Ud);
* ``3x3 points``: the 3 x 3 point values at +-R/2 that FLORIS's turbine grid samples, averaged
  the same way (FLORIS's turbine grid without rotor cells);
* ``3x3 cells``: FLORIS's ``turbine_grid`` with 3 x 3 points as shipped in ``inputs/``, every point
  carrying its rotor cell's average (docs/coupling.md#rotor-average);
* ``cubature N``: FLORIS's ``turbine_cubature_grid`` (point values, FLORIS's cubature mean).

Error: power error (u / u_ref)^3 - 1. Cases (the issue list): the paper's actuator disk in CNBL,
SBL-4 and SBL-6 (``inputs/cnbl.yaml``, ``sbl4.yaml``, ``sbl6.yaml``) and the NREL 5 MW farm
input (``inputs/farm_sbl6.yaml``, 9 m/s at 90 m); veer on and off (M-1, M-2); upstream yaw 0 and
+-20 deg; downstream rotor 5, 7, 10, 15 D behind, laterally offset -1.5 D to +1.5 D in steps of
0.25 D. Prints the largest |error| per input, veer and quadrature (the README's table), the
worst case, and the errors of an unwaked rotor (the ambient profile alone). ``--quick`` uses steps of 0.5 D and 5 and 10 D only.
``--points N`` adds FLORIS's ``turbine_grid`` with N x N rotor cells (``NxN cells``; in the
multi-wake table: every case on N x N cells in place of the shipped grid).

Multiple wakes: every turbine's power with the shipped settings (the farm input's wake settings:
sosfs, crespo_hernandez, local_turbulence; 3 x 3 rotor cells) against the converged point-wise
reference of tests/plugin/rotor/multiwake_reference.py (FLORIS's point-wise sosfs, wake-added turbulence and
cubic mean on 4,096 equal-area points per rotor), for the layouts of MULTIWAKE_CASES in the
SBL-6, SBL-4 and neutral atmospheres: the largest |P / P_ref - 1| over turbines and conditions.
"""

from __future__ import annotations

import argparse
import copy
import warnings
from pathlib import Path

import numpy as np

REPOSITORY = Path(__file__).resolve().parent.parent
import floris_ekman_veer  # noqa: F401

from floris import FlorisModel  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

from tests.plugin.rotor.multiwake_reference import (  # noqa: E402  (the tests' reference)
    FARM_3X3,
    SIDE_BY_SIDE,
    disk_quadrature,
    farm_config,
    power_errors,
    row,
)

INPUTS = {"CNBL disk": "cnbl.yaml", "SBL-4 disk": "sbl4.yaml", "SBL-6 disk": "sbl6.yaml",
          "NREL 5 MW, farm input": "farm_sbl6.yaml"}
YAWS = (0.0, 20.0, -20.0)
QUADRATURES = ("3x3 points", "3x3 cells", "cubature 3", "cubature 5")


def mean(u, weight, moment):
    """The operation model's rotor average of ``u`` (..., points) with ``weight``."""
    return np.sum(weight * u, -1) if moment == 1 else np.cbrt(np.sum(weight * u**3, -1))


def single_wake_errors(input_name, veer, distance, offset, reference, solver=None,
                       quadratures=QUADRATURES):
    """Power errors of the downstream rotor for the upstream yaws YAWS: dict quadrature ->
    (n_yaw,) array. ``solver`` restricts to one FLORIS quadrature (None: all)."""
    config = load_yaml(REPOSITORY / "inputs" / input_name)
    config["wake"]["wake_deflection_parameters"].setdefault("ekman_veer", {})["veer"] = veer
    probe = FlorisModel(copy.deepcopy(config))
    diameter = float(probe.core.farm.rotor_diameters[0])
    hub = float(probe.core.farm.hub_heights[0])
    plain = probe.core.farm.turbine_definitions[0].get("operation_model") == "actuator-disk"
    moment = 1 if plain else 3
    config["farm"]["layout_x"] = [0.0, distance * diameter]
    config["farm"]["layout_y"] = [0.0, offset * diameter]
    if len(config["farm"]["turbine_type"]) == 1:
        config["farm"]["turbine_type"] = config["farm"]["turbine_type"] * 2
    n = len(YAWS)
    flow = config["flow_field"]
    conditions = dict(
        wind_directions=[270.0] * n, wind_speeds=[flow["wind_speeds"][0]] * n,
        turbulence_intensities=[flow["turbulence_intensities"][0]] * n,
    )
    yaw = np.stack([np.array(YAWS), np.zeros(n)], axis=1)
    y, z, weight = reference
    radius = 0.5 * diameter

    def sampled(ys, zs):
        fmodel = FlorisModel(copy.deepcopy(config))
        fmodel.set(**conditions, yaw_angles=yaw)
        return fmodel.sample_flow_at_points(np.full(ys.size, distance * diameter),
                                            offset * diameter + radius * ys, hub + radius * zs)

    u_ref = mean(sampled(y, z), weight, moment)
    errors = {}
    for quadrature in quadratures:
        if solver is not None and quadrature != solver:
            continue
        if quadrature == "3x3 points":
            g = np.linspace(-0.5, 0.5, 3)
            gy, gz = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
            u = mean(sampled(gy, gz), np.full(9, 1.0 / 9.0), moment)
        else:
            fmodel = FlorisModel(copy.deepcopy(config))
            if quadrature.endswith(" cells"):
                settings = {"type": "turbine_grid",
                            "turbine_grid_points": int(quadrature.split("x")[0])}
            else:
                settings = {"type": "turbine_cubature_grid",
                            "turbine_grid_points": int(quadrature.split()[1])}
            fmodel.set(**conditions, yaw_angles=yaw, solver_settings=settings)
            fmodel.run()
            u = fmodel.turbine_average_velocities[:, 1]
            if moment == 1:  # the actuator disk's plain mean of the rotor points (or cubature)
                velocities = fmodel.core.flow_field.u[:, 1].reshape(n, -1)
                w = fmodel.core.grid.cubature_weights
                w = np.full(velocities.shape[1], 1.0 / velocities.shape[1]) if w is None \
                    else w.ravel() / w.sum()
                u = np.sum(velocities * w, axis=-1)
        errors[quadrature] = (u / u_ref) ** 3 - 1.0
    return errors


def _directions(directions, speed):
    return dict(wind_directions=list(directions), wind_speeds=[speed] * len(directions),
                turbulence_intensities=[0.06] * len(directions))


_FRONT_YAW = np.array([[20.0, 20.0, 0.0], [-20.0, -20.0, 0.0], [20.0, -20.0, 0.0]])

#: label -> (turbine, wind speed at hub height, layout in D, conditions or None: 270 deg).
MULTIWAKE_CASES = {
    "two rotors at y = +-0.6 D, target at 7 D (9 m/s)": ("nrel_5MW", 9.0, SIDE_BY_SIDE, None),
    "the same, front yawed +-20 deg": (
        "nrel_5MW", 9.0, SIDE_BY_SIDE, _directions([270.0] * 3, 9.0) | {"yaw_angles": _FRONT_YAW}),
    "row of 5 at 4 D (9 m/s)": ("nrel_5MW", 9.0, row(4.0), None),
    "row of 5 at 5 D (9 m/s)": ("nrel_5MW", 9.0, row(5.0), None),
    "the 3 x 3 farm input, 260-280 deg, 9 m/s": (
        "nrel_5MW", 9.0, FARM_3X3, _directions(np.arange(260.0, 281.0, 2.5), 9.0)),
    "the 3 x 3 farm input, 260-280 deg, 11 m/s": (
        "nrel_5MW", 11.0, FARM_3X3, _directions(np.arange(260.0, 281.0, 2.5), 11.0)),
    "IEA 15 MW side by side (9 m/s at 150 m)": ("iea_15MW", 9.0, SIDE_BY_SIDE, None),
    "IEA 15 MW row of 5 at 4 D (9 m/s at 150 m)": ("iea_15MW", 9.0, row(4.0), None),
}


def multiwake_table(rings: int = 32, angles: int = 128, points: int | None = None) -> None:
    """Print the multi-wake convergence table (module docstring); ``points``: N x N rotor cells
    in place of the shipped grid."""
    atmospheres = ("SBL-6", "SBL-4", "neutral")
    grid = "shipped settings" if points is None else f"{points} x {points} rotor cells"
    print(f"Multiple wakes: largest |P / P_ref - 1| per turbine against the point-wise disk "
          f"reference ({rings} x {angles} equal-area points per rotor), {grid}\n")
    print("| case | " + " | ".join(atmospheres) + " |")
    print("|---|" + "---:|" * len(atmospheres))
    for label, (turbine, speed, layout, conditions) in MULTIWAKE_CASES.items():
        cells = []
        for atmosphere in atmospheres:
            config = farm_config(atmosphere, turbine, layout, speed)
            if points is not None:
                config["solver"]["turbine_grid_points"] = points
            errors = power_errors(config, conditions, rings=rings, angles=angles)
            cells.append(f"{100 * errors.flat[np.argmax(np.abs(errors))]:+.2f} %")
        print(f"| {label} | " + " | ".join(cells) + " |", flush=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--reference", default="48x192")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--multiwake", action="store_true")
    parser.add_argument("--points", type=int, default=None)
    args = parser.parse_args(argv)
    quadratures = QUADRATURES if args.points is None or args.points == 3 else (
        QUADRATURES[:2] + (f"{args.points}x{args.points} cells",) + QUADRATURES[2:])
    if args.multiwake:
        warnings.simplefilter("ignore", RuntimeWarning)
        multiwake_table(points=args.points)
        return
    reference = disk_quadrature(*(int(v) for v in args.reference.split("x")))
    distances = (5.0, 10.0) if args.quick else (5.0, 7.0, 10.0, 15.0)
    offsets = np.arange(-1.5, 1.51, 0.5 if args.quick else 0.25)
    warnings.simplefilter("ignore", RuntimeWarning)
    print(f"Single-wake rotor averages against a {args.reference} polar disk integral; power "
          f"error (u/u_ref)^3 - 1, largest |error| over yaw {YAWS} deg, downstream "
          f"{distances} D and lateral offsets {offsets[0]:+.2f}..{offsets[-1]:+.2f} D\n")
    print("| case | veer | " + " | ".join(quadratures) + " |")
    print("|---|---|" + "---:|" * len(quadratures))
    worst = (0.0, None)
    for label, input_name in INPUTS.items():
        for veer in (True, False):
            largest = dict.fromkeys(quadratures, 0.0)
            for distance in distances:
                for offset in offsets:
                    errors = single_wake_errors(input_name, veer, distance, offset, reference,
                                                quadratures=quadratures)
                    for quadrature, error in errors.items():
                        largest[quadrature] = max(largest[quadrature], np.max(np.abs(error)))
                    cells = np.max(np.abs(errors["3x3 cells"]))
                    if cells > worst[0]:
                        worst = (cells, (label, veer, distance, offset))
            print(f"| {label} | {'on' if veer else 'off'} | "
                  + " | ".join(f"{100 * largest[q]:.1f} %" for q in quadratures) + " |")
    print(f"\nworst 3x3 cells case: {100 * worst[0]:.2f} % at {worst[1]}")
    # The ambient part alone: a rotor 8 D aside of the wake (no wake on it).
    unwaked = single_wake_errors(INPUTS["NREL 5 MW, farm input"], True, 7.0, 8.0, reference,
                                 quadratures=quadratures)
    print("unwaked NREL 5 MW in the farm input (9 m/s): "
          + ", ".join(f"{q} {100 * unwaked[q][0]:+.1f} %" for q in quadratures))


if __name__ == "__main__":
    main()
