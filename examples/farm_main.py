"""A 3 x 3 wind farm in a strongly stable night: the veer-corrected curled-wake model in FLORIS.

Run it from anywhere (after ``pip install -e .`` in the repository, or from a checkout):

    python examples/farm_main.py [--output DIR]

It loads ``inputs/farm_sbl6.yaml`` (3 x 3 NREL 5 MW at 7 D, the paper's SBL-6 by its surface
cooling rate: f_c = 1e-4 1/s, z0 = 0.1 m, C_r = -1 K/h, N = 6.1e-3 1/s) and compares, on the SAME Ekman inflow:

* M-1    ``ekman_veer`` velocity + deflection (yaw and veer deflection: the wake is sheared),
* M-2    the same with the veer deflection off (``wake_deflection_parameters.ekman_veer.veer``),
* gauss  FLORIS's own Gaussian velocity + deflection models with FLORIS's superposition (sosfs);
         only the model names change, so FLORIS's inflow stays the Ekman U(z) (and
         ``wind_veer`` stays 0, see below).

Every model gets the atmosphere's I_u(z_h) as turbulence intensity (the ekman_veer models take
their wake expansion k_w from the ABL itself, plus the upstream wakes' added turbulence, and
scale a waked rotor's wake with its incoming speed: the input's array coupling,
docs/coupling.md#wakes-deep-in-an-array; gauss reads the TI). ``--gauss-wind-veer`` also
gives gauss the rotor-layer veer as FLORIS's ``wind_veer`` (as
``floris_ekman_veer.studies.comparison.builtin_inflow_settings`` suggests). It is off by default:
FLORIS's gauss narrows its initial width by cos(wind_veer) and tilts its ellipse, and with this
night's ~40 degrees and I_u ~ 0.02 its deficit saturates (u = 0 on part of the waked rotor at
9 m/s, 107 kW instead of 495 kW for the turbine 7 D behind). It prints the ABL of each
wind speed, per-turbine and farm powers at 270 deg, farm power over a small wind rose at 9 m/s
and a yaw-optimisation demo (FLORIS's YawOptimizationSR over -25..25 deg: with veer the optimum
is not symmetric in the sign of yaw), and writes figures to DIR (default ./output).
"""

from __future__ import annotations

import argparse
import copy
import time
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

REPOSITORY = Path(__file__).resolve().parent.parent
import floris_ekman_veer  # noqa: F401  (registers the models and the Ekman inflow hook)

from floris import FlorisModel  # noqa: E402
from floris.flow_visualization import visualize_cut_plane  # noqa: E402
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

from floris_ekman_veer import EkmanABL  # noqa: E402
from floris_ekman_veer.studies.comparison import builtin_inflow_settings  # noqa: E402
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning  # noqa: E402
from floris_ekman_veer.plugin.inflow.inflow import ambient_velocity  # noqa: E402
from floris_ekman_veer.studies.validity import validity_report, validity_summary  # noqa: E402

FARM_INPUT = REPOSITORY / "inputs" / "farm_sbl6.yaml"

MODELS = ("M-1", "M-2", "gauss")
LABELS = {
    "M-1": "M-1 ekman_veer (yaw + veer)",
    "M-2": "M-2 ekman_veer, veer off",
    "gauss": "FLORIS gauss, same Ekman inflow",
}
COLOURS = {"M-1": "m", "M-2": "tab:blue", "gauss": "tab:cyan"}

SPEEDS_270 = (8.0, 9.0, 11.0)  # wind speeds [m/s] at 90 m, wind from 270 deg
ROSE_SPEED = 9.0
ROSE_TABLE = np.arange(255.0, 285.1, 5.0)  # printed
ROSE_FIGURE = np.arange(240.0, 300.1, 1.0)  # plotted (contains ROSE_TABLE)
YAW_CONDITIONS = ((270.0, 9.0), (270.0, 11.0), (265.0, 11.0), (275.0, 11.0))  # (deg, m/s)


# ----------------------------------------------------------------------------------- models
def build_models(config: dict) -> dict[str, FlorisModel]:
    """M-1, M-2 and gauss from one input dictionary (same farm, same atmosphere block)."""
    m2 = copy.deepcopy(config)
    m2["wake"]["wake_deflection_parameters"]["ekman_veer"]["veer"] = False
    gauss = copy.deepcopy(config)
    gauss["wake"]["model_strings"].update(velocity_model="gauss", deflection_model="gauss",
                                          combination_model="sosfs")
    return {"M-1": FlorisModel(config), "M-2": FlorisModel(m2), "gauss": FlorisModel(gauss)}


