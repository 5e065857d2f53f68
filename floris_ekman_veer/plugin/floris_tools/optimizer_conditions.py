"""FLORIS's yaw optimisers on models whose atmosphere varies per condition.

FLORIS's yaw optimisers tile, mask and re-order their model's conditions internally (the Serial
Refine evaluates ``Ny`` copies of every condition at once and skips those already in memory;
the SciPy optimiser sets one condition at a time), so a per-condition atmosphere list
(docs/coupling.md#yaw-optimisation), which binds to conditions by position, cannot follow them.
Every condition's optimum depends on that condition alone, so :func:`optimize_each_atmosphere`
runs the optimiser once per distinct atmosphere (and per chunk of conditions, for the progress
bar) on a model holding just those conditions with that atmosphere as scalars
(:func:`condition_subset`), or, for FLORIS's serial refine, once per chunk on a model whose
atmosphere follows its conditions through the optimiser's tiling (:func:`row_following_subset`),
and puts the rows of FLORIS's ``df_opt`` frames back in the caller's order. The result is, by
construction, the result of running each distinct atmosphere on its own
(tests/studies/yaw/test_optimization.py measures it). :func:`~floris_ekman_veer.optimize_yaw` and the
optimisers' own ``optimize()`` on a per-condition atmosphere
(:mod:`~floris_ekman_veer.plugin.floris_tools.optimizer_hooks`) run it.
"""

from __future__ import annotations

import copy
import inspect
import types
import warnings
from collections.abc import Mapping

import numpy as np
import pandas as pd
from floris import FlorisModel
from floris.core import FlowField, TurbineCubatureGrid, TurbineGrid, WakeModelManager

from floris_ekman_veer.plugin.inflow.inflow import atmosphere_groups, atmosphere_of, set_atmosphere
from floris_ekman_veer.plugin.floris_tools.optimizer_options import options_for_conditions
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning

#: Conditions per optimiser run: large enough to keep FLORIS's vectorisation efficient, small
#: enough for the progress bar to move on long studies.
DEFAULT_CHUNK_SIZE = 256


