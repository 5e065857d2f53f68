"""Stage 3 of the site fit (pipeline.py): the vane offsets, what a vane reads minus the true
direction relative to the vane nearest the reference height, estimated from the records
(docs/measurements.md#vane-offsets).

Two passes: first from the strong-wind records (near-neutral by their wind: mechanical mixing)
as the median turning from the reference vane minus the neutral reference turning between those
heights (:func:`neutral_turning`: the published neutral forms compared, the constant-stress
surface layer's chosen, the others' departure from it the systematic uncertainty), the cups then read again with the corrected directions
(stage 2's :func:`~.readings.read_cups_again`); then again from the strong-wind records that a
fit of either sign finds neutral, since a strong wind of a stable night turns with height more
than a neutral one and would move the median (:func:`offsets_from_neutral_fits`). Given offsets
(``direction_offsets={38: -4.1}``) are stage 2's and are not estimated here.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.atmosphere.fit.fit_inputs import FIT_OPTIONS
from floris_ekman_veer.studies.site.columns import MastColumns
from floris_ekman_veer.studies.site.readings import (
    SHADOW_HALF_WIDTH,
    Instruments,
    fit_data,
    measured_turbulence,
    read_cups_again,
)
from floris_ekman_veer.studies.site.vanes import (
    OFFSET_MIN_RECORDS,
    strong_wind_rows,
    with_offsets_from,
)


def estimate_vane_offsets(instruments: Instruments, records, columns: MastColumns,
                          reference_height: float, fit_options_and_inputs: dict, *,
                          booms=None, shadow_half_width: float = SHADOW_HALF_WIDTH
                          ) -> Instruments:
    """``instruments`` with its vanes' offsets estimated (module docstring): the offsets table
    says per vane the offset, its standard error, the records and the source."""
    if instruments.directions is None or instruments.vane_heights.size < 2:
        return instruments
    turning = neutral_turning(fit_options_and_inputs)
    instruments = with_offsets_from(instruments, strong_wind_rows(instruments, reference_height),
                                    reference_height, turning)
    instruments = read_cups_again(instruments, records, columns, booms=booms,
                                  shadow_half_width=shadow_half_width)
    if (instruments.offsets["source"] == "estimated").any():
        instruments = offsets_from_neutral_fits(instruments, reference_height,
                                                fit_options_and_inputs)
    return instruments


def offsets_from_neutral_fits(instruments: Instruments, reference_height: float,
                              fit_options_and_inputs: dict) -> Instruments:
    """The vane offsets again from the strong-wind records the fit (either sign, the offsets of
    the first estimate applied) finds neutral (module docstring)."""
    rows = strong_wind_rows(instruments, reference_height)
    speeds = instruments.speeds[rows]
    rows = rows[~np.any(speeds <= 0, axis=1) & (np.sum(np.isfinite(speeds), axis=1) >= 2)]
    if rows.size < OFFSET_MIN_RECORDS:
        return instruments
    inputs = {k: (np.asarray(v)[rows] if k not in FIT_OPTIONS and np.ndim(v) == 1 else v)
              for k, v in fit_options_and_inputs.items() if k not in ("stability",)}
    if "turbulence_intensity" in inputs:
        inputs["turbulence_intensity"] = tuple(
            np.asarray(v, float)[rows] if np.ndim(v) == 1 else v
            for v in inputs["turbulence_intensity"])
    elif instruments.speed_std is not None:
        height, intensity = measured_turbulence(instruments, reference_height)
        inputs["turbulence_intensity"] = (height, intensity[rows])
    # (the records are fitted again, and warned about, by the per-record fit of stage 4)
    with package_warnings.discarding():
        fit = EkmanABL.fit_profile(**fit_data(instruments, rows), on_misfit="flag",
                                   stability="either", **inputs).profile_fit
    neutral = rows[np.asarray(fit.fits) & (np.asarray(fit.stability_class) == "neutral")]
    if neutral.size < OFFSET_MIN_RECORDS:
        return instruments
    return with_offsets_from(instruments, neutral, reference_height,
                             neutral_turning(fit_options_and_inputs))


#: The surface layer, where the stress is constant with height and the wind does not turn
#: (Monin-Obukhov similarity), is the lowest tenth of the neutral boundary layer (Stull 1988,
#: *An Introduction to Boundary Layer Meteorology*, sect. 1.3 and 9.7).
SURFACE_LAYER_FRACTION = 0.1
#: The neutral turning forms compared between the vanes (docs/measurements.md#vane-offsets); the
#: first is the reference, the others' departures from it its systematic uncertainty.
TURNING_FORMS = ("surface layer", "Ekman layer from the ground", "model")


def neutral_turning(fit_options_and_inputs: dict):
    """The neutral turning between heights by the published forms (module docstring): a
    function of (speeds at ``height``, ``height``, ``heights``) giving ``{form: (n, m) array}``,
    the direction at ``heights`` minus that at ``height`` [deg, meteorological: positive
    clockwise], per :data:`TURNING_FORMS`:

    * "surface layer" (the reference): none within the constant-stress surface layer (the lowest
      :data:`SURFACE_LAYER_FRACTION` of the neutral layer's depth h), and above it the
      geostrophic drag law's whole turning alpha_0 (Eq. GDL: tan alpha_0 = -V_g / U_g) spread
      evenly up to h, veering (clockwise with height in the northern hemisphere);
    * "Ekman layer from the ground": alpha_0 spread evenly from the ground to h (no
      constant-stress layer: the most an Ekman layer turns near the ground with a uniform rate);
    * "model": the model's own neutral turning (EkmanABL with L = inf at the site's inputs),
      which near the ground turns counterclockwise by a few tenths of a degree before veering
      above (its surface layer's matching, not a published neutral form).

    h, alpha_0 and u* are the model's neutral state at each speed."""
    fixed = {k: (float(np.median(v)) if np.ndim(v) else v)
             for k, v in fit_options_and_inputs.items() if k not in FIT_OPTIONS}

    def turning(speed, height, heights):
        abl = EkmanABL.from_reference_wind(speed, height, obukhov_length=np.inf, **fixed)
        heights = np.asarray(heights, float)
        angle = np.asarray(abl.wind_angle(heights[:, None]), float)
        model = -(angle - np.asarray(abl.wind_angle(height), float)[None, :]).T
        depth = np.asarray(abl.boundary_layer_height, float).reshape(-1, 1)
        # the whole turning, clockwise with height in the northern hemisphere
        whole = (np.abs(np.asarray(abl.cross_isobaric_angle, float)).reshape(-1, 1)
                 * np.asarray(abl.hemisphere, float).reshape(-1, 1))
        top = SURFACE_LAYER_FRACTION * depth

        def above_surface_layer(z):
            return whole * np.clip(z - top, 0.0, None) / (depth - top)

        def from_ground(z):
            return whole * np.minimum(z, depth) / depth

        return {"surface layer": above_surface_layer(heights[None, :])
                - above_surface_layer(height),
                "Ekman layer from the ground": from_ground(heights[None, :]) - from_ground(height),
                "model": model}

    return turning


def turning_forms_between(fit_options_and_inputs: dict, speeds, height: float, lower: float,
                          upper: float) -> pd.DataFrame:
    """The neutral forms' median turning from ``lower`` to ``upper`` [deg, meteorological] at
    the speeds ``speeds`` at ``height`` (:func:`neutral_turning`): the comparison behind the
    reference turning, for a report or the docs."""
    forms = neutral_turning(fit_options_and_inputs)(np.asarray(speeds, float), height,
                                                     np.array([upper, lower]))
    return pd.DataFrame({"turning_deg": {k: float(np.median(v[:, 0] - v[:, 1]))
                                         for k, v in forms.items()}})
