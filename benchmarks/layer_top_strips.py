"""What a strip edge at the stable layer's top would gain the coarse rotor cells (hand-run study,
not a test):

    python -m benchmarks.layer_top_strips [--sweep]

The wake cells' strips (plugin/rotor/rotor_cells.py) integrate a step in height to first order:
the whole strip it cuts counts on one side of it. In a stable layer whose top lies on the rotor
the inflow has such a step there (the jet nose, and the veer deflection x V / U), at a height
that moves with the condition, so the shipped strips, shared by all conditions of a rotor kind,
cannot follow it; the package splits the strip h cuts per condition instead
(plugin/rotor/strip_split.py, docs/coupling.md#rotor-average). This study runs the 16 cases of
benchmarks/matched_accuracy.py one wind speed at a time (one layer top h per run), on 2 x 2 and
3 x 3 cells with the shipped strips (the cut strip split) and with the strip edge nearest to h
moved to h (``rotor_cells(..., step_height=...)``: nothing left to split), each against the same
20 x 20 answer (its strips untouched), with the wakes summed and with the cumulative default,
and prints the largest |P_farm / P_farm,20x20 - 1| per case and over all.

``--sweep``: instead, the shipped strips' count on 2 x 2 and 3 x 3 cells raised from 8 to 24 per
grid point (16 / 24 strips shipped), all conditions of each case in one run, against the same
20 x 20 answers: the error is erratic in the strip count (a step cut by a strip at a different
place each time), not a convergence.
"""

from __future__ import annotations

import copy
import logging
import sys
import warnings

import numpy as np

from benchmarks import matched_accuracy

import floris_ekman_veer  # noqa: F401,E402  (registers the models)
from floris import FlorisModel  # noqa: E402
from floris_ekman_veer.plugin.inflow import ambient  # noqa: E402
from floris_ekman_veer.plugin.rotor.rotor_cells import (  # noqa: E402
    NODES_PER_INTERVAL,
    rotor_cells,
    sub_quadrature,
)

#: Strips per grid point of the sweep (8: the shipped ROWS_PER_POINT).
SWEEP_STRIPS_PER_POINT = (8, 10, 12, 14, 16, 24)

#: The layer top in rotor radii from the hub for the run being made (None: the shipped strips).
STEP = {"height": None}


def cells_with_step(n: int, rows: int, nodes: int):
    """The wake cells with the strip edge nearest to the layer top moved there; the ambient
    cells (AMBIENT_ROWS) and the 20 x 20 reference's keep their strips."""
    if STEP["height"] is None or rows >= 8 * matched_accuracy.REFERENCE:
        return rotor_cells(n, rows, nodes)
    return rotor_cells(n, rows, nodes, STEP["height"])


def layer_top(fmodel: FlorisModel) -> float:
    """The layer top of a run of one wind speed, in rotor radii from the hub."""
    abl = ambient.Ambient.of(fmodel.core.grid, fmodel.core.flow_field).abl
    top = float(np.ravel(abl.boundary_layer_height)[0])
    hub = float(fmodel.core.farm.hub_heights.ravel()[0])
    radius = 0.5 * float(fmodel.core.farm.rotor_diameters.ravel()[0])
    return (top - hub) / radius


def summed(config: dict) -> dict:
    """The farm input with the wakes summed (``wake_superposition: combination_model``)."""
    config = copy.deepcopy(config)
    for block in config["wake"]["wake_velocity_parameters"].values():
        if "wake_superposition" in block:
            block["wake_superposition"] = "combination_model"
    return config


