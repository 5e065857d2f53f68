"""PyWake's Zong & Porte-Agel (2020) and Niayifar & Porte-Agel (2016) on the shipped farm cases,
scored as the package's models are (hand-run; needs the ``peers`` extra):

    pip install '.[peers]'
    python -m benchmarks.peer_validation [--output DIR]

The two PyWake models run as PyWake's own validation runs them (py_wake.validation): uniform
inflow at the case's hub-height speed and turbulence intensity (Horns Rev 1: 8 m/s, 0.056;
Lillgrund: 9 m/s, 0.048), the case's turbine table, PyWake's default settings of each model
(``Zong_PorteAgel_2020``: its near-wake width, local-TI expansion, Crespo-Hernandez added
turbulence with the largest wake's kept, the momentum-conserving ``WeightedSum``, rotor centre;
``Niayifar_PorteAgel_2016``: k = 0.3837 I + 0.003678, the same added turbulence, ``LinearSum`` of
the deficits scaled with each rotor's incoming speed, Gaussian overlap rotor average). Their
turbine powers at whole-degree directions are turned into P_i/P_1 along the case's reference
rows exactly as ``studies.validation.models.row_ratios`` does for FLORIS (mean over the measured
direction bin; "averaged": each turbine's powers weighted over the direction uncertainty with
its Gaussian, 1-degree samples out to 3 sigma_max), and scored with
``studies.validation.metrics.row_errors`` (RMSE and bias over the waked positions) beside the
published EllipSys3D RANS; Horns Rev's farm efficiency against the LES likewise. Prints markdown
tables (docs/validation.md#peers) and writes ``peer_rows.csv`` to DIR (default ./output).
Takes a minute or two.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd

from floris_ekman_veer.studies.validation import metrics, models
from floris_ekman_veer.studies.validation.cases import HORNS_REV, LILLGRUND, SINGLE_WAKE_CASES
from floris_ekman_veer.studies.validation.turbines import constant_thrust_turbine

#: Sample spacing of the direction-uncertainty average [deg] (as examples/validate.py).
SAMPLE_STEP = 1.0


def pywake_models():
    """{label: PyWake wind-farm-model class} of the two peers."""
    from py_wake.literature.gaussian_models import Niayifar_PorteAgel_2016, Zong_PorteAgel_2020

    return {"PyWake Zong & Porte-Agel 2020": Zong_PorteAgel_2020,
            "PyWake Niayifar & Porte-Agel 2016": Niayifar_PorteAgel_2016}


def pywake_turbine(case):
    """The case's FLORIS turbine table (``case.turbine``) as a PyWake wind turbine."""
    from py_wake.wind_turbines import WindTurbine
    from py_wake.wind_turbines.power_ct_functions import PowerCtTabular

    table = case.turbine["power_thrust_table"]
    return WindTurbine(name=str(case.turbine["turbine_type"]), diameter=case.rotor_diameter,
                       hub_height=case.hub_height,
                       powerCtFunction=PowerCtTabular(
                           ws=np.asarray(table["wind_speed"], dtype=float),
                           power=np.asarray(table["power"], dtype=float), power_unit="kW",
                           ct=np.asarray(table["thrust_coefficient"], dtype=float)))


def turbine_powers(case, model_class, directions) -> np.ndarray:
    """(n_directions, n_turbines) powers [W] of the PyWake model on the case's uniform inflow."""
    from py_wake.site import UniformSite

    site = UniformSite(p_wd=[1], ti=case.turbulence, ws=case.wind_speed)
    model = model_class(site, pywake_turbine(case))
    x, y = case.layout
    result = model(x, y, wd=np.asarray(directions, dtype=float), ws=[case.wind_speed], yaw=0)
    return np.asarray(result.Power.values[:, :, 0], dtype=float).T


def _uncertainty_weights(sigma, offsets):
    weights = np.exp(-(offsets[:, None] ** 2) / (2.0 * sigma[None, :] ** 2))
    return weights / weights.sum(axis=0)


def row_ratios(case, label, model_class) -> pd.DataFrame:
    """The tidy P_i/P_1 table of ``studies.validation.models.row_ratios`` for a PyWake model."""
    sigma = case.direction_sigma()
    reach = np.ceil(3.0 * sigma.max() / SAMPLE_STEP) * SAMPLE_STEP
    samples = np.arange(-reach, reach + 0.5 * SAMPLE_STEP, SAMPLE_STEP)
    offsets = np.asarray(case.direction_offsets, dtype=float)
    row_directions = sorted({row.wind_direction for row in case.rows})
    centres = np.concatenate([d + offsets for d in row_directions])
    wanted = np.unique(np.round((centres[:, None] + samples[None, :]) % 360.0, 6))
    powers = turbine_powers(case, model_class, wanted)
    index = {float(d): k for k, d in enumerate(wanted)}
    at = lambda d: powers[index[float(np.round(d % 360.0, 6))]]  # noqa: E731
    weights = _uncertainty_weights(sigma, samples)
    raw = np.array([at(d) for d in centres])
    averaged = np.array([np.sum(weights * np.array([at(d + s) for s in samples]), axis=0)
                         for d in centres])
    frames = []
    for row in case.rows:
        k = row_directions.index(row.wind_direction)
        chosen = slice(k * offsets.size, (k + 1) * offsets.size)
        turbines = np.where(row.turbines < 0, 0, row.turbines)
        gaps = np.all(row.turbines < 0, axis=1)
        for kind, table in (("raw", raw), ("averaged", averaged)):
            mean = table[chosen].mean(axis=0)[turbines].mean(axis=1)
            rans = (row.rans[:, 2 if kind == "averaged" else 1] if row.rans is not None
                    else np.full(len(row.turbines), np.nan))
            frames.append(pd.DataFrame({
                "case": case.name, "reading": "uniform", "model": label, "row": row.label,
                "wind_direction": row.wind_direction,
                "position": row.measured[:, 0].astype(int), "kind": kind,
                "ratio": np.where(gaps, np.nan, mean / mean[0]),
                "measured": row.measured[:, 1], "standard_error": row.measured[:, 2],
                "rans": rans}))
    return pd.concat(frames, ignore_index=True)


