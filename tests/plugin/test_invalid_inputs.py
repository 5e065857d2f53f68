"""Every invalid wake-model, turbine, layout, condition and operation input is refused with a
ValueError naming the input's path and the offending value (docs/coupling.md#input-validation).

Each row: how the (otherwise valid) 2-turbine ``ekman_veer`` input is spoiled, and the fragments
the message must contain. Build-time rows fail in ``FlorisModel(...)``; operation rows (yaw, sample
points) fail when FLORIS solves, before any wake is evaluated.
"""

from __future__ import annotations

import copy
import math
import re

import numpy as np
import pytest
from floris import FlorisModel
from floris.utilities import load_yaml

import floris_ekman_veer  # noqa: F401  (registers the models)
from floris_ekman_veer.plugin.rotor.turbine import actuator_disk_turbine
from tests.conftest import STABLE_ATMOSPHERE

VELOCITY = "wake.wake_velocity_parameters.ekman_veer"
DEFLECTION = "wake.wake_deflection_parameters.ekman_veer"
M3 = "wake.wake_velocity_parameters.bastankhah2014"
DISK = "farm.turbine_type[0].power_thrust_table"


def base_config() -> dict:
    config = load_yaml("inputs/farm_sbl6.yaml")
    config["farm"].update(layout_x=[0.0, 882.0], layout_y=[0.0, 0.0])
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"] = dict(
        STABLE_ATMOSPHERE
    )
    config["flow_field"].update(
        wind_speeds=[8.0, 9.0], wind_directions=[270.0, 275.0], turbulence_intensities=[0.06] * 2
    )
    return config


def velocity(key, value):
    return lambda c: c["wake"]["wake_velocity_parameters"]["ekman_veer"].__setitem__(key, value)


def deflection(key, value):
    return lambda c: c["wake"]["wake_deflection_parameters"]["ekman_veer"].__setitem__(key, value)


def m3(key, value):
    def spoil(c):
        c["wake"]["model_strings"]["velocity_model"] = "bastankhah2014"
        c["wake"]["wake_velocity_parameters"]["bastankhah2014"] = {key: value}
    return spoil


def block(kind, value):
    return lambda c: c["wake"][kind].__setitem__("ekman_veer", value)


def flow(key, value):
    return lambda c: c["flow_field"].__setitem__(key, value)


def layout(x, y):
    return lambda c: c["farm"].update(layout_x=x, layout_y=y)


def nrel_5mw(**changes):
    import floris

    def spoil(c):
        path = f"{floris.__path__[0]}/turbine_library/nrel_5MW.yaml"
        c["farm"]["turbine_type"] = [{**load_yaml(path), **changes}]
    return spoil


def disk(**table):
    def spoil(c):
        turbine = actuator_disk_turbine()
        turbine["power_thrust_table"].update(table)
        c["farm"]["turbine_type"] = [turbine]
        c["flow_field"]["reference_wind_height"] = 100.0
    return spoil


def disk_diameter(diameter):
    def spoil(c):
        turbine = actuator_disk_turbine()
        turbine["rotor_diameter"] = diameter
        c["farm"]["turbine_type"] = [turbine]
    return spoil


