"""What a FLORIS user meets first: converting an input, the package's warnings, the packaged
inputs, calm and weak winds, trial layouts, and the inputs real studies contain
(docs/user_guide.md)."""

from __future__ import annotations

import contextlib
import copy
import os
import pickle
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from floris import FlorisModel, WindRose
from floris.utilities import load_yaml

import floris_ekman_veer
import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer import EkmanABL
from floris_ekman_veer.plugin.inflow import shallow
from tests.conftest import STABLE_ATMOSPHERE, own_turbine

REPO = Path(__file__).resolve().parents[1]
FARM = floris_ekman_veer.example_input("farm_sbl6")
SBL6 = load_yaml(str(FARM))["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]


@contextlib.contextmanager
def caught():
    """Record every warning (Python's own de-duplication off)."""
    with warnings.catch_warnings(record=True) as records:
        warnings.simplefilter("always")
        yield records


def of(records, category):
    """The records of ``category``."""
    return [r for r in records if issubclass(r.category, category)]


def line_of(text: str) -> int:
    """The line number of ``text`` in this file."""
    return next(i for i, line in enumerate(Path(__file__).read_text().splitlines(), 1)
                if text in line)


def defaults_with_veer(**wake_switches) -> dict:
    """FLORIS's default input (GCH on the NREL 5 MW) turned to ekman_veer as the user guide says."""
    config = FlorisModel.get_defaults()
    config["wake"]["model_strings"].update(velocity_model="ekman_veer", deflection_model="ekman_veer",
                                           combination_model="fls")
    config["wake"]["wake_velocity_parameters"]["ekman_veer"] = {"atmosphere": dict(STABLE_ATMOSPHERE)}
    config["wake"].update(wake_switches)
    config["farm"].update(layout_x=[0.0, 630.0, 1260.0], layout_y=[0.0, 0.0, 0.0])
    config["flow_field"].update(reference_wind_height=90.0, wind_shear=0.0,
                                wind_directions=[270.0, 275.0],
                                wind_speeds=[8.0, 10.0], turbulence_intensities=[0.06, 0.06])
    return config


GCH_OFF = dict(enable_secondary_steering=False, enable_yaw_added_recovery=False,
               enable_transverse_velocities=False)


# ------------------------------------------------------------------------- converting an input
def test_floris_defaults_convert_with_missing_blocks_defaulted():
    converted = FlorisModel(defaults_with_veer(**GCH_OFF))
    explicit = defaults_with_veer(**GCH_OFF)
    explicit["wake"]["wake_deflection_parameters"]["ekman_veer"] = {}
    explicit = FlorisModel(explicit)
    for fmodel in (converted, explicit):
        fmodel.run()
    np.testing.assert_array_equal(converted.get_turbine_powers(), explicit.get_turbine_powers())
    # the defaulted block is the model's defaults: the paper's M-1 with veer
    assert converted.core.wake.deflection_model.veer is True
    assert "ekman_veer" in converted.core.as_dict()["wake"]["wake_deflection_parameters"]


def test_gch_switches_with_ekman_veer_give_one_warning_saying_what_they_do():
    with caught() as records:
        fmodel = FlorisModel(defaults_with_veer())
        fmodel.set(yaw_angles=np.array([[20.0, 0.0, 0.0]] * 2))
        fmodel.run()
    settings = of(records, floris_ekman_veer.ModelSettingsWarning)
    assert len(settings) == 1
    message = str(settings[0].message)
    for text in ("enable_secondary_steering", "enable_yaw_added_recovery",
                 "enable_transverse_velocities", "effective yaw", "not the paper's model"):
        assert text in message
    assert settings[0].filename == __file__
    # and they do change the answer behind a yawed rotor (FLORIS's vortex model on top)
    plain = FlorisModel(defaults_with_veer(**GCH_OFF))
    plain.set(yaw_angles=np.array([[20.0, 0.0, 0.0]] * 2))
    plain.run()
    assert not np.allclose(fmodel.get_turbine_powers()[:, 2], plain.get_turbine_powers()[:, 2],
                           rtol=1e-3)


def test_ekman_veer_velocity_with_gauss_deflection_warns_that_veer_is_lost():
    config = defaults_with_veer(**GCH_OFF)
    config["wake"]["model_strings"]["deflection_model"] = "gauss"
    with caught() as records:
        FlorisModel(config).run()
    (record,) = of(records, floris_ekman_veer.ModelSettingsWarning)
    assert "deflection_model gauss" in str(record.message)
    assert "do not shear with veer" in str(record.message)


def test_paper_models_and_plain_floris_inputs_give_no_settings_warning():
    m3 = load_yaml(str(FARM))
    m3["wake"]["model_strings"]["velocity_model"] = "bastankhah2014"
    with warnings.catch_warnings():
        warnings.simplefilter("error", package_warnings.ModelSettingsWarning)
        for config in (load_yaml(str(FARM)), m3, FlorisModel.get_defaults()):
            FlorisModel(config)


# ------------------------------------------------------------------------------------ warnings
def test_every_warning_class_is_importable_from_the_package():
    for name, cls in package_warnings.CLASSES.items():
        assert getattr(floris_ekman_veer, name) is cls
        assert name in floris_ekman_veer.__all__
        assert issubclass(cls, floris_ekman_veer.FlorisEkmanVeerWarning)
    assert shallow.ShallowBoundaryLayerWarning is floris_ekman_veer.ShallowBoundaryLayerWarning
    assert issubclass(floris_ekman_veer.ThrustLimitWarning, RuntimeWarning)


def test_shallow_warning_at_the_users_line_once_per_study_with_a_summary():
    """Building and set() say nothing; the first run counts the model's shallow conditions at
    the user's line, in its own numbers (the optimiser's tiled copies add nothing); later runs
    of the same conditions say nothing new."""
    from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

    with caught() as records:
        fmodel = FlorisModel(FARM)
        fmodel.set(wind_directions=[270.0] * 5, wind_speeds=[6.0, 7.0, 8.0, 9.0, 15.0],
                   turbulence_intensities=[0.06] * 5)
        assert not of(records, floris_ekman_veer.ShallowBoundaryLayerWarning)
        YawOptimizationSR(fmodel, minimum_yaw_angle=-10.0, maximum_yaw_angle=10.0,  # OPT-LINE
                          Ny_passes=[3, 2]).optimize(print_progress=False)
        fmodel.set(wind_speeds=[9.0, 8.0, 7.0, 6.0, 15.0])  # same conditions: nothing new
        fmodel.run()
    shallow_records = of(records, floris_ekman_veer.ShallowBoundaryLayerWarning)
    assert [(r.filename, r.lineno) for r in shallow_records] == [
        (__file__, line_of("# OPT" "-LINE"))]
    assert str(shallow_records[0].message).startswith(
        "4 of 5 conditions (wind speeds 6, 7, 8 and 9 m/s at 90 m; h = 43.24 to 86.3 m)")


def test_every_shipped_input_builds_without_a_warning():
    """No shipped input warns before the user's own set() or run() (farm_sbl6's placeholder
    9 m/s condition has a boundary layer shallower than the rotor top: counted at its run)."""
    names = sorted(p.stem for p in (REPO / "inputs").glob("*.yaml"))
    assert "farm_sbl6" in names
    for name in names:
        with caught() as records:
            fmodel = FlorisModel(floris_ekman_veer.example_input(name))
        assert not of(records, floris_ekman_veer.FlorisEkmanVeerWarning), name
    with caught() as records:
        fmodel = FlorisModel(FARM)
        fmodel.run()  # RUN-SBL6
    (record,) = of(records, floris_ekman_veer.ShallowBoundaryLayerWarning)
    assert (record.filename, record.lineno) == (__file__, line_of("# RUN" "-SBL6"))
    assert str(record.message).startswith("1 of 1 conditions (wind speeds 9 m/s at 90 m")


def test_optimize_yaw_counts_the_shallow_conditions_once_at_its_start():
    from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

    fmodel = FlorisModel(FARM)
    fmodel.set(wind_directions=[270.0, 280.0, 270.0], wind_speeds=[8.0, 9.0, 15.0],
               turbulence_intensities=[0.06] * 3)
    with caught() as records:
        floris_ekman_veer.optimize_yaw(fmodel, YawOptimizationSR, minimum_yaw_angle=-10.0,  # YAW
                                       maximum_yaw_angle=10.0, Ny_passes=[3, 2], progress=False)
    (record,) = of(records, floris_ekman_veer.ShallowBoundaryLayerWarning)
    assert (record.filename, record.lineno) == (__file__, line_of("# YAW"))
    assert str(record.message).startswith("2 of 3 conditions (wind speeds 8 and 9 m/s at 90 m")


def test_thrust_limit_warning_once_per_run_naming_the_speeds(caplog):
    """The user's turbine whose thrust table exceeds the limit (a copy of the NREL 5 MW's) gets
    one ThrustLimitWarning per run naming the speeds; FLORIS's own NREL 5 MW, whose table the
    user cannot change, one INFO notice on FLORIS's logger and no warning."""
    conditions = dict(wind_speeds=[3.0, 3.5, 9.0, 4.0], wind_directions=[270.0] * 4,
                      turbulence_intensities=[0.06] * 4)
    fmodel = FlorisModel(own_turbine(FARM))
    fmodel.set(**conditions)
    with caught() as records:
        fmodel.run()  # RUN-LINE
        fmodel.run()
    (record,) = of(records, floris_ekman_veer.ThrustLimitWarning)
    assert (record.filename, record.lineno) == (__file__, line_of("# RUN" "-LINE"))
    # NREL 5 MW's C_T cos^2 = 0.96 is exceeded below about 4 m/s only (its thrust table)
    summary = ("turbine wakes in 3 of 4 conditions (wind speeds 3, 3.5 and 4 m/s at 90 m) have "
               "C_T cos^2(yaw) > 0.96")
    assert str(record.message).startswith(summary)
    stock = FlorisModel(FARM)
    stock.set(**conditions)
    with caught() as records, caplog.at_level("INFO", logger="floris.floris_ekman_veer"):
        stock.run()
        stock.run()
    assert not of(records, floris_ekman_veer.ThrustLimitWarning)
    notices = [r.getMessage() for r in caplog.records if r.name == "floris.floris_ekman_veer"
               and r.getMessage().startswith("turbine wakes")]
    assert len(notices) == 1 and notices[0].startswith(summary)
    np.testing.assert_array_equal(stock.get_turbine_powers(), fmodel.get_turbine_powers())


def test_thrust_limit_warning_once_per_study_over_wind_roses():
    """The stock NREL 5 MW's own table exceeds C_T = 0.96 below about 4 m/s, so every wind rose
    meets the limit: one warning for the study (with the user's copy of it), not one per wind
    rose (before: one per new set of speeds)."""
    fmodel = FlorisModel(own_turbine(FARM))
    with caught() as records:
        for speeds in ([3.0, 8.0], [3.5, 10.0], [4.0, 3.2, 12.0]):
            fmodel.set(wind_speeds=speeds, wind_directions=[270.0] * len(speeds),
                       turbulence_intensities=[0.06] * len(speeds))
            fmodel.run()
    (record,) = of(records, floris_ekman_veer.ThrustLimitWarning)
    assert str(record.message).startswith("turbine wakes in 1 of 2 conditions (wind speeds 3 m/s")
    assert str(record.message).endswith("said once per study")


@pytest.fixture
def restore_setting():
    before = os.environ.get(package_warnings.ENVIRONMENT_VARIABLE)
    yield
    if before is None:
        os.environ.pop(package_warnings.ENVIRONMENT_VARIABLE, None)
    else:
        os.environ[package_warnings.ENVIRONMENT_VARIABLE] = before


def test_silence_warnings_here_and_in_the_workers_it_sends_models_to(restore_setting):
    from floris_ekman_veer.plugin.floris_tools.parallel import WorkerDict

    floris_ekman_veer.silence_warnings()
    with caught() as records:
        FlorisModel(FARM).run()
    assert not of(records, floris_ekman_veer.FlorisEkmanVeerWarning)
    sent = pickle.dumps(WorkerDict({"farm": {}}))
    floris_ekman_veer.silence_warnings(None)
    assert package_warnings.ENVIRONMENT_VARIABLE not in os.environ
    pickle.loads(sent)  # what a worker does with the model it receives
    assert os.environ[package_warnings.ENVIRONMENT_VARIABLE] == "ignore"
    floris_ekman_veer.silence_warnings("ShallowBoundaryLayerWarning", floris_ekman_veer.ThrustLimitWarning)
    assert os.environ[package_warnings.ENVIRONMENT_VARIABLE] == \
        "ShallowBoundaryLayerWarning,ThrustLimitWarning"
    with pytest.raises(ValueError, match=r"unknown warning class\(es\) \['Shallow'\]"):
        floris_ekman_veer.silence_warnings("Shallow")


def test_environment_variable_silences_a_fresh_process():
    script = ("import floris_ekman_veer as f; from floris import FlorisModel; "
              f"FlorisModel({str(FARM)!r}).run()")
    env = {**os.environ, "PYTHONPATH": str(REPO), "FLORIS_EKMAN_VEER_WARNINGS": "ignore"}
    quiet = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True)
    env.pop("FLORIS_EKMAN_VEER_WARNINGS")
    loud = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True)
    assert quiet.returncode == loud.returncode == 0
    assert "Warning" not in quiet.stderr
    assert "ShallowBoundaryLayerWarning" in loud.stderr


