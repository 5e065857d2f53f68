"""ABL profiles of the paper's Table 1 cases (G = 15 m/s, z0 = 0.1 m, f_c = 1e-4 1/s,
N = 6.1e-3 1/s, Theta0 = 265 K), with the stability given by the LES cooling rates C_r.

Prints a summary for CNBL and SBL-6 and writes a figure of U(z), V(z) and the wind direction
change with height for CNBL and SBL-1..6:

    PYTHONPATH=. python examples/abl_profiles.py --output output
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from floris_ekman_veer.atmosphere.ekman import EkmanABL  # noqa: E402

PAPER = dict(geostrophic_wind=15.0, roughness_length=0.1, coriolis_parameter=1e-4,
             brunt_vaisala_frequency=6.1e-3, reference_potential_temperature=265.0)
COOLING_RATES = {"CNBL": 0.0, "SBL-1": -0.03, "SBL-2": -0.125, "SBL-3": -0.25,
                 "SBL-4": -0.375, "SBL-5": -0.5, "SBL-6": -1.0}  # K/h, paper Table 1
HUB_HEIGHT, ROTOR_BOTTOM, ROTOR_TOP = 100.0, 50.0, 150.0  # the paper's turbine, D = 100 m


def summary(name, abl):
    return (f"{name:6s} u* = {float(abl.friction_velocity):.3f} m/s  "
            f"h = {float(abl.boundary_layer_height):6.1f} m  "
            f"mu = {float(abl.stability_parameter):6.1f}  "
            f"alpha_0 = {float(abl.cross_isobaric_angle):6.2f} deg  "
            f"U_h(100 m) = {float(abl.speed(HUB_HEIGHT)):5.2f} m/s  "
            f"veer(50->150 m) = {float(abl.wind_direction_change(ROTOR_BOTTOM, ROTOR_TOP)):5.2f} deg  "
            f"I_u(z_h) = {float(abl.turbulence_intensity(HUB_HEIGHT)):.4f}  "
            f"k_w = {float(abl.wake_expansion_rate(HUB_HEIGHT)):.4f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--output", type=Path, default=Path("output"))
    output = parser.parse_args().output
    output.mkdir(parents=True, exist_ok=True)

    cases = {name: EkmanABL(**PAPER, cooling_rate=c_r) for name, c_r in COOLING_RATES.items()}
    print("Ekman-surface-layer ABL, paper Table 1 conditions, mu from the cooling rate:")
    for name in ("CNBL", "SBL-6"):
        print(summary(name, cases[name]))

    z = np.linspace(1.0, 1400.0, 1400)
    fig, axes = plt.subplots(1, 3, figsize=(12, 5), sharey=True)
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, len(cases)))
    for (name, abl), colour in zip(cases.items(), colours):
        u, v = abl.hub_aligned_velocity(z, HUB_HEIGHT)
        axes[0].plot(u, z, color=colour, label=name)
        axes[1].plot(v, z, color=colour)
        # direction change relative to hub height, positive = veering (clockwise)
        axes[2].plot(-np.rad2deg(np.arctan2(v, u)), z, color=colour)
    axes[0].set(xlabel="U (m/s)", ylabel="z (m)", ylim=(0, 1400))
    axes[1].set(xlabel="V (m/s)")
    axes[2].set(xlabel="wind direction - direction at 100 m (deg)")
    for ax in axes:
        ax.axhspan(ROTOR_BOTTOM, ROTOR_TOP, color="0.9", zorder=0)
        ax.grid(alpha=0.3)
    axes[0].legend()
    fig.suptitle("Ekman-surface-layer ABL (frame: x along the wind at 100 m; rotor shaded)")
    fig.tight_layout()
    path = output / "abl_profiles.png"
    fig.savefig(path, dpi=120)
    print(f"figure: {path}")


if __name__ == "__main__":
    main()
