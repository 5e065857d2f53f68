"""Stage 2 of the site fit (pipeline.py): the cleaned readings, the records' speeds,
turbulence and directions as wind-resource practice reads a met mast's instruments before any fit
(docs/measurements.md#a-real-mast). Works on stage 1's :class:`~.columns.MastColumns`.

What :func:`read_instruments` makes of them:

* readings that are no number a cup or vane gives (inf) are removed, named ("infinite reading");
* redundant cups: the cup in the mast's wake (the wind from its boom's orientation + 180 deg,
  within ``shadow_half_width``; IEC 61400-12-1 Annex G) is not used, the other one is; both are
  averaged where neither is in the wake; a cup in the wake alone is not used. The wake's ratio
  against the direction is measured from the records (Annex G's two-cup ratio). A pair that
  disagrees beyond the cups' uncertainty (clear cups) or beyond the wake's measured ratio (a cup
  in the wake) in a record is removed at that height and named ("cups disagree"); a pair whose
  median ratio over the year departs from 1 by more than :data:`PAIR_TOLERANCE` is named in
  ``cup_pairs``; a cup reading 0 (or stalled at its starting threshold) beside a working
  partner is dead, not a calm: its reading removed and named ("dead cup"), the partner used;
* stuck vanes (icing): a vane repeating its reading for :data:`~.vanes.STUCK_RECORDS` records
  or more while another vane turns is removed there and named ("stuck vane");
* given vane offsets (``direction_offsets={38: -4.1}``) subtracted from the readings; estimated
  ones are stage 3's (offsets.py), which reads the cups again with them (:func:`read_cups_again`).

Before anything else, the cups' calibration certificates where given
(:func:`calibrated_cups`): each cup's reading re-calibrated from the logger's generic transfer
function to its own certificate's, as wind-resource practice does (IEC 61400-12-1 Annex F).

Also the readings as the fit's data (:func:`fit_heights`, :func:`fit_data`) and the measured
turbulence intensity (:func:`measured_turbulence`).
"""

from __future__ import annotations

import attrs
import numpy as np
import pandas as pd

from floris_ekman_veer.studies.site.columns import MastColumns
from floris_ekman_veer.studies.site.vanes import (
    direction_near,
    median_and_error,
    offsets_given,
    reference_index,
    unstick,
    wrapped_angle,
)

#: Half-width [deg] of the sector around boom orientation + 180 deg in which a cup is in the
#: mast's wake (IEC 61400-12-1 Annex G: a lattice mast's wake reaches about +-20-30 deg).
SHADOW_HALF_WIDTH = 30.0
#: A cup's standard uncertainty of a record's mean speed, relative: calibration, mounting and
#: the 10-minute sampling of a class-1 cup (IEC 61400-12-1 Annex E, 1-2 %).
CUP_UNCERTAINTY = 0.015
#: Bins [deg] of the angle from the mast wake's centre in which the records give its ratio, and
#: the records a bin needs.
WAKE_BIN = 5.0
WAKE_MIN_RECORDS = 20
#: A pair of cups disagrees in a record beyond this many standard deviations of their
#: difference (plus 0.2 m/s: the cups' resolution and starting threshold).
PAIR_SIGMAS = 5.0
#: The largest mast-wake deficit a cup in the wake shows (IEC 61400-12-1 Annex G: up to
#: 20-40 % behind a lattice mast): the span of a wake bin the records do not measure.
MAX_SHADOW_DEFICIT = 0.4
#: Median ratio of a pair beyond 1 +- this: the pair disagrees (two class-1 calibrations, 1 %
#: each, at two standard deviations of their ratio).
PAIR_TOLERANCE = 0.03
#: A speed column reading this many times the cups above it (or, for the top cups over
#: :data:`UNIT_MIN_RECORDS` records or more, the cups below) in median is in km/h (3.6 times
#: m/s): no wind falls with height by that much, and a year's shear never reaches it.
KMH_RATIO = (2.8, 4.6)
UNIT_MIN_RECORDS = 24
#: No site's median wind reaches this [m/s] over :data:`UNIT_SITE_RECORDS` records: a speed
#: column above it is in km/h (every column, so that no ratio shows it).
MAX_MEDIAN_SPEED = 25.0
UNIT_SITE_RECORDS = 720
#: A cup reading this much or less [m/s] (0, or its starting threshold: IEC 61400-12-1 class-1
#: cups start at 0.3-0.5 m/s) beside a partner reading :data:`DEAD_CUP_PARTNER` or more at its
#: height is dead or stalled, not in a calm.
DEAD_CUP_SPEED = 0.5
DEAD_CUP_PARTNER = 2.0
#: A cup's calibration uncertainty, relative, without its certificate applied: the logger's
#: generic transfer function against the cup's own (IEC 61400-12-1 Annex E: about 1 % for a
#: class-1 cup).
CUP_CALIBRATION_GENERIC = 0.01
#: A calibration certificate's standard uncertainty of a cup's slope, relative, where the
#: certificate gives none: the part that differs between cups calibrated in one accredited wind
#: tunnel (its repeatability and the cup's own fit; MEASNET, *Cup anemometer calibration
#: procedure*, v2, 2009). The tunnel's reference, common to the cups, cancels in a ratio of two
#: of them, which is what the roughness rose reads (baseline.py).
CERTIFICATE_UNCERTAINTY = 0.0015
#: A certificate's entries: its own slope [m/s per logger unit] and offset [m/s], and the
#: logger's generic transfer function (slope and offset) the readings were logged with.
CERTIFICATE_KEYS = ("slope", "offset", "logger_slope", "logger_offset")
#: What is named per value removed.
FLAG_KINDS = ("infinite reading", "dead cup", "cups disagree", "stuck vane")



