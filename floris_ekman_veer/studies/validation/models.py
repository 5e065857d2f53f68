"""Every case as a FLORIS model on the package's inflow, for the package's and FLORIS's wake models.

One FLORIS input per case, atmosphere reading (validation.atmospheres) and wake model: the
turbines and layout of the case, FLORIS's reference height at the hub, the atmosphere block in
``wake_velocity_parameters.ekman_veer.atmosphere`` (so every model, FLORIS's own included, runs
on the Ekman U(z)), FLORIS's turbulence intensity = I_u(z_h) of that atmosphere and, for
FLORIS's own models, the rotor veer of ``studies.comparison.fair_builtin_set_kwargs``. The wake
models (:data:`WAKE_MODELS`): the paper's M-1, M-2 and M-3 with the package's defaults, and
FLORIS 4.7's gauss, GCH, cc, TurbOPark (``turboparkgauss``, A = 0.04) and empirical Gauss with
FLORIS's default parameters; a user adds a set-up to the dictionary or passes one. Results
(docs/validation.md#measured-wakes-and-farms):

* :func:`arc_profiles`: U/U0 at hub height on the arcs of a single-wake case;
* :func:`row_ratios`: P_i/P_1 along a farm case's reference rows, as computed and averaged over
  the wind-direction uncertainty with FLORIS's ``UncertainFlorisModel``, as a tidy table;
* :func:`farm_efficiency`: the farm efficiency against wind direction.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from floris import FlorisModel, UncertainFlorisModel
from floris.uncertain_floris_model import map_turbine_values_uncertain

from floris_ekman_veer.plugin.wake_models.input_checks import reads_wind_shear, uses_wake_models
from floris_ekman_veer.studies.comparison import (
    BUILTIN_WAKES,
    GCH_SWITCHES,
    fair_builtin_set_kwargs,
)
from floris_ekman_veer.studies.validation.atmospheres import atmosphere, hub_turbulence
from floris_ekman_veer.studies.validation.cases import ARC_HALF_WIDTH


def _ekman(veer=True, velocity="ekman_veer", **velocity_parameters):
    deflection = {"veer": veer, "yaw_deflection": velocity == "ekman_veer"}
    return ({"velocity_model": velocity, "deflection_model": "ekman_veer",
             "turbulence_model": "crespo_hernandez", "combination_model": "fls"}, False,
            {"velocity": velocity_parameters, "deflection": deflection})


def _builtin(name):
    strings, gch = BUILTIN_WAKES[name]
    return ({**strings, "turbulence_model": "crespo_hernandez"}, gch, {})


#: Wake set-ups: model strings (FLORIS's combination ``sosfs`` unless given), the GCH switches,
#: parameters for the package's models. The package's models take their defaults
#: (``wake_expansion: array_turbulence``, ``turbulence_overlap: wake_radius``,
#: ``deficit_velocity: incoming``, deficits summed: docs/coupling.md#wakes-deep-in-an-array; the
#: super-Gaussian near wake inside a potential core, docs/wake_model.md#near-wake); for an
#: isolated wake beyond x0 that is the paper's model exactly. "M-1, ambient k_w" is the paper's
#: k_w for every turbine; "M-1, FLORIS-style" the farm coupling FLORIS's gauss has (the largest
#: upstream wake's added turbulence with FLORIS's overlap count, deficits scaled with the free
#: stream, their squares summed), for comparison.
WAKE_MODELS = {
    "M-1": _ekman(),
    "M-1, ambient k_w": _ekman(wake_expansion="ambient"),
    "M-1, FLORIS-style": (
        {**_ekman()[0], "combination_model": "sosfs"}, False,
        {**_ekman()[2], "velocity": {"wake_expansion": "local_turbulence",
                                     "deficit_velocity": "free_stream",
                                     "turbulence_overlap": "wake_velocity"}}),
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
#: Models run on the single wakes (the farm variants of M-1 are M-1 there).
SINGLE_WAKE_MODELS = tuple(m for m in WAKE_MODELS if not m.startswith("M-1,"))


def _setup(model):
    """(name, set-up) of ``model``: a name of :data:`WAKE_MODELS` or a (name, set-up) pair."""
    if isinstance(model, str):
        if model not in WAKE_MODELS:
            raise ValueError(f"model must be one of {list(WAKE_MODELS)} or a (name, set-up) pair, "
                             f"got {model!r}")
        return model, WAKE_MODELS[model]
    name, setup = model
    return name, setup


def floris_input(case, reading: str, model) -> dict:
    """The FLORIS input dictionary of ``case`` (its turbine and layout) with the ``reading``
    atmosphere and wake ``model`` (a name of :data:`WAKE_MODELS` or a (name, set-up) pair)."""
    name, (strings, gch, parameters) = _setup(model)
    block = atmosphere(case, reading)
    turbulence = hub_turbulence(case, block)
    velocity_parameters = {"ekman_veer": {"atmosphere": block, **parameters.get("velocity", {})}}
    if strings["velocity_model"] == "bastankhah2014":
        velocity_parameters["bastankhah2014"] = parameters["velocity"]
    for builtin in ("gauss", "cc", "turboparkgauss", "empirical_gauss"):
        velocity_parameters.setdefault(builtin, None)  # FLORIS's defaults
    turbine = case.turbine
    layout = case.layout
    x, y = layout
    return {
        "name": f"{case.name} {name} ({reading})",
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
            "wake_turbulence_parameters": {"crespo_hernandez": None, "wake_induced_mixing": None,
                                           **parameters.get("turbulence", {})},
        },
    }


def build_model(case, reading: str, model) -> FlorisModel:
    """:func:`floris_input` as a FlorisModel, with FLORIS's ambient TI the atmosphere's I_u(z_h)
    and, for FLORIS's own models, the atmosphere's rotor veer, and its rotor shear where GCH's
    terms read it (the package's models take both from the atmosphere itself; the inflow
    never takes FLORIS's power law)."""
    fmodel = FlorisModel(floris_input(case, reading, model))
    settings = fair_builtin_set_kwargs(fmodel)
    if not reads_wind_shear(fmodel.core):
        settings.pop("wind_shear")
    if uses_wake_models(fmodel.core):
        settings.pop("wind_veer")
    fmodel.set(**settings)
    return fmodel


def arc_directions(step: float = 0.5) -> np.ndarray:
    """Relative wind directions of the computed arcs [deg], -30 to 30."""
    return np.arange(-ARC_HALF_WIDTH, ARC_HALF_WIDTH + 0.5 * step, step)


def arc_profiles(case, reading: str, model: str, step: float = 0.5) -> np.ndarray:
    """U/U0 at hub height on every arc of ``case`` (rows: ``case.distances``; columns:
    :func:`arc_directions`). The wind blows from 270 deg along +x; a relative direction theta
    (wind turned clockwise by theta) puts the arc point at x (cos theta, sin theta) in the
    wind's frame, the measured-wake convention (0 = wake centre). U0 is the hub-height speed."""
    fmodel = build_model(case, reading, model)
    theta = np.radians(arc_directions(step))
    radius = np.asarray(case.distances)[:, None] * case.rotor_diameter
    x, y = radius * np.cos(theta), radius * np.sin(theta)
    z = np.full(x.size, case.hub_height)
    u = fmodel.sample_flow_at_points(x.ravel(), y.ravel(), z)
    return np.asarray(u).reshape(x.shape) / case.wind_speed


def _conditions(fmodel, case, directions):
    directions = np.asarray(directions, dtype=float)
    n = directions.size
    fmodel.set(wind_directions=directions, wind_speeds=np.full(n, case.wind_speed),
               turbulence_intensities=np.full(n, fmodel.core.flow_field.turbulence_intensities[0]))


def _gaussian_weights(sigma, offsets):
    # The normalised Gaussian UncertainFlorisModel weights its samples with.
    values = np.exp(-(offsets**2) / (2.0 * sigma**2))
    return values / values.sum()


def turbine_powers(case, reading: str, model, directions, sample_step: float = 1.0):
    """Turbine powers [W] at each wind direction, raw and averaged over the direction
    uncertainty, as ``{"raw": (n_directions, n_turbines), "averaged": ...}``.

    One ``UncertainFlorisModel`` runs the directions perturbed by ``sample_step``-spaced offsets
    out to 3 sigma_max; FLORIS's ``map_turbine_values_uncertain`` then weights the expanded
    model's turbine powers with each turbine's own Gaussian (``case.direction_sigma()``) and,
    for "raw", with all weight on the zero offset."""
    fmodel = build_model(case, reading, model)
    directions = np.asarray(directions, dtype=float)
    _conditions(fmodel, case, directions)
    sigma = case.direction_sigma()
    reach = np.ceil(3.0 * sigma.max() / sample_step) * sample_step
    offsets = np.arange(-reach, reach + 0.5 * sample_step, sample_step)
    ufm = UncertainFlorisModel(fmodel, wd_resolution=sample_step, ws_resolution=1e-6,
                               ti_resolution=1e-9, wd_std=float(sigma.max()),
                               wd_sample_points=offsets.tolist())
    ufm.run()
    unique = ufm.fmodel_expanded.get_turbine_powers()
    n_turbines = unique.shape[1]

    def weighted(weights):
        return map_turbine_values_uncertain(unique, ufm.map_to_expanded_inputs, weights,
                                            ufm.n_unexpanded, ufm.n_sample_points, n_turbines)

    averaged = np.empty((directions.size, n_turbines))
    for s in np.unique(sigma):
        columns = sigma == s
        averaged[:, columns] = weighted(_gaussian_weights(s, offsets))[:, columns]
    return {"raw": weighted((offsets == 0.0).astype(float)), "averaged": averaged}


def _ratios(per_turbine, row):
    # Mean over the row's parallel rows at each position, relative to position 1; gaps NaN.
    powers = per_turbine[np.where(row.turbines < 0, 0, row.turbines)].mean(axis=1)
    return np.where(row.gaps, np.nan, powers / powers[0])


def row_ratios(case, models, readings=("matched",), sample_step: float = 1.0,
               offsets=None) -> pd.DataFrame:
    """P_i/P_1 along every reference row of ``case`` for each model and atmosphere reading, a
    tidy table: case, reading, model, row, wind_direction, position, kind ("raw": mean over
    the direction bin; "averaged": also over the direction uncertainty), ratio, measured,
    standard_error (of the measured mean), rans (the published RANS's ratio of the same kind,
    NaN without one).

    The model runs, per row direction, the directions ``direction + offsets`` (default
    ``case.direction_offsets``, the measurements' bin; e.g. (0,) for speed) through
    :func:`turbine_powers`; all rows of a case go in one run per model and reading.
    ``models``: names of :data:`WAKE_MODELS` or (name, set-up) pairs."""
    offsets = np.asarray(case.direction_offsets if offsets is None else offsets, dtype=float)
    row_directions = sorted({row.wind_direction for row in case.rows})
    directions = np.concatenate([d + offsets for d in row_directions])
    frames = []
    for reading in readings:
        for model in models:
            name = _setup(model)[0]
            powers = turbine_powers(case, reading, model, directions, sample_step)
            for row in case.rows:
                k = row_directions.index(row.wind_direction)
                chosen = slice(k * offsets.size, (k + 1) * offsets.size)
                for kind in ("raw", "averaged"):
                    rans = (row.rans[:, 2 if kind == "averaged" else 1] if row.rans is not None
                            else np.full(len(row.turbines), np.nan))
                    frames.append(pd.DataFrame({
                        "case": case.name, "reading": reading, "model": name, "row": row.label,
                        "wind_direction": row.wind_direction,
                        "position": row.measured[:, 0].astype(int), "kind": kind,
                        "ratio": _ratios(powers[kind][chosen].mean(axis=0), row),
                        "measured": row.measured[:, 1], "standard_error": row.measured[:, 2],
                        "rans": rans,
                    }))
    return pd.concat(frames, ignore_index=True)


def farm_efficiency(case, models, readings=("matched",), directions=None) -> pd.DataFrame:
    """Farm power over n unwaked turbines' power at each wind direction [deg] (default: the
    case's efficiency reference's), no averaging: a tidy table case, reading, model,
    wind_direction, efficiency, reference (NaN where the case has none at that direction)."""
    reference = case.efficiency
    if directions is None:
        if reference is None:
            raise ValueError(f"{case.name}: give directions (the case has no efficiency reference)")
        directions, measured = reference.directions, reference.efficiency
    else:
        directions = np.asarray(directions, dtype=float)
        measured = np.full(directions.size, np.nan)
        if reference is not None:  # the reference's first value at each direction it has
            match = np.isclose(directions[:, None], reference.directions[None, :])
            found = match.any(axis=1)
            measured[found] = reference.efficiency[match.argmax(axis=1)[found]]
    frames = []
    for reading in readings:
        for model in models:
            fmodel = build_model(case, reading, model)
            _conditions(fmodel, case, directions)
            fmodel.run()
            farm = fmodel.get_farm_power()
            fmodel.run_no_wake()
            frames.append(pd.DataFrame({
                "case": case.name, "reading": reading, "model": _setup(model)[0],
                "wind_direction": directions, "efficiency": farm / fmodel.get_farm_power(),
                "reference": measured}))
    return pd.concat(frames, ignore_index=True)
