"""The Ekman ABL of FLORIS's conditions, solved once per (atmosphere, wind speeds, reference
height) and kept: building a model, initialising its flow fields, the wake models' look-ups and
the studies that solve the same block share one solve.

Per condition, the ABL is driven by FLORIS's wind speed at ``reference_wind_height``:
``EkmanABL.from_reference_wind(wind_speeds[:, None, None, None], reference_wind_height, **atm)``,
solved for all conditions in one vectorised call.
"""

from __future__ import annotations

import threading
from collections import OrderedDict

import numpy as np

from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.plugin.inflow.atmosphere_block import CONFIG_PATH, AtmosphereSpec

_SOLVE_CACHE: OrderedDict = OrderedDict()
_SOLVE_CACHE_SIZE = 32
_SOLVE_LOCK = threading.Lock()


def solve(spec: AtmosphereSpec, wind_speeds, reference_height: float):
    """EkmanABL for every condition: ``|(U, V)(reference_height)| = wind_speeds``.

    One vectorised ``from_reference_wind`` call with speeds shaped ``(n_findex, 1, 1, 1)``; the
    result is cached by (atmosphere, wind speeds, reference height), so building a model,
    initialising its flow fields and the wake models' look-ups share one solve.
    """
    wind_speeds = np.asarray(wind_speeds, dtype=float).reshape(-1)
    reference_height = float(reference_height)
    spec.check_conditions(wind_speeds.size)
    key = (spec.key, wind_speeds.tobytes(), reference_height, spec.rest_below)
    with _SOLVE_LOCK:
        if key in _SOLVE_CACHE:
            _SOLVE_CACHE.move_to_end(key)
            return _SOLVE_CACHE[key]
    # Calm conditions (0 m/s) are at rest: no ABL is solved for them (they take the ABL of a
    # moving condition, unused) and the inflow is 0, so they give zero power. Conditions below
    # every turbine's cut-in are at rest too when no valid ABL reaches their speed
    # (docs/user_guide.md#calm-and-weak-winds).
    at_rest = wind_speeds <= 0.0
    try:
        abl = _solve_moving(spec, wind_speeds, reference_height, at_rest)
    except ValueError:
        weak = at_rest | (wind_speeds <= spec.rest_below)
        if not np.any(weak & ~at_rest):
            raise
        at_rest = weak
        abl = _solve_moving(spec, wind_speeds, reference_height, at_rest)
    abl.at_rest = at_rest
    with _SOLVE_LOCK:
        _SOLVE_CACHE[key] = abl
        while len(_SOLVE_CACHE) > _SOLVE_CACHE_SIZE:
            _SOLVE_CACHE.popitem(last=False)
    return abl


def clear() -> None:
    """Forget every kept solve (for timings of the solve itself)."""
    with _SOLVE_LOCK:
        _SOLVE_CACHE.clear()


def _solve_moving(spec: AtmosphereSpec, wind_speeds, reference_height: float, at_rest):
    """from_reference_wind for the conditions not at rest (those at rest take the fastest
    moving condition's speed, or 10 m/s when every condition is at rest)."""
    moving = wind_speeds[~at_rest]
    wind_speeds = np.where(at_rest, moving.max() if moving.size else 10.0, wind_speeds)
    z0 = spec.inputs.get("roughness_length")
    if z0 is not None and np.any(reference_height <= np.asarray(z0)):
        raise ValueError(
            f"flow_field.reference_wind_height = {reference_height} m must be above "
            f"{CONFIG_PATH}.roughness_length (max {np.max(z0)} m)"
        )
    try:
        abl = EkmanABL.from_reference_wind(
            wind_speeds[:, None, None, None], reference_height, **spec.inputs
        )
    except ValueError as error:
        raise ValueError(
            f"{CONFIG_PATH} driven by flow_field.wind_speeds at flow_field.reference_wind_height: "
            f"{error}"
        ) from error
    return abl
