"""The results of an annual-energy study (:func:`~floris_ekman_veer.annual_energy`): the energy
per model and stability class, baseline and steered, as FLORIS's ``get_farm_AEP`` computes it
from each condition's farm power and frequency, with the optimal yaws, the inflow each model was
given, the farm power per condition, and a bar chart.
"""

from __future__ import annotations

import attrs
import numpy as np
import pandas as pd

HOURS_PER_YEAR = 8760.0

COLUMNS = ("model", "stability", "frequency", "n_conditions", "aep_baseline_gwh",
           "aep_steered_gwh", "gain_percent")


@attrs.frozen
class AnnualEnergy:
    """Result of :func:`~floris_ekman_veer.annual_energy`.

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
    #: A fitted record set's typical year per calendar month (``SiteAtmosphere.annual_energy``):
    #: one row per model and month (1-12), the years holding it, its data ``coverage``, and the
    #: columns of ``table`` (``energy.energy_by_month``); else None.
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


def energy_table(per_model: dict, names, frequencies, owner, freq, wind_index,
                 steered: bool) -> AnnualEnergy:
    """The :class:`AnnualEnergy` of a study from its farm powers per condition.

    Args:
        per_model: ``{model: {"baseline", "steered", "optima", "turbulence_intensities",
            "wind_veer", "wind_shear"}}``, one entry (or frame row) per condition run.
        names, frequencies: The stability classes' names and frequencies.
        owner, freq, wind_index: Per condition run: its class (position in ``names``), its
            joint frequency and its index in the wind data.
        steered: Whether an optimiser ran (else the steered columns are NaN).
    """
    n_classes = len(names)
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
                row["aep_baseline_gwh"] = aep(freq[rows_k], result["baseline"][rows_k])
                if steered:
                    row["aep_steered_gwh"] = aep(freq[rows_k], result["steered"][rows_k])
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


def aep(freq, farm_power) -> float:
    """FLORIS's ``get_farm_AEP(freq=freq)`` [GWh] from the farm power per condition."""
    return float(np.nansum(np.multiply(freq, farm_power)) * HOURS_PER_YEAR) / 1e9

