"""Every shipped input through FLORIS's own AEP workflow: a wind rose (and a time series) from 0
to 360 deg and from cut-in to cut-out (docs/atmosphere.md#a-fixed-stability-across-wind-speeds).

The shipped night (inputs/farm_night.yaml, the paper's SBL-3 cooling rate -0.25 K/h) stays inside
the physical domain at every speed with no policy. The paper's SBL-6 cooling rate, -1 K/h
(inputs/farm_sbl6.yaml, inputs/sbl6.yaml), implies a surface heat flux beyond -300 W/m^2 at the
strongest winds; their atmosphere blocks say ``outside_domain: limit``, which carries those
conditions with their stability limited toward neutral to the bound, named in validity_report's
``stability_limited``. A fixed Obukhov length (L = 100 m, farm_night's until issue 39) leaves the
domain from 20 m/s: without the policy the model refuses those conditions naming every speed and
what to give.
"""

from __future__ import annotations

import contextlib
import copy
import warnings

import numpy as np
import pytest
from floris import FlorisModel, TimeSeries, WindRose
from floris.utilities import load_yaml

import floris_ekman_veer
from floris_ekman_veer.atmosphere.inputs.input_ranges import SENSIBLE_HEAT_FLUX_RANGE

#: The FLORIS inputs the package ships (not its turbines or data files).
SHIPPED = [name for name in floris_ekman_veer.example_inputs()
           if not name.startswith(("turbines/", "site/"))]
#: Cut-in to cut-out of the NREL 5 MW (and beyond the actuator disk's 15 m/s), every 1 m/s.
SPEEDS = np.arange(3.0, 25.01, 1.0)
DIRECTIONS = np.arange(0.0, 360.0, 5.0)
#: What a rose over every speed may say: the placeholder TI, the stock NREL 5 MW's own C_T above
#: momentum theory at 3-4 m/s, and boundary layers shallower than the rotor at light winds.
EXPECTED = (floris_ekman_veer.ModelSettingsWarning, floris_ekman_veer.ThrustLimitWarning,
            floris_ekman_veer.ShallowBoundaryLayerWarning)
#: The speeds each input carries at the heat-flux bound (H < -300 W/m^2 at the given stability).
LIMITED_FROM = {"farm_sbl6": 21.0, "sbl6": 22.0}


@contextlib.contextmanager
def only_expected_warnings():
    """Record the warnings of the block and assert that each is one of EXPECTED."""
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        yield
    unexpected = [str(w.message) for w in record if not issubclass(w.category, EXPECTED)]
    assert not unexpected


def run_quietly(fmodel, **set_kwargs):
    """set() and run(), asserting that only the expected warnings are said."""
    with only_expected_warnings():
        fmodel.set(**set_kwargs)
        fmodel.run()


def test_the_shipped_inputs_are_all_walked():
    assert {"cnbl", "farm_day", "farm_night", "farm_sbl6", "sbl1", "sbl6"} <= set(SHIPPED)


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_input_runs_floris_aep_over_every_direction_and_speed(name):
    """get_farm_AEP on a 0-360 deg x 3-25 m/s WindRose: finite, below the farm's wake-free
    AEP, above half of it; every condition has a boundary layer (none at rest); the inputs
    with a fixed stability carry exactly their strong-wind conditions at the heat-flux bound."""
    rose = WindRose(wind_directions=DIRECTIONS, wind_speeds=SPEEDS, ti_table=0.06)
    fmodel = FlorisModel(floris_ekman_veer.example_input(name))
    with only_expected_warnings():
        fmodel.set(wind_data=rose)
        fmodel.run()
        aep = fmodel.get_farm_AEP()
        power = fmodel.get_farm_power()
        fmodel.run_no_wake()
        free = fmodel.get_farm_AEP()
        report = floris_ekman_veer.validity_report(fmodel)
    assert np.all(np.isfinite(power)) and np.all(power >= 0.0)
    assert 0.5 * free < aep <= free * (1.0 + 1e-12)
    assert not report.at_rest.any()
    assert np.all(report.sensible_heat_flux >= SENSIBLE_HEAT_FLUX_RANGE[0])
    limited = report.stability_limited.to_numpy()
    np.testing.assert_array_equal(limited, report.wind_speed >= LIMITED_FROM.get(name, np.inf))
    # At the bound (within the margin LIMIT_MARGIN), L growing with the wind (L ~ u*^3 / H).
    np.testing.assert_allclose(report.sensible_heat_flux[limited], SENSIBLE_HEAT_FLUX_RANGE[0],
                               rtol=1e-6)
    by_speed = report[limited].groupby("wind_speed").obukhov_length.first().to_numpy()
    assert np.all(np.diff(by_speed) > 0)


