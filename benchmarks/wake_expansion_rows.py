"""How the farm couplings of M-1 change a farm's rows: power by row of a 10 x 10 farm (hand-run script).

    python -m benchmarks.wake_expansion_rows [--speed 8] [--direction 270]

Farm: 10 x 10 NREL 5 MW at 7 D (882 m), the wake settings of ``inputs/farm_sbl6.yaml``
(ekman_veer velocity and deflection, M-1; crespo_hernandez added turbulence; 3 x 3 rotor
points), wind along the rows (270 deg), one speed at 90 m. Atmospheres: neutral (the farm input's
with mu = 0) and SBL-6 (the farm input's, mu = 148.49); FLORIS's ambient TI set to the ABL's
I_u(z_h) (studies/comparison.py). Variants:

    ambient           k_w from the ABL's I_u(z_h), Eq. (kw_CNBL_SBL_model), as in the paper;
                      the wakes scaled with the free stream, their squares summed (sosfs);
    local_turbulence  alpha' times the ambient plus the largest upstream wake's added
                      turbulence at each turbine in the same smooth maximum (as FLORIS combines
                      it), otherwise as ``ambient``;
    array             the farm input's defaults: the upstream wakes' added turbulence summed in
                      quadrature, each waked rotor's wake scaled with its incoming speed, the
                      cumulative wake on fls (docs/coupling.md#wakes-deep-in-an-array);
    gauss             FLORIS's gauss velocity and deflection on the same inflow and TI (sosfs),
                      for reference (FLORIS's wake expansion grows with the local TI).

Prints, per atmosphere, the mean power of each row (row 1 faces the wind) relative to row 1, and
the farm's total relative to 100 unwaked turbines. The table of
docs/coupling.md#wake-expansion-in-farms comes from this script with its defaults.
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

from floris_ekman_veer.studies.comparison import builtin_inflow_settings  # noqa: E402
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning  # noqa: E402

FARM_INPUT = REPOSITORY / "inputs" / "farm_sbl6.yaml"
SIDE, SPACING = 10, 7 * 126.0
HUB_HEIGHT, ROTOR_DIAMETER = 90.0, 125.88
VARIANTS = ("ambient", "local_turbulence", "array", "gauss")
#: The free-stream couplings (FLORIS's gauss has the same).
FREE_STREAM = {"combination_model": "sosfs"}


def configuration(stability_parameter: float, variant: str, speed: float, direction: float):
    config = load_yaml(FARM_INPUT)
    x, y = np.meshgrid(np.arange(SIDE) * SPACING, np.arange(SIDE) * SPACING)
    config["farm"].update(layout_x=x.ravel().tolist(), layout_y=y.ravel().tolist())
    wake = config["wake"]
    block = wake["wake_velocity_parameters"]["ekman_veer"]
    block["atmosphere"].pop("cooling_rate", None)  # the input's own stability, replaced
    block["atmosphere"]["stability_parameter"] = stability_parameter
    turbulence = builtin_inflow_settings(block["atmosphere"], [speed], 90.0, HUB_HEIGHT,
                                         ROTOR_DIAMETER)["turbulence_intensities"]
    config["flow_field"].update(wind_speeds=[speed], wind_directions=[direction],
                                turbulence_intensities=turbulence.tolist())
    if variant == "gauss":
        wake["model_strings"].update(velocity_model="gauss", deflection_model="gauss",
                                     **FREE_STREAM)
        wake["wake_velocity_parameters"].setdefault(
            "gauss", dict(alpha=0.58, beta=0.077, ka=0.38, kb=0.004))
    elif variant != "array":  # "array": the farm input as it ships
        wake["model_strings"].update(**FREE_STREAM)
        block.update(wake_expansion=variant, deficit_velocity="free_stream")
    return config, float(turbulence[0])


def row_powers(config) -> np.ndarray:
    """Mean power of each row [W], row 1 facing a westerly wind (x = 0)."""
    fmodel = FlorisModel(config)
    fmodel.run()
    powers = fmodel.get_turbine_powers()[0]
    x = np.asarray(config["farm"]["layout_x"])
    return np.array([powers[np.isclose(x, i * SPACING)].mean() for i in range(SIDE)])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speed", type=float, default=8.0, help="wind speed at 90 m [m/s]")
    parser.add_argument("--direction", type=float, default=270.0, help="wind direction [deg]")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)  # SBL-6 at 8 m/s: h = 110 m
    for name, mu in (("neutral (mu = 0)", 0.0), ("SBL-6 (mu = 148.49)", 148.49)):
        table, unwaked = {}, None
        for variant in VARIANTS:
            config, turbulence = configuration(mu, variant, args.speed, args.direction)
            table[variant] = row_powers(config)
            single = copy.deepcopy(config)
            single["farm"].update(layout_x=[0.0], layout_y=[0.0])
            unwaked = row_powers_single(single) if unwaked is None else unwaked
        print(f"\n{name}, {args.speed:g} m/s at 90 m from {args.direction:g} deg, "
              f"I_u(z_h) = {turbulence:.3f} (FLORIS's ambient TI)")
        print("| row | " + " | ".join(VARIANTS) + " |")
        print("|---|" + "---|" * len(VARIANTS))
        for row in range(SIDE):
            print(f"| {row + 1} | " + " | ".join(
                f"{table[v][row] / table[v][0]:.3f}" for v in VARIANTS) + " |")
        print("| farm / 100 unwaked | " + " | ".join(
            f"{table[v].sum() * SIDE / (100 * unwaked):.3f}" for v in VARIANTS) + " |")


def row_powers_single(config) -> float:
    fmodel = FlorisModel(config)
    fmodel.run()
    return float(fmodel.get_turbine_powers()[0, 0])


if __name__ == "__main__":
    main()