@attrs.frozen(eq=False)
class Instruments:
    """The records as the fit reads them (:func:`read_instruments`).

    Attributes:
        cup_heights, speeds, speed_std: per record (rows) and cup height (columns) the speed and
            its standard deviation [m/s] (NaN: none usable);
        vane_heights, directions: the vanes' directions with their offsets removed [deg];
        offsets: per vane height (index) ``offset_deg`` (reading minus true direction, relative
            to the reference vane), ``uncertainty_deg`` (standard error), ``systematic_deg``
            (the reference turning's: the largest departure of the published neutral forms'
            turning between the vanes from the surface layer's, offsets.py), ``records`` and
            ``source`` ("reference", "estimated", "given", or "not estimated");
        cup_pairs: per cup height with two cups or more: the cups, their median ratio over the
            records where none is in the mast's wake, its standard error, the records, and
            whether they disagree;
        flags: the values removed, one row each: ``row`` (in the records), ``column``,
            ``kind`` (:data:`FLAG_KINDS`) and ``reason``.
    """

    cup_heights: np.ndarray
    speeds: np.ndarray
    speed_std: np.ndarray | None
    vane_heights: np.ndarray
    directions: np.ndarray | None
    offsets: pd.DataFrame
    cup_pairs: pd.DataFrame
    flags: pd.DataFrame


def calibrated_cups(records: pd.DataFrame, columns: MastColumns, cup_calibrations=None):
    """``records`` with each certified cup's readings re-calibrated (module docstring), and the
    table of the calibrations applied (per cup column: ``slope``, ``offset``, ``logger_slope``,
    ``logger_offset``, ``uncertainty`` and ``source``; every cup, "logged" where no certificate
    was given, with :data:`CUP_CALIBRATION_GENERIC` as its uncertainty).

    ``cup_calibrations``: ``{cup column: {"slope": s, "offset": o, "logger_slope": s_L,
    "logger_offset": o_L[, "uncertainty": u]}}``: the logger's value v = s_L f + o_L (f the
    cup's rotation frequency or pulse rate) becomes s f + o = s (v - o_L) / s_L + o, its
    standard deviation times s / s_L; a reading of 0 or less (a stopped or dead cup) is left as
    it is. ``uncertainty``: the certificate's relative standard uncertainty of the slope
    (default :data:`CERTIFICATE_UNCERTAINTY`). ValueError naming a cup the records lack, or an
    entry missing or out of range."""
    cups = {c: (h, std) for h in columns.cup_heights for _, c, std in columns.cups[h]}
    given = {} if cup_calibrations is None else cup_calibrations
    if not isinstance(given, dict):
        raise ValueError(f"fit_site: cup_calibrations must be {{cup column: {{'slope': ..., "
                         f"'offset': ..., 'logger_slope': ..., 'logger_offset': ...}}}}; got "
                         f"{type(given).__name__}")
    lacking = [c for c in given if c not in cups]
    if lacking:
        raise ValueError(f"fit_site: cup_calibrations names cup {lacking[0]!r}, which the "
                         f"records lack (their cups: {sorted(cups)}); give the certificates of "
                         "the mast's own cups")
    rows = []
    out = records.copy() if given else records
    for column, (height, std) in cups.items():
        entry = given.get(column)
        if entry is None:
            rows.append({"cup": column, "height": height, "slope": np.nan, "offset": np.nan,
                         "logger_slope": np.nan, "logger_offset": np.nan,
                         "uncertainty": CUP_CALIBRATION_GENERIC, "source": "logged"})
            continue
        values = _certificate(column, entry)
        gain = values["slope"] / values["logger_slope"]
        reading = out[column].to_numpy(dtype=float)
        out[column] = np.where(reading > 0, (reading - values["logger_offset"]) * gain
                               + values["offset"], reading)
        if std is not None:
            out[std] = out[std].to_numpy(dtype=float) * gain
        rows.append({"cup": column, "height": height, **values, "source": "certificate"})
    table = pd.DataFrame(rows, columns=["cup", "height", *CERTIFICATE_KEYS, "uncertainty",
                                        "source"]).set_index("cup")
    return out, table


