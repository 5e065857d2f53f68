"""Stage 3 of the site fit (pipeline.py), with the vane offsets: the site's own neutral baseline
(docs/measurements.md#the-sites-neutral-baseline).

From the strong-wind records (the speed at the cup nearest the reference height at least
:data:`~.vanes.OFFSET_MIN_SPEED`: mechanical mixing makes them near-neutral, the premise of
wind-resource practice's roughness rose, Troen & Petersen 1989, European Wind Atlas, ch. 8;
IEC 61400-12-1 Annex B), per direction sector:

* the effective roughness length z0: the z0 at which the model's own neutral profile (Eq.
  U_model with L = inf) gives the sector's median ratio of the speed at the cup nearest the
  reference height to the speed at the lowest cup, at the sector's median speed. The ratio is
  the mean of the sector's records within :data:`RATIO_CLIP` robust standard deviations (from
  the MAD) of their median: the records beyond are spikes a cup pair's check could not catch
  (one cup in use, its partner in the mast's wake), and the mean of the rest has a standard
  error 0.8 times the median's for the cups' Gaussian scatter (efficiency 2/pi for the
  median; on 16 other seeds of examples/instrumented_mast_year.py with certificates, the rms
  error of ln z0 0.143 against 0.158, every sector within a factor 1.5 in 14 of 16 seeds
  against 10, the reported uncertainty as honest: rms of error / sigma 0.95 both). An effective
  z0 holds what the log law's z0 alone does not (a hilltop's speed-up flattens the profile,
  upwind roughness changes steepen it): it is the roughness that makes the model's neutral
  profile the site's own. Its uncertainty is the ratio's standard error (of the median, from the
  clipped records' standard deviation over their square root) carried through that inversion, given as a factor (z0 times or divided by it), and beside
  it the systematic factor of the cups' calibration (their certificates' uncertainty where
  applied, readings.py's :func:`~.readings.calibrated_cups`, else the generic transfer
  function's :data:`~.readings.CUP_CALIBRATION_GENERIC`);
* the neutral turbulence intensity: the median of the cups' sigma_u / U at that cup, with its
  standard error, beside the model's neutral I_u there (Eq. Iu_model) at the sector's z0; and
  the terrain's excess turbulence (Wieringa 1993; Panofsky & Dutton 1984, ch. 7): the median
  over the same records of each one's measured TI over the model's neutral I_u at its own
  speed and its sector's z0, with the ratio's robust relative scatter (the terrain's
  uncertainty). The stability fit reads the measured TI only as its departure from it
  (stability.py :func:`~.stability.turbulence_departure`).

Sectors of :data:`SECTOR_WIDTH` deg (12, as a wind atlas's rose); a sector with fewer than
:data:`BASELINE_MIN_RECORDS` strong-wind records takes those of a wider window about its centre
(widened by half a sector at a time), so where the data are thin the rose has fewer independent
sectors, and says so (``half_width_deg``). Each record's neutral roughness and turbulence are
its sector's (by the direction at the vane nearest the reference height), the all-direction
values where it has none.
"""

from __future__ import annotations

from numbers import Real

import attrs
import numpy as np
import pandas as pd

from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.atmosphere.fit.fit_inputs import FIT_OPTIONS
from floris_ekman_veer.studies.site.readings import CUP_CALIBRATION_GENERIC, Instruments
from floris_ekman_veer.studies.site.vanes import (OFFSET_MIN_SPEED, direction_near,
                                                  median_and_error, reference_index,
                                                  wrapped_angle)

#: Width [deg] of the roughness rose's sectors (12 sectors).
SECTOR_WIDTH = 30.0
#: Strong-wind records a sector's estimate needs (else its window widens).
BASELINE_MIN_RECORDS = 20
#: The roughness lengths [m] over which the model's neutral shear is inverted: open sea to
#: city centre (Wieringa 1993's table).
ROUGHNESS_RANGE = (1e-5, 2.0)
_GRID = np.geomspace(*ROUGHNESS_RANGE, 61)
#: A sector's shear ratios beyond this many robust standard deviations (1.4826 MAD) of their
#: median are left out of its mean (module docstring).
RATIO_CLIP = 3.5


