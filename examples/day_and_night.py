"""The shipped day and night, condition by condition: the forcing each input names and what it
implies at every wind speed (docs/atmosphere.md#convective-boundary-layer,
docs/yaw_steering.md#the-validated-envelope).

``inputs/farm_day.yaml`` is a convective afternoon named by its surface heat flux (+150 W/m^2)
and mixed-layer depth (1500 m); ``inputs/farm_night.yaml`` a stable night named by its Obukhov
length (100 m). For each, at 3-25 m/s at 90 m, this prints the boundary-layer height, the
Obukhov length, the implied surface sensible heat flux, the friction Rossby number, the
stability class, the veer across the NREL 5 MW rotor, I_u(90 m) and whether the condition lies
inside the paper's validated envelope (floris_ekman_veer.validity_report), then the farm power
of FLORIS's gauss and the package's ekman_veer on the day's inflow (same inflow hook).

Run: python examples/day_and_night.py
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from floris import FlorisModel

import floris_ekman_veer
from floris_ekman_veer.coupling.shallow import ShallowBoundaryLayerWarning

INPUTS = Path(__file__).resolve().parents[1] / "inputs"
SPEEDS = [3.0, 4.0, 6.0, 8.0, 10.0, 11.0, 12.0, 15.0, 19.5, 25.0]


def farm(name: str, speeds=SPEEDS) -> FlorisModel:
    fmodel = FlorisModel(INPUTS / f"{name}.yaml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        fmodel.set(wind_speeds=speeds, wind_directions=[270.0] * len(speeds),
                   turbulence_intensities=[0.06] * len(speeds))
    return fmodel


def table(name: str, speeds=SPEEDS):
    """validity_report of the input ``name`` at ``speeds`` (wind from 270 deg)."""
    return floris_ekman_veer.validity_report(farm(name, speeds))


def farm_powers(name: str, speeds=SPEEDS) -> dict[str, np.ndarray]:
    """Farm power [MW] per speed of FLORIS's gauss and of ekman_veer on the input's inflow."""
    out = {}
    for model in ("gauss", "ekman_veer"):
        fmodel = farm(name, speeds)
        if model == "gauss":
            config = fmodel.core.as_dict()
            config["wake"]["model_strings"].update(velocity_model="gauss", deflection_model="gauss")
            fmodel = FlorisModel(config)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
            fmodel.run()
        out[model] = fmodel.get_farm_power() / 1e6
    return out


def main():
    columns = ["wind_speed", "boundary_layer_height", "obukhov_length", "sensible_heat_flux",
               "friction_rossby_number", "stability_class", "veer_across_rotor_deg",
               "turbulence_intensity", "inside_envelope"]
    for name in ("farm_day", "farm_night"):
        report = table(name)
        print(f"\n{name}:")
        with np.printoptions(precision=3):
            print(report[columns].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    powers = farm_powers("farm_day")
    print("\nfarm_day farm power [MW] (wind from 270 deg):")
    for speed, gauss, ekman in zip(SPEEDS, powers["gauss"], powers["ekman_veer"]):
        print(f"  {speed:5.1f} m/s  gauss {gauss:7.3f}  ekman_veer {ekman:7.3f}")


if __name__ == "__main__":
    main()
