"""Wake steering with veer: optimal yaw per direction and day/night annual energy.

Run it from anywhere (after ``pip install .``, or from a checkout):

    python examples/yaw_study.py [--output DIR] [--gallery DIR]

Two atmospheres, read from the project's inputs: the paper's neutral CNBL (the atmosphere block of
``inputs/cnbl.yaml``) and its strongly stable SBL-6 (``inputs/farm_sbl6.yaml``); the farm, the
turbines and the solver settings are those of ``inputs/farm_sbl6.yaml`` (NREL 5 MW at 7 D).
Three wake models on the same Ekman inflow: ``ekman_veer`` (the input's own) and FLORIS's GCH and
cc (``floris_ekman_veer.coupling.comparison.builtin_model``), each built-in given the fair inflow
scalars of ``comparison.fair_builtin_set_kwargs`` (turbulence intensity I_u(z_h), rotor-layer veer
and shear of the atmosphere); the script prints what each model sees.

1. A 3-turbine row (the farm's first column turned into a row along 270 degrees): the optimal yaw
   angles per wind direction, searched separately with positive and with negative yaw
   (FLORIS's YawOptimizationSR through ``floris_ekman_veer.optimize_yaw``): veer makes the two
   signs differ.
2. The 3 x 3 farm over a wind rose with stable nights and neutral days
   (``floris_ekman_veer.annual_energy``): AEP per class with and without wake steering.

Figures (PNG) go to DIR (default ./output); tables are printed. ``run_study(reduced=True)`` is the
same computation on a coarser grid (tests/test_yaw_study.py).
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

REPOSITORY = Path(__file__).resolve().parent.parent
try:
    import floris_ekman_veer  # noqa: F401  (registers the models and the Ekman inflow hook)
except ImportError:  # run from a checkout without installing
    sys.path.insert(0, str(REPOSITORY))
    import floris_ekman_veer  # noqa: F401

import pandas as pd  # noqa: E402
from floris import FlorisModel, WindRose  # noqa: E402
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

from floris_ekman_veer import annual_energy, optimize_yaw  # noqa: E402
from floris_ekman_veer.coupling.comparison import builtin_model, fair_builtin_set_kwargs  # noqa: E402
from floris_ekman_veer.coupling.inflow import atmosphere_of, set_atmosphere  # noqa: E402
from floris_ekman_veer.coupling.shallow import ShallowBoundaryLayerWarning  # noqa: E402

FARM_INPUT = REPOSITORY / "inputs" / "farm_sbl6.yaml"
NEUTRAL_INPUT = REPOSITORY / "inputs" / "cnbl.yaml"
MODELS = ("ekman_veer", "gch", "cc")

# Study settings (inputs of the study, not results).
ROW_SPEED = 8.0                                # m/s at the reference height
YAW_LIMIT = 25.0                               # degrees, each sign searched on its own
NY_PASSES = [5, 4]                             # YawOptimizationSR passes
NIGHT_FREQUENCY = 0.5                          # stable nights, neutral days
ROSE_WEIBULL = (2.0, 8.0)                      # shape k, scale A [m/s] of the speeds
ROSE_PREVAILING, ROSE_SPREAD = 270.0, 60.0     # deg: direction of most wind, its spread
GRIDS = {
    False: dict(row_directions=np.arange(250.0, 290.1, 2.0), ny_passes=NY_PASSES, models=MODELS,
                rose_directions=np.arange(0.0, 360.0, 15.0), rose_speeds=np.arange(4.0, 16.1, 2.0)),
    # Each FLORIS optimiser evaluation rebuilds a model: the reduced study makes few of them.
    True: dict(row_directions=np.array([266.0, 274.0]), ny_passes=[5], models=MODELS[:2],
               rose_directions=np.array([270.0, 300.0]), rose_speeds=np.array([8.0])),
}


def atmospheres() -> dict[str, dict]:
    """The neutral day (CNBL) and stable night (SBL-6) atmosphere blocks, from the inputs."""
    def block(path):
        return load_yaml(path)["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]

    return {"CNBL": block(NEUTRAL_INPUT), "SBL-6": block(FARM_INPUT)}


def wind_rose(directions, speeds) -> WindRose:
    """A Weibull speed distribution times a smooth direction distribution (ROSE_* settings)."""
    k, scale = ROSE_WEIBULL
    speed_weight = (k / scale) * (speeds / scale) ** (k - 1) * np.exp(-(speeds / scale) ** k)
    offset = np.deg2rad(directions - ROSE_PREVAILING)
    direction_weight = np.exp(np.cos(offset) / np.deg2rad(ROSE_SPREAD))
    freq = np.outer(direction_weight, speed_weight)
    return WindRose(wind_directions=directions, wind_speeds=speeds, ti_table=0.06,
                    freq_table=freq / freq.sum())


def row_model() -> FlorisModel:
    """The farm input's first column of three turbines, turned into a row along 270 degrees."""
    fmodel = FlorisModel(FARM_INPUT)
    spacing = float(np.diff(fmodel.layout_y[:2])[0])
    fmodel.set(layout_x=spacing * np.arange(3), layout_y=np.zeros(3))
    return fmodel