# (id, spoil, message fragments)
BUILD_CASES = [
    ("curl string false", velocity("curl", "false"), [f"{VELOCITY}.curl", "'false'", "boolean"]),
    ("curl string true", velocity("curl", "true"), [f"{VELOCITY}.curl", "'true'", "boolean"]),
    ("curl integer", velocity("curl", 0), [f"{VELOCITY}.curl", "0 (int)", "boolean"]),
    ("veer string no", deflection("veer", "no"), [f"{DEFLECTION}.veer", "'no'", "boolean"]),
    ("yaw_deflection string", deflection("yaw_deflection", "off"),
     [f"{DEFLECTION}.yaw_deflection", "'off'", "boolean"]),
    ("ground_image string", deflection("ground_image", "yes"),
     [f"{DEFLECTION}.ground_image", "'yes'", "boolean"]),
    ("A1 string", velocity("A1", "1.25"), [f"{VELOCITY}.A1", "'1.25'", "number", "> 0"]),
    ("A1 boolean", velocity("A1", True), [f"{VELOCITY}.A1", "True", "number"]),
    ("A1 NaN", velocity("A1", math.nan), [f"{VELOCITY}.A1", "nan", "> 0"]),
    ("A1 negative", velocity("A1", -1.25), [f"{VELOCITY}.A1", "-1.25", "> 0"]),
    ("B1 negative", velocity("B1", -0.6), [f"{VELOCITY}.B1", "-0.6", ">= 0"]),
    ("alpha_prime negative", velocity("alpha_prime", -0.33),
     [f"{VELOCITY}.alpha_prime", "-0.33", "> 0"]),
    ("alpha_prime NaN", velocity("alpha_prime", math.nan), [f"{VELOCITY}.alpha_prime", "nan"]),
    ("k_w_floor negative", velocity("k_w_floor", -0.02), [f"{VELOCITY}.k_w_floor", "-0.02", "> 0"]),
    ("k_w_floor zero", velocity("k_w_floor", 0.0), [f"{VELOCITY}.k_w_floor", "0.0", "> 0"]),
    ("k_w_exponent zero", velocity("k_w_exponent", 0), [f"{VELOCITY}.k_w_exponent", "0.0", ">= 1"]),
    ("k_w_exponent below 1", velocity("k_w_exponent", 0.5),
     [f"{VELOCITY}.k_w_exponent", "0.5", ">= 1"]),
    ("k_w_exponent infinite", velocity("k_w_exponent", math.inf),
     [f"{VELOCITY}.k_w_exponent", "inf", "finite"]),
    ("max_thrust_coefficient string", velocity("max_thrust_coefficient", "0.9"),
     [f"{VELOCITY}.max_thrust_coefficient", "'0.9'", "in (0, 1)"]),
    ("max_thrust_coefficient 1", velocity("max_thrust_coefficient", 1.0),
     [f"{VELOCITY}.max_thrust_coefficient", "1.0", "in (0, 1)"]),
    ("deflection max_thrust_coefficient", deflection("max_thrust_coefficient", 1.5),
     [f"{DEFLECTION}.max_thrust_coefficient", "1.5", "in (0, 1)"]),
    ("wake_expansion unknown", velocity("wake_expansion", "local"),
     [f"{VELOCITY}.wake_expansion", "'local'", "'ambient'", "'local_turbulence'"]),
    ("polar_angle_centre unknown", velocity("polar_angle_centre", "centre"),
     [f"{VELOCITY}.polar_angle_centre", "'centre'", "'wake_centre'"]),
    ("k_star negative", m3("k_star", -0.03), [f"{M3}.k_star", "-0.03", "> 0"]),
    ("k_star string", m3("k_star", "0.03"), [f"{M3}.k_star", "'0.03'", "number"]),
    ("velocity block a string", block("wake_velocity_parameters", "on"),
     [VELOCITY, "'on'", "mapping"]),
    ("deflection block a string", block("wake_deflection_parameters", "on"),
     [DEFLECTION, "'on'", "mapping"]),
    ("velocity block unknown key", velocity("kw", 0.03), [VELOCITY, "unknown key(s) ['kw']"]),
    ("deflection block unknown key", deflection("vear", False),
     [DEFLECTION, "unknown key(s) ['vear']"]),
    ("turbulence intensity negative", flow("turbulence_intensities", [0.06, -0.1]),
     ["flow_field.turbulence_intensities", "-0.1 at condition 1", ">= 0"]),
    ("turbulence intensity NaN", flow("turbulence_intensities", [math.nan, 0.06]),
     ["flow_field.turbulence_intensities", "nan at condition 0", "finite"]),
    ("wind direction NaN", flow("wind_directions", [270.0, math.nan]),
     ["flow_field.wind_directions", "nan at condition 1", "finite"]),
    ("wind speed NaN", flow("wind_speeds", [math.nan, 9.0]),
     ["flow_field.wind_speeds", "nan at condition 0", "finite"]),
    ("empty layout", layout([], []), ["farm.layout_x", "at least one turbine"]),
    ("layout NaN", layout([0.0, math.nan], [0.0, 0.0]),
     ["farm.layout_x", "nan at turbine 1", "finite"]),
    ("coincident turbines", layout([0.0, 0.0], [0.0, 0.0]),
     ["farm.layout_x", "turbines 0 and 1", "0 m apart", "cannot stand in one place"]),
    # (intersecting rotors run, with a warning: tests/test_user_inputs_and_warnings.py)
    ("reference height negative", flow("reference_wind_height", -5.0),
     ["flow_field.reference_wind_height", "> 0 m", "or -1", "got -5.0"]),
    ("reference height zero", flow("reference_wind_height", 0.0),
     ["flow_field.reference_wind_height", "> 0 m", "got 0.0"]),
    ("rotor below the ground", nrel_5mw(hub_height=50.0),
     ["farm.turbine_type[0].hub_height", ">= rotor_diameter / 2 = 62.94 m", "got 50 m at turbine 0",
      "12.94 m below the ground"]),
    ("ct_prime beyond momentum theory", disk(ct_prime=40.0),
     [f"{DISK}.ct_prime", "40.0", "in (0, 4]"]),
    ("ct_prime zero", disk(ct_prime=0.0), [f"{DISK}.ct_prime", "0.0", "in (0, 4]"]),
    ("ct_prime string", disk(ct_prime="1.33"), [f"{DISK}.ct_prime", "'1.33'", "number"]),
    ("ct_prime boolean", disk(ct_prime=True), [f"{DISK}.ct_prime", "True", "number"]),
    ("disk air density negative", disk(ref_air_density=-1.225),
     [f"{DISK}.ref_air_density", "-1.225", "> 0"]),
    ("disk tilt", disk(ref_tilt=5.0), [f"{DISK}.ref_tilt", "5.0", "no tilt"]),
    ("disk diameter mismatch", disk_diameter(120.0),
     [f"{DISK}.rotor_diameter", "farm.turbine_type[0].rotor_diameter", "120"]),
]