class Farm:
    """The three models plus the atmosphere, evaluated per wind speed."""

    def __init__(self, config: dict, gauss_wind_veer: bool = False):
        self.config = config
        self.gauss_wind_veer = gauss_wind_veer
        self.models = build_models(config)
        farm, flow = config["farm"], config["flow_field"]
        self.layout = np.array([farm["layout_x"], farm["layout_y"]])
        self.n_turbines = self.layout.shape[1]
        self.atmosphere = config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
        self.reference_height = float(flow["reference_wind_height"])
        turbine = self.models["M-1"].core.farm
        self.hub_height = float(turbine.hub_heights.ravel()[0])
        self.diameter = float(turbine.rotor_diameters.ravel()[0])

    def inflow_scalars(self, speeds) -> dict:
        """I_u(z_h), rotor-layer veer [deg] and rotor-equivalent shear exponent of the
        atmosphere, arrays with one value per wind speed in ``speeds``."""
        return builtin_inflow_settings(
            self.atmosphere, np.atleast_1d(speeds), self.reference_height, self.hub_height,
            self.diameter,
        )

    def abl(self, speeds) -> EkmanABL:
        return EkmanABL.from_reference_wind(np.asarray(speeds, float), self.reference_height,
                                            **self.atmosphere)

    def set_conditions(self, name: str, directions, speeds) -> FlorisModel:
        """Set conditions (``speeds`` a scalar or one per direction) on model ``name`` with
        TI = I_u(z_h) per condition. With ``gauss_wind_veer`` gauss also gets the rotor-layer veer
        as ``wind_veer``, one value per FLORIS model: gauss then takes one speed at a time."""
        directions = np.atleast_1d(np.asarray(directions, float))
        speeds = np.broadcast_to(np.asarray(speeds, float), directions.shape).copy()
        scalars = self.inflow_scalars(speeds)
        kwargs = dict(
            wind_directions=directions,
            wind_speeds=speeds,
            turbulence_intensities=scalars["turbulence_intensities"],
        )
        if name == "gauss" and self.gauss_wind_veer:
            if np.ptp(speeds) > 0:
                raise ValueError("gauss takes one wind speed per call (one wind_veer per model)")
            kwargs["wind_veer"] = float(scalars["wind_veer"][0])
        fmodel = self.models[name]
        fmodel.set(**kwargs)
        fmodel.reset_operation()
        return fmodel

    def turbine_powers(self, name: str, directions, speeds) -> np.ndarray:
        """Turbine powers [W], shape (n_conditions, n_turbines); gauss per distinct speed."""
        directions = np.atleast_1d(np.asarray(directions, float))
        speeds = np.broadcast_to(np.asarray(speeds, float), directions.shape)
        groups = np.unique(speeds) if name == "gauss" and self.gauss_wind_veer else [None]
        powers = np.empty((directions.size, self.n_turbines))
        for speed in groups:
            rows = np.ones(directions.size, bool) if speed is None else speeds == speed
            fmodel = self.set_conditions(name, directions[rows], speeds[rows])
            fmodel.run()
            powers[rows] = fmodel.get_turbine_powers()
        return powers


