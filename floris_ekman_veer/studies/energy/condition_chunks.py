"""Chunks of an annual-energy study's conditions: each a self-contained task (its conditions,
their atmosphere and the optimiser's options cut to them) run as one vectorised FLORIS model,
baseline and steered, on every model on the same Ekman inflow (docs/coupling.md#annual-energy).

A condition's numbers do not depend on the chunk it runs in; the chunks run in turn
(studies/energy/energy.py) or as Dask tasks (studies/energy/distributed.py). Conditions whose every turbine is
at the maximum of its power table keep zero yaw without the optimiser, which is what it returns
for them (:func:`_cannot_gain`, docs/yaw_steering.md#in-a-years-study).
"""

from __future__ import annotations

import inspect

import attrs
import numpy as np
import pandas as pd
from floris.optimization.yaw_optimization.yaw_optimizer_scipy import YawOptimizationScipy
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

from floris_ekman_veer.plugin.inflow.inflow import farm_atmosphere, set_atmosphere
from floris_ekman_veer.plugin.wake_models.names import VELOCITY_MODEL_NAME as MODEL_NAME
from floris_ekman_veer.plugin.floris_tools.optimizer_options import (
    options_for_conditions,
    with_default_yaw_bounds,
)
from floris_ekman_veer.studies.comparison import comparison_set_kwargs
from floris_ekman_veer.studies.yaw.optimization import optimize_yaw

#: Conditions per FLORIS model of a study: enough to keep FLORIS's vectorisation efficient, few
#: enough to bound the memory of a 100-turbine farm to a few hundred MB.
DEFAULT_CHUNK_SIZE = 1024
#: Operation models whose power never exceeds the maximum of the turbine's power table: FLORIS
#: interpolates the table (the package's veer-aware rotor scales the speed it is read at,
#: docs/yaw_steering.md), derating only lowers it. A condition with every turbine at that
#: maximum cannot gain from steering (:func:`_cannot_gain`).
CAPPED_OPERATION_MODELS = ("simple", "cosine-loss", "simple-derating")
#: The optimisers that maximise the farm power (and keep the baseline where nothing beats it).
POWER_OPTIMIZERS = (YawOptimizationSR, YawOptimizationScipy)


