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

A user's farm goes through the same modules (docs/validation.md#your-own-farm).

May import: the base, the physics, the plugin, FLORIS and the other studies; never the registry
or the package's top (docs/architecture.md).
"""