def sweep() -> None:
    """The ``--sweep`` table."""
    per_point = {"strips": None}
    ambient.sub_quadrature = lambda n, diameter=0.0: (  # noqa: E731
        (per_point["strips"] * n, NODES_PER_INTERVAL) if per_point["strips"] and n in (2, 3)
        else sub_quadrature(n, diameter))
    worst = {}
    for label, input_name, layout, directions, speeds, yaw in matched_accuracy.cases():
        shipped = matched_accuracy.floris_config("M-1", input_name, layout)
        for superposition, config in (("summed", summed(shipped)), ("cumulative", shipped)):
            per_point["strips"] = None
            reference = matched_accuracy.floris_farm_powers(
                config, matched_accuracy.REFERENCE, directions, speeds, yaw)
            for strips in SWEEP_STRIPS_PER_POINT:
                per_point["strips"] = strips
                for n in (2, 3):
                    powers = matched_accuracy.floris_farm_powers(config, n, directions, speeds,
                                                                 yaw)
                    key = (superposition, n, strips)
                    worst[key] = max(worst.get(key, 0.0),
                                     100.0 * np.max(np.abs(powers / reference - 1.0)))
        print(f"  {label}", file=sys.stderr, flush=True)
    print("Largest |P_farm / P_farm,20x20 - 1| [%] over the 16 cases of "
          "benchmarks/matched_accuracy.py, by the strips of the 2 x 2 / 3 x 3 cells\n")
    print("| wakes | cells | " + " | ".join(f"{2 * s} / {3 * s} strips"
                                          for s in SWEEP_STRIPS_PER_POINT) + " |")
    print("|---|---|" + "---:|" * len(SWEEP_STRIPS_PER_POINT))
    for superposition in ("summed", "cumulative"):
        for n in (2, 3):
            print(f"| {superposition} | {n} x {n} | " + " | ".join(
                f"{worst[superposition, n, s]:.2f}" for s in SWEEP_STRIPS_PER_POINT) + " |")


def main() -> None:
    if "--sweep" in sys.argv[1:]:
        sweep()
        return
    ambient.rotor_cells = cells_with_step
    worst = {}
    for k, (label, input_name, layout, directions, speeds, yaw) in enumerate(
            matched_accuracy.cases()):
        shipped = matched_accuracy.floris_config("M-1", input_name, layout)
        for superposition, config in (("summed", summed(shipped)), ("cumulative", shipped)):
            row = []
            for speed in np.unique(speeds):
                chosen = speeds == speed
                conditions = directions[chosen], speeds[chosen], yaw[chosen]
                STEP["height"] = None
                fmodel = matched_accuracy.on_grid(FlorisModel(copy.deepcopy(config)),
                                                  matched_accuracy.REFERENCE)
                fmodel.set(wind_directions=conditions[0], wind_speeds=conditions[1],
                           turbulence_intensities=np.full(chosen.sum(), 0.06),
                           yaw_angles=conditions[2])
                fmodel.run()
                reference, top = fmodel.get_farm_power(), layer_top(fmodel)
                for n in (2, 3):
                    for strips in ("shipped", "edge at h"):
                        STEP["height"] = top if strips != "shipped" and abs(top) < 1 else None
                        powers = matched_accuracy.floris_farm_powers(config, n, *conditions)
                        error = 100.0 * np.max(np.abs(powers / reference - 1.0))
                        key = (superposition, n, strips)
                        worst[key] = max(worst.get(key, 0.0), error)
                        row.append(f"{n}x{n} {strips} {error:.2f}")
                row.append(f"[h at {top:+.2f} R]")
            print(f"C{k + 1} {superposition}: " + "; ".join(row), file=sys.stderr, flush=True)
    print("Largest |P_farm / P_farm,20x20 - 1| [%] over the 16 cases of "
          "benchmarks/matched_accuracy.py, one wind speed per run\n")
    print("| wakes | cells | shipped strips | strip edge at the layer top |")
    print("|---|---|---:|---:|")
    for superposition in ("summed", "cumulative"):
        for n in (2, 3):
            print(f"| {superposition} | {n} x {n} | {worst[superposition, n, 'shipped']:.2f} | "
                  f"{worst[superposition, n, 'edge at h']:.2f} |")


if __name__ == "__main__":
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the coarse-grid advice, the shallow-layer summary
        logging.disable(logging.WARNING)  # FLORIS's negative-velocity notice on 2 x 2 cells
        main()
