"""Wake steering with veer: optimal yaw of a 3-turbine row, both signs, and day/night energy.

Run it from anywhere (after ``pip install .``, or from a checkout):

    python examples/yaw_study.py [--output DIR] [--gallery DIR]

Three atmospheres, each named by a forcing fixed across wind speeds and read from the project's
inputs: the neutral day (CNBL, ``inputs/cnbl.yaml``'s atmosphere), the paper's SBL-4 cooling rate
(-0.375 K/h, ``inputs/sbl4.yaml``) and the shipped stable night (the paper's SBL-3 cooling rate,
-0.25 K/h, ``inputs/farm_night.yaml``). One line per atmosphere says which conditions lie inside the
paper's validated envelope (``floris_ekman_veer.validity_report``): SBL-4 at 8 m/s has h below
the NREL 5 MW rotor top, and its rows are flagged.

1. A 3-turbine NREL 5 MW row along 270 degrees at 4, 5 and 7 D, at 8, 10 and 12 m/s: the optimal
   yaw over -25..25 deg (``floris_ekman_veer.optimize_yaw``, both signs searched), the farm gain,
   the best gain restricted to positive and to negative yaw, and the front rotor's own
   P(+20 deg)/P(-20 deg) (the veer-aware rotor, docs/yaw_steering.md). Models on the same Ekman
   inflow and the same rotor: ``ekman_veer`` (the paper's M-1), FLORIS's GCH with
   ``wind_veer = 0`` (the comparison) and GCH with the fair scalar wind_veer of
   ``comparison.fair_builtin_set_kwargs`` (flagged: gauss's cos(wind_veer) narrowing, not
   steering, drives its gains at tens of degrees of veer).
2. With ``--energy``: the 3 x 3 farm of ``inputs/farm_day.yaml`` (its layout and turbines) over
   a wind rose with stable nights and neutral days (``floris_ekman_veer.annual_energy``): AEP per class with and without
   wake steering.

Figures (PNG) go to DIR (default ./output); tables are printed. ``run_study(reduced=True)`` is the
same computation on a coarser grid (tests/docs/test_yaw_study_example.py).
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

REPOSITORY = Path(__file__).resolve().parent.parent
import floris_ekman_veer  # noqa: F401  (registers the models and the Ekman inflow hook)

import pandas as pd  # noqa: E402
from floris import FlorisModel, WindRose  # noqa: E402
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

from floris_ekman_veer import annual_energy, optimize_yaw  # noqa: E402
from floris_ekman_veer.studies.comparison import (  # noqa: E402
    builtin_model,
    comparison_set_kwargs,
    fair_builtin_set_kwargs,
)
from floris_ekman_veer.plugin.inflow.inflow import set_atmosphere  # noqa: E402
from floris_ekman_veer.studies.validity import validity_report, validity_summary  # noqa: E402
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning  # noqa: E402

DAY_INPUT = REPOSITORY / "inputs" / "farm_day.yaml"
NIGHT_INPUT = REPOSITORY / "inputs" / "farm_night.yaml"
#: The neutral day's atmosphere (CNBL: cooling rate 0; farm_day.yaml is a convective day).
CNBL_INPUT = REPOSITORY / "inputs" / "cnbl.yaml"
SBL4_INPUT = REPOSITORY / "inputs" / "sbl4.yaml"
#: name -> (label printed, FLORIS configuration): GCH with wind_veer = 0 is the comparison.
MODELS = {
    "ekman_veer": "ekman_veer (M-1)",
    "gch": "GCH, wind_veer 0 (the comparison)",
    "gch_fair_veer": "GCH, fair wind_veer (flagged: cos(wind_veer) narrowing)",
}

# Study settings (inputs of the study, not results).
YAW_LIMIT = 25.0                               # degrees, optimised over -YAW_LIMIT..YAW_LIMIT
ASYMMETRY_YAW = 20.0                           # deg: the front rotor's P(+b)/P(-b)
NY_PASSES = [5, 4]                             # YawOptimizationSR passes
NIGHT_FREQUENCY = 0.5                          # stable nights, neutral days
ROSE_WEIBULL = (2.0, 8.0)                      # shape k, scale A [m/s] of the speeds
ROSE_PREVAILING, ROSE_SPREAD = 270.0, 60.0     # deg: direction of most wind, its spread
GRIDS = {
    False: dict(spacings=(4.0, 5.0, 7.0), speeds=(8.0, 10.0, 12.0), models=tuple(MODELS),
                atmospheres=("CNBL", "SBL-4", "night -0.25 K/h"),
                rose_directions=np.arange(0.0, 360.0, 30.0), rose_speeds=np.arange(4.0, 14.1, 2.0),
                rose_models=("ekman_veer", "gch"), rose_bounds=(-YAW_LIMIT, YAW_LIMIT)),
    # Each FLORIS optimiser evaluation rebuilds a model: the reduced study makes few of them
    # (and steers the farm one way only, two optimiser runs instead of six).
    True: dict(spacings=(5.0,), speeds=(8.0,), models=("ekman_veer",),
               atmospheres=("CNBL", "night -0.25 K/h"),
               rose_directions=np.array([270.0]), rose_speeds=np.array([8.0]),
               rose_models=("ekman_veer",), rose_bounds=(0.0, YAW_LIMIT)),
}


def _block(path):
    return load_yaml(path)["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]


def atmospheres() -> dict[str, dict]:
    """The neutral day, SBL-4 and the shipped night, from the inputs."""
    return {"CNBL": _block(CNBL_INPUT), "SBL-4": _block(SBL4_INPUT),
            "night -0.25 K/h": _block(NIGHT_INPUT)}


def wind_rose(directions, speeds) -> WindRose:
    """A Weibull speed distribution times a smooth direction distribution (ROSE_* settings)."""
    k, scale = ROSE_WEIBULL
    speed_weight = (k / scale) * (speeds / scale) ** (k - 1) * np.exp(-(speeds / scale) ** k)
    offset = np.deg2rad(directions - ROSE_PREVAILING)
    direction_weight = np.exp(np.cos(offset) / np.deg2rad(ROSE_SPREAD))
    freq = np.outer(direction_weight, speed_weight)
    return WindRose(wind_directions=directions, wind_speeds=speeds, ti_table=0.06,
                    freq_table=freq / freq.sum())


def row_model(spacing: float) -> FlorisModel:
    """Three NREL 5 MW of the day input in a row along 270 degrees, ``spacing`` rotor diameters."""
    fmodel = FlorisModel(DAY_INPUT)
    diameter = float(fmodel.core.farm.rotor_diameters[0])
    fmodel.set(layout_x=spacing * diameter * np.arange(3), layout_y=np.zeros(3))
    return fmodel


def model_on(fmodel, name: str, atmosphere: dict, speeds, yaw=None):
    """``name`` (a MODELS key) on these speeds (wind from 270 deg) and this atmosphere, with the
    atmosphere's I_u(z_h) as FLORIS's turbulence intensity."""
    base = "gch" if name.startswith("gch") else None
    model = fmodel.copy() if base is None else builtin_model(fmodel, base)
    n = len(speeds)
    set_atmosphere(model, atmosphere, wind_directions=np.full(n, 270.0),
                   wind_speeds=np.asarray(speeds, float), turbulence_intensities=np.full(n, 0.06),
                   yaw_angles=yaw)
    if name == "gch_fair_veer":
        model.set(**fair_builtin_set_kwargs(model))
    else:  # annual_energy's comparison (ekman_veer reads neither veer nor shear)
        farm = model.core.farm
        model.set(**comparison_set_kwargs(atmosphere, speeds,
                                          model.core.flow_field.reference_wind_height,
                                          float(farm.hub_heights.flat[0]),
                                          float(farm.rotor_diameters.flat[0])))
    return model


def validity_lines(atmospheres_: dict, speeds) -> dict[str, tuple[str, pd.DataFrame]]:
    """Per atmosphere: the one-line validity summary and the report of the row's conditions."""
    out = {}
    for label, atmosphere in atmospheres_.items():
        report = validity_report(model_on(row_model(5.0), "ekman_veer", atmosphere, speeds))
        out[label] = (validity_summary(report, label), report)
    return out


