"""Invalid atmosphere input, table-driven (docs/atmosphere.md#input-ranges).

Every row gives an invalid input, in Python (EkmanABL and its methods) or in the FLORIS input
(``wake.wake_velocity_parameters.ekman_veer.atmosphere``, from YAML or a dict alike), and asserts
a ValueError whose message names the parameter (by its input path in FLORIS), the offending value
and, for per-condition lists, the condition index.
"""

import re

import numpy as np
import pytest
import yaml
from floris import FlorisModel

from floris_ekman_veer.atmosphere.ekman import EkmanABL

from conftest import STABLE_ATMOSPHERE, make_config

PATH = re.escape("wake.wake_velocity_parameters.ekman_veer.atmosphere.")
BASE = dict(geostrophic_wind=10.0, latitude=45.0, roughness_length=0.1)
ABL = EkmanABL(**BASE, cooling_rate=-0.5)


def build(**changes):
    return EkmanABL(**{**BASE, **changes})


def floris(atmosphere, **kwargs):
    return FlorisModel(make_config("gauss", atmosphere, **kwargs))


def floris_with(**changes):
    """The stable atmosphere with ``changes``, on three conditions (lists of 3 are valid)."""
    return floris({**STABLE_ATMOSPHERE, **changes}, wind_speeds=(8.0, 9.0, 10.0),
                  wind_directions=(270.0,) * 3)


REFERENCE = dict(surface_heat_flux=-0.04, roughness_length=0.28, latitude=19.8)

PYTHON = {
    # numbers given as strings or booleans: refused, never coerced
    "G string": (lambda: build(geostrophic_wind="10"), r"^geostrophic_wind must be a real number.*got '10' \(str\)"),
    "G word": (lambda: build(geostrophic_wind="ten"), r"^geostrophic_wind must be a real number.*> 0 m/s.*got 'ten'"),
    "G boolean": (lambda: build(geostrophic_wind=True), r"^geostrophic_wind must be a real number.*got True \(bool\)"),
    "G list with a string": (lambda: build(geostrophic_wind=[8.0, "9"]), r"^geostrophic_wind must be a real number"),
    "G boolean array": (lambda: build(geostrophic_wind=np.array([True, False])), r"^geostrophic_wind must be a real number"),
    # a year of per-record values (checked by the items' types at once, not item by item):
    # one boolean, string or None at the end is still found
    "long list ending in a boolean": (lambda: build(cooling_rate=[-0.5] * 8760 + [True]), r"^cooling_rate must be a real number.*got \[-0.5, "),
    "long list with a numpy boolean": (lambda: build(cooling_rate=[-0.5] * 8760 + [np.True_]), r"^cooling_rate must be a real number"),
    "long list ending in a string": (lambda: build(cooling_rate=[-0.5] * 8760 + ["-1"]), r"^cooling_rate must be a real number"),
    "long object array with None": (lambda: build(cooling_rate=np.array([-0.5] * 8760 + [None], dtype=object)), r"^cooling_rate must be a real number"),
    "long list of rows with a boolean": (lambda: build(cooling_rate=[[-0.5]] * 8760 + [[True]]), r"^cooling_rate must be a real number"),
    "z0 string": (lambda: build(roughness_length="0.1"), r"^roughness_length must be a real number.*got '0.1'"),
    "latitude boolean": (lambda: build(latitude=True), r"^latitude must be a real number.*got True"),
    "constant string": (lambda: build(von_karman="0.4"), r"^von_karman must be a real number"),
    "constant boolean": (lambda: build(c_g=True), r"^c_g must be a real number"),
    "stability string": (lambda: build(cooling_rate="-1"), r"^cooling_rate must be a real number"),
    # ranges
    "f_c above 2 Omega": (lambda: EkmanABL(geostrophic_wind=10.0, coriolis_parameter=0.01, roughness_length=0.1),
                          r"^coriolis_parameter must be .*<= \|f_c\| <= 2 Omega = 0.0001454 1/s.*got 0.01"),
    "f_c below -2 Omega": (lambda: EkmanABL(geostrophic_wind=10.0, coriolis_parameter=-2e-4, roughness_length=0.1),
                           r"^coriolis_parameter must be .*2 Omega.*got -0.0002"),
    "per-entry index": (lambda: build(cooling_rate=[-0.5, 30.0, -1.0]),
                        r"^cooling_rate must be -10 to 10 K/h.*got 30 at condition 1"),
    "NaN entry index": (lambda: build(roughness_length=[0.1, np.nan]),
                        r"^roughness_length must be > 0 m; got nan at condition 1"),
    # NaN heights in every profile method (never NaN out, never a finite V(NaN))
    "velocity(NaN)": (lambda: ABL.velocity(np.nan), r"^z must be >= 0 m.*got nan"),
    "speed(NaN)": (lambda: ABL.speed([10.0, np.nan]), r"^z must be >= 0 m.*got nan at condition 1"),
    "velocity below ground": (lambda: ABL.velocity(-1.0), r"^z must be >= 0 m.*got -1"),
    "velocity(string)": (lambda: ABL.velocity("10"), r"^z must be a real number"),
    "hub_aligned z NaN": (lambda: ABL.hub_aligned_velocity(np.nan, 90.0), r"^z must be >= 0 m.*got nan"),
    "hub_aligned reference NaN": (lambda: ABL.hub_aligned_velocity(50.0, np.nan), r"^reference_height must be > 0 m.*got nan"),
    "hub_aligned reference at ground": (lambda: ABL.hub_aligned_velocity(50.0, 0.0), r"^reference_height must be > 0 m.*got 0"),
    "turbulence_intensity(NaN)": (lambda: ABL.turbulence_intensity(np.nan), r"^z must be >= roughness_length z0.*got nan"),
    "turbulence_intensity reference NaN": (lambda: ABL.turbulence_intensity(50.0, np.nan), r"^reference_height must be >= roughness_length z0.*got nan"),
    "wake_expansion_rate(NaN)": (lambda: ABL.wake_expansion_rate(np.nan), r"^hub_height must be >= roughness_length z0.*got nan"),
    "wind_direction_change z1 NaN": (lambda: ABL.wind_direction_change(np.nan, 90.0), r"^z1 must be > 0 m.*got nan"),
    "wind_direction_change z2 NaN": (lambda: ABL.wind_direction_change(10.0, np.nan), r"^z2 must be > 0 m.*got nan"),
    # the reference-wind solve: no solution, in the user's terms
    "no ABL reaches the speed": (
        lambda: EkmanABL.from_reference_wind(np.array([12.0, 3.0, 15.0]), 136.6, **REFERENCE),
        r"^from_reference_wind: no ABL has a wind speed of 3 m/s at 136.6 m at condition 1 "
        r"\(surface_heat_flux=-0.04, roughness_length=0.28, latitude=19.8\): the slowest wind "
        r"these inputs support at 136.6 m is 11.\d+ m/s; .*the stable boundary layer collapses"),
    "reference speed string": (lambda: EkmanABL.from_reference_wind("8", 90.0, **REFERENCE), r"^speed must be a real number"),
    "reference height NaN": (lambda: EkmanABL.from_reference_wind(8.0, np.nan, **REFERENCE), r"^height must be > roughness_length z0.*got nan"),
}

