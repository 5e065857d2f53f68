"""A met mast's vanes (docs/measurements.md#a-real-mast), for stages 2 and 3 of the site fit
(readings.py, offsets.py): stuck vanes (icing) removed and named, and the vane offsets, what a
vane reads minus the true direction relative to the vane nearest the reference height, given or
estimated from the strong-wind records (near-neutral) as the median turning from the reference
vane minus the model's own neutral turning (docs/measurements.md#vane-offsets), with the
median's standard error and, beside it, the reference turning's systematic uncertainty: the
model's neutral turning between the vanes against the surface layer's (none, by Monin-Obukhov
similarity)."""

from __future__ import annotations

import attrs
import numpy as np
import pandas as pd

#: A vane repeating its reading (within its 0.1 deg resolution) this many records in a row
#: while another vane turns by more than :data:`STUCK_TURN` is stuck.
STUCK_RECORDS = 4
STUCK_TURN = 2.0
#: Records from which vane offsets are estimated: the speed at the reference height from this
#: [m/s] (near-neutral: mechanical mixing), at least :data:`OFFSET_MIN_RECORDS` of them.
OFFSET_MIN_SPEED = 12.0
OFFSET_MIN_RECORDS = 20


def wrapped_angle(a):
    """Angle wrapped to [-180, 180) deg."""
    return (np.asarray(a, float) + 180.0) % 360.0 - 180.0


def reference_index(heights, reference_height):
    """Index of the height nearest the reference height (the higher one on a tie)."""
    heights = np.asarray(heights, float)
    distance = np.abs(heights - reference_height)
    return int(np.flatnonzero(distance == distance.min())[-1])


def direction_near(directions, vane_heights, height, n):
    """Per record the direction of the vane nearest ``height`` that reads (NaN: none)."""
    if directions is None:
        return np.full(n, np.nan)
    order = np.argsort(np.abs(vane_heights - height), kind="stable")
    wind = np.full(directions.shape[0], np.nan)
    for k in order[::-1]:
        wind = np.where(np.isfinite(directions[:, k]), directions[:, k], wind)
    return wind