def models_on(fmodel, atmosphere: dict, directions, speed: float, models=MODELS) -> dict:
    """ekman_veer, GCH and cc on these conditions and this atmosphere, with the fair scalars."""
    built = {}
    for name in models:
        model = fmodel.copy() if name == "ekman_veer" else builtin_model(fmodel, name)
        set_atmosphere(model, atmosphere, wind_directions=directions,
                       wind_speeds=np.full(len(directions), speed),
                       turbulence_intensities=np.full(len(directions), 0.06))
        fair = fair_builtin_set_kwargs(model)
        if name == "ekman_veer":  # reads neither FLORIS's veer nor its shear
            model.set(turbulence_intensities=fair["turbulence_intensities"])
        else:
            model.set(**fair)
        built[name] = model
    return built


def inflow_seen(fmodel, atmospheres_: dict, speed: float) -> pd.DataFrame:
    """What each model is given, per atmosphere, at ``speed``."""
    rows = []
    input_ti = float(fmodel.core.flow_field.turbulence_intensities[0])
    expansion = fmodel.core.wake.wake_velocity_parameters["ekman_veer"].get("wake_expansion",
                                                                             "ambient")
    ekman_use = {
        "ambient": "k_w (Eq. kw_CNBL_SBL_model) from the ABL's I_u(z_h)",
        "local_turbulence": "k_w from this TI plus FLORIS's wake-added TI",
    }.get(expansion, f"wake_expansion: {expansion}")
    for label, atmosphere in atmospheres_.items():
        for name, model in models_on(fmodel, atmosphere, [270.0], speed).items():
            flow_field = model.core.flow_field
            ti = float(flow_field.turbulence_intensities[0])
            rows.append({
                "atmosphere": label, "model": name,
                "turbulence_intensity": ti,
                "used_as": ekman_use if name == "ekman_veer" else "FLORIS ambient TI",
                "wind_veer_deg": np.nan if name == "ekman_veer" else float(flow_field.wind_veer),
                "input_file_ti": input_ti,
            })
    return pd.DataFrame(rows)


def row_yaw_study(atmospheres_: dict, directions, ny_passes=NY_PASSES, models=MODELS):
    """Optimal yaw per direction for the 3-turbine row, positive and negative yaw searched apart."""
    row = row_model()
    frames = []
    for label, atmosphere in atmospheres_.items():
        for name, model in models_on(row, atmosphere, directions, ROW_SPEED, models).items():
            for sign, bounds in (("+", (0.0, YAW_LIMIT)), ("-", (-YAW_LIMIT, 0.0))):
                df = optimize_yaw(model, YawOptimizationSR, minimum_yaw_angle=bounds[0],
                                  maximum_yaw_angle=bounds[1], Ny_passes=ny_passes,
                                  progress=False)
                yaw = np.vstack(df["yaw_angles_opt"])
                frames.append(pd.DataFrame({
                    "atmosphere": label, "model": name, "sign": sign,
                    "wind_direction": df["wind_direction"].to_numpy(),
                    "yaw_T1": yaw[:, 0], "yaw_T2": yaw[:, 1], "yaw_T3": yaw[:, 2],
                    "gain_percent": 100.0 * (df["farm_power_opt"] / df["farm_power_baseline"]
                                             - 1.0).to_numpy(),
                }))
    return pd.concat(frames, ignore_index=True)


def day_night_energy(atmospheres_: dict, directions, speeds, ny_passes=NY_PASSES, models=MODELS):
    """AEP of the 3 x 3 farm: neutral days and stable nights, with and without steering."""
    stability = {
        "neutral day": {"frequency": 1.0 - NIGHT_FREQUENCY, "atmosphere": atmospheres_["CNBL"]},
        "stable night": {"frequency": NIGHT_FREQUENCY, "atmosphere": atmospheres_["SBL-6"]},
    }
    return annual_energy(FlorisModel(FARM_INPUT), wind_rose(directions, speeds), stability,
                         YawOptimizationSR, models=models, minimum_yaw_angle=-YAW_LIMIT,
                         maximum_yaw_angle=YAW_LIMIT, Ny_passes=ny_passes)