def front_rotor_asymmetry(atmosphere: dict, speeds) -> np.ndarray:
    """P(+b)/P(-b) of one unwaked NREL 5 MW yawed by b = ASYMMETRY_YAW, per speed."""
    fmodel = FlorisModel(DAY_INPUT)
    fmodel.set(layout_x=[0.0], layout_y=[0.0])
    speeds = np.asarray(speeds, float)
    yaw = np.concatenate([np.full(speeds.size, ASYMMETRY_YAW), np.full(speeds.size, -ASYMMETRY_YAW)])
    n = yaw.size
    set_atmosphere(fmodel, atmosphere, wind_directions=np.full(n, 270.0),
                   wind_speeds=np.tile(speeds, 2), turbulence_intensities=np.full(n, 0.06),
                   yaw_angles=yaw[:, None])
    fmodel.run()
    power = fmodel.get_turbine_powers()[:, 0]
    return power[: speeds.size] / power[speeds.size:]


def row_yaw_study(atmospheres_: dict, spacings, speeds, models, inside: dict):
    """Per atmosphere, spacing, speed and model: the optimum over both signs and per sign."""
    rows = []
    for label, atmosphere in atmospheres_.items():
        asymmetry = front_rotor_asymmetry(atmosphere, speeds)
        for spacing in spacings:
            row = row_model(spacing)
            for name in models:
                model = model_on(row, name, atmosphere, speeds)
                runs = {}
                for key, bounds in (("both", (-YAW_LIMIT, YAW_LIMIT)), ("+", (0.0, YAW_LIMIT)),
                                    ("-", (-YAW_LIMIT, 0.0))):
                    runs[key] = optimize_yaw(model, YawOptimizationSR,
                                             minimum_yaw_angle=bounds[0],
                                             maximum_yaw_angle=bounds[1], Ny_passes=NY_PASSES,
                                             progress=False)
                for k, speed in enumerate(speeds):
                    best = runs["both"].iloc[k]
                    yaw = np.asarray(best["yaw_angles_opt"], float)

                    def gain(df):
                        return 100.0 * (df["farm_power_opt"].iloc[k]
                                        / df["farm_power_baseline"].iloc[k] - 1.0)

                    rows.append({
                        "atmosphere": label, "spacing_D": spacing, "wind_speed": speed,
                        "model": name, "yaw_T1": yaw[0], "yaw_T2": yaw[1], "yaw_T3": yaw[2],
                        "gain_percent": gain(runs["both"]), "gain_plus_only": gain(runs["+"]),
                        "gain_minus_only": gain(runs["-"]),
                        "front_P_plus_over_minus": asymmetry[k],
                        "inside_envelope": bool(inside[label].loc[k, "inside_envelope"]),
                    })
    return pd.DataFrame(rows)