def _certificate(column, entry):
    """A certificate's entries checked (calibrated_cups)."""
    if not isinstance(entry, dict):
        raise ValueError(f"fit_site: cup_calibrations[{column!r}] must be a mapping with "
                         f"{list(CERTIFICATE_KEYS)} (and optionally 'uncertainty'); got {entry!r}")
    missing = [k for k in CERTIFICATE_KEYS if k not in entry]
    unknown = sorted(set(entry) - set(CERTIFICATE_KEYS) - {"uncertainty"})
    if missing or unknown:
        raise ValueError(f"fit_site: cup_calibrations[{column!r}] "
                         + (f"lacks {missing}" if missing else f"has unknown entries {unknown}")
                         + f": give {list(CERTIFICATE_KEYS)} (and optionally 'uncertainty')")
    values = {k: entry[k] for k in CERTIFICATE_KEYS}
    values["uncertainty"] = entry.get("uncertainty", CERTIFICATE_UNCERTAINTY)
    for key, value in values.items():
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer,
                                                             np.floating)) or not np.isfinite(value):
            raise ValueError(f"fit_site: cup_calibrations[{column!r}][{key!r}] must be a finite "
                             f"number; got {value!r}")
    for key in ("slope", "logger_slope"):
        if values[key] <= 0:
            raise ValueError(f"fit_site: cup_calibrations[{column!r}][{key!r}] must be > 0 "
                             f"(m/s per logger unit); got {values[key]!r}")
    if not 0 <= values["uncertainty"] < 0.1:
        raise ValueError(f"fit_site: cup_calibrations[{column!r}]['uncertainty'] must be a "
                         f"relative uncertainty in [0, 0.1); got {values['uncertainty']!r}")
    return {k: float(v) for k, v in values.items()}


def _numbers(records, columns):
    frame = records[list(columns)]
    bad = [c for c in frame.columns if not pd.api.types.is_numeric_dtype(frame[c])]
    if bad:
        raise ValueError(f"records: columns {bad} must be numbers (NaN: missing)")
    return frame.to_numpy(dtype=float)


class _Flags:
    def __init__(self):
        self.rows = []

    def add(self, rows, column, kind, reason):
        self.rows.extend({"row": int(r), "column": column, "kind": kind,
                          "reason": reason(int(r)) if callable(reason) else reason} for r in rows)

    def table(self):
        table = pd.DataFrame(self.rows, columns=["row", "column", "kind", "reason"])
        return table.sort_values("row", kind="stable").reset_index(drop=True)


def _remove_bad(values, columns, flags):
    bad = np.isinf(values)
    for j in np.flatnonzero(bad.any(axis=0)):
        flags.add(np.flatnonzero(bad[:, j]), columns[j], "infinite reading",
                  lambda r, v=values[:, j]: f"{v[r]} is no reading an instrument gives: removed")
    return np.where(bad, np.nan, values)


