"""A site's measured wind profiles as a FLORIS run: fitted atmosphere per record, a FLORIS
``TimeSeries``, annual energy and yaw optimisation (docs/measurements.md#from-the-fit-to-floris).

Records are a pandas DataFrame, one row per record (a 10-minute mean, say), with columns
``speed_<height>m`` [m/s] and ``direction_<height>m`` [deg, meteorological] (e.g. ``speed_90m``,
``direction_90m``; NaN for a missing value), or a real mast's cups on booms, their standard
deviations and vanes at their own heights (studies/mast.py, docs/measurements.md#a-real-mast),
and optionally a ``time`` column naming the records.
:func:`fit_site` fits every record (``EkmanABL.fit_profile``, one vectorised call) and gives, per
record, FLORIS's inputs at the reference height: the wind speed and direction of the fitted
profile there, the turbulence intensity I_u of the fitted ABL (Eq. Iu_model), and the atmosphere
block with one entry per record. Driven by those wind speeds, the block gives back the fitted
ABLs (checked when it is made). ``SiteAtmosphere.summary()`` reports the site.
"""

from __future__ import annotations

import attrs
import numpy as np
import pandas as pd
from floris.wind_data import TimeSeries

from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.atmosphere.fit.fit_inputs import FIT_OPTIONS
from floris_ekman_veer.studies.mast import (SHADOW_HALF_WIDTH, mast_columns, measured_turbulence,
                                            read_instruments)
from floris_ekman_veer.studies.site_records import (
    EXCLUSION_KINDS,
    fit_data,
    fit_heights,
    more_excluded_text,
    neutral_turning,
    offsets_from_neutral_fits,
    reasons_text,
    screen_records,
)
from floris_ekman_veer.studies.energy.energy import energy_by_period, record_energy
from floris_ekman_veer.plugin.inflow.inflow import set_atmosphere

#: What :func:`fit_site` does with records that fit no atmosphere of the model.
MISFIT_POLICIES = ("raise", "drop")
#: The reference height may lie at most this many times above the highest measurement: the
#: fitted profile is not extrapolated further than the mast's own height again.
MAX_EXTRAPOLATION = 2.0


#: The fitted records' classes, by their Obukhov length (ProfileFit.stability_class).
STABILITY_CLASSES = ("convective", "neutral", "stable")


