"""What the package's FLORIS wake models take from their input: their parameter block, read
and range-checked (docs/coupling.md#input-validation), and the thrust coefficient their formulas
use, C_T = ct_i / cos(yaw) from FLORIS's ct_i, held to momentum theory's range
(docs/conventions.md#thrust-coefficient-and-yaw). Shared by the velocity models
(plugin/wake_models/models.py) and the deflection model (plugin/wake_models/deflection_model.py).
"""

from __future__ import annotations

import attrs
import numpy as np
from floris.core import BaseModel

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer._validation import input_block

#: a = 0.4: beyond it momentum theory gives way to the Glauert (turbulent-wake) regime.
GLAUERT_THRUST_COEFFICIENT = 0.96


def from_input_block(cls, data):
    """FLORIS's ``from_dict`` for a model block, refusing a non-mapping block (e.g. ``"on"``,
    which FLORIS would iterate as the keys 'o', 'n') or unknown keys with a ValueError naming
    the block's input path (docs/coupling.md#input-validation)."""
    input_block(data, cls.input_path, [a.name for a in attrs.fields(cls) if a.init])
    return BaseModel.from_dict.__func__(cls, data)


#: Valid ranges of the model parameters (docs/coupling.md#input-validation): text and test.
POSITIVE = ("finite and > 0", lambda v: np.isfinite(v) and v > 0.0)
NON_NEGATIVE = ("finite and >= 0", lambda v: np.isfinite(v) and v >= 0.0)
# k_w_exponent n: the smooth maximum (floor^n + x^n)^(1/n) lies between max(floor, x) (n -> inf)
# and floor + x (n = 1); n < 1 would exceed the sum, n = 0 divides by zero.
MERGE_EXPONENT_RANGE = ("finite and >= 1", lambda v: np.isfinite(v) and v >= 1.0)
# A thrust-coefficient limit below 1: momentum theory's a < 1/2 (docs/conventions.md).
THRUST_LIMIT_RANGE = ("in (0, 1)", lambda v: 0.0 < v < 1.0)


def unyawed_thrust_coefficient(ct_i, yaw, max_thrust_coefficient):
    """C_T = ct_i / cos(yaw) (docs/conventions.md#thrust-coefficient-and-yaw), limited to the momentum-theory range.

    The limit acts on the rotor-normal loading C_T cos^2(yaw), as in Eqs. A_star and
    ind_factor. ``yaw`` in radians. Returns the C_T the wake formulas use; warns when the limit
    acts.
    """
    if np.any(np.abs(yaw) >= np.pi / 2):
        raise ValueError(
            "yaw angles must satisfy |yaw| < 90 degrees for the ekman_veer wake models; got "
            f"{np.rad2deg(yaw.flat[np.argmax(np.abs(yaw))]):.6g} degrees"
        )
    ct = np.asarray(ct_i, dtype=float) / np.cos(yaw)
    limit = max_thrust_coefficient / np.cos(yaw) ** 2
    heavy = ct > limit
    if np.any(heavy):
        # One summary per run, naming the conditions' wind speeds (floris_ekman_veer.warnings).
        package_warnings.note_thrust_limit(heavy, max_thrust_coefficient)
    return np.where(heavy, limit, ct)