@attrs.frozen(eq=False)
class NeutralBaseline:
    """The site's neutral baseline (module docstring).

    Attributes:
        sectors: per sector centre [deg] (index) ``half_width_deg`` (the window its records come
            from), ``records``, ``roughness_length`` [m], ``roughness_factor`` (its statistical
            uncertainty as a factor), ``roughness_factor_calibration`` (the cups' calibration's),
            ``speed_ratio`` (the measured median shear ratio) and its
            ``speed_ratio_error``, ``neutral_ti`` and ``neutral_ti_error`` (NaN without the
            cups' standard deviations), ``model_neutral_ti`` (the model's I_u at the sector's z0),
            ``terrain_turbulence_ratio`` and ``terrain_turbulence_scatter`` (the median of the
            records' measured TI over the model's neutral I_u, and its relative scatter) and
            ``source`` ("estimated", "given").
        heights: (lower, upper) cup heights [m] of the shear ratio (the turbulence's: the cup
            nearest the reference height).
        roughness_lengths, turbulence_intensities: per record of the records its sector's
            neutral roughness length [m] and neutral turbulence intensity (NaN: none measured).
        sector_of: per record its sector's centre [deg] (NaN: no direction).
        terrain_turbulence_ratios, terrain_turbulence_scatters: per record its sector's
            terrain excess turbulence and its relative scatter (the all-direction values where
            it has no direction; 1 and NaN without the cups' standard deviations).
    """

    sectors: pd.DataFrame
    heights: tuple
    roughness_lengths: np.ndarray
    turbulence_intensities: np.ndarray
    sector_of: np.ndarray
    terrain_turbulence_ratios: np.ndarray | None = None
    terrain_turbulence_scatters: np.ndarray | None = None

    def __str__(self) -> str:
        return (f"neutral baseline (records from {OFFSET_MIN_SPEED:g} m/s; shear between "
                f"{self.heights[0]:g} and {self.heights[1]:g} m):\n"
                + self.sectors.to_string(float_format="{:.4g}".format))


def checked_roughness(roughness_length, reference_height: float):
    """``roughness_length`` as fit_site takes it: "estimate", a number [m] > 0, or
    ``{sector centre deg: z0}``; ValueError naming the entry otherwise."""
    if isinstance(roughness_length, str):
        if roughness_length != "estimate":
            raise ValueError(f"fit_site: roughness_length must be 'estimate', a number [m] or "
                             f"{{sector centre deg: z0 m}}; got {roughness_length!r}")
        return roughness_length
    limit = reference_height / 10.0
    entries = (roughness_length.items() if isinstance(roughness_length, dict)
               else [(None, roughness_length)])
    if isinstance(roughness_length, dict) and not roughness_length:
        raise ValueError("fit_site: roughness_length {} names no sector; give {sector centre "
                         "deg: z0 m}, a number or 'estimate'")
    for sector, z0 in entries:
        where = "roughness_length" if sector is None else f"roughness_length[{sector!r}]"
        if sector is not None and (isinstance(sector, bool) or not isinstance(sector, Real)
                                   or not 0.0 <= sector < 360.0):
            raise ValueError(f"fit_site: roughness_length's sectors must be their centres in "
                             f"[0, 360) deg; got {sector!r}")
        if sector is None and np.ndim(z0) == 1:
            z0 = np.asarray(z0, float)  # (one per record: fit_profile checks its length)
            bad = ~(np.isfinite(z0) & (z0 > 0) & (z0 < limit))
            if bad.any():
                k = int(np.flatnonzero(bad)[0])
                raise ValueError(f"fit_site: roughness_length[{k}] must be in (0, {limit:g}) m "
                                 f"(below a tenth of the reference height); got {z0[k]!r}")
            continue
        if (isinstance(z0, bool) or not isinstance(z0, Real) or not np.isfinite(z0)
                or not 0 < z0 < limit):
            raise ValueError(f"fit_site: {where} must be a number in (0, {limit:g}) m (below a "
                             f"tenth of the reference height {reference_height:g} m); got {z0!r}")
    return roughness_length


