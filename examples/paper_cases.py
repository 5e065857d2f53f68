"""The single-turbine cases of Narasimhan, Gayme & Meneveau (JRSE 2025), run through FLORIS.

    python examples/paper_cases.py [--output DIR]

Cases (paper Table 1; actuator disk C_T' = 1.33, D = z_h = 100 m, G = 15 m/s, f_c = 1e-4 1/s,
z0 = 0.1 m, N = 6.1e-3 1/s, Theta0 = 265 K, Q0 = C_r h): CNBL (``inputs/cnbl.yaml``, C_r = 0),
SBL-6 (``inputs/sbl6.yaml``, C_r = -1 K/h) and SBL-4, SBL-5 (``inputs/sbl6.yaml`` with C_r = -0.375
and -0.5 K/h). FLORIS drives the ABL by the wind speed at its reference height, so for every case
that speed is set to |(U, V)(z_h)| of the ABL with G = 15 m/s. The turbulence intensity is set to
the atmosphere's I_u(z_h) (the ekman_veer models do not use it: they take k_w from the ABL).

Models (paper Section 4.4): M-1 = ``ekman_veer`` velocity + deflection; M-2 = the same with the
veer deflection off; M-3 = ``bastankhah2014`` (Bastankhah & Porte-Agel 2014) with no deflection
(a zero deflection model defined here: FLORIS's ``none`` refuses yawed turbines); behind a yawed
disk M-3 only sees its thrust coefficient.
Yaw beta = 0, +20, -20 deg (FLORIS's positive yaw = the paper's positive beta: wake to -y).

Prints the ABL of each case and, per case and yaw, the thrust coefficient the wake sees, x0/D
(Eq. x0_transition), C(x) = Delta u_max/U_h at 5 D and 10 D (Eq. Cx; at 10 D also read back from
FLORIS) and the wake centre y_c/D at 10 D (position of the largest deficit sampled through FLORIS)
at hub height and half a radius below/above it. Writes to DIR (default ./output):

* ``paper_cross_planes_SBL-6_beta{0,+20,-20}.png``: Delta u/U_h at x/D = 4, 6, 8, 10 for M-1,
  M-2, M-3 in SBL-6 (like the paper's figure u_yaw0_SBL4_M1M2M3), FLORIS cross planes;
* ``paper_power_ratio_beta{0,+20,-20}.png``: P/P0 vs y_T/D at x_T/D = 4, 6, 8, 10 (Eq. P_ratio:
  the cube of the average of U(z) - Delta u over a disk of radius R centred at (x_T, y_T, z_h),
  over U_h^3), M-1/M-2/M-3 in CNBL and SBL-6, the disk average by a polar Gauss quadrature of
  FLORIS's sample_flow_at_points, all disks of one model and yaw in one call;
* ``paper_abl_profiles.png``: U(z), V(z) (hub-aligned frame) and the direction change.
"""

from __future__ import annotations

import argparse
import copy
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

REPOSITORY = Path(__file__).resolve().parent.parent
try:
    import floris_ekman_veer  # noqa: F401  (registers the models and the Ekman inflow hook)
except ImportError:  # run from a checkout without installing
    sys.path.insert(0, str(REPOSITORY))
    import floris_ekman_veer  # noqa: F401

from floris import FlorisModel  # noqa: E402
from floris.cut_plane import rescale_axis  # noqa: E402
from floris.flow_visualization import visualize_cut_plane  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

from floris_ekman_veer import EkmanABL  # noqa: E402
from floris_ekman_veer.wake.deficit import max_deficit, potential_core_length  # noqa: E402

INPUTS = REPOSITORY / "inputs"
GEOSTROPHIC_WIND = 15.0
#: case -> (input file, cooling rate C_r [K/h] replacing the file's, or None to keep it)
CASES = {
    "CNBL": ("cnbl.yaml", None),
    "SBL-4": ("sbl6.yaml", -0.375),
    "SBL-5": ("sbl6.yaml", -0.5),
    "SBL-6": ("sbl6.yaml", None),
}
MODELS = ("M-1", "M-2", "M-3")
STYLE = {"M-1": dict(color="m", ls="-."), "M-2": dict(color="b", ls="-"),
         "M-3": dict(color="c", ls=":")}