def test_parallel_chunks_do_not_repeat_the_shallow_warning():
    from floris import ParFlorisModel

    fmodel = FlorisModel(FARM)
    fmodel.set(wind_speeds=[8.0, 9.0, 15.0, 16.0], wind_directions=[270.0] * 4,
               turbulence_intensities=[0.06] * 4)
    par = ParFlorisModel(fmodel, interface="multiprocessing", max_workers=2)
    with caught() as records:
        par.run()  # PAR-RUN
    # the parent counts all its conditions once, at the user's line
    (record,) = of(records, floris_ekman_veer.ShallowBoundaryLayerWarning)
    assert (record.filename, record.lineno) == (__file__, line_of("# PAR" "-RUN"))
    assert str(record.message).startswith("2 of 4 conditions (wind speeds 8 and 9 m/s at 90 m")
    chunks = par._preprocessing()
    assert len(chunks) == 2
    for fmodel_dict, _ in chunks:
        block = fmodel_dict["wake"]["wake_velocity_parameters"]["ekman_veer"]
        assert block["shallow_boundary_layer"] == "ignore"
    assert "shallow_boundary_layer" not in \
        par.core.as_dict()["wake"]["wake_velocity_parameters"]["ekman_veer"]


# ---------------------------------------------------------------------------- packaged inputs
def test_example_input_names_every_input_and_runs_from_any_directory(tmp_path, monkeypatch):
    names = {str(p.relative_to(REPO / "inputs").with_suffix("")) for p in (REPO / "inputs").rglob("*.yaml")}
    assert set(floris_ekman_veer.example_inputs()) == names
    for name in names:
        assert floris_ekman_veer.example_input(name).is_file()
        assert floris_ekman_veer.example_input(name + ".yaml") == floris_ekman_veer.example_input(name)
    with pytest.raises(ValueError, match=r"no input named 'farm'; the inputs are \[.*'farm_sbl6'"):
        floris_ekman_veer.example_input("farm")
    mast = floris_ekman_veer.example_input("site/synthetic_mast.csv")
    assert mast == REPO / "inputs" / "site" / "synthetic_mast.csv"
    assert mast.read_text().startswith("# SYNTHETIC")
    with pytest.raises(ValueError, match=r"no file 'site/none.csv' among the package's inputs"):
        floris_ekman_veer.example_input("site/none.csv")
    monkeypatch.chdir(tmp_path)
    fmodel = FlorisModel(floris_ekman_veer.example_input("sbl6"))  # includes turbines/...
    fmodel.run()
    assert np.all(fmodel.get_turbine_powers() > 0)