def read_instruments(records: pd.DataFrame, columns: MastColumns, *, booms=None,
                     direction_offsets="estimate",
                     shadow_half_width: float = SHADOW_HALF_WIDTH, labels=None) -> Instruments:
    """The records' speeds, turbulence and directions as the fit reads them (module
    docstring), the given vane offsets removed (``"estimate"`` or None: none yet);
    ``labels``: the records' names (time stamps) in the reasons (default: their rows)."""
    labels = [str(i) for i in range(len(records))] if labels is None else list(labels)
    booms = {} if booms is None else dict(booms)
    if (isinstance(shadow_half_width, (bool, np.bool_))
            or not isinstance(shadow_half_width, (int, float, np.integer, np.floating))
            or not 0 <= shadow_half_width < 90):
        raise ValueError(f"fit_site: shadow_half_width must be a number in [0, 90) deg; got "
                         f"{shadow_half_width!r}")
    check_speed_units(records, columns)
    flags = _Flags()
    vane_heights = columns.vane_heights
    directions = None
    if vane_heights.size:
        vane_columns = [columns.vanes[h] for h in vane_heights]
        directions = _remove_bad(_numbers(records, vane_columns), vane_columns, flags)
        directions = unstick(directions, vane_columns, flags, labels)
    offsets = offsets_given(direction_offsets, vane_heights)
    if directions is not None:
        directions = directions - offsets["offset_deg"].to_numpy()[None, :]  # given ones
    speeds, speed_std, pairs = _combine_cups(records, columns, directions, vane_heights, booms,
                                             shadow_half_width, flags)
    return Instruments(cup_heights=columns.cup_heights, speeds=speeds,
                       speed_std=speed_std if columns.has_std else None,
                       vane_heights=vane_heights, directions=directions, offsets=offsets,
                       cup_pairs=pairs, flags=flags.table())


def check_speed_units(records: pd.DataFrame, columns: MastColumns) -> None:
    """ValueError naming a speed column that reads in km/h, not m/s (:data:`KMH_RATIO`,
    :data:`MAX_MEDIAN_SPEED`): its speeds would fall with height, or be a storm all year."""
    heights = [h for h in columns.cup_heights for _ in columns.cups[h]]
    names = [c for h in columns.cup_heights for _, c, _ in columns.cups[h]]
    values = _numbers(records, names)
    values = np.where(np.isfinite(values) & (values > 0), values, np.nan)
    counts = np.sum(np.isfinite(values), axis=0)
    medians = np.array([np.median(v[np.isfinite(v)]) if n else np.nan
                        for v, n in zip(values.T, counts)])
    heights = np.asarray(heights)
    for k, name in enumerate(names):
        if not counts[k]:
            continue
        above = (heights > heights[k]) & np.isfinite(medians)
        below = (heights < heights[k]) & np.isfinite(medians)
        if above.any():
            ratio = medians[k] / np.median(medians[above])
        elif below.any() and counts[k] >= UNIT_MIN_RECORDS:
            ratio = medians[k] / np.median(medians[below])
        else:
            ratio = np.nan
        if KMH_RATIO[0] <= ratio <= KMH_RATIO[1] or (
                counts[k] >= UNIT_SITE_RECORDS and medians[k] > MAX_MEDIAN_SPEED):
            shown = (f"{ratio:.2f} times the cups {'above' if above.any() else 'below'} it"
                     if np.isfinite(ratio) else f"a median of {medians[k]:.1f}")
            raise ValueError(
                f"records: speed column {name!r} reads {shown} (median {medians[k]:.2f}): it is "
                "likely in km/h (3.6 times m/s); give the speeds in m/s (divide by 3.6)")


def read_cups_again(instruments: Instruments, records: pd.DataFrame, columns: MastColumns, *,
                    booms=None, shadow_half_width: float = SHADOW_HALF_WIDTH) -> Instruments:
    """``instruments`` with its cups read again with its vanes' directions as they are now
    (offsets removed): the mast wake's sector and its ratio against the direction are sharper
    (a vane 4 deg off moves the wake's centre 4 deg). The vanes' flags are kept, the cups'
    replaced."""
    booms = {} if booms is None else dict(booms)
    cup_flags = _Flags()
    speeds, speed_std, pairs = _combine_cups(records, columns, instruments.directions,
                                             instruments.vane_heights, booms, shadow_half_width,
                                             cup_flags)
    flags = instruments.flags
    flags = pd.concat([flags[flags["column"].isin(list(columns.vanes.values()))],
                       cup_flags.table()], ignore_index=True)
    return attrs.evolve(instruments, speeds=speeds, cup_pairs=pairs,
                        speed_std=speed_std if columns.has_std else None,
                        flags=flags.sort_values("row", kind="stable").reset_index(drop=True))