@pytest.mark.parametrize(
    "spoil, fragments", [c[1:] for c in BUILD_CASES], ids=[c[0] for c in BUILD_CASES]
)
def test_invalid_input_is_refused_at_build(spoil, fragments):
    config = base_config()
    spoil(config)
    with pytest.raises(ValueError) as info:
        FlorisModel(config)
    for fragment in fragments:
        assert fragment in str(info.value)


def test_the_valid_base_input_builds_and_runs():
    """The rows above spoil one value each of an input that is itself valid."""
    fmodel = FlorisModel(base_config())
    fmodel.run()
    assert np.all(np.isfinite(fmodel.get_turbine_powers()))


@pytest.mark.filterwarnings("ignore:.*max_thrust_coefficient:RuntimeWarning")
@pytest.mark.parametrize("ct_prime", [1e-3, 4.0])
def test_ct_prime_at_the_ends_of_its_range_builds(ct_prime):
    """C_T' = 4 (a = 1/2) is accepted; its wake is evaluated at max_thrust_coefficient."""
    config = base_config()
    config["farm"]["turbine_type"] = [actuator_disk_turbine(ct_prime=ct_prime)]
    config["flow_field"]["reference_wind_height"] = 100.0
    fmodel = FlorisModel(config)
    fmodel.run()
    assert np.all(np.isfinite(fmodel.get_turbine_powers()))


def test_set_revalidates():
    """set() rebuilds the Core, so it is checked again."""
    fmodel = FlorisModel(base_config())
    with pytest.raises(ValueError, match=r"flow_field\.turbulence_intensities.*-0\.2 at condition 0"):
        fmodel.set(turbulence_intensities=[-0.2, 0.06])


@pytest.mark.parametrize(
    "yaw, fragments",
    [
        (-90.0, ["yaw_angles", "-90 at condition 0, turbine 1", "(-90, 90) degrees"]),
        (95.0, ["yaw_angles", "95 at condition 0, turbine 1"]),
        (math.nan, ["yaw_angles", "nan at condition 0, turbine 1", "finite"]),
    ],
)
def test_invalid_yaw_is_refused_before_solving(yaw, fragments):
    fmodel = FlorisModel(base_config())
    fmodel.set(yaw_angles=np.array([[0.0, yaw], [0.0, 0.0]]))
    for solve in (fmodel.run, lambda: fmodel.sample_flow_at_points([500.0], [0.0], [90.0])):
        with pytest.raises(ValueError) as info:
            solve()
        for fragment in fragments:
            assert fragment in str(info.value)


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_nan_sample_point_is_refused(axis):
    fmodel = FlorisModel(base_config())
    points = {"x": [500.0, 600.0], "y": [0.0, 10.0], "z": [90.0, 90.0]}
    points[axis] = [points[axis][0], math.nan]
    with pytest.raises(ValueError, match=re.escape(f"sample_flow_at_points {axis} must be finite")
                       + ".*nan at point 1"):
        fmodel.sample_flow_at_points(**points)


def test_plain_floris_inputs_are_left_to_floris():
    """Without the package's atmosphere, models or turbines, FLORIS's own behaviour is kept
    (here: FLORIS accepts a negative turbulence intensity for its gauss model)."""
    config = FlorisModel.get_defaults()
    config["flow_field"].update(
        wind_speeds=[8.0], wind_directions=[270.0], turbulence_intensities=[-0.1]
    )
    fmodel = FlorisModel(copy.deepcopy(config))
    fmodel.run()
    assert np.all(np.isfinite(fmodel.get_turbine_powers()))