# ----------------------------------------------------------------------- calm and weak winds
@pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")  # SBL-6 at 9 m/s: h 125 m < rotor top, not tested here
def test_calm_bin_of_a_wind_rose_gives_zero_power():
    rose = WindRose(wind_directions=np.array([270.0, 280.0]), wind_speeds=np.array([0.0, 6.0, 12.0]),
                    ti_table=0.06)
    fmodel = FlorisModel(FARM)
    fmodel.set(wind_data=rose)
    fmodel.run()
    powers = fmodel.get_turbine_powers()  # (directions, speeds, turbines)
    assert np.all(powers[:, 0] == 0.0)
    moving = FlorisModel(FARM)
    moving.set(wind_data=WindRose(wind_directions=np.array([270.0, 280.0]),
                                  wind_speeds=np.array([6.0, 12.0]), ti_table=0.06))
    moving.run()
    np.testing.assert_allclose(powers[:, 1:], moving.get_turbine_powers(), rtol=1e-12)
    assert np.isfinite(fmodel.get_farm_AEP())


@pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")  # SBL-6 at 9 m/s: h 125 m < rotor top, not tested here
@pytest.mark.parametrize("wake", ["ekman_veer", "gauss"])
def test_sub_cut_in_speeds_no_abl_reaches_give_zero_power(wake):
    """SBL-6 stability has no boundary layer (h >= 10 m) with 0.5-2 m/s at 90 m; the NREL 5 MW
    makes no power below 2.9 m/s: those conditions are at rest, the others are unchanged."""
    config = load_yaml(str(FARM))
    config["wake"]["model_strings"].update(velocity_model=wake, deflection_model=wake,
                                           combination_model="fls" if wake == "ekman_veer"
                                           else "sosfs")
    speeds = [0.0, 0.5, 1.0, 2.0, 9.0]
    with pytest.raises(ValueError, match="no ABL|the model accepts"):
        EkmanABL.from_reference_wind(0.5, 90.0, **SBL6)
    fmodel = FlorisModel(config)
    fmodel.set(wind_speeds=speeds, wind_directions=[270.0] * 5, turbulence_intensities=[0.06] * 5)
    with np.errstate(all="raise"):  # FLORIS's divisions by the zero inflow stay quiet
        fmodel.run()
    powers = fmodel.get_turbine_powers()
    assert np.all(powers[:4] == 0.0) and np.all(np.isfinite(powers))
    alone = FlorisModel(config)
    alone.run()  # 9 m/s
    np.testing.assert_allclose(powers[4], alone.get_turbine_powers()[0], rtol=1e-12)


