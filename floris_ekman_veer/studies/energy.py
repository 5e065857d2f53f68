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
  which is what it returns for them (:func:`_cannot_gain`, docs/yaw_steering.md#in-a-years-study).

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
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Mapping, Sequence

import attrs
import numpy as np
import pandas as pd
from floris.optimization.yaw_optimization.yaw_optimizer_scipy import YawOptimizationScipy
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR
from floris.wind_data import TimeSeries, WindRose
import floris_ekman_veer.warnings as package_warnings

from floris_ekman_veer.studies.comparison import (
    BUILTIN_WAKES,
    builtin_model,
    comparison_set_kwargs,
)
from floris_ekman_veer.plugin.inflow import (
    ATMOSPHERE_KEY,
    PARAMETER_BLOCK,
    AtmosphereSpec,
    farm_atmosphere,
    set_atmosphere,
)
from floris_ekman_veer.plugin.names import VELOCITY_MODEL_NAME as MODEL_NAME
from floris_ekman_veer._validation import require_floris_model
from floris_ekman_veer.studies.optimization import (
    check_optimizer_options,
    optimize_yaw,
    with_default_yaw_bounds,
)

#: Keys of one class of a stability distribution.
CLASS_KEYS = ("frequency", "atmosphere")
#: Tolerance on the sum of the class frequencies.
FREQUENCY_TOLERANCE = 1e-9
#: Where turbulence intensities come from (see the module docstring).
TURBULENCE_SOURCES = ("atmosphere", "wind_data")
HOURS_PER_YEAR = 8760.0
#: Conditions per FLORIS model of a study: enough to keep FLORIS's vectorisation efficient, few
#: enough to bound the memory of a 100-turbine farm to a few hundred MB.
DEFAULT_CHUNK_SIZE = 1024
#: Conditions x turbines per run of the yaw optimiser in a steered study (``steering_chunk_size``
#: None: this over the farm's turbines, at most ``chunk_size`` conditions). Every run of the
#: optimiser pays a fixed cost per iteration (a FLORIS model set up for its yaw grid), so larger
#: runs cost less per condition; the optimiser evaluates tens of yaw sets of every condition at
#: once, so the memory grows with conditions x turbines (docs/performance.md#a-steered-year).
STEERING_TURBINE_CONDITIONS = 4608
#: Operation models whose power never exceeds the maximum of the turbine's power table: FLORIS
#: interpolates the table (the package's veer-aware rotor scales the speed it is read at,
#: docs/yaw_steering.md), derating only lowers it. A condition with every turbine at that
#: maximum cannot gain from steering (:func:`_cannot_gain`).
CAPPED_OPERATION_MODELS = ("simple", "cosine-loss", "simple-derating")
#: The optimisers that maximise the farm power (and keep the baseline where nothing beats it).
POWER_OPTIMIZERS = (YawOptimizationSR, YawOptimizationScipy)

COLUMNS = ("model", "stability", "frequency", "n_conditions", "aep_baseline_gwh",
           "aep_steered_gwh", "gain_percent")


@attrs.frozen
class StabilityClass:
    """One stability class: its name, atmosphere (scalar EkmanABL inputs without the wind speed)
    and, per condition of the wind data, the frequency of (this class, that condition)."""

    name: str
    atmosphere: dict
    frequency: float
    condition_frequencies: np.ndarray


def stability_classes(stability: Mapping, wind_data, records=None) -> list[StabilityClass]:
    """Validate a stability distribution against ``wind_data`` (see the module docstring).

    Args:
        stability: ``{name: {"frequency": f, "atmosphere": {...}}}``; without ``frequency``
            when ``records`` are given.
        wind_data: A FLORIS ``WindRose`` or ``TimeSeries``.
        records: With a TimeSeries: the class name of every record.

    Raises:
        ValueError: naming the class, the key and the value, for unknown keys, frequencies out
            of [0, 1] or not summing to 1, atmospheres EkmanABL rejects or that vary per
            condition, records of unknown classes or of the wrong length.
    """
    if not isinstance(wind_data, (WindRose, TimeSeries)):
        raise ValueError(
            "annual energy: wind_data must be a floris.WindRose or floris.TimeSeries, got "
            f"{type(wind_data).__name__}"
        )
    if not isinstance(stability, Mapping) or not stability:
        raise ValueError(
            "annual energy: stability must be a non-empty mapping {class name: {'frequency': f, "
            f"'atmosphere': {{...}}}}}}, got {stability!r}"
        )
    wind_frequencies = np.asarray(wind_data.unpack_freq(), dtype=float).reshape(-1)
    if records is not None:
        if not isinstance(wind_data, TimeSeries):
            raise ValueError(
                "annual energy: records (a stability class per record) need a floris.TimeSeries; "
                f"got a {type(wind_data).__name__} (give a frequency per class instead)"
            )
        records = np.asarray(records, dtype=object).reshape(-1)
        if records.size != wind_frequencies.size:
            raise ValueError(
                f"annual energy: records must give one stability class per TimeSeries record "
                f"({wind_frequencies.size}); got {records.size}"
            )
        unknown = [i for i, name in enumerate(records) if name not in stability]
        if unknown:
            raise ValueError(
                f"annual energy: records[{unknown[0]}] = {records[unknown[0]]!r} is not a class "
                f"of stability {sorted(stability)} ({len(unknown)} such records)"
            )
    classes = []
    for name, entry in stability.items():
        where = f"stability[{name!r}]"
        if not isinstance(entry, Mapping):
            raise ValueError(f"annual energy: {where} must be a mapping with keys "
                             f"{list(CLASS_KEYS)}, got {entry!r}")
        unknown = sorted(set(entry) - set(CLASS_KEYS))
        if unknown:
            raise ValueError(f"annual energy: {where}: unknown key(s) {unknown}; "
                             f"allowed: {list(CLASS_KEYS)}")
        if "atmosphere" not in entry or not isinstance(entry["atmosphere"], Mapping):
            raise ValueError(f"annual energy: {where}['atmosphere'] must be a mapping of "
                             f"EkmanABL inputs without the wind speed, got "
                             f"{entry.get('atmosphere')!r}")
        try:
            spec = AtmosphereSpec.from_mapping(entry["atmosphere"])
        except ValueError as error:
            raise ValueError(f"annual energy: {where}['atmosphere']: {error}") from None
        if spec.n_conditions is not None:
            raise ValueError(
                f"annual energy: {where}['atmosphere'] must hold scalars (a class is one "
                "atmosphere); give each atmosphere its own class"
            )
        if records is not None:
            if "frequency" in entry:
                raise ValueError(
                    f"annual energy: {where}: with records the class frequencies follow from the "
                    f"records; remove 'frequency' (got {entry['frequency']!r})"
                )
            mask = records == name
            frequency = float(np.sum(wind_frequencies[mask]))
            condition_frequencies = np.where(mask, wind_frequencies, 0.0)
        else:
            frequency = entry.get("frequency")
            if (isinstance(frequency, bool) or not isinstance(frequency, (int, float, np.number))
                    or not 0.0 <= frequency <= 1.0):
                raise ValueError(
                    f"annual energy: {where}['frequency'] must be a number in [0, 1], got "
                    f"{frequency!r}"
                )
            frequency = float(frequency)
            condition_frequencies = frequency * wind_frequencies
        classes.append(StabilityClass(str(name), spec.sliced(slice(None)), frequency,
                                      condition_frequencies))
    total = math.fsum(c.frequency for c in classes)
    if abs(total - 1.0) > FREQUENCY_TOLERANCE:
        given = ", ".join(f"{c.name!r}: {c.frequency:g}" for c in classes)
        raise ValueError(f"annual energy: the stability class frequencies must sum to 1; got "
                         f"{total:.12g} ({given})")
    return classes


@attrs.frozen
class AnnualEnergy:
    """Result of :func:`annual_energy`.

    Attributes:
        table: One row per (model, stability class) and one per model with stability ``"all"``
            (the year), columns :data:`COLUMNS` (energies in GWh; the steered columns are NaN
            without an optimiser).
        optima: ``{(model, class): df_opt}``, FLORIS's frames of the optimal yaw angles, one row
            per condition of the class (the wind data's order; records of the class only).
        inflow: ``{(model, class): {"turbulence_intensities": array per condition,
            "wind_veer": deg, "wind_shear": exponent}}``, what each model was given (FLORIS's
            flow-field inputs; ekman_veer reads neither veer nor shear from them and, with
            ``wake_expansion: ambient``, takes its k_w from the ABL's I_u(z_h)).
    """

    table: pd.DataFrame
    optima: dict
    inflow: dict
    #: ``{model: DataFrame}``, one row per condition run (index: the condition's position in the
    #: wind data), columns ``stability``, ``frequency``, ``farm_power_baseline`` and
    #: ``farm_power_steered`` [W] (NaN without an optimiser).
    conditions: dict = attrs.field(factory=dict)
    #: A fitted year's energy per month (``SiteAtmosphere.annual_energy``): one row per model
    #: and month, the columns of ``table`` with ``period`` for ``stability``; else None.
    by_month: pd.DataFrame | None = None

    def plot(self, ax=None):
        """Bar chart of the AEP per class and model, baseline and steered; returns the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(7.0, 4.0))
        table = self.table
        models = list(dict.fromkeys(table["model"]))
        stabilities = list(dict.fromkeys(table["stability"]))
        width = 0.8 / len(models)
        for m, model in enumerate(models):
            rows = table[table["model"] == model].set_index("stability").loc[stabilities]
            x = np.arange(len(stabilities)) + (m - 0.5 * (len(models) - 1)) * width
            base = ax.bar(x, rows["aep_baseline_gwh"], width * 0.9, label=f"{model} baseline",
                          alpha=0.45)
            ax.bar(x, rows["aep_steered_gwh"] - rows["aep_baseline_gwh"], width * 0.9,
                   bottom=rows["aep_baseline_gwh"], color=base.patches[0].get_facecolor(),
                   label=f"{model} steering gain", alpha=1.0)
            for xi, (_, row) in zip(x, rows.iterrows()):
                if np.isfinite(row["gain_percent"]):
                    ax.annotate(f"{row['gain_percent']:+.2f} %", (xi, row["aep_steered_gwh"]),
                                ha="center", va="bottom", fontsize=7)
        ax.set_xticks(np.arange(len(stabilities)), stabilities)
        ax.set_ylabel("AEP [GWh]")
        ax.legend(fontsize=7)
        return ax

    def __attrs_post_init__(self):
        # print(result.table) shows every column in a plain terminal (studies/tables.py).
        from floris_ekman_veer.studies.tables import FullTable

        object.__setattr__(self, "table", FullTable(self.table))


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
            cannot raise their power (:func:`_cannot_gain`, docs/yaw_steering.md).
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
        return {k: v if np.ndim(v) == 0 else np.asarray(v, dtype=float)[rows].tolist()
                for k, v in self.atmosphere.items()}


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
        _check_client(fmodel, client)
    return dict(models=models, directions=directions, speeds=speeds, wind_ti=wind_ti,
                turbulence_intensities=turbulence_intensities, chunk_size=int(chunk_size),
                steering_chunk_size=int(steering_chunk_size), client=client)


def _check_client(fmodel, client) -> None:
    """Refuse, before any run, a ``client`` that is not a ``dask.distributed.Client`` or a
    model the workers cannot rebuild as it is; register the package on every worker."""
    from floris import FlorisModel
    from floris.par_floris_model import ParFlorisModel

    from floris_ekman_veer.studies.distributed import _check_workers, _import_distributed

    if isinstance(fmodel, ParFlorisModel) or not isinstance(fmodel, FlorisModel):
        raise ValueError(
            "annual energy: with client= each chunk of conditions runs on a Dask worker as a "
            f"plain FlorisModel; fmodel must be a FlorisModel, got {type(fmodel).__name__} "
            "(give its FlorisModel, or drop client= to let the model run its own chunks)"
        )
    distributed = _import_distributed()
    if not isinstance(client, distributed.Client):
        raise ValueError(
            "annual energy: client must be a dask.distributed.Client (e.g. "
            f"Client(LocalCluster()) or Client('tcp://scheduler:8786')); got "
            f"{type(client).__name__}"
        )
    _check_workers(client)


def _run_study(fmodel, wind_data, names, frequencies, conditions, optimizer_class, study,
               progress, optimizer_kwargs) -> AnnualEnergy:
    """Run every model over the study's conditions in chunks, one vectorised FLORIS model per
    chunk (each condition with its own atmosphere), and sum the energies per class."""
    from tqdm.auto import tqdm

    steered = optimizer_class is not None
    n_classes = len(names)
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
                      for rows in _chunk_rows(c.wind_index.size, study["chunk_size"])]
            if study["client"] is None:
                parts = []
                for chunk in chunks:
                    parts.append(_run_chunk(template, model, chunk, study["turbulence_intensities"],
                                            optimizer_class))
                    bar.update(chunk.speeds.size)
            else:
                parts = _run_on_cluster(study["client"], template, model, chunks,
                                        study["turbulence_intensities"], optimizer_class, bar)
            per_model[model] = {k: np.concatenate([p[k] for p in parts]) if k != "optima"
                                else pd.concat([p[k] for p in parts], ignore_index=True)
                                for k in parts[0] if parts[0][k] is not None}
    owner = np.concatenate([c.owner for c in conditions])
    freq = np.concatenate([c.freq for c in conditions])
    order = np.argsort(owner, kind="stable")
    bounds = np.searchsorted(owner[order], np.arange(n_classes + 1))
    rows, optima, inflow = [], {}, {}
    for model, result in per_model.items():
        for k, name in enumerate(names):
            rows_k = order[bounds[k]:bounds[k + 1]]
            row = dict(model=model, stability=name, frequency=frequencies[k],
                       n_conditions=rows_k.size, aep_baseline_gwh=0.0,
                       aep_steered_gwh=0.0 if steered else np.nan)
            if rows_k.size:
                # As FLORIS's get_farm_AEP of a model holding the class's conditions.
                row["aep_baseline_gwh"] = _aep(freq[rows_k], result["baseline"][rows_k])
                if steered:
                    row["aep_steered_gwh"] = _aep(freq[rows_k], result["steered"][rows_k])
                    optima[model, name] = result["optima"].iloc[rows_k].reset_index(drop=True)
                inflow[model, name] = {
                    "turbulence_intensities": result["turbulence_intensities"][rows_k],
                    "wind_veer": float(result["wind_veer"][rows_k[0]]),
                    "wind_shear": float(result["wind_shear"][rows_k[0]]),
                }
            rows.append(row)
    table = pd.DataFrame(rows)
    year = table.groupby("model", sort=False)[
        ["frequency", "n_conditions", "aep_baseline_gwh", "aep_steered_gwh"]
    ].sum(min_count=1).reset_index()
    year.insert(1, "stability", "all")
    table = pd.concat([table, year], ignore_index=True)
    table["gain_percent"] = 100.0 * (table["aep_steered_gwh"] / table["aep_baseline_gwh"] - 1.0)
    wind_index = np.concatenate([c.wind_index for c in conditions])
    per_condition = {
        model: pd.DataFrame({
            "stability": np.asarray(names, dtype=object)[owner], "frequency": freq,
            "farm_power_baseline": result["baseline"],
            "farm_power_steered": result["steered"] if steered else np.nan,
        }, index=pd.Index(wind_index, name="condition")).sort_index()
        for model, result in per_model.items()
    }
    return AnnualEnergy(table=table[list(COLUMNS)], optima=optima, inflow=inflow,
                        conditions=per_condition)


def energy_by_period(energy: AnnualEnergy, periods) -> pd.DataFrame:
    """The study's energy per model and period (``periods``: a name per condition of the wind
    data, e.g. its month), as :func:`annual_energy`'s table: the periods sum to the year."""
    rows = []
    for model, conditions in energy.conditions.items():
        period = np.asarray(periods, dtype=object)[conditions.index.to_numpy()]
        for name in pd.unique(period):
            these = conditions[period == name]
            baseline = _aep(these["frequency"], these["farm_power_baseline"])
            steered = (_aep(these["frequency"], these["farm_power_steered"])
                       if these["farm_power_steered"].notna().any() else np.nan)
            rows.append({"model": model, "period": name, "frequency": these["frequency"].sum(),
                         "n_conditions": len(these), "aep_baseline_gwh": baseline,
                         "aep_steered_gwh": steered,
                         "gain_percent": 100.0 * (steered / baseline - 1.0)})
    from floris_ekman_veer.studies.tables import FullTable

    return FullTable(pd.DataFrame(rows))


