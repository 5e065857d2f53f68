"""A site's measured wind profiles as a FLORIS run: fitted atmosphere per record, a FLORIS
``TimeSeries``, annual energy and yaw optimisation (docs/measurements.md#from-the-fit-to-floris).

Records are a pandas DataFrame, one row per record (a 10-minute mean, say), with columns
``speed_<height>m`` [m/s] and ``direction_<height>m`` [deg, meteorological] (e.g. ``speed_90m``,
``direction_90m``; NaN for a missing value) and optionally a ``time`` column naming the records.
:func:`fit_site` fits every record (``EkmanABL.fit_profile``, one vectorised call) and gives, per
record, FLORIS's inputs at the reference height: the wind speed and direction of the fitted
profile there, the turbulence intensity I_u of the fitted ABL (Eq. Iu_model), and the atmosphere
block with one entry per record. Driven by those wind speeds, the block gives back the fitted
ABLs (checked when it is made).
"""

from __future__ import annotations

import re

import attrs
import numpy as np
import pandas as pd
from floris.wind_data import TimeSeries

from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.studies.energy import record_energy
from floris_ekman_veer.plugin.inflow import set_atmosphere

#: Column names of the measured speeds and directions: the height in metres is in the name.
SPEED_COLUMN = re.compile(r"^speed_(\d+(?:\.\d+)?)m$")
DIRECTION_COLUMN = re.compile(r"^direction_(\d+(?:\.\d+)?)m$")
#: Fractions of the rotor radius at which :func:`atmosphere_from_shear_and_veer` samples the
#: power law: bottom tip, half way, hub, half way, top tip.
ROTOR_SAMPLES = (-1.0, -0.5, 0.0, 0.5, 1.0)
#: What :func:`fit_site` does with records that fit no atmosphere of the model.
MISFIT_POLICIES = ("raise", "drop")


def mast_profiles(records: pd.DataFrame):
    """(heights [m], speeds (n_records, n_heights), directions or None) from the
    ``speed_<h>m`` and ``direction_<h>m`` columns of ``records`` (heights sorted)."""
    if not isinstance(records, pd.DataFrame):
        raise ValueError(f"records must be a pandas DataFrame; got {type(records).__name__}")
    speeds = {float(m[1]): c for c in records.columns if (m := SPEED_COLUMN.match(str(c)))}
    directions = {float(m[1]): c for c in records.columns
                  if (m := DIRECTION_COLUMN.match(str(c)))}
    if len(speeds) < 2:
        raise ValueError(
            "records need speed columns at two heights or more, named speed_<height>m (e.g. "
            f"speed_90m); got columns {list(records.columns)}"
        )
    if directions and set(directions) != set(speeds):
        raise ValueError(
            f"records: direction columns at heights {sorted(directions)} m do not match the "
            f"speed columns at {sorted(speeds)} m (give both at every height; NaN: missing)"
        )
    heights = np.array(sorted(speeds))

    def table(columns):
        frame = records[[columns[h] for h in heights]]
        bad = [c for c in frame.columns if not pd.api.types.is_numeric_dtype(frame[c])]
        if bad:
            raise ValueError(f"records: columns {bad} must be numbers (NaN: missing)")
        return frame.to_numpy(dtype=float)

    return heights, table(speeds), table(directions) if directions else None


