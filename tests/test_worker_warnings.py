"""The package's warnings from ParFlorisModel workers reach the user as a serial run's do: once,
at the user's line, with the counts of the whole run (floris_ekman_veer/warnings.py,
plugin/parallel.py). Before, each worker printed its own, located at the pool's frame and
counting its share of the conditions."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from floris import FlorisModel

import floris_ekman_veer as fev
from floris_ekman_veer import ParFlorisModel
from floris_ekman_veer.warnings import ThrustLimitWarning


@pytest.fixture(scope="module")
def light_wind_farm():
    rng = np.random.default_rng(1)
    n = 40
    wd, ws, yaw = rng.uniform(0, 360, n), rng.uniform(3, 8, n), rng.uniform(-30, 30, (n, 9))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fmodel = FlorisModel(fev.example_input("farm_sbl6"))
        fmodel.set(wind_directions=wd, wind_speeds=ws, turbulence_intensities=np.full(n, 0.06),
                   yaw_angles=yaw)
    return fmodel


def caught(run):
    with warnings.catch_warnings(record=True) as records:
        warnings.simplefilter("always")
        run()
    return [w for w in records if issubclass(w.category, ThrustLimitWarning)]


def test_worker_warnings_are_said_once_at_the_users_line(light_wind_farm):
    serial = caught(light_wind_farm.run)
    parallel_model = ParFlorisModel(light_wind_farm, interface="multiprocessing",
                                    max_workers=2, n_wind_condition_splits=4)
    parallel = caught(parallel_model.run)
    assert len(serial) == 1 and "of 40 conditions" in str(serial[0].message)
    assert len(parallel) == 1
    assert str(parallel[0].message) == str(serial[0].message)
    assert parallel[0].filename == __file__
    np.testing.assert_array_equal(parallel_model.get_turbine_powers(),
                                  light_wind_farm.get_turbine_powers())