@pytest.mark.parametrize("name", ["farm_night", "farm_sbl6", "farm_day"])
def test_a_time_series_runs_every_speed_and_direction(name):
    """A TimeSeries of the same conditions gives the rose's powers, condition by condition."""
    directions, speeds = (a.ravel() for a in np.meshgrid(DIRECTIONS[::6], SPEEDS))
    series = TimeSeries(wind_directions=directions, wind_speeds=speeds,
                        turbulence_intensities=0.06)
    fmodel = FlorisModel(floris_ekman_veer.example_input(name))
    run_quietly(fmodel, wind_data=series)
    rose = FlorisModel(floris_ekman_veer.example_input(name))
    run_quietly(rose, wind_directions=directions, wind_speeds=speeds,
                turbulence_intensities=np.full(speeds.size, 0.06))
    np.testing.assert_array_equal(fmodel.get_farm_power(), rose.get_farm_power())
    assert np.all(np.isfinite(fmodel.get_farm_power()))
    # Every speed above cut-in produces (the NREL 5 MW's table gives 0 at 3 m/s).
    assert np.all(fmodel.get_farm_power()[speeds > 3.0] > 0.0)


def night(policy=None):
    """inputs/farm_night.yaml with a fixed Obukhov length L = 100 m instead of its cooling rate,
    and the outside_domain ``policy`` (None: the default)."""
    config = load_yaml(str(floris_ekman_veer.example_input("farm_night")))
    atmosphere = config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    del atmosphere["cooling_rate"]
    atmosphere["obukhov_length"] = 100.0
    if policy is not None:
        atmosphere["outside_domain"] = policy
    return config


@pytest.mark.parametrize("policy", [None, "refuse"])
def test_a_fixed_obukhov_length_is_refused_naming_every_speed_and_what_to_give(policy):
    fmodel = FlorisModel(night(policy))
    with pytest.raises(ValueError) as error:
        fmodel.set(wind_data=WindRose(wind_directions=np.array([270.0]), wind_speeds=SPEEDS,
                                      ti_table=0.06))
    message = str(error.value)
    assert "leaves the physical domain" in message
    assert "6 of 23 conditions leave it: wind speeds 20, 21, 22, 23, 24 and 25 m/s at 90 m" in message
    assert "sensible_heat_flux, cooling_rate" in message
    assert "wake.wake_velocity_parameters.ekman_veer.atmosphere.outside_domain: limit" in message


def test_the_limit_keeps_the_conditions_inside_bit_for_bit():
    """The conditions the limit does not touch are those of the refusing model (3-19 m/s), and
    the limited ones are continuous with them: H falls to the bound between 19 and 20 m/s."""
    speeds = np.arange(12.0, 25.01, 1.0)
    conditions = dict(wind_directions=np.full(speeds.size, 270.0), wind_speeds=speeds,
                      turbulence_intensities=np.full(speeds.size, 0.06))
    limited = FlorisModel(night("limit"))
    run_quietly(limited, **conditions)
    inside = speeds < 20.0
    refusing = FlorisModel(night("refuse"))
    run_quietly(refusing, **{k: v[inside] for k, v in conditions.items()})
    np.testing.assert_array_equal(limited.get_turbine_powers()[inside],
                                  refusing.get_turbine_powers())
    with only_expected_warnings():
        heat = floris_ekman_veer.validity_report(limited).sensible_heat_flux.to_numpy()
    assert heat[inside][-1] > SENSIBLE_HEAT_FLUX_RANGE[0] > heat[inside][-1] * 1.2


def test_the_policy_survives_set_copy_and_per_condition_lists():
    """outside_domain is part of the block: as_dict()/copy keep it, and per-condition
    atmosphere lists are limited condition by condition."""
    config = night("limit")
    atmosphere = config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    atmosphere["obukhov_length"] = [100.0, 1000.0]
    config["flow_field"].update(wind_directions=[270.0, 270.0], wind_speeds=[22.0, 22.0],
                                turbulence_intensities=[0.06, 0.06])
    fmodel = FlorisModel(config)
    run_quietly(fmodel)
    with only_expected_warnings():
        report = floris_ekman_veer.validity_report(fmodel)
    # L = 1000 m implies about -130 W/m^2 at 22 m/s: inside, untouched.
    assert report.stability_limited.tolist() == [True, False]
    assert -300.0 < report.sensible_heat_flux.iloc[1] < -50.0
    np.testing.assert_allclose(report.obukhov_length.iloc[1], 1000.0, rtol=1e-12)
    copied = fmodel.copy()
    run_quietly(copied)
    np.testing.assert_array_equal(copied.get_farm_power(), fmodel.get_farm_power())
    again = FlorisModel(copy.deepcopy(fmodel.core.as_dict()))
    run_quietly(again)
    np.testing.assert_array_equal(again.get_farm_power(), fmodel.get_farm_power())


@pytest.mark.parametrize("bad", ["clip", "neutral", 1, True])
def test_a_bad_policy_is_refused_by_name(bad):
    with pytest.raises(ValueError, match=r"wake\.wake_velocity_parameters\.ekman_veer\.atmosphere"
                                         r"\.outside_domain must be one of \['refuse', 'limit'\]"):
        FlorisModel(night(bad))
