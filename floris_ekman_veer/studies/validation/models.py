"""Every case as a FLORIS model on the package's inflow, for the package's and FLORIS's wake models.

One FLORIS input per case, atmosphere reading (validation.atmospheres) and wake model: the
turbines and layout of the case, FLORIS's reference height at the hub, the atmosphere block in
``wake_velocity_parameters.ekman_veer.atmosphere`` (so every model, FLORIS's own included, runs
on the Ekman U(z)), FLORIS's turbulence intensity = I_u(z_h) of that atmosphere and the rotor
veer and shear of ``studies.comparison.fair_builtin_set_kwargs``. The wake models
(:data:`WAKE_MODELS`): the paper's M-1, M-2 and M-3 and FLORIS 4.7's gauss, GCH, cc, TurbOPark
(``turboparkgauss``, A = 0.04) and empirical Gauss with FLORIS's default parameters. Results (docs/validation.md#measured-wakes-and-farms):

* :func:`arc_profiles`: U/U0 at hub height on the arcs of a single-wake case;
* :func:`horns_rev_rows`: P_i/P_1 along Horns Rev's inner rows, as computed and averaged over
  the wind-direction uncertainty with FLORIS's ``UncertainFlorisModel``;
* :func:`horns_rev_efficiency`: the farm efficiency against wind direction.
"""

from __future__ import annotations

import numpy as np
from floris import FlorisModel, UncertainFlorisModel
from floris.uncertain_floris_model import map_turbine_values_uncertain

from floris_ekman_veer.studies.comparison import (
    BUILTIN_WAKES,
    GCH_SWITCHES,
    fair_builtin_set_kwargs,
)
from floris_ekman_veer.studies.validation.atmospheres import atmosphere, hub_turbulence
from floris_ekman_veer.studies.validation.cases import (
    ARC_HALF_WIDTH,
    HORNS_REV,
    constant_thrust_turbine,
    v80_turbine,
)


def _ekman(veer=True, velocity="ekman_veer", wake_expansion="local_turbulence"):
    deflection = {"veer": veer, "yaw_deflection": velocity == "ekman_veer"}
    return ({"velocity_model": velocity, "deflection_model": "ekman_veer",
             "turbulence_model": "crespo_hernandez"}, False,
            {"velocity": {"wake_expansion": wake_expansion}, "deflection": deflection})


def _builtin(name):
    strings, gch = BUILTIN_WAKES[name]
    return ({**strings, "turbulence_model": "crespo_hernandez"}, gch, {})


#: Wake set-ups: model strings, the GCH switches, parameters for the package's models.
#: ``local_turbulence`` is the farm input's wake expansion (docs/coupling.md#wake-expansion-in-farms);
#: for an isolated wake it is the paper's ambient k_w exactly.
WAKE_MODELS = {
    "M-1": _ekman(),
    "M-1, ambient k_w": _ekman(wake_expansion="ambient"),
    "M-2": _ekman(veer=False),
    "M-3": _ekman(veer=False, velocity="bastankhah2014"),
    "gauss": _builtin("gauss"),
    "GCH": _builtin("gch"),
    "cc": _builtin("cc"),
    "TurbOPark": ({"velocity_model": "turboparkgauss", "deflection_model": "gauss",
                   "turbulence_model": "crespo_hernandez"}, False, {}),
    "empirical_gauss": ({"velocity_model": "empirical_gauss", "deflection_model": "empirical_gauss",
                         "turbulence_model": "wake_induced_mixing"}, False, {}),
}
#: Models run on the single wakes ("M-1, ambient k_w" is M-1 there).
SINGLE_WAKE_MODELS = tuple(m for m in WAKE_MODELS if m != "M-1, ambient k_w")


def floris_input(case, reading: str, model: str, turbine: dict, layout) -> dict:
    """The FLORIS input dictionary of ``case`` with the ``reading`` atmosphere and wake ``model``."""
    if model not in WAKE_MODELS:
        raise ValueError(f"model must be one of {list(WAKE_MODELS)}, got {model!r}")
    strings, gch, parameters = WAKE_MODELS[model]
    block = atmosphere(case, reading)
    turbulence = hub_turbulence(case, block["roughness_length"])
    velocity_parameters = {"ekman_veer": {"atmosphere": block, **parameters.get("velocity", {})}}
    if strings["velocity_model"] == "bastankhah2014":
        velocity_parameters["bastankhah2014"] = parameters["velocity"]
    for name in ("gauss", "cc", "turboparkgauss", "empirical_gauss"):
        velocity_parameters.setdefault(name, None)  # FLORIS's defaults
    x, y = layout
    return {
        "name": f"{case.name} {model} ({reading})",
        "description": "floris_ekman_veer.studies.validation",
        "floris_version": "v4",
        "logging": {"console": {"enable": True, "level": "WARNING"},
                    "file": {"enable": False, "level": "WARNING"}},
        "solver": {"type": "turbine_grid", "turbine_grid_points": 3},
        "farm": {"layout_x": [float(v) for v in x], "layout_y": [float(v) for v in y],
                 "turbine_type": [turbine]},
        "flow_field": {
            "air_density": 1.225, "reference_wind_height": float(case.hub_height),
            "turbulence_intensities": [turbulence], "wind_directions": [270.0],
            "wind_shear": 0.0, "wind_speeds": [float(case.wind_speed)], "wind_veer": 0.0,
        },
        "wake": {
            "model_strings": {"combination_model": "sosfs", **strings},
            **dict.fromkeys(GCH_SWITCHES, gch),
            "enable_active_wake_mixing": False,
            "wake_deflection_parameters": {"ekman_veer": parameters.get("deflection", {}),
                                           "gauss": None, "empirical_gauss": None},
            "wake_velocity_parameters": velocity_parameters,
            "wake_turbulence_parameters": {"crespo_hernandez": None, "wake_induced_mixing": None},
        },
    }