# ----------------------------------------------------------------------------------- printing
def print_abl(farm: Farm, speeds) -> dict:
    abl = farm.abl(speeds)
    z_h, radius = farm.hub_height, 0.5 * farm.diameter
    veer = abl.wind_direction_change(z_h - radius, z_h + radius)
    k_w = abl.wake_expansion_rate(z_h)
    print(f"Atmosphere (Ekman-surface-layer ABL of {FARM_INPUT.name}): f_c = "
          f"{farm.atmosphere['coriolis_parameter']:g} 1/s, z0 = {farm.atmosphere['roughness_length']:g} m, "
          f"C_r = {farm.atmosphere['cooling_rate']:g} K/h, "
          f"N = {farm.atmosphere['brunt_vaisala_frequency']:g} 1/s")
    print(f"  rotor layer {z_h - radius:.0f}-{z_h + radius:.0f} m (NREL 5 MW, D = "
          f"{farm.diameter:.0f} m, z_h = {z_h:.0f} m)")
    header = (f"  {'U(90 m)':>8} {'G':>6} {'u*':>6} {'h':>6} {'alpha0':>7} {'veer rotor':>10} "
              f"{'I_u(z_h)':>8} {'k_w':>6} {'shear':>6}")
    print(header)
    print(f"  {'[m/s]':>8} {'[m/s]':>6} {'[m/s]':>6} {'[m]':>6} {'[deg]':>7} {'[deg]':>10} "
          f"{'[-]':>8} {'[-]':>6} {'[-]':>6}")
    scalars = farm.inflow_scalars(speeds)
    for i, speed in enumerate(speeds):
        print(f"  {speed:8.1f} {abl.geostrophic_wind[i]:6.2f} {abl.friction_velocity[i]:6.3f} "
              f"{abl.boundary_layer_height[i]:6.0f} {abl.cross_isobaric_angle[i]:7.1f} "
              f"{veer[i]:10.1f} {scalars['turbulence_intensities'][i]:8.3f} {k_w[i]:6.4f} "
              f"{scalars['wind_shear'][i]:6.3f}")
    print("  (veer rotor: direction change from rotor bottom to top, positive = veering; "
          "shear: rotor-equivalent power-law exponent, for reference only: FLORIS's inflow is "
          "the Ekman U(z); k_w: paper Eq. kw_CNBL_SBL_model, used by M-1/M-2; I_u(z_h) is every "
          f"model's TI; gauss wind_veer = {'the rotor veer' if farm.gauss_wind_veer else '0'})")
    shallow = [speed for i, speed in enumerate(speeds)
               if abl.boundary_layer_height[i] < z_h + radius]
    if shallow:
        print(f"  note: at U(90 m) = {', '.join(f'{s:g}' for s in shallow)} m/s h is below the "
              f"rotor top ({z_h + radius:.0f} m), outside the paper's validated range: above h the "
              "inflow is the geostrophic wind and k_w falls continuously to its floor "
              "(docs/atmosphere.md#shallow-boundary-layer); the ShallowBoundaryLayerWarning of "
              "each model build is silenced in this example")
    report_model = FlorisModel(FARM_INPUT)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        report_model.set(wind_speeds=list(speeds), wind_directions=[270.0] * len(speeds),
                         turbulence_intensities=[0.06] * len(speeds))
    print("  " + validity_summary(validity_report(report_model), FARM_INPUT.name))


def ratio(a: float, b: float) -> str:
    return f"{a / b:.3f}" if b > 0 else "-"


def print_turbine_table(farm: Farm, speeds) -> None:
    print("\nWind from 270 deg: per-turbine power [kW] (turbines T0-T2 face the wind; T3-T5 are "
          "7 D behind them, T6-T8 14 D)")
    directions = np.full(len(speeds), 270.0)
    powers = {m: farm.turbine_powers(m, directions, speeds) / 1e3 for m in MODELS}
    columns = "".join(f"{m:>9}" for m in MODELS) + f"{'M-1/M-2':>9}{'M-1/gauss':>10}"
    for i, speed in enumerate(speeds):
        print(f"\n  U(90 m) = {speed:g} m/s")
        print(f"  {'turbine':<8}{'x [m]':>6}{'y [m]':>6}" + columns)
        for t in range(farm.n_turbines):
            row = [powers[m][i, t] for m in MODELS]
            print(f"  T{t:<7}{farm.layout[0, t]:6.0f}{farm.layout[1, t]:6.0f}"
                  + "".join(f"{v:9.0f}" for v in row)
                  + f"{ratio(row[0], row[1]):>9}{ratio(row[0], row[2]):>10}")
        totals = [powers[m][i].sum() / 1e3 for m in MODELS]
        print(f"  {'farm [MW]':<20}" + "".join(f"{v:9.2f}" for v in totals)
              + f"{ratio(totals[0], totals[1]):>9}{ratio(totals[0], totals[2]):>10}")


def print_rose(farm: Farm) -> dict:
    powers = {m: farm.turbine_powers(m, ROSE_FIGURE, ROSE_SPEED).sum(axis=1) / 1e6 for m in MODELS}
    print(f"\nWind rose at U(90 m) = {ROSE_SPEED:g} m/s: farm power [MW]")
    print(f"  {'dir [deg]':>9}" + "".join(f"{m:>9}" for m in MODELS) + f"{'M-1/M-2':>9}"
          f"{'M-1/gauss':>10}")
    table = np.isin(ROSE_FIGURE, ROSE_TABLE)
    for i in np.flatnonzero(table):
        row = [powers[m][i] for m in MODELS]
        print(f"  {ROSE_FIGURE[i]:9.0f}" + "".join(f"{v:9.2f}" for v in row)
              + f"{ratio(row[0], row[1]):>9}{ratio(row[0], row[2]):>10}")
    means = [powers[m][table].mean() for m in MODELS]
    print(f"  {'mean':>9}" + "".join(f"{v:9.2f}" for v in means)
          + f"{ratio(means[0], means[1]):>9}{ratio(means[0], means[2]):>10}")
    return powers