def farm_efficiency(case, label, model_class) -> pd.DataFrame:
    """Farm power over n unwaked turbines' at the efficiency reference's directions."""
    reference = case.efficiency
    powers = turbine_powers(case, model_class, reference.directions)
    unwaked = turbine_powers(case, model_class, [reference.directions[0]]).max()
    return pd.DataFrame({"case": case.name, "reading": "uniform", "model": label,
                         "wind_direction": reference.directions,
                         "efficiency": powers.sum(axis=1) / (unwaked * powers.shape[1]),
                         "reference": reference.efficiency})


def arc_profiles(case, model_class, step: float = 0.5) -> np.ndarray:
    """U/U0 at hub height on the single-wake case's arcs (``models.arc_profiles``' layout: rows
    ``case.distances``, columns ``models.arc_directions``), PyWake's model on uniform inflow at
    the case's speed and total TI (as PyWake's validation gives them), the case's C_T."""
    from py_wake.flow_map import Points
    from py_wake.site import UniformSite

    turbine = constant_thrust_turbine(case)
    pywake = pywake_turbine(SimpleNamespace(
        turbine=turbine, rotor_diameter=case.rotor_diameter, hub_height=case.hub_height))
    site = UniformSite(p_wd=[1], ti=case.total_turbulence, ws=case.wind_speed)
    theta = np.radians(models.arc_directions(step))
    radius = np.asarray(case.distances)[:, None] * case.rotor_diameter
    # PyWake's wind from 270 deg blows along +x, as FLORIS's.
    x, y = radius * np.cos(theta), radius * np.sin(theta)
    result = model_class(site, pywake)([0.0], [0.0], wd=[270.0], ws=[case.wind_speed], yaw=0)
    flow = result.flow_map(Points(x.ravel(), y.ravel(), np.full(x.size, case.hub_height)))
    return np.asarray(flow.WS_eff).reshape(x.shape) / case.wind_speed


def _pooled(chosen) -> str:
    if not chosen:
        return "-"
    rmse, bias, _ = metrics.pooled(chosen)
    return f"{rmse:.3f} ({bias:+.3f})"


def _cell(row) -> str:
    return f"{row.rmse:.3f} ({row.bias:+.3f})"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=Path("output"))
    args = parser.parse_args(argv)
    args.output.mkdir(parents=True, exist_ok=True)
    rows = pd.concat([row_ratios(case, label, model_class)
                      for case in (HORNS_REV, LILLGRUND)
                      for label, model_class in pywake_models().items()], ignore_index=True)
    rows.to_csv(args.output / "peer_rows.csv", index=False)
    errors = metrics.row_errors(rows)
    print("| model | Horns Rev rows, averaged | Horns Rev rows, raw | Lillgrund rows, averaged "
          "| Lillgrund rows, raw | Horns Rev efficiency |")
    print("|---|---|---|---|---|---|")
    for label, model_class in pywake_models().items():
        cells = [_cell(next(errors[(errors["case"] == case.name) & (errors["model"] == label)
                                   & (errors["kind"] == kind)].itertuples()))
                 for case in (HORNS_REV, LILLGRUND) for kind in ("averaged", "raw")]
        efficiency = metrics.efficiency_errors(farm_efficiency(HORNS_REV, label, model_class))
        print(f"| {label} | " + " | ".join(cells) + f" | {_cell(next(efficiency.itertuples()))} |")
    print()
    print("Single wakes: RMSE (bias) of U/U0 pooled over the arcs, against the measurements / "
          "the LES")
    print("| model | " + " | ".join(SINGLE_WAKE_CASES) + " |")
    print("|---|" + "---|" * len(SINGLE_WAKE_CASES))
    for label, model_class in pywake_models().items():
        cells = []
        for case in SINGLE_WAKE_CASES.values():
            errors = metrics.arc_errors(case, arc_profiles(case, model_class))
            parts = []
            for reference in ("measured", "les"):
                chosen = [e for e in errors if e["reference"] == reference]
                parts.append(_pooled(chosen))
            cells.append(" / ".join(parts))
        print(f"| {label} | " + " | ".join(cells) + " |")
    print()
    for case in (HORNS_REV, LILLGRUND):
        chosen = rows[(rows["case"] == case.name) & (rows["kind"] == "averaged")]
        labels = list(pywake_models())
        first = chosen[chosen["model"] == labels[0]].reset_index(drop=True)
        print(f"{case.name}, direction-averaged P_i/P_1 by position")
        print("| row | position | measured | RANS | " + " | ".join(labels) + " |")
        print("|---|---|---|---|" + "---|" * len(labels))
        for k, point in first.iterrows():
            if np.isnan(point["measured"]):
                continue
            values = [chosen[chosen["model"] == m]["ratio"].iloc[k] for m in labels]
            print(f"| {point['row']}, {point['wind_direction']:g} | {point['position']} | "
                  f"{point['measured']:.3f} | {point['rans']:.3f} | "
                  + " | ".join(f"{v:.3f}" for v in values) + " |")
        print()


if __name__ == "__main__":
    main()
