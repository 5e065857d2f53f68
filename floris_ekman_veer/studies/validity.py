"""Per-condition validity of a model's atmosphere: is each condition inside what the paper
validated? (docs/yaw_steering.md#the-validated-envelope)

Narasimhan, Gayme & Meneveau (JRSE 2025) validate the wake model against LES of one forcing
(G = 15 m/s, z0 = 0.1 m, f_c = 1e-4 1/s; Table 1) in the neutral CNBL and the stable SBL-4,
SBL-5 and SBL-6 (Section 4.3; SBL-1..3 enter only the turbulence-intensity comparison), with a
50-150 m rotor well inside the boundary layer (h / rotor top >= 218/150 = 1.45 in the LES) and
friction Rossby numbers Ro = u*/(f z0) of 3.39e4 to 6.02e4. A condition is *inside the envelope*
only where all three hold, each with the paper's own cases inside it as the model computes them:

- its stability is one the wake validation covers: near-neutral (|mu| < 2.81, half of SBL-1's
  5.62) or SBL-4 to SBL-6 (55.4 <= mu <= 169, so that both Table 1's mu and the cooling-rate
  closure's of each of these cases are inside, and those of SBL-3 are not); convective layers
  (mu <= -2.81) are beyond the paper (docs/atmosphere.md#convective-boundary-layer);
- h / rotor top >= 1.33 (the LES's 1.45 with the h the model gives SBL-6, 199 m);
- Ro within the LES's range widened to the model's u* of the paper's cases (3.39e4 to 6.27e4),
  or a ``rossby_range`` the caller documents.

Farms add physics the paper's single wakes do not test: where a rotor stands in another's wake,
the package's farm coupling (the upstream wakes' added turbulence in k_w, the wakes scaled with
their rotors' incoming speed and summed, docs/coupling.md#wakes-deep-in-an-array) is beyond the
paper's validation, which the report's ``farm_coupling_beyond_paper`` column says (it leaves
``inside_envelope``, a property of the atmosphere, unchanged). Likewise the near wake: where a
rotor may stand inside another's potential core, the super-Gaussian profile there
(``near_wake: super_gaussian``, docs/wake_model.md#near-wake) is beyond the paper, which the
``near_wake_beyond_paper`` column says per condition.

Outside it the wake model is extrapolated (a shallow night, h below the rotor top, sees the
geostrophic wind above h: docs/atmosphere.md#shallow-boundary-layer): its numbers, and any gain
computed from them, are not validated.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from floris_ekman_veer._validation import real_array, require_floris_model
from floris_ekman_veer.plugin.inflow.inflow import atmosphere_of, solve
from floris_ekman_veer.wake.deficit import initial_radius, potential_core_length

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

#: Table 1: the LES cases' stability parameter mu, friction Rossby number u*/(f z0), cooling rate
#: [K/h] and h [m] (G = 15 m/s, f_c = 1e-4 1/s, z0 = 0.1 m, N = 6.1e-3 1/s, Theta0 = 265 K).
TABLE1 = {
    "CNBL": (0.0, 6.02e4, 0.0, 1157.0),
    "SBL-1": (5.62, 5.93e4, -0.03, 1032.0),
    "SBL-2": (20.59, 5.25e4, -0.125, 662.0),
    "SBL-3": (39.84, 4.58e4, -0.25, 463.0),
    "SBL-4": (59.25, 4.12e4, -0.375, 361.0),
    "SBL-5": (78.35, 3.84e4, -0.5, 306.0),
    "SBL-6": (148.49, 3.39e4, -1.0, 218.0),
}
#: The cases whose wakes the paper compares with LES (Section 4.3).
WAKE_VALIDATED = ("CNBL", "SBL-4", "SBL-5", "SBL-6")
#: The LES rotor top [m]: hub 100 m + D/2 = 50 m (Section 3.1).
LES_ROTOR_TOP = 150.0


def _paper_cases():
    """The model's ABL of each Table 1 case (its cooling rate at G = 15 m/s), one vectorised solve."""
    from floris_ekman_veer.atmosphere.ekman import EkmanABL

    return EkmanABL(geostrophic_wind=15.0, coriolis_parameter=1e-4, roughness_length=0.1,
                    cooling_rate=np.array([case[2] for case in TABLE1.values()]),
                    brunt_vaisala_frequency=6.1e-3, reference_potential_temperature=265.0)


_MODEL_CASES = _paper_cases()
#: Each case's two values of mu: Table 1's and the cooling-rate closure's (CNBL 0 and 0 ...
#: SBL-3 39.84 and 51.56, SBL-4 59.25 and 72.71, ... SBL-6 148.49 and 169.02).
_CASE_MU = np.array([[case[0] for case in TABLE1.values()],
                     np.asarray(_MODEL_CASES.stability_parameter, dtype=float)])