BETAS = (0.0, 20.0, -20.0)
X_OVER_D = (4.0, 6.0, 8.0, 10.0)
Y_T_OVER_D = np.linspace(-4.0, 4.0, 161)
#: Disk quadrature of Eq. P_ratio: Gauss-Legendre in r (weight r) x uniform in theta.
#: 16 x 48 points: P/P0 within 1e-4 of a 48 x 128 rule, also for the thin sheared SBL-6 wake.
DISK_RADIAL, DISK_ANGULAR = 16, 48


# ----------------------------------------------------------------------------------- set-up
class Case:
    """One paper case: its FLORIS input (per model) and its ABL."""

    def __init__(self, name: str):
        self.name = name
        file, cooling_rate = CASES[name]
        config = load_yaml(INPUTS / file)
        atmosphere = config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
        if cooling_rate is not None:
            atmosphere["cooling_rate"] = cooling_rate
        self.atmosphere = dict(atmosphere)
        turbine = config["farm"]["turbine_type"][0]
        self.diameter = float(turbine["rotor_diameter"])
        self.radius = 0.5 * self.diameter
        self.hub_height = float(turbine["hub_height"])
        self.reference_height = float(config["flow_field"]["reference_wind_height"])
        # The paper fixes G = 15 m/s; FLORIS is driven by the speed at its reference height.
        self.abl = EkmanABL(geostrophic_wind=GEOSTROPHIC_WIND, **self.atmosphere)
        self.wind_speed = float(self.abl.speed(self.reference_height))
        self.hub_speed = float(self.abl.speed(self.hub_height))
        self.turbulence = float(self.abl.turbulence_intensity(self.hub_height))
        self.k_w = float(self.abl.wake_expansion_rate(self.hub_height))
        config["flow_field"]["wind_speeds"] = [self.wind_speed]
        config["flow_field"]["wind_directions"] = [270.0]
        config["flow_field"]["turbulence_intensities"] = [self.turbulence]
        self.config = config
        self._models: dict[str, FlorisModel] = {}
        self._yaw: dict[str, float] = {}

    def model(self, name: str, beta: float = 0.0) -> FlorisModel:
        """FLORIS model ``name`` with the turbine yawed by ``beta`` [deg] (FLORIS's set() rebuilds
        the whole model, so it is called only when the yaw changes)."""
        if name not in self._models:
            config = copy.deepcopy(self.config)
            wake = config["wake"]
            if name == "M-2":
                wake["wake_deflection_parameters"]["ekman_veer"]["veer"] = False
            elif name == "M-3":
                wake["model_strings"]["velocity_model"] = "bastankhah2014"
                # M-3 has neither yaw nor veer deflection, also behind a yawed rotor.
                wake["wake_deflection_parameters"]["ekman_veer"].update(
                    veer=False, yaw_deflection=False
                )
                wake["wake_velocity_parameters"].setdefault("bastankhah2014", {})
            self._models[name] = FlorisModel(config)
        fmodel = self._models[name]
        if self._yaw.get(name) != beta:
            fmodel.set(yaw_angles=np.array([[beta]]))
            self._yaw[name] = beta
        return fmodel

    def ambient(self, z) -> np.ndarray:
        """Hub-aligned ambient U(z) (FLORIS's inflow: the reference height is the hub height)."""
        u, _ = self.abl.hub_aligned_velocity(np.asarray(z, float), self.reference_height,
                                             below_roughness="zero")
        return u

    def thrust_coefficient(self, beta: float) -> float:
        """The un-yawed-basis C_T the wake models use: FLORIS's ct_i / cos(beta)."""
        fmodel = self.model("M-1", beta)
        fmodel.run()
        ct_i = float(fmodel.get_turbine_thrust_coefficients()[0, 0])
        return ct_i / np.cos(np.deg2rad(beta))


