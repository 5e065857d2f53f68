"""The first hour of a site engineer (plugin/wake_models/input_checks.py, registry.py,
studies/tables.py; docs/user_guide.md#floris-inputs-the-atmosphere-replaces): FLORIS inputs
the atmosphere replaces say so once, a model-name typo names the registered models and the
closest one, a result table prints whole, and the README's quick start is inside the validated
envelope without a warning."""

import re
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from floris import FlorisModel

import floris_ekman_veer
from floris_ekman_veer import ModelSettingsWarning
from floris_ekman_veer.studies.energy.energy_results import COLUMNS, AnnualEnergy
from floris_ekman_veer.registry import UnknownModelError

REPO = Path(__file__).resolve().parents[3]
ATMOSPHERE = {"latitude": 52.0, "roughness_length": 0.1, "cooling_rate": -0.25}


def defaults(velocity="ekman_veer", deflection="ekman_veer", **flow_field):
    config = FlorisModel.get_defaults()
    config["wake"]["model_strings"].update(velocity_model=velocity, deflection_model=deflection,
                                           combination_model="fls")
    config["wake"]["wake_velocity_parameters"]["ekman_veer"] = {"atmosphere": ATMOSPHERE}
    config["wake"].update(enable_secondary_steering=False, enable_yaw_added_recovery=False,
                          enable_transverse_velocities=False)
    config["flow_field"].update(reference_wind_height=90.0, **flow_field)
    return config


#: The ekman_veer wake model's notice that FLORIS's turbulence intensities are not its ambient
#: turbulence (test_floris_turbulence_intensities_are_said_unused_by_ekman_veer).
TURBULENCE_NOTICE = "flow_field.turbulence_intensities"


def settings_warnings(config, repeat=2, intensities=(0.06, 0.06), turbulence_notice=False):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for _ in range(repeat):
            fmodel = FlorisModel(config)
            fmodel.set(wind_speeds=[8.0, 9.0], wind_directions=[270.0] * 2,
                       turbulence_intensities=list(intensities))
            fmodel.run()
    return [str(w.message) for w in caught if issubclass(w.category, ModelSettingsWarning)
            and (turbulence_notice or not str(w.message).startswith(TURBULENCE_NOTICE))]


def test_floris_turbulence_intensities_are_said_unused_by_ekman_veer():
    """ekman_veer takes I_u from the atmosphere: FLORIS's TI changes none of its powers (0.02,
    0.06, 0.15), and one ModelSettingsWarning per study says so at the run, one constant TI
    included, with the values given and the atmosphere's own I_u; TI that are the atmosphere's
    I_u to three decimals are silent, and so are gauss on the same inflow and a shipped input's
    build."""
    constant = settings_warnings(defaults(wind_shear=0.0, wind_veer=0.0), turbulence_notice=True)
    assert len(constant) == 1
    assert constant[0].startswith("flow_field.turbulence_intensities (0.06) are not used as the "
                                  "ambient turbulence by the ekman_veer wake model: it takes I_u")
    own = re.search(r"its I_u at hub height here: ([\d.]+) to ([\d.]+)\)", constant[0])
    found = settings_warnings(defaults(wind_shear=0.0, wind_veer=0.0), intensities=(0.02, 0.15),
                              turbulence_notice=True)
    assert len(found) == 1
    assert found[0].startswith("flow_field.turbulence_intensities (0.02 to 0.15) are not used")
    # The atmosphere's own I_u at 8 and 9 m/s (the notice's range), to three decimals: silent.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        probe = FlorisModel(defaults(wind_shear=0.0, wind_veer=0.0))
        probe.set(wind_speeds=[8.0, 9.0], wind_directions=[270.0] * 2,
                  turbulence_intensities=[0.06, 0.06])
        probe.run()
    intensities = np.round(np.asarray(floris_ekman_veer.validity_report(probe)
                                      .turbulence_intensity, dtype=float), 3)
    np.testing.assert_allclose(sorted(intensities), [float(own[1]), float(own[2])], atol=6e-4)
    assert settings_warnings(defaults(wind_shear=0.0, wind_veer=0.0), intensities=intensities,
                             turbulence_notice=True) == []
    assert settings_warnings(defaults("gauss", "gauss", wind_shear=0.0, wind_veer=0.0),
                             turbulence_notice=True) == []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        FlorisModel(floris_ekman_veer.example_input("farm_night"))  # placeholder TI 0.06
    assert not [w for w in caught if str(w.message).startswith(TURBULENCE_NOTICE)]
    powers = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for ti in (0.02, 0.06, 0.15):  # one study: said once, at the first run
            fmodel = FlorisModel(defaults(wind_shear=0.0, wind_veer=0.0))
            fmodel.set(layout_x=[0.0, 630.0], layout_y=[0.0, 0.0], wind_speeds=[8.0],
                       wind_directions=[270.0], turbulence_intensities=[ti])
            fmodel.run()
            powers.append(fmodel.get_turbine_powers())
    notices = [str(w.message) for w in caught if str(w.message).startswith(TURBULENCE_NOTICE)]
    assert len(notices) == 1 and notices[0].startswith(
        "flow_field.turbulence_intensities (0.02) are not used")
    np.testing.assert_array_equal(powers[0], powers[1])
    np.testing.assert_array_equal(powers[0], powers[2])