@attrs.frozen(eq=False)
class SiteSummary:
    """What :func:`fit_site` made of a site, as a site report reads it (``print`` shows it all).

    Attributes:
        exclusions: per kind of record left out (:data:`EXCLUSION_KINDS`) the number of
            records, the first and last time stamps and one reason as written; and the number
            fitted (kind ``fitted``).
        records, fitted: the numbers of records given and fitted.
        kept_fraction: fitted / given; kept_fraction_not_calm: fitted / (given - calm).
        classes: fitted records per class (convective, neutral, stable).
        class_by_hour: fitted records per hour of day (rows 0-23) and class (None when the
            records' names are no time stamps).
        offsets: the vane offsets applied [deg] (reading minus true direction, relative to the
            reference vane), their standard errors, the records they come from, and the source.
        cup_pairs: each redundant cup pair's median ratio where neither is in the mast's wake,
            its standard error and whether the pair disagrees.
        flags: the instruments' values removed, per kind and column: the count, the first time
            stamp and one reason.
    """

    exclusions: pd.DataFrame
    records: int
    fitted: int
    kept_fraction: float
    kept_fraction_not_calm: float
    classes: pd.Series
    class_by_hour: pd.DataFrame | None
    offsets: pd.DataFrame | None
    cup_pairs: pd.DataFrame | None
    flags: pd.DataFrame

    def plot_class_by_hour(self, ax=None):
        """Stacked bars of the fitted classes' fractions per hour of day; returns the Axes."""
        import matplotlib.pyplot as plt

        if self.class_by_hour is None:
            raise ValueError("the records' names are no time stamps: no hour of day to plot by")
        if ax is None:
            _, ax = plt.subplots(figsize=(7.0, 3.5))
        counts = self.class_by_hour
        share = counts.div(counts.sum(axis=1).replace(0, 1), axis=0)
        bottom = np.zeros(len(share))
        colours = {"convective": "tab:orange", "neutral": "tab:green", "stable": "tab:blue"}
        for name in share.columns:
            ax.bar(share.index, share[name], bottom=bottom, label=name, color=colours[name])
            bottom += share[name].to_numpy()
        ax.set_xlabel("hour of day")
        ax.set_ylabel("fraction of fitted records")
        ax.set_xticks(range(0, 24, 3))
        ax.set_ylim(0.0, 1.0)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))
        return ax

    def __str__(self) -> str:
        parts = [f"records {self.records}, fitted {self.fitted} ({100 * self.kept_fraction:.1f} "
                 f"%; {100 * self.kept_fraction_not_calm:.1f} % of those not calm)",
                 "classes: " + ", ".join(f"{k} {int(v)}" for k, v in self.classes.items()),
                 "left out:\n" + self.exclusions.drop(columns="example").to_string()]
        if self.offsets is not None and len(self.offsets):
            parts.append("vane offsets applied [deg] (reading minus true, relative to the "
                         "reference vane):\n" + self.offsets.to_string(float_format="{:.2f}".format))
        if self.cup_pairs is not None and len(self.cup_pairs):
            parts.append("cup pairs:\n" + self.cup_pairs.to_string(float_format="{:.4f}".format))
        if len(self.flags):
            parts.append("values removed:\n" + self.flags.drop(columns="example").to_string())
        if self.class_by_hour is not None:
            parts.append("class mix by hour of day (records):\n" + self.class_by_hour.T.to_string())
        return "\n\n".join(parts)

    __repr__ = __str__


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
    #: Per fitted record its row in the records, and the count of records given.
    rows: np.ndarray | None = None
    n_records: int | None = None
    #: What the mast's instruments gave (studies/mast.py): the vane offsets applied, the cup
    #: pairs' agreement, and the values removed (``row``, ``time``, ``column``, ``kind``,
    #: ``reason``).
    offsets: pd.DataFrame | None = None
    cup_pairs: pd.DataFrame | None = None
    flags: pd.DataFrame | None = None

    @property
    def stability_classes(self) -> np.ndarray:
        """Per fitted record its class: "convective", "neutral" or "stable"."""
        return np.atleast_1d(np.asarray(self.profile_fit.stability_class)).astype(str)

    def timestamps(self) -> pd.DatetimeIndex | None:
        """The fitted records' labels as times (None where they do not read as times)."""
        try:
            return pd.DatetimeIndex(pd.to_datetime(pd.Series(self.labels), errors="raise"))
        except (ValueError, TypeError):
            return None

    def summary(self) -> SiteSummary:
        """What the fit made of the site (:class:`SiteSummary`): what was left out and why,
        the fraction kept, the vane offsets applied, the cup pairs, the values removed, and the
        class mix by hour of day."""
        rows = []
        for kind in EXCLUSION_KINDS:
            some = self.excluded[self.excluded["kind"] == kind]
            if len(some):
                rows.append({"kind": kind, "records": len(some), "first": some["time"].iloc[0],
                             "last": some["time"].iloc[-1], "example": some["reason"].iloc[0]})
        rows.append({"kind": "fitted", "records": len(self.labels), "first": self.labels[0],
                     "last": self.labels[-1], "example": ""})
        exclusions = pd.DataFrame(rows).set_index("kind")
        total = self.n_records if self.n_records is not None else len(self.labels) + len(
            self.excluded)
        calm = int((self.excluded["kind"] == "calm").sum())
        times = self.timestamps()
        classes = pd.Categorical(self.stability_classes, categories=STABILITY_CLASSES)
        by_hour = None
        if times is not None:
            by_hour = pd.crosstab(np.asarray(times.hour), np.asarray(classes, dtype=str),
                                  rownames=["hour"], colnames=["class"])
            by_hour = by_hour.reindex(index=pd.RangeIndex(24, name="hour"),
                                      columns=pd.Index(STABILITY_CLASSES, name="class"),
                                      fill_value=0)
        flags = self.flags if self.flags is not None else pd.DataFrame(
            columns=["row", "time", "column", "kind", "reason"])
        return SiteSummary(
            exclusions=exclusions, records=total, fitted=len(self.labels),
            kept_fraction=len(self.labels) / total,
            kept_fraction_not_calm=len(self.labels) / max(total - calm, 1),
            classes=pd.Series(classes).value_counts().reindex(list(STABILITY_CLASSES)),
            class_by_hour=by_hour, offsets=self.offsets, cup_pairs=self.cup_pairs,
            flags=flags.groupby(["kind", "column"]).agg(
                records=("row", "size"), first=("time", "first"), example=("reason", "first")))

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
        serial numbers, docs/coupling.md#annual-energy), as a site report gives it: ``table``
        by fitted stability class (convective, neutral, stable) and the year, ``by_month``
        the energy per month of the records' time stamps (None when the records' names are no
        time stamps).

        The records run as chunks of one vectorised FLORIS model each, with the per-record
        atmosphere block (as :meth:`apply`), never a model per class."""
        energy = record_energy(fmodel, self.time_series(), self.atmosphere,
                               [str(label) for label in self.labels], optimizer_class,
                               classes=list(self.stability_classes), **options)
        times = self.timestamps()
        if times is not None:
            energy = attrs.evolve(energy, by_month=energy_by_period(energy,
                                                                    times.strftime("%Y-%m")))
        return energy


def fit_site(records: pd.DataFrame, reference_height: float, *,
             stability_input: str = "stability_parameter", on_misfit: str = "raise",
             time_column: str | None = None, booms: dict | None = None,
             direction_offsets="estimate", shadow_half_width: float = SHADOW_HALF_WIDTH,
             **fit_options_and_inputs) -> SiteAtmosphere:
    """Fit every record of a site (module docstring) and give FLORIS's inputs per record.

    The mast's instruments are read first (studies/mast.py, docs/measurements.md#a-real-mast):
    vanes at their own heights, their offsets estimated and removed, stuck vanes and bad or
    disagreeing readings removed and named, redundant cups chosen out of the mast's wake, and
    the cups' standard deviations (``speed_<h>m_std``) given to the fit as the measured
    turbulence intensity at the cup height nearest ``reference_height``.

    Records a mast logs that no atmosphere of the model describes (docs/measurements.md#a-year-of-records)
    are named by their time stamp and a reason: a zero (or negative) speed reading, too few
    data, calm, a direction backing with height (a front), speeds falling with height, less
    shear than a neutral layer (convective, with the default stable fit; ``stability="either"``
    fits convective layers), a profile the model cannot follow (misfit), a repeated time
    stamp, or a fitted state the atmosphere block cannot give back. One record never aborts the others' fits.

    Args:
        records: DataFrame with ``speed_<h>m`` (or ``speed_<h>m_<boom>``), optionally
            ``speed_<h>m[_<boom>]_std``, ``direction_<h>m`` and a time column.
        reference_height: FLORIS's ``reference_wind_height`` [m] (the hub height, usually),
            above 10 roughness lengths and at most twice the highest measurement.
        stability_input: the stability input of the atmosphere block (``stability_parameter``,
            ``obukhov_length`` or ``cooling_rate``; the block is checked to give back the fit).
        on_misfit: ``"raise"`` (ValueError naming the first such record, its time stamp and
            why) or ``"drop"`` (leave such records out: ``dropped`` lists them,
            ``excluded`` gives each one's reason and ``summary()`` the counts).
        time_column: the column naming the records in messages and classes (default: ``time``
            where the records have it, else their index).
        booms: ``{boom: orientation_deg}`` of cups named ``speed_<h>m_<boom>``: the direction
            from the mast to the cup, clockwise from north.
        direction_offsets: ``"estimate"`` (default: each vane's offset relative to the vane
            nearest ``reference_height``, from the strong-wind records), ``{vane height:
            offset_deg}`` (the reading minus the true direction; vanes not named: 0), or None.
        shadow_half_width: [deg] half-width of a cup's mast-wake sector (default 30).
        **fit_options_and_inputs: ``EkmanABL.fit_profile``'s options and fixed inputs
            (``latitude``, ``roughness_length``, ``speed_noise``...).
    """
    if on_misfit not in MISFIT_POLICIES:
        raise ValueError(f"fit_site: on_misfit must be one of {list(MISFIT_POLICIES)}; got "
                         f"{on_misfit!r}")
    if {"on_misfit", "labels", "direction_heights"} & set(fit_options_and_inputs):
        raise ValueError("fit_site sets fit_profile's on_misfit, labels and direction_heights "
                         "itself (from its own on_misfit, the time column and the vanes' "
                         "columns)")
    if (isinstance(reference_height, (bool, np.bool_))
            or not isinstance(reference_height, (int, float, np.integer, np.floating))
            or not np.isfinite(reference_height) or reference_height <= 0):
        raise ValueError(f"fit_site: reference_height must be a number > 0 m (not a string); "
                         f"got {reference_height!r}")
    columns = mast_columns(records, booms)
    if time_column is not None and time_column not in records.columns:
        raise ValueError(f"fit_site: time_column {time_column!r} is not a column of records "
                         f"(columns: {list(records.columns)}); give None to name the records "
                         "by their index")
    time_column = "time" if time_column is None else time_column
    labels = (records[time_column].astype(str).tolist() if time_column in records.columns
              else [str(i) for i in records.index])
    if len(records) == 0:
        raise ValueError("fit_site: records is empty")
    z0 = np.max(np.asarray(fit_options_and_inputs.get("roughness_length", 0.0), float))
    if not reference_height > 10.0 * z0:
        raise ValueError(f"fit_site: reference_height must be > 10 roughness lengths "
                         f"(roughness_length {z0:g} m: above the roughness sublayer, where the "
                         f"fitted profile is a wind a turbine meets); got {reference_height!r} m")
    top = max(columns.cup_heights.max(), columns.vane_heights.max(initial=0.0))
    if reference_height > MAX_EXTRAPOLATION * top:
        raise ValueError(f"fit_site: reference_height must be at most {MAX_EXTRAPOLATION:g} "
                         f"times the highest measurement ({top:g} m: the fitted profile is not "
                         f"extrapolated further); got {reference_height!r} m")
    instruments = read_instruments(
        records, columns, float(reference_height), neutral_turning(fit_options_and_inputs),
        booms=booms, direction_offsets=direction_offsets, shadow_half_width=shadow_half_width,
        labels=labels)
    if (isinstance(direction_offsets, str)
            and (instruments.offsets["source"] == "estimated").any()):
        instruments = offsets_from_neutral_fits(instruments, float(reference_height),
                                                 fit_options_and_inputs)
    heights, speeds, directions, speed_columns = fit_heights(instruments, columns)
    excluded = screen_records(speed_columns, labels, heights, speeds, directions,
                       3 if fit_options_and_inputs.get("fit_roughness") else 2)
    if on_misfit == "raise" and excluded:
        row, (kind, text) = next(iter(sorted(excluded.items())))
        raise ValueError(f"fit_site: record {labels[row]} cannot be fitted: {text}"
                         + more_excluded_text(excluded, labels, row) + ". Give on_misfit='drop' to leave out "
                         "such records (SiteAtmosphere.summary() tells what was left out and why)")
    fit_inputs = dict(fit_options_and_inputs)
    # (a measured turbulence intensity is a pair (height, value), each one number or a column)
    turbulence = fit_inputs.pop("turbulence_intensity", None)
    if turbulence is None and instruments.speed_std is not None:
        turbulence = measured_turbulence(instruments, float(reference_height))
    # (fixed inputs may be one per record; the fit's options, a noise pair say, are not)
    per_record = {k: v for k, v in fit_inputs.items() if k not in FIT_OPTIONS and np.ndim(v) == 1}
    candidates = np.setdiff1d(np.arange(len(records)), np.fromiter(excluded, int, len(excluded)))
    if candidates.size == 0:
        raise ValueError(f"fit_site: no record can be fitted ({reasons_text(excluded)})")
    inputs = {**fit_inputs, **{k: np.asarray(v)[candidates] for k, v in per_record.items()}}
    if turbulence is not None:
        inputs["turbulence_intensity"] = tuple(
            np.asarray(v, float)[candidates] if np.ndim(v) == 1 else v for v in turbulence)
    abl = EkmanABL.fit_profile(
        **fit_data(instruments, candidates),
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
                         f"({reasons_text(excluded)})")
    rows = sorted(excluded)
    table = pd.DataFrame({"time": [labels[i] for i in rows],
                          "kind": [excluded[i][0] for i in rows],
                          "reason": [excluded[i][1] for i in rows]},
                         index=pd.Index(rows, name="row"))
    flags = instruments.flags
    flags.insert(1, "time", [labels[i] for i in flags["row"]])
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
        rows=candidates[kept],
        n_records=len(records),
        offsets=instruments.offsets,
        cup_pairs=instruments.cup_pairs,
        flags=flags,
    )