def neutral_baseline(instruments: Instruments, reference_height: float,
                     fit_options_and_inputs: dict, roughness_length="estimate", *,
                     cups_per_height=None, calibration_uncertainty=None) -> NeutralBaseline:
    """The site's neutral baseline from the records (module docstring). ``roughness_length``:
    "estimate", or a number or ``{sector centre: z0}`` given (then only the turbulence is
    estimated, and each record takes the given roughness of the sector nearest its direction).
    ValueError when "estimate" finds fewer than :data:`BASELINE_MIN_RECORDS` strong-wind
    records (give the roughness length). ``calibration_uncertainty``: per cup height the
    relative calibration uncertainty of its speed (the cups' certificates', readings.py); by
    default the generic transfer function's over the height's ``cups_per_height`` cups. It does
    not average out over records (a 1 % error of the shear ratio moves z0 by a factor of about
    1.5 between 40 and 80 m) and is given as its own factor beside the statistical one."""
    n = instruments.speeds.shape[0]
    cups = instruments.cup_heights
    # The turbulence's cup is the one nearest the reference height; the shear is read between
    # the lowest cup and that one (the highest where that one is the lowest).
    cup = reference_index(cups, reference_height)
    lower, upper = 0, (cup if cup > 0 else cups.size - 1)
    speeds = instruments.speeds
    counts = list(cups_per_height or [1] * cups.size)
    direction = direction_near(instruments.directions, instruments.vane_heights,
                               reference_height, n)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = speeds[:, upper] / speeds[:, lower]
        intensity = (instruments.speed_std[:, cup] / speeds[:, cup]
                     if instruments.speed_std is not None else np.full(n, np.nan))
    strong = (np.isfinite(speeds[:, cup]) & (speeds[:, cup] >= OFFSET_MIN_SPEED)
              & np.isfinite(ratio) & (ratio > 0))
    given = not isinstance(roughness_length, str)
    if not given and np.count_nonzero(strong) < BASELINE_MIN_RECORDS:
        raise ValueError(
            f"fit_site: roughness_length='estimate' needs {BASELINE_MIN_RECORDS} records or more "
            f"with {OFFSET_MIN_SPEED:g} m/s or more at {cups[cup]:g} m (near-neutral: the "
            f"site's neutral profile); the records have {np.count_nonzero(strong)}. Give the "
            "roughness length (a number [m] or {sector centre deg: z0 m})")
    centres = np.arange(0.0, 360.0, SECTOR_WIDTH)
    rows, windows = [], []
    for centre in centres:
        half = SECTOR_WIDTH / 2.0
        while True:
            near = np.abs(wrapped_angle(direction - centre)) < half
            use = strong & near
            if np.count_nonzero(use) >= BASELINE_MIN_RECORDS or half >= 180.0:
                break
            half += SECTOR_WIDTH / 2.0
        if half >= 180.0:
            use = strong  # (every direction, and the records without one)
        windows.append(use)
        shear, shear_error, kept = clipped_mean_and_error(ratio[use])
        ti, ti_error = median_and_error(intensity[use])
        rows.append({"centre_deg": centre, "half_width_deg": min(half, 180.0),
                     "records": int(np.count_nonzero(use)),
                     # (the kept records' mean speed: their mean ratio is the model's there
                     # where the neutral ratio changes linearly with the speed)
                     "speed": float(np.mean(speeds[use, upper][kept])) if kept.any() else np.nan,
                     "speed_ratio": shear, "speed_ratio_error": shear_error,
                     "neutral_ti": ti, "neutral_ti_error": ti_error})
    table = pd.DataFrame(rows).set_index("centre_deg")
    fixed = {k: (float(np.median(v)) if np.ndim(v) else v)
             for k, v in fit_options_and_inputs.items()
             if k not in FIT_OPTIONS and k != "roughness_length"}
    heights = (float(cups[lower]), float(cups[upper]))
    if given:
        table["roughness_length"] = _given_at(roughness_length, table.index.to_numpy())
        table["roughness_factor"] = np.nan
        table["roughness_factor_calibration"] = np.nan
        table["source"] = "given"
    else:
        per_height = (np.asarray(calibration_uncertainty, float)
                      if calibration_uncertainty is not None
                      else CUP_CALIBRATION_GENERIC / np.sqrt(np.asarray(counts, float)))
        calibration = float(np.hypot(per_height[lower], per_height[upper]))
        z0, factor, inside, systematic = _inverted(table, heights, fixed, calibration)
        table["roughness_length"], table["roughness_factor"] = z0, factor
        table["roughness_factor_calibration"] = systematic
        # (a shear beyond the model's neutral range, open sea to city centre, is given the
        # range's end and named: no effective roughness of the model makes it)
        table["source"] = np.where(inside, "estimated", "range end")
    table["model_neutral_ti"] = _model_turbulence(table, heights[1], float(cups[cup]), fixed)
    table = table.drop(columns="speed")
    sector = np.full(n, np.nan)
    known = np.isfinite(direction)
    sector[known] = centres[np.argmin(np.abs(wrapped_angle(
        direction[known, None] - centres[None, :])), axis=1)]
    at = np.searchsorted(centres, np.where(known, sector, 0.0))
    ti_all, _ = median_and_error(intensity[strong])
    turbulence = np.where(known, table["neutral_ti"].to_numpy()[at], ti_all)
    if isinstance(roughness_length, dict):
        values = np.array([float(v) for v in roughness_length.values()])
        roughness = np.where(known, _given_at(roughness_length, np.where(known, direction, 0.0)),
                             float(np.exp(np.mean(np.log(values)))))
    elif given:
        roughness = np.broadcast_to(np.asarray(roughness_length, float), (n,)).copy()
    else:
        z0 = table["roughness_length"].to_numpy()
        roughness = np.where(known, z0[at], float(np.exp(np.mean(np.log(z0)))))
    excess, scatter, excess_all, scatter_all = _terrain_turbulence(
        intensity, speeds[:, cup], float(cups[cup]), roughness, strong, windows, fixed)
    table["terrain_turbulence_ratio"], table["terrain_turbulence_scatter"] = excess, scatter
    return NeutralBaseline(sectors=table, heights=heights, roughness_lengths=roughness,
                           turbulence_intensities=turbulence, sector_of=sector,
                           terrain_turbulence_ratios=np.where(known, excess[at], excess_all),
                           terrain_turbulence_scatters=np.where(known, scatter[at], scatter_all))