def test_floris_wind_shear_and_veer_without_effect_warn_once():
    found = settings_warnings(defaults(wind_shear=0.3, wind_veer=10.0))
    assert len(found) == 2  # once each, over two builds, a set() and a run each
    assert re.match(r"flow_field.wind_shear = 0.3 is not used: the atmosphere \(wake.wake_velocity"
                    r"_parameters.ekman_veer.atmosphere\) gives the inflow's shear", found[0])
    assert found[1].startswith("flow_field.wind_veer = 10 deg is not used by the ekman_veer models")
    # ... and they are indeed without effect: the powers are those of zero shear and veer.
    powers = []
    for flow in (dict(wind_shear=0.3, wind_veer=10.0), dict(wind_shear=0.0, wind_veer=0.0)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fmodel = FlorisModel(defaults(**flow))
            fmodel.set(layout_x=[0.0, 630.0], layout_y=[0.0, 0.0], wind_speeds=[8.0],
                       wind_directions=[270.0], turbulence_intensities=[0.06])
            fmodel.run()
        powers.append(fmodel.get_turbine_powers())
    np.testing.assert_array_equal(powers[0], powers[1])


def test_zero_shear_and_veer_and_gauss_reading_its_veer_are_silent():
    assert settings_warnings(defaults(wind_shear=0.0, wind_veer=0.0)) == []
    # FLORIS's gauss reads wind_veer on the Ekman inflow: only the shear is said unused.
    found = settings_warnings(defaults("gauss", "gauss", wind_shear=0.12, wind_veer=5.0), 1)
    assert len(found) == 1 and found[0].startswith("flow_field.wind_shear = 0.12 is not used")
    # Without an atmosphere FLORIS's own inputs are FLORIS's business.
    plain = FlorisModel.get_defaults()
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelSettingsWarning)
        FlorisModel(plain)


@pytest.mark.parametrize("kind, typo, match", [
    ("velocity_model", "ekman_ver", "ekman_veer"),
    ("deflection_model", "ekmanveer", "ekman_veer"),
    ("velocity_model", "bastankhah2104", "bastankhah2014"),
])
def test_a_model_name_typo_names_the_registered_models_and_the_closest(kind, typo, match):
    config = defaults()
    config["wake"]["model_strings"][kind] = typo
    with pytest.raises(ValueError, match=rf"wake.model_strings.{kind}: no model named '{typo}' "
                                         rf"\(did you mean '{match}'\?\); the registered models "
                                         r"are \[.*'gauss'.*\]") as error:
        FlorisModel(config)
    assert isinstance(error.value, KeyError)  # what FLORIS raised, for code that catches it


def test_an_operation_model_typo_is_named_too():
    config = FlorisModel.get_defaults()
    config["farm"]["turbine_type"] = ["nrel_5MW"]
    fmodel = FlorisModel(config)
    with pytest.raises(UnknownModelError, match=r"no model named 'actuator-dsk' \(did you mean "
                                                r"'actuator-disk'\?\)"):
        fmodel.set_operation_model("actuator-dsk")


def test_a_result_table_prints_every_column_in_a_plain_terminal():
    table = pd.DataFrame({column: [1.5, 2.5] for column in COLUMNS})
    result = AnnualEnergy(table=table, optima={}, inflow={})
    with pd.option_context("display.width", 80, "display.max_columns", 0):
        text = str(result.table)
        plain = str(table)
    assert "..." in plain  # pandas alone would hide the middle columns at 80 characters
    assert "..." not in text and all(column in text for column in COLUMNS)
    selected = result.table[result.table["frequency"] > 2.0]
    assert "aep_baseline_gwh" in repr(selected) and isinstance(selected, pd.DataFrame)


def test_readme_quick_start_prints_its_numbers():
    """The README's quick start runs inside the validated envelope, without any warning (the
    shipped input's placeholder condition included), and prints what its comments say."""
    text = (REPO / "README.md").read_text()
    code = re.search(r"```python\n(import floris_ekman_veer.*?)```", text, flags=re.S)[1]
    run = subprocess.run([sys.executable, "-W", "error::UserWarning", "-c", code],
                         capture_output=True, text=True, cwd=REPO, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stderr == ""
    powers = [float(v) for v in re.search(r"# MW: ([\d.]+), ([\d.]+)", code).groups()]
    printed = [float(v) for v in re.findall(r"[\d.]+", run.stdout.splitlines()[0])]
    np.testing.assert_allclose(printed, powers, atol=0.005)
    assert run.stdout.splitlines()[1] == "[True, True]"


def test_the_pages_build_shipped_inputs_that_build_without_a_warning():
    """The inputs the README's and docs' code blocks build warn about nothing before the user's
    set() (a placeholder condition outside the envelope would)."""
    blocks = "".join(m for page in [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
                     for m in re.findall(r"```python\n(.*?)```", page.read_text(), flags=re.S))
    names = set(re.findall(r'example_input\("(\w+)"\)', blocks))
    assert "farm_night" in names and "farm_sbl6" not in names
    for name in sorted(names):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            FlorisModel(floris_ekman_veer.example_input(name))


def test_nan_heterogeneous_multipliers_are_named():
    fmodel = FlorisModel(floris_ekman_veer.example_input("farm_night"))
    with pytest.raises(ValueError, match=r"flow_field.heterogeneous_inflow_config.speed_multipliers "
                                         r"must be finite and > 0; got nan at condition 0"):
        fmodel.set(wind_directions=[270.0], wind_speeds=[9.0], turbulence_intensities=[0.06],
                   heterogeneous_inflow_config={"speed_multipliers": [[1.0, np.nan, 1.0]],
                                                "x": [0.0, 500.0, 1000.0],
                                                "y": [0.0, 500.0, -500.0]})
