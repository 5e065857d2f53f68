"""Boundary layers shallower than the rotor (docs/atmosphere.md#shallow-boundary-layer).

Every physically valid condition runs: the variance law is continued above h to its zero at
h exp(B1/A1), so the wake expansion falls continuously to its floor; the conditions are counted
in a ShallowBoundaryLayerWarning at the model's run, or refused when it is built with
``wake_velocity_parameters.ekman_veer.shallow_boundary_layer: raise``.
"""

import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel, WindRose
from floris.utilities import load_yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from floris_ekman_veer.atmosphere import turbulence as tb
from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning

pytestmark = pytest.mark.usefixtures("inflow_hook")

INPUTS = Path(__file__).resolve().parents[2] / "inputs"
HUB, RADIUS = 90.0, 0.5 * 125.88  # NREL 5 MW of inputs/farm_sbl6.yaml


def farm_config(**farm):
    config = load_yaml(str(INPUTS / "farm_sbl6.yaml"))
    config["farm"].update(farm)
    return config


def atmosphere(config):
    return config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]


def boundary_layer_height(speed, config):
    return float(EkmanABL.from_reference_wind(speed, HUB, **atmosphere(config)).boundary_layer_height)


def test_wind_rose_3_to_19_ms_runs_with_finite_powers_and_counts_shallow_conditions():
    # (to 19 m/s: the limit of farm_sbl6's -1 K/h from 21 m/s is tests/plugin/inflow/test_wind_roses.py's)
    config = farm_config()
    speeds, directions = np.arange(3.0, 20.0), np.arange(0.0, 360.0, 5.0)
    fmodel = FlorisModel(config)  # 9 m/s: h = 86 m, below the hub (said at a run)
    fmodel.set(wind_data=WindRose(wind_directions=directions, wind_speeds=speeds,
                                  ti_table=0.06))
    with pytest.warns(ShallowBoundaryLayerWarning) as caught, warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # heavy loading below 4 m/s (README)
        fmodel.run()
    powers = fmodel.get_turbine_powers()
    assert powers.shape == (len(directions), len(speeds), 9)
    assert np.all(np.isfinite(powers)) and np.all(powers >= 0.0)
    assert np.all(powers.max(axis=2)[:, 1:-1] > 0.0)  # every turbine above cut-in, below cut-out
    # The count, against h solved here for each speed (every direction shares it).
    h = np.array([boundary_layer_height(s, config) for s in speeds])
    shallow, hub_above = np.sum(h < HUB + RADIUS), np.sum(h <= HUB)
    assert 0 < hub_above < shallow < len(speeds)
    message = str([w for w in caught if issubclass(w.category, ShallowBoundaryLayerWarning)][-1].message)
    assert shallow == 10 and hub_above == 7  # 3-12 m/s below the rotor top, 3-9 m/s the hub
    assert message.startswith(
        f"{shallow * len(directions)} of {len(speeds) * len(directions)} conditions (wind "
        f"speeds 3 to 12 m/s (10 distinct) at 90 m; h = {h.min():.4g} to "
        f"{h[shallow - 1]:.4g} m) have a boundary layer shallower than the rotor top")
    assert f"{hub_above * len(directions)} of them with h at or below the hub" in message


def test_strict_mode_names_condition_speed_h_and_hub_height_at_build():
    config = farm_config()
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["shallow_boundary_layer"] = "raise"
    config["flow_field"]["wind_speeds"] = [15.0]  # h = 344 m above the rotor top, 152.94 m
    fmodel = FlorisModel(config)
    speeds = [15.0, 4.0, 19.0]
    with pytest.raises(ValueError) as error:
        fmodel.set(wind_speeds=speeds, wind_directions=[270.0] * 3,
                   turbulence_intensities=[0.06] * 3)
    h = boundary_layer_height(4.0, config)
    expected = (f"condition 1: wind speed 4 m/s at 90 m, h = {h:.4g} m, hub height 90 m "
                f"(rotor top 152.94 m)")
    assert "1 of 3 conditions" in str(error.value) and expected in str(error.value)
    assert "shallow_boundary_layer = 'raise'" in str(error.value)
    # conditions with the whole rotor inside the boundary layer build and run
    fmodel.set(wind_speeds=[15.0, 19.0], wind_directions=[270.0] * 2,
               turbulence_intensities=[0.06] * 2)
    fmodel.run()
    assert np.all(np.isfinite(fmodel.get_turbine_powers()))


def test_strict_mode_indexes_per_condition_atmospheres():
    config = farm_config(layout_x=[0.0], layout_y=[0.0])
    atm = atmosphere(config)
    atm["cooling_rate"] = [0.0, -1.0, 0.0]  # a night between two neutral days, all at 8 m/s
    block = config["wake"]["wake_velocity_parameters"]["ekman_veer"]
    block["shallow_boundary_layer"] = "raise"
    config["flow_field"].update(wind_speeds=[8.0] * 3, wind_directions=[270.0] * 3,
                                turbulence_intensities=[0.06] * 3)
    with pytest.raises(ValueError, match=r"1 of 3 conditions .* condition 1: wind speed 8 m/s"):
        FlorisModel(config)


