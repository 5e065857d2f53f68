"""floris_ekman_veer.optimize_yaw and FLORIS's yaw optimisers on per-condition atmospheres.

The reference is always FLORIS's own optimiser class run on a model of one atmosphere (scalar
values) holding just that atmosphere's conditions: a per-condition (day/night) model must give
the same optimal angles and, to 1e-12, the same powers.
"""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from floris import FlorisModel, UncertainFlorisModel
from floris.optimization.yaw_optimization.yaw_optimizer_geometric import YawOptimizationGeometric
from floris.optimization.yaw_optimization.yaw_optimizer_scipy import YawOptimizationScipy
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR
from floris.utilities import load_yaml

import floris_ekman_veer
from floris_ekman_veer import optimize_yaw
from floris_ekman_veer.plugin.inflow import inflow
from floris_ekman_veer import registry
from floris_ekman_veer.plugin.floris_tools.optimizer_conditions import atmosphere_groups

from conftest import STABLE_ATMOSPHERE, assert_as_plain_floris, make_config

# The stable atmospheres of these farms give, in some conditions and by design, boundary layers
# shallower than the NREL 5 MW rotor top (153 m); their ShallowBoundaryLayerWarning is not what
# is tested here (tests/physics/test_shallow_abl.py and tests/test_user_inputs_and_warnings.py are).
pytestmark = [pytest.mark.usefixtures("inflow_hook"), pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")]

INPUTS = Path(__file__).resolve().parents[3] / "inputs"

NEUTRAL = dict(STABLE_ATMOSPHERE, cooling_rate=0.0)
STABLE = dict(STABLE_ATMOSPHERE, cooling_rate=-0.5)
# Day, night, night, day, night: interleaved, so that order and grouping are both exercised.
CLASSES = [NEUTRAL, STABLE, STABLE, NEUTRAL, STABLE]
SPEEDS = [8.0, 8.0, 10.0, 10.0, 9.0]
DIRECTIONS = [270.0, 270.0, 274.0, 266.0, 268.0]

OPTIMIZERS = {
    "sr": (YawOptimizationSR, dict(minimum_yaw_angle=-25.0, maximum_yaw_angle=25.0,
                                   Ny_passes=[5, 4])),
    "scipy": (YawOptimizationScipy, dict(minimum_yaw_angle=-25.0, maximum_yaw_angle=25.0,
                                         opt_options=dict(maxiter=2, disp=False, ftol=1e-8,
                                                          eps=0.5))),
    "geometric": (YawOptimizationGeometric, dict(minimum_yaw_angle=-25.0,
                                                 maximum_yaw_angle=25.0)),
}


def per_condition(values):
    """The atmosphere whose cooling rate is given per condition."""
    return dict(STABLE_ATMOSPHERE, cooling_rate=[a["cooling_rate"] for a in values])


def gch_row(atmosphere, speeds, directions):
    return FlorisModel(make_config("gch", atmosphere, wind_speeds=speeds,
                                   wind_directions=directions))


def ekman_row(atmosphere, speeds, directions):
    """inputs/farm_sbl6.yaml (ekman_veer, M-1) cut to a 3-turbine row at 7 D."""
    config = load_yaml(str(INPUTS / "farm_sbl6.yaml"))
    config["farm"].update(layout_x=[0.0, 882.0, 1764.0], layout_y=[0.0, 0.0, 0.0])
    config["flow_field"].update(wind_speeds=list(speeds), wind_directions=list(directions),
                                turbulence_intensities=[0.06] * len(speeds))
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"] = atmosphere
    return FlorisModel(config)


def run_floris(optimizer_class, fmodel, options):
    optimizer = optimizer_class(fmodel, **options)
    if optimizer_class is YawOptimizationSR:
        return optimizer.optimize(print_progress=False)
    return optimizer.optimize()


def per_class_reference(build, optimizer_class, options):
    """FLORIS's optimiser on one scalar-atmosphere model per class, rows back in input order."""
    rows = {}
    for atmosphere in (NEUTRAL, STABLE):
        index = [i for i, a in enumerate(CLASSES) if a is atmosphere]
        df = run_floris(optimizer_class, build(atmosphere, [SPEEDS[i] for i in index],
                                               [DIRECTIONS[i] for i in index]), options)
        rows.update({i: df.iloc[k] for k, i in enumerate(index)})
    return pd.DataFrame([rows[i] for i in range(len(CLASSES))])


def assert_same_optimum(result, reference):
    assert list(result.index) == list(range(len(CLASSES)))
    np.testing.assert_array_equal(result.wind_direction, DIRECTIONS)
    np.testing.assert_array_equal(result.wind_speed, SPEEDS)
    np.testing.assert_array_equal(np.vstack(result.yaw_angles_opt),
                                  np.vstack(reference.yaw_angles_opt))
    for column in ("farm_power_opt", "farm_power_baseline"):
        if reference[column].isna().all():
            assert result[column].isna().all()
        else:
            np.testing.assert_allclose(result[column].astype(float),
                                       reference[column].astype(float), rtol=1e-12, atol=0)


@pytest.mark.parametrize("name", sorted(OPTIMIZERS))
def test_per_condition_atmosphere_equals_per_class_runs(name):
    optimizer_class, options = OPTIMIZERS[name]
    reference = per_class_reference(gch_row, optimizer_class, options)
    result = optimize_yaw(gch_row(per_condition(CLASSES), SPEEDS, DIRECTIONS), optimizer_class,
                          search="single", **options)
    assert_same_optimum(result, reference)
    if name == "sr":  # wake steering found both signs and gained power
        angles = np.vstack(result.yaw_angles_opt)
        assert angles.min() < 0.0 < angles.max()
        assert np.all(result.farm_power_opt > result.farm_power_baseline)


def test_ekman_veer_model_per_condition_equals_per_class_runs():
    optimizer_class, options = OPTIMIZERS["sr"]
    reference = per_class_reference(ekman_row, optimizer_class, options)
    result = optimize_yaw(ekman_row(per_condition(CLASSES), SPEEDS, DIRECTIONS),
                          optimizer_class, search="single", chunk_size=2, **options)
    assert_same_optimum(result, reference)


def test_scalar_atmosphere_is_floris_own_result():
    optimizer_class, options = OPTIMIZERS["sr"]
    fmodel = gch_row(STABLE, SPEEDS, DIRECTIONS)
    reference = run_floris(optimizer_class, fmodel, options)
    result = optimize_yaw(fmodel, optimizer_class, search="single", chunk_size=3, **options)
    np.testing.assert_array_equal(np.vstack(result.yaw_angles_opt),
                                  np.vstack(reference.yaw_angles_opt))
    np.testing.assert_allclose(result.farm_power_opt, reference.farm_power_opt, rtol=1e-12)


def test_per_condition_bounds_follow_their_conditions():
    bounds = np.zeros((len(CLASSES), 3))
    bounds[1] = 25.0  # only condition 1 (a night) may yaw
    result = optimize_yaw(gch_row(per_condition(CLASSES), SPEEDS, DIRECTIONS), YawOptimizationSR,
                          minimum_yaw_angle=-bounds, maximum_yaw_angle=bounds, Ny_passes=[5, 4])
    angles = np.vstack(result.yaw_angles_opt)
    assert np.all(angles[[0, 2, 3, 4]] == 0.0) and np.abs(angles[1]).max() > 0.0


def test_groups_follow_first_appearance():
    groups = atmosphere_groups(gch_row(per_condition(CLASSES), SPEEDS, DIRECTIONS))
    assert [g[0]["cooling_rate"] for g in groups] == [0.0, -0.5]
    assert [g[1].tolist() for g in groups] == [[0, 3], [1, 2, 4]]


def test_optimize_yaw_is_exported():
    assert floris_ekman_veer.optimize_yaw is optimize_yaw


@pytest.mark.parametrize("optimizer_class, options, message", [
    (YawOptimizationSR, dict(Ny_passes=[5, 3]), "Ny_passes"),
    (YawOptimizationSR, dict(Ny_passes=[1]), "Ny_passes"),
    (YawOptimizationSR, dict(opt_method="SLSQP"), r"no option\(s\) \['opt_method'\]"),
    (YawOptimizationSR, dict(minimum_yaw_angle=10.0, maximum_yaw_angle=5.0), "must not exceed"),
    (YawOptimizationSR, dict(minimum_yaw_angle=-95.0), r"\(-90, 90\)"),
    (YawOptimizationSR, dict(maximum_yaw_angle=[20.0, 20.0]), "n_turbines = 3"),
    (YawOptimizationScipy, dict(opt_method="newton"), "opt_method"),
    (YawOptimizationScipy, dict(x0=[30.0, 0.0, 0.0]), "x0"),
    (YawOptimizationScipy, dict(opt_options=5), "opt_options"),
    (YawOptimizationGeometric, dict(Ny_passes=[5, 4]), "Ny_passes"),
    (FlorisModel, {}, "optimizer_class"),
])
def test_bad_optimizer_options_fail_before_any_work(monkeypatch, optimizer_class, options,
                                                    message):
    fmodel = gch_row(per_condition(CLASSES), SPEEDS, DIRECTIONS)

    def no_work(*args, **kwargs):
        raise AssertionError("FLORIS ran before the options were checked")

    monkeypatch.setattr(FlorisModel, "run", no_work)
    with pytest.raises(ValueError, match=message):
        optimize_yaw(fmodel, optimizer_class, **options)
    with pytest.raises(ValueError, match="chunk_size"):
        optimize_yaw(fmodel, YawOptimizationSR, chunk_size=0)
    with pytest.raises(ValueError, match=r"search must be one of \['both_signs', 'single'\]"):
        optimize_yaw(fmodel, YawOptimizationSR, search="both")


# ------------------------------------------------------------------ FLORIS's own classes directly


@pytest.mark.parametrize("name", sorted(OPTIMIZERS))
def test_floris_optimizer_classes_accept_per_condition_atmospheres(name):
    optimizer_class, options = OPTIMIZERS[name]
    if name == "scipy":  # one SLSQP iteration is enough to compare the two routes
        options = dict(options, opt_options=dict(maxiter=1, disp=False, ftol=1e-8, eps=0.5))
    reference = per_class_reference(gch_row, optimizer_class, options)
    optimizer = optimizer_class(gch_row(per_condition(CLASSES), SPEEDS, DIRECTIONS), **options)
    result = optimizer.optimize(print_progress=False) if name == "sr" else optimizer.optimize()
    assert_same_optimum(result, reference)
    np.testing.assert_array_equal(optimizer.yaw_angles_opt, np.vstack(reference.yaw_angles_opt))


def uncertain(build):
    def make(atmosphere, speeds, directions):
        return UncertainFlorisModel(build(atmosphere, speeds, directions), wd_std=3.0,
                                    wd_sample_points=[-3.0, 0.0, 3.0])
    return make


def test_uncertain_floris_model_per_condition_equals_per_class_models():
    mixed = uncertain(gch_row)(per_condition(CLASSES), SPEEDS, DIRECTIONS)
    mixed.run()
    powers = mixed.get_turbine_powers()
    assert powers.shape == (len(CLASSES), 3)
    for atmosphere in (NEUTRAL, STABLE):
        index = [i for i, a in enumerate(CLASSES) if a is atmosphere]
        alone = uncertain(gch_row)(atmosphere, [SPEEDS[i] for i in index],
                                   [DIRECTIONS[i] for i in index])
        alone.run()
        np.testing.assert_allclose(powers[index], alone.get_turbine_powers(), rtol=1e-12, atol=0)
    # Conditions 0 and 1 differ only by their atmosphere: not merged by the de-duplication.
    assert not np.allclose(powers[0], powers[1], rtol=1e-3)


def test_yaw_optimisation_of_a_per_condition_uncertain_model_equals_per_class_runs():
    optimizer_class, options = YawOptimizationSR, dict(OPTIMIZERS["sr"][1], Ny_passes=[3, 2])
    reference = per_class_reference(uncertain(gch_row), optimizer_class, options)
    result = optimize_yaw(uncertain(gch_row)(per_condition(CLASSES), SPEEDS, DIRECTIONS),
                          optimizer_class, search="single", **options)
    assert_same_optimum(result, reference)


def test_plain_floris_optimizer_and_uncertain_model_are_bitwise_unchanged():
    """Without an atmosphere the wrappers of the optimisers and of UncertainFlorisModel are
    FLORIS's own behaviour, bit for bit."""
    def outputs():
        fmodel = gch_row(None, [8.0, 9.0], [270.0, 275.0])
        df = run_floris(YawOptimizationSR, fmodel, OPTIMIZERS["sr"][1])
        ufmodel = UncertainFlorisModel(fmodel)
        ufmodel.run()
        return np.vstack(df.yaw_angles_opt), df.farm_power_opt.to_numpy(), \
            ufmodel.get_turbine_powers()

    assert_as_plain_floris(outputs)


@pytest.mark.parametrize("per_condition_atmosphere", [True, False], ids=["rows", "scalar"])
def test_condition_rebuild_is_bitwise_floris_full_rebuild(monkeypatch, per_condition_atmosphere):
    """The optimiser's subsets rebuild only what new conditions change
    (plugin/floris_tools/optimizer_conditions.py ``_reinitialize_conditions``): the both-signs search of a
    per-condition (row-following) and of a scalar atmosphere gives bit for bit the yaw angles
    and powers of FLORIS's full Core rebuild at every evaluation."""
    from floris_ekman_veer.plugin.floris_tools import optimizer_conditions as optimization

    atmosphere = per_condition(CLASSES) if per_condition_atmosphere else STABLE
    options = OPTIMIZERS["sr"][1]

    def outputs():
        df = optimize_yaw(ekman_row(atmosphere, SPEEDS, DIRECTIONS), YawOptimizationSR,
                          progress=False, **options)
        return [np.vstack(df.yaw_angles_opt)] + [
            df[column].to_numpy(float) for column in ("farm_power_opt", "farm_power_baseline")]

    calls = []
    quick = optimization._reinitialize_conditions
    monkeypatch.setattr(optimization, "_reinitialize_conditions",
                        lambda self, **kwargs: calls.append(1) or quick(self, **kwargs))
    rebuilt = outputs()
    assert len(calls) > 10  # every evaluation took the condition rebuild
    monkeypatch.setattr(optimization, "_reinitialize_conditions",
                        lambda self, **kwargs: FlorisModel._reinitialize(self, **kwargs))
    for new, full in zip(rebuilt, outputs()):
        np.testing.assert_array_equal(new, full)
