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


def fixed_obukhov_night(speeds):
    """inputs/farm_night.yaml with its cooling rate replaced by a "stable" class L = 100 m fixed
    across wind speeds (the input until issue 39), at ``speeds`` from 270 deg."""
    config = load_yaml(INPUTS / "farm_night.yaml")
    atmosphere = config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    del atmosphere["cooling_rate"]
    atmosphere.update(obukhov_length=100.0, outside_domain="limit")
    fmodel = FlorisModel(config)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", floris_ekman_veer.ShallowBoundaryLayerWarning)
        fmodel.set(wind_speeds=speeds, wind_directions=[270.0] * len(speeds),
                   turbulence_intensities=[0.06] * len(speeds))
    return fmodel


def test_the_shipped_night_keeps_the_nrel_rotor_below_h_from_8_m_s():
    speeds = [8.0, 9.0, 10.0, 12.0, 25.0]
    report = floris_ekman_veer.validity_report(farm("farm_night", speeds))
    atmosphere = load_yaml(INPUTS / "farm_night.yaml")["wake"]["wake_velocity_parameters"][
        "ekman_veer"]["atmosphere"]
    assert atmosphere["cooling_rate"] == -0.25  # the paper's SBL-3 forcing, fixed across speeds
    abl = EkmanABL.from_reference_wind(np.array(speeds), 90.0, **atmosphere)
    np.testing.assert_allclose(report.boundary_layer_height, abl.boundary_layer_height, rtol=1e-12)
    np.testing.assert_allclose(report.veer_across_rotor_deg,
                               abl.wind_direction_change(90.0 - 62.94, 90.0 + 62.94), rtol=1e-12)
    assert report.rotor_top.iloc[0] == pytest.approx(153.0, abs=0.1)
    assert np.all(report.boundary_layer_height > 153.0)
    assert report.boundary_layer_height.iloc[0] == pytest.approx(196.7, abs=0.1)
    # A veered night at light winds that turns near-neutral as the wind grows (the cooling
    # stays, the layer deepens): 25 deg across the rotor at 8 m/s, 14 at 9, none at 25 m/s.
    veer = report.veer_across_rotor_deg.to_numpy()
    assert np.all(np.diff(veer) < 0) and 24.0 < veer[0] < 26.0 and 13.0 < veer[1] < 14.5
    assert abs(veer[-1]) < 2.0
    iu = report.turbulence_intensity.to_numpy()
    assert np.all(np.diff(iu) > 0) and 0.035 < iu[0] < 0.045 and 0.11 < iu[-1] < 0.13
    # Every column by hand: Ro = u*/(f z0), h / rotor top, H = rho c_p Q0 with Q0 = C_r h
    # (C_r in K/h) and rho c_p = c_p p0/(R_d Theta0) = 1005 * 1e5/(287.05 * 265) J/(m^3 K),
    # L = -u*^3 Theta0/(kappa g Q0).
    u_star, h = abl.friction_velocity, abl.boundary_layer_height
    np.testing.assert_allclose(report.friction_rossby_number, u_star / (1e-4 * 0.1), rtol=1e-12)
    np.testing.assert_allclose(report.h_over_rotor_top, report.boundary_layer_height
                               / report.rotor_top, rtol=1e-12)
    rho_cp = 1005.0 * 1e5 / (287.05 * 265.0)
    q0 = -0.25 / 3600.0 * h
    np.testing.assert_allclose(report.sensible_heat_flux, rho_cp * q0, rtol=1e-9)
    np.testing.assert_allclose(report.obukhov_length, -u_star**3 * 265.0 / (0.41 * 9.81 * q0),
                               rtol=1e-9)
    # SBL-5 at 8 m/s, SBL-4 at 9 m/s, weaker from 10 m/s; u*/(f z0) below the LES's 3.39e4 at
    # 8 m/s and above its 6.27e4 at 25 m/s; h < 1.33 x rotor top at 8 m/s.
    assert list(report.stability_class) == ["SBL-5", "SBL-4", "SBL-3", "SBL-3", "SBL-2"]
    assert list(report.wake_validated_stability) == [True, True, False, False, False]
    assert list(report.rossby_in_range) == [False, True, True, True, False]
    assert list(report.deep_enough) == [False, True, True, True, True]
    assert list(report.inside_envelope) == [False, True, False, False, False]


