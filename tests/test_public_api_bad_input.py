"""Every name of ``floris_ekman_veer.__all__`` given wrong types and ranges: a ValueError or a
TypeError naming the input (docs/user_guide.md#valid-input-ranges), never another exception,
a numpy message or a silent acceptance."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
from floris import FlorisModel, WindRose
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

import floris_ekman_veer
from floris_ekman_veer import EkmanABL, FlorisEkmanVeerWarning

BASE = dict(geostrophic_wind=10.0, latitude=45.0, roughness_length=0.1)
SITE = dict(latitude=45.0, roughness_length=0.1)
NIGHT = {"coriolis_parameter": 1e-4, "roughness_length": 0.1, "obukhov_length": 100.0}


@pytest.fixture(scope="module")
def fmodel():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = FlorisModel(floris_ekman_veer.example_input("farm_night"))
        model.set(wind_speeds=[8.0], wind_directions=[270.0], turbulence_intensities=[0.06])
    return model


def rose():
    return WindRose(wind_directions=np.array([270.0]), wind_speeds=np.array([8.0]), ti_table=0.06)


STABILITY = {"night": {"frequency": 1.0, "atmosphere": NIGHT}}

#: Per public name: (call taking the fixture model, the input it must name). Wrong types first,
#: then wrong ranges.
BAD_CALLS = {
    "EkmanABL": [
        (lambda m: EkmanABL(**{**BASE, "latitude": "45"}), "latitude"),
        (lambda m: EkmanABL(**{**BASE, "roughness_length": [0.1, "x"]}), "roughness_length"),
        (lambda m: EkmanABL(**{**BASE, "geostrophic_wind": None}), "geostrophic_wind"),
        (lambda m: EkmanABL(**BASE, bogus=1.0), "bogus"),
        (lambda m: EkmanABL(**BASE, obukhov_length="inf"), "obukhov_length.*\\.inf"),
        (lambda m: EkmanABL(**{**BASE, "geostrophic_wind": -1.0}), "geostrophic_wind"),
        (lambda m: EkmanABL(**{**BASE, "latitude": 0.0}), "latitude"),
        (lambda m: EkmanABL(**BASE, mixed_layer_height=6000.0), "mixed_layer_height"),
        (lambda m: EkmanABL(**BASE, turbulence_factor=120.0), "turbulence_factor.*<= 10"),
        (lambda m: EkmanABL(**BASE, turbulence_factor=[1.2, True]), "turbulence_factor"),
        (lambda m: EkmanABL(**BASE, sensible_heat_flux=900.0), "sensible_heat_flux"),
        (lambda m: EkmanABL(**BASE, obukhov_length=-2.0), "sensible heat flux H"),
        (lambda m: EkmanABL(**{**BASE, "geostrophic_wind": 90.0}), "geostrophic wind G"),
        (lambda m: EkmanABL.from_reference_wind("8", 90.0, **SITE), "speed"),
        (lambda m: EkmanABL.from_reference_wind([[8.0, 9.0], [7.0]], 90.0, **SITE), "speed"),
        (lambda m: EkmanABL.from_reference_wind([8.0, 9.0, 7.0], [90.0, 80.0], **SITE),
         "speed .* and height"),
        (lambda m: EkmanABL.from_reference_wind(8.0, 90.0, tolerance="x", **SITE), "tolerance"),
        (lambda m: EkmanABL.from_reference_wind(8.0, 90.0, tolerance=-1.0, **SITE), "tolerance"),
        (lambda m: EkmanABL.from_reference_wind(8.0, -1.0, **SITE), "height"),
        (lambda m: EkmanABL.from_reference_wind(1e4, 90.0, **SITE), "geostrophic wind G"),
        (lambda m: EkmanABL.check_inputs(latitude=45.0, roughness_length="x"), "roughness_length"),
        (lambda m: EkmanABL.valid_range("nope"), "valid_range: name"),
        (lambda m: EkmanABL.valid_range(3), "valid_range: name"),
        (lambda m: EkmanABL(**BASE).velocity("x"), "z"),
        (lambda m: EkmanABL(**BASE).speed(-1.0), "z"),
        (lambda m: EkmanABL(**BASE).turbulence_intensity(90.0, A1=-1.0), "A1"),
        (lambda m: EkmanABL(**BASE).turbulence_intensity(90.0, B1="x"), "B1"),
        (lambda m: EkmanABL(**BASE).wake_expansion_rate(90.0, n=0.5), "n"),
        (lambda m: EkmanABL(**BASE).wake_expansion_rate(90.0, bogus=1.0), "bogus"),
    ],
    "ParFlorisModel": [
        (lambda m: floris_ekman_veer.ParFlorisModel(
            floris_ekman_veer.example_input("farm_night"), max_workers="x"), "max_workers"),
        (lambda m: floris_ekman_veer.ParFlorisModel(
            floris_ekman_veer.example_input("farm_night"), n_wind_condition_splits=0),
         "n_wind_condition_splits"),
        (lambda m: floris_ekman_veer.ParFlorisModel(
            floris_ekman_veer.example_input("farm_night"), interface="bogus"), "interface"),
    ],
    "annual_energy": [
        (lambda m: floris_ekman_veer.annual_energy("x", rose(), STABILITY), "fmodel"),
        (lambda m: floris_ekman_veer.annual_energy(m, "x", STABILITY), "wind_data"),
        (lambda m: floris_ekman_veer.annual_energy(m, rose(), {}), "stability"),
        (lambda m: floris_ekman_veer.annual_energy(m, rose(), STABILITY, "x"), "optimizer_class"),
        (lambda m: floris_ekman_veer.annual_energy(m, rose(), STABILITY, models=["bogus"]),
         "models"),
        (lambda m: floris_ekman_veer.annual_energy(m, rose(), STABILITY,
                                                   turbulence_intensities="x"),
         "turbulence_intensities"),
        (lambda m: floris_ekman_veer.annual_energy(m, rose(), STABILITY, chunk_size=0),
         "chunk_size"),
    ],
    "example_input": [
        (lambda m: floris_ekman_veer.example_input(3), "example_input name"),
        (lambda m: floris_ekman_veer.example_input("nope"), "example_input: no input named"),
    ],
    "example_inputs": [(lambda m: floris_ekman_veer.example_inputs(3), "example_inputs")],
    # reference_height='90', reference_height=1e4, time_column='nope' and the dropped
    # 'speed_-30m' column are covered by the site-fit tests (tests/test_site*.py).
    "fit_site": [(lambda m: floris_ekman_veer.fit_site("x", 90.0), "records")],
    "optimize_yaw": [
        (lambda m: floris_ekman_veer.optimize_yaw("x", YawOptimizationSR), "fmodel"),
        (lambda m: floris_ekman_veer.optimize_yaw(m, "x"), "optimizer_class"),
        (lambda m: floris_ekman_veer.optimize_yaw(m, YawOptimizationSR, search="x"), "search"),
        (lambda m: floris_ekman_veer.optimize_yaw(m, YawOptimizationSR, progress="x"),
         "progress"),
        (lambda m: floris_ekman_veer.optimize_yaw(m, YawOptimizationSR, chunk_size=0),
         "chunk_size"),
        (lambda m: floris_ekman_veer.optimize_yaw(m, YawOptimizationSR, minimum_yaw_angle="x"),
         "minimum_yaw_angle"),
        (lambda m: floris_ekman_veer.optimize_yaw(m, YawOptimizationSR, minimum_yaw_angle=10.0,
                                                  maximum_yaw_angle=5.0), "minimum_yaw_angle"),
        (lambda m: floris_ekman_veer.optimize_yaw(m, YawOptimizationSR, bogus=1), "bogus"),
    ],
    "register": [(lambda m: floris_ekman_veer.register(3), "register")],
    "silence_warnings": [
        (lambda m: floris_ekman_veer.silence_warnings("Bogus"), "silence_warnings: unknown"),
        (lambda m: floris_ekman_veer.silence_warnings(3), "silence_warnings: unknown"),
    ],
    "validity_report": [
        (lambda m: floris_ekman_veer.validity_report("x"), "fmodel"),
        (lambda m: floris_ekman_veer.validity_report(m, rossby_range=(1,)), "rossby_range"),
        (lambda m: floris_ekman_veer.validity_report(m, rossby_range=("a", "b")), "rossby_range"),
        (lambda m: floris_ekman_veer.validity_report(m, rossby_range=(5.0, 1.0)), "rossby_range"),
    ],
}


def public_names():
    return sorted(floris_ekman_veer.__all__)


@pytest.mark.parametrize("name", public_names())
def test_every_public_name_refuses_bad_input_naming_it(name, fmodel):
    value = getattr(floris_ekman_veer, name)
    if isinstance(value, type) and issubclass(value, Warning):
        # warning classes take no input; every one is the package's
        assert issubclass(value, FlorisEkmanVeerWarning)
        return
    if name == "__version__":
        assert isinstance(value, str) and re.fullmatch(r"\d+\.\d+(\.\d+)?.*", value)
        return
    calls = BAD_CALLS[name]  # a public name without bad-input cases is a gap in this test
    assert calls
    for call, named in calls:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with pytest.raises((ValueError, TypeError)) as refusal:
                call(fmodel)
        assert re.search(named, str(refusal.value)), (name, named, str(refusal.value))
        assert "ufunc" not in str(refusal.value) and "broadcast" not in str(refusal.value).replace(
            "do not broadcast together", "")


@pytest.mark.parametrize("inputs, named", [
    (dict(speed_tolerance=-1.0), r"speed_tolerance must be in \(0, 1\).*got -1"),
    (dict(speed_tolerance="x"), r"speed_tolerance"),
    (dict(veer_tolerance=0.0), r"veer_tolerance must be > 0 deg; got 0"),
    (dict(hub_speed=[8.0, 9.0], shear_exponent=[0.1, 0.2, 0.3]),
     r"one length .*hub_speed \(2,\).*shear_exponent \(3,\)"),
])
def test_shear_and_veer_refuses_bad_tolerances_and_ragged_conditions_naming_them(inputs, named):
    """The tolerances are this function's inputs, named as such (not as the fit's speed_noise
    they become), and conditions of different lengths are named with their shapes."""
    from floris_ekman_veer.studies.site.shear_and_veer import atmosphere_from_shear_and_veer

    call = dict(hub_speed=8.0, hub_height=90.0, rotor_diameter=126.0, shear_exponent=0.2,
                latitude=52.0)
    call.update(inputs)
    with pytest.raises(ValueError, match=named):
        atmosphere_from_shear_and_veer(**call)