def _aep(freq, farm_power) -> float:
    """FLORIS's ``get_farm_AEP(freq=freq)`` [GWh] from the farm power per condition."""
    return float(np.nansum(np.multiply(freq, farm_power)) * HOURS_PER_YEAR) / 1e9


def _chunk_rows(n: int, chunk_size: int) -> list:
    """Contiguous chunks of at most ``chunk_size`` of ``n`` conditions (np.array_split, as
    FLORIS's ParFlorisModel cuts its conditions)."""
    return [rows for rows in np.array_split(np.arange(n), max(1, -(-n // chunk_size)))
            if rows.size]


@attrs.frozen(eq=False)
class _Chunk:
    """One chunk of a study, self-contained (a Dask task carries it): its conditions, their
    atmosphere (a plain block: scalars, or one value per condition), the optimiser's options
    cut to them and the conditions per optimiser run."""

    atmosphere: dict
    directions: np.ndarray
    speeds: np.ndarray
    wind_ti: np.ndarray
    optimizer_kwargs: dict
    steering_chunk_size: int = DEFAULT_CHUNK_SIZE

    def rows(self, rows) -> _Chunk:
        """The chunk of its conditions ``rows``."""
        return _Chunk({k: v if np.ndim(v) == 0 else np.asarray(v, dtype=float)[rows].tolist()
                       for k, v in self.atmosphere.items()},
                      self.directions[rows], self.speeds[rows], self.wind_ti[rows],
                      _rows_of(self.optimizer_kwargs, rows), self.steering_chunk_size)


def _chunk_of(conditions, rows, study, optimizer_kwargs) -> _Chunk:
    index = conditions.wind_index[rows]
    return _Chunk(conditions.atmosphere_of(rows), study["directions"][index],
                  study["speeds"][index], study["wind_ti"][index],
                  _rows_of(optimizer_kwargs, index), study["steering_chunk_size"])


def _run_chunk(template, model, chunk, ti_source, optimizer_class) -> dict:
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


def _run_on_cluster(client, template, model, chunks, ti_source, optimizer_class, bar) -> list:
    """:func:`_run_chunk` of every chunk as a task on the Dask cluster of ``client``; the results
    in the chunks' order, the workers' warnings reported here once (floris_ekman_veer.warnings)."""
    from distributed import as_completed

    import floris_ekman_veer.warnings as package_warnings

    config = template.core.as_dict()
    # The workers set every chunk's conditions and atmosphere: the template's own (possibly a
    # year of per-record lists) need not travel.
    config["flow_field"].update(wind_directions=[], wind_speeds=[], turbulence_intensities=[])
    block = config["wake"]["wake_velocity_parameters"].get(PARAMETER_BLOCK)
    if block is not None:
        block.pop(ATMOSPHERE_KEY, None)
    [config] = client.scatter([config], broadcast=True)
    futures = client.map(_remote_chunk, chunks, config=config, model=model, ti_source=ti_source,
                         optimizer_class=optimizer_class,
                         setting=package_warnings.warnings_setting(), pure=False)
    sizes = {future.key: chunk.speeds.size for future, chunk in zip(futures, chunks)}
    package_warnings.discard_from_workers()
    for future in as_completed(futures):
        bar.update(sizes[future.key])
    results = client.gather(futures)
    package_warnings.report_from_workers(sum(sizes.values()))
    return [part for part, _ in results]


def _remote_chunk(chunk, config, model, ti_source, optimizer_class, setting):
    """A chunk on a Dask worker: the template rebuilt there with the chunk's conditions (a plain
    FlorisModel), then :func:`_run_chunk` as in the serial study; the package's warnings travel
    back with the result."""
    import copy

    from floris import FlorisModel

    import floris_ekman_veer.warnings as package_warnings
    from floris_ekman_veer.plugin.parallel import prepare_worker

    prepare_worker()
    package_warnings.apply_setting(setting)
    config = copy.deepcopy(config)
    config["flow_field"].update(wind_directions=chunk.directions.tolist(),
                                wind_speeds=chunk.speeds.tolist(),
                                turbulence_intensities=chunk.wind_ti.tolist())
    parameters = config["wake"]["wake_velocity_parameters"]
    parameters.setdefault(PARAMETER_BLOCK, {})[ATMOSPHERE_KEY] = dict(chunk.atmosphere)
    with package_warnings.collecting() as records:
        part = _run_chunk(FlorisModel(config), model, chunk, ti_source, optimizer_class)
    return part, package_warnings.WorkerRecords(records) if records else None


def _rows_of(optimizer_kwargs, index):
    """The optimiser's options for the wind data's conditions ``index`` (per-condition arrays
    cut to them)."""
    from floris_ekman_veer.studies.optimization import PER_CONDITION_OPTIONS

    return {name: np.asarray(value, dtype=float)[index]
            if name in PER_CONDITION_OPTIONS and np.ndim(value) == 2 else value
            for name, value in optimizer_kwargs.items()}


def _chunk_model(template, model: str, chunk: _Chunk, ti_source: str):
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