def _terrain_turbulence(intensity, speed, height, roughness, strong, windows, fixed):
    """(per sector, its records ``windows``, the median of the strong-wind records' measured TI
    over the model's neutral I_u at ``height``, each at its own speed there and roughness, and
    its robust relative scatter; the same over every strong-wind record). Without measured TI:
    1 and NaN. With fewer than :data:`BASELINE_MIN_RECORDS` strong-wind records (a short
    record with a given roughness), the upper quartile of the speeds stands for them, in one
    all-direction window."""
    if np.count_nonzero(strong) < BASELINE_MIN_RECORDS:
        moving = np.isfinite(speed) & (speed > 1.0)
        if moving.any():
            strong = moving & (speed >= np.quantile(speed[moving], 0.75))
        windows = [strong] * len(windows)
    ratio = np.full(intensity.size, np.nan)
    pick = strong & np.isfinite(intensity)
    if pick.any():
        abl = EkmanABL.from_reference_wind(speed[pick], height, obukhov_length=np.inf,
                                           **{**fixed, "roughness_length": roughness[pick]})
        ratio[pick] = intensity[pick] / np.asarray(abl.turbulence_intensity(height),
                                                   float).reshape(-1)
    both = [_median_and_scatter(ratio[use]) for use in windows]
    return (np.array([b[0] for b in both]), np.array([b[1] for b in both]),
            *_median_and_scatter(ratio[strong]))