def fit_heights(instruments: Instruments, columns: MastColumns):
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


def fit_data(instruments: Instruments, rows):
    """``fit_profile``'s data of the records ``rows``: the cups' heights and speeds, and the
    vanes' directions with their own heights (``direction_heights``) where those differ."""
    cups, vanes = instruments.cup_heights, instruments.vane_heights
    data = {"heights": cups, "speeds": instruments.speeds[rows], "directions": None}
    if instruments.directions is not None:
        data["directions"] = instruments.directions[rows]
        if not (cups.size == vanes.size and np.allclose(cups, vanes)):
            data["direction_heights"] = vanes
    return data


def _combine_cups(records, columns, directions, vane_heights, booms, half_width, flags):
    """Per cup height the speed and standard deviation from its cups (module docstring), and
    the pairs' agreement."""
    n = len(records)
    heights = columns.cup_heights
    speeds = np.full((n, heights.size), np.nan)
    variance = np.full((n, heights.size), np.nan)
    pairs = []
    for i, height in enumerate(heights):
        group = columns.cups[height]
        names = [c for _, c, _ in group]
        values = _remove_bad(_numbers(records, names), names, flags)
        std_names = [s for _, _, s in group]
        stds = np.column_stack([
            _remove_bad(_numbers(records, [s]), [s], flags)[:, 0] if s else np.full(n, np.nan)
            for s in std_names])
        if len(group) == 1:
            speeds[:, i], variance[:, i] = values[:, 0], stds[:, 0] ** 2
            continue
        values, stds = _remove_dead(values, stds, names, height, flags)
        wind = direction_near(directions, vane_heights, height, n)
        orientation = np.array([booms[b] for b, _, _ in group])
        # Each cup's angle from its wake's centre: the wind from its boom's orientation + 180.
        offset = wrapped_angle(wind[:, None] - orientation[None, :] - 180.0)
        shadowed = np.abs(offset) < half_width
        finite = np.isfinite(values)
        # A cup in the wake is never used (with its partner missing, the height is missing);
        # where the wind is unknown (no vane reading), every cup.
        clear = np.where(np.isfinite(wind)[:, None], finite & ~shadowed, finite)
        used = np.where(clear, values, np.nan)
        mean = _row_mean(values, clear)
        # The pair test: clear cups within the cups' uncertainty; a cup in the wake as much
        # below the clear one as the wake's own ratio at that angle, measured from the records.
        allowance = PAIR_SIGMAS * np.sqrt(2.0) * CUP_UNCERTAINTY * mean + 0.2
        wake = np.where(finite & ~clear, values, np.nan)
        expected, spread, deficit = _wake_ratio(np.abs(offset), wake, mean, half_width)
        with np.errstate(invalid="ignore"):
            high = np.fmax.reduce(used, axis=1) - np.fmin.reduce(used, axis=1) > allowance
            # (the wake ratio's spread holds both cups' uncertainty already)
            low = np.any(np.abs(wake - expected * mean[:, None])
                         > PAIR_SIGMAS * spread * mean[:, None] + 0.2, axis=1)
        disagree = np.flatnonzero(high | low)
        for r in disagree:
            shown = ", ".join(f"{c} {values[r, k]:g}" for k, c in enumerate(names))
            waked = [names[k] for k in np.flatnonzero(np.isfinite(wake[r]))]
            flags.add([r], ", ".join(names), "cups disagree",
                      f"the cups at {height:g} m read {shown} m/s, beyond their uncertainty"
                      + (f" and the mast wake's ratio at that direction ({', '.join(waked)} in "
                         "it)" if waked else "") + " (a spike or a stalled cup): the height's "
                      "speed is removed")
        mean_var = _row_mean(stds**2, clear & np.isfinite(stds))
        mean[disagree] = np.nan
        mean_var[disagree] = np.nan
        speeds[:, i], variance[:, i] = mean, mean_var
        both = np.all(np.isfinite(values) & ~shadowed, axis=1)
        both[disagree] = False
        ratio = values[both, 1:] / values[both, :1]
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = ratio[np.all(np.isfinite(ratio), axis=1)]
        for k in range(1, len(group)):
            median, error = median_and_error(ratio[:, k - 1]) if len(ratio) else (np.nan, np.nan)
            pairs.append({"height": height, "cups": f"{names[k]} / {names[0]}",
                          "median_ratio": median, "uncertainty": error, "records": len(ratio),
                          "disagree": bool(abs(median - 1.0) > PAIR_TOLERANCE),
                          "wake_deficit": deficit})
    pairs = pd.DataFrame(pairs, columns=["height", "cups", "median_ratio", "uncertainty",
                                         "records", "disagree", "wake_deficit"])
    return speeds, np.sqrt(variance), pairs


