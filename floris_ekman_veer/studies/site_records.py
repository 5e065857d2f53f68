"""A site's records as the fit takes them (docs/measurements.md#a-year-of-records): the records no
fit should see (repeated time stamps, infinite or zero readings, too few data) named with a
reason, the heights of cups and vanes as the fit's data, the vane offsets again from the records
the fit finds neutral (docs/measurements.md#vane-offsets), and the model's neutral turning."""

from __future__ import annotations

import numpy as np
import pandas as pd

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.atmosphere.fit.fit_inputs import FIT_OPTIONS
from floris_ekman_veer.studies.mast import measured_turbulence
from floris_ekman_veer.studies.vanes import (OFFSET_MIN_RECORDS, strong_wind_rows,
                                             with_offsets_from)

#: Why a record can be left out, in the order ``SiteAtmosphere.summary`` lists them.
EXCLUSION_KINDS = ("repeated record", "repeated time stamp", "infinite reading",
                   "zero reading", "missing data",
                   "calm", "falling speeds", "convective", "backing", "no top", "misfit",
                   "physical bound", "two states")


def fit_heights(instruments, columns):
    """(heights, speeds, directions, speed column names per height) as the fit takes them:
    vanes at heights other than the cups' give their directions at their own heights (the
    speeds there missing, and the directions missing at the cups' heights)."""
    cups, vanes = instruments.cup_heights, instruments.vane_heights
    names = {h: ", ".join(c for _, c, _ in columns.cups[h]) for h in cups}
    directions = instruments.directions
    if directions is None or (cups.size == vanes.size and np.allclose(cups, vanes)):
        return cups, instruments.speeds, directions, [names[h] for h in cups]
    heights = np.union1d(cups, vanes)
    n = instruments.speeds.shape[0]
    speeds = np.full((n, heights.size), np.nan)
    speeds[:, np.searchsorted(heights, cups)] = instruments.speeds
    at_heights = np.full((n, heights.size), np.nan)
    at_heights[:, np.searchsorted(heights, vanes)] = directions
    return heights, speeds, at_heights, [names.get(h, f"(no cup at {h:g} m)") for h in heights]


def offsets_from_neutral_fits(instruments, reference_height, fit_options_and_inputs):
    """The vane offsets again from the strong-wind records the fit (either sign, the offsets of
    the first estimate applied) finds neutral: a strong wind of a stable night turns with height
    more than a neutral one, and would move the median (docs/measurements.md#vane-offsets)."""
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
    # (the records are fitted again, and warned about, by fit_site's own fit)
    with package_warnings.discarding():
        fit = EkmanABL.fit_profile(**fit_data(instruments, rows), on_misfit="flag",
                                   stability="either", **inputs).profile_fit
    neutral = rows[np.asarray(fit.fits) & (np.asarray(fit.stability_class) == "neutral")]
    if neutral.size < OFFSET_MIN_RECORDS:
        return instruments
    return with_offsets_from(instruments, neutral, reference_height,
                             neutral_turning(fit_options_and_inputs))


def fit_data(instruments, rows):
    """``fit_profile``'s data of the records ``rows``: the cups' heights and speeds, and the
    vanes' directions with their own heights (``direction_heights``) where those differ."""
    cups, vanes = instruments.cup_heights, instruments.vane_heights
    data = {"heights": cups, "speeds": instruments.speeds[rows], "directions": None}
    if instruments.directions is not None:
        data["directions"] = instruments.directions[rows]
        if not (cups.size == vanes.size and np.allclose(cups, vanes)):
            data["direction_heights"] = vanes
    return data


def neutral_turning(fit_options_and_inputs):
    """The model's neutral turning between heights (for the vane offsets): the direction at
    ``heights`` minus that at ``height`` [deg, meteorological] per speed at ``height``."""
    fixed = {k: (float(np.median(v)) if np.ndim(v) else v)
             for k, v in fit_options_and_inputs.items() if k not in FIT_OPTIONS}

    def turning(speed, height, heights):
        abl = EkmanABL.from_reference_wind(speed, height, obukhov_length=np.inf, **fixed)
        angle = np.asarray(abl.wind_angle(np.asarray(heights, float)[:, None]), float)
        return -(angle - np.asarray(abl.wind_angle(height), float)[None, :]).T

    return turning


def screen_records(speed_columns, labels, heights, speeds, directions, unknowns):
    """{row: (kind, text)} of the records no fit should see: repeated time stamps, zero or
    negative speed readings, too few data."""
    excluded = {}
    stamps = pd.Series(labels)
    repeated = stamps.duplicated(keep=False)
    if repeated.any():
        data = pd.DataFrame(speeds if directions is None else np.hstack([speeds, directions]))
        for stamp, group in stamps[repeated].groupby(stamps[repeated], sort=False):
            same = group.index.to_numpy()
            if len(data.iloc[same].drop_duplicates()) == 1:  # (NaN equals NaN here)
                for k in same[1:]:
                    excluded[k] = ("repeated record", f"a repeat of row {same[0]} (same time "
                                   "stamp and data): counted once")
            else:
                for k in same:
                    excluded[k] = ("repeated time stamp",
                                   f"time stamp {stamp} is given to {len(same)} records (rows "
                                   f"{', '.join(str(j) for j in same)}) with different data: "
                                   "which one is the record of that time is unknown")
    # An infinite reading (a logger's overflow) is no measurement: named by its time stamp.
    infinite = np.isinf(speeds) | (np.isinf(directions) if directions is not None else False)
    for i in np.flatnonzero(np.atleast_2d(infinite).any(axis=1)):
        if i not in excluded:
            excluded[i] = ("infinite reading", "an infinite speed or direction reading: a "
                           "logger or instrument fault; give NaN (missing) where a reading is "
                           "not a measurement")
    bad = ~(np.isnan(speeds) | (speeds > 0))
    for i in np.flatnonzero(bad.any(axis=1)):
        if i in excluded:
            continue
        columns = [speed_columns[j] for j in np.flatnonzero(bad[i])]
        values = sorted({f"{v:g}" for v in speeds[i][bad[i]]})
        what = "zero" if values == ["0"] else "zero or negative" if "0" in values else "negative"
        excluded[i] = ("zero reading",
                       f"{what} speed reading ({', '.join(values)} m/s) in "
                       f"{', '.join(columns)}: a calm or a stalled or failed anemometer; give NaN "
                       "(missing) where a reading is not a measurement")
    valid = np.sum(np.isfinite(speeds), axis=1)
    changes = 0 if directions is None else np.maximum(
        np.sum(np.isfinite(directions), axis=1) - 1, 0)
    for i in np.flatnonzero((valid < 1) | (valid + changes < unknowns)):
        if i not in excluded:
            excluded[i] = ("missing data",
                           f"{valid[i]} speed(s) and {np.broadcast_to(changes, valid.shape)[i]} "
                           f"direction change(s): the fit needs a speed and {unknowns} data in all")
    return excluded


def more_excluded_text(excluded, labels, first):
    others = [k for k in sorted(excluded) if k != first]
    if not others:
        return ""
    shown = ", ".join(labels[k] for k in others[:5])
    return (f"; {len(others)} more record(s) cannot be fitted either ({reasons_text(excluded)}"
            f": {shown}{', ...' if len(others) > 5 else ''})")


def reasons_text(excluded):
    counts = pd.Series([kind for kind, _ in excluded.values()]).value_counts()
    return ", ".join(f"{n} {kind}" for kind, n in counts.items())

