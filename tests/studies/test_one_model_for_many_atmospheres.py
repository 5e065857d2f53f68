"""Studies of many per-condition atmospheres without a FLORIS model per atmosphere: optimize_yaw's
serial refine on a row-following subset, and SiteAtmosphere.annual_energy."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

from floris_ekman_veer import optimize_yaw
from floris_ekman_veer.plugin.floris_tools import optimizer_conditions as optimization
from floris_ekman_veer.plugin.inflow.inflow import atmosphere_of, set_atmosphere

FARM = Path(__file__).resolve().parents[2] / "inputs" / "farm_sbl6.yaml"


# The stable atmospheres of these farms give, in some conditions and by design, boundary layers
# shallower than the NREL 5 MW rotor top (153 m); their ShallowBoundaryLayerWarning is not what
# is tested here (tests/physics/test_shallow_abl.py and tests/test_user_inputs_and_warnings.py are).
pytestmark = pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")


@pytest.fixture(scope="module")
def records_row():
    """A 3-turbine row with 6 conditions of 3 atmospheres (neutral, mid, SBL-6) in mixed order."""
    fmodel = FlorisModel(FARM)
    fmodel.set(layout_x=[0.0, 882.0, 1764.0], layout_y=[0.0, 0.0, 0.0])
    night = atmosphere_of(fmodel.core).sliced(slice(None))
    del night["cooling_rate"]  # the input's SBL-6 given here by mu instead, per condition
    mu = [148.49, 0.0, 50.0, 0.0, 148.49, 50.0]
    set_atmosphere(fmodel, dict(night, stability_parameter=mu),
                   wind_directions=[270.0, 266.0, 273.0, 270.0, 275.0, 268.0],
                   wind_speeds=[8.0, 9.0, 10.0, 11.0, 9.5, 7.5],
                   turbulence_intensities=[0.06] * 6)
    return fmodel


OPTIONS = dict(minimum_yaw_angle=-25.0, maximum_yaw_angle=25.0, Ny_passes=[5],
               progress=False)


@pytest.mark.parametrize("search", ["single", "both_signs"])
def test_one_run_for_every_atmosphere_equals_a_run_per_atmosphere(records_row, monkeypatch,
                                                                  search):
    built = []
    subset = optimization.condition_subset

    def counting(*args, **kwargs):
        built.append(args[1])
        return subset(*args, **kwargs)

    monkeypatch.setattr(optimization, "condition_subset", counting)
    together = optimize_yaw(records_row, YawOptimizationSR, search=search, **OPTIONS)
    runs = len(built)
    monkeypatch.setattr(optimization, "_rows_follow", lambda *args: False)
    apart = optimize_yaw(records_row, YawOptimizationSR, search=search, **OPTIONS)
    # One model per optimiser run, whatever the number of atmospheres (3 here).
    assert len(built) - runs == 3 * runs
    for column in ("farm_power_opt", "farm_power_baseline"):
        np.testing.assert_array_equal(together[column].to_numpy(), apart[column].to_numpy())
    np.testing.assert_array_equal(np.vstack(together.yaw_angles_opt),
                                  np.vstack(apart.yaw_angles_opt))
    assert np.any(np.vstack(together.yaw_angles_opt) != 0.0)  # the case steers


def test_row_following_subset_refuses_a_mismatched_set(records_row):
    subset = optimization.row_following_subset(records_row, np.arange(3))
    with pytest.raises(ValueError, match="carrying the atmospheres of 3"):
        subset.set(wind_directions=[270.0, 270.0], wind_speeds=[8.0, 9.0],
                   turbulence_intensities=[0.06, 0.06])
    # A set of its own conditions keeps each condition's atmosphere.
    subset.set(yaw_angles=np.zeros((3, 3)))
    mu = atmosphere_of(subset.core).inputs["stability_parameter"].reshape(-1)
    np.testing.assert_array_equal(mu, [148.49, 0.0, 50.0])


def test_record_energy_is_annual_energy_of_the_site_classes(records_row):
    """SiteAtmosphere.annual_energy's path (an atmosphere per record, classes by distinct
    atmosphere named by their first record) gives annual_energy's numbers with those classes."""
    from floris import TimeSeries

    from floris_ekman_veer import annual_energy
    from floris_ekman_veer.studies.energy.energy import record_energy

    flow_field = records_row.core.flow_field
    series = TimeSeries(flow_field.wind_directions, flow_field.wind_speeds,
                        turbulence_intensities=flow_field.turbulence_intensities)
    block = atmosphere_of(records_row.core).sliced(slice(None))
    labels = [f"t{i}" for i in range(6)]
    mu = block["stability_parameter"]
    first = {m: labels[mu.index(m)] for m in mu}
    classes = {first[m]: {"atmosphere": dict(block, stability_parameter=m)} for m in mu}
    by_class = annual_energy(records_row, series, classes, records=[first[m] for m in mu],
                             models=["ekman_veer", "gch"])
    by_record = record_energy(records_row, series, block, labels, models=["ekman_veer", "gch"])
    assert list(by_record.table["stability"]) == list(by_class.table["stability"])
    for column in ("frequency", "n_conditions", "aep_baseline_gwh"):
        np.testing.assert_array_equal(by_record.table[column], by_class.table[column])
