"""Shared fixtures: the inflow hook and FLORIS inputs carrying an Ekman atmosphere; the
hypothesis profiles."""

import copy
import inspect
import os
import types

import floris.type_dec
import pytest
from floris import FlorisModel
from hypothesis import HealthCheck, Phase, settings

from floris_ekman_veer.plugin.inflow import inflow

# Hypothesis profiles, selected by the environment variable HYPOTHESIS_PROFILE (README, "Set up"):
# "ci" (default): few examples, derandomised (reproducible CI), no example database; "long": the
# hand run, 2,000 random examples per property test. Tests that fix max_examples themselves keep
# their count under both. Examples run whole FLORIS farms, hence no deadline; the property
# suite's valid-by-construction filters discard some draws, hence filter_too_much is allowed.
_RELAXED = [HealthCheck.too_slow, HealthCheck.filter_too_much]
# No "explain" phase: it re-runs a failing FLORIS example dozens of times for a coverage report.
_PHASES = [Phase.explicit, Phase.reuse, Phase.generate, Phase.target, Phase.shrink]
settings.register_profile(
    "ci", max_examples=20, deadline=None, derandomize=True, database=None,
    suppress_health_check=_RELAXED, phases=_PHASES,
)
settings.register_profile(
    "long", max_examples=2000, deadline=None, suppress_health_check=_RELAXED, phases=_PHASES,
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# FLORIS's convert_to_path (every FlorisModel build and set(): the turbine library path) reads
# only the file names of inspect.stack()[1] and [-1], but inspect.stack() also reads each frame's
# source line, which under pytest (dozens of frames, runpy's frozen ones among them) scans every
# loaded module per frame: about half the time of a test that builds FLORIS models. The frames'
# file names do not depend on the context asked for (inspect.getframeinfo computes them first),
# so FLORIS here gets inspect.stack without source lines: the same paths, without the scan.
floris.type_dec.inspect = types.SimpleNamespace(stack=lambda context=0: inspect.stack(context))

#: The stable atmosphere of the issue's example (EkmanABL inputs without the wind speed).
STABLE_ATMOSPHERE = {
    "coriolis_parameter": 1.0e-4,
    "roughness_length": 0.1,
    "cooling_rate": -0.25,
    "brunt_vaisala_frequency": 6.1e-3,
    "reference_potential_temperature": 265.0,
}

# Model choices of FLORIS's example inputs (examples/inputs/*.yaml), on FLORIS's default farm.
EXAMPLE_WAKES = {
    "gauss": dict(velocity_model="gauss", deflection_model="gauss",
                  combination_model="sosfs", turbulence_model="crespo_hernandez", gch=False),
    "gch": dict(velocity_model="gauss", deflection_model="gauss",
                combination_model="sosfs", turbulence_model="crespo_hernandez", gch=True),
    "cc": dict(velocity_model="cc", deflection_model="gauss",
               combination_model="sosfs", turbulence_model="crespo_hernandez", gch=False),
    "jensen": dict(velocity_model="jensen", deflection_model="jimenez",
                   combination_model="fls", turbulence_model="crespo_hernandez", gch=False),
    "turbopark": dict(velocity_model="turbopark", deflection_model="gauss",
                      combination_model="fls", turbulence_model="crespo_hernandez", gch=False),
    "empirical_gauss": dict(velocity_model="empirical_gauss", deflection_model="empirical_gauss",
                            combination_model="sosfs", turbulence_model="wake_induced_mixing",
                            gch=False),
}


def make_config(
    wake: str = "gch",
    atmosphere: dict | None = STABLE_ATMOSPHERE,
    layout_x=(0.0, 630.0, 1260.0),
    layout_y=(0.0, 0.0, 0.0),
    wind_speeds=(8.0,),
    wind_directions=(270.0,),
    reference_wind_height: float = 90.0,
) -> dict:
    """FLORIS's default input with one of the example wake set-ups and (optionally) the
    atmosphere block at wake.wake_velocity_parameters.ekman_veer.atmosphere."""
    config = FlorisModel.get_defaults()
    choice = dict(EXAMPLE_WAKES[wake])
    gch = choice.pop("gch")
    config["wake"]["model_strings"].update(choice)
    for flag in ("enable_secondary_steering", "enable_yaw_added_recovery",
                 "enable_transverse_velocities"):
        config["wake"][flag] = gch
    if atmosphere is not None:
        config["wake"]["wake_velocity_parameters"]["ekman_veer"] = {
            "atmosphere": copy.deepcopy(atmosphere)
        }
    config["farm"]["layout_x"] = list(layout_x)
    config["farm"]["layout_y"] = list(layout_y)
    config["flow_field"]["wind_speeds"] = list(wind_speeds)
    config["flow_field"]["wind_directions"] = list(wind_directions)
    config["flow_field"]["turbulence_intensities"] = [0.06] * len(wind_speeds)
    config["flow_field"]["reference_wind_height"] = reference_wind_height
    if atmosphere is not None and not gch:
        # The atmosphere gives the inflow's shear and only GCH's terms read FLORIS's wind_shear:
        # 0.0 says so, as the ModelSettingsWarning of FLORIS's default 0.12 asks.
        config["flow_field"]["wind_shear"] = 0.0
    return config


@pytest.fixture
def inflow_hook():
    """The Ekman inflow hook, installed (idempotent; stays installed: it is a no-op for FLORIS
    inputs without an atmosphere block)."""
    inflow.install_inflow_hook()
    return inflow


def assert_as_plain_floris(outputs):
    """``outputs()`` (a sequence of arrays) is bitwise the same with the package's hooks
    installed and with all of them removed (plain FLORIS); the hooks are installed again."""
    import numpy as np

    from floris_ekman_veer import registry

    hooked = outputs()
    inflow.uninstall_inflow_hook()
    try:
        plain = outputs()
    finally:
        registry.register()
    for a, b in zip(hooked, plain, strict=True):
        np.testing.assert_array_equal(a, b)


def own_turbine(config: dict, name: str = "my_nrel_5MW") -> dict:
    """``config`` (an input dict, or a YAML path) with its NREL 5 MW turbines replaced by the
    user's own copy of FLORIS's definition under ``name``: the same thrust table, but the user's,
    so that the thrust limit is a ThrustLimitWarning (on FLORIS's library turbine it is a notice
    on FLORIS's logger: floris_ekman_veer.warnings._warn_thrust_limit)."""
    from floris.core.farm import default_turbine_library_path
    from floris.utilities import load_yaml

    config = copy.deepcopy(load_yaml(str(config)) if not isinstance(config, dict) else config)
    turbine = load_yaml(str(default_turbine_library_path / "nrel_5MW.yaml"))
    turbine["turbine_type"] = name
    config["farm"]["turbine_type"] = [
        turbine if t in ("nrel_5MW",) or (isinstance(t, dict) and t.get("turbine_type") == "nrel_5MW")
        else t for t in config["farm"]["turbine_type"]]
    return config


#: Table 1's SBL-6 stability parameter: the state the LES reached at G = 15 m/s.
TABLE1_SBL6_MU = 148.49


def table1_sbl6(config) -> dict:
    """``config`` (an input dict, or a YAML path) with its atmosphere's stability given as
    Table 1's SBL-6 mu = 148.49, fixed across speeds, instead of the input's own (farm_sbl6's
    cooling rate -1 K/h since issue 39, whose layer is below the hub at 8-9 m/s). For tests of
    machinery and rotor accuracy designed on that state: h (110-165 m at 8-11 m/s) stays above
    the hub."""
    from floris.utilities import load_yaml

    config = copy.deepcopy(load_yaml(str(config)) if not isinstance(config, dict) else config)
    atmosphere = config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    for key in ("cooling_rate", "obukhov_length", "surface_heat_flux", "sensible_heat_flux"):
        atmosphere.pop(key, None)
    atmosphere["stability_parameter"] = TABLE1_SBL6_MU
    return config