def yaw_demo(farm: Farm) -> None:
    print("\nYaw optimisation (FLORIS YawOptimizationSR, yaw -25..25 deg, Ny_passes [5, 4]; "
          "positive yaw sends the wake to -y)")
    directions = np.array([c[0] for c in YAW_CONDITIONS])
    speeds = np.array([c[1] for c in YAW_CONDITIONS])
    print(f"  {'model':<6}{'dir':>5}{'U90':>6}  {'optimal yaw [deg] T0..T8':<54}"
          f"{'base MW':>8}{'opt MW':>8}{'gain':>8}{'mirror':>8}")
    for name in ("M-1", "M-2"):
        fmodel = farm.set_conditions(name, directions, speeds)
        optimiser = YawOptimizationSR(fmodel, minimum_yaw_angle=-25.0, maximum_yaw_angle=25.0)
        result = optimiser.optimize(print_progress=False)
        yaw = np.vstack(result.yaw_angles_opt.to_numpy()).astype(float)
        base = result.farm_power_baseline.to_numpy()
        best = result.farm_power_opt.to_numpy()
        # The mirror image of the optimum, -yaw: as good without veer, worse with it.
        fmodel.set(yaw_angles=-yaw)
        fmodel.run()
        mirror = fmodel.get_farm_power()
        fmodel.reset_operation()
        for i in range(len(directions)):
            angles = " ".join(f"{a:+5.1f}" for a in yaw[i])
            print(f"  {name:<6}{directions[i]:5.0f}{speeds[i]:6.1f}  {angles:<54}"
                  f"{base[i] / 1e6:8.2f}{best[i] / 1e6:8.2f}{100 * (best[i] / base[i] - 1):+7.2f}%"
                  f"{100 * (mirror[i] / base[i] - 1):+7.2f}%")
    print("  gain: farm power at the optimum vs zero yaw; mirror: the optimal angles with the "
          "opposite sign.\n  Veer favours one sign twice: the veer-aware rotor (every model, "
          "docs/yaw_steering.md#the-veer-aware-rotor)\n  and, in M-1, the sheared wake "
          "(docs/coupling.md#yaw-optimisation). FLORIS's optimiser is run here as it is (one "
          "search);\n  floris_ekman_veer.optimize_yaw searches both signs "
          "(docs/yaw_steering.md#finding-the-optimum).")


