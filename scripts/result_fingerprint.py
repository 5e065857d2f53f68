"""The bits of three results, to compare two versions of the package that should not differ:

* the main job's farm powers: ``inputs/farm_sbl6.yaml`` (3 x 3 NREL 5 MW, SBL-6) with the
  ekman_veer models (M-1), with the veer deflection off (M-2) and with FLORIS's gauss on the same
  inflow, at 8, 9 and 11 m/s from 270 deg and over 255..285 deg at 9 m/s;
* a yaw optimisation: ``floris_ekman_veer.optimize_yaw`` with FLORIS's ``YawOptimizationSR`` on
  the first row of that farm at 9 and 11 m/s;
* a site fit: ``floris_ekman_veer.fit_site`` on ``inputs/site/synthetic_mast.csv`` and the farm's
  powers on the fitted records.

Only the package's public API is used, so the script runs on any version of the tree:

    PYTHONPATH=$PWD python scripts/result_fingerprint.py

It prints one sha256 per result (of the arrays' bytes, float64, C order) and one of all three;
two trees give the same bits when the lines are the same.
"""

from __future__ import annotations

import copy
import hashlib
import warnings
from pathlib import Path

import numpy as np

import pandas as pd
from floris import FlorisModel
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR
from floris.utilities import load_yaml

import floris_ekman_veer  # the tree on PYTHONPATH, else the installed one (printed at the end)

REPOSITORY = Path(__file__).resolve().parent.parent

FARM = REPOSITORY / "inputs" / "farm_sbl6.yaml"
MAST = REPOSITORY / "inputs" / "site" / "synthetic_mast.csv"


def digest(*arrays) -> str:
    sha = hashlib.sha256()
    for array in arrays:
        array = np.ascontiguousarray(np.asarray(array, dtype=np.float64))
        sha.update(str(array.shape).encode())
        sha.update(array.tobytes())
    return sha.hexdigest()


def model(config: dict, name: str) -> FlorisModel:
    config = copy.deepcopy(config)
    if name == "M-2":
        config["wake"].setdefault("wake_deflection_parameters", {}).setdefault(
            "ekman_veer", {})["veer"] = False
    elif name == "gauss":
        config["wake"]["model_strings"].update(velocity_model="gauss", deflection_model="gauss")
    return FlorisModel(config)


def farm_powers(config: dict) -> list[np.ndarray]:
    directions = np.r_[[270.0] * 3, np.arange(255.0, 285.1, 5.0)]
    speeds = np.r_[8.0, 9.0, 11.0, [9.0] * 7]
    abl = floris_ekman_veer.EkmanABL.from_reference_wind(
        speeds, config["flow_field"]["reference_wind_height"],
        **config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"])
    turbulence = np.asarray(abl.turbulence_intensity(config["flow_field"]["reference_wind_height"]),
                            dtype=float).reshape(-1)
    out = []
    for name in ("M-1", "M-2", "gauss"):
        fmodel = model(config, name)
        fmodel.set(wind_directions=directions, wind_speeds=speeds,
                   turbulence_intensities=np.broadcast_to(turbulence, speeds.shape).copy())
        fmodel.run()
        out.append(fmodel.get_turbine_powers())
    return out


def yaw_optimisation(config: dict) -> list[np.ndarray]:
    fmodel = model(config, "M-1")
    fmodel.set(layout_x=[0.0, 882.0, 1764.0], layout_y=[0.0, 0.0, 0.0],
               wind_directions=[270.0, 270.0], wind_speeds=[9.0, 11.0],
               turbulence_intensities=[0.03, 0.03])
    df = floris_ekman_veer.optimize_yaw(fmodel, YawOptimizationSR, minimum_yaw_angle=-25.0,
                                        maximum_yaw_angle=25.0, Ny_passes=[5, 4], progress=False)
    return [np.vstack(df["yaw_angles_opt"].to_numpy()), df["farm_power_opt"].to_numpy()]


def site_fit(config: dict) -> list[np.ndarray]:
    records = pd.read_csv(MAST, comment="#")
    site = floris_ekman_veer.fit_site(records, 90.0, stability_input="obukhov_length",
                                      stability="either", latitude=52.0, roughness_length=0.05,
                                      speed_noise=0.1, direction_noise=0.5)
    fit = site.profile_fit
    fmodel = model(config, "M-1")
    site.apply(fmodel)
    fmodel.run()
    return [site.wind_speeds, site.wind_directions, site.turbulence_intensities,
            fit.obukhov_length, fit.boundary_layer_height, fit.misfit, fmodel.get_turbine_powers()]


def main() -> None:
    config = load_yaml(FARM)
    with warnings.catch_warnings():
        # the warnings are the same in both trees; only the numbers are compared
        warnings.simplefilter("ignore")
        results = {"farm powers": farm_powers(config), "yaw optimisation": yaw_optimisation(config),
                   "site fit": site_fit(config)}
    everything = hashlib.sha256()
    for name, arrays in results.items():
        value = digest(*arrays)
        everything.update(value.encode())
        print(f"{name:17s} {value}")
    print(f"{'all':17s} {everything.hexdigest()}")
    print(f"(package: {floris_ekman_veer.__file__})")


if __name__ == "__main__":
    main()
