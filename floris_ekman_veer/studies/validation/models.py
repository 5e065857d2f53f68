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
* :func:`farm_efficiency`: the farm efficiency against wind direction, as computed and averaged
  over the wind-direction uncertainty, with the farm's and its no-wake power.

Every table carries the model's name and its :func:`model_label`: the name with the settings
the model ran with (docs/validation.md#model-labels).
"""

from __future__ import annotations

import re

import attrs
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
from floris_ekman_veer.studies.validation.checks import array, scalar
from floris_ekman_veer.studies.validation.farm_case import MAX_DIRECTION_OFFSET
from floris_ekman_veer.studies.validation.reference_data import ARC_HALF_WIDTH


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
#: (``wake_expansion: array_turbulence``, ``deficit_velocity: incoming``, deficits summed:
#: docs/coupling.md#wakes-deep-in-an-array); for an isolated wake that is the paper's model
#: exactly. "M-1, ambient k_w" is the paper's k_w for every turbine; "M-1, FLORIS-style" the
#: farm coupling FLORIS's gauss has (the largest upstream wake's added turbulence, deficits
#: scaled with the free stream, their squares summed), for comparison.
WAKE_MODELS = {
    "M-1": _ekman(),
    "M-1, ambient k_w": _ekman(wake_expansion="ambient"),
    "M-1, FLORIS-style": (
        {**_ekman()[0], "combination_model": "sosfs"}, False,
        {**_ekman()[2], "velocity": {"wake_expansion": "local_turbulence",
                                     "deficit_velocity": "free_stream"}}),
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
    if not (isinstance(model, (tuple, list)) and len(model) == 2 and isinstance(model[0], str)
            and isinstance(model[1], (tuple, list)) and len(model[1]) == 3):
        raise TypeError("model must be a name of WAKE_MODELS or a (name, (model strings, GCH "
                        f"switch, parameters)) pair; got {model!r}")
    name, setup = model
    return name, setup


def _models(models) -> list:
    if isinstance(models, (str, bytes)) or not isinstance(models, (tuple, list)) or not models:
        raise TypeError(f"models must be a non-empty list of model names or (name, set-up) "
                        f"pairs; got {models!r}")
    return [(_setup(m)[0], m) for m in models]


def _readings(readings) -> tuple:
    if isinstance(readings, str) or not isinstance(readings, (tuple, list)) or not readings:
        raise TypeError(f"readings must be a non-empty list of atmosphere readings; got "
                        f"{readings!r}")
    return tuple(readings)


def _sample_step(sample_step) -> float:
    return scalar(sample_step, "sample_step", "in (0, 10] deg",
                  lambda step: np.isfinite(step) and 0.0 < step <= 10.0)


#: Fields of a wake model that are not model settings: the inflow, the shallow-ABL policy.
_NOT_SETTINGS = ("atmosphere", "shallow_boundary_layer")


def _shown(component) -> list[str]:
    # Every choice (string or boolean) of a wake component, and its numbers: all of them for
    # the package's own models (whose defaults a release may change), those set away from
    # FLORIS's defaults for FLORIS's (FLORIS's version is pinned).
    own = type(component).__module__.startswith("floris_ekman_veer.")
    items = []
    for item in attrs.fields(type(component)):
        if not item.init or item.name in _NOT_SETTINGS:
            continue
        value = getattr(component, item.name)
        if isinstance(value, (str, bool, np.bool_)):
            items.append(f"{item.name}={value}")
        elif isinstance(value, (int, float)) and (own or value != item.default):
            items.append(f"{item.name}={value:g}")
    return items


#: FLORIS's secondary-effect switches, named in a label when on.
_SWITCHES = {"enable_secondary_steering": "secondary_steering",
             "enable_yaw_added_recovery": "yaw_added_recovery",
             "enable_transverse_velocities": "transverse_velocities"}


def model_label(name: str, fmodel) -> str:
    """A label that carries the settings a built model runs with, and makes a good key (no
    commas, no spaces): the name, then in brackets FLORIS's model strings, the GCH switches
    that are on, every choice of the velocity, deflection and turbulence models (the
    package's ``wake_expansion``, ``deficit_velocity``, ``veer`` ...) with their defaults
    resolved, every number of the package's models and each number of FLORIS's set away from
    its default. Two runs with one label ran one model (docs/validation.md#model-labels)."""
    wake = fmodel.core.wake
    items = [f"{kind}={wake.model_strings[f'{kind}_model']}"
             for kind in ("velocity", "deflection", "turbulence", "combination")]
    items += [short for switch, short in _SWITCHES.items() if getattr(wake, switch)]
    items += _shown(wake.velocity_model)
    items += [f"{kind}.{item}" for kind in ("deflection", "turbulence")
              for item in _shown(getattr(wake, f"{kind}_model"))]
    return f"{re.sub(r'[^A-Za-z0-9.-]+', '_', name)}[{';'.join(items)}]"


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
            "wake_turbulence_parameters": {"crespo_hernandez": None, "wake_induced_mixing": None},
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
    uncertainty, as ``{"raw": (n_directions, n_turbines), "averaged": ...}`` (the model built
    by :func:`build_model`; see :func:`uncertain_powers`)."""
    fmodel = build_model(case, reading, model)
    return uncertain_powers(fmodel, case, _directions(directions, "directions"), sample_step)


def uncertain_powers(fmodel, case, directions, sample_step: float = 1.0):
    """Turbine powers [W] of a built model at each wind direction, raw and averaged over the
    direction uncertainty, as ``{"raw": (n_directions, n_turbines), "averaged": ...}``.

    One ``UncertainFlorisModel`` runs the directions perturbed by ``sample_step``-spaced offsets
    out to 3 sigma_max; FLORIS's ``map_turbine_values_uncertain`` then weights the expanded
    model's turbine powers with each turbine's own Gaussian (``case.direction_sigma()``) and,
    for "raw", with all weight on the zero offset."""
    sample_step = _sample_step(sample_step)
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


def _directions(directions, name: str) -> np.ndarray:
    return array(directions, name, 1, "finite, in [0, 360] deg", lambda d: (d >= 0) & (d <= 360))


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
    ``models``: names of :data:`WAKE_MODELS` or (name, set-up) pairs; the "label" column is
    each one's :func:`model_label`."""
    offsets = array(case.direction_offsets if offsets is None else offsets, "offsets", 1,
                    f"finite, within +-{MAX_DIRECTION_OFFSET:g} deg",
                    lambda o: np.abs(o) <= MAX_DIRECTION_OFFSET)
    if not case.rows:
        raise ValueError(f"{case.name}: row_ratios needs the case's rows (RowReference); it has none")
    row_directions = sorted({row.wind_direction for row in case.rows})
    directions = np.concatenate([d + offsets for d in row_directions])
    frames = []
    for reading in _readings(readings):
        for name, model in _models(models):
            fmodel = build_model(case, reading, model)
            label = model_label(name, fmodel)
            powers = uncertain_powers(fmodel, case, directions, sample_step)
            for row in case.rows:
                k = row_directions.index(row.wind_direction)
                chosen = slice(k * offsets.size, (k + 1) * offsets.size)
                for kind in ("raw", "averaged"):
                    rans = (row.rans[:, 2 if kind == "averaged" else 1] if row.rans is not None
                            else np.full(len(row.turbines), np.nan))
                    frames.append(pd.DataFrame({
                        "case": case.name, "reading": reading, "model": name, "label": label,
                        "row": row.label,
                        "wind_direction": row.wind_direction,
                        "position": row.measured[:, 0].astype(int), "kind": kind,
                        "ratio": _ratios(powers[kind][chosen].mean(axis=0), row),
                        "measured": row.measured[:, 1], "standard_error": row.measured[:, 2],
                        "rans": rans,
                    }))
    return pd.concat(frames, ignore_index=True)


def farm_efficiency(case, models, readings=("matched",), directions=None,
                    sample_step: float = 1.0) -> pd.DataFrame:
    """Farm power over the farm's no-wake power at each wind direction [deg] (default: the
    case's efficiency reference's), a tidy table: case, reading, model, label, wind_direction,
    kind ("raw": at the direction; "averaged": each turbine's power averaged over the direction
    uncertainty as in :func:`row_ratios`, for a case with one), efficiency, farm_power and no_wake_power [W],
    reference and standard_error (the efficiency reference's at that direction; NaN where the
    case has none)."""
    reference = case.efficiency
    if directions is None:
        if reference is None:
            raise ValueError(f"{case.name}: give directions (the case has no efficiency reference)")
        directions = reference.directions
        measured, error = reference.efficiency, reference.standard_errors
    else:
        directions = _directions(directions, "directions")
        measured, error = np.full(directions.size, np.nan), np.full(directions.size, np.nan)
        if reference is not None:  # the reference's first value at each direction it has
            match = np.isclose(directions[:, None], reference.directions[None, :])
            found = match.any(axis=1)
            measured[found] = reference.efficiency[match.argmax(axis=1)[found]]
            error[found] = reference.standard_errors[match.argmax(axis=1)[found]]
    frames = []
    for reading in _readings(readings):
        for name, model in _models(models):
            fmodel = build_model(case, reading, model)
            label = model_label(name, fmodel)
            kinds = {}
            if case.direction_uncertainty is not None:
                powers = uncertain_powers(fmodel, case, directions, sample_step)
                kinds["averaged"] = powers["averaged"].sum(axis=1)
            else:
                _conditions(fmodel, case, directions)
            fmodel.run()
            kinds = {"raw": fmodel.get_farm_power(), **kinds}
            fmodel.run_no_wake()
            no_wake = fmodel.get_farm_power()
            for kind, power in kinds.items():
                frames.append(pd.DataFrame({
                    "case": case.name, "reading": reading, "model": name, "label": label,
                    "wind_direction": directions, "kind": kind, "efficiency": power / no_wake,
                    "farm_power": power, "no_wake_power": no_wake, "reference": measured,
                    "standard_error": error}))
    return pd.concat(frames, ignore_index=True)