def run_study(reduced: bool = False) -> dict:
    """The whole computation (no figures); ``reduced``: the coarse grid, one optimiser pass and
    ekman_veer and GCH only (GRIDS)."""
    grid = GRIDS[reduced]
    atmospheres_ = atmospheres()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ShallowBoundaryLayerWarning)
        inflow = inflow_seen(row_model(), atmospheres_, ROW_SPEED)
        yaw = row_yaw_study(atmospheres_, grid["row_directions"], grid["ny_passes"],
                            grid["models"])
        energy = day_night_energy(atmospheres_, grid["rose_directions"], grid["rose_speeds"],
                                  grid["ny_passes"], grid["models"])
    shallow = [w for w in caught if issubclass(w.category, ShallowBoundaryLayerWarning)]
    for w in caught:
        if not issubclass(w.category, ShallowBoundaryLayerWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return {"inflow": inflow, "yaw": yaw, "energy": energy,
            "shallow_warnings": sorted({str(w.message) for w in shallow})}


# ----------------------------------------------------------------------------------- figures
def plot_row(yaw: pd.DataFrame, output: Path, dpi: int = 120) -> Path:
    import matplotlib.pyplot as plt

    labels = list(dict.fromkeys(yaw["atmosphere"]))
    fig, axes = plt.subplots(2, len(labels), figsize=(11, 6.5), sharex=True, sharey="row")
    colours = {"ekman_veer": "m", "gch": "tab:cyan", "cc": "tab:orange"}
    for j, label in enumerate(labels):
        for (name, sign), df in yaw[yaw["atmosphere"] == label].groupby(["model", "sign"]):
            style = "-" if sign == "+" else "--"
            axes[0, j].plot(df["wind_direction"], df["yaw_T1"], style, color=colours[name],
                            label=f"{name}, {sign} yaw")
            axes[1, j].plot(df["wind_direction"], df["gain_percent"], style,
                            color=colours[name], label=f"{name}, {sign} yaw")
        axes[0, j].set_title(f"{label}: 3-turbine row, {ROW_SPEED:g} m/s")
        axes[1, j].set_xlabel("wind direction [deg]")
    axes[0, 0].set_ylabel("optimal yaw of the front turbine [deg]")
    axes[1, 0].set_ylabel("farm power gain [%]")
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    path = output / "yaw_study_row.png"
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def plot_energy(energy, output: Path) -> Path:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    energy.plot(ax=ax)
    ax.set_title("3 x 3 farm: AEP per stability class, baseline and with wake steering")
    fig.tight_layout()
    path = output / "yaw_study_aep.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=Path("output"))
    parser.add_argument("--gallery", type=Path, default=None,
                        help="also write the README gallery's small copy of yaw_study_row.png")
    args = parser.parse_args(argv)
    args.output.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    study = run_study()
    pd.set_option("display.width", 250)
    pd.set_option("display.max_rows", 200)

    print("What each model sees at the hub (row study wind speed "
          f"{ROW_SPEED:g} m/s; the farm input's own TI is what FLORIS would use otherwise):")
    print(study["inflow"].to_string(index=False, float_format="%.4f"))
    if study["shallow_warnings"]:
        print(f"note: {len(study['shallow_warnings'])} model builds had stable conditions with a "
              "boundary layer shallower than the rotor, e.g.\n  " + study["shallow_warnings"][0])
    veer = study["inflow"].groupby("atmosphere")["wind_veer_deg"].max()
    print("note: GCH and cc get FLORIS wind_veer = "
          + ", ".join(f"{v:.1f} deg ({a})" for a, v in veer.items())
          + "; at tens of degrees gauss's cos(wind_veer) narrowing makes its unsteered wakes "
          "very deep, which inflates its steering gains (docs/coupling.md#floris-inflow)")

    yaw = study["yaw"]
    print(f"\n3-turbine row at {ROW_SPEED:g} m/s, wind along the row (270 deg): optimal yaw "
          "[deg] and farm power gain per sign of yaw")
    aligned = yaw[np.isclose(yaw["wind_direction"], 270.0)]
    print(aligned.drop(columns="wind_direction").to_string(index=False, float_format="%.2f"))
    for value, title in (("gain_percent", "farm power gain [%]"),
                         ("yaw_T1", "optimal yaw of the front turbine [deg]")):
        print(f"\n{title} per wind direction [deg], positive and negative yaw searched apart:")
        print(yaw.pivot_table(index=["atmosphere", "model", "sign"], columns="wind_direction",
                              values=value).to_string(float_format="%.1f"))

    energy = study["energy"]
    print("\n3 x 3 farm, day/night annual energy [GWh] with and without wake steering "
          f"(Weibull k = {ROSE_WEIBULL[0]:g}, A = {ROSE_WEIBULL[1]:g} m/s; nights "
          f"{NIGHT_FREQUENCY:.0%} of the year, SBL-6; days CNBL):")
    print(energy.table.to_string(index=False, float_format="%.3f"))
    paths = [plot_row(yaw, args.output), plot_energy(energy, args.output)]
    if args.gallery is not None:
        args.gallery.mkdir(parents=True, exist_ok=True)
        paths.append(plot_row(yaw, args.gallery, dpi=60))
    for path in paths:
        print(f"wrote {path}")
    print(f"done in {time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()
