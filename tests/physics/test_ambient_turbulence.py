"""The ambient turbulence factor (docs/atmosphere.md#ambient-turbulence): an EkmanABL input beyond
the paper that scales the model's I_u(z), Eq. (Iu_model), to a site's measured turbulence, and with
it the wake expansion rate k_w of Eq. (kw_CNBL_SBL_model) of the ekman_veer and bastankhah2014
wakes; the mean wind is not touched, and without it every number is the paper's bit for bit."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from floris import FlorisModel

import floris_ekman_veer
from floris_ekman_veer.atmosphere import turbulence as tb
from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.plugin.inflow.atmosphere_block import AtmosphereSpec, atmosphere_groups
from floris_ekman_veer.plugin.inflow.solve_cache import solve
from floris.utilities import load_yaml

from pathlib import Path

INPUTS = Path(__file__).resolve().parents[2] / "inputs"

NIGHT = dict(latitude=52.0, roughness_length=0.1, obukhov_length=150.0)


def make_config(model, atmosphere, wind_speeds, wind_directions):
    """inputs/farm_sbl6.yaml's first row (three NREL 5 MW 7 D apart) with ``model`` as the
    velocity model, ``atmosphere`` as its block and the conditions given."""
    config = load_yaml(INPUTS / "farm_sbl6.yaml")
    config["farm"]["layout_x"], config["farm"]["layout_y"] = [0.0, 882.0, 1764.0], [0.0] * 3
    config["wake"]["model_strings"]["velocity_model"] = model
    config["wake"]["wake_velocity_parameters"].setdefault("ekman_veer", {})["atmosphere"] = (
        dict(atmosphere))
    config["flow_field"].update(wind_speeds=list(wind_speeds),
                                wind_directions=list(wind_directions),
                                turbulence_intensities=[0.06] * len(wind_speeds))
    return config


def test_the_factor_scales_the_turbulence_intensity_and_k_w_by_hand():
    # I_u = sqrt(1.25 ln 3 + 0.6) 0.4/8 (h = 300 m, z = 100 m); with c = 1.3: c I_u
    i_u = math.sqrt(1.25 * math.log(3.0) + 0.6) * 0.05
    assert tb.streamwise_turbulence_intensity(100.0, 0.4, 300.0, 8.0, turbulence_factor=1.3) == (
        pytest.approx(1.3 * i_u, rel=1e-15))
    expected = (0.021**6 + (0.33 * 1.3 * i_u) ** 6) ** (1.0 / 6.0)
    assert tb.wake_expansion_rate(0.4, 300.0, 100.0, 8.0, turbulence_factor=1.3) == (
        pytest.approx(expected, rel=1e-14))
    # a factor of the floor's order leaves the floor: k_w -> 0.021 as c -> 0
    assert tb.wake_expansion_rate(0.4, 300.0, 100.0, 8.0, turbulence_factor=1e-3) == (
        pytest.approx(0.021, rel=1e-12))


def test_the_factor_scales_i_u_at_every_height_and_leaves_the_mean_wind():
    plain = EkmanABL.from_reference_wind(8.0, 90.0, **NIGHT)
    factors = np.array([0.8, 1.0, 1.2, 2.0])
    scaled = EkmanABL.from_reference_wind(8.0, 90.0, turbulence_factor=factors, **NIGHT)
    z = np.array([20.0, 60.0, 90.0, 150.0])[:, None]
    # the state is the same bits: the factor is no input of the drag law
    assert scaled.friction_velocity == plain.friction_velocity
    np.testing.assert_array_equal(plain.velocity(z), scaled.velocity(z))
    np.testing.assert_allclose(scaled.turbulence_intensity(z),
                               factors * plain.turbulence_intensity(z), rtol=1e-15)
    i_hub = float(plain.turbulence_intensity(90.0))
    np.testing.assert_allclose(
        scaled.wake_expansion_rate(90.0),
        (0.021**6 + (0.33 * factors * i_hub) ** 6) ** (1 / 6), rtol=1e-14)
    # a factor of 1 is the paper's I_u bit for bit
    assert scaled.turbulence_intensity(90.0)[1] == plain.turbulence_intensity(90.0)
    assert EkmanABL.from_reference_wind(8.0, 90.0, turbulence_factor=None,
                                        **NIGHT).turbulence_factor is None


@pytest.mark.parametrize("bad", [0.0, -1.2, 120.0, np.nan, np.inf])
def test_a_bad_factor_is_refused_naming_it_its_value_and_range(bad):
    with pytest.raises(ValueError, match=r"turbulence_factor.*> 0 and <= 10"):
        EkmanABL.from_reference_wind(8.0, 90.0, turbulence_factor=bad, **NIGHT)
    with pytest.raises(ValueError, match=r"got .* at condition 1"):
        EkmanABL.from_reference_wind(8.0, 90.0, turbulence_factor=[1.2, bad], **NIGHT)
    with pytest.raises(ValueError, match=r"turbulence_factor.*(number|real)"):
        EkmanABL.from_reference_wind(8.0, 90.0, turbulence_factor="1.2", **NIGHT)
    config = make_config("ekman_veer", {**NIGHT, "turbulence_factor": [1.1, bad]},
                         wind_speeds=(8.0, 9.0), wind_directions=(270.0, 270.0))
    with pytest.raises(ValueError, match=r"wake\.wake_velocity_parameters\.ekman_veer\.atmosphere"
                                         r"\.turbulence_factor.*> 0 and <= 10"):
        FlorisModel(config)


def _row(factor=None, alpha_prime=None, wake_expansion="ambient", model="ekman_veer"):
    """A row of three NREL 5 MW 5 D apart on the night atmosphere, two conditions."""
    atmosphere = dict(NIGHT) if factor is None else {**NIGHT, "turbulence_factor": factor}
    config = make_config(model, atmosphere, wind_speeds=(8.0, 10.0),
                         wind_directions=(270.0, 270.0))
    block = config["wake"]["wake_velocity_parameters"]
    name = config["wake"]["model_strings"]["velocity_model"]
    block.setdefault(name, {}).update(wake_expansion=wake_expansion)
    if alpha_prime is not None:
        block[name]["alpha_prime"] = alpha_prime
    fmodel = FlorisModel(config)
    fmodel.run()
    return fmodel


@pytest.mark.parametrize("model", ["ekman_veer", "bastankhah2014"])
def test_the_wake_of_a_factor_is_the_wake_of_alpha_prime_times_the_factor(model):
    # k_w = [floor^n + (alpha' c I_u)^n]^(1/n): with the ambient expansion the factor c acts as
    # alpha' c, computed independently by FLORIS with alpha_prime = 0.33 c.
    with_factor = _row([1.3, 1.3], model=model)
    with_alpha = _row(alpha_prime=0.33 * 1.3, model=model)
    plain = _row(model=model)
    np.testing.assert_allclose(with_factor.turbine_average_velocities,
                               with_alpha.turbine_average_velocities, rtol=1e-12)
    # more ambient turbulence: faster recovery, more wind at the waked rotors
    assert np.all(with_factor.turbine_average_velocities[:, 1:]
                  > plain.turbine_average_velocities[:, 1:] + 1e-3)
    np.testing.assert_array_equal(with_factor.turbine_average_velocities[:, 0],
                                  plain.turbine_average_velocities[:, 0])
    # a factor of 1 is the paper's wake bit for bit
    np.testing.assert_array_equal(_row([1.0, 1.0], model=model).turbine_average_velocities,
                                  plain.turbine_average_velocities)


def test_the_factor_scales_the_ambient_part_of_the_array_turbulence():
    fmodel = _row([1.0, 1.5], wake_expansion="array_turbulence")
    abl = solve(floris_ekman_veer.plugin.inflow.atmosphere_block.atmosphere_of(fmodel.core),
                fmodel.core.flow_field.wind_speeds, 90.0)
    velocity = fmodel.core.wake.velocity_model
    hub = np.full((2, 1, 1, 1), 90.0)
    speed = np.full((2, 1, 1, 1), [[[[8.0]]], [[[10.0]]]])
    i_u = abl.turbulence_intensity(90.0, reference_height=90.0).reshape(2, 1, 1, 1)
    # TI at the rotor 0.06 above FLORIS's 0.06 ambient plus an added 0.08: I^2 = I_0^2 + 0.08^2
    k_w = velocity.expansion_rate(abl, hub, speed, np.hypot(0.06, 0.08), 0.06)
    expected = (0.021**6 + (0.33 * np.hypot(i_u, 0.08)) ** 6) ** (1 / 6)
    np.testing.assert_allclose(k_w, expected, rtol=1e-12)
    assert i_u.reshape(-1)[1] == pytest.approx(
        1.5 * float(EkmanABL.from_reference_wind(10.0, 90.0, **NIGHT).turbulence_intensity(90.0)),
        rel=1e-12)


def test_the_block_carries_the_factor_through_key_slices_groups_and_validity():
    spec = AtmosphereSpec.from_mapping({**NIGHT, "turbulence_factor": [1.1, 1.1, 1.4]})
    assert spec.sliced([2]) == {**NIGHT, "turbulence_factor": [1.4]}
    assert spec.key != AtmosphereSpec.from_mapping({**NIGHT, "turbulence_factor": 1.1}).key
    config = make_config("ekman_veer", {**NIGHT, "turbulence_factor": [1.1, 1.1, 1.4]},
                         wind_speeds=(8.0, 9.0, 9.0), wind_directions=(270.0,) * 3)
    fmodel = FlorisModel(config)
    groups = atmosphere_groups(fmodel)
    assert [g[0]["turbulence_factor"] for g in groups] == [1.1, 1.4]
    assert [list(g[1]) for g in groups] == [[0, 1], [2]]
    report = floris_ekman_veer.validity_report(fmodel)
    assert report.ambient_turbulence_beyond_paper.all()
    plain = floris_ekman_veer.validity_report(_row())
    assert not plain.ambient_turbulence_beyond_paper.any()
    expected = 1.4 * float(EkmanABL.from_reference_wind(9.0, 90.0, **NIGHT).turbulence_intensity(
        float(np.mean(fmodel.core.farm.hub_heights))))
    assert report.turbulence_intensity.iloc[2] == pytest.approx(expected, rel=1e-12)


def test_uncertain_floris_model_carries_the_factor():
    from floris import UncertainFlorisModel

    config = make_config("ekman_veer", {**NIGHT, "turbulence_factor": [1.0, 1.6]},
                         wind_speeds=(8.0, 8.0), wind_directions=(270.0, 270.0))
    ufmodel = UncertainFlorisModel(copy.deepcopy(config), wd_std=3.0)
    ufmodel.run()
    powers = ufmodel.get_turbine_powers()
    # the same wind, more ambient turbulence in the second condition: the waked rotors gain
    assert powers[0, 0] == pytest.approx(powers[1, 0], rel=1e-12)
    assert np.all(powers[1, 1:] > powers[0, 1:])