def _median_and_scatter(ratio):
    """The median of the ratios and their relative scatter (1.4826 MAD / median); 1 and NaN
    without any."""
    ratio = ratio[np.isfinite(ratio)]
    if ratio.size == 0:
        return 1.0, np.nan
    median = float(np.median(ratio))
    return median, float(1.4826 * np.median(np.abs(ratio - median)) / median)


def clipped_mean_and_error(values):
    """The mean of the finite ``values`` within :data:`RATIO_CLIP` robust standard deviations
    of their median, its standard error (module docstring; NaN for none) and which values
    are kept."""
    values = np.asarray(values, float)
    finite = np.isfinite(values)
    if not finite.any():
        return np.nan, np.nan, finite
    median = np.median(values[finite])
    spread = 1.4826 * np.median(np.abs(values[finite] - median))
    kept = finite & (np.abs(values - median) <= RATIO_CLIP * spread if spread > 0 else finite)
    if np.count_nonzero(kept) < 2:
        return float(np.mean(values[kept])), 0.0, kept
    return (float(np.mean(values[kept])),
            float(np.std(values[kept], ddof=1) / np.sqrt(np.count_nonzero(kept))), kept)


def _given_at(roughness_length, centres):
    """At the directions [deg] the given roughness: the number (the geometric median of one per
    record), or the given sector's nearest each."""
    if not isinstance(roughness_length, dict):
        value = np.asarray(roughness_length, float)
        return np.full(centres.size, float(np.exp(np.median(np.log(value)))))
    keys = np.array([float(k) for k in roughness_length])
    values = np.array([float(v) for v in roughness_length.values()])
    nearest = np.argmin(np.abs(wrapped_angle(centres[:, None] - keys[None, :])), axis=1)
    return values[nearest]


def _neutral_ratio(z0, speed, heights, fixed):
    """The model's neutral U(upper) / U(lower) at z0 [m] with ``speed`` at the upper height."""
    abl = EkmanABL.from_reference_wind(speed, heights[1], obukhov_length=np.inf,
                                       **{**fixed, "roughness_length": z0})
    return np.asarray(abl.speed(heights[1]), float) / np.asarray(abl.speed(heights[0]), float)


def _inverted(table, heights, fixed, calibration):
    """Per sector the z0 whose model neutral ratio is the measured one, and its uncertainty
    factor (module docstring), and whether the measured ratio lies inside the grid's range.
    One vectorised solve over sectors and the z0 grid."""
    grid = _GRID[_GRID < heights[0] / 10.0]
    speed = table["speed"].to_numpy()
    m = speed.size
    ratios = _neutral_ratio(np.tile(grid, m), np.repeat(speed, grid.size), heights,
                            fixed).reshape(m, grid.size)
    log_grid = np.log(grid)
    z0 = np.empty(m)
    factor = np.empty(m)
    inside = np.zeros(m, bool)
    systematic = np.empty(m)
    for k in range(m):
        # (the neutral ratio grows with z0: interpolated in ln z0; outside the range, its end)
        measured, error = table["speed_ratio"].iloc[k], table["speed_ratio_error"].iloc[k]
        at = np.interp([measured - error, measured, measured + error], ratios[k], log_grid)
        z0[k] = np.exp(at[1])
        factor[k] = np.exp(0.5 * (at[2] - at[0]))
        inside[k] = ratios[k, 0] <= measured <= ratios[k, -1]
        off = measured * calibration
        ends = np.interp([measured - off, measured + off], ratios[k], log_grid)
        systematic[k] = np.exp(0.5 * (ends[1] - ends[0]))
    return z0, factor, inside, systematic


def _model_turbulence(table, height, turbulence_height, fixed):
    """The model's neutral I_u at ``turbulence_height`` per sector at its z0 and its median
    speed at ``height``."""
    speed = table["speed"].to_numpy()
    ok = np.isfinite(speed)
    out = np.full(speed.size, np.nan)
    if ok.any():
        abl = EkmanABL.from_reference_wind(speed[ok], height, obukhov_length=np.inf,
                                           **{**fixed, "roughness_length":
                                              table["roughness_length"].to_numpy()[ok]})
        out[ok] = np.asarray(abl.turbulence_intensity(turbulence_height), float).reshape(-1)
    return out
