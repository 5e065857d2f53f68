"""FLORIS's own wake models on the package's inflow and veer-aware rotor: finite and
batch-independent over the yawed conditions a study meets (docs/yaw_steering.md).

The NREL 5 MW 3 x 3 farm of ``inputs/farm_sbl6.yaml`` (SBL-6) with FLORIS's gauss, GCH, cc,
jensen and turbopark set-ups (tests/conftest.py EXAMPLE_WAKES): wind speeds 3-25 m/s at 90 m,
any direction, yaw in +-30 deg per turbine. Where the table's C_T is near FLORIS's clip (light
wind), the veer-aware thrust used to push C_T above 1 and FLORIS's gauss took sqrt(1 - C_T):
NaN powers, and NaN only when another condition of the batch had points in the near wake
(FLORIS's batch-wide ``if np.sum(near_wake_mask)``).
"""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel
from floris.utilities import load_yaml
from hypothesis import given
from hypothesis import strategies as st

import floris_ekman_veer  # noqa: F401

from conftest import EXAMPLE_WAKES

FARM = Path(__file__).resolve().parents[3] / "inputs" / "farm_sbl6.yaml"
MODELS = ("gauss", "gch", "cc", "jensen", "turbopark")
N_TURBINES = 9


# The stable atmospheres of these farms give, in some conditions and by design, boundary layers
# shallower than the NREL 5 MW rotor top (153 m); their ShallowBoundaryLayerWarning is not what
# is tested here (tests/physics/test_shallow_abl.py and tests/test_user_inputs_and_warnings.py are).
pytestmark = pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")


def floris_model(wake):
    config = copy.deepcopy(load_yaml(FARM))
    choice = dict(EXAMPLE_WAKES[wake])
    gch = choice.pop("gch")
    config["wake"]["model_strings"].update(choice)
    defaults = FlorisModel.get_defaults()["wake"]
    for block in ("wake_velocity_parameters", "wake_deflection_parameters",
                  "wake_turbulence_parameters"):
        for name, parameters in defaults[block].items():
            config["wake"][block].setdefault(name, parameters)
    for flag in ("enable_secondary_steering", "enable_yaw_added_recovery",
                 "enable_transverse_velocities"):
        config["wake"][flag] = gch
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return FlorisModel(config)


@pytest.fixture(scope="module")
def models():
    return {name: floris_model(name) for name in MODELS}


def run(fmodel, speeds, directions, yaw):
    with warnings.catch_warnings():
        # Light-wind conditions: the package's shallow-layer warning, not the subject here.
        warnings.simplefilter("ignore")
        fmodel.set(wind_speeds=speeds, wind_directions=directions,
                   turbulence_intensities=np.full(len(speeds), 0.06), yaw_angles=yaw)
    with warnings.catch_warnings():
        # numpy's "invalid value" from an unphysical C_T must not happen: an error here.
        warnings.filterwarnings("error", message="invalid value", category=RuntimeWarning)
        fmodel.run()
        return fmodel.get_turbine_powers(), fmodel.get_turbine_thrust_coefficients()


# (to 19 m/s: above about 19.5 m/s SBL-6's fixed mu implies H < -300 W/m^2, outside the
# physical domain, docs/atmosphere.md#physical-domain)
conditions = st.integers(2, 4).flatmap(lambda n: st.tuples(
    st.lists(st.floats(3.0, 19.0), min_size=n, max_size=n),
    st.lists(st.floats(0.0, 359.9), min_size=n, max_size=n),
    st.lists(st.lists(st.floats(-30.0, 30.0), min_size=N_TURBINES, max_size=N_TURBINES),
             min_size=n, max_size=n),
    st.integers(0, n - 1),
))


@given(wake=st.sampled_from(MODELS), drawn=conditions)
def test_floris_models_finite_and_batch_independent(models, wake, drawn):
    speeds, directions, yaw = (np.array(x, dtype=float) for x in drawn[:3])
    alone = drawn[3]
    fmodel = models[wake]
    powers, thrust = run(fmodel, speeds, directions, yaw)
    assert np.all(np.isfinite(powers)) and np.all(powers >= 0.0)
    # The veer-aware C_T = ct_i / cos(beta) stays within FLORIS's own clip (0.9999).
    assert np.all(thrust <= 0.9999 * np.cos(np.radians(yaw)) * (1 + 1e-12))
    # The same conditions in reverse order, and one of them alone.
    reversed_powers, _ = run(fmodel, speeds[::-1], directions[::-1], yaw[::-1])
    np.testing.assert_array_equal(reversed_powers[::-1], powers)
    single, _ = run(fmodel, speeds[alone:alone + 1], directions[alone:alone + 1],
                    yaw[alone:alone + 1])
    np.testing.assert_array_equal(single[0], powers[alone])


def test_issue_reproducer_light_wind_batch():
    """The reproducer of the defect: 400 conditions at 3-8 m/s (rng 1) gave 98 NaN conditions
    with GCH, and condition 5 was finite alone but NaN next to condition 0."""
    rng = np.random.default_rng(1)
    wd = rng.uniform(0, 360, 400)
    ws = rng.uniform(3, 8, 400)
    yaw = rng.uniform(-30, 30, (400, 9))
    fmodel = floris_model("gch")
    powers, _ = run(fmodel, ws, wd, yaw)
    assert np.all(np.isfinite(powers))
    pair, _ = run(fmodel, ws[[0, 5]], wd[[0, 5]], yaw[[0, 5]])
    alone, _ = run(fmodel, ws[[5]], wd[[5]], yaw[[5]])
    np.testing.assert_array_equal(pair[1], alone[0])
    np.testing.assert_array_equal(powers[[0, 5]], pair)


# Light yawed winds (3-5 m/s) load rotors beyond max_thrust_coefficient by design: the
# ThrustLimitWarning is tested in tests/test_user_inputs_and_warnings.py, not here.
@pytest.mark.filterwarnings("ignore::floris_ekman_veer.ThrustLimitWarning")
def test_ekman_veer_light_wind_yawed_farm_raises_no_numpy_warning():
    """The ekman_veer model reads FLORIS's axial induction, 0.5/cos b (1 - sqrt(1 - ct_i cos b)),
    of the veer-aware thrust: with C_T above 1 numpy warned 'invalid value encountered in sqrt'
    (floris operation_models.py) once per optimiser run. Light-wind yawed conditions of the
    reproducer: no RuntimeWarning, finite inductions at most 1/2."""
    rng = np.random.default_rng(1)
    wd, ws, yaw = rng.uniform(0, 360, 400), rng.uniform(3, 8, 400), rng.uniform(-30, 30, (400, 9))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fmodel = FlorisModel(FARM)
    powers, thrust = run(fmodel, ws[:100], wd[:100], yaw[:100])
    with warnings.catch_warnings():
        warnings.filterwarnings("error", message="invalid value", category=RuntimeWarning)
        induction = fmodel.get_turbine_ais()
    assert np.all(np.isfinite(powers)) and np.all(np.isfinite(induction))
    assert np.all(induction * np.cos(np.radians(yaw[:100])) <= 0.5)