def test_bad_policy_is_refused_with_its_path():
    config = farm_config()
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["shallow_boundary_layer"] = "quiet"
    with pytest.raises(ValueError, match=r"shallow_boundary_layer must be one of "
                                         r"\['warn', 'raise', 'ignore'\]; got 'quiet'"):
        FlorisModel(config)


def test_ignore_policy_counts_silently():
    config = farm_config()  # 9 m/s: h = 86 m, below the hub
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["shallow_boundary_layer"] = "ignore"
    with warnings.catch_warnings():
        warnings.simplefilter("error", ShallowBoundaryLayerWarning)
        FlorisModel(config).run()


def test_no_warning_when_every_rotor_is_inside_the_boundary_layer():
    config = load_yaml(str(INPUTS / "cnbl.yaml"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", ShallowBoundaryLayerWarning)
        FlorisModel(config).run()


# Where h crosses the hub, a reference speed lies in the profile's step at the ABL top: its
# ReferenceWindWarning (the closest state taken) is tested in tests/physics/test_convective_properties.py.
@pytest.mark.filterwarnings("ignore::floris_ekman_veer.ReferenceWindWarning")
@pytest.mark.parametrize("height", [HUB, HUB + RADIUS], ids=["hub", "rotor_top"])
def test_farm_power_is_continuous_where_h_crosses_the_rotor(height):
    """Power just below and just above the wind speed at which h equals the hub height (or
    the rotor top): the change is that of a 2e-9 relative speed change, not a jump."""
    config = farm_config(layout_x=[0.0, 882.0, 1764.0], layout_y=[0.0] * 3)
    # Table 1's SBL-6 mu fixed: with the input's cooling rate the speed at 90 m steps past the
    # crossing of h with 90 m itself (docs/atmosphere.md#lateral-velocity-near-the-abl-top:
    # within 1e-9 of it no ABL has that speed), which this 1e-9 bracket would straddle.
    atmosphere(config).pop("cooling_rate")
    atmosphere(config)["stability_parameter"] = 148.49
    crossing = brentq(lambda s: boundary_layer_height(s, config) - height, 3.0, 15.0,
                      xtol=1e-12)
    speeds = crossing * (1.0 + np.array([-1e-9, 1e-9]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        fmodel = FlorisModel(config)
        fmodel.set(wind_speeds=speeds, wind_directions=[270.0] * 2,
                   turbulence_intensities=[0.06] * 2)
        fmodel.run()
    powers = fmodel.get_turbine_powers()
    assert np.all(np.isfinite(powers))
    # wake losses (downstream / front) change by far less than a k_w step of 1e-4 would give
    ratio = powers[:, 1:] / powers[:, :1]
    np.testing.assert_allclose(ratio[1], ratio[0], rtol=1e-7)
    np.testing.assert_allclose(powers[1], powers[0], rtol=1e-7)


def test_wake_expansion_is_continuous_and_reaches_the_floor():
    u_star, h, speed = 0.2, 100.0, 6.0
    z_t = h * math.exp(0.6 / 1.25)
    k = lambda z: float(tb.wake_expansion_rate(u_star, h, z, speed))  # noqa: E731
    inside = (0.021**6 + (0.33 * math.sqrt(0.6) * u_star / speed) ** 6) ** (1 / 6)
    assert k(h * (1 - 1e-13)) == pytest.approx(inside, rel=1e-12)
    assert k(h) == pytest.approx(inside, rel=1e-12)
    assert k(z_t * (1 - 1e-12)) == pytest.approx(0.021, rel=1e-12)
    assert k(z_t) == pytest.approx(0.021, rel=1e-15) and k(3 * h) == pytest.approx(0.021, rel=1e-15)


@settings(max_examples=300, deadline=None)
@given(u_star=st.floats(0.01, 2.0), h=st.floats(20.0, 3000.0), ratio=st.floats(0.01, 4.0),
       speed=st.floats(1.0, 40.0))
def test_property_wake_expansion_finite_monotone_and_continuous(u_star, h, ratio, speed):
    z = ratio * h
    k, k_up = (float(tb.wake_expansion_rate(u_star, h, zz, speed)) for zz in (z, z * (1 + 1e-9)))
    assert math.isfinite(k) and k >= 0.021 * (1 - 1e-15)
    assert k_up <= k * (1 + 1e-15)  # less turbulence higher up
    # continuous: a 1e-9 step in z moves k_w by at most what the sqrt at the variance's zero
    # allows (sqrt(A1 1e-9) alpha' u*/U, far below any jump)
    assert k - k_up <= 0.33 * math.sqrt(1.25 * 2e-9) * u_star / speed + 1e-15