def optimize_each_atmosphere(fmodel, optimizer_class, *, progress, chunk_size, **optimizer_kwargs):
    """One run of ``optimizer_class`` with ``optimizer_kwargs`` (checked: plugin/floris_tools/optimizer_options.py)
    over every condition of ``fmodel``, per atmosphere and chunk of ``chunk_size`` conditions;
    FLORIS's ``df_opt`` frame, one row per condition in ``fmodel``'s order (the module
    docstring)."""
    n_findex = fmodel.core.flow_field.n_findex
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, (int, np.integer)) or chunk_size < 1:
        raise ValueError(f"optimize_yaw: chunk_size must be an integer >= 1; got {chunk_size!r}")

    groups = atmosphere_groups(fmodel)
    if len(groups) > 1 and _rows_follow(fmodel, optimizer_class, optimizer_kwargs):
        # Every atmosphere in one run per chunk (FLORIS's serial refine carries the condition
        # rows through its tiling, see row_following_subset): no model per atmosphere.
        groups = [(ROWS, np.arange(n_findex))]
    runs = [
        (atmosphere, chunk)
        for atmosphere, index in groups
        for chunk in np.array_split(index, -(-index.size // chunk_size))
    ]
    if progress is None:
        progress = len(runs) > 1
    optimize_takes_progress = "print_progress" in inspect.signature(optimizer_class.optimize).parameters

    from tqdm.auto import tqdm

    frames = []
    with tqdm(total=n_findex, desc=f"{optimizer_class.__name__}", unit="condition",
              disable=not progress) as bar, warnings.catch_warnings():
        # The caller counted fmodel's shallow conditions (warn_shallow); the optimiser's many
        # re-builds (tiled, masked condition sets) would repeat that count in other numbers.
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        for atmosphere, index in runs:
            subset = (row_following_subset(fmodel, index) if atmosphere is ROWS
                      else condition_subset(fmodel, index, atmosphere))
            optimizer = optimizer_class(subset, **options_for_conditions(optimizer_kwargs, index))
            # FLORIS's own per-pass prints would interleave with the bar.
            df = optimizer.optimize(print_progress=False) if optimize_takes_progress else optimizer.optimize()
            df.index = index
            frames.append(df)
            bar.update(index.size)
    return pd.concat(frames).sort_index()


#: Marks the run of :func:`optimize_each_atmosphere` holding conditions of different atmospheres.
ROWS = object()


def _rows_follow(fmodel, optimizer_class, options) -> bool:
    """Whether ``optimizer_class`` on ``fmodel`` can run conditions of different atmospheres
    together (:func:`row_following_subset`): FLORIS's serial refine (which tiles a model's
    per-condition heterogeneous speed-ups with its conditions) without a heterogeneous map of
    its own or a convergence check (which re-evaluates without them), on a FlorisModel (a
    ParFlorisModel hands its workers the heterogeneous configuration as a map)."""
    from floris import ParFlorisModel
    from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

    return (issubclass(optimizer_class, YawOptimizationSR)
            and type(fmodel).set is FlorisModel.set and not isinstance(fmodel, ParFlorisModel)
            and fmodel.core.flow_field.heterogeneous_inflow_config is None
            and not options.get("verify_convergence", False))


def row_following_subset(fmodel, index):
    """:func:`condition_subset` of conditions ``index`` with their per-condition atmosphere,
    whose atmosphere follows its conditions through FLORIS's serial-refine optimiser.

    The serial refine evaluates tiled and masked copies of its model's conditions, and carries
    per-condition heterogeneous speed-ups the same way (``speed_multipliers`` tiled with the
    conditions). The subset holds, in that place, the row of each of its conditions (one
    column, never read as speed-ups: FLORIS builds its map only at construction), and its
    ``set()`` gives each condition set the atmosphere rows of the rows it carries. One model
    per chunk of conditions, whatever their atmospheres.
    """
    index = np.asarray(index)
    spec = atmosphere_of(fmodel.core)
    subset = condition_subset(fmodel, index, spec.sliced(index))
    subset._atmosphere_rows = {k: v if isinstance(v, float) else v.reshape(-1)[index]
                               for k, v in spec.inputs.items()}
    _mark_rows(subset, np.arange(index.size))
    subset.set = types.MethodType(_set_following_rows, subset)
    return subset


def _mark_rows(fmodel, rows) -> None:
    # Past FlowField's validator (which wants a map's x and y): the rows are no map.
    object.__setattr__(fmodel.core.flow_field, "heterogeneous_inflow_config",
                       {"speed_multipliers": np.asarray(rows, dtype=float).reshape(-1, 1)})


def _set_following_rows(self, **kwargs):
    """``set()`` of a :func:`row_following_subset`: the atmosphere of the rows it carries."""
    rows = np.asarray(self.core.flow_field.heterogeneous_inflow_config["speed_multipliers"],
                      dtype=float).reshape(-1).astype(int)
    n = np.size(kwargs.get("wind_directions", rows))
    if n != rows.size:
        raise ValueError(f"optimize_yaw: the optimiser set {n} conditions on a model "
                         f"carrying the atmospheres of {rows.size}")
    atmosphere = {k: v if isinstance(v, float) else v[rows].tolist()
                  for k, v in self._atmosphere_rows.items()}
    object.__setattr__(self.core.flow_field, "heterogeneous_inflow_config", None)
    set_atmosphere(_Plain(self), atmosphere, **kwargs)
    _mark_rows(self, rows)


class _Plain:
    """A model seen through its class's own ``set()`` (for :func:`set_atmosphere`)."""

    def __init__(self, fmodel):
        self.core, self._fmodel = fmodel.core, fmodel

    def set(self, **kwargs):
        type(self._fmodel).set(self._fmodel, **kwargs)


def condition_subset(fmodel, index, atmosphere: Mapping | None):
    """A copy of ``fmodel`` holding conditions ``index`` (in that order) and ``atmosphere``.

    Carries every per-condition input FLORIS has: wind directions, speeds, turbulence
    intensities, heterogeneous speed multipliers and the operation set-points (yaw angles,
    power set-points, active wake control), so that the subset's conditions are those of the
    parent.
    """
    index = np.asarray(index)
    core = fmodel.core
    flow_field, farm = core.flow_field, core.farm
    set_kwargs = dict(
        wind_directions=flow_field.wind_directions[index],
        wind_speeds=flow_field.wind_speeds[index],
        turbulence_intensities=flow_field.turbulence_intensities[index],
        yaw_angles=farm.yaw_angles[index],
        power_setpoints=farm.power_setpoints[index],
        awc_modes=farm.awc_modes[index],
        awc_amplitudes=farm.awc_amplitudes[index],
        awc_frequencies=farm.awc_frequencies[index],
    )
    heterogeneous = flow_field.heterogeneous_inflow_config
    if heterogeneous is not None and heterogeneous.get("speed_multipliers") is not None:
        set_kwargs["heterogeneous_inflow_config"] = {
            **heterogeneous,
            "speed_multipliers": np.asarray(heterogeneous["speed_multipliers"])[index],
        }
    subset = fmodel.copy()
    set_atmosphere(subset, atmosphere, **set_kwargs)
    if type(subset) is FlorisModel:
        # The optimiser's set() per evaluation gives only conditions (and set-points): rows
        # of this subset, checked when it was built above.
        subset._reinitialize = types.MethodType(_reinitialize_conditions, subset)
    return subset


#: The inputs :func:`_reinitialize_conditions` rebuilds; any other goes through FLORIS's own
#: ``_reinitialize``.
_CONDITION_INPUTS = frozenset({"wind_directions", "wind_speeds", "turbulence_intensities"})


def _reinitialize_conditions(self, **kwargs):
    """FlorisModel._reinitialize of an optimiser's subset, for new conditions only: the same
    Core as FLORIS's ``Core.from_dict(core.as_dict())`` with those conditions, reusing the
    farm's turbines and their tables.

    FLORIS's yaw optimisers set each evaluation's conditions (tiled and masked rows of the
    subset) on a copy of the subset, which rebuilds the whole Core: the farm re-reads every
    turbine's YAML file and builds its turbines anew, resolving the library path through
    ``inspect.stack`` twice per turbine type, and the package re-validates the conditions:
    38 % of a steered study's time (docs/yaw_steering.md#how-both-signs-are-searched). Neither
    the layout nor the turbines change here, and every condition is one of the subset's,
    already validated; the flow field, the wake
    models (with the atmosphere the subset now carries), the per-condition set-points and the
    grid are built as FLORIS builds them (``Core.__attrs_post_init__``). Results are bitwise
    those of the full rebuild (tests/studies/yaw/test_optimization.py).
    """
    given = {k for k, v in kwargs.items() if v is not None}
    core = self.core
    if (not given <= _CONDITION_INPUTS or self._wind_data is not None
            or core.solver["type"] not in ("turbine_grid", "turbine_cubature_grid")):
        return FlorisModel._reinitialize(self, **kwargs)
    floris_dict = core.as_dict()
    flow_field_dict = floris_dict["flow_field"]
    for name in given:
        flow_field_dict[name] = kwargs[name]
    # FLORIS's own code builds the wake models, the flow field and the grid (from_dict, the grid
    # classes) and sets the farm's per-condition set-points (the Farm's methods); only the
    # order of those calls is FLORIS's Core.__attrs_post_init__ written out. That method itself
    # cannot be called on the kept farm: it first rebuilds every turbine (construct_turbine_map
    # and the turbine tables), 10-11 % more time on a steered study (4.10 against 4.57 s on
    # benchmarks/bench_yaw_search.py's rebuild case, bitwise the same results; the full
    # Core.from_dict 5.69 s), and FLORIS 4.7 has no method for the steps after it.
    new = copy.copy(core)
    farm = copy.copy(core.farm)
    # Past attrs' converters (they would rebuild from a dict): these are built objects.
    object.__setattr__(new, "wake", WakeModelManager.from_dict(floris_dict["wake"]))
    object.__setattr__(new, "flow_field", FlowField.from_dict(flow_field_dict))
    object.__setattr__(new, "farm", farm)
    n_findex = new.flow_field.n_findex
    farm.set_yaw_angles_to_ref_yaw(n_findex)
    farm.set_tilt_to_ref_tilt(n_findex)
    farm.set_power_setpoints_to_ref_power(n_findex)
    farm.set_awc_modes_to_ref_mode(n_findex)
    farm.set_awc_amplitudes_to_ref_amp(n_findex)
    farm.set_awc_frequencies_to_ref_freq(n_findex)
    grid_class = TurbineGrid if core.solver["type"] == "turbine_grid" else TurbineCubatureGrid
    object.__setattr__(new, "grid", grid_class(
        turbine_coordinates=farm.coordinates,
        turbine_diameters=farm.rotor_diameters,
        wind_directions=new.flow_field.wind_directions,
        grid_resolution=new.solver["turbine_grid_points"],
    ))
    farm.expand_farm_properties(n_findex, new.grid.sorted_coord_indices)
    self.core = new

