"""The shipped validation cases, built from the shipped data through the public classes
(docs/validation.md#measured-wakes-and-farms).

Horns Rev 1 and Lillgrund's rows B and D as :class:`~floris_ekman_veer.studies.validation.farm_case.FarmCase` s,
six single wakes as :class:`~floris_ekman_veer.studies.validation.single_wake.SingleWakeCase` s:
the same door a user's farm goes through (docs/validation.md#your-own-farm). The data and their
readers are ``reference_data`` (DTU PyWake's validation data, MIT licence; attribution and the
original studies in the data folder's README.md and in docs/validation.md#data-and-original-studies).
"""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.studies.validation.farm_case import FarmCase
from floris_ekman_veer.studies.validation.reference_data import (
    DATA,
    read_layout,
    read_row_measurements,
    read_table,
    read_turbine_table,
)
from floris_ekman_veer.studies.validation.references import (
    DirectionUncertainty,
    EfficiencyReference,
    RowReference,
)
from floris_ekman_veer.studies.validation.single_wake import SingleWakeCase
from floris_ekman_veer.studies.validation.turbines import turbine_from_table

SINGLE_WAKE_CASES = {
    case.name: case for case in (
        SingleWakeCase("Wieringermeer-West", 10.7, 0.63, 0.08, 80.0, 80.0, 52.8, False, (2.5, 3.5, 7.5)),
        SingleWakeCase("Wieringermeer-East", 10.9, 0.63, 0.06, 80.0, 80.0, 52.8, False, (2.5, 3.5, 7.5)),
        SingleWakeCase("Nibe", 8.5, 0.89, 0.08, 40.0, 45.0, 57.0, False, (2.5, 4.0, 7.5)),
        SingleWakeCase("Nordtank-500", 7.45, 0.70, 0.112, 41.0, 36.0, 55.7, False,
                       (1.0, 2.0, 3.0, 4.0, 5.0, 7.5)),
        SingleWakeCase("NREL-5MW_TIlow", 8.0, 0.79, 0.04, 126.0, 90.0, 55.0, True, (2.5, 5.0, 7.5)),
        SingleWakeCase("NREL-5MW_TIhigh", 8.0, 0.79, 0.128, 126.0, 90.0, 55.0, False, (2.5, 5.0, 7.5)),
    )
}


def horns_rev() -> FarmCase:
    """Horns Rev 1: 80 V80s, the wind from 270 +- 2.5 deg along rows 7 D apart, 8 m/s, hub TI
    0.056, direction uncertainty of van der Laan et al. about G2 (turbine 6); the measured
    inner-row mean with the RANS, and the LES's farm efficiency (docs/validation.md#horns-rev-1)."""
    table = read_turbine_table(DATA / "V80_power_ct.csv")
    columns = np.arange(80).reshape(10, 8)
    rans = read_table(DATA / "Hornsrev1_RANS_wd270_InnerRowMean.dat")
    les = read_table(DATA / "Hornsrev1_LES_WFeff.dat")
    return FarmCase(
        name="Hornsrev1", layout=read_layout(DATA / "Hornsrev1_layout.csv"),
        turbine=turbine_from_table("V80", 80.0, 70.0, *table.T), wind_speed=8.0, latitude=55.5,
        turbulence=0.056,
        direction_uncertainty=DirectionUncertainty(2.5, growth=0.00035, offset=2.1, reference_turbine=6),
        rows=(RowReference("inner rows", 270.0, columns[:, 1:-1],
                           read_row_measurements(DATA / "Hornsrev1_WFdata_wd270_InnerRowMean.dat"),
                           rans),),
        efficiency=EfficiencyReference(les[:, 0], les[:, 1], "LES (Zong & Porte-Agel 2020)"),
        offshore=True,
    )


#: Lillgrund's rows as the measurements name them (turbine indices of Lillgrund_layout.csv,
#: upstream first for the wind from the south-west; -1: the gap in row D).
LILLGRUND_ROWS = {"B": (14, 13, 12, 11, 10, 9, 8, 7), "D": (29, 28, 27, -1, 26, 25, 24, 23)}


def lillgrund() -> FarmCase:
    """Lillgrund: 48 SWT-2.3-93s, rows B and D for the wind from 222 deg (along the rows, 4.3 D
    apart) and 207 deg, 9 m/s, hub TI 0.048, a constant 3.3-deg direction uncertainty (the
    published comparisons'); measured and RANS (docs/validation.md#lillgrund)."""
    table = read_turbine_table(DATA / "SWT-2.3-93_power_ct.csv")
    rows = []
    for direction in (222, 207):
        for label, turbines in LILLGRUND_ROWS.items():
            stem = f"wd{direction}_Row{label}.dat"
            rows.append(RowReference(
                f"row {label}", float(direction), turbines,
                read_row_measurements(DATA / f"Lillgrund_WFdata_{stem}"),
                read_table(DATA / f"Lillgrund_RANS_{stem}")))
    return FarmCase(
        name="Lillgrund", layout=read_layout(DATA / "Lillgrund_layout.csv"),
        turbine=turbine_from_table("SWT-2.3-93", 92.6, 65.0, *table.T), wind_speed=9.0,
        latitude=55.5, turbulence=0.048, direction_uncertainty=DirectionUncertainty(3.3),
        rows=tuple(rows), offshore=True,
    )


HORNS_REV = horns_rev()
LILLGRUND = lillgrund()
#: The shipped farm cases.
FARM_CASES = {case.name: case for case in (HORNS_REV, LILLGRUND)}