# ----------------------------------------------------------------------------------- printing
def print_abl(cases: dict[str, Case]) -> None:
    print(f"ABL of the paper's cases (G = {GEOSTROPHIC_WIND:g} m/s, f_c = 1e-4 1/s, z0 = 0.1 m, "
          "N = 6.1e-3 1/s, Q0 = C_r h)")
    print(f"  {'case':<6}{'C_r':>7}{'U_h':>7}{'u*':>7}{'h':>7}{'mu':>8}{'alpha0':>8}"
          f"{'veer 50-150 m':>14}{'I_u(z_h)':>9}{'k_w':>8}")
    print(f"  {'':<6}{'[K/h]':>7}{'[m/s]':>7}{'[m/s]':>7}{'[m]':>7}{'[-]':>8}{'[deg]':>8}"
          f"{'[deg]':>14}{'[-]':>9}{'[-]':>8}")
    for case in cases.values():
        abl = case.abl
        veer = float(abl.wind_direction_change(case.hub_height - case.radius,
                                               case.hub_height + case.radius))
        print(f"  {case.name:<6}{case.atmosphere['cooling_rate']:7.3f}{case.hub_speed:7.2f}"
              f"{float(abl.friction_velocity):7.3f}{float(abl.boundary_layer_height):7.0f}"
              f"{float(abl.stability_parameter):8.1f}{float(abl.cross_isobaric_angle):8.1f}"
              f"{veer:14.1f}{case.turbulence:9.3f}{case.k_w:8.4f}")


def wake_centres(case: Case, fmodel: FlorisModel, x: float, heights) -> tuple[np.ndarray, np.ndarray]:
    """(y_c, Delta u_max/U_h) at each height: the largest deficit along y, sampled through FLORIS
    on a 0.005 D grid over +-3 D and refined by a parabola through the three best points."""
    dy = 0.005 * case.diameter
    y = np.arange(-3.0 * case.diameter, 3.0 * case.diameter + 0.5 * dy, dy)
    heights = np.asarray(heights, float)
    yy, zz = np.meshgrid(y, heights)
    u = fmodel.sample_flow_at_points(np.full(yy.size, x), yy.ravel(), zz.ravel())[0]
    deficit = ((case.ambient(zz) - u.reshape(zz.shape)) / case.hub_speed)
    centres, peaks = [], []
    for row in deficit:
        i = int(np.clip(np.argmax(row), 1, row.size - 2))
        a, b, c = row[i - 1], row[i], row[i + 1]
        curvature = a - 2.0 * b + c
        shift = 0.5 * (a - c) / curvature if curvature < 0 else 0.0
        centres.append(y[i] + shift * dy)
        peaks.append(b - 0.25 * (a - c) * shift)
    return np.array(centres), np.array(peaks)


def print_wake_table(cases: dict[str, Case]) -> None:
    D_heights = (-0.25, 0.0, 0.25)  # (z - z_h)/D: half a radius below, hub, half a radius above
    print("\nWake of the yawed disk (M-1; beta > 0 sends the wake to -y; C_T: the un-yawed-basis "
          "thrust coefficient FLORIS's actuator disk hands the wake)")
    print(f"  {'case':<6}{'beta':>6}{'C_T':>7}{'x0/D':>7}{'C(5D)':>8}{'C(10D)':>8}"
          f"{'FLORIS':>8}   {'y_c/D at 10 D: z_h-R/2':>23}{'z_h':>7}{'z_h+R/2':>9}")
    for case in cases.values():
        for beta in BETAS:
            yaw = np.deg2rad(beta)
            ct = case.thrust_coefficient(beta)
            x0 = potential_core_length(case.k_w, case.radius, ct, yaw) / case.diameter
            c5, c10 = (float(max_deficit(n * case.diameter, case.k_w, case.radius, ct, yaw))
                       for n in (5.0, 10.0))
            heights = case.hub_height + np.array(D_heights) * case.diameter
            centres, peaks = wake_centres(case, case.model("M-1", beta), 10.0 * case.diameter,
                                          heights)
            yc = centres / case.diameter
            print(f"  {case.name:<6}{beta:+6.0f}{ct:7.4f}{x0:7.2f}{c5:8.4f}{c10:8.4f}"
                  f"{peaks[1]:8.4f}   {yc[0]:+23.3f}{yc[1]:+7.3f}{yc[2]:+9.3f}")
    print("  (FLORIS: the largest Delta u/U_h at hub height 10 D behind, sampled through FLORIS; "
          "it equals C(10D).\n   y_c: position of the largest deficit along y at that height: "
          "veer shifts the wake to +y below the hub and to -y above it)")


