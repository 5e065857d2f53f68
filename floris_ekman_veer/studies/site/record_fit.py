"""Stage 4 of the site fit (pipeline.py): the per-record fit. The records no fit should see
(repeated time stamps, infinite or zero readings, too few data) named with a reason
(docs/measurements.md#a-year-of-records), every other record fitted (``EkmanABL.fit_profile``,
one vectorised call) on stage 2-3's readings, those the model cannot follow or whose state the
atmosphere block cannot give back named too. One record never aborts the others' fits."""

from __future__ import annotations

import attrs
import numpy as np
import pandas as pd

from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.atmosphere.fit.fit_inputs import FIT_OPTIONS
from floris_ekman_veer.studies.site.baseline import NeutralBaseline
from floris_ekman_veer.studies.site.columns import MastColumns
from floris_ekman_veer.studies.site.readings import (Instruments, fit_data, fit_heights,
                                                     measured_turbulence)
from floris_ekman_veer.studies.site.stability import (stability_options, stability_options_of,
                                                      turbulence_departure)

#: Why a record can be left out, in the order ``SiteAtmosphere.summary`` lists them.
EXCLUSION_KINDS = ("repeated record", "repeated time stamp", "infinite reading",
                   "zero reading", "missing data",
                   "calm", "falling speeds", "convective", "backing", "no top", "misfit",
                   "physical bound", "too few data", "two states")


@attrs.frozen(eq=False)
class RecordFit:
    """What the per-record fit made of the records (:func:`fit_records`).

    Attributes:
        abl: the fitted EkmanABL of the records kept, shape (n_kept,); ``abl.profile_fit``.
        rows: per record kept its row in the records.
        excluded: {row: (kind, reason)} of the records left out (kinds :data:`EXCLUSION_KINDS`).
    """

    abl: EkmanABL
    rows: np.ndarray
    excluded: dict
    #: the cups' measured turbulence intensity (height, one value per record), or None: the
    #: wake's ambient turbulence (docs/measurements.md#reading-stability)
    measured_turbulence: tuple | None = None


def fit_records(instruments: Instruments, columns: MastColumns, labels: list,
                reference_height: float, fit_options_and_inputs: dict, *,
                stability_input: str = "stability_parameter",
                on_misfit: str = "raise", records: pd.DataFrame | None = None,
                site_type: str | None = None, longitude: float | None = None,
                time_zone: str | None = None,
                baseline: NeutralBaseline | None = None) -> RecordFit:
    """Every record's fit (module docstring). ``on_misfit="raise"``: ValueError naming the
    first record that cannot be fitted and why; ``"drop"``: such records are left out and
    named in ``excluded``. The cups' measured turbulence intensity (nearest the reference
    height) enters the fit as its departure from the site's neutral turbulence in its sector
    (the ``baseline``'s terrain excess, stage 3) unless a ``turbulence_intensity`` is given;
    the fit takes the weak prior on 1/L, an onshore site's sun bound, and the temperatures'
    and a sonic's stability where ``records`` hold them (stability.py,
    docs/measurements.md#reading-stability)."""
    heights, speeds, directions, speed_columns = fit_heights(instruments, columns)
    excluded = screen_records(speed_columns, labels, heights, speeds, directions,
                              3 if fit_options_and_inputs.get("fit_roughness") else 2)
    if on_misfit == "raise" and excluded:
        row, (kind, text) = next(iter(sorted(excluded.items())))
        raise ValueError(f"fit_site: record {labels[row]} cannot be fitted: {text}"
                         + more_excluded_text(excluded, labels, row) + ". Give on_misfit='drop' "
                         "to leave out such records (SiteAtmosphere.summary() tells what was left "
                         "out and why)")
    fit_inputs = dict(fit_options_and_inputs)
    # (a measured turbulence intensity is a pair (height, value), each one number or a column)
    turbulence = fit_inputs.pop("turbulence_intensity", None)
    measured = None
    if turbulence is None and instruments.speed_std is not None and baseline is not None:
        # the measured TI: the wake's input, and to the fit only its departure from the site's
        # neutral TI in its sector (docs/measurements.md#reading-stability)
        measured = measured_turbulence(instruments, reference_height)
        turbulence, noise = turbulence_departure(measured, baseline)
        fit_inputs.setdefault("turbulence_noise", noise)
    fit_inputs.update(stability_options(fit_inputs, labels, instruments, records, site_type,
                                        longitude, time_zone))
    # (fixed inputs may be one per record; the fit's options, a noise pair say, are not)
    per_record = {k: v for k, v in fit_inputs.items() if k not in FIT_OPTIONS and np.ndim(v) == 1}
    n = instruments.speeds.shape[0]
    candidates = np.setdiff1d(np.arange(n), np.fromiter(excluded, int, len(excluded)))
    if candidates.size == 0:
        raise ValueError(f"fit_site: no record can be fitted ({reasons_text(excluded)})")
    inputs = {**fit_inputs, **{k: np.asarray(v)[candidates] for k, v in per_record.items()}}
    if turbulence is not None:
        inputs["turbulence_intensity"] = tuple(
            np.asarray(v, float)[candidates] if np.ndim(v) == 1 else v for v in turbulence)
    inputs.update(stability_options_of(inputs, candidates, n))
    abl = EkmanABL.fit_profile(
        **fit_data(instruments, candidates),
        on_misfit="raise" if on_misfit == "raise" else "flag",
        labels=[labels[i] for i in candidates], **inputs,
    )
    fit = abl.profile_fit
    for k in np.flatnonzero(~np.asarray(fit.fits)):
        excluded[int(candidates[k])] = fit.reason(k)
    kept = np.flatnonzero(fit.fits)
    if kept.size:
        abl = fit.subset(kept) if kept.size < candidates.size else abl
        fit = abl.profile_fit
        same, _ = fit.given_back(fit.atmosphere(stability_input), reference_height)
        if on_misfit == "raise" and not np.all(same):
            # raises, naming the records
            fit.atmosphere(stability_input, reference_height=reference_height)
        for k in np.flatnonzero(~same):
            excluded[int(candidates[kept[k]])] = (
                "two states", f"its fitted state has a second one, deeper, with the same speed at "
                f"{reference_height:g} m, which the atmosphere block gives and which does not fit "
                f"the data (give the stability as another stability_input)")
        if not np.all(same):
            kept = kept[same]
            abl = fit.subset(np.flatnonzero(same))
    if kept.size == 0:
        raise ValueError(f"fit_site: no record fits an atmosphere of the model "
                         f"({reasons_text(excluded)})")
    return RecordFit(abl=abl, rows=candidates[kept], excluded=excluded,
                     measured_turbulence=measured)


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

