"""Calm conditions in validity_report have no boundary layer (studies/validity.py), and a bad
warnings setting is refused when the package is imported (floris_ekman_veer/warnings.py,
docs/user_guide.md#warnings)."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from floris import FlorisModel

import floris_ekman_veer
from floris_ekman_veer.warnings import CLASSES, ENVIRONMENT_VARIABLE

REPO = Path(__file__).resolve().parents[1]


def report(speeds):
    fmodel = FlorisModel(floris_ekman_veer.example_input("farm_night"))
    fmodel.set(wind_directions=[270.0] * len(speeds), wind_speeds=speeds,
               turbulence_intensities=[0.06] * len(speeds))
    return floris_ekman_veer.validity_report(fmodel)


def test_calm_rows_are_at_rest_with_no_boundary_layer():
    both = report([0.0, 0.001, 9.0])
    alone = report([9.0])
    assert list(both["at_rest"]) == [True, True, False]
    for column in ("boundary_layer_height", "veer_across_rotor_deg", "turbulence_intensity",
                   "stability_parameter", "obukhov_length", "sensible_heat_flux",
                   "friction_rossby_number", "h_over_rotor_top"):
        assert np.isnan(both[column].iloc[0]) and np.isnan(both[column].iloc[1]), column
        assert both[column].iloc[2] == alone[column].iloc[0]
    assert list(both["stability_class"])[:2] == ["at rest", "at rest"]
    assert list(both["inside_envelope"]) == [False, False, True]
    assert list(both["wind_speed"]) == [0.0, 0.001, 9.0]
    assert not alone["at_rest"].any()
    from floris_ekman_veer.studies.validity import validity_summary

    line = validity_summary(both)
    assert "1 of 3 conditions inside" in line and "2 at rest" in line and "OUTSIDE" not in line


def test_a_bad_warnings_setting_is_refused_at_import():
    environment = dict(os.environ, **{ENVIRONMENT_VARIABLE: "Bogus"},
                       PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    run = subprocess.run([sys.executable, "-c", "import floris_ekman_veer"], env=environment,
                         capture_output=True, text=True, cwd=REPO)
    assert run.returncode != 0
    assert "unknown warning class(es) ['Bogus']; give 'ignore' or" in run.stderr
    assert all(name in run.stderr for name in CLASSES)
    environment[ENVIRONMENT_VARIABLE] = "ThrustLimitWarning"
    assert subprocess.run([sys.executable, "-c", "import floris_ekman_veer"], env=environment,
                          cwd=REPO).returncode == 0