@attrs.frozen(eq=False)
class SiteAtmosphere:
    """The fitted atmosphere of a site's records (see :func:`fit_site`).

    Attributes:
        labels: the record names (the ``time`` column, else the DataFrame index).
        abl: the fitted EkmanABL, shape (n_records,); ``abl.profile_fit`` the fit.
        reference_height: FLORIS's ``reference_wind_height`` [m].
        wind_speeds, wind_directions, turbulence_intensities: per record, FLORIS's inputs at
            the reference height (the fitted profile's speed and meteorological direction, the
            fitted ABL's I_u).
        atmosphere: the ``ekman_veer.atmosphere`` block, one entry per record.
        dropped: labels of the records left out (``on_misfit="drop"``).
        excluded: the records left out, one row each (index: the row in ``records``): ``time``,
            ``kind`` (one of :data:`EXCLUSION_KINDS`) and ``reason``, a sentence.
    """

    labels: list
    abl: EkmanABL
    reference_height: float
    wind_speeds: np.ndarray
    wind_directions: np.ndarray
    turbulence_intensities: np.ndarray
    atmosphere: dict
    dropped: list
    excluded: pd.DataFrame = attrs.field(
        factory=lambda: pd.DataFrame({"time": [], "kind": [], "reason": []}))

    def summary(self) -> pd.DataFrame:
        """What was left out and why: per kind of record (:data:`EXCLUSION_KINDS`), the number
        of records, the first and last time stamps, and one reason as written; and the number
        fitted (kind ``fitted``)."""
        rows = []
        for kind in EXCLUSION_KINDS:
            some = self.excluded[self.excluded["kind"] == kind]
            if len(some):
                rows.append({"kind": kind, "records": len(some), "first": some["time"].iloc[0],
                             "last": some["time"].iloc[-1], "example": some["reason"].iloc[0]})
        rows.append({"kind": "fitted", "records": len(self.labels), "first": self.labels[0],
                     "last": self.labels[-1], "example": ""})
        return pd.DataFrame(rows).set_index("kind")

    @property
    def profile_fit(self):
        return self.abl.profile_fit

    def time_series(self) -> TimeSeries:
        """The records as a FLORIS TimeSeries (equal frequencies)."""
        return TimeSeries(wind_directions=self.wind_directions, wind_speeds=self.wind_speeds,
                          turbulence_intensities=self.turbulence_intensities)

    def apply(self, fmodel) -> None:
        """Set ``fmodel``'s conditions to the records and its atmosphere to the per-record block
        (one vectorised FLORIS run for all records; ``optimize_yaw`` takes it as it is).
        ``fmodel``'s reference wind height must be the fit's."""
        height = float(fmodel.core.flow_field.reference_wind_height)
        if abs(height - self.reference_height) > 1e-9 * max(1.0, self.reference_height):
            raise ValueError(
                f"fmodel's flow_field.reference_wind_height is {height} m but the site "
                f"atmosphere was made for {self.reference_height} m (fit_site(..., "
                "reference_height=...))"
            )
        set_atmosphere(fmodel, self.atmosphere, wind_directions=self.wind_directions,
                       wind_speeds=self.wind_speeds,
                       turbulence_intensities=self.turbulence_intensities)

    def stability(self) -> tuple[dict, list]:
        """(stability classes, record classes) for :func:`~floris_ekman_veer.annual_energy`:
        one class per distinct fitted atmosphere (named by its first record's label), each
        record of its own class."""
        n = len(self.labels)
        names = [k for k, v in self.atmosphere.items() if isinstance(v, list)]
        rows = np.array([[self.atmosphere[k][i] for k in names] for i in range(n)]).reshape(n, -1)
        _, first, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
        inverse = inverse.reshape(-1)
        classes, records = {}, []
        for i in range(n):
            j = int(first[inverse[i]])
            name = str(self.labels[j])
            if name not in classes:
                classes[name] = {"atmosphere": {
                    k: (v[j] if isinstance(v, list) else v) for k, v in self.atmosphere.items()
                }}
            records.append(name)
        return classes, records

    def annual_energy(self, fmodel, optimizer_class=None, **options):
        """:func:`~floris_ekman_veer.annual_energy` of ``fmodel`` for these records, each record
        with its fitted atmosphere (``options``: annual_energy's and the optimiser's;
        ``client=`` a ``dask.distributed.Client`` runs the chunks on its cluster, bitwise the
        serial numbers, docs/coupling.md#annual-energy).

        The classes are those of :meth:`stability`; the records run as chunks of one vectorised
        FLORIS model each, with the per-record atmosphere block (as :meth:`apply`), never a
        model per class."""
        return record_energy(fmodel, self.time_series(), self.atmosphere,
                             [str(label) for label in self.labels], optimizer_class, **options)


