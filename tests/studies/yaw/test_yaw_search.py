"""optimize_yaw finds the optimum over both signs of yaw, whatever the bounds
(studies/yaw/yaw_search.py, docs/yaw_steering.md#finding-the-optimum).

The reference is a brute-force search on a 1-degree grid, built here: every pair of yaw angles of
the two front turbines of a 3-turbine row, and for each pair the best yaw of the last turbine
(whose yaw moves no wake onto a turbine, so its power given its inflow is all that depends on
it: evaluated with the operation model on that inflow for every angle); on the night rows it is
refined by Nelder-Mead (scipy) from the best grid point. The rows are held out: spacings,
directions and speeds that examples/yaw_study.py does not use.
"""

from __future__ import annotations

import contextlib
import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel
from scipy.optimize import minimize
from floris.core.turbine.turbine import power
from floris.optimization.yaw_optimization.yaw_optimization_base import YawOptimization
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR
from floris.utilities import load_yaml

import floris_ekman_veer  # noqa: F401
from floris_ekman_veer import optimize_yaw
from floris_ekman_veer.plugin.inflow.inflow import set_atmosphere
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning
from floris_ekman_veer.plugin.rotor.yawed_rotor import veer_aware

INPUTS = Path(__file__).resolve().parents[3] / "inputs"
DIAMETER = 126.0
LIMIT = 25.0
#: Held-out rows: (spacing in D, atmosphere input, wind direction, wind speed).
ROWS = [(4.5, "sbl4", 266.0, 9.0), (6.0, "cnbl", 268.0, 9.0)]
BOUNDS = [(-LIMIT, LIMIT), (0.0, LIMIT), (-LIMIT, 0.0)]
#: Held-out night rows: 3 turbines at 4.5 D on the shipped night (inputs/farm_night.yaml, the
#: paper's SBL-3 cooling rate -0.25 K/h) at 8 m/s, the lightest wind at which its boundary layer
#: (h = 197 m) is above the rotor top (at 7 m/s, 133 m). At 268 and 263 deg the serial refine
#: stops on the ridge between the two front turbines' yaws (the last turbine left at 0 deg).
NIGHT_ROWS = [(4.5, "farm_night", direction, 8.0) for direction in (273.0, 268.0, 263.0)]


def atmosphere(name):
    return load_yaml(INPUTS / f"{name}.yaml")["wake"]["wake_velocity_parameters"]["ekman_veer"][
        "atmosphere"]