#: Class edges in mu: midway between the larger mu of a case and the smaller of the next, so that
#: both readings of every case fall in its own class (2.81, 14.4, 34.2, 55.4, 75.5, 120.7).
CLASS_EDGES = 0.5 * (_CASE_MU.max(axis=0)[:-1] + _CASE_MU.min(axis=0)[1:])
#: |mu| below this is near-neutral (the CNBL class): the CNBL/SBL-1 edge, half of SBL-1's 5.62.
MU_NEAR_NEUTRAL = float(CLASS_EDGES[0])
#: The lower stability parameter of the validated stable wakes: the SBL-3/SBL-4 edge (55.4).
MU_SBL4 = float(CLASS_EDGES[list(TABLE1).index("SBL-4") - 1])
#: h / rotor top of the LES (218/150 = 1.45) and of the model's SBL-6 (199/150 = 1.33): the smaller.
MIN_H_OVER_ROTOR_TOP = min(TABLE1["SBL-6"][3], float(_MODEL_CASES.boundary_layer_height[-1])) / (
    LES_ROTOR_TOP)
#: Friction Rossby numbers of Table 1 (3.39e4-6.02e4) widened to the model's u* of the same cases
#: (3.48e4-6.27e4): 3.39e4 to 6.27e4 (compared with a relative tolerance of 1e-9).
ROSSBY_RANGE = (
    min(min(c[1] for c in TABLE1.values()), float(np.min(_MODEL_CASES.friction_rossby_number))),
    max(max(c[1] for c in TABLE1.values()), float(np.max(_MODEL_CASES.friction_rossby_number))),
)


def stability_class(mu) -> np.ndarray:
    """The paper's case a stability parameter belongs to (:data:`CLASS_EDGES`): "convective" for
    mu <= -MU_NEAR_NEUTRAL, "CNBL", "SBL-1".."SBL-6", and "beyond SBL-6" above MU_ENVELOPE."""
    mu = np.asarray(mu, dtype=float)
    label = np.array(list(TABLE1), dtype=object)[np.searchsorted(CLASS_EDGES, mu, side="right")]
    label = np.where(mu <= -MU_NEAR_NEUTRAL, "convective", label)
    return np.where(mu > MU_ENVELOPE * (1 + 1e-12), "beyond SBL-6", label)


def wake_validated_stability(mu) -> np.ndarray:
    """Whether mu is one of the stabilities whose wakes the paper validates: near-neutral
    (|mu| < MU_NEAR_NEUTRAL) or SBL-4 to SBL-6 (MU_SBL4 <= mu <= MU_ENVELOPE)."""
    mu = np.asarray(mu, dtype=float)
    return (np.abs(mu) < MU_NEAR_NEUTRAL) | (
        (mu >= MU_SBL4 * (1 - 1e-12)) & (mu <= MU_ENVELOPE * (1 + 1e-12))
    )


#: Columns of the report that describe the condition, not its boundary layer.
_CONDITION_COLUMNS = ("wind_direction", "wind_speed", "rotor_top")


def _mark_rest(report: pd.DataFrame, rest: np.ndarray) -> pd.DataFrame:
    """Rows of conditions at rest (calm, or below every cut-in where no ABL reaches their speed,
    docs/user_guide.md#calm-and-weak-winds) have no boundary layer: an ``at_rest`` column, NaN
    (False, for flags; "at rest", for names) in the boundary layer's columns, and never
    inside the envelope. (The solve gives them a moving condition's ABL as a stand-in.)"""
    if rest.any():
        for column in report.columns:
            if column in _CONDITION_COLUMNS:
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


