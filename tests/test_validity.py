"""floris_ekman_veer.validity_report: each condition against the paper's CNBL..SBL-6 envelope
(coupling/validity.py, docs/yaw_steering.md#the-validated-envelope)."""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel
from floris.utilities import load_yaml

import floris_ekman_veer
from floris_ekman_veer import EkmanABL
from floris_ekman_veer.coupling.shallow import ShallowBoundaryLayerWarning
from floris_ekman_veer.coupling.validity import MU_ENVELOPE, validity_summary

INPUTS = Path(__file__).resolve().parents[1] / "inputs"
SPEEDS = [6.0, 8.0, 10.0, 12.0]


def farm(name, speeds=SPEEDS):
    fmodel = FlorisModel(INPUTS / f"{name}.yaml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        fmodel.set(wind_speeds=speeds, wind_directions=[270.0] * len(speeds),
                   turbulence_intensities=[0.06] * len(speeds))
    return fmodel


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
    assert np.all(report.boundary_layer_height > 153.0) and report.inside_envelope.all()
    # A veered night, not a neutral one: 15-23 deg across the rotor, I_u 4-5 %.
    assert np.all((report.veer_across_rotor_deg > 14.0) & (report.veer_across_rotor_deg < 24.0))
    assert np.all((report.turbulence_intensity > 0.04) & (report.turbulence_intensity < 0.055))


def test_table1_sbl6_farm_is_outside_and_the_summary_says_so():
    report = floris_ekman_veer.validity_report(farm("farm_sbl6"))
    assert list(report.inside_envelope) == [False, False, False, True]  # h < 153 m up to 10 m/s
    line = validity_summary(report, "farm_sbl6")
    assert line.startswith("farm_sbl6: 1 of 4 conditions inside")
    assert "OUTSIDE at 6, 8, 10 m/s" in line


def test_the_paper_cases_are_inside_and_the_day_everywhere():
    for name in ("cnbl", "sbl4", "sbl5", "sbl6"):
        assert floris_ekman_veer.validity_report(FlorisModel(INPUTS / f"{name}.yaml")) \
            .inside_envelope.all(), name
    assert floris_ekman_veer.validity_report(farm("farm_day", [3.0, 8.0, 25.0])) \
        .inside_envelope.all()
    # The two SBL-6: Table 1's mu and the cooling-rate closure's.
    assert MU_ENVELOPE == pytest.approx(169.0, abs=0.1)


def test_stability_beyond_sbl6_is_outside():
    report = floris_ekman_veer.validity_report(farm("farm_night", [3.0, 19.0, 20.0]))
    assert list(report.inside_envelope) == [False, True, False]  # h < rotor top; mu > 169
    assert report.stability_parameter.iloc[2] > MU_ENVELOPE


def test_without_atmosphere_raises():
    config = copy.deepcopy(load_yaml(INPUTS / "farm_sbl6.yaml"))
    del config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    config["wake"]["model_strings"].update(velocity_model="gauss", deflection_model="gauss")
    with pytest.raises(ValueError, match="validity_report: the model has no atmosphere"):
        floris_ekman_veer.validity_report(FlorisModel(config))
