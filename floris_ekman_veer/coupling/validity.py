"""Per-condition validity of a model's atmosphere: is each condition inside what the paper
validated? (docs/yaw_steering.md#the-validated-envelope)

Narasimhan, Gayme & Meneveau (JRSE 2025) validate the model against LES from the neutral CNBL
(stability parameter mu = 0) to the strongly stable SBL-6 (Table 1: mu = 148.49, h of about
200 m, 22.5 degrees of veer across a 50-150 m rotor), always with the whole rotor inside the
boundary layer. A condition is *inside the envelope* when 0 <= mu <= 169 (SBL-6 as the model
closes the LES's cooling rate; Table 1 lists 148.49) and the boundary layer top h lies above
every rotor top. Outside it (a shallow night, h below the rotor top) the
inflow above h is the geostrophic wind and the wake model is extrapolated
(docs/atmosphere.md#shallow-boundary-layer): its numbers, and any gain computed from them, are
not validated.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from floris_ekman_veer.coupling.inflow import atmosphere_of, solve

#: The paper's Table 1 stability parameter of SBL-6, the most stable validated case.
MU_SBL6_TABLE1 = 148.49


def _mu_sbl6_closure() -> float:
    """mu of SBL-6 as the model closes the LES's forcing (-1 K/h at G = 15 m/s,
    inputs/sbl6.yaml): 169."""
    from floris_ekman_veer.atmosphere.ekman import EkmanABL

    return float(EkmanABL(geostrophic_wind=15.0, coriolis_parameter=1e-4, roughness_length=0.1,
                          cooling_rate=-1.0, brunt_vaisala_frequency=6.1e-3,
                          reference_potential_temperature=265.0).stability_parameter)


#: The envelope's upper stability parameter: the larger of SBL-6's two definitions (Table 1's
#: 148.49 and the cooling-rate closure's 169), so that the paper's own SBL-6 case is inside.
MU_ENVELOPE = max(MU_SBL6_TABLE1, _mu_sbl6_closure())


#: Columns of the report that describe the condition, not its boundary layer.
_CONDITION_COLUMNS = ("wind_direction", "wind_speed", "rotor_top")


def _rest_rows_marked(report_function):
    """Rows of conditions at rest (calm, or below every cut-in where no ABL reaches their speed,
    docs/user_guide.md#calm-and-weak-winds) have no boundary layer: an ``at_rest`` column, NaN
    (False, for flags; "at rest", for names) in the boundary layer's columns, and never
    inside the envelope. (The solve gives them a moving condition's ABL as a stand-in.)"""
    import functools

    @functools.wraps(report_function)
    def report_with_rest(fmodel, *args, **kwargs):
        report = report_function(fmodel, *args, **kwargs)
        flow_field = fmodel.core.flow_field
        abl = solve(atmosphere_of(fmodel.core), flow_field.wind_speeds,
                    flow_field.reference_wind_height)  # (cached: the report's own solve)
        rest = np.asarray(getattr(abl, "at_rest", np.zeros(len(report), bool))).reshape(-1)
        for column in report.columns:
            if column in _CONDITION_COLUMNS or not rest.any():
                continue
            values = report[column]
            if pd.api.types.is_bool_dtype(values):
                report[column] = values & ~rest
            elif pd.api.types.is_numeric_dtype(values):
                report[column] = values.astype(float).where(~rest, np.nan)
            else:
                report[column] = values.where(~rest, "at rest")
        report.insert(2, "at_rest", rest)
        return report

    return report_with_rest


@_rest_rows_marked
def validity_report(fmodel) -> pd.DataFrame:
    """One row per condition of ``fmodel``: the atmosphere against the paper's envelope.

    Columns: ``wind_direction``, ``wind_speed`` [m/s at the reference height],
    ``boundary_layer_height`` h [m], ``rotor_top`` [m] (the highest rotor of the farm),
    ``h_above_rotor_top`` (bool), ``veer_across_rotor_deg`` (change of wind direction from the
    lowest rotor bottom to the highest rotor top, positive veering), ``turbulence_intensity``
    (the ABL's I_u at the farm's mean hub height, Eq. Iu_model), ``stability_parameter`` mu,
    ``inside_envelope`` (0 <= mu <= :data:`MU_ENVELOPE` = 169 and h above the rotor top),
    ``at_rest`` (a calm condition: no boundary layer, its columns NaN).

    Raises:
        ValueError: if ``fmodel`` has no atmosphere (plain FLORIS has nothing to report).
    """
    core = fmodel.core
    spec = atmosphere_of(core)
    if spec is None:
        raise ValueError(
            "validity_report: the model has no atmosphere "
            "(wake.wake_velocity_parameters.ekman_veer.atmosphere)"
        )
    flow_field, farm = core.flow_field, core.farm
    abl = solve(spec, flow_field.wind_speeds, flow_field.reference_wind_height)
    hubs = np.asarray(farm.hub_heights, dtype=float).reshape(-1, farm.n_turbines)[0]
    radii = 0.5 * np.asarray(farm.rotor_diameters, dtype=float).reshape(-1, farm.n_turbines)[0]
    top, bottom = float(np.max(hubs + radii)), float(np.min(hubs - radii))
    h = np.asarray(abl.boundary_layer_height, dtype=float).reshape(-1)
    mu = np.broadcast_to(np.asarray(abl.stability_parameter, dtype=float).reshape(-1), h.shape)
    veer = np.asarray(abl.wind_direction_change(bottom, top), dtype=float).reshape(-1)
    ti = np.asarray(abl.turbulence_intensity(float(np.mean(hubs))), dtype=float).reshape(-1)
    above = h >= top
    return pd.DataFrame({
        "wind_direction": np.asarray(flow_field.wind_directions, dtype=float),
        "wind_speed": np.asarray(flow_field.wind_speeds, dtype=float),
        "boundary_layer_height": h,
        "rotor_top": top,
        "h_above_rotor_top": above,
        "veer_across_rotor_deg": veer,
        "turbulence_intensity": ti,
        "stability_parameter": mu,
        "inside_envelope": above & (mu >= 0.0) & (mu <= MU_ENVELOPE * (1 + 1e-12)),
    })


def validity_summary(report: pd.DataFrame, label: str = "") -> str:
    """One line: how many conditions are inside the envelope, and the ranges of h, veer, I_u."""
    inside = int(report["inside_envelope"].sum())
    n = len(report)
    prefix = f"{label}: " if label else ""
    line = (
        f"{prefix}{inside} of {n} conditions inside the paper's CNBL..SBL-6 envelope "
        f"(h {report.boundary_layer_height.min():.0f}-{report.boundary_layer_height.max():.0f} m, "
        f"rotor top {report.rotor_top.iloc[0]:.0f} m; veer across the rotor "
        f"{report.veer_across_rotor_deg.min():.1f}-{report.veer_across_rotor_deg.max():.1f} deg; "
        f"I_u {100 * report.turbulence_intensity.min():.1f}-"
        f"{100 * report.turbulence_intensity.max():.1f} %)"
    )
    outside = report[~report["inside_envelope"]]
    if len(outside):
        speeds = ", ".join(f"{s:g}" for s in sorted(set(outside.wind_speed)))
        line += f"; OUTSIDE at {speeds} m/s (results there are extrapolated, not validated)"
    return line
