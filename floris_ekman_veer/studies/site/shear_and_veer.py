"""The atmosphere of FLORIS's simpler inflow inputs (docs/measurements.md#simpler-site-inputs): a
hub speed with a power-law shear exponent and/or the veer across the rotor, fitted by the profile
fit."""

from __future__ import annotations

import numpy as np

from floris_ekman_veer._validation import real_array, require_at
from floris_ekman_veer.atmosphere.ekman import EkmanABL

#: Fractions of the rotor radius at which :func:`atmosphere_from_shear_and_veer` samples the
#: power law: bottom tip, half way, hub, half way, top tip.
ROTOR_SAMPLES = (-1.0, -0.5, 0.0, 0.5, 1.0)


def atmosphere_from_shear_and_veer(hub_speed, hub_height, rotor_diameter, shear_exponent=None,
                                   veer=None, *, speed_tolerance=0.01, veer_tolerance=0.5,
                                   **fit_options_and_inputs) -> EkmanABL:
    """The atmosphere of FLORIS's simpler inflow inputs (docs/measurements.md#simpler-site-inputs):
    a hub speed [m/s] with a power-law ``shear_exponent`` and/or the ``veer`` [deg, positive
    veering] from the bottom to the top of the rotor.

    The power law U_hub (z/z_hub)^shear is sampled at the rotor's bottom tip, half radius, hub,
    and up, and the veer taken as the direction change between the tips; ``EkmanABL.fit_profile``
    fits them with ``speed_noise = speed_tolerance * hub_speed`` and ``direction_noise =
    veer_tolerance``. With one of shear and veer the atmosphere follows exactly (two unknowns,
    u* and L, two data: the hub speed and that number) and its profile gives the other; with
    both, the model has one stability to meet two numbers (at a given z0 its shear and veer go
    together) and the fit is refused when no stability meets both within the tolerances
    (``fit_roughness=True`` lets z0 meet the shear). Vectorised: the inputs broadcast over
    conditions of shape (n,).
    """
    if shear_exponent is None and veer is None:
        raise ValueError("atmosphere_from_shear_and_veer needs shear_exponent, veer or both")
    for name, value, ok, valid in (
            ("hub_speed", hub_speed, lambda v: v > 0, "> 0 m/s"),
            ("hub_height", hub_height, lambda v: v > 0, "> 0 m"),
            ("rotor_diameter", rotor_diameter, lambda v: v > 0, "> 0 m"),
            ("shear_exponent", shear_exponent, lambda v: np.isfinite(v), "finite"),
            ("veer", veer, lambda v: np.isfinite(v), "finite [deg]"),
            ("speed_tolerance", speed_tolerance, lambda v: (v > 0) & (v < 1),
             "in (0, 1): a fraction of the hub speed"),
            ("veer_tolerance", veer_tolerance, lambda v: v > 0, "> 0 deg")):
        if value is None:
            continue
        array = real_array(f"atmosphere_from_shear_and_veer: {name}", value, valid)
        require_at(np.isfinite(array) & ok(array), f"atmosphere_from_shear_and_veer: {name}",
                   valid, array)
    for name, tolerance in (("speed_tolerance", speed_tolerance),
                            ("veer_tolerance", veer_tolerance)):
        if np.ndim(tolerance) != 0:
            raise ValueError(f"atmosphere_from_shear_and_veer: {name} must be one number; got "
                             f"an array of shape {np.shape(tolerance)}")
    single = all(np.ndim(v) == 0 for v in (hub_speed, hub_height, rotor_diameter,
                                           shear_exponent, veer))
    hub_speed, hub_height, rotor_diameter = (
        np.atleast_1d(np.asarray(v, dtype=float)) for v in (hub_speed, hub_height, rotor_diameter)
    )
    given = {"hub_speed": hub_speed, "hub_height": hub_height, "rotor_diameter": rotor_diameter,
             "shear_exponent": shear_exponent, "veer": veer}
    try:
        n = np.broadcast_shapes(*(np.shape(v) for v in given.values() if v is not None))
    except ValueError:
        shapes = ", ".join(f"{k} {np.shape(v)}" for k, v in given.items() if v is not None)
        raise ValueError("atmosphere_from_shear_and_veer: the inputs must be numbers or 1-D "
                         f"arrays of one length (one per condition); got shapes {shapes}") from None
    if len(n) != 1:
        raise ValueError("atmosphere_from_shear_and_veer: inputs must be numbers or 1-D arrays")
    radius = 0.5 * np.broadcast_to(rotor_diameter, n)[:, None]
    hub = np.broadcast_to(hub_height, n)[:, None]
    if np.any(~(radius < hub)):
        raise ValueError("atmosphere_from_shear_and_veer: the rotor's bottom tip must be above "
                         f"the ground (rotor_diameter / 2 < hub_height); got rotor_diameter "
                         f"{rotor_diameter}, hub_height {hub_height}")
    heights = hub + radius * np.asarray(ROTOR_SAMPLES)[None, :]
    centre = ROTOR_SAMPLES.index(0.0)
    speed = np.broadcast_to(hub_speed, n)[:, None]
    if shear_exponent is None:
        speeds = np.where(np.arange(heights.shape[1]) == centre, speed, np.nan)
    else:
        speeds = speed * (heights / hub) ** np.broadcast_to(shear_exponent, n)[:, None]
    directions = None
    if veer is not None:
        # Meteorological direction grows with veering; only the tips carry the veer.
        turn = np.broadcast_to(veer, n)[:, None] * (heights - hub) / (2.0 * radius)
        directions = np.where(np.isin(np.arange(heights.shape[1]), (0, heights.shape[1] - 1)),
                              270.0 + turn, np.nan)
    if single:
        heights, speeds = heights[0], speeds[0]
        directions = None if directions is None else directions[0]
    # The veer is met within veer_tolerance as stated: no model error of the directions is
    # added to it (docs/measurements.md#direction-model-error).
    fit_options_and_inputs.setdefault("direction_model_error", 0.0)
    # The fit flags what it refuses; the refusal is said here, of this function's inputs.
    on_misfit = fit_options_and_inputs.pop("on_misfit", "raise")
    abl = EkmanABL.fit_profile(
        heights, speeds, directions,
        speed_noise=float(speed_tolerance * np.min(hub_speed)), direction_noise=veer_tolerance,
        on_misfit="flag" if on_misfit == "raise" else on_misfit, **fit_options_and_inputs,
    )
    failing = np.flatnonzero(~np.atleast_1d(abl.profile_fit.fits))
    if on_misfit != "raise" or failing.size == 0:
        return abl
    k = int(failing[0])
    value = (lambda v: repr(float(np.ravel(v)[0]))) if single else (
        lambda v: f"{float(np.broadcast_to(v, n)[k]):g}")
    given = " and ".join(f"{name}={value(v)}{unit}" for name, v, unit in (
        ("shear_exponent", shear_exponent, ""),
        ("veer", veer, " [deg, from the bottom to the top of the rotor]")) if v is not None)
    where = (f"{given} at hub_speed {hub_speed.tolist()} m/s" if single else
             f"condition {k} ({given} at hub_speed {value(hub_speed)} m/s)")
    more = ""
    if failing.size > 1:
        shown = ", ".join(str(j) for j in failing[1:6])
        more = (f"; {failing.size - 1} more condition(s) fail ({shown}"
                f"{', ...' if failing.size > 6 else ''})")
    raise ValueError(
        f"atmosphere_from_shear_and_veer: {where} "
        f"fits no atmosphere of the model (within speed_tolerance={speed_tolerance:g}, "
        f"veer_tolerance={veer_tolerance:g} deg): {abl.profile_fit.reason(k)[1]}{more}. Give "
        "on_misfit='flag' to keep the fits and read profile_fit.fits")
