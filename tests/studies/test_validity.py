"""floris_ekman_veer.validity_report: each condition against the paper's validated envelope
(wake-validated stability, h / rotor top, friction Rossby number; studies/validity.py,
docs/yaw_steering.md#the-validated-envelope)."""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel
from floris.utilities import load_yaml

import day_and_night  # examples/ is on pytest's pythonpath (pyproject.toml)
import floris_ekman_veer
from floris_ekman_veer import EkmanABL
from floris_ekman_veer.studies.validity import (
    MIN_H_OVER_ROTOR_TOP,
    MU_ENVELOPE,
    ROSSBY_RANGE,
    TABLE1,
    stability_class,
    validity_summary,
)

INPUTS = Path(__file__).resolve().parents[2] / "inputs"
SPEEDS = [6.0, 8.0, 10.0, 12.0]


def farm(name, speeds=SPEEDS):
    """The shipped input ``name`` at ``speeds`` from 270 deg, as examples/day_and_night.py runs it."""
    return day_and_night.farm(name, speeds)


def test_the_shipped_night_keeps_the_nrel_rotor_below_h_at_6_to_12_m_s():
    report = floris_ekman_veer.validity_report(farm("farm_night"))
    atmosphere = load_yaml(INPUTS / "farm_night.yaml")["wake"]["wake_velocity_parameters"][
        "ekman_veer"]["atmosphere"]
    assert atmosphere["obukhov_length"] == 100.0  # the forcing, fixed across wind speeds
    abl = EkmanABL.from_reference_wind(np.array(SPEEDS), 90.0, **atmosphere)
    np.testing.assert_allclose(report.boundary_layer_height, abl.boundary_layer_height, rtol=1e-12)
    np.testing.assert_allclose(report.veer_across_rotor_deg,
                               abl.wind_direction_change(90.0 - 62.94, 90.0 + 62.94), rtol=1e-12)
    assert report.rotor_top.iloc[0] == pytest.approx(153.0, abs=0.1)
    assert np.all(report.boundary_layer_height > 153.0)
    # A veered night, not a neutral one: 15-23 deg across the rotor, I_u 4-5 %.
    assert np.all((report.veer_across_rotor_deg > 14.0) & (report.veer_across_rotor_deg < 24.0))
    assert np.all((report.turbulence_intensity > 0.04) & (report.turbulence_intensity < 0.055))
    # Every column by hand: Ro = u*/(f z0), h / rotor top, H = -rho c_p u*^3 Theta0/(kappa g L)
    # with rho c_p = c_p p0/(R_d Theta0) = 1005 * 1e5/(287.05 * 265) J/(m^3 K).
    u_star = abl.friction_velocity
    np.testing.assert_allclose(report.friction_rossby_number, u_star / (1e-4 * 0.1), rtol=1e-12)
    np.testing.assert_allclose(report.h_over_rotor_top, report.boundary_layer_height
                               / report.rotor_top, rtol=1e-12)
    rho_cp = 1005.0 * 1e5 / (287.05 * 265.0)
    np.testing.assert_allclose(report.sensible_heat_flux,
                               -rho_cp * u_star**3 * 265.0 / (0.41 * 9.81 * 100.0), rtol=1e-12)
    np.testing.assert_allclose(report.obukhov_length, 100.0, rtol=1e-12)
    # SBL-3 at 6 m/s (mu = 51), SBL-4 and SBL-5 above; below 10 m/s u*/(f z0) is below the
    # LES's 3.39e4.
    assert list(report.stability_class) == ["SBL-3", "SBL-4", "SBL-5", "SBL-5"]
    assert list(report.wake_validated_stability) == [False, True, True, True]
    assert list(report.rossby_in_range) == [False, False, True, True]
    assert list(report.inside_envelope) == [False, False, True, True]


