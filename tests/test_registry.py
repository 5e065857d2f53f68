"""Registration of the package's models in FLORIS's tables (registry.py)."""

from __future__ import annotations

from pathlib import Path

import pytest
from floris import FlorisModel
from floris.core.turbine import turbine as floris_turbine
from floris.core.wake import MODEL_MAP
from floris.utilities import load_yaml

import floris_ekman_veer
from floris_ekman_veer.plugin.floris_hooks import patching
from floris_ekman_veer.plugin.inflow import inflow
from floris_ekman_veer import registry
from floris_ekman_veer.plugin.wake_models.models import (
    EkmanVeerVelocityDeficit,
    EkmanVeerVelocityDeflection,
    Gaussian2014VelocityDeficit,
)
from floris_ekman_veer.plugin.rotor.turbine import ActuatorDiskTurbine

INPUTS = Path(__file__).resolve().parents[1] / "inputs"

OPERATION_MODELS = floris_turbine.TURBINE_MODEL_MAP["operation_model"]

#: (table, name, class) of every registration the package makes.
REGISTRATIONS = [
    (MODEL_MAP["velocity_model"], "ekman_veer", EkmanVeerVelocityDeficit),
    (MODEL_MAP["velocity_model"], "bastankhah2014", Gaussian2014VelocityDeficit),
    (MODEL_MAP["deflection_model"], "ekman_veer", EkmanVeerVelocityDeflection),
    (OPERATION_MODELS, "actuator-disk", ActuatorDiskTurbine),
]
IDS = ["velocity:ekman_veer", "velocity:bastankhah2014", "deflection:ekman_veer",
       "operation:actuator-disk"]


def snapshot():
    return [dict(table) for table in (MODEL_MAP["velocity_model"],
                                      MODEL_MAP["deflection_model"], OPERATION_MODELS)]


def assert_same_tables(before, after):
    assert [list(t) for t in before] == [list(t) for t in after]
    for old, new in zip(before, after):
        assert all(old[name] is new[name] for name in old)


def test_import_registers_everything():
    for table, name, cls in REGISTRATIONS:
        assert table[name] is cls
    assert registry.VELOCITY_MODEL_NAME == registry.DEFLECTION_MODEL_NAME == "ekman_veer"
    assert registry.GAUSSIAN_2014_NAME == "bastankhah2014"
    assert inflow.is_installed()
    # FLORIS's own models are untouched.
    assert MODEL_MAP["velocity_model"]["gauss"].__name__ == "GaussVelocityDeficit"
    assert OPERATION_MODELS["cosine-loss"].__name__ == "CosineLossTurbine"


def test_floris_finds_the_models_by_name_case_insensitively():
    """FLORIS lower-cases model strings before the look-up: the package names are lower case."""
    config = load_yaml(str(INPUTS / "cnbl.yaml"))
    config["wake"]["model_strings"].update(velocity_model="EKMAN_VEER", deflection_model="Ekman_Veer")
    fmodel = FlorisModel(config)
    assert type(fmodel.core.wake.velocity_model) is EkmanVeerVelocityDeficit
    assert type(fmodel.core.wake.deflection_model) is EkmanVeerVelocityDeflection
    turbine = fmodel.core.farm.turbine_map[0]
    assert turbine.operation_model == "actuator-disk"
    assert turbine.power_function == ActuatorDiskTurbine.power


def test_names_do_not_select_floris_special_solvers():
    """cc, turbopark(gauss) and empirical_gauss have their own solvers (docs/coupling.md#registry)."""
    special = {"cc", "turbopark", "turboparkgauss", "empirical_gauss"}
    assert not {registry.VELOCITY_MODEL_NAME, registry.GAUSSIAN_2014_NAME} & special


def test_register_is_idempotent():
    before = snapshot()
    hook_originals = dict(patching.ORIGINALS)
    floris_ekman_veer.register()
    floris_ekman_veer.register()
    assert_same_tables(before, snapshot())
    assert patching.ORIGINALS == hook_originals


@pytest.mark.parametrize("table, name, cls", REGISTRATIONS, ids=IDS)
def test_register_refuses_to_overwrite_another_class(table, name, cls):
    class Dummy:
        pass

    original = table[name]
    table[name] = Dummy
    try:
        with pytest.raises(ValueError, match=f"'{name}' is already registered"):
            floris_ekman_veer.register()
        assert table[name] is Dummy  # left alone
    finally:
        table[name] = original
    assert table[name] is cls
    floris_ekman_veer.register()  # and the package registers again cleanly
    assert table[name] is cls


@pytest.mark.parametrize("table, name, cls", REGISTRATIONS, ids=IDS)
def test_register_replaces_a_reloaded_copy_of_its_own_class(table, name, cls):
    """importlib.reload makes a new class of the same module and qualified name: replaced."""
    stale = type(cls.__name__, (), {"__module__": cls.__module__, "__qualname__": cls.__qualname__})
    table[name] = stale
    try:
        floris_ekman_veer.register()
        assert table[name] is cls
    finally:
        table[name] = cls


def test_register_in():
    table = {}
    assert registry.register_in(table, "x", EkmanVeerVelocityDeficit, "velocity_model") \
        is EkmanVeerVelocityDeficit
    assert registry.register_in(table, "x", EkmanVeerVelocityDeficit, "velocity_model") \
        is EkmanVeerVelocityDeficit
    with pytest.raises(ValueError, match="velocity_model 'x'.*refusing to overwrite"):
        registry.register_in(table, "x", Gaussian2014VelocityDeficit, "velocity_model")
    assert table == {"x": EkmanVeerVelocityDeficit}
