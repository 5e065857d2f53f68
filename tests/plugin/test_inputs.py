"""The shipped FLORIS inputs are the paper's cases (Table 1, Section 3) and run as documented."""

from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel
from floris.utilities import load_yaml

import floris_ekman_veer  # noqa: F401  (registers the models)
from floris_ekman_veer import EkmanABL

INPUTS = Path(__file__).resolve().parents[2] / "inputs"
#: Paper, Table 1 caption and Section 3.
PAPER_ATMOSPHERE = dict(
    coriolis_parameter=1.0e-4, roughness_length=0.1, brunt_vaisala_frequency=6.1e-3,
    reference_potential_temperature=265.0,
)
PAPER_G = 15.0


#: The paper's cases (Table 1) and their LES cooling rates C_r [K/h]; every file uses the
#: cooling-rate closure (Q0 = C_r h).
PAPER_COOLING_RATES = {
    "cnbl": 0.0, "sbl1": -0.03, "sbl2": -0.125, "sbl3": -0.25, "sbl4": -0.375, "sbl5": -0.5,
    "sbl6": -1.0,
}


# The stable atmospheres of these farms give, in some conditions and by design, boundary layers
# shallower than the NREL 5 MW rotor top (153 m); their ShallowBoundaryLayerWarning is not what
# is tested here (tests/physics/test_shallow_abl.py and tests/test_user_inputs_and_warnings.py are).
pytestmark = pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")


@pytest.mark.parametrize("case, cooling_rate", PAPER_COOLING_RATES.items())
def test_paper_case_inputs(case, cooling_rate):
    """The wind speed of each paper-case file is the 100 m speed of the paper's atmosphere with
    G = 15 m/s: solving the ABL back from it gives G = 15 m/s; one actuator disk (C_T' = 1.33,
    D = z_h = 100 m) at the origin, wind from 270 degrees, the ekman_veer models."""
    config = load_yaml(INPUTS / f"{case}.yaml")
    atmosphere = config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    # SBL-6's -1 K/h implies H < -300 W/m^2 from 22 m/s at 100 m: carried at the bound there
    # (tests/plugin/inflow/test_wind_roses.py), the paper's own speed untouched.
    policy = atmosphere.pop("outside_domain", "refuse")
    assert policy == ("limit" if case == "sbl6" else "refuse")
    assert atmosphere == {**PAPER_ATMOSPHERE, "cooling_rate": cooling_rate}
    flow = config["flow_field"]
    assert flow["wind_directions"] == [270.0] and flow["reference_wind_height"] == 100.0
    abl = EkmanABL.from_reference_wind(flow["wind_speeds"][0], 100.0, **atmosphere)
    assert abl.geostrophic_wind == pytest.approx(PAPER_G, rel=1e-9)
    # I_u(z_h) of that atmosphere, as the file says
    assert flow["turbulence_intensities"][0] == pytest.approx(
        float(abl.turbulence_intensity(100.0)), abs=5e-4
    )
    turbine = config["farm"]["turbine_type"][0]
    assert (turbine["rotor_diameter"], turbine["hub_height"]) == (100.0, 100.0)
    assert turbine["operation_model"] == "actuator-disk"
    assert turbine["power_thrust_table"]["ct_prime"] == 1.33
    assert config["farm"]["layout_x"] == [0.0] and config["farm"]["layout_y"] == [0.0]
    models = config["wake"]["model_strings"]
    assert models["velocity_model"] == models["deflection_model"] == "ekman_veer"

    fmodel = FlorisModel(INPUTS / f"{case}.yaml")
    fmodel.run()
    # the disk's un-yawed C_T = 4a(1 - a), a = C_T'/(4 + C_T')
    a = 1.33 / 5.33
    assert fmodel.get_turbine_thrust_coefficients()[0, 0] == pytest.approx(4 * a * (1 - a), rel=1e-12)


def test_farm_input_runs_each_model_by_name():
    """The farm input carries the blocks that make ekman_veer, bastankhah2014 (M-3), gauss, cc,
    jensen and turbopark selectable by changing model names (and, for gauss and cc, the
    combination to FLORIS's own sosfs: docs/user_guide.md#floriss-own-models-on-the-same-inflow),
    all on the Ekman inflow."""
    config = load_yaml(INPUTS / "farm_sbl6.yaml")
    assert config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"][
        "cooling_rate"] == -1.0  # the paper's SBL-6 by its cooling rate (Table 1)
    powers = {}
    for velocity, deflection in (
        ("ekman_veer", "ekman_veer"), ("bastankhah2014", "ekman_veer"), ("gauss", "gauss"),
        ("cc", "gauss"), ("jensen", "gauss"), ("turbopark", "gauss"),
    ):
        config["wake"]["model_strings"].update(
            velocity_model=velocity, deflection_model=deflection,
            combination_model="sosfs" if velocity in ("gauss", "cc") else "fls")
        # M-3 proper: no veer (at zero yaw, bastankhah2014 with the veer offset is M-1 exactly)
        m3 = velocity == "bastankhah2014"
        config["wake"]["wake_deflection_parameters"]["ekman_veer"].update(
            veer=not m3, yaw_deflection=not m3
        )
        fmodel = FlorisModel(config)
        fmodel.run()
        powers[velocity] = fmodel.get_turbine_powers()[0]
        assert np.all(np.isfinite(powers[velocity]))
        # the front column is unwaked: the same inflow, hence the same power, for every model
        np.testing.assert_allclose(powers[velocity][:3], powers["ekman_veer"][:3], rtol=1e-12)
    # the waked turbines differ between models
    assert len({round(p[4], 3) for p in powers.values()}) == len(powers)
