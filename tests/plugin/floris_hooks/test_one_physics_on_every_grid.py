"""One physics on every grid (docs/coupling.md#one-physics-on-every-grid): with the defaults
(``wake_expansion: array_turbulence``, ``deficit_velocity: incoming``, ``combination_model:
fls``, ``wake_superposition: cumulative``, and with the point-wise sum ``combination_model``) the wakes of FLORIS's cubature grids, planes and sampled points take the turbine-grid
solve's rotor states (incoming speeds, array turbulence), so that they show the wakes the powers
have: a 64-point cubature grid gives the turbine grid's powers, and points sampled densely over
each rotor disk its rotor-averaged velocities.

Measured (4 NREL 5 MW 5 D apart in SBL-4 at 11 m/s, wind along the row), cubature over turbine
grid in power (per turbine; farm) and points sampled over the rotors over the turbine velocities,
before the states were handed: 0 / -0.8 / -17.3 / -29.0 %; -8.7 %, and 0 / 0.02 / -5.8 / -10.0 %;
now: 0 / -0.8 / -0.5 / -0.6 %; -0.4 %, and 0 / 0.02 / 0.02 / 0.02 %.
The cumulative wake (Bastankhah et al. 2021) evaluates its centre deficit C_n on the turbine
grid where the deflection's centre is, at the grid's point heights, interpolated to the sub-point
rows as the centre is, and the other grids at their points (veer-sheared centres differ with
height); with one rotor-mean C_n per wake and rotor, cubature over turbine grid was +2.75 % at
turbine 3 of the zig-zag row, +0.26 % with C_n at each of the 24 rows, now +0.23 % (zig-zag
-0.005 / -0.61 / +0.23 / -0.26 %, aligned -0.005 / -0.83 / -0.26 / +0.007 %; at the rows:
-0.005 / -0.61 / +0.26 / -0.05 % and -0.005 / -0.83 / -0.06 / +0.37 %).
"""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest
from floris import FlorisModel
from floris.core.rotor_velocity import average_velocity
from floris.utilities import load_yaml
from tests.plugin.rotor.multiwake_reference import equal_area_disk

import floris_ekman_veer
from floris_ekman_veer.plugin.floris_hooks.solver import hands_turbine_states

D, HUB = 126.0, 90.0
#: The paper's SBL-4 forcing (Table 1: C_r = -0.375 K/h, f_c = 1e-4 1/s, z0 = 0.1 m).
SBL4 = dict(coriolis_parameter=1.0e-4, roughness_length=0.1, cooling_rate=-0.375,
            brunt_vaisala_frequency=6.1e-3, reference_potential_temperature=265.0)
#: Rows of 4 turbines 5 D apart: aligned, and zig-zag (partial, multiple overlaps) in D.
ROWS = {"aligned": (0.0, 0.0, 0.0, 0.0), "zigzag": (0.0, 0.3, -0.2, 0.4)}


def row(offsets, solver="turbine_grid", points=3, **wake_settings):
    """The 4-turbine row on farm_sbl6's input (the package's defaults) in SBL-4 at 11 m/s."""
    config = load_yaml(str(floris_ekman_veer.example_input("farm_sbl6")))
    block = config["wake"]["wake_velocity_parameters"]["ekman_veer"]
    block["atmosphere"] = dict(SBL4)
    block.update(wake_settings)
    config["farm"].update(layout_x=[5.0 * D * k for k in range(4)],
                          layout_y=[D * y for y in offsets])
    config["flow_field"].update(wind_speeds=[11.0], wind_directions=[270.0],
                                turbulence_intensities=[0.06])
    config["solver"] = {"type": solver, "turbine_grid_points": points}
    fmodel = FlorisModel(config)
    with warnings.catch_warnings():
        # The cubature grid's band-resolution advice and the placeholder TI note: not asserted
        # here (tests/plugin/wake_models/test_models.py asserts the first).
        warnings.simplefilter("ignore", RuntimeWarning)
        warnings.simplefilter("ignore", floris_ekman_veer.ModelSettingsWarning)
        fmodel.run()
    return fmodel