def build_model(case, reading: str, model: str, turbine: dict, layout) -> FlorisModel:
    """:func:`floris_input` as a FlorisModel, with FLORIS's inflow scalars set from the atmosphere."""
    fmodel = FlorisModel(floris_input(case, reading, model, turbine, layout))
    fmodel.set(**fair_builtin_set_kwargs(fmodel))
    return fmodel


def arc_directions(step: float = 0.5) -> np.ndarray:
    """Relative wind directions of the computed arcs [deg], -30 to 30."""
    return np.arange(-ARC_HALF_WIDTH, ARC_HALF_WIDTH + 0.5 * step, step)


def arc_profiles(case, reading: str, model: str, step: float = 0.5) -> np.ndarray:
    """U/U0 at hub height on every arc of ``case`` (rows: ``case.distances``; columns:
    :func:`arc_directions`). The wind blows from 270 deg along +x; a relative direction theta
    (wind turned clockwise by theta) puts the arc point at x (cos theta, sin theta) in the
    wind's frame, the measured-wake convention (0 = wake centre). U0 is the hub-height speed."""
    fmodel = build_model(case, reading, model, constant_thrust_turbine(case), ([0.0], [0.0]))
    theta = np.radians(arc_directions(step))
    radius = np.asarray(case.distances)[:, None] * case.rotor_diameter
    x, y = radius * np.cos(theta), radius * np.sin(theta)
    z = np.full(x.size, case.hub_height)
    u = fmodel.sample_flow_at_points(x.ravel(), y.ravel(), z)
    return np.asarray(u).reshape(x.shape) / case.wind_speed


def _row_ratio(powers: np.ndarray, case=HORNS_REV) -> np.ndarray:
    # Mean over the direction bin, then over the inner rows of each column; relative to column 1.
    per_turbine = powers.mean(axis=0)
    rows = per_turbine[case.inner_rows].mean(axis=1)
    return rows / rows[0]


def horns_rev_rows(model: str, reading: str, sample_step: float = 1.0,
                   directions=None) -> dict:
    """P_i/P_1 of Horns Rev's inner-row mean, i = 1..10, for the measured direction bin.

    One ``UncertainFlorisModel`` runs the wind directions of the bin perturbed by
    ``sample_step``-spaced offsets out to 3 sigma_max; FLORIS's ``map_turbine_values_uncertain``
    then weights its results with each turbine's own Gaussian (sigma of
    ``HORNS_REV.direction_sigma``, van der Laan et al.), and, for the row without averaging,
    with all weight on the zero offset. ``directions`` replaces the bin (e.g. (270,) for speed).

    Returns ``{"raw": ratios, "averaged": ratios}``, each an array of 10.
    """
    case = HORNS_REV
    fmodel = build_model(case, reading, model, v80_turbine(), case.layout)
    directions = np.asarray(case.direction_bin if directions is None else directions, dtype=float)
    n = directions.size
    fmodel.set(wind_directions=directions, wind_speeds=np.full(n, case.wind_speed),
               turbulence_intensities=np.full(n, fmodel.core.flow_field.turbulence_intensities[0]))
    sigma = case.direction_sigma()
    reach = np.ceil(3.0 * sigma.max() / sample_step) * sample_step
    offsets = np.arange(-reach, reach + 0.5 * sample_step, sample_step)
    ufm = UncertainFlorisModel(fmodel, wd_resolution=sample_step, ws_resolution=1e-6,
                               ti_resolution=1e-9, wd_std=float(sigma.max()),
                               wd_sample_points=offsets.tolist())
    ufm.run()
    unique = ufm.fmodel_expanded._get_turbine_powers()
    n_turbines = unique.shape[1]

    def weighted(weights):
        return map_turbine_values_uncertain(unique, ufm.map_to_expanded_inputs, weights,
                                            ufm.n_unexpanded, ufm.n_sample_points, n_turbines)

    averaged = np.empty((n, n_turbines))
    for s in np.unique(sigma):
        columns = sigma == s
        averaged[:, columns] = weighted(ufm._get_weights(s, offsets))[:, columns]
    raw = weighted((offsets == 0.0).astype(float))
    return {"raw": _row_ratio(raw), "averaged": _row_ratio(averaged)}


def horns_rev_efficiency(model: str, reading: str, directions) -> np.ndarray:
    """Farm power over 80 unwaked turbines' power at each wind direction [deg] (no averaging,
    as the LES gives it)."""
    case = HORNS_REV
    fmodel = build_model(case, reading, model, v80_turbine(), case.layout)
    directions = np.asarray(directions, dtype=float)
    n = directions.size
    fmodel.set(wind_directions=directions, wind_speeds=np.full(n, case.wind_speed),
               turbulence_intensities=np.full(n, fmodel.core.flow_field.turbulence_intensities[0]))
    fmodel.run()
    farm = fmodel.get_farm_power()
    fmodel.run_no_wake()
    return farm / fmodel.get_farm_power()
