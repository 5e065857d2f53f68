"""A condition's result does not depend on what else is in its batch (ParFlorisModel chunks,
the optimisers' tiled conditions, a study split in two): bitwise, for the package's wake
models on rotor cells.

The cells' sums used to follow the batch: the rows a wake reaches were grouped by width and cut
into chunks over all conditions together, and each chunk's rows added into the cells in turn;
a condition alone (one group) summed its rows in another order than inside a batch (6 of 40
conditions differed in the last bits, <= 1.3e-15 relative). Now each row's stretches are summed
per row and added into the cells in row order (plugin/rotor/rotor.py), and the inflow's cell means
are segment sums, not a BLAS matrix product (plugin/rotor/rotor_cells.py).
"""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel
from floris.utilities import load_yaml

import floris_ekman_veer  # noqa: F401
from floris_ekman_veer.plugin.rotor import rotor

FARM = Path(__file__).resolve().parents[3] / "inputs" / "farm_sbl6.yaml"


def powers(fmodel, speeds, directions, yaw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fmodel.set(wind_speeds=speeds, wind_directions=directions,
                   turbulence_intensities=np.full(len(speeds), 0.06), yaw_angles=yaw)
        fmodel.run()
    return fmodel.get_turbine_powers()


@pytest.mark.parametrize("velocity_model", ["ekman_veer", "bastankhah2014"])
def test_condition_alone_equals_it_in_a_batch(velocity_model, monkeypatch):
    config = copy.deepcopy(load_yaml(FARM))
    config["wake"]["model_strings"]["velocity_model"] = velocity_model
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fmodel = FlorisModel(config)
    rng = np.random.default_rng(4)
    n = 12
    speeds, directions = rng.uniform(5.0, 14.0, n), rng.uniform(255.0, 285.0, n)
    yaw = rng.uniform(-25.0, 25.0, (n, 9))
    batch = powers(fmodel, speeds, directions, yaw)
    for i in range(n):
        alone = powers(fmodel, speeds[i:i + 1], directions[i:i + 1], yaw[i:i + 1])
        np.testing.assert_array_equal(alone[0], batch[i], err_msg=f"condition {i}")
    # Smaller chunks of rows (what a bigger batch gets): the same bits.
    monkeypatch.setattr(rotor, "ROW_CHUNK", 97)
    np.testing.assert_array_equal(powers(fmodel, speeds, directions, yaw), batch)
    monkeypatch.setattr(rotor, "PAIR_CHUNK", 5)
    np.testing.assert_array_equal(powers(fmodel, speeds[::-1], directions[::-1], yaw[::-1]),
                                  batch[::-1])