def test_the_shipped_night_is_physical_at_the_speeds_it_claims():
    """inputs/farm_night.yaml claims 3-11 m/s: |H| <= 50 W/m^2 there, not at 12 m/s."""
    claimed = [3.0, 4.0, 6.0, 8.0, 10.0, 11.0]
    report = floris_ekman_veer.validity_report(farm("farm_night", claimed + [12.0]))
    heat = report.sensible_heat_flux.to_numpy()
    assert np.all((heat[:-1] < 0) & (heat[:-1] >= -50.0))
    assert heat[-2] == pytest.approx(-48.5, abs=0.1) and heat[-1] == pytest.approx(-63.2, abs=0.1)


def test_table1_sbl6_farm_is_outside_and_the_summary_says_so():
    report = floris_ekman_veer.validity_report(farm("farm_sbl6"))
    # mu = 148.49 is a validated stability, but h (90-190 m) is under 1.33 x the 153 m rotor
    # top and u*/(f z0) below the LES's at every speed.
    assert report.wake_validated_stability.all() and not report.deep_enough.any()
    assert not report.inside_envelope.any()
    line = validity_summary(report, "farm_sbl6")
    assert line.startswith("farm_sbl6: 0 of 4 conditions inside")
    assert "OUTSIDE at 6, 8, 10, 12 m/s" in line and "h below 1.33 x rotor top" in line
    assert "stability not among" not in line


def test_the_paper_cases_are_inside_exactly_where_their_wakes_were_validated():
    """CNBL and SBL-4..6 (Section 4.3) inside; SBL-1..3 (turbulence only) outside."""
    for name in ("cnbl", "sbl4", "sbl5", "sbl6"):
        report = floris_ekman_veer.validity_report(FlorisModel(INPUTS / f"{name}.yaml"))
        assert report.inside_envelope.all(), name
        assert report.stability_class.iloc[0] == name.upper().replace("SBL", "SBL-"), name
    for name in ("sbl1", "sbl2", "sbl3"):
        report = floris_ekman_veer.validity_report(FlorisModel(INPUTS / f"{name}.yaml"))
        assert report.stability_class.iloc[0] == name.upper().replace("SBL", "SBL-"), name
        assert not report.wake_validated_stability.any() and not report.inside_envelope.any()
    # The two SBL-6: Table 1's mu and the cooling-rate closure's.
    assert MU_ENVELOPE == pytest.approx(169.0, abs=0.1)
    # Both readings of every Table 1 case fall in its own class.
    assert list(stability_class([case[0] for case in TABLE1.values()])) == list(TABLE1)
    assert list(stability_class([0.0, 8.20, 28.64, 51.56, 72.71, 92.90, 169.0])) == list(TABLE1)
    assert ROSSBY_RANGE == pytest.approx((3.39e4, 6.2654e4), rel=1e-4)
    assert MIN_H_OVER_ROTOR_TOP == pytest.approx(199.05 / 150.0, rel=1e-4)


def test_the_convective_day_is_flagged_beyond_the_paper():
    report = floris_ekman_veer.validity_report(farm("farm_day", [3.0, 8.0, 25.0]))
    assert list(report.stability_class) == ["convective"] * 3
    assert not report.wake_validated_stability.any() and not report.inside_envelope.any()
    np.testing.assert_allclose(report.sensible_heat_flux, 150.0, rtol=1e-12)  # the forcing
    np.testing.assert_allclose(report.boundary_layer_height, 1500.0)  # z_i
    assert np.all(report.obukhov_length < 0)
    line = validity_summary(report, "farm_day")
    assert line.startswith("farm_day: 0 of 3 conditions inside")
    assert "convective: beyond the paper" in line


def test_stability_beyond_sbl6_is_outside():
    # With the Rossby-number check widened, stability and depth alone decide.
    report = floris_ekman_veer.validity_report(farm("farm_night", [3.0, 19.0, 19.7]),
                                               rossby_range=(1e3, 1e6))
    assert list(report.inside_envelope) == [False, True, False]
    # h < 1.33 rotor top; mu > 169 at 19.7 m/s (H = -296 W/m^2, inside the physical domain)
    assert report.stability_parameter.iloc[2] > MU_ENVELOPE
    assert list(report.stability_class) == ["SBL-2", "SBL-6", "beyond SBL-6"]
    # The LES's own range: 19 m/s has u*/(f z0) = 6.7e4 > 6.27e4.
    default = floris_ekman_veer.validity_report(farm("farm_night", [19.0]))
    assert not default.rossby_in_range.iloc[0] and not default.inside_envelope.iloc[0]