# ----------------------------------------------------------------------------------- figures
def cross_plane_figure(case: Case, beta: float, output: Path) -> Path:
    D = case.diameter
    levels = np.linspace(0.0, 0.5, 21)
    fig, axes = plt.subplots(len(MODELS), len(X_OVER_D), figsize=(15, 8.2), sharex=True,
                             sharey=True, constrained_layout=True)
    for i, name in enumerate(MODELS):
        fmodel = case.model(name, beta)
        for j, x_d in enumerate(X_OVER_D):
            plane = fmodel.calculate_cross_plane(
                downstream_dist=x_d * D, y_resolution=101, z_resolution=61,
                y_bounds=(-2.0 * D, 2.0 * D), z_bounds=(0.02 * D, 2.0 * D),
            )
            deficit = (case.ambient(plane.df.x2.to_numpy()) - plane.df.u.to_numpy()) \
                / case.hub_speed
            plane.df["u"] = np.where(np.abs(deficit) < 1e-9, 0.0, deficit)  # round-off: -1e-16
            rescale_axis(plane, D, D)
            ax = axes[i, j]
            visualize_cut_plane(plane, ax=ax, min_speed=levels[0], max_speed=levels[-1],
                                clevels=levels, levels=levels[1::3], cmap="viridis")
            ax.add_patch(plt.Circle((0.0, case.hub_height / D), 0.5, fill=False, ls="--",
                                    color="w", lw=0.8))
            ax.set_title(f"{name}, x/D = {x_d:g}", fontsize=10)
            if i == len(MODELS) - 1:
                ax.set_xlabel("y/D (looking downstream)")
            if j == 0:
                ax.set_ylabel("z/D")
    fig.colorbar(axes[0, 0].collections[0], ax=axes, shrink=0.8, label=r"$\Delta u / U_h$")
    fig.suptitle(f"{case.name}, beta = {beta:+g} deg: M-1 (yaw + veer), M-2 (veer off), "
                 "M-3 (Bastankhah & Porte-Agel 2014); dashed: rotor disk")
    path = output / f"paper_cross_planes_{case.name}_beta{beta:+.0f}.png".replace("+0", "0")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def disk_quadrature(radius: float):
    """Offsets (dy, dz) and weights (sum 1) of a polar Gauss rule on a disk of ``radius``."""
    s, w = np.polynomial.legendre.leggauss(DISK_RADIAL)
    s, w = 0.5 * (s + 1.0), 0.5 * w  # on [0, 1]
    theta = (np.arange(DISK_ANGULAR) + 0.5) * 2.0 * np.pi / DISK_ANGULAR
    r = radius * s[:, None]
    weights = (w * s)[:, None] * np.ones_like(theta)
    return (r * np.cos(theta)).ravel(), (r * np.sin(theta)).ravel(), \
        (weights / weights.sum()).ravel()


def power_ratios(case: Case, name: str, beta: float) -> np.ndarray:
    """P/P0 of Eq. P_ratio, shape (len(X_OVER_D), len(Y_T_OVER_D)), from ONE FLORIS call."""
    D = case.diameter
    dy, dz, weights = disk_quadrature(case.radius)
    x_t = np.asarray(X_OVER_D)[:, None, None] * D
    y_t = Y_T_OVER_D[None, :, None] * D
    shape = (len(X_OVER_D), len(Y_T_OVER_D), dy.size)
    x = np.broadcast_to(x_t, shape).ravel()
    y = np.broadcast_to(y_t + dy, shape).ravel()
    z = np.broadcast_to(case.hub_height + dz, shape).ravel()
    u = case.model(name, beta).sample_flow_at_points(x, y, z)[0].reshape(shape)
    return (u @ weights / case.hub_speed) ** 3