def validity_report(fmodel, rossby_range=ROSSBY_RANGE) -> pd.DataFrame:
    """One row per condition of ``fmodel``: the atmosphere against the paper's envelope.

    Columns: ``wind_direction``, ``wind_speed`` [m/s at the reference height],
    ``boundary_layer_height`` h [m] (z_i in a convective layer), ``rotor_top`` [m] (the highest
    rotor of the farm), ``h_above_rotor_top`` (bool), ``h_over_rotor_top`` (h / rotor top),
    ``veer_across_rotor_deg`` (change of wind direction from the lowest rotor bottom to the
    highest rotor top, positive veering), ``turbulence_intensity`` (the ABL's I_u at the farm's
    mean hub height, Eq. Iu_model, with the convective variance in a convective layer),
    ``stability_parameter`` mu, ``obukhov_length`` L [m], ``sensible_heat_flux`` [W/m^2, upward
    > 0] (the surface heat flux the condition implies), ``stability_limited`` (bool: carried
    with its stability limited to the heat-flux bound by the atmosphere block's
    ``outside_domain: limit``), ``friction_rossby_number`` u*/(f z0),
    ``stability_class`` (:func:`stability_class`), and the four checks
    ``wake_validated_stability`` (:func:`wake_validated_stability`), ``deep_enough``
    (h / rotor top >= :data:`MIN_H_OVER_ROTOR_TOP`), ``rossby_in_range`` (within
    ``rossby_range``, default :data:`ROSSBY_RANGE`) and ``inside_envelope`` (all three), and
    ``at_rest`` (a calm condition: no boundary layer, its columns NaN), and
    ``farm_coupling_beyond_paper`` (:func:`farm_coupling_beyond_paper`: the same for every
    condition) and ``near_wake_beyond_paper`` (:func:`near_wake_beyond_paper`), and
    ``ambient_turbulence_beyond_paper`` (the atmosphere's ``turbulence_factor`` other than 1:
    the wake's I_u scaled to a site's measured turbulence, docs/atmosphere.md#ambient-turbulence;
    ``turbulence_intensity`` is then the scaled one).

    Raises:
        ValueError: if ``fmodel`` has no atmosphere (plain FLORIS has nothing to report), or if
            ``rossby_range`` is not two increasing positive numbers.
    """
    require_floris_model(fmodel, "validity_report")
    valid = "two positive numbers (low, high) with low < high"
    bounds = real_array("validity_report: rossby_range", rossby_range, valid)
    if bounds.shape != (2,) or not (0 < bounds[0] < bounds[1] < np.inf):
        raise ValueError(
            f"validity_report: rossby_range must be {valid}; got "
            f"{tuple(float(v) for v in np.ravel(bounds))!r}"
        )
    low, high = (float(v) for v in bounds)
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
    per_condition = lambda value: np.broadcast_to(  # noqa: E731
        np.asarray(value, dtype=float).reshape(-1), h.shape)
    rossby = per_condition(abl.friction_rossby_number)
    above = h >= top
    validated = wake_validated_stability(mu)
    deep = h / top >= MIN_H_OVER_ROTOR_TOP * (1 - 1e-12)
    in_range = (rossby >= low * (1 - 1e-9)) & (rossby <= high * (1 + 1e-9))
    rest = np.broadcast_to(np.asarray(getattr(abl, "at_rest", False), dtype=bool).reshape(-1),
                           h.shape)
    return _mark_rest(pd.DataFrame({
        "wind_direction": np.asarray(flow_field.wind_directions, dtype=float),
        "wind_speed": np.asarray(flow_field.wind_speeds, dtype=float),
        "boundary_layer_height": h,
        "rotor_top": top,
        "h_above_rotor_top": above,
        "veer_across_rotor_deg": veer,
        "turbulence_intensity": ti,
        "stability_parameter": mu,
        "h_over_rotor_top": h / top,
        "obukhov_length": per_condition(abl.obukhov_length),
        "sensible_heat_flux": per_condition(abl.sensible_heat_flux),
        # Conditions the atmosphere block's outside_domain: limit carried at the heat-flux
        # bound (docs/atmosphere.md#a-fixed-stability-across-wind-speeds).
        "stability_limited": np.broadcast_to(np.asarray(
            getattr(abl, "domain_limited", False), dtype=bool).reshape(-1), h.shape),
        "friction_rossby_number": rossby,
        "stability_class": stability_class(mu),
        "wake_validated_stability": validated,
        "deep_enough": deep,
        "rossby_in_range": in_range,
        "inside_envelope": validated & deep & in_range,
        "farm_coupling_beyond_paper": farm_coupling_beyond_paper(core),
        "near_wake_beyond_paper": near_wake_beyond_paper(core),
        "ambient_turbulence_beyond_paper": per_condition(
            1.0 if abl.turbulence_factor is None else abl.turbulence_factor) != 1.0,
    }), rest)


