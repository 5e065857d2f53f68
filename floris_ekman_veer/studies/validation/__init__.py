"""Validation against measured wakes and farms, for any farm (docs/validation.md#measured-wakes-and-farms).

A study on top of FLORIS and the package's coupling: ``cases`` describes a case (a farm from its
layout, turbine, conditions and measured references, or a single wake with its arcs) and builds
the shipped ones (Horns Rev 1, Lillgrund rows B and D, six single wakes: measured, LES, RANS),
``atmospheres`` turns a case into the atmosphere every model runs on, ``models`` builds and runs
the FLORIS models into tidy tables, ``metrics`` the error tables. ``examples/validate.py`` writes
the tables and figures; docs/validation.md#your-own-farm shows a user's farm in a few lines.
"""
