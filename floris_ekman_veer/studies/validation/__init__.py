"""Validation against measured wakes and farms, for any farm (docs/validation.md#measured-wakes-and-farms).

A study on top of FLORIS and the package's coupling. What a case is: ``farm_case`` (a farm from
its layout, turbine, conditions and references), ``references`` (measured rows, the farm
efficiency, the direction uncertainty), ``turbines`` (a FLORIS turbine from a power/C_T table),
``single_wake`` (an isolated wake and its arcs), all checked when built (``checks``). The data:
``reference_data`` (the shipped files and their readers); ``cases`` builds the shipped cases
from them (Horns Rev 1, Lillgrund rows B and D, six single wakes: measured, LES, RANS).
What runs on a case: ``atmospheres`` (the atmosphere every model runs on, the TI conversion),
``models`` (the FLORIS models run into tidy tables, with labels that carry their settings),
``metrics`` (the error tables). ``examples/validate.py`` writes the tables and figures.

The names a user's farm needs are importable from here (docs/validation.md#your-own-farm):
``FarmCase``, ``RowReference``, ``EfficiencyReference``, ``DirectionUncertainty``,
``turbine_from_table``, ``streamwise_turbulence``, ``row_ratios``, ``farm_efficiency``,
``row_errors``, ``efficiency_errors``, ``model_label`` and ``WAKE_MODELS``.

May import: the base, the physics, the plugin, FLORIS and the other studies; never the registry
or the package's top (docs/architecture.md).
"""

from floris_ekman_veer.studies.validation.atmospheres import streamwise_turbulence
from floris_ekman_veer.studies.validation.farm_case import FarmCase
from floris_ekman_veer.studies.validation.metrics import efficiency_errors, row_errors
from floris_ekman_veer.studies.validation.models import (
    WAKE_MODELS,
    farm_efficiency,
    model_label,
    row_ratios,
)
from floris_ekman_veer.studies.validation.references import (
    DirectionUncertainty,
    EfficiencyReference,
    RowReference,
)
from floris_ekman_veer.studies.validation.turbines import turbine_from_table

__all__ = ["WAKE_MODELS", "DirectionUncertainty", "EfficiencyReference", "FarmCase",
           "RowReference", "efficiency_errors", "farm_efficiency", "model_label", "row_errors",
           "row_ratios", "streamwise_turbulence", "turbine_from_table"]
