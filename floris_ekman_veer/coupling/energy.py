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
:data:`~floris_ekman_veer.coupling.comparison.BUILTIN_WAKES`, GCH by default) and class,
:func:`annual_energy` builds one FLORIS model holding the class's conditions with the class's
atmosphere, on the same Ekman inflow for all models, and computes with FLORIS's own
``get_farm_AEP`` (``freq`` = the joint frequency of each condition, so the classes' energies add
up to the year's)

* the baseline AEP (every turbine aligned with the hub-height wind: the yaw angles are measured
  from the wind direction at FLORIS's reference height) and
* the AEP with wake steering: the yaw angles of :func:`~floris_ekman_veer.optimize_yaw` (any
  FLORIS yaw optimiser) per condition.

Each model sees the atmosphere the way it can (docs/coupling.md#annual-energy): the ekman_veer
models take their wake expansion from the ABL itself; FLORIS's built-ins get, per condition, the
turbulence intensity I_u(z_h) of the class's atmosphere and, per class, its rotor-layer veer and
shear (:func:`~floris_ekman_veer.coupling.comparison.fair_builtin_set_kwargs`). With
``turbulence_intensities="wind_data"`` every model gets the wind data's turbulence intensities
instead (then, with one class, the baseline is exactly ``get_farm_AEP`` of the model set with that
wind data). Every input is checked before any FLORIS run.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import attrs
import numpy as np
import pandas as pd
from floris.wind_data import TimeSeries, WindRose

from floris_ekman_veer.coupling.comparison import (
    BUILTIN_WAKES,
    builtin_model,
    fair_builtin_set_kwargs,
)
from floris_ekman_veer.coupling.inflow import AtmosphereSpec, set_atmosphere
from floris_ekman_veer.coupling.names import VELOCITY_MODEL_NAME as MODEL_NAME
from floris_ekman_veer.coupling.optimization import check_optimizer_options, optimize_yaw

#: Keys of one class of a stability distribution.
CLASS_KEYS = ("frequency", "atmosphere")
#: Tolerance on the sum of the class frequencies.
FREQUENCY_TOLERANCE = 1e-9
#: Where turbulence intensities come from (see the module docstring).
TURBULENCE_SOURCES = ("atmosphere", "wind_data")
HOURS_PER_YEAR = 8760.0

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
        # print(result.table) shows every column in a plain terminal (coupling/tables.py).
        from floris_ekman_veer.coupling.tables import FullTable

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
    **optimizer_kwargs,
) -> AnnualEnergy:
    """AEP per stability class and model, baseline and with optimised yaw (module docstring).

    Args:
        fmodel: FlorisModel or ParFlorisModel with the farm (and, for ``"ekman_veer"``, the
            ekman_veer wake models); its conditions and atmosphere are replaced per class.
        wind_data: FLORIS ``WindRose`` or ``TimeSeries``.
        stability: Stability classes (see :func:`stability_classes`).
        optimizer_class: A FLORIS yaw optimiser class for the steered AEP, or None (baseline
            only).
        records: With a TimeSeries, the class of every record.
        models: ``"ekman_veer"`` (``fmodel`` itself) and/or keys of ``BUILTIN_WAKES``.
        turbulence_intensities: ``"atmosphere"`` (I_u(z_h) of each class's atmosphere) or
            ``"wind_data"``.
        progress: tqdm bars (None: when more than one optimiser run).
        **optimizer_kwargs: Options of ``optimizer_class`` (checked before any run).
    """
    classes = stability_classes(stability, wind_data, records)
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
    directions, speeds, wind_ti, heterogeneous = wind_data.unpack_for_reinitialize()
    if heterogeneous is not None:
        raise ValueError("annual energy: wind data with a heterogeneous inflow map is not "
                         "supported (the Ekman profile is the inflow)")
    if optimizer_class is not None:
        check_optimizer_options(optimizer_class, optimizer_kwargs, len(directions),
                                fmodel.core.farm.n_turbines)
    elif optimizer_kwargs:
        raise ValueError(f"annual energy: optimiser options {sorted(optimizer_kwargs)} given "
                         "without an optimizer_class")

    from tqdm.auto import tqdm

    cases = [(model, c) for model in models for c in classes]
    rows, optima, inflow = [], {}, {}
    with tqdm(cases, desc="annual energy", unit="case",
              disable=not (progress if progress is not None else optimizer_class is not None)
              ) as bar:
        for model, c in bar:
            bar.set_postfix_str(f"{model}, {c.name}")
            index = np.flatnonzero(c.condition_frequencies > 0.0)
            row = dict(model=model, stability=c.name, frequency=c.frequency,
                       n_conditions=index.size, aep_baseline_gwh=0.0,
                       aep_steered_gwh=0.0 if optimizer_class is not None else np.nan)
            if index.size:
                case = _class_model(fmodel, model, c.atmosphere, directions[index],
                                    speeds[index], wind_ti[index], turbulence_intensities)
                flow_field = case.core.flow_field
                inflow[model, c.name] = {
                    "turbulence_intensities": flow_field.turbulence_intensities.copy(),
                    "wind_veer": float(flow_field.wind_veer),
                    "wind_shear": float(flow_field.wind_shear),
                }
                freq = c.condition_frequencies[index]
                case.run()
                row["aep_baseline_gwh"] = case.get_farm_AEP(freq=freq) / 1e9
                if optimizer_class is not None:
                    df_opt = optimize_yaw(case, optimizer_class, progress=progress,
                                          **optimizer_kwargs)
                    case.set(yaw_angles=np.vstack(df_opt["yaw_angles_opt"]))
                    case.run()
                    row["aep_steered_gwh"] = case.get_farm_AEP(freq=freq) / 1e9
                    optima[model, c.name] = df_opt
            rows.append(row)
    table = pd.DataFrame(rows)
    year = table.groupby("model", sort=False)[
        ["frequency", "n_conditions", "aep_baseline_gwh", "aep_steered_gwh"]
    ].sum(min_count=1).reset_index()
    year.insert(1, "stability", "all")
    table = pd.concat([table, year], ignore_index=True)
    table["gain_percent"] = 100.0 * (table["aep_steered_gwh"] / table["aep_baseline_gwh"] - 1.0)
    return AnnualEnergy(table=table[list(COLUMNS)], optima=optima, inflow=inflow)


def _class_model(fmodel, model: str, atmosphere: dict, directions, speeds, wind_ti,
                 turbulence_intensities: str):
    """``model`` (ekman_veer = ``fmodel``, or a built-in) on these conditions and atmosphere."""
    case = fmodel.copy() if model == MODEL_NAME else builtin_model(fmodel, model)
    set_atmosphere(case, atmosphere, wind_directions=directions, wind_speeds=speeds,
                   turbulence_intensities=wind_ti)
    if turbulence_intensities == "atmosphere":
        fair = fair_builtin_set_kwargs(case)
        if model != MODEL_NAME:  # only FLORIS's built-ins read wind_veer and wind_shear
            case.set(turbulence_intensities=fair["turbulence_intensities"],
                     wind_veer=fair["wind_veer"], wind_shear=fair["wind_shear"])
        else:
            case.set(turbulence_intensities=fair["turbulence_intensities"])
    return case