FLORIS = {
    "z0 string": (dict(roughness_length="0.1"), PATH + r"roughness_length must be a real number .*> 0 m.*got '0.1' \(str\)"),
    "z0 word": (dict(roughness_length="ten"), PATH + r"roughness_length must be a real number.*got 'ten'"),
    "z0 boolean": (dict(roughness_length=True), PATH + r"roughness_length must be a real number.*got True \(bool\)"),
    "cooling rate boolean list": (dict(cooling_rate=[True, False]), PATH + r"cooling_rate must be a real number"),
    "f_c above 2 Omega": (dict(coriolis_parameter=0.01), PATH + r"coriolis_parameter must be .*2 Omega.*got 0.01"),
    "per-condition range": (dict(cooling_rate=[-0.5, -1.0, 15.0]), PATH + r"cooling_rate must be -10 to 10 K/h.*got 15 at condition 2"),
    "per-condition NaN": (dict(roughness_length=[0.1, np.nan, 0.1]), PATH + r"roughness_length must be > 0 m; got nan at condition 1"),
    "list of lists": (dict(cooling_rate=[[-0.5], [-1.0], [-0.5]]), PATH + r"cooling_rate must be a number or a 1-D list"),
    "wrong length": (dict(cooling_rate=[-0.5, -1.0]),
                     PATH + r"cooling_rate must have one value per condition \(length n_findex = 3\) or be a single number; got 2 values"),
    "lengths disagree": (dict(cooling_rate=[-0.5, -1.0, -0.2], roughness_length=[0.1, 0.2]),
                         r"^per-condition lists must all have one value per condition(?=.*" + PATH
                         + r"cooling_rate has 3)(?=.*" + PATH + r"roughness_length has 2)"),
}


@pytest.mark.parametrize("case", list(PYTHON))
def test_invalid_python_input(case):
    call, pattern = PYTHON[case]
    with pytest.raises(ValueError, match=pattern):
        call()


@pytest.mark.parametrize("case", list(FLORIS))
def test_invalid_floris_atmosphere(case):
    changes, pattern = FLORIS[case]
    with pytest.raises(ValueError, match=pattern):
        floris_with(**changes)


def test_yaml_strings_are_not_numbers():
    """A quoted YAML number is a string and is refused, at model build, with its input path."""
    block = yaml.safe_load(
        'coriolis_parameter: 1.0e-4\nroughness_length: "0.1"\ncooling_rate: -0.5\n'
    )
    with pytest.raises(ValueError, match=PATH + r"roughness_length must be a real number"):
        floris(block)


def test_floris_reference_wind_failure_names_the_condition():
    """FLORIS's wind speeds drive the solve: a speed no ABL of the atmosphere reaches is named by
    its condition index and value (and the slowest speed the atmosphere supports is given)."""
    atmosphere = dict(latitude=19.8, roughness_length=0.28, surface_heat_flux=-0.04)
    with pytest.raises(ValueError, match=r"no ABL has a wind speed of 3 m/s at 90 m at condition 1 .*"
                                         r"the slowest wind these inputs support at 90 m is"):
        floris(atmosphere, wind_speeds=(12.0, 3.0, 14.0), wind_directions=(270.0,) * 3)


def test_long_lists_of_numbers_are_read_as_given():
    """Plain numbers of any numeric type in a long list are accepted (and read exactly)."""
    from floris_ekman_veer._validation import real_array

    values = [-0.5] * 8759 + [np.float32(-0.25), np.int64(-1), -2]
    array = real_array("cooling_rate", values)
    np.testing.assert_array_equal(array, np.array(values, dtype=float))
    assert real_array("z", np.array(values, dtype=object)).dtype == float