def day_night_energy(atmospheres_: dict, directions, speeds, models, bounds=(-YAW_LIMIT, YAW_LIMIT)):
    """AEP of the 3 x 3 farm: neutral days and stable nights (-0.25 K/h), with and without
    steering."""
    stability = {
        "neutral day": {"frequency": 1.0 - NIGHT_FREQUENCY, "atmosphere": atmospheres_["CNBL"]},
        "stable night": {"frequency": NIGHT_FREQUENCY, "atmosphere": _block(NIGHT_INPUT)},
    }
    return annual_energy(FlorisModel(DAY_INPUT), wind_rose(directions, speeds), stability,
                         YawOptimizationSR, models=models, minimum_yaw_angle=bounds[0],
                         maximum_yaw_angle=bounds[1], Ny_passes=NY_PASSES)


def run_study(reduced: bool = False, energy: bool = True) -> dict:
    """The whole computation (no figures); ``reduced``: the coarse grid (GRIDS); ``energy``:
    also the day/night AEP of the 3 x 3 farm (None in the result otherwise)."""
    grid = GRIDS[reduced]
    atmospheres_ = {k: v for k, v in atmospheres().items() if k in grid["atmospheres"]}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ShallowBoundaryLayerWarning)
        validity = validity_lines(atmospheres_, grid["speeds"])
        yaw = row_yaw_study(atmospheres_, grid["spacings"], grid["speeds"], grid["models"],
                            {k: v[1] for k, v in validity.items()})
        energy = day_night_energy(atmospheres_, grid["rose_directions"], grid["rose_speeds"],
                                  grid["rose_models"], grid["rose_bounds"]) if energy else None
    for w in caught:
        if not issubclass(w.category, ShallowBoundaryLayerWarning):  # said by the validity lines
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return {"validity": {k: v[0] for k, v in validity.items()}, "yaw": yaw, "energy": energy}


