"""Validation against measured wakes and farms (docs/validation.md#measured-wakes-and-farms).

A study on top of FLORIS and the package's coupling: ``cases`` reads the shipped reference data
(Horns Rev 1 and six single wakes: measured, LES, RANS), ``atmospheres`` turns a case into the
atmosphere every model runs on, ``models`` builds and runs the FLORIS models, ``metrics`` the
error tables. ``examples/validate.py`` writes the tables and figures.
"""