def row(spacing, name, direction, speed, yaw=None):
    fmodel = FlorisModel(INPUTS / "farm_sbl6.yaml")
    n = 1 if yaw is None else len(yaw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        set_atmosphere(fmodel, atmosphere(name), layout_x=spacing * DIAMETER * np.arange(3),
                       layout_y=np.zeros(3), wind_directions=np.full(n, direction),
                       wind_speeds=np.full(n, speed), turbulence_intensities=np.full(n, 0.06),
                       yaw_angles=yaw)
    return fmodel


def last_turbine_powers(fmodel, angles):
    """(n_findex, angles) power of the last turbine yawed by each angle, in its inflow."""
    farm, flow = fmodel.core.farm, fmodel.core.flow_field
    out = []
    with veer_aware(fmodel.core):
        for angle in angles:
            yaw = farm.yaw_angles.copy()
            yaw[:, 2] = angle
            out.append(power(
                velocities=flow.u, turbulence_intensities=flow.turbulence_intensity_field[:, :, None, None],
                air_density=flow.air_density, power_functions=farm.turbine_power_functions,
                yaw_angles=yaw, tilt_angles=farm.tilt_angles, power_setpoints=farm.power_setpoints,
                awc_modes=farm.awc_modes, awc_amplitudes=farm.awc_amplitudes,
                tilt_interps=farm.turbine_tilt_interps, turbine_type_map=farm.turbine_type_map,
                turbine_power_thrust_tables=farm.turbine_power_thrust_tables,
                correct_cp_ct_for_tilt=farm.correct_cp_ct_for_tilt, ix_filter=[2],
            )[:, 0])
    return np.stack(out, axis=1)


def brute_force_tables(rows):
    """(front yaw pairs, last-turbine angles, [farm power table per row]) on the 1-degree grid."""
    angles = np.arange(-LIMIT, LIMIT + 1.0)
    y1, y2 = (a.ravel() for a in np.meshgrid(angles, angles, indexing="ij"))
    pairs = np.stack([y1, y2, np.zeros_like(y1)], axis=1)
    tables = []
    for spacing, name, direction, speed in rows:
        fmodel = row(spacing, name, direction, speed, pairs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
            fmodel.run()
        front = fmodel.get_turbine_powers()[:, :2].sum(axis=1)
        tables.append(front[:, None] + last_turbine_powers(fmodel, angles))
    return pairs, angles, tables


def farm_power(spacing, name, direction, speed, yaw):
    fmodel = row(spacing, name, direction, speed, np.atleast_2d(yaw))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        fmodel.run()
    return float(fmodel.get_farm_power()[0])


def refined_brute_force(spec, table, pairs, angles, lower=-LIMIT, upper=LIMIT):
    """(yaws, farm power) of the best 1-degree grid point refined by Nelder-Mead (1-degree initial
    simplex, yaws clipped to the bounds)."""
    front, last = np.unravel_index(np.argmax(table), table.shape)
    start = np.array([pairs[front, 0], pairs[front, 1], angles[last]])
    result = minimize(lambda x: -farm_power(*spec, np.clip(x, lower, upper)) / 1e3, start,
                      method="Nelder-Mead", options=dict(
                          xatol=0.01, fatol=1e-4, maxfev=400,
                          initial_simplex=start + np.vstack([np.zeros(3), np.eye(3)])))
    yaw = np.clip(result.x, lower, upper)
    return yaw, max(farm_power(*spec, yaw), float(table.max()))


@pytest.fixture(scope="module")
def brute_force():
    """Per held-out row: (front yaw pairs, last-turbine angles, farm power table)."""
    return brute_force_tables(ROWS)


def best_within(brute_force, k, lower, upper):
    pairs, angles, tables = brute_force
    inside = np.all((pairs[:, :2] >= lower) & (pairs[:, :2] <= upper), axis=1)
    columns = (angles >= lower) & (angles <= upper)
    return tables[k][np.ix_(inside, columns)].max()


@pytest.mark.parametrize("bounds", BOUNDS, ids=["-25..25", "0..25", "-25..0"])
def test_optimum_within_0_05_percent_of_brute_force(brute_force, bounds):
    for k, (spacing, name, direction, speed) in enumerate(ROWS):
        df = optimize_yaw(row(spacing, name, direction, speed), YawOptimizationSR,
                          minimum_yaw_angle=bounds[0], maximum_yaw_angle=bounds[1],
                          progress=False)
        found = float(df["farm_power_opt"].iloc[0])
        reference = best_within(brute_force, k, *bounds)
        shortfall = 1.0 - found / reference
        assert shortfall < 5e-4, (spacing, name, direction, bounds, shortfall)
        yaw = np.vstack(df["yaw_angles_opt"])[0]
        assert np.all((yaw >= bounds[0]) & (yaw <= bounds[1]))


def test_single_search_is_floris_own_and_loses_the_other_sign(brute_force):
    """search="single" is FLORIS's serial refine as it is; on a veered row over -25..25 deg it
    falls short of the optimum by more than the both-signs search."""
    spacing, name, direction, speed = ROWS[0]
    fmodel = row(spacing, name, direction, speed)
    single = optimize_yaw(fmodel, YawOptimizationSR, search="single", minimum_yaw_angle=-LIMIT,
                          maximum_yaw_angle=LIMIT, progress=False)
    own = YawOptimizationSR(fmodel, minimum_yaw_angle=-LIMIT, maximum_yaw_angle=LIMIT)
    own = own.optimize(print_progress=False)
    assert float(single["farm_power_opt"].iloc[0]) == float(own["farm_power_opt"].iloc[0])
    both = optimize_yaw(fmodel, YawOptimizationSR, minimum_yaw_angle=-LIMIT,
                        maximum_yaw_angle=LIMIT, progress=False)
    reference = best_within(brute_force, 0, -LIMIT, LIMIT)
    assert float(both["farm_power_opt"].iloc[0]) >= float(single["farm_power_opt"].iloc[0])
    assert 1.0 - float(single["farm_power_opt"].iloc[0]) / reference > \
        1.0 - float(both["farm_power_opt"].iloc[0]) / reference


@pytest.mark.parametrize("spec", [
    pytest.param(spec, id=f"{spec[2]:.0f}deg", marks=() if k == 0 else pytest.mark.study)
    for k, spec in enumerate(NIGHT_ROWS)
])
def test_night_rows_within_0_05_percent_of_refined_brute_force(spec):
    """The held-out night rows: within 0.05 % of the 1-degree grid refined by Nelder-Mead, and
    not below FLORIS's own serial refine by more than 0.02 %, evaluating at most twice its
    conditions (the first row in the fast suite, all three in the study run). Measured with the
    cumulative wake: 0.005, 0.005 and 0.010 % short of the reference at 273, 268 and 263 deg
    (273 deg: [13.6, 9.2, -8.0] against its [13.6, 9.3, -8.0] deg, the last turbine's yaw,
    which moves its own power alone, reached by the quadratic steps' Newton moves); above
    FLORIS's run by 0.029 % at 273 deg (its [12.5, 9.4, -9.4] deg; by 0.016 % with the wakes
    summed by the combination model), by 0.10 and 0.07 % at 268 and 263 deg; 42, 40 and 40
    conditions against its 25, 23 and 23."""
    pairs, angles, (table,) = brute_force_tables([spec])
    _, reference = refined_brute_force(spec, table, pairs, angles)
    with counting_conditions() as count:
        df = optimize_yaw(row(*spec), YawOptimizationSR, minimum_yaw_angle=-LIMIT,
                          maximum_yaw_angle=LIMIT, progress=False)
    found = float(df["farm_power_opt"].iloc[0])
    assert 1.0 - found / reference < 5e-4, (spec, found, reference)
    yaw = np.vstack(df["yaw_angles_opt"])[0]
    assert np.all(np.abs(yaw) <= LIMIT)
    assert farm_power(*spec, yaw) == pytest.approx(found, rel=1e-12)
    with counting_conditions() as own_count:
        own = YawOptimizationSR(row(*spec), minimum_yaw_angle=-LIMIT, maximum_yaw_angle=LIMIT)
        own = own.optimize(print_progress=False)
    assert found >= float(own["farm_power_opt"].iloc[0]) * (1.0 - 2e-4)
    assert count["conditions"] <= 2.0 * own_count["conditions"], (count, own_count)


@pytest.mark.parametrize("bounds", [(5.0, 10.0), (10.0, 10.0), (-10.0, -10.0)],
                         ids=["5..10", "10..10", "-10..-10"])
def test_bounds_that_exclude_zero(bounds):
    """The optimum stays inside bounds that exclude zero yaw: for a fixed yaw it is that yaw;
    for 5..10 deg within 0.05 % of the best point of a 1-degree grid of all three yaws. The
    baseline stays the zero-yaw farm."""
    spec = NIGHT_ROWS[0]
    lower, upper = bounds
    df = optimize_yaw(row(*spec), YawOptimizationSR, minimum_yaw_angle=lower,
                      maximum_yaw_angle=upper, progress=False)
    yaw = np.vstack(df["yaw_angles_opt"])[0]
    found = float(df["farm_power_opt"].iloc[0])
    assert np.all((yaw >= lower) & (yaw <= upper)), yaw
    assert farm_power(*spec, yaw) == pytest.approx(found, rel=1e-12)
    assert float(df["farm_power_baseline"].iloc[0]) == pytest.approx(
        farm_power(*spec, np.zeros(3)), rel=1e-12)
    grid = np.arange(lower, upper + 0.5)
    points = np.stack([a.ravel() for a in np.meshgrid(grid, grid, grid, indexing="ij")], axis=1)
    fmodel = row(*spec, yaw=points)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        fmodel.run()
    best = fmodel.get_farm_power().max()
    if lower == upper:
        np.testing.assert_array_equal(yaw, np.full(3, lower))
        assert found == pytest.approx(best, rel=1e-12)
    else:
        assert 1.0 - found / best < 5e-4, (found, best)


def test_a_model_without_conditions_is_refused_naming_it():
    fmodel = FlorisModel(floris_ekman_veer.example_input("farm_night"))
    fmodel.set(wind_directions=np.array([]), wind_speeds=np.array([]),
               turbulence_intensities=np.array([]))
    with pytest.raises(ValueError, match=r"optimize_yaw: the model has no conditions \(n_findex = 0\)"):
        optimize_yaw(fmodel, YawOptimizationSR)


def test_both_signs_is_at_least_each_sign_on_the_neutral_row():
    """The neutral day's row at 4 D, 8 m/s along 270 deg: the both-signs search finds in its one
    run at least what the searches restricted to each sign find, the front turbine steering
    with positive yaw. (On the wakes of the time the seeds were introduced steering paid here
    only when the two front turbines turned together and a serial refine from zero yaw stayed
    near zero; on today's wakes the front turbine alone gains: FLORIS's serial refine finds
    [25, 0, 0] deg at +1.233 %, the both-signs search [24.5, -0.9, -0.3] deg at +1.240 %,
    positive yaw alone +1.236 %, negative yaw alone +0.847 %.)"""
    fmodel = row(4.0, "cnbl", 270.0, 8.0)
    both = optimize_yaw(fmodel, YawOptimizationSR, minimum_yaw_angle=-LIMIT,
                        maximum_yaw_angle=LIMIT)
    for lower, upper in ((0.0, LIMIT), (-LIMIT, 0.0)):
        one_sign = optimize_yaw(fmodel, YawOptimizationSR, minimum_yaw_angle=lower,
                                maximum_yaw_angle=upper)
        assert both["farm_power_opt"].iloc[0] >= one_sign["farm_power_opt"].iloc[0] * (1 - 1e-12)
    gain = both["farm_power_opt"].iloc[0] / both["farm_power_baseline"].iloc[0] - 1.0
    assert gain > 0.008  # +1.240 % at about (+24.5, -0.9, -0.3) deg (docs/yaw_steering.md)
    assert both["yaw_angles_opt"].iloc[0][0] > 10.0


@contextlib.contextmanager
def counting_conditions():
    """Count the FLORIS runs and the conditions they evaluate, in every yaw optimiser (all
    evaluations go through YawOptimization._calculate_farm_power)."""
    count = {"runs": 0, "conditions": 0}
    original = YawOptimization._calculate_farm_power

    def counted(self, yaw_angles=None, *args, **kwargs):
        count["runs"] += 1
        count["conditions"] += (self.fmodel_subset.core.flow_field.n_findex if yaw_angles is None
                                else np.shape(yaw_angles)[0])
        return original(self, yaw_angles, *args, **kwargs)

    YawOptimization._calculate_farm_power = counted
    try:
        yield count
    finally:
        YawOptimization._calculate_farm_power = original


def test_both_signs_costs_at_most_twice_floris_serial_refine():
    """The 3 x 3 night farm (inputs/farm_night.yaml), 12 directions 255-285 deg at 8 m/s, yaw
    -25..25 deg: the both-signs search evaluates at most twice the conditions of FLORIS's own
    serial refine on the same conditions (one run, seeded: docs/yaw_steering.md#how-both-signs-are-searched),
    and finds at least its farm power in every condition but by 0.02 % (a heuristic's margin: on the
    cumulative wake's landscape two of 12 end 0.003 % below), more on average (+0.170 %; 1,244
    conditions against its 873, 1.42 x)."""
    fmodel = FlorisModel(INPUTS / "farm_night.yaml")
    directions = np.linspace(255.0, 285.0, 12)
    fmodel.set(wind_directions=directions, wind_speeds=np.full(12, 8.0),
               turbulence_intensities=np.full(12, 0.06))
    options = dict(minimum_yaw_angle=-LIMIT, maximum_yaw_angle=LIMIT, Ny_passes=[5, 4])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        with counting_conditions() as own_count:
            own = YawOptimizationSR(fmodel, **options).optimize(print_progress=False)
        with counting_conditions() as count:
            both = optimize_yaw(fmodel, YawOptimizationSR, progress=False, **options)
    assert own_count["runs"] == 1 + 2 * 9
    assert count["conditions"] <= 2.0 * own_count["conditions"], (count, own_count)
    ratio = both["farm_power_opt"].to_numpy(float) / own["farm_power_opt"].to_numpy(float)
    assert np.all(ratio > 1.0 - 2e-4), ratio
    assert ratio.mean() > 1.0


def test_without_bounds_both_signs_are_searched():
    """optimize_yaw without bounds searches -25..25 deg (FLORIS's default, 0..25 deg, one sign):
    on the shipped night's 3-turbine row at 4.5 D, 8 m/s, 263 deg the gain is on the negative
    side, [-22.7, -23.3, -2.5] at about 3,750 kW where FLORIS's bounds gave [0, 0, 0] at
    3,427.6 kW (+9.4 %); bounds given stay the caller's."""
    fmodel = row(4.5, "farm_night", 263.0, 8.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        free = optimize_yaw(fmodel, YawOptimizationSR)
        one_sign = optimize_yaw(fmodel, YawOptimizationSR, minimum_yaw_angle=0.0,
                                maximum_yaw_angle=25.0)
    yaw = free["yaw_angles_opt"].iloc[0]
    assert yaw[0] <= -21.0 and yaw[1] <= -22.0
    assert free["farm_power_opt"].iloc[0] == pytest.approx(3.7492e6, rel=2e-3)
    assert free["farm_power_opt"].iloc[0] > 1.08 * free["farm_power_baseline"].iloc[0]
    assert np.all(one_sign["yaw_angles_opt"].iloc[0] >= 0.0)
    assert one_sign["farm_power_opt"].iloc[0] < 0.93 * free["farm_power_opt"].iloc[0]