def median_and_error(values):
    """The median and its standard error (1.2533 sigma / sqrt(n), sigma from the MAD)."""
    values = np.asarray(values, float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return np.nan, np.nan
    median = float(np.median(values))
    sigma = 1.4826 * float(np.median(np.abs(values - median)))
    return median, 1.2533 * sigma / np.sqrt(values.size)


def unstick(directions, vane_columns, flags, labels):
    """Readings of vanes that repeat for STUCK_RECORDS records or more while another vane turns
    by more than STUCK_TURN (icing): removed and named."""
    n, m = directions.shape
    if n < STUCK_RECORDS:
        return directions
    same = np.zeros((n, m), bool)
    same[1:] = np.abs(wrapped_angle(directions[1:] - directions[:-1])) < 0.05
    out = directions.copy()
    for j in range(m):
        # Runs of equal readings: starts where a reading differs from the one before.
        start = np.flatnonzero(~same[:, j])
        stop = np.append(start[1:], n)
        for a, b in zip(start[(stop - start) >= STUCK_RECORDS], stop[(stop - start) >= STUCK_RECORDS]):
            others = [k for k in range(m) if k != j]
            turns = [np.nanmax(np.abs(wrapped_angle(directions[a:b, k] - directions[a, k])), initial=0.0)
                     for k in others if np.isfinite(directions[a, k])]
            if others and not (turns and max(turns) > STUCK_TURN):
                continue
            if not np.isfinite(directions[a, j]):
                continue
            rows = np.arange(a, b)
            out[rows, j] = np.nan
            flags.add(rows, vane_columns[j], "stuck vane",
                      f"the vane reads {directions[a, j]:g} deg in {b - a} records in a row "
                      f"({labels[a]} to {labels[b - 1]}) while the other vanes turn (icing): removed")
    return out


def strong_wind_rows(instruments, reference_height: float) -> np.ndarray:
    """The records whose speed at the cup height nearest the reference height is at least
    :data:`OFFSET_MIN_SPEED` (the vane offsets' records, near-neutral by their wind)."""
    speed = instruments.speeds[:, reference_index(instruments.cup_heights, reference_height)]
    return np.flatnonzero(np.isfinite(speed) & (speed >= OFFSET_MIN_SPEED))


def with_offsets_from(instruments, rows, reference_height: float,
                      neutral_turning):
    """``instruments`` with its vanes' offsets estimated from the records ``rows`` (module
    docstring) in place of those it has."""
    applied = instruments.offsets["offset_deg"].to_numpy()
    readings = instruments.directions + applied[None, :]
    offsets = estimate_offsets(readings, instruments.vane_heights, instruments.speeds,
                                instruments.cup_heights, reference_height, neutral_turning,
                                np.asarray(rows, dtype=int))
    return attrs.evolve(instruments, offsets=offsets,
                        directions=readings - offsets["offset_deg"].to_numpy()[None, :])


def offsets_given(direction_offsets, vane_heights):
    table = pd.DataFrame({"offset_deg": 0.0, "uncertainty_deg": np.nan, "systematic_deg": np.nan,
                          "records": 0, "source": "reference"},
                         index=pd.Index(vane_heights, name="height"))
    if direction_offsets is None or isinstance(direction_offsets, str):
        if isinstance(direction_offsets, str) and direction_offsets != "estimate":
            raise ValueError(f"fit_site: direction_offsets must be 'estimate', None or "
                             f"{{vane height: offset deg}}; got {direction_offsets!r}")
        return table
    if not isinstance(direction_offsets, dict):
        raise ValueError(f"fit_site: direction_offsets must be 'estimate', None or "
                         f"{{vane height: offset deg}}; got {direction_offsets!r}")
    for height, offset in direction_offsets.items():
        match = np.flatnonzero(np.isclose(vane_heights, float(height)))
        if match.size != 1:
            raise ValueError(f"fit_site: direction_offsets names a vane at {height!r} m; the "
                             f"records' vanes are at {vane_heights.tolist()} m")
        if isinstance(offset, bool) or not np.isscalar(offset) or not np.isfinite(offset):
            raise ValueError(f"fit_site: direction_offsets[{height!r}] must be a number of "
                             f"degrees; got {offset!r}")
        table.iloc[match[0], :] = [float(offset), np.nan, np.nan, 0, "given"]
    return table


def estimate_offsets(directions, vane_heights, speeds, cup_heights, reference_height,
                      neutral_turning, rows):
    """Vane offsets relative to the vane nearest the reference height from the records
    ``rows`` (module docstring)."""
    ref = reference_index(vane_heights, reference_height)
    cup = reference_index(cup_heights, reference_height)
    table = pd.DataFrame({"offset_deg": 0.0, "uncertainty_deg": np.nan, "systematic_deg": np.nan,
                          "records": 0, "source": "reference"},
                         index=pd.Index(vane_heights, name="height"))
    strong = np.zeros(directions.shape[0], dtype=bool)
    strong[rows] = True
    strong &= np.isfinite(speeds[:, cup]) & np.isfinite(directions[:, ref])
    for k, height in enumerate(vane_heights):
        if k == ref:
            continue
        rows = np.flatnonzero(strong & np.isfinite(directions[:, k]))
        if rows.size < OFFSET_MIN_RECORDS:
            table.loc[height, ["records", "source"]] = [rows.size, "not estimated"]
            continue
        forms = neutral_turning(speeds[rows, cup], cup_heights[cup],
                                np.array([height, vane_heights[ref]]))
        between = {name: form[:, 0] - form[:, 1] for name, form in forms.items()}
        reference = next(iter(between.values()))  # (the first form is the reference)
        turning = wrapped_angle(directions[rows, k] - directions[rows, ref])
        median, error = median_and_error(wrapped_angle(turning - reference))
        # The reference turning's own uncertainty: how far the other published forms turn
        # between the vanes from it; systematic, not statistical.
        systematic = max(abs(float(np.median(form - reference))) for form in between.values())
        table.loc[height, :] = [median, error, systematic, rows.size, "estimated"]
    return table
