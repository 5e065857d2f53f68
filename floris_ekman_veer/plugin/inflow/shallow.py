"""Conditions whose boundary layer is shallower than the rotor: counted, warned about, or refused.

Weak winds under strong stable stratification give boundary layers tens of metres deep (SBL-6 at
3 m/s: h = 47 m under a 90 m hub). The model runs there (docs/atmosphere.md#shallow-boundary-layer):
the inflow above h is the geostrophic wind and the turbulence of the variance law is continued
above h to its zero at h exp(B1/A1), so the ``ekman_veer`` wake expansion falls continuously to
its floor. Those conditions lie outside what the paper validated, so at the user's run they are
counted in a :class:`ShallowBoundaryLayerWarning` (once: building a model, a shipped input
included, says nothing), or, when the model is built (its conditions known), with::

    wake:
      wake_velocity_parameters:
        ekman_veer:
          shallow_boundary_layer: raise

refused with a ValueError naming each such condition's index, wind speed, h and hub height
(``ignore``: counted silently; the package sends its ParFlorisModel and Dask workers their share
of conditions with ``ignore``, because the parent counts all its conditions once, and
``optimize_yaw`` counts them once at its start, not in each of its re-built models). A condition
is affected when any rotor's top (hub height + D/2) is above h.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer.plugin.wake_models import input_checks
from floris_ekman_veer.plugin.inflow.atmosphere_block import PARAMETER_BLOCK, AtmosphereSpec, atmosphere_of
from floris_ekman_veer.plugin.inflow.solve_cache import solve
from floris_ekman_veer.warnings import ShallowBoundaryLayerWarning  # noqa: F401  (its home once)

#: Key of the policy in ``wake.wake_velocity_parameters.ekman_veer``, and its values.
POLICY_KEY = "shallow_boundary_layer"
POLICIES = ("warn", "raise", "ignore")
POLICY_PATH = f"wake.wake_velocity_parameters.ekman_veer.{POLICY_KEY}"

_SHOWN = 5  # conditions listed in a message

#: When :func:`check_rotor_inside` is called: a model's build (refuses only) or a run (warns).
STAGES = ("build", "run")


def policy(block: Mapping | None) -> str:
    """The validated policy of an ``ekman_veer`` parameter block ("warn" by default)."""
    value = (block or {}).get(POLICY_KEY, "warn")
    if value not in POLICIES:
        raise ValueError(f"{POLICY_PATH} must be one of {list(POLICIES)}; got {value!r}")
    return value


def check_rotor_inside(
    block: Mapping | None, boundary_layer_height, wind_speeds, reference_height: float,
    hub_heights, rotor_diameters, *, stage: str,
) -> np.ndarray:
    """Warn about (policy "warn") or refuse (policy "raise") conditions with a rotor top above h.

    ``boundary_layer_height`` and ``wind_speeds`` per condition; ``hub_heights`` and
    ``rotor_diameters`` per turbine. ``stage``: "build" (a model's build: refuses, never warns,
    so that building an input says nothing before the user's run) or "run" (warns). Returns the
    boolean mask of affected conditions.
    """
    mode = policy(block)
    if stage not in STAGES:
        raise ValueError(f"check_rotor_inside: stage must be one of {list(STAGES)}; got {stage!r}")
    if stage == "build" and mode == "warn":
        mode = "ignore"
    h = np.asarray(boundary_layer_height, dtype=float).reshape(-1)
    speeds = np.broadcast_to(np.asarray(wind_speeds, dtype=float).reshape(-1), h.shape)
    hubs = np.asarray(hub_heights, dtype=float).reshape(-1)
    tops = hubs + 0.5 * np.asarray(rotor_diameters, dtype=float).reshape(-1)
    highest = np.argmax(tops)
    affected = tops[highest] > h
    if not np.any(affected) or mode == "ignore":
        return affected
    hub, top = hubs[highest], tops[highest]
    index = np.flatnonzero(affected)
    listed = "; ".join(
        f"condition {i}: wind speed {speeds[i]:.6g} m/s at {reference_height:.6g} m, "
        f"h = {h[i]:.4g} m, hub height {hub:.6g} m (rotor top {top:.6g} m)"
        for i in index[:_SHOWN]
    )
    more = f"; and {index.size - _SHOWN} more" if index.size > _SHOWN else ""
    hub_above = int(np.count_nonzero(h[index] <= hub))
    if mode == "raise":
        raise ValueError(
            f"{index.size} of {h.size} conditions have a boundary layer shallower than the rotor "
            f"(rotor top above h), refused by {POLICY_PATH} = 'raise': {listed}{more}"
        )
    package_warnings.warn_shallow(index.size, h.size, speeds[index], h[index], top, hub,
                                  hub_above, reference_height, POLICY_PATH)
    return affected


def reference_height(core) -> float | None:
    """The Core's reference wind height, FLORIS's "use the hub height" sentinel (-1, which
    FlorisModel replaces without a rebuild) read as the hub height; None where FLORIS refuses
    the sentinel (several hub heights)."""
    height = core.flow_field.reference_wind_height
    if abs(height + 1.0) < 1e-6:
        hubs = np.unique(core.farm.hub_heights)
        if hubs.size != 1:
            return None
        height = float(hubs[0])
    return height


def check_core(core, abl, height: float, stage: str) -> None:
    """The policy of a Core's ``ekman_veer`` block on its conditions solved as ``abl``
    (those at rest have no boundary layer to be shallow), at ``stage``."""
    check_rotor_inside(
        core.wake.wake_velocity_parameters.get(PARAMETER_BLOCK),
        np.where(abl.at_rest, np.inf, np.reshape(abl.boundary_layer_height, -1)),
        core.flow_field.wind_speeds, height, core.farm.hub_heights, core.farm.rotor_diameters,
        stage=stage,
    )


def warn_shallow(core, spec: AtmosphereSpec | None = None) -> None:
    """Count a Core's conditions whose boundary layer is shallower than a rotor top in one
    :class:`~floris_ekman_veer.warnings.ShallowBoundaryLayerWarning`, at the user's run: every
    Core solve, the ParFlorisModel parent before its workers (sent with
    the policy ``ignore``) and ``optimize_yaw`` before its many re-built models. ``spec``: the
    Core's atmosphere, if known (else read). FLORIS's turbulence intensities that the ekman_veer
    model does not read are said there as well (:func:`input_checks.notice_unused_turbulence`)."""
    spec = atmosphere_of(core) if spec is None else spec
    if spec is None or not core.flow_field.n_findex:
        return
    height = reference_height(core)
    if height is not None:
        abl = solve(spec, core.flow_field.wind_speeds, height)
        check_core(core, abl, height, "run")
        # Said at the run too, not at build: a shipped input's placeholder TI is not the user's.
        input_checks.notice_unused_turbulence(core, abl, spec)
