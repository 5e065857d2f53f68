"""Annual energy production per stability class, with and without wake steering.

A wind climate is a FLORIS wind-data object for the wind and a stability distribution of named
classes, each an atmosphere (the ``ekman_veer.atmosphere`` block of the FLORIS input, scalars):

* with a ``WindRose`` (directions x speeds) or a ``TimeSeries``, each class has a ``frequency``
  (the frequencies sum to 1) and the frequency of (class, direction, speed) is the product of
  the class frequency and the wind's: stability is taken as independent of the wind, as a
  frequency per class states;
* with a ``TimeSeries`` and ``records`` (a class name per record), each record has its own
  class and the class frequencies follow from the records.

For every model (``ekman_veer``, the input's own wake model, and FLORIS's built-ins of
:data:`~floris_ekman_veer.studies.comparison.BUILTIN_WAKES`, GCH by default),
:func:`annual_energy` runs every condition of every class with non-zero frequency as one
vectorised FLORIS model, each condition carrying its class's atmosphere (a per-condition
atmosphere block, docs/coupling.md#annual-energy), in chunks of ``chunk_size`` conditions that
bound the memory (a condition's numbers do not depend on the chunk it runs in), on the same Ekman
inflow for all models, and computes, per class, FLORIS's ``get_farm_AEP`` of the class's
conditions (``freq`` = the joint frequency of each condition, so the classes' energies add up to
the year's)

* the baseline AEP (every turbine aligned with the hub-height wind: the yaw angles are measured
  from the wind direction at FLORIS's reference height) and
* the AEP with wake steering: the yaw angles of :func:`~floris_ekman_veer.optimize_yaw` (any
  FLORIS yaw optimiser) per condition, run over ``steering_chunk_size`` conditions at a time;
  conditions whose every turbine is at the maximum of its power table keep zero yaw without it,
  which is what it returns for them (studies/energy/condition_chunks.py,
  docs/yaw_steering.md#in-a-years-study).

:func:`record_energy` (``SiteAtmosphere.annual_energy``) does the same for a time series whose
records each carry their own atmosphere.

Each model sees the atmosphere the way it can (docs/coupling.md#annual-energy): the ekman_veer
models take their wake expansion from the ABL itself; FLORIS's built-ins get the comparison of
:func:`~floris_ekman_veer.studies.comparison.comparison_set_kwargs` (the one
``examples/yaw_study.py`` uses): per condition the turbulence intensity I_u(z_h) of the class's
atmosphere, and FLORIS's ``wind_veer`` = 0 (the veer is in the Ekman inflow and the rotor; gauss's
scalar wind_veer would narrow its wake by cos(wind_veer), docs/yaw_steering.md). With
``turbulence_intensities="wind_data"`` every model gets the wind data's turbulence intensities
instead (then, with one class, the baseline is exactly ``get_farm_AEP`` of the model set with that
wind data). Every input is checked before any FLORIS run.

The stability classes are checked in studies/energy/stability_classes.py, the chunks of conditions run in
studies/energy/condition_chunks.py (on a Dask cluster: studies/energy/distributed.py), and the result is
tabulated in studies/energy/energy_results.py.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import attrs
import numpy as np
import pandas as pd
from floris.wind_data import TimeSeries

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer._validation import require_floris_model
from floris_ekman_veer.plugin.inflow.inflow import AtmosphereSpec
from floris_ekman_veer.plugin.wake_models.names import VELOCITY_MODEL_NAME as MODEL_NAME
from floris_ekman_veer.plugin.floris_tools.optimizer_options import (
    check_optimizer_options,
    options_for_conditions,
    with_default_yaw_bounds,
)
from floris_ekman_veer.studies.comparison import BUILTIN_WAKES, builtin_model
from floris_ekman_veer.studies.energy.condition_chunks import (
    DEFAULT_CHUNK_SIZE,
    Chunk,
    atmosphere_rows,
    chunk_rows,
    run_chunk,
)
from floris_ekman_veer.studies.energy.distributed import check_client, run_chunks_on_cluster
from floris_ekman_veer.studies.energy.energy_results import AnnualEnergy, aep, energy_table
from floris_ekman_veer.studies.energy.stability_classes import stability_classes

#: Where turbulence intensities come from (see the module docstring).
TURBULENCE_SOURCES = ("atmosphere", "wind_data")
#: Conditions x turbines per run of the yaw optimiser in a steered study (``steering_chunk_size``
#: None: this over the farm's turbines, at most ``chunk_size`` conditions). Every run of the
#: optimiser pays a fixed cost per iteration (a FLORIS model set up for its yaw grid), so larger
#: runs cost less per condition; the optimiser evaluates tens of yaw sets of every condition at
#: once, so the memory grows with conditions x turbines (docs/performance.md#a-steered-year).
STEERING_TURBINE_CONDITIONS = 4608


def annual_energy(
    fmodel,
    wind_data,
    stability: Mapping,
    optimizer_class=None,
    *,
    records: Sequence | None = None,
    models: Sequence[str] = (MODEL_NAME, "gch"),
    turbulence_intensities: str = "atmosphere",
    progress: bool | None = None,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    steering_chunk_size: int | None = None,
    client=None,
    **optimizer_kwargs,
) -> AnnualEnergy:
    """AEP per stability class and model, baseline and with optimised yaw (module docstring).

    Args:
        fmodel: FlorisModel or ParFlorisModel with the farm (and, for ``"ekman_veer"``, the
            ekman_veer wake models); its conditions and atmosphere are replaced per chunk.
        wind_data: FLORIS ``WindRose`` or ``TimeSeries``.
        stability: Stability classes (see :func:`stability_classes`).
        optimizer_class: A FLORIS yaw optimiser class for the steered AEP, or None (baseline
            only).
        records: With a TimeSeries, the class of every record.
        models: ``"ekman_veer"`` (``fmodel`` itself) and/or keys of ``BUILTIN_WAKES``.
        turbulence_intensities: ``"atmosphere"`` (I_u(z_h) of each class's atmosphere) or
            ``"wind_data"``.
        progress: tqdm bar over the study's conditions (None: with an optimiser).
        chunk_size: Conditions per FLORIS model (bounds the memory; results do not depend on
            it).
        steering_chunk_size: Conditions per run of the yaw optimiser within a chunk (bounds its
            memory; results do not depend on it); None: :data:`STEERING_TURBINE_CONDITIONS`
            over the farm's turbines (512 on a 3 x 3 farm). Conditions whose every turbine
            is at the maximum of its power table skip the optimiser and keep zero yaw: steering
            cannot raise their power (studies/energy/condition_chunks.py, docs/yaw_steering.md).
        client: A ``dask.distributed.Client``: the chunks run on its workers, each a
            self-contained task (the chunk's FLORIS model, its run and its yaw optimisation),
            gathered in order, so the numbers are bitwise those of the serial study
            (docs/coupling.md#annual-energy); needs the extra ``dask`` and ``fmodel`` a plain
            FlorisModel.
        **optimizer_kwargs: Options of ``optimizer_class`` (checked before any run).
    """
    require_floris_model(fmodel, "annual energy")
    classes = stability_classes(stability, wind_data, records)
    study = _check_study(fmodel, wind_data, optimizer_class, models, turbulence_intensities,
                         chunk_size, optimizer_kwargs, client, steering_chunk_size)
    groups = {}
    for k, c in enumerate(classes):
        # Classes giving the same EkmanABL inputs run together, one atmosphere per condition.
        groups.setdefault(tuple(sorted(c.atmosphere)), []).append(k)
    conditions = []
    for members in groups.values():
        index = [np.flatnonzero(classes[k].condition_frequencies > 0.0) for k in members]
        owner = np.concatenate([np.full(i.size, k) for k, i in zip(members, index)])
        wind_index = np.concatenate(index)
        if len(members) == 1:
            atmosphere = classes[members[0]].atmosphere
        else:
            atmosphere = {name: np.array([classes[k].atmosphere[name] for k in members])[
                np.searchsorted(members, owner)] for name in classes[members[0]].atmosphere}
        freq = np.concatenate([classes[k].condition_frequencies[i]
                               for k, i in zip(members, index)])
        conditions.append(_Conditions(atmosphere, wind_index, owner, freq))
    return _run_study(fmodel, wind_data, [c.name for c in classes],
                      [c.frequency for c in classes], conditions, optimizer_class, study,
                      progress, optimizer_kwargs)


def record_energy(fmodel, series: TimeSeries, atmosphere: Mapping, labels: Sequence[str],
                  optimizer_class=None, *, models: Sequence[str] = (MODEL_NAME, "gch"),
                  turbulence_intensities: str = "atmosphere", progress: bool | None = None,
                  chunk_size: int = DEFAULT_CHUNK_SIZE, steering_chunk_size: int | None = None,
                  client=None, classes: Sequence[str] | None = None,
                  **optimizer_kwargs) -> AnnualEnergy:
    """:func:`annual_energy` of a ``TimeSeries`` whose records each have their own atmosphere
    (``atmosphere``: the block with one value per record, as ``SiteAtmosphere.atmosphere``).

    One class per distinct atmosphere, named by the label of its first record (as
    ``SiteAtmosphere.stability``); the numbers are those of ``annual_energy`` with these
    classes and records, without a class mapping per record. ``classes``: instead, a class
    name per record (e.g. the fitted "convective", "neutral", "stable"), each record still run
    with its own atmosphere; the classes in the order of their first record.
    """
    study = _check_study(fmodel, series, optimizer_class, models, turbulence_intensities,
                         chunk_size, optimizer_kwargs, client, steering_chunk_size)
    wind_frequencies = np.asarray(series.unpack_freq(), dtype=float).reshape(-1)
    n = wind_frequencies.size
    spec = AtmosphereSpec.from_mapping(atmosphere)
    spec.check_conditions(n)
    per_record = sorted(k for k, v in spec.inputs.items() if not isinstance(v, float))
    if classes is not None:
        if len(classes) != n:
            raise ValueError(f"annual energy: classes must name the {n} records' classes; got "
                             f"{len(classes)}")
        _, first, owner = np.unique(np.asarray(classes, dtype=str), return_index=True,
                                    return_inverse=True)
        owner, labels = owner.reshape(-1), [str(c) for c in classes]
    elif per_record:
        rows = np.stack([spec.inputs[k].reshape(-1) for k in per_record], axis=1)
        _, first, owner = np.unique(rows, axis=0, return_index=True, return_inverse=True)
        owner = owner.reshape(-1)
    else:
        first, owner = np.zeros(1, dtype=int), np.zeros(n, dtype=int)
    # Classes in order of their first record.
    rank = np.empty(first.size, dtype=int)
    rank[np.argsort(first, kind="stable")] = np.arange(first.size)
    owner, first = rank[owner], np.sort(first)
    names = [str(labels[j]) for j in first]
    order = np.argsort(owner, kind="stable")
    bounds = np.searchsorted(owner[order], np.arange(first.size + 1))
    frequencies = [float(np.sum(wind_frequencies[np.sort(order[bounds[k]:bounds[k + 1]])]))
                   for k in range(first.size)]
    keep = np.flatnonzero(wind_frequencies > 0.0)
    conditions = _Conditions(
        {k: v if isinstance(v, float) else v.reshape(-1)[keep] for k, v in spec.inputs.items()},
        keep, owner[keep], wind_frequencies[keep])
    return _run_study(fmodel, series, names, frequencies, [conditions], optimizer_class, study,
                      progress, optimizer_kwargs)


@attrs.frozen(eq=False)
class _Conditions:
    """Conditions of a study sharing one set of EkmanABL inputs: per condition its atmosphere
    (scalars, or arrays of one value per condition), its index in the wind data, its class
    (position in the study's classes) and its frequency."""

    atmosphere: dict
    wind_index: np.ndarray
    owner: np.ndarray
    freq: np.ndarray

    def atmosphere_of(self, rows) -> dict:
        return atmosphere_rows(self.atmosphere, rows)


def _check_study(fmodel, wind_data, optimizer_class, models, turbulence_intensities,
                 chunk_size, optimizer_kwargs, client=None, steering_chunk_size=None) -> dict:
    """Check a study's options before any FLORIS run; the wind data's arrays and models."""
    models = list(models)
    allowed = [MODEL_NAME, *BUILTIN_WAKES]
    if not models or any(m not in allowed for m in models) or len(set(models)) < len(models):
        raise ValueError(f"annual energy: models must be distinct names from {allowed}; "
                         f"got {models!r}")
    velocity_model = fmodel.core.wake.model_strings["velocity_model"]
    if MODEL_NAME in models and velocity_model != MODEL_NAME:
        raise ValueError(f"annual energy: models has {MODEL_NAME!r}, which runs fmodel itself, "
                         f"but fmodel's velocity_model is {velocity_model!r}")
    if turbulence_intensities not in TURBULENCE_SOURCES:
        raise ValueError(f"annual energy: turbulence_intensities must be one of "
                         f"{list(TURBULENCE_SOURCES)}, got {turbulence_intensities!r}")
    for name, size in (("chunk_size", chunk_size), ("steering_chunk_size", steering_chunk_size)):
        if size is None and name == "steering_chunk_size":
            continue
        if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
            raise ValueError(f"annual energy: {name} must be an integer >= 1; got {size!r}")
    if steering_chunk_size is None:
        steering_chunk_size = max(1, STEERING_TURBINE_CONDITIONS // fmodel.core.farm.n_turbines)
    directions, speeds, wind_ti, heterogeneous = wind_data.unpack_for_reinitialize()
    if heterogeneous is not None:
        raise ValueError("annual energy: wind data with a heterogeneous inflow map is not "
                         "supported (the Ekman profile is the inflow)")
    if optimizer_class is not None:
        check_optimizer_options(optimizer_class,
                                with_default_yaw_bounds(optimizer_class, optimizer_kwargs),
                                len(directions), fmodel.core.farm.n_turbines)
    elif optimizer_kwargs:
        raise ValueError(f"annual energy: optimiser options {sorted(optimizer_kwargs)} given "
                         "without an optimizer_class")
    if client is not None:
        check_client(fmodel, client)
    return dict(models=models, directions=directions, speeds=speeds, wind_ti=wind_ti,
                turbulence_intensities=turbulence_intensities, chunk_size=int(chunk_size),
                steering_chunk_size=int(steering_chunk_size), client=client)


def _run_study(fmodel, wind_data, names, frequencies, conditions, optimizer_class, study,
               progress, optimizer_kwargs) -> AnnualEnergy:
    """Run every model over the study's conditions in chunks, one vectorised FLORIS model per
    chunk (each condition with its own atmosphere), and sum the energies per class."""
    from tqdm.auto import tqdm

    steered = optimizer_class is not None
    total = sum(c.wind_index.size for c in conditions)
    per_model = {}
    # One summary per warning class for the whole study, not one per chunk and model.
    with package_warnings.study_scope(), tqdm(
            total=total * len(study["models"]), desc="annual energy", unit="condition",
            disable=not (progress if progress is not None else steered)) as bar:
        for model in study["models"]:
            bar.set_postfix_str(model)
            template = fmodel.copy() if model == MODEL_NAME else builtin_model(fmodel, model)
            chunks = [_chunk_of(c, rows, study, optimizer_kwargs) for c in conditions
                      for rows in chunk_rows(c.wind_index.size, study["chunk_size"])]
            if study["client"] is None:
                parts = []
                for chunk in chunks:
                    parts.append(run_chunk(template, model, chunk, study["turbulence_intensities"],
                                           optimizer_class))
                    bar.update(chunk.speeds.size)
            else:
                parts = run_chunks_on_cluster(study["client"], template, model, chunks,
                                              study["turbulence_intensities"], optimizer_class,
                                              bar)
            per_model[model] = {k: np.concatenate([p[k] for p in parts]) if k != "optima"
                                else pd.concat([p[k] for p in parts], ignore_index=True)
                                for k in parts[0] if parts[0][k] is not None}
    return energy_table(per_model, names, frequencies,
                        np.concatenate([c.owner for c in conditions]),
                        np.concatenate([c.freq for c in conditions]),
                        np.concatenate([c.wind_index for c in conditions]), steered)


def _chunk_of(conditions, rows, study, optimizer_kwargs) -> Chunk:
    index = conditions.wind_index[rows]
    return Chunk(conditions.atmosphere_of(rows), study["directions"][index],
                 study["speeds"][index], study["wind_ti"][index],
                 options_for_conditions(optimizer_kwargs, index), study["steering_chunk_size"])


def energy_by_month(energy: AnnualEnergy, times) -> pd.DataFrame:
    """A typical year's energy per calendar month, January to December (``times``: the wind
    data's time stamps, one per condition): per model and month the mean farm power of each year
    present, averaged over those years, times the month's hours (February 28.25 days), so that
    a month with gaps reads as its weather, not as a weak month; ``coverage`` is the share of
    the month's records present over those years (from the records' median interval), and
    ``years`` how many years hold it. A month with no record is NaN (``years`` 0). With every
    month fully covered, the twelve sum to the year's AEP of the same records."""
    times = pd.DatetimeIndex(times)
    step = (pd.Series(times).sort_values().diff().median() / pd.Timedelta("1h")
            if len(times) > 1 else 1.0)
    step = step if np.isfinite(step) and step > 0 else 1.0
    days = np.array([31.0, 28.25, 31.0, 30.0, 31.0, 30.0, 31.0, 31.0, 30.0, 31.0, 30.0, 31.0])
    rows = []
    for model, conditions in energy.conditions.items():
        at = times[conditions.index.to_numpy()]
        frame = pd.DataFrame({"year": at.year, "month": at.month,
                              "baseline": conditions["farm_power_baseline"].to_numpy(),
                              "steered": conditions["farm_power_steered"].to_numpy()})
        for month in range(1, 13):
            these = frame[frame["month"] == month]
            per_year = these.groupby("year")[["baseline", "steered"]].mean()
            hours = 24.0 * days[month - 1]
            expected = sum(pd.Period(f"{y}-{month:02d}").days_in_month * 24.0 / step
                           for y in per_year.index)
            baseline = float(per_year["baseline"].mean()) * hours / 1e9 if len(these) else np.nan
            steered = (float(per_year["steered"].mean()) * hours / 1e9
                       if these["steered"].notna().any() else np.nan)
            rows.append({"model": model, "month": month, "years": len(per_year),
                         "coverage": len(these) / expected if expected else 0.0,
                         "n_conditions": len(these), "aep_baseline_gwh": baseline,
                         "aep_steered_gwh": steered,
                         "gain_percent": 100.0 * (steered / baseline - 1.0)})
    from floris_ekman_veer.studies.tables import FullTable

    return FullTable(pd.DataFrame(rows))