def power_ratio_figure(cases: dict[str, Case], beta: float, output: Path) -> tuple[Path, dict]:
    names = ("CNBL", "SBL-6")
    fig, axes = plt.subplots(len(names), len(X_OVER_D), figsize=(15, 6.8), sharex=True,
                             sharey="row", constrained_layout=True)
    minima = {}
    for i, case_name in enumerate(names):
        case = cases[case_name]
        for name in MODELS:
            ratio = power_ratios(case, name, beta)
            for j, x_d in enumerate(X_OVER_D):
                axes[i, j].plot(Y_T_OVER_D, ratio[j], lw=1.8, label=name, **STYLE[name])
                k = int(np.argmin(ratio[j]))
                minima[(case_name, name, x_d)] = (Y_T_OVER_D[k], ratio[j, k])
        for j, x_d in enumerate(X_OVER_D):
            ax = axes[i, j]
            ax.set_title(f"{case_name}, $x_T/D$ = {x_d:g}", fontsize=10)
            ax.grid(alpha=0.3)
            if j == 0:
                ax.set_ylabel(r"$P/P_0$")
            if i == len(names) - 1:
                ax.set_xlabel(r"$y_T/D$")
    axes[0, 0].legend(loc="lower left", fontsize=9)
    fig.suptitle(rf"Power ratio (Eq. P_ratio) of a disk behind a turbine yawed by "
                 rf"$\beta$ = {beta:+g} deg (normalised by $U_h^3$)")
    path = output / f"paper_power_ratio_beta{beta:+.0f}.png".replace("+0", "0")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path, minima


def abl_figure(cases: dict[str, Case], output: Path) -> Path:
    z = np.linspace(0.5, 420.0, 840)
    fig, axes = plt.subplots(1, 3, figsize=(13, 5), sharey=True, constrained_layout=True)
    for case in cases.values():
        u, v = case.abl.hub_aligned_velocity(z, case.hub_height)
        angle = np.rad2deg(np.arctan2(v, u))
        h = float(case.abl.boundary_layer_height)
        line, = axes[0].plot(u, z, label=f"{case.name} (h = {h:.0f} m)")
        axes[1].plot(v, z, color=line.get_color())
        axes[2].plot(-angle, z, color=line.get_color())
        for ax in axes:
            ax.axhline(h, color=line.get_color(), ls=":", lw=0.8)
    for ax in axes:
        ax.axhspan(50.0, 150.0, color="0.85", zorder=0)
        ax.grid(alpha=0.3)
        ax.set_ylim(0.0, 420.0)
    axes[0].set_xlabel("U(z) [m/s] (along the hub-height wind)")
    axes[1].set_xlabel("V(z) [m/s] (to the left of the hub-height wind)")
    axes[2].set_xlabel("wind direction relative to hub height [deg] (+ = veered)")
    axes[0].set_ylabel("z [m]")
    axes[0].legend(fontsize=9)
    fig.suptitle(f"Ekman-surface-layer ABL of the paper's cases, G = {GEOSTROPHIC_WIND:g} m/s "
                 "(shaded: rotor 50-150 m; dotted: ABL height h, CNBL's above the plot)")
    path = output / "paper_abl_profiles.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


# ----------------------------------------------------------------------------------- main
def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--output", type=Path, default=Path("output"),
                        help="directory for the figures (default ./output)")
    args = parser.parse_args(argv)
    args.output.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()

    cases = {name: Case(name) for name in CASES}
    print_abl(cases)
    print_wake_table(cases)

    written = [abl_figure(cases, args.output)]
    for beta in BETAS:
        written.append(cross_plane_figure(cases["SBL-6"], beta, args.output))
    print("\nPower ratio P/P0 (Eq. P_ratio): minimum over y_T/D in [-4, 4], as (y_T/D, P/P0)")
    print(f"  {'case':<6}{'beta':>6}{'model':>6}" + "".join(f"{f'x_T = {x:g} D':>16}"
                                                          for x in X_OVER_D))
    for beta in BETAS:
        path, minima = power_ratio_figure(cases, beta, args.output)
        written.append(path)
        for case_name in ("CNBL", "SBL-6"):
            for name in MODELS:
                cells = "".join(f"{f'({minima[(case_name, name, x)][0]:+.2f}, ' f'{minima[(case_name, name, x)][1]:.3f})':>16}"
                                for x in X_OVER_D)
                print(f"  {case_name:<6}{beta:+6.0f}{name:>6}{cells}")
    print("\nFigures:")
    for path in written:
        print(f"  {path}")
    print(f"Done in {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
