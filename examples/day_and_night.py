"""The shipped day and night, condition by condition: the forcing each input names and what it
implies at every wind speed (docs/atmosphere.md#convective-boundary-layer,
docs/yaw_steering.md#the-validated-envelope).

``inputs/farm_day.yaml`` is a convective afternoon named by its surface heat flux (+150 W/m^2)
and mixed-layer depth (1500 m); ``inputs/farm_night.yaml`` a stable night named by its surface
cooling rate (-0.25 K/h, the paper's SBL-3); ``inputs/farm_sbl6.yaml`` the paper's SBL-6 by its
cooling rate (-1 K/h). For each, at 3-25 m/s at 90 m, this prints the boundary-layer height, the
Obukhov length, the implied surface sensible heat flux, the friction Rossby number, the
stability class, the veer across the NREL 5 MW rotor, I_u(90 m) and whether the condition lies
inside the paper's validated envelope (floris_ekman_veer.validity_report), then the farm power
of FLORIS's gauss and the package's ekman_veer on the day's inflow (same inflow hook). Last, the
convective layer against the paper's CNBL at 8 m/s at 90 m: how it departs from it as L goes
from -1e5 m to -30 m, with z_i the default (the neutral height) and 1500 m, and the geostrophic
drag law's A and B over that range (docs/atmosphere.md#the-geostrophic-drag-law-of-a-convective-layer).

Run: python examples/day_and_night.py
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from floris import FlorisModel

import floris_ekman_veer
from floris_ekman_veer import EkmanABL
from floris_ekman_veer.atmosphere.ekman import gdl_coefficients
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning

INPUTS = Path(__file__).resolve().parents[1] / "inputs"
#: The site of the shipped inputs and the paper's cases.
SITE = dict(coriolis_parameter=1e-4, roughness_length=0.1, brunt_vaisala_frequency=6.1e-3,
            reference_potential_temperature=265.0)
#: Convective Obukhov lengths of the sweep: near-neutral to about +350 W/m^2 at 8 m/s at 90 m.
OBUKHOV_LENGTHS = [-1e5, -1e3, -300.0, -150.0, -100.0]
#: Obukhov lengths of the drag-law table, with the labels the page prints them by.
#: To -30 m (733 W/m^2 at 8 m/s at 90 m): -10 m would need 3.5 kW/m^2, outside the physical
#: domain (docs/atmosphere.md#physical-domain).
DRAG_LAW_LENGTHS = {-1e5: "-1e5", -1e4: "-1e4", -1e3: "-1000", -300.0: "-300", -100.0: "-100",
                    -30.0: "-30"}
#: Cut-in to cut-out: the cooling rates stay inside the physical domain (farm_sbl6's -1 K/h is
#: carried at H = -300 W/m^2 from 21 m/s, its outside_domain: limit; stability_limited).
SPEEDS = [3.0, 4.0, 6.0, 8.0, 9.0, 10.0, 11.0, 12.0, 15.0, 19.0, 25.0]


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
            config["wake"]["model_strings"].update(velocity_model="gauss", deflection_model="gauss",
                                                   combination_model="sosfs")  # FLORIS's own
            fmodel = FlorisModel(config)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
            fmodel.run()
        out[model] = fmodel.get_farm_power() / 1e6
    return out


def convective_sweep(speed=8.0, height=90.0, mixed_layer_height=None):
    """Rows (L, u*, h, cross-isobaric angle, I_u(90 m), k_w(90 m), veer and speed ratio across a
    27-153 m rotor, sensible heat flux [W/m^2]) for the CNBL (L = inf) and each of OBUKHOV_LENGTHS, driven by ``speed`` at
    ``height``, all solved at once."""
    lengths = np.array([np.inf] + OBUKHOV_LENGTHS)
    extra = {} if mixed_layer_height is None else {"mixed_layer_height": mixed_layer_height}
    abl = EkmanABL.from_reference_wind(speed, height, obukhov_length=lengths, **SITE, **extra)
    return np.column_stack([
        lengths, abl.friction_velocity, abl.boundary_layer_height, abl.cross_isobaric_angle,
        abl.turbulence_intensity(height), abl.wake_expansion_rate(height),
        abl.wind_direction_change(27.0, 153.0), abl.speed(153.0) / abl.speed(27.0),
        abl.sensible_heat_flux + 0.0,  # (+ 0.0: no "-0.0" for the neutral row)
    ])


def cnbl_limit(length=-1e5, speed=8.0, height=90.0):
    """Largest relative differences from the paper's CNBL at L = ``length``: u*, h, U and V on
    1-1000 m (relative to the speed at ``height``), k_w(90 m)."""
    heights = np.array([1.0, 10.0, 50.0, 90.0, 150.0, 300.0, 600.0, 1000.0])
    cnbl = EkmanABL.from_reference_wind(speed, height, **SITE)
    near = EkmanABL.from_reference_wind(speed, height, obukhov_length=length, **SITE)
    (u0, v0), (u1, v1) = cnbl.velocity(heights), near.velocity(heights)
    return {
        "u*": near.friction_velocity / cnbl.friction_velocity - 1,
        "h": near.boundary_layer_height / cnbl.boundary_layer_height - 1,
        "U": np.max(np.abs(u1 - u0)) / speed, "V": np.max(np.abs(v1 - v0)) / speed,
        "k_w": near.wake_expansion_rate(height) / cnbl.wake_expansion_rate(height) - 1,
    }


def drag_law_sweep(mixed_layer_height=None, speed=8.0, height=90.0):
    """Rows (L, sensible heat flux [W/m^2], mu, A, A - A_N, B, alpha_0 [deg]) of the geostrophic
    drag law for the CNBL (L = inf) and each of DRAG_LAW_LENGTHS, driven by ``speed`` at
    ``height``. A_N is Eq. (A_model_GDL) at mu = 0 with the same h_hat and surface Rossby number:
    A - A_N is the stability dependence of A alone."""
    lengths = np.array([np.inf, *DRAG_LAW_LENGTHS])
    extra = {} if mixed_layer_height is None else {"mixed_layer_height": mixed_layer_height}
    abl = EkmanABL.from_reference_wind(speed, height, obukhov_length=lengths, **SITE, **extra)
    neutral_a, _ = gdl_coefficients(
        0.0, abl.zilitinkevich_number, abl.h_hat, abl.friction_rossby_number, abl.von_karman,
        abl.c_g, abl.stress_decay, abl.matching_fraction, abl.businger_dyer_gamma)
    return np.column_stack([
        lengths, abl.sensible_heat_flux + 0.0, abl.stability_parameter + 0.0, abl.gdl_a,
        abl.gdl_a - neutral_a, abl.gdl_b, abl.cross_isobaric_angle,
    ])


def deep_mixed_layer(speed=8.0):
    """The deep mixed layer's weak shear and veer: (z_i = 2000 m, L = -20 m) and the CNBL at
    G = ``speed``: speed ratio across a 27-153 m rotor minus 1, turning of the wind from 0.2 h to
    h [deg], cross-isobaric angle [deg]."""
    out = {}
    for name, extra in (("CNBL", {}), ("z_i 2000 m, L -20 m",
                                       dict(obukhov_length=-20.0, mixed_layer_height=2000.0))):
        abl = EkmanABL(geostrophic_wind=speed, **SITE, **extra)
        h = float(abl.boundary_layer_height)
        out[name] = (float(abl.speed(153.0) / abl.speed(27.0) - 1),
                     float(abl.wind_direction_change(0.2 * h, h)), float(abl.cross_isobaric_angle))
    return out


def main():
    columns = ["wind_speed", "boundary_layer_height", "obukhov_length", "sensible_heat_flux",
               "friction_rossby_number", "stability_class", "veer_across_rotor_deg",
               "turbulence_intensity", "inside_envelope", "stability_limited"]
    for name in ("farm_day", "farm_night", "farm_sbl6"):
        report = table(name)
        print(f"\n{name}:")
        with np.printoptions(precision=3):
            print(report[columns].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    powers = farm_powers("farm_day")
    print("\nfarm_day farm power [MW] (wind from 270 deg):")
    for speed, gauss, ekman in zip(SPEEDS, powers["gauss"], powers["ekman_veer"]):
        print(f"  {speed:5.1f} m/s  gauss {gauss:7.3f}  ekman_veer {ekman:7.3f}")
    for z_i in (None, 1500.0):
        label = "the neutral height (default)" if z_i is None else f"{z_i:g} m"
        print(f"\nConvective layers at 8 m/s at 90 m, z_i = {label}:")
        print("       L [m]   u* [m/s]   h [m]  alpha0 [deg]  I_u(90)  k_w(90)  veer 27-153 [deg]"
              "  U(153)/U(27)  H [W/m^2]")
        for row in convective_sweep(mixed_layer_height=z_i):
            print(f"  {row[0]:10.4g}  {row[1]:8.4f}  {row[2]:7.1f}  {row[3]:11.2f}  {row[4]:7.4f}"
                  f"  {row[5]:7.4f}  {row[6]:16.2f}  {row[7]:12.4f}  {row[8]:9.1f}")
    default, deep = drag_law_sweep(), drag_law_sweep(mixed_layer_height=1500.0)
    print("\nDrag-law coefficients at 8 m/s at 90 m: L [m], H [W/m^2], mu, then A, A - A_N, B, "
          "alpha0 [deg] with the default z_i, then A, B, alpha0 [deg] with z_i = 1500 m")
    for row, other in zip(default, deep):
        label = "inf" if np.isinf(row[0]) else DRAG_LAW_LENGTHS[row[0]]
        print(f"  {label:>6s}  {row[1]:7.0f}  {row[2]:8.2f}  {row[3]:6.3f}  {row[4]:6.3f}  "
              f"{row[5]:6.3f}  {row[6]:6.1f}  {other[3]:6.3f}  {other[5]:6.3f}  {other[6]:6.1f}")
    print("\nDeep mixed layer against the CNBL (G = 8 m/s): rotor shear U(153)/U(27) - 1, turning "
          "0.2 h to h [deg], cross-isobaric angle [deg]")
    for name, (shear, turn, angle) in deep_mixed_layer().items():
        print(f"  {name:22s} {shear:.3f}  {turn:.1f}  {angle:.1f}")
    limit = cnbl_limit()
    print("\nAt L = -1e5 m against the CNBL (8 m/s at 90 m): "
          + ", ".join(f"{k} {100 * v:+.3f} %" for k, v in limit.items()))


if __name__ == "__main__":
    main()