def near_wake_beyond_paper(core) -> np.ndarray:
    """Per condition, whether a rotor may stand inside another rotor's potential core with the
    super-Gaussian near wake on (``near_wake: super_gaussian`` of the ekman_veer velocity model,
    docs/wake_model.md#near-wake): downstream of it, along the condition's wind direction, by
    less than the longest core its rotor can have (Eq. x0_transition with k_w at its floor and
    the turbine's C_T at the condition's wind speed, 0.75 where its table has none) and
    laterally within the two rotors' radii plus the stream tube's."""
    velocity = getattr(core.wake, "velocity_model", None)
    farm, flow_field = core.farm, core.flow_field
    directions = np.asarray(flow_field.wind_directions, dtype=float).reshape(-1)
    if farm.n_turbines < 2 or getattr(velocity, "near_wake", None) != "super_gaussian":
        return np.zeros(directions.shape, dtype=bool)
    radii = 0.5 * np.asarray(farm.rotor_diameters, dtype=float).reshape(-1, farm.n_turbines)[0]
    speeds = np.asarray(flow_field.wind_speeds, dtype=float).reshape(-1)
    thrust = np.empty((speeds.size, farm.n_turbines))
    for k, definition in enumerate(farm.turbine_definitions):
        table = definition.get("power_thrust_table", {})
        if "thrust_coefficient" in table and "wind_speed" in table:
            thrust[:, k] = np.interp(speeds, table["wind_speed"], table["thrust_coefficient"])
        else:
            thrust[:, k] = 0.75
    thrust = np.clip(thrust, 0.0, velocity.max_thrust_coefficient)
    core_length = potential_core_length(velocity.k_w_floor, radii, thrust, 0.0)
    tube = initial_radius(radii, thrust, 0.0)
    # FLORIS's frame: the wind from 270 degrees blows along +x.
    angle = np.radians(270.0 - directions)[:, None]
    x, y = np.asarray(farm.layout_x, dtype=float), np.asarray(farm.layout_y, dtype=float)
    along = x * np.cos(angle) + y * np.sin(angle)
    across = -x * np.sin(angle) + y * np.cos(angle)
    dx = along[:, None, :] - along[:, :, None]  # [condition, upstream i, downstream j]
    dy = np.abs(across[:, None, :] - across[:, :, None])
    reach = radii[None, :, None] + radii[None, None, :] + tube[:, :, None]
    inside = (dx > 0.0) & (dx < core_length[:, :, None]) & (dy < reach)
    return inside.any(axis=(1, 2))


def farm_coupling_beyond_paper(core) -> bool:
    """Whether the farm's waked rotors go through the package's farm coupling, beyond the
    paper's single-wake validation: more than one turbine and the ekman_veer or bastankhah2014
    velocity model with the upstream wakes' added turbulence in k_w (``wake_expansion`` other
    than ``ambient``, in either ``wake_turbulence`` form), the incoming-speed deficits or a
    published superposition (``wake_superposition`` momentum_conserving or cumulative, which act
    on FLORIS's ``fls``; with another combination each wake is left to it)
    (docs/coupling.md#wakes-deep-in-an-array)."""
    velocity = getattr(core.wake, "velocity_model", None)
    if core.farm.n_turbines < 2 or not hasattr(velocity, "deficit_velocity"):
        return False
    summed = core.wake.model_strings.get("combination_model") == "fls"
    return (velocity.wake_expansion != "ambient" or velocity.deficit_velocity == "incoming"
            or (velocity.wake_superposition != "combination_model" and summed))


def validity_summary(report: pd.DataFrame, label: str = "") -> str:
    """One line: how many conditions are inside the envelope, and the ranges of h, veer, I_u."""
    inside = int(report["inside_envelope"].sum())
    n = len(report)
    prefix = f"{label}: " if label else ""
    line = (
        f"{prefix}{inside} of {n} conditions inside the paper's validated envelope "
        f"(h {report.boundary_layer_height.min():.0f}-{report.boundary_layer_height.max():.0f} m, "
        f"rotor top {report.rotor_top.iloc[0]:.0f} m; veer across the rotor "
        f"{report.veer_across_rotor_deg.min():.1f}-{report.veer_across_rotor_deg.max():.1f} deg; "
        f"I_u {100 * report.turbulence_intensity.min():.1f}-"
        f"{100 * report.turbulence_intensity.max():.1f} %)"
    )
    at_rest = report["at_rest"] if "at_rest" in report else pd.Series(False, index=report.index)
    if at_rest.any():
        line += f"; {int(at_rest.sum())} at rest (calm: no boundary layer)"
    outside = report[~report["inside_envelope"] & ~at_rest]
    if len(outside):
        speeds = ", ".join(f"{s:g}" for s in sorted(set(outside.wind_speed)))
        line += f"; OUTSIDE at {speeds} m/s (results there are extrapolated, not validated"
        reasons = [
            text for column, text in (
                ("wake_validated_stability", "stability not among CNBL, SBL-4..6"),
                ("deep_enough", f"h below {MIN_H_OVER_ROTOR_TOP:.2f} x rotor top"),
                ("rossby_in_range", "Ro outside the LES's"),
            ) if column in outside and not outside[column].all()
        ]
        if "stability_class" in outside and (outside.stability_class == "convective").any():
            reasons.insert(0, "convective: beyond the paper")
        line += f": {'; '.join(reasons)})" if reasons else ")"
    return line