def fit_site(records: pd.DataFrame, reference_height: float, *,
             stability_input: str = "stability_parameter", on_misfit: str = "raise",
             time_column: str = "time", **fit_options_and_inputs) -> SiteAtmosphere:
    """Fit every record of a site (module docstring) and give FLORIS's inputs per record.

    Records a mast logs that no atmosphere of the model describes (docs/measurements.md#a-year-of-records)
    are named by their time stamp and a reason: a zero (or negative) speed reading, too few
    data, calm, a direction backing with height (a front), speeds falling with height, less
    shear than a neutral layer (convective, with the default stable fit; ``stability="either"``
    fits convective layers), a profile the model cannot follow (misfit), a repeated time
    stamp, or a fitted state the atmosphere block cannot give back. One record never aborts the others' fits.

    Args:
        records: DataFrame with ``speed_<h>m``, ``direction_<h>m`` and optionally ``time``.
        reference_height: FLORIS's ``reference_wind_height`` [m] (the hub height, usually).
        stability_input: the stability input of the atmosphere block (``stability_parameter``,
            ``obukhov_length`` or ``cooling_rate``; the block is checked to give back the fit).
        on_misfit: ``"raise"`` (ValueError naming the first such record, its time stamp and
            why) or ``"drop"`` (leave such records out: ``dropped`` lists them,
            ``excluded`` gives each one's reason and ``summary()`` the counts).
        time_column: the column naming the records in messages and classes.
        **fit_options_and_inputs: ``EkmanABL.fit_profile``'s options and fixed inputs
            (``latitude``, ``roughness_length``, ``speed_noise``...).
    """
    if on_misfit not in MISFIT_POLICIES:
        raise ValueError(f"fit_site: on_misfit must be one of {list(MISFIT_POLICIES)}; got "
                         f"{on_misfit!r}")
    if "on_misfit" in fit_options_and_inputs or "labels" in fit_options_and_inputs:
        raise ValueError("fit_site sets fit_profile's on_misfit and labels itself (from its "
                         "own on_misfit and the time column)")
    if (isinstance(reference_height, bool) or not np.isscalar(reference_height)
            or not np.isfinite(reference_height) or reference_height <= 0):
        raise ValueError(f"fit_site: reference_height must be a number > 0 m; got "
                         f"{reference_height!r}")
    heights, speeds, directions = mast_profiles(records)
    labels = (records[time_column].astype(str).tolist() if time_column in records.columns
              else [str(i) for i in records.index])
    if len(records) == 0:
        raise ValueError("fit_site: records is empty")
    z0 = np.max(np.asarray(fit_options_and_inputs.get("roughness_length", 0.0), float))
    if not reference_height > 10.0 * z0:
        raise ValueError(f"fit_site: reference_height must be > 10 roughness lengths "
                         f"(roughness_length {z0:g} m: above the roughness sublayer, where the "
                         f"fitted profile is a wind a turbine meets); got {reference_height!r} m")
    excluded = _screen(records, labels, heights, speeds, directions,
                       3 if fit_options_and_inputs.get("fit_roughness") else 2)
    if on_misfit == "raise" and excluded:
        row, (kind, text) = next(iter(sorted(excluded.items())))
        raise ValueError(f"fit_site: record {labels[row]} cannot be fitted: {text}"
                         + _more(excluded, labels, row) + ". Give on_misfit='drop' to leave out "
                         "such records (SiteAtmosphere.summary() tells what was left out and why)")
    fit_inputs = dict(fit_options_and_inputs)
    # (a measured turbulence intensity is a pair (height, value), each one number or a column)
    turbulence = fit_inputs.pop("turbulence_intensity", None)
    per_record = {k: v for k, v in fit_inputs.items() if np.ndim(v) == 1}
    candidates = np.setdiff1d(np.arange(len(records)), np.fromiter(excluded, int, len(excluded)))
    if candidates.size == 0:
        raise ValueError(f"fit_site: no record can be fitted ({_reasons_text(excluded)})")
    inputs = {**fit_inputs, **{k: np.asarray(v)[candidates] for k, v in per_record.items()}}
    if turbulence is not None:
        inputs["turbulence_intensity"] = tuple(
            np.asarray(v, float)[candidates] if np.ndim(v) == 1 else v for v in turbulence)
    abl = EkmanABL.fit_profile(
        heights, speeds[candidates], None if directions is None else directions[candidates],
        on_misfit="raise" if on_misfit == "raise" else "flag",
        labels=[labels[i] for i in candidates], **inputs,
    )
    fit = abl.profile_fit
    for k in np.flatnonzero(~np.asarray(fit.fits)):
        excluded[int(candidates[k])] = fit.reason(k)
    kept = np.flatnonzero(fit.fits)
    z_ref = float(reference_height)
    if kept.size:
        abl = fit.subset(kept) if kept.size < candidates.size else abl
        fit = abl.profile_fit
        same, _ = fit.given_back(fit.atmosphere(stability_input), z_ref)
        if on_misfit == "raise" and not np.all(same):
            fit.atmosphere(stability_input, reference_height=z_ref)  # raises, naming the records
        for k in np.flatnonzero(~same):
            excluded[int(candidates[kept[k]])] = (
                "two states", f"its fitted state has a second one, deeper, with the same speed at "
                f"{z_ref:g} m, which the atmosphere block gives and which does not fit the data "
                f"(give the stability as another stability_input)")
        if not np.all(same):
            kept = kept[same]
            abl = fit.subset(np.flatnonzero(same))
            fit = abl.profile_fit
    if kept.size == 0:
        raise ValueError(f"fit_site: no record fits an atmosphere of the model "
                         f"({_reasons_text(excluded)})")
    rows = sorted(excluded)
    table = pd.DataFrame({"time": [labels[i] for i in rows],
                          "kind": [excluded[i][0] for i in rows],
                          "reason": [excluded[i][1] for i in rows]},
                         index=pd.Index(rows, name="row"))
    return SiteAtmosphere(
        labels=list(fit.labels),
        abl=abl,
        reference_height=z_ref,
        wind_speeds=fit.speed(np.array([z_ref]))[:, 0],
        wind_directions=fit.direction(np.array([z_ref]))[:, 0],
        turbulence_intensities=np.asarray(abl.turbulence_intensity(z_ref), float).reshape(-1),
        atmosphere=fit.atmosphere(stability_input),
        dropped=list(table["time"]),
        excluded=table,
    )