def _remove_dead(values, stds, names, height, flags):
    """A cup reading :data:`DEAD_CUP_SPEED` or less (0, or stalled at its starting threshold)
    beside a partner reading :data:`DEAD_CUP_PARTNER` or more is dead, not a calm: its reading
    (and standard deviation) removed and named ("dead cup"), the partner used in its place
    (as where it is missing: out of the mast's wake)."""
    with np.errstate(invalid="ignore"):
        partner = np.fmax.reduce(np.where(np.isfinite(values), values, -np.inf), axis=1)
        dead = (values <= DEAD_CUP_SPEED) & (partner[:, None] >= DEAD_CUP_PARTNER)
    for k in np.flatnonzero(dead.any(axis=0)):
        flags.add(np.flatnonzero(dead[:, k]), names[k], "dead cup",
                  lambda r, k=k: f"the cup reads {values[r, k]:g} m/s beside "
                  f"{', '.join(f'{c} {values[r, j]:g}' for j, c in enumerate(names) if j != k)}"
                  f" m/s at {height:g} m (a dead or stalled cup, not a calm): the partner is used")
    return np.where(dead, np.nan, values), np.where(dead, np.nan, stds)


def _wake_ratio(angle, wake, clear_mean, half_width):
    """The mast wake as the records show it (IEC 61400-12-1 Annex G: the ratio of the two cups
    against the direction): per record and cup, the median ratio of a cup in the wake to the
    clear cups' mean at its angle from the wake's centre (bins of :data:`WAKE_BIN` deg, both
    sides and all cups together) and its robust spread; where a bin holds fewer than
    :data:`WAKE_MIN_RECORDS`, (1 - MAX_SHADOW_DEFICIT / 2) +- MAX_SHADOW_DEFICIT / 2 spans every
    deficit up to MAX_SHADOW_DEFICIT. Also the largest median deficit (NaN: none measured)."""
    edges = np.arange(0.0, half_width + WAKE_BIN, WAKE_BIN)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = wake / clear_mean[:, None]
    where = np.clip(np.searchsorted(edges, angle, side="right") - 1, 0, edges.size - 1)
    expected = np.full(ratio.shape, 1.0 - 0.5 * MAX_SHADOW_DEFICIT)
    spread = np.full(ratio.shape, 0.5 * MAX_SHADOW_DEFICIT / PAIR_SIGMAS)
    deficit = np.nan
    measured = np.isfinite(ratio)
    for b in range(edges.size - 1):
        in_bin = measured & (where == b)
        if np.count_nonzero(in_bin) < WAKE_MIN_RECORDS:
            continue
        median = float(np.median(ratio[in_bin]))
        sigma = max(1.4826 * float(np.median(np.abs(ratio[in_bin] - median))),
                    np.sqrt(2.0) * CUP_UNCERTAINTY)
        expected[where == b], spread[where == b] = median, sigma
        deficit = np.nanmax([deficit, 1.0 - median])
    return expected, spread, deficit


def _row_mean(values, use):
    """Per row the mean of ``values`` where ``use`` (NaN where none)."""
    count = np.sum(use, axis=1)
    total = np.sum(np.where(use, values, 0.0), axis=1)
    return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def measured_turbulence(instruments: Instruments, reference_height: float):
    """The fit's ``turbulence_intensity=(height, values)``: sigma_u / U of the cups at the cup
    height nearest the reference height (NaN where a record has none)."""
    k = reference_index(instruments.cup_heights, reference_height)
    with np.errstate(invalid="ignore", divide="ignore"):
        intensity = instruments.speed_std[:, k] / instruments.speeds[:, k]
    intensity = np.where(np.isfinite(intensity) & (intensity > 0), intensity, np.nan)
    return float(instruments.cup_heights[k]), intensity
