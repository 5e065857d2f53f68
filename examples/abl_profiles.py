"""ABL profiles and turbulence of the paper's Table 1 cases, from the shipped inputs.

    python examples/abl_profiles.py [--output DIR] [--gallery DIR]

CNBL and SBL-1..6 (``inputs/cnbl.yaml``, ``inputs/sbl1.yaml`` ... ``inputs/sbl6.yaml``: G = 15 m/s,
z0 = 0.1 m, f_c = 1e-4 1/s, N = 6.1e-3 1/s, Theta0 = 265 K, Q0 = C_r h with the LES cooling rates
C_r), each ABL solved from the file's hub-height wind as FLORIS does. Prints per case C_r, U_h, u*,
h, mu, alpha_0, the veer across the rotor, I_u(z_h) and k_w, and writes to DIR (default ./output):

* ``abl_profiles.png``: U(z), V(z) (frame aligned with the hub-height wind), speed and wind
  direction relative to hub height, the ABL height h marked;
* ``turbulence_intensity.png``: I_u(z) of Eq. (Iu_model) per case (normalised by U_h, hub height
  marked) and k_w of Eq. (kw_CNBL_SBL_model) against I_u(z_h) (the paper's turbulence figure).

``--gallery DIR`` also writes a small copy of ``abl_profiles.png`` for the README (``docs/``).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from paper_cases import CASE_FILES, Case, arguments  # noqa: E402

from floris_ekman_veer.atmosphere.turbulence import (  # noqa: E402
    ALPHA_PRIME,
    MERGE_EXPONENT,
    MIXING_LAYER_FLOOR,
)


def case_table(cases: dict[str, Case]) -> dict[str, dict[str, float]]:
    """The numbers printed per case."""
    table = {}
    for name, case in cases.items():
        abl = case.abl
        table[name] = {
            "C_r": case.atmosphere["cooling_rate"], "U_h": case.hub_speed,
            "u*": float(abl.friction_velocity), "h": float(abl.boundary_layer_height),
            "mu": float(abl.stability_parameter), "alpha0": float(abl.cross_isobaric_angle),
            "veer": float(abl.wind_direction_change(case.hub_height - case.radius,
                                                    case.hub_height + case.radius)),
            "I_u": float(abl.turbulence_intensity(case.hub_height)), "k_w": case.k_w,
        }
    return table


def print_table(table: dict[str, dict[str, float]]) -> None:
    print("ABL of the paper's cases (G = 15 m/s, f_c = 1e-4 1/s, z0 = 0.1 m, N = 6.1e-3 1/s, "
          "Q0 = C_r h)")
    print(f"  {'case':<6}{'C_r':>7}{'U_h':>7}{'u*':>7}{'h':>7}{'mu':>8}{'alpha0':>8}"
          f"{'veer 50-150 m':>14}{'I_u(z_h)':>9}{'k_w':>8}")
    print(f"  {'':<6}{'[K/h]':>7}{'[m/s]':>7}{'[m/s]':>7}{'[m]':>7}{'[-]':>8}{'[deg]':>8}"
          f"{'[deg]':>14}{'[-]':>9}{'[-]':>8}")
    for name, row in table.items():
        print(f"  {name:<6}{row['C_r']:7.3f}{row['U_h']:7.2f}{row['u*']:7.3f}{row['h']:7.0f}"
              f"{row['mu']:8.1f}{row['alpha0']:8.1f}{row['veer']:14.1f}{row['I_u']:9.3f}"
              f"{row['k_w']:8.4f}")


def profiles(case: Case, z) -> tuple[np.ndarray, ...]:
    """U, V (frame of the hub-height wind), speed and direction relative to hub height [deg,
    + = veered, clockwise] at heights z."""
    u, v = case.abl.hub_aligned_velocity(np.asarray(z, float), case.hub_height)
    return u, v, np.hypot(u, v), -np.rad2deg(np.arctan2(v, u))


def profiles_figure(cases: dict[str, Case], output: Path, dpi: int = 90) -> Path:
    z = np.linspace(0.5, 1300.0, 1300)
    fig, axes = plt.subplots(1, 4, figsize=(15, 5.5), sharey=True, constrained_layout=True)
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, len(cases)))
    for (name, case), colour in zip(cases.items(), colours):
        h = float(case.abl.boundary_layer_height)
        for ax, values in zip(axes, profiles(case, z)):
            ax.plot(values, z, color=colour, label=f"{name} (h = {h:.0f} m)")
            ax.plot(np.interp(h, z, values), h, "o", color=colour, ms=5)
    for ax in axes:
        ax.axhspan(50.0, 150.0, color="0.88", zorder=0)
        ax.grid(alpha=0.3)
    axes[0].set(xlabel="U (m/s), along the hub-height wind", ylabel="z (m)", ylim=(0, 1300))
    axes[1].set_xlabel("V (m/s), to the left of the hub-height wind")
    axes[2].set_xlabel("speed (m/s)")
    axes[3].set_xlabel("direction - direction at z_h (deg), + = veered")
    axes[0].legend(fontsize=8, loc="upper left")
    fig.suptitle("Ekman-surface-layer ABL of the paper's cases, G = 15 m/s (dots: ABL height h; "
                 "shaded: rotor)")
    path = output / "abl_profiles.png"
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def turbulence_figure(cases: dict[str, Case], table, output: Path) -> Path:
    fig, axes = plt.subplots(1, 2, figsize=(12, 5), constrained_layout=True,
                             gridspec_kw=dict(width_ratios=(1.3, 1)))
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, len(cases)))
    for (name, case), colour in zip(cases.items(), colours):
        h = float(case.abl.boundary_layer_height)
        z = np.geomspace(1.0, 0.999 * h, 200)
        axes[0].semilogy(case.abl.turbulence_intensity(z, case.hub_height), z, color=colour,
                         label=name)
        axes[0].plot(table[name]["I_u"], case.hub_height, "o", color=colour)
        axes[1].plot(table[name]["I_u"], table[name]["k_w"], "o", color=colour, label=name)
    intensity = np.linspace(0.0, 0.16, 200)
    k_w = (MIXING_LAYER_FLOOR**MERGE_EXPONENT
           + (ALPHA_PRIME * intensity) ** MERGE_EXPONENT) ** (1.0 / MERGE_EXPONENT)
    axes[1].plot(intensity, k_w, "k-", lw=1, label="Eq. (kw_CNBL_SBL_model)")
    axes[0].set(xlabel=r"$I_u(z)$ (Eq. Iu_model, over $U_h$)", ylabel="z (m)", ylim=(1, 1300))
    axes[1].set(xlabel=r"$I_u(z_h)$", ylabel=r"$k_w$")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Turbulence intensity (dots: hub height) and the wake expansion rate")
    path = output / "turbulence_intensity.png"
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def main(argv=None) -> None:
    args = arguments(__doc__, argv)
    cases = {name: Case(name) for name in CASE_FILES}
    table = case_table(cases)
    print_table(table)
    paths = [profiles_figure(cases, args.output), turbulence_figure(cases, table, args.output)]
    if args.gallery is not None:
        paths.append(profiles_figure(cases, args.gallery, dpi=60))
    for path in paths:
        print(f"figure: {path}")


if __name__ == "__main__":
    main()