def curve_power(fmodel, speeds):
    """The NREL 5 MW's power [W] at rotor-equivalent speeds (its table, no yaw or tilt)."""
    table = fmodel.core.farm.turbine_definitions[0]["power_thrust_table"]
    return 1e3 * np.interp(speeds, table["wind_speed"], table["power"])


def test_the_defaults_hand_the_turbine_states_and_the_point_wise_settings_do_not():
    """The states are handed only where FLORIS's point-wise solvers lack the physics (the
    cumulative wake's thrust needs each rotor's incoming speed, whatever the deficit's scale)."""
    model = row(ROWS["aligned"]).core.wake.velocity_model
    assert hands_turbine_states(model)
    point_wise = dict(wake_expansion="local_turbulence", deficit_velocity="free_stream")
    assert hands_turbine_states(row(ROWS["aligned"], **point_wise).core.wake.velocity_model)
    summed = row(ROWS["aligned"], wake_superposition="combination_model", **point_wise)
    assert not hands_turbine_states(summed.core.wake.velocity_model)


@pytest.mark.parametrize("superposition", ["cumulative", "combination_model"])
@pytest.mark.parametrize("layout", sorted(ROWS))
def test_a_64_point_cubature_grid_gives_the_turbine_grids_powers(layout, superposition):
    """The 8 x 8 cubature grid's rotor speeds (FLORIS's cubic cubature mean, its own weights)
    give each turbine's power within 1 % of the turbine grid's, and the farm's. (FLORIS 4.7's
    get_turbine_powers averages cubature points with equal weights, which moves the waked
    rotors' powers by up to 2 % more: a property of FLORIS's averaging, not of the wakes.)"""
    turbine = row(ROWS[layout], wake_superposition=superposition)
    cubature = row(ROWS[layout], solver="turbine_cubature_grid", points=8,
                   wake_superposition=superposition)
    assert cubature.core.grid.x_sorted.shape[2:] == (64, 1)
    u_turbine = average_velocity(turbine.core.flow_field.u, method="cubic-mean")
    u_cubature = average_velocity(cubature.core.flow_field.u, method="cubic-cubature",
                                  cubature_weights=cubature.core.grid.cubature_weights)
    p_turbine, p_cubature = curve_power(turbine, u_turbine), curve_power(cubature, u_cubature)
    # FLORIS's own powers on the turbine grid are the curve's at its rotor speeds.
    np.testing.assert_allclose(p_turbine, turbine.get_turbine_powers(), rtol=1e-3)
    # The downstream rotors are waked (the test is about wakes).
    assert np.all(p_turbine[0, 1:] < 0.8 * p_turbine[0, 0])
    np.testing.assert_allclose(p_cubature, p_turbine, rtol=0.01)
    np.testing.assert_allclose(p_cubature.sum(), p_turbine.sum(), rtol=0.01)


@pytest.mark.parametrize("superposition", ["cumulative", "combination_model"])
@pytest.mark.parametrize("layout", sorted(ROWS))
def test_points_sampled_on_the_rotors_give_the_turbine_velocities(layout, superposition):
    """sample_flow_at_points (FLORIS's full-flow solver, as planes) over each rotor disk (1,024
    equal-area points): their cubic mean is the turbine's rotor velocity within 1 %."""
    fmodel = row(ROWS[layout], wake_superposition=superposition)
    y_unit, z_unit = equal_area_disk(16, 64)
    x = np.array(fmodel.core.farm.layout_x)[:, None] + 0.0 * y_unit
    y = np.array(fmodel.core.farm.layout_y)[:, None] + 0.5 * D * y_unit
    z = HUB + 0.5 * D * z_unit + 0.0 * x
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        sampled = fmodel.sample_flow_at_points(x.ravel(), y.ravel(), z.ravel())
    disk = np.cbrt(np.mean(sampled.reshape(x.shape) ** 3, axis=1))
    assert np.all(fmodel.turbine_average_velocities[0, 1:] < 0.9 * 11.0)
    np.testing.assert_allclose(disk, fmodel.turbine_average_velocities[0], rtol=0.01)
