"""Registration of the package's models in FLORIS's model tables (idempotent, never overwriting).

``register()`` makes the wake models selectable by name in a FLORIS input
(``velocity_model: ekman_veer``, ``deflection_model: ekman_veer``, ``velocity_model:
bastankhah2014``), adds the ``actuator-disk`` turbine operation model and installs every FLORIS
patch by walking the patch tables (plugin/floris_hooks/patches.py: the Ekman inflow, the support of
ParFlorisModel, UncertainFlorisModel and the yaw optimisers, the conversion of FLORIS wake inputs,
the veer-aware rotor and the models' solver). Importing ``floris_ekman_veer`` calls it.

This is the top of the coupling layer: it imports the models, the turbine, the patch tables and
the yaw optimisation, and none of them imports it (docs/coupling.md#registry).
"""

from __future__ import annotations

import difflib
from collections.abc import MutableMapping

from floris_ekman_veer.plugin.wake_models.names import (  # noqa: F401  (part of the registry's interface)
    DEFLECTION_MODEL_NAME,
    GAUSSIAN_2014_NAME,
    VELOCITY_MODEL_NAME,
)


def register_in(table: MutableMapping, name: str, cls: type, kind: str) -> type:
    """Put ``cls`` in ``table[name]`` unless another class holds the name (ValueError).

    A class of the same module and qualified name (this very class after a module reload) is
    replaced, so that reloading the package does not lock itself out.
    """
    existing = table.get(name)
    if existing is not None and existing is not cls:
        same_origin = (getattr(existing, "__module__", None), getattr(existing, "__qualname__", None)) \
            == (cls.__module__, cls.__qualname__)
        if not same_origin:
            raise ValueError(
                f"FLORIS {kind} '{name}' is already registered as {existing!r}; refusing to "
                f"overwrite it with {cls!r}"
            )
    table[name] = cls
    return cls


class UnknownModelError(ValueError, KeyError):
    """A model name FLORIS's tables do not hold (a ValueError, and the KeyError FLORIS's own
    lookup raised, for code that catches that)."""

    def __str__(self) -> str:
        return str(self.args[0])


class RegisteredModels(dict):
    """FLORIS's table of one kind of model. Looking up a name it does not hold (a typo,
    ``ekman_ver``) is an :class:`UnknownModelError` naming the input, the registered models and
    the closest match, instead of FLORIS's bare ``KeyError: 'ekman_ver'``."""

    def __init__(self, table, path: str):
        super().__init__(table)
        self.path = path

    def __missing__(self, name):
        names = sorted(str(k) for k in self)
        close = difflib.get_close_matches(str(name), names, n=1)
        raise UnknownModelError(
            f"{self.path}: no model named {name!r}"
            + (f" (did you mean {close[0]!r}?)" if close else "")
            + f"; the registered models are {names} (floris_ekman_veer adds its own on import)"
        )


def name_checked(tables: MutableMapping, paths: dict) -> None:
    """Make each table of ``tables`` (FLORIS's MODEL_MAP, TURBINE_MODEL_MAP) a
    :class:`RegisteredModels` in place (idempotent; the entries are kept)."""
    for kind, path in paths.items():
        table = tables.get(kind)
        if table is not None and type(table).__name__ != RegisteredModels.__name__:
            tables[kind] = RegisteredModels(table, path)


#: Where each kind of model is named in a FLORIS input.
MODEL_PATHS = {kind: f"wake.model_strings.{kind}" for kind in
               ("velocity_model", "deflection_model", "turbulence_model", "combination_model")}
OPERATION_MODEL_PATH = {"operation_model": "farm.turbine_type[...].operation_model"}


def register_operation_model() -> type:
    """Register the actuator disk as FLORIS operation model ``"actuator-disk"``; return its class.

    Idempotent. Raises ValueError if that name already maps to another class (a reloaded copy of
    that very class, same module and qualified name, is replaced by the current one).
    """
    from floris.core.turbine import turbine as floris_turbine

    from floris_ekman_veer.plugin.rotor.turbine import OPERATION_MODEL_NAME, ActuatorDiskTurbine

    name_checked(floris_turbine.TURBINE_MODEL_MAP, OPERATION_MODEL_PATH)
    return register_in(
        floris_turbine.TURBINE_MODEL_MAP["operation_model"], OPERATION_MODEL_NAME,
        ActuatorDiskTurbine, "operation model",
    )


def patch_tables() -> tuple:
    """The tables of FLORIS patches :func:`register` installs (tuples of
    :class:`~floris_ekman_veer.plugin.floris_hooks.patches.Patch` rows): the plugin's
    (plugin/floris_hooks/patches.py) and the yaw optimisers' (docs/coupling.md#what-is-patched)."""
    from floris_ekman_veer.plugin.floris_hooks.patches import PATCHES
    from floris_ekman_veer.plugin.floris_tools.optimizer_hooks import PATCHES as OPTIMIZER_PATCHES

    return (PATCHES, OPTIMIZER_PATCHES)


def register() -> None:
    """Register the wake models and the actuator-disk turbine, and install every FLORIS patch by
    walking :func:`patch_tables` (the inflow, ParFlorisModel, UncertainFlorisModel and yaw
    optimiser support, the wake inputs, the veer-aware rotor and the models' solver)."""
    from floris.core.wake import MODEL_MAP

    from floris_ekman_veer.plugin.wake_models.deflection_model import EkmanVeerVelocityDeflection
    from floris_ekman_veer.plugin.wake_models.models import EkmanVeerVelocityDeficit, Gaussian2014VelocityDeficit

    name_checked(MODEL_MAP, MODEL_PATHS)
    register_in(MODEL_MAP["velocity_model"], VELOCITY_MODEL_NAME, EkmanVeerVelocityDeficit,
                "velocity_model")
    register_in(MODEL_MAP["velocity_model"], GAUSSIAN_2014_NAME, Gaussian2014VelocityDeficit,
                "velocity_model")
    register_in(MODEL_MAP["deflection_model"], DEFLECTION_MODEL_NAME, EkmanVeerVelocityDeflection,
                "deflection_model")
    register_operation_model()
    for table in patch_tables():
        for row in table:
            row.install()