@pytest.mark.parametrize("bad", [(6e4, 3e4), (0.0, 1e4), (-1.0, 1e4)])
def test_bad_rossby_range_raises(bad):
    with pytest.raises(ValueError, match=r"validity_report: rossby_range must be two positive "
                                         r"numbers \(low, high\) with low < high; got"):
        floris_ekman_veer.validity_report(farm("farm_night", [10.0]), rossby_range=bad)


def test_without_atmosphere_raises():
    config = copy.deepcopy(load_yaml(INPUTS / "farm_sbl6.yaml"))
    del config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    config["wake"]["model_strings"].update(velocity_model="gauss", deflection_model="gauss")
    with pytest.raises(ValueError, match="validity_report: the model has no atmosphere"):
        floris_ekman_veer.validity_report(FlorisModel(config))


def test_farm_coupling_is_flagged_beyond_the_paper():
    """A farm with the array coupling (the shipped default) is flagged beyond the paper's
    single-wake validation, every condition alike, without changing inside_envelope; a single
    turbine, or the paper's ambient k_w with free-stream deficits, is not."""
    config = load_yaml(floris_ekman_veer.example_input("farm_night"))
    conditions = dict(wind_directions=[270.0, 270.0], wind_speeds=[10.0, 11.0],
                      turbulence_intensities=[0.06, 0.06])
    farm = FlorisModel(config)
    farm.set(**conditions)
    report = floris_ekman_veer.validity_report(farm)
    assert report.farm_coupling_beyond_paper.tolist() == [True, True]
    assert report.inside_envelope.tolist() == [True, True]
    single = FlorisModel(config)
    single.set(layout_x=[0.0], layout_y=[0.0], **conditions)
    assert not floris_ekman_veer.validity_report(single).farm_coupling_beyond_paper.any()
    config["wake"]["wake_velocity_parameters"]["ekman_veer"].update(
        wake_expansion="ambient", deficit_velocity="free_stream")
    config["wake"]["model_strings"]["combination_model"] = "sosfs"
    paper = FlorisModel(config)
    paper.set(**conditions)
    assert not floris_ekman_veer.validity_report(paper).farm_coupling_beyond_paper.any()
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["wake_superposition"] = "cumulative"
    config["wake"]["model_strings"]["combination_model"] = "fls"
    cumulative = FlorisModel(config)
    cumulative.set(**conditions)
    assert floris_ekman_veer.validity_report(cumulative).farm_coupling_beyond_paper.all()


def test_rotors_inside_a_potential_core_are_flagged_with_the_near_wake():
    """near_wake_beyond_paper: a row 3 D apart along the wind puts the second rotor inside the
    first's potential core (x0 up to ~5 D at the k_w floor), flagged with the default
    super-Gaussian near wake and not with the paper's potential core; the same row across the
    wind (0 deg), or 8 D apart, is not flagged."""
    config = load_yaml(floris_ekman_veer.example_input("farm_night"))
    d = 126.0  # the NREL 5 MW of the farm inputs
    for spacing, directions, expected in ((3.0, [270.0, 0.0, 90.0], [True, False, True]),
                                          (8.0, [270.0], [False])):
        farm = FlorisModel(config)
        farm.set(layout_x=[0.0, spacing * d], layout_y=[0.0, 0.0],
                 wind_directions=directions, wind_speeds=[10.0] * len(directions),
                 turbulence_intensities=[0.06] * len(directions))
        report = floris_ekman_veer.validity_report(farm)
        assert report.near_wake_beyond_paper.tolist() == expected
        assert report.inside_envelope.all()
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["near_wake"] = "potential_core"
    paper = FlorisModel(config)
    paper.set(layout_x=[0.0, 3.0 * d], layout_y=[0.0, 0.0], wind_directions=[270.0],
              wind_speeds=[10.0], turbulence_intensities=[0.06])
    assert not floris_ekman_veer.validity_report(paper).near_wake_beyond_paper.any()