# ----------------------------------------------------------------------------------- figures
def hub_plane_figure(farm: Farm, output: Path, speed: float) -> Path:
    fig, axes = plt.subplots(1, 3, figsize=(16, 5.2), constrained_layout=True)
    planes = {}
    for name in MODELS:
        fmodel = farm.set_conditions(name, [270.0], speed)
        planes[name] = fmodel.calculate_horizontal_plane(
            height=farm.hub_height, x_resolution=220, y_resolution=160,
            x_bounds=(-400.0, 2900.0), y_bounds=(-500.0, 2260.0),
        )
    # Levels 0.5 m/s apart with the ambient hub speed mid-bin (no contour at the free stream).
    levels = np.arange(2.75, speed + 0.3, 0.5)
    for ax, name in zip(axes, MODELS):
        visualize_cut_plane(planes[name], ax=ax, min_speed=levels[0], max_speed=levels[-1],
                            clevels=levels, levels=levels[::2], title=LABELS[name])
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    mappable = axes[0].collections[0]
    fig.colorbar(mappable, ax=axes, shrink=0.85, label="u at hub height (90 m) [m/s]")
    fig.suptitle(f"3 x 3 NREL 5 MW, SBL-6 stability, wind 270 deg, {speed:g} m/s at 90 m")
    path = output / "farm_hub_height_plane.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def cross_plane_figure(farm: Farm, output: Path, speed: float) -> Path:
    """u and Delta u/U_h at 7 D behind T0 (the rotor plane of T3, whose own wake starts there)."""
    x_plane = 7.0 * farm.diameter
    abl = farm.abl([speed])
    u_hub = float(abl.speed(farm.hub_height)[0])
    radius = 0.5 * farm.diameter
    fig, axes = plt.subplots(2, 3, figsize=(15, 6.2), constrained_layout=True)
    speed_levels = np.arange(1.75, speed + 0.8, 0.5)
    deficit_levels = np.linspace(0.0, 0.6, 25)
    for j, name in enumerate(MODELS):
        fmodel = farm.set_conditions(name, [270.0], speed)
        plane = fmodel.calculate_cross_plane(
            downstream_dist=x_plane, y_resolution=121, z_resolution=81,
            y_bounds=(-300.0, 300.0), z_bounds=(1.0, 241.0),
        )
        visualize_cut_plane(plane, ax=axes[0, j], min_speed=speed_levels[0],
                            max_speed=speed_levels[-1], clevels=speed_levels,
                            levels=speed_levels[::2], title=LABELS[name])
        # Deficit: the ambient hub-aligned U(z) of the Ekman inflow minus the waked u.
        ambient, _ = ambient_velocity(abl, plane.df.x2.to_numpy()[None, :], farm.reference_height)
        deficit = copy.deepcopy(plane)
        values = (ambient[0] - plane.df.u.to_numpy()) / u_hub
        deficit.df["u"] = np.where(np.abs(values) < 1e-9, 0.0, values)  # round-off: -1e-16
        visualize_cut_plane(deficit, ax=axes[1, j], min_speed=0.0, max_speed=0.6,
                            clevels=deficit_levels, levels=deficit_levels[2::4], cmap="viridis",
                            title=f"{name}: wake deficit (max {deficit.df.u.max():.2f})")
        for ax in axes[:, j]:
            circle = plt.Circle((0.0, farm.hub_height), radius, fill=False, ls="--", lw=1.0,
                                color="k")
            ax.add_patch(circle)
            ax.set_xlabel("y [m] (looking downstream)")
            ax.set_ylabel("z [m]")
    fig.colorbar(axes[0, 0].collections[0], ax=axes[0, :], shrink=0.9, label="u [m/s]")
    fig.colorbar(axes[1, 0].collections[0], ax=axes[1, :], shrink=0.9,
                 label=r"$\Delta u / U_h$ = (U(z) - u) / U_h")
    fig.suptitle(f"Cross plane x = 7 D behind T0 (wind 270 deg, {speed:g} m/s at 90 m, "
                 f"veer across the rotor {float(abl.wind_direction_change(27.0, 153.0)[0]):.0f} "
                 "deg); dashed: rotor of T3")
    path = output / "farm_cross_plane_7D.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def rose_figure(rose: dict, output: Path) -> Path:
    fig, ax = plt.subplots(figsize=(7.5, 4.5), constrained_layout=True)
    styles = {"M-1": "-.", "M-2": "-", "gauss": ":"}
    for name in MODELS:
        ax.plot(ROSE_FIGURE, rose[name], styles[name], color=COLOURS[name], lw=2,
                label=LABELS[name])
    ax.set_xlabel("wind direction [deg]")
    ax.set_ylabel("farm power [MW]")
    ax.set_title(f"3 x 3 NREL 5 MW at 7 D, SBL-6 stability, {ROSE_SPEED:g} m/s at 90 m")
    ax.grid(alpha=0.3)
    ax.legend()
    path = output / "farm_power_vs_direction.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


# ----------------------------------------------------------------------------------- main
def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--output", type=Path, default=Path("output"),
                        help="directory for the figures (default ./output)")
    parser.add_argument("--gauss-wind-veer", action="store_true",
                        help="give gauss the rotor-layer veer as FLORIS's wind_veer")
    args = parser.parse_args(argv)
    args.output.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    np.set_printoptions(precision=3, suppress=True)

    # Every model build of this night would repeat the warning; print_abl says it once.
    warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
    farm = Farm(load_yaml(FARM_INPUT), gauss_wind_veer=args.gauss_wind_veer)
    if args.gauss_wind_veer:
        LABELS["gauss"] += " + wind_veer"
    print_abl(farm, SPEEDS_270)
    print_turbine_table(farm, SPEEDS_270)
    rose = print_rose(farm)
    yaw_demo(farm)

    written = [
        hub_plane_figure(farm, args.output, ROSE_SPEED),
        cross_plane_figure(farm, args.output, ROSE_SPEED),
        rose_figure(rose, args.output),
    ]
    print("\nFigures:")
    for path in written:
        print(f"  {path}")
    print(f"Done in {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