def chunk_rows(n: int, chunk_size: int) -> list:
    """Contiguous chunks of at most ``chunk_size`` of ``n`` conditions (np.array_split, as
    FLORIS's ParFlorisModel cuts its conditions)."""
    return [rows for rows in np.array_split(np.arange(n), max(1, -(-n // chunk_size)))
            if rows.size]


def atmosphere_rows(atmosphere: dict, rows) -> dict:
    """A plain atmosphere block (scalars, or one value per condition) for its conditions
    ``rows``."""
    return {k: v if np.ndim(v) == 0 else np.asarray(v, dtype=float)[rows].tolist()
            for k, v in atmosphere.items()}


@attrs.frozen(eq=False)
class Chunk:
    """One chunk of a study, self-contained (a Dask task carries it): its conditions, their
    atmosphere (a plain block: scalars, or one value per condition), the optimiser's options
    cut to them and the conditions per optimiser run."""

    atmosphere: dict
    directions: np.ndarray
    speeds: np.ndarray
    wind_ti: np.ndarray
    optimizer_kwargs: dict
    steering_chunk_size: int = DEFAULT_CHUNK_SIZE

    def rows(self, rows) -> Chunk:
        """The chunk of its conditions ``rows``."""
        return Chunk(atmosphere_rows(self.atmosphere, rows),
                     self.directions[rows], self.speeds[rows], self.wind_ti[rows],
                     options_for_conditions(self.optimizer_kwargs, rows), self.steering_chunk_size)


def run_chunk(template, model, chunk, ti_source, optimizer_class) -> dict:
    """Farm powers (baseline and steered), optima and inflow of one chunk, on ``template`` set
    to the chunk's conditions (one model build; a second, of the conditions steered, where some
    cannot gain from steering)."""
    case = _chunk_model(template, model, chunk, ti_source)
    flow_field = case.core.flow_field
    n = chunk.speeds.size
    out = {"turbulence_intensities": flow_field.turbulence_intensities.copy(),
           "wind_veer": np.full(n, float(flow_field.wind_veer)),
           "wind_shear": np.full(n, float(flow_field.wind_shear)),
           "steered": None, "optima": None}
    case.run()
    powers = case.get_turbine_powers()
    out["baseline"] = np.sum(powers, axis=1)
    if optimizer_class is None:
        return out
    skip = _cannot_gain(case, powers, optimizer_class, chunk.optimizer_kwargs)
    steer = np.flatnonzero(~skip)
    out["steered"] = out["baseline"].copy()
    frames = [_unsteered_frame(case, powers, np.flatnonzero(skip), optimizer_class,
                               chunk.optimizer_kwargs)] if skip.any() else []
    if steer.size:
        options = chunk.optimizer_kwargs
        if skip.any():
            # A condition's numbers do not depend on the others run with it: the conditions
            # steered run on their own.
            steered = chunk.rows(steer)
            case, options = _chunk_model(template, model, steered, ti_source), steered.optimizer_kwargs
        df_opt = optimize_yaw(case, optimizer_class, progress=False,
                              chunk_size=chunk.steering_chunk_size, **options)
        df_opt.index = steer
        frames.append(df_opt)
        case.set(yaw_angles=np.vstack(df_opt["yaw_angles_opt"]))
        case.run()
        out["steered"][steer] = np.sum(case.get_turbine_powers(), axis=1)
        # FLORIS's set() keeps non-zero yaw angles: the next chunk's baseline is unyawed.
        case.reset_operation()
    out["optima"] = pd.concat(frames).sort_index().reset_index(drop=True)
    return out


def _rated_powers(fmodel):
    """The most each turbine's power can be [W] (the maximum of its power table, FLORIS's kW
    x 1e3), or None where an operation model is not one of :data:`CAPPED_OPERATION_MODELS`
    (or its table is multi-dimensional)."""
    rated = []
    for turbine in fmodel.core.farm.turbine_definitions:
        if (turbine.get("operation_model", "cosine-loss") not in CAPPED_OPERATION_MODELS
                or turbine.get("multi_dimensional_cp_ct", False)):
            return None
        rated.append(1e3 * float(np.max(turbine["power_thrust_table"]["power"])))
    return np.array(rated)


def _option_rows(optimizer_class, options, name, shape):
    """The optimiser's option ``name`` (or its default) as an array of ``shape``."""
    value = with_default_yaw_bounds(optimizer_class, options).get(name)
    if value is None and name not in ("yaw_angles_baseline", "turbine_weights"):
        value = inspect.signature(optimizer_class.__init__).parameters[name].default
    return None if value is None else np.broadcast_to(np.asarray(value, dtype=float), shape)


def _cannot_gain(fmodel, powers, optimizer_class, options) -> np.ndarray:
    """Per condition of ``fmodel`` (run, turbine ``powers`` [W]): steering cannot raise its
    power, so the optimiser is skipped and zero yaw kept (exact: the optimiser keeps the
    baseline where nothing beats it).

    Where every turbine is at the maximum of its power table (:func:`_rated_powers`), no yaw
    raises any turbine's power. The bound the search would be judged by, the no-wake power, is
    not one here: the veer-aware rotor's power is not largest at zero yaw (a lone turbine in a
    veered wind gains by turning against the veer, docs/yaw_steering.md), so a condition with
    no wake loss below rated may still gain. Only for optimisers of the farm power
    (:data:`POWER_OPTIMIZERS`; the geometric one yaws by the layout alone) and where zero yaw is within the bounds, the
    baseline yaw (``yaw_angles_baseline``) is zero and the turbine weights are not negative.
    """
    shape = powers.shape
    rated = _rated_powers(fmodel)
    if rated is None or not issubclass(optimizer_class, POWER_OPTIMIZERS):
        return np.zeros(shape[0], dtype=bool)
    lower = _option_rows(optimizer_class, options, "minimum_yaw_angle", shape)
    upper = _option_rows(optimizer_class, options, "maximum_yaw_angle", shape)
    baseline = _option_rows(optimizer_class, options, "yaw_angles_baseline", shape)
    weights = _option_rows(optimizer_class, options, "turbine_weights", shape)
    eligible = (lower <= 0.0) & (upper >= 0.0)
    if baseline is not None:
        eligible &= baseline == 0.0
    if weights is not None:
        eligible &= weights >= 0.0
    return np.all(eligible & (powers >= rated), axis=1)


def _unsteered_frame(fmodel, powers, rows, optimizer_class, options) -> pd.DataFrame:
    """FLORIS's ``df_opt`` rows of conditions ``rows`` kept at zero yaw (:func:`_cannot_gain`):
    the farm power optimised and baseline both the weighted power of the baseline run, as the
    optimiser computes it."""
    weights = _option_rows(optimizer_class, options, "turbine_weights", powers.shape)
    weights = np.ones(powers.shape) if weights is None else weights
    farm_power = np.sum(np.multiply(weights, powers), axis=1)[rows]
    flow_field = fmodel.core.flow_field
    calc_baseline = options.get("calc_baseline_power", True)
    return pd.DataFrame({
        "wind_direction": flow_field.wind_directions[rows],
        "wind_speed": flow_field.wind_speeds[rows],
        "turbulence_intensity": flow_field.turbulence_intensities[rows],
        "yaw_angles_opt": list(np.zeros((rows.size, powers.shape[1]))),
        "farm_power_opt": farm_power,
        "farm_power_baseline": farm_power if calc_baseline else np.nan,
    }, index=rows)


def _chunk_model(template, model: str, chunk: Chunk, ti_source: str):
    """``template`` set to the chunk's conditions, each with its atmosphere, and the inflow
    scalars of the comparison (:func:`comparison_set_kwargs`): one model build and one ABL solve
    (the comparison solves the ABL as the model's inflow hook does, so the build finds it in the
    solve cache)."""
    kwargs = dict(wind_directions=chunk.directions, wind_speeds=chunk.speeds,
                  turbulence_intensities=chunk.wind_ti)
    if ti_source == "atmosphere" or model != MODEL_NAME:
        farm = template.core.farm
        fair = comparison_set_kwargs(
            farm_atmosphere(chunk.atmosphere, farm), chunk.speeds, template.core.flow_field.reference_wind_height,
            float(farm.hub_heights.reshape(-1, farm.n_turbines)[0, 0]),
            float(farm.rotor_diameters.reshape(-1, farm.n_turbines)[0, 0]))
        if ti_source == "atmosphere":
            kwargs["turbulence_intensities"] = fair["turbulence_intensities"]
        if model != MODEL_NAME:  # only FLORIS's built-ins read wind_veer
            kwargs["wind_veer"] = fair["wind_veer"]
    set_atmosphere(template, chunk.atmosphere, **kwargs)
    return template