# ----------------------------------------------------------------------------------- figures
#: How the row figure tells the models apart: colour, a small shift along the spacing axis (so
#: that equal optima, e.g. two models at the -25 deg bound, stay visible side by side) and a
#: filled or open marker; the wind speed is the line style and marker shape.
MODEL_STYLE = {"ekman_veer": dict(color="m", shift=-0.14, mfc="m"),
               "gch": dict(color="tab:cyan", shift=0.0, mfc="tab:cyan"),
               "gch_fair_veer": dict(color="tab:gray", shift=0.14, mfc="none")}
SPEED_STYLE = {8.0: ("-", "o", -0.04), 10.0: ("--", "s", 0.0), 12.0: (":", "^", 0.04)}


def _same_sign_segments(x, y):
    """Consecutive points joined only where the optimum keeps its sign: a line from -23 to +23
    deg would suggest optima in between that the study never found."""
    for k in range(len(x) - 1):
        if np.sign(y[k]) == np.sign(y[k + 1]) or 0.0 in (y[k], y[k + 1]):
            yield x[k:k + 2], y[k:k + 2]


def plot_row(yaw: pd.DataFrame, output: Path, dpi: int = 120) -> Path:
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    labels = list(dict.fromkeys(yaw["atmosphere"]))
    fig, axes = plt.subplots(2, len(labels), figsize=(4.2 * len(labels), 7.2), sharex=True,
                             squeeze=False)
    for j, label in enumerate(labels):
        for (name, speed), df in yaw[yaw["atmosphere"] == label].groupby(["model", "wind_speed"]):
            line, marker, shift = SPEED_STYLE.get(speed, ("-", "o", 0.0))
            model = MODEL_STYLE[name]
            df = df.sort_values("spacing_D")
            x = df["spacing_D"].to_numpy() + model["shift"] + shift
            marks = dict(marker=marker, color=model["color"], mfc=model["mfc"], ms=5)
            axes[0, j].plot(x, df["gain_percent"], ls=line, **marks)
            yaw_front = df["yaw_T1"].to_numpy()
            axes[1, j].plot(x, yaw_front, ls="none", **marks)
            for xs, ys in _same_sign_segments(x, yaw_front):
                axes[1, j].plot(xs, ys, ls=line, color=model["color"])
        axes[0, j].set_title(f"{label}: 3-turbine row, 270 deg")
        axes[1, j].set_xlabel("spacing [D]")
        axes[1, j].axhline(0.0, color="k", lw=0.5)
        for bound in (-YAW_LIMIT, YAW_LIMIT):
            axes[1, j].axhline(bound, color="k", lw=0.5, ls=":")
    axes[0, 0].set_ylabel("farm power gain [%]")
    axes[1, 0].set_ylabel("optimal yaw of the front turbine [deg]\n(dotted: the search's bounds)")
    # One legend below the panels, colour = model, style = wind speed: off the data.
    models = [Line2D([], [], color=m["color"], marker="o", mfc=m["mfc"], label=MODELS[name])
              for name, m in MODEL_STYLE.items() if name in set(yaw["model"])]
    speeds = [Line2D([], [], color="k", ls=ls, marker=mk, mfc="none", label=f"{speed:g} m/s")
              for speed, (ls, mk, _) in SPEED_STYLE.items() if speed in set(yaw["wind_speed"])]
    fig.tight_layout(rect=(0.0, 0.13, 1.0, 1.0))
    fig.legend(handles=models, loc="lower center", bbox_to_anchor=(0.5, 0.05), ncol=3,
               fontsize=8, frameon=False, title_fontsize=8,
               title="colour: model; markers side by side where optima coincide (as at the "
                     "-25 deg bound); lines join optima of one sign only")
    fig.legend(handles=speeds, loc="lower center", bbox_to_anchor=(0.5, 0.0), ncol=3,
               fontsize=8, frameon=False)
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
    parser.add_argument("--energy", action="store_true",
                        help="also the day/night AEP of the 3 x 3 farm (six optimiser runs per "
                             "class and model: slow)")
    args = parser.parse_args(argv)
    args.output.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    study = run_study(energy=args.energy)
    pd.set_option("display.width", 250)
    pd.set_option("display.max_rows", 300)

    print("Validity of the row's conditions (docs/yaw_steering.md#the-validated-envelope):")
    for line in study["validity"].values():
        print("  " + line)
    print("Models (same Ekman inflow, same veer-aware rotor): "
          + "; ".join(f"{k} = {v}" for k, v in MODELS.items()))
    print("The comparison is GCH with wind_veer 0; GCH with the fair wind_veer is shown for "
          "reference only: at tens of degrees of veer gauss's cos(wind_veer) narrowing makes its "
          "unsteered wakes very deep and its gains measure that, not steering "
          "(docs/yaw_steering.md#comparing-with-floriss-models).")

    yaw = study["yaw"]
    print(f"\n3-turbine NREL 5 MW row, wind along the row: optimal yaw [deg] over +-{YAW_LIMIT:g} "
          "deg (both signs), farm power gain [%], the best gain with each sign alone, and the "
          f"front rotor's own P(+{ASYMMETRY_YAW:g})/P(-{ASYMMETRY_YAW:g}). "
          "inside_envelope False: outside the paper's validated envelope (stability, h / rotor "
          "top or u*/(f z0); the validity lines say which), extrapolated, not validated.")
    print(yaw.to_string(index=False, float_format="%.3f"))
    table = yaw.pivot_table(index=["atmosphere", "model"], columns=["spacing_D", "wind_speed"],
                            values="gain_percent")
    print("\nfarm power gain [%] by spacing [D] and wind speed [m/s]:")
    print(table.to_string(float_format="%.2f"))

    energy = study["energy"]
    paths = [plot_row(yaw, args.output)]
    if args.gallery is not None:
        args.gallery.mkdir(parents=True, exist_ok=True)
        paths.append(plot_row(yaw, args.gallery, dpi=60))
    if energy is None:
        for path in paths:
            print(f"wrote {path}")
        print(f"done in {time.perf_counter() - started:.1f} s (day/night AEP: --energy)")
        return
    print("\n3 x 3 farm, day/night annual energy [GWh] with and without wake steering "
          f"(Weibull k = {ROSE_WEIBULL[0]:g}, A = {ROSE_WEIBULL[1]:g} m/s; nights "
          f"{NIGHT_FREQUENCY:.0%} of the year, -0.25 K/h; days CNBL):")
    print(energy.table.to_string(index=False, float_format="%.3f"))
    for path in paths + [plot_energy(energy, args.output)]:
        print(f"wrote {path}")
    print(f"done in {time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()