#: Why a record can be left out, in the order ``SiteAtmosphere.summary`` lists them.
EXCLUSION_KINDS = ("repeated record", "repeated time stamp", "infinite reading",
                   "zero reading", "missing data",
                   "calm", "falling speeds", "convective", "backing", "no top", "misfit",
                   "physical bound", "two states")


def _screen(records, labels, heights, speeds, directions, unknowns):
    """{row: (kind, text)} of the records no fit should see: repeated time stamps, zero or
    negative speed readings, too few data."""
    excluded = {}
    by_height = {float(m[1]): str(c) for c in records.columns if (m := SPEED_COLUMN.match(str(c)))}
    speed_columns = [by_height[h] for h in heights]
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


def _more(excluded, labels, first):
    others = [k for k in sorted(excluded) if k != first]
    if not others:
        return ""
    shown = ", ".join(labels[k] for k in others[:5])
    return (f"; {len(others)} more record(s) cannot be fitted either ({_reasons_text(excluded)}"
            f": {shown}{', ...' if len(others) > 5 else ''})")


def _reasons_text(excluded):
    counts = pd.Series([kind for kind, _ in excluded.values()]).value_counts()
    return ", ".join(f"{n} {kind}" for kind, n in counts.items())


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
    from floris_ekman_veer._validation import real_array, require_at

    if shear_exponent is None and veer is None:
        raise ValueError("atmosphere_from_shear_and_veer needs shear_exponent, veer or both")
    for name, value, ok, valid in (
            ("hub_speed", hub_speed, lambda v: v > 0, "> 0 m/s"),
            ("hub_height", hub_height, lambda v: v > 0, "> 0 m"),
            ("rotor_diameter", rotor_diameter, lambda v: v > 0, "> 0 m"),
            ("shear_exponent", shear_exponent, lambda v: np.isfinite(v), "finite"),
            ("veer", veer, lambda v: np.isfinite(v), "finite [deg]")):
        if value is None:
            continue
        array = real_array(f"atmosphere_from_shear_and_veer: {name}", value, valid)
        require_at(np.isfinite(array) & ok(array), f"atmosphere_from_shear_and_veer: {name}",
                   valid, array)
    single = all(np.ndim(v) == 0 for v in (hub_speed, hub_height, rotor_diameter,
                                           shear_exponent, veer))
    hub_speed, hub_height, rotor_diameter = (
        np.atleast_1d(np.asarray(v, dtype=float)) for v in (hub_speed, hub_height, rotor_diameter)
    )
    n = np.broadcast_shapes(hub_speed.shape, hub_height.shape, rotor_diameter.shape,
                            *(np.shape(v) for v in (shear_exponent, veer) if v is not None))
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