def test_the_shipped_night_is_shallow_only_below_8_m_s_and_runs_finite_there():
    """At 3-7 m/s the -0.25 K/h night's h (38-133 m) is below the 153 m rotor top: reported
    per condition, one ShallowBoundaryLayerWarning at the run counting them, finite powers."""
    speeds = np.arange(3.0, 9.01, 1.0)
    report = floris_ekman_veer.validity_report(farm("farm_night", list(speeds)))
    np.testing.assert_array_equal(report.h_above_rotor_top, speeds >= 8.0)
    np.testing.assert_allclose(report.boundary_layer_height[:5], [38.4, 61.3, 87.3, 99.9, 132.5],
                               atol=0.05)
    fmodel = FlorisModel(INPUTS / "farm_night.yaml")
    fmodel.set(wind_speeds=speeds, wind_directions=np.full(speeds.size, 270.0),
               turbulence_intensities=np.full(speeds.size, 0.06))
    with pytest.warns(floris_ekman_veer.ShallowBoundaryLayerWarning, match="5 of 7") as caught:
        fmodel.run()
    assert len([w for w in caught
                if issubclass(w.category, floris_ekman_veer.ShallowBoundaryLayerWarning)]) == 1
    power = fmodel.get_farm_power()
    assert np.all(np.isfinite(power)) and np.all(np.diff(power) > 0)


def test_the_shipped_night_is_physical_at_every_speed_without_a_limit():
    """inputs/farm_night.yaml gives a cooling rate, with no outside_domain policy: from cut-in
    to cut-out its heat flux stays inside the physical domain (-3.5 to -164 W/m^2), nothing is
    limited, and L grows with the wind; a fixed L = 100 m leaves the domain from 20 m/s."""
    atmosphere = load_yaml(INPUTS / "farm_night.yaml")["wake"]["wake_velocity_parameters"][
        "ekman_veer"]["atmosphere"]
    assert "outside_domain" not in atmosphere  # the default, refuse
    speeds = list(np.arange(3.0, 25.01, 1.0))
    report = floris_ekman_veer.validity_report(farm("farm_night", speeds))
    heat = report.sensible_heat_flux.to_numpy()
    assert not report.stability_limited.any()
    assert np.all((heat < 0.0) & (heat > -300.0)) and np.all(np.diff(heat) < 0)
    assert heat[0] == pytest.approx(-3.52, abs=0.01) and heat[-1] == pytest.approx(-164.0, abs=0.1)
    assert np.all(np.diff(report.obukhov_length) > 0)
    fixed = floris_ekman_veer.validity_report(fixed_obukhov_night(speeds))
    np.testing.assert_array_equal(fixed.stability_limited, np.array(speeds) >= 20.0)


def test_the_sbl6_farm_is_outside_and_the_summary_says_so():
    """inputs/farm_sbl6.yaml, the paper's SBL-6 by its cooling rate (-1 K/h): at 6-12 m/s more
    stable than SBL-6 (h 43-122 m, below the rotor top), inside only at 14 and 15 m/s."""
    report = floris_ekman_veer.validity_report(farm("farm_sbl6"))
    assert list(report.stability_class) == ["beyond SBL-6"] * 4
    assert not report.wake_validated_stability.any() and not report.deep_enough.any()
    assert not report.inside_envelope.any() and not report.h_above_rotor_top.any()
    line = validity_summary(report, "farm_sbl6")
    assert line.startswith("farm_sbl6: 0 of 4 conditions inside")
    assert "OUTSIDE at 6, 8, 10, 12 m/s" in line and "h below 1.33 x rotor top" in line
    assert "stability not among" in line
    strong = floris_ekman_veer.validity_report(farm("farm_sbl6", [13.0, 14.0, 15.0, 16.0]))
    assert list(strong.inside_envelope) == [False, True, True, False]


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
    report = floris_ekman_veer.validity_report(fixed_obukhov_night([3.0, 19.0, 19.7]),
                                               rossby_range=(1e3, 1e6))
    assert list(report.inside_envelope) == [False, True, False]
    # h < 1.33 rotor top; mu > 169 at 19.7 m/s (H = -296 W/m^2, inside the physical domain)
    assert report.stability_parameter.iloc[2] > MU_ENVELOPE
    assert list(report.stability_class) == ["SBL-2", "SBL-6", "beyond SBL-6"]
    # The LES's own range: 19 m/s has u*/(f z0) = 6.7e4 > 6.27e4.
    default = floris_ekman_veer.validity_report(fixed_obukhov_night([19.0]))
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
    conditions = dict(wind_directions=[270.0, 275.0], wind_speeds=[9.0, 9.0],
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
                 wind_directions=directions, wind_speeds=[9.0] * len(directions),
                 turbulence_intensities=[0.06] * len(directions))
        report = floris_ekman_veer.validity_report(farm)
        assert report.near_wake_beyond_paper.tolist() == expected
        assert report.inside_envelope.all()
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["near_wake"] = "potential_core"
    paper = FlorisModel(config)
    paper.set(layout_x=[0.0, 3.0 * d], layout_y=[0.0, 0.0], wind_directions=[270.0],
              wind_speeds=[9.0], turbulence_intensities=[0.06])
    assert not floris_ekman_veer.validity_report(paper).near_wake_beyond_paper.any()
