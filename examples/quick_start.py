"""Quick start: your FLORIS input with veer (docs/user_guide.md#your-floris-input-with-veer).

FLORIS's own default input (GCH on the NREL 5 MW) turned into an ``ekman_veer`` input: the two
model names, the wakes summed (``combination_model: fls``), the atmosphere once, GCH's switches
off. Then what veer changes (the same run with
the veer offset switched off: the paper's M-2) and what GCH's switches would add behind a yawed
rotor if left on (FLORIS's own vortex model on top of the ekman_veer wake).

    python examples/quick_start.py
"""

from __future__ import annotations

import warnings

import numpy as np
from floris import FlorisModel

import floris_ekman_veer

LAYOUT = dict(layout_x=[0.0, 630.0, 1260.0], layout_y=[0.0, 0.0, 0.0])  # a row at 5 D
CONDITIONS = dict(wind_directions=[270.0, 270.0], wind_speeds=[8.0, 10.0],
                  turbulence_intensities=[0.06, 0.06])
#: A moderately stable night at 52 degrees N: 0.25 K/h of surface cooling over grass.
ATMOSPHERE = {"latitude": 52.0, "roughness_length": 0.1, "cooling_rate": -0.25}
GCH_SWITCHES = ("enable_secondary_steering", "enable_yaw_added_recovery",
                "enable_transverse_velocities")


def veer_input(gch: bool = False, veer: bool = True) -> dict:
    """FLORIS's default input with the ekman_veer models and the atmosphere."""
    config = FlorisModel.get_defaults()
    config["wake"]["model_strings"].update(velocity_model="ekman_veer",
                                           deflection_model="ekman_veer", combination_model="fls")
    config["wake"]["wake_velocity_parameters"]["ekman_veer"] = {"atmosphere": ATMOSPHERE}
    if not veer:
        config["wake"]["wake_deflection_parameters"]["ekman_veer"] = {"veer": False}
    config["wake"].update({name: gch for name in GCH_SWITCHES})
    config["flow_field"].update(reference_wind_height=90.0, wind_shear=0.0)  # the atmosphere's
    return config


def powers(config: dict, yaw_first: float = 0.0) -> np.ndarray:
    """Turbine powers [kW] of the row, (conditions, turbines)."""
    fmodel = FlorisModel(config)
    fmodel.set(**LAYOUT, **CONDITIONS,
               yaw_angles=np.array([[yaw_first, 0.0, 0.0]] * len(CONDITIONS["wind_speeds"])))
    fmodel.run()
    return fmodel.get_turbine_powers() / 1e3


def table(title: str, values: np.ndarray) -> None:
    print(title)
    print("  U(90 m)   turbine 1   turbine 2   turbine 3   [kW]")
    for speed, row in zip(CONDITIONS["wind_speeds"], values):
        print(f"  {speed:4.1f} m/s " + "".join(f"{p:12.1f}" for p in row))


def main() -> None:
    m1 = powers(veer_input())
    table("ekman_veer (M-1: veer on)", m1)
    table("ekman_veer, veer off (M-2)", powers(veer_input(veer=False)))
    abl = floris_ekman_veer.EkmanABL.from_reference_wind(
        np.array(CONDITIONS["wind_speeds"]), 90.0, **ATMOSPHERE)
    for speed, h, veer in zip(CONDITIONS["wind_speeds"], abl.boundary_layer_height,
                              abl.wind_direction_change(27.0, 153.0)):
        print(f"  {speed:g} m/s: h = {h:.0f} m, veer across the rotor {veer:.1f} deg")
    yawed = powers(veer_input(), yaw_first=20.0)
    with warnings.catch_warnings():
        # the warning says what the switches do; this script shows it in numbers
        warnings.simplefilter("ignore", floris_ekman_veer.ModelSettingsWarning)
        yawed_gch = powers(veer_input(gch=True), yaw_first=20.0)
    table("first turbine yawed 20 deg, GCH's switches off", yawed)
    table("first turbine yawed 20 deg, GCH's switches on (not the paper's model)", yawed_gch)
    change = 100.0 * (yawed_gch[:, 1:].sum(axis=1) / yawed[:, 1:].sum(axis=1) - 1.0)
    print("  waked turbines with the switches on: "
          + ", ".join(f"{c:+.1f} % at {s:g} m/s" for c, s in zip(change, CONDITIONS["wind_speeds"])))


if __name__ == "__main__":
    main()
