"""A fitted record set's energy by calendar month as a typical year (studies/energy/energy.py
``energy_by_month``, docs/measurements.md#the-site-report): January to December, each month the
mean power of the years present averaged over those years, with its data coverage."""

import numpy as np
import pandas as pd
import pytest

from floris_ekman_veer.studies.energy.energy import energy_by_month
from floris_ekman_veer.studies.energy.energy_results import AnnualEnergy


def energy_of(times, power):
    conditions = pd.DataFrame({"stability": "all", "frequency": 1.0 / len(times),
                               "farm_power_baseline": power, "farm_power_steered": np.nan})
    return AnnualEnergy(table=pd.DataFrame(), optima={}, inflow={}, conditions={"m": conditions})


def test_two_years_with_a_gap_give_one_typical_january():
    # January 2017 complete at 1 MW, January 2018 half logged at 3 MW, one March at 2 MW.
    times = pd.DatetimeIndex(list(pd.date_range("2017-01-01", periods=744, freq="h"))
                             + list(pd.date_range("2018-01-01", periods=372, freq="h"))
                             + list(pd.date_range("2018-03-01", periods=744, freq="h")))
    power = np.r_[np.full(744, 1e6), np.full(372, 3e6), np.full(744, 2e6)]
    table = energy_by_month(energy_of(times, power), times).set_index("month")
    assert list(table.index) == list(range(1, 13))
    # The years' mean powers averaged (2 MW), not the records' (1.67 MW): the half-logged
    # January counts as much as the full one; times January's 744 hours.
    assert table.loc[1, "aep_baseline_gwh"] == pytest.approx(2e6 * 744 / 1e9, rel=1e-12)
    assert table.loc[1, "years"] == 2 and table.loc[1, "coverage"] == pytest.approx(0.75)
    assert table.loc[3, "aep_baseline_gwh"] == pytest.approx(2e6 * 744 / 1e9, rel=1e-12)
    assert table.loc[3, "coverage"] == pytest.approx(1.0)
    # Months without a record: no energy, no years, no coverage (not a weak month).
    empty = table.drop(index=[1, 3])
    assert empty["aep_baseline_gwh"].isna().all() and (empty["years"] == 0).all()
    assert (empty["coverage"] == 0).all()
    assert table["aep_steered_gwh"].isna().all()


def test_a_full_year_sums_to_its_annual_energy():
    times = pd.date_range("2021-01-01", "2021-12-31 23:00", freq="h")
    power = 1e6 * (2.0 + np.sin(2 * np.pi * np.arange(times.size) / 500.0))
    table = energy_by_month(energy_of(times, power), times)
    assert np.allclose(table["coverage"], 1.0)
    # Each month its own hours (February 28.25 days in a typical year; 28 in 2021): the
    # twelve months' energy is the year's mean power times 8766 h within February's quarter day.
    by_hours = sum(power[times.month == m].mean() * 24 * times[times.month == m].day.max()
                   for m in range(1, 13)) / 1e9
    february = power[times.month == 2].mean() * 6 / 1e9
    assert table["aep_baseline_gwh"].sum() == pytest.approx(by_hours + february, rel=1e-12)