def test_unreachable_speed_above_cut_in_is_still_an_error():
    config = load_yaml(str(FARM))
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"] = dict(
        STABLE_ATMOSPHERE, cooling_rate=-3.0)  # 4 m/s: h below 10 m; 6 m/s: h = 17 m
    fmodel = FlorisModel(config)
    with pytest.raises(ValueError, match=r"4 m/s at 90 m at condition 1 .*the model accepts"):
        fmodel.set(wind_speeds=[2.0, 4.0, 6.0], wind_directions=[270.0] * 3,
                   turbulence_intensities=[0.06] * 3)


# ------------------------------------------------------------------------------------ layouts
def intersecting(x2=100.0):
    config = load_yaml(str(FARM))
    config["farm"].update(layout_x=[0.0, x2], layout_y=[0.0, 0.0])
    return config


def test_intersecting_rotors_of_a_given_layout_warn_and_run():
    with caught() as records:
        fmodel = FlorisModel(intersecting())
        fmodel.run()
    (record,) = of(records, floris_ekman_veer.TurbinePlacementWarning)
    assert "turbines 0 and 1 (100 m) would intersect" in str(record.message)
    assert np.all(np.isfinite(fmodel.get_turbine_powers()))


def test_coincident_turbines_are_still_refused():
    with pytest.raises(ValueError, match=r"turbines 0 and 1 are 0 m apart .*one place"):
        FlorisModel(intersecting(0.0))


@pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")  # SBL-6 at 9 m/s: h 125 m < rotor top, not tested here
# The optimiser packs the two turbines 1.6 D apart: the downstream rotor stands in the near wake's
# super-Gaussian (docs/wake_model.md#near-wake), deeper across it, at speeds where the NREL 5 MW's
# C_T passes the momentum limit: that warning is right and not what this test is about.
@pytest.mark.filterwarnings("ignore::floris_ekman_veer.ThrustLimitWarning")
def test_floris_layout_optimiser_and_turbine_plane_run_without_placement_warnings():
    from floris.flow_visualization import calculate_horizontal_plane_with_turbines
    from floris.optimization.layout_optimization.layout_optimization_scipy import (
        LayoutOptimizationScipy,
    )

    fmodel = FlorisModel(FARM)
    fmodel.set(layout_x=[0.0, 630.0], layout_y=[0.0, 0.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error", floris_ekman_veer.TurbinePlacementWarning)
        # planes with a turbine added at each point: points within a rotor radius of a turbine
        plane = calculate_horizontal_plane_with_turbines(
            fmodel, x_resolution=4, y_resolution=3, x_bounds=(-100.0, 700.0), y_bounds=(-60.0, 60.0))
        assert np.all(np.isfinite(plane.df.u.values))
        optimiser = LayoutOptimizationScipy(
            fmodel, boundaries=[(0.0, 0.0), (200.0, 0.0), (200.0, 200.0), (0.0, 200.0)],
            min_dist=126.0, optOptions={"maxiter": 3, "disp": False})
        optimiser.optimize()


def test_reference_height_minus_one_keeps_the_shallow_check():
    config = load_yaml(str(FARM))
    config["flow_field"]["reference_wind_height"] = -1
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["shallow_boundary_layer"] = "raise"
    with pytest.raises(ValueError, match=r"1 of 1 conditions .* condition 0: wind speed 9 m/s at 90 m"):
        FlorisModel(config)


def test_hub_in_the_roughness_sublayer_warns():
    config = load_yaml(str(FARM))
    atmosphere = config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    # neutral: the hub in the roughness sublayer, not the stability, is tested here
    atmosphere.update(roughness_length=40.0, cooling_rate=0.0)
    with caught() as records:
        FlorisModel(config)
    (record,) = of(records, floris_ekman_veer.TurbinePlacementWarning)
    assert "9 turbine(s)" in str(record.message) and "roughness sublayer" in str(record.message)


@pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")  # SBL-6 at 9 m/s: h 125 m < rotor top, not tested here
def test_heterogeneous_map_with_the_atmosphere_warns_how_they_combine():
    config = load_yaml(str(FARM))
    config["flow_field"]["heterogeneous_inflow_config"] = {
        "x": [-1000.0, -1000.0, 3000.0, 3000.0], "y": [-1000.0, 3000.0, -1000.0, 3000.0],
        "speed_multipliers": [[1.0, 1.1, 1.0, 1.1]],
    }
    with caught() as records:
        fmodel = FlorisModel(config)
        fmodel.run()
    (record,) = of(records, floris_ekman_veer.HeterogeneousInflowWarning)
    assert "solved from flow_field.wind_speeds" in str(record.message)
    # the profile is multiplied: the faster side of the farm makes more power
    powers = fmodel.get_turbine_powers()[0]
    plain = FlorisModel(FARM)
    plain.run()
    assert powers[2] > plain.get_turbine_powers()[0, 2]


def test_empty_condition_list_is_a_clear_error():
    fmodel = FlorisModel(FARM)
    fmodel.set(wind_speeds=[], wind_directions=[], turbulence_intensities=[])
    with pytest.raises(ValueError, match="no condition to run"):
        fmodel.run()


# ---------------------------------------------------------------------------- array-likes
@pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")  # SBL-6 at 9 m/s: h 125 m < rotor top, not tested here
def test_pandas_series_are_accepted_like_arrays():
    speeds = pd.Series([8.0, 9.0, 11.0])
    from_series = EkmanABL.from_reference_wind(speeds, 90.0, **SBL6)
    from_array = EkmanABL.from_reference_wind(speeds.to_numpy(), 90.0, **SBL6)
    np.testing.assert_array_equal(from_series.boundary_layer_height, from_array.boundary_layer_height)
    config = load_yaml(str(FARM))
    atmosphere = config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    atmosphere["cooling_rate"] = pd.Series([-1.0, -0.5])
    config["flow_field"].update(wind_speeds=[9.0, 9.0], wind_directions=[270.0] * 2,
                                turbulence_intensities=[0.06] * 2)
    FlorisModel(config).run()
    with pytest.raises(ValueError, match="real number"):
        EkmanABL(geostrophic_wind=pd.Series(["10", "12"]), latitude=50.0, roughness_length=0.1)


def test_shape_mismatch_names_both_inputs():
    with pytest.raises(ValueError, match=r"geostrophic_wind \(shape \(2,\)\) and roughness_length "
                                         r"\(shape \(3,\)\) do not broadcast together"):
        EkmanABL(geostrophic_wind=[10.0, 12.0], latitude=50.0, roughness_length=[0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match=r"speed \(shape \(2,\)\) and height \(shape \(3,\)\)"):
        EkmanABL.from_reference_wind([8.0, 9.0], [80.0, 90.0, 100.0], **SBL6)


def test_millimetre_deep_boundary_layer_is_refused():
    with pytest.raises(ValueError, match=r"h = 0.0132 m deep, below the 10 m the model accepts"):
        EkmanABL.from_reference_wind(10.3, 90.0, latitude=-68.58, roughness_length=0.0025,
                                     surface_heat_flux=-0.0908)
    assert copy.deepcopy(SBL6)  # the shipped input is untouched


def test_quick_start_example_converts_floris_defaults_and_shows_what_veer_changes():
    import quick_start  # examples/ is on pytest's pythonpath (pyproject.toml)
    m1 = quick_start.powers(quick_start.veer_input())
    m2 = quick_start.powers(quick_start.veer_input(veer=False))
    # the front turbine sees the same inflow; veer shears the wakes past the turbines behind
    np.testing.assert_array_equal(m1[:, 0], m2[:, 0])
    assert np.all(m1[:, 1:] > m2[:, 1:])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", floris_ekman_veer.ModelSettingsWarning)
        gch = quick_start.powers(quick_start.veer_input(gch=True), yaw_first=20.0)
    yawed = quick_start.powers(quick_start.veer_input(), yaw_first=20.0)
    np.testing.assert_array_equal(gch[:, 0], yawed[:, 0])
    # GCH's additions act behind the yawed rotor, mostly on the last turbine (+1.60 % and +1.54 %
    # with the cumulative wake; +3 % and +4.5 % on the plain sum, which recovered less)
    np.testing.assert_allclose(gch[:, 1], yawed[:, 1], rtol=1e-5)
    assert np.all(gch[:, 2] / yawed[:, 2] - 1.0 > 0.012)


DASK_SCRIPT = '''
import os
import floris_ekman_veer
from floris import FlorisModel

def setting():
    return os.environ.get("FLORIS_EKMAN_VEER_WARNINGS")

def main():
    from distributed import Client, LocalCluster
    from tests.conftest import own_turbine
    fmodel = FlorisModel(own_turbine(floris_ekman_veer.example_input("farm_sbl6")))
    fmodel.set(wind_directions=[270.0] * 2, wind_speeds=[3.5, 9.0], turbulence_intensities=[0.06] * 2)
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0") as cluster, \\
            Client(cluster) as client:
        floris_ekman_veer.silence_warnings()  # after the workers started
        par = floris_ekman_veer.ParFlorisModel(fmodel, interface="dask", client=client)
        par.run()  # 3.5 m/s: the thrust limit acts on a worker, silenced
        silenced = sorted(set(client.run(setting).values()))
        import sys, time
        time.sleep(0.5)  # the workers' stderr reaches ours through their nannies
        print("SILENCED-RUN-DONE", file=sys.stderr, flush=True)
        floris_ekman_veer.silence_warnings(None)
        par.run()
        restored = sorted(set(map(str, client.run(setting).values())))
        time.sleep(0.5)
    print("RESULT", silenced, restored)

if __name__ == "__main__":
    main()
'''


def test_silencing_reaches_dask_workers_started_before_it(tmp_path):
    pytest.importorskip("distributed")
    script = tmp_path / "dask_silence.py"
    script.write_text(DASK_SCRIPT)
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    env.pop(package_warnings.ENVIRONMENT_VARIABLE, None)
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "RESULT ['ignore'] ['None']" in done.stdout
    silenced_run, _, restored_run = done.stderr.partition("SILENCED-RUN-DONE")
    assert "ThrustLimitWarning" not in silenced_run
    assert "ThrustLimitWarning" in restored_run  # the worker running 3.5 m/s says it again
