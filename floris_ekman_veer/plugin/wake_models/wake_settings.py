"""The wake block of a FLORIS input converted to the package's models: defaults for the missing
model blocks, and one warning for settings that mix the package's models with FLORIS's.

A FLORIS input written for gauss/GCH (``FlorisModel.get_defaults()``, FLORIS's ``gch.yaml``)
becomes an ``ekman_veer`` input by changing the two model names and adding the atmosphere
(docs/user_guide.md#your-floris-input-with-veer). FLORIS itself requires a parameter block for every
selected model and fails with a bare ``KeyError`` without one; for the package's models
(``ekman_veer``, ``bastankhah2014``) a missing block means the model's defaults, as an empty one
does. Settings that run but are not the paper's model are said once, in a
:class:`~floris_ekman_veer.warnings.ModelSettingsWarning` naming what they do:

* ``velocity_model: ekman_veer`` with another deflection model (gauss, jimenez): the veer offset
  x V(z)/U(z) and the vortex-pair yaw deflection are the ``ekman_veer`` deflection model's, so
  the wakes are deflected by the other model's yaw deflection only and do not shear with veer;
* ``deflection_model: ekman_veer`` under FLORIS's velocity models: their deficits are moved by
  the veer-sheared centre, a combination the paper does not test;
* GCH's switches (``enable_secondary_steering``, ``enable_yaw_added_recovery``,
  ``enable_transverse_velocities``) on with the package's velocity models: FLORIS then adds to
  each turbine's yaw an effective yaw from the wakes' transverse velocity (secondary steering)
  and extra mixing behind yawed rotors (yaw-added recovery), both from its own vortex model of a
  yawed rotor, on top of the ``ekman_veer`` curl and deflection that already model them.
"""

from __future__ import annotations

import functools

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer.plugin.wake_models.names import (
    DEFLECTION_MODEL_NAME,
    GAUSSIAN_2014_NAME,
    VELOCITY_MODEL_NAME,
)

VELOCITY_MODELS = (VELOCITY_MODEL_NAME, GAUSSIAN_2014_NAME)
GCH_SWITCHES = {
    "enable_secondary_steering": "adds to each turbine's yaw an effective yaw from the wakes' "
                                 "transverse velocity (secondary steering)",
    "enable_yaw_added_recovery": "adds mixing behind yawed rotors (yaw-added recovery)",
    "enable_transverse_velocities": "computes FLORIS's own vortex model of yawed rotors for "
                                    "the two above",
}


def with_default_blocks(wake: dict) -> dict:
    """``wake`` (FLORIS's wake input) with an empty parameter block (the model's defaults) for
    each selected package model whose block is missing; the input itself is not changed."""
    strings = {k: str(v).lower() for k, v in (wake.get("model_strings") or {}).items()}
    wake = dict(wake)
    for kind, names, key in (
        ("velocity_model", VELOCITY_MODELS, "wake_velocity_parameters"),
        ("deflection_model", (DEFLECTION_MODEL_NAME,), "wake_deflection_parameters"),
    ):
        name = strings.get(kind)
        if name in names and name not in (wake.get(key) or {}):
            wake[key] = {**(wake.get(key) or {}), name: {}}
    return wake


def mixed_settings(wake) -> list[str]:
    """What the wake settings mix (the sentences of the warning); empty for the paper's models
    and for plain FLORIS inputs."""
    strings = {k: str(v).lower() for k, v in wake.model_strings.items()}
    velocity, deflection = strings.get("velocity_model"), strings.get("deflection_model")
    found = []
    if velocity == VELOCITY_MODEL_NAME and deflection != DEFLECTION_MODEL_NAME:
        found.append(
            f"velocity_model {VELOCITY_MODEL_NAME} with deflection_model {deflection}: the veer "
            f"offset x V(z)/U(z) and the paper's yaw deflection are those of deflection_model "
            f"{DEFLECTION_MODEL_NAME}, so these wakes are deflected by {deflection}'s yaw "
            "deflection only and do not shear with veer (set deflection_model: "
            f"{DEFLECTION_MODEL_NAME})"
        )
    if deflection == DEFLECTION_MODEL_NAME and velocity not in VELOCITY_MODELS:
        found.append(
            f"deflection_model {DEFLECTION_MODEL_NAME} with velocity_model {velocity}: "
            f"{velocity}'s deficits are moved by the veer-sheared wake centre, a combination the "
            f"paper does not test (set velocity_model: {VELOCITY_MODEL_NAME})"
        )
    if velocity in VELOCITY_MODELS:
        on = [name for name in GCH_SWITCHES if getattr(wake, name, False)]
        if on:
            found.append(
                f"velocity_model {velocity} with GCH's " + ", ".join(on) + " on: FLORIS then "
                + "; ".join(GCH_SWITCHES[name] for name in on)
                + f", on top of the {velocity} wake's own curl and deflection, so results are "
                "not the paper's model (set them false, as in inputs/farm_sbl6.yaml)"
            )
    return found


def converting_post_init(method):
    """WakeModelManager.__attrs_post_init__: defaults for missing package blocks, and the
    mixed-settings warning."""

    @functools.wraps(method)
    def wrapper(self) -> None:
        completed = with_default_blocks({
            "model_strings": self.model_strings,
            "wake_velocity_parameters": self.wake_velocity_parameters,
            "wake_deflection_parameters": self.wake_deflection_parameters,
        })
        self.wake_velocity_parameters = completed["wake_velocity_parameters"]
        self.wake_deflection_parameters = completed["wake_deflection_parameters"]
        method(self)
        found = mixed_settings(self)
        if found:
            package_warnings.warn(
                "this FLORIS input mixes the package's wake models with FLORIS's settings: "
                + "; ".join(found) + " (docs/user_guide.md#your-floris-input-with-veer)",
                package_warnings.ModelSettingsWarning, items=found,
            )

    return wrapper
