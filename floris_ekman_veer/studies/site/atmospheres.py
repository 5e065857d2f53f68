"""Stage 5 of the site fit (pipeline.py): the atmospheres, per record kept FLORIS's inputs at
the reference height (docs/measurements.md#from-the-fit-to-floris): the wind speed and direction
of the fitted profile there, the turbulence intensity I_u of the fitted ABL (Eq. Iu_model) or the
cups' measured one, and the atmosphere block with one entry per record (with the measured
turbulence as its ``turbulence_factor``, the wake's ambient turbulence). Driven by those wind
speeds, the block gives back the fitted ABLs (checked by stage 4). :class:`SiteAtmosphere`
carries them to FLORIS (a ``TimeSeries``, :meth:`~SiteAtmosphere.apply`, annual energy), and
:meth:`SiteAtmosphere.summary` reports the site (:class:`SiteSummary`).
"""

from __future__ import annotations

import warnings

import attrs
import numpy as np
import pandas as pd
from floris.wind_data import TimeSeries

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.atmosphere.inputs.input_ranges import MAX_TURBULENCE_FACTOR
from floris_ekman_veer.plugin.inflow.inflow import set_atmosphere
from floris_ekman_veer.studies.energy.energy import energy_by_month, record_energy
from floris_ekman_veer.studies.site.baseline import NeutralBaseline
from floris_ekman_veer.studies.site.readings import Instruments
from floris_ekman_veer.studies.site.record_fit import EXCLUSION_KINDS, RecordFit
from floris_ekman_veer.studies.site.wra_file import MastMetadata

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
            reference vane), their standard errors (statistical) and the reference turning's
            systematic uncertainty (offsets.py), the records they come from, and the source.
        cup_pairs: each redundant cup pair's median ratio where neither is in the mast's wake,
            its standard error and whether the pair disagrees.
        flags: the instruments' values removed, per kind and column: the count, the first time
            stamp and one reason.
        baseline: the neutral baseline per sector (roughness length with its uncertainty factor,
            neutral TI with its standard error, the model's neutral TI; baseline.py).
        tops_below_reference: fitted records whose layer is so shallow that their I_u at the
            reference height is 0 (its top below 1 / 1.62 of it; warned by :func:`fit_site`).
        cup_calibrations: per cup the calibration applied (its certificate's slope, offset and
            uncertainty, and the logger's transfer function it replaced; readings.py).
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
    tops_below_reference: int = 0
    baseline: pd.DataFrame | None = None
    cup_calibrations: pd.DataFrame | None = None

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
        if self.cup_calibrations is not None and (
                self.cup_calibrations["source"] == "certificate").any():
            parts.append("cup calibrations applied (certificate replacing the logger's transfer "
                         "function; uncertainty relative):\n"
                         + self.cup_calibrations.to_string(float_format="{:.5g}".format))
        if self.offsets is not None and len(self.offsets):
            parts.append("vane offsets applied [deg] (reading minus true, relative to the "
                         "reference vane):\n" + self.offsets.to_string(float_format="{:.2f}".format))
        if self.baseline is not None:
            parts.append("neutral baseline per sector (strong-wind records):\n"
                         + self.baseline.to_string(float_format="{:.4g}".format))
        if self.cup_pairs is not None and len(self.cup_pairs):
            parts.append("cup pairs:\n" + self.cup_pairs.to_string(float_format="{:.4f}".format))
        if self.tops_below_reference:
            parts.append(f"{self.tops_below_reference} fitted records have their boundary layer "
                         "top so far below the reference height that their I_u there is 0")
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
            the reference height (the fitted profile's speed and meteorological direction; the
            measured TI where the cups log their standard deviations, else the fitted ABL's
            I_u: :func:`ambient_turbulence`).
        atmosphere: the ``ekman_veer.atmosphere`` block, one entry per record; where the cups
            log their standard deviations its ``turbulence_factor`` makes the wake's ambient
            I_u the measured TI (:func:`turbulence_factors`).
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
    #: What the mast's instruments gave (stages 2-3, readings.py and offsets.py): the vane
    #: offsets applied, the cup pairs' agreement, and the values removed (``row``, ``time``,
    #: ``column``, ``kind``, ``reason``).
    offsets: pd.DataFrame | None = None
    cup_pairs: pd.DataFrame | None = None
    flags: pd.DataFrame | None = None
    #: The site's neutral baseline (baseline.py): the roughness rose and neutral turbulence.
    baseline: NeutralBaseline | None = None
    #: The mast's metadata file as read (wra_file.py: location, logger's UTC offset, columns).
    metadata: MastMetadata | None = None
    #: Per cup the calibration applied (readings.py's calibrated_cups).
    cup_calibrations: pd.DataFrame | None = None

    @property
    def neutral_roughness_lengths(self) -> np.ndarray | None:
        """Per fitted record its sector's neutral (effective) roughness length [m]."""
        return None if self.baseline is None else self.baseline.roughness_lengths[self.rows]

    @property
    def neutral_turbulence_intensities(self) -> np.ndarray | None:
        """Per fitted record its sector's measured neutral turbulence intensity (NaN: none)."""
        return None if self.baseline is None else self.baseline.turbulence_intensities[self.rows]

    @property
    def stability_classes(self) -> np.ndarray:
        """Per fitted record its class: "convective", "neutral" or "stable"."""
        return np.atleast_1d(np.asarray(self.profile_fit.stability_class)).astype(str)

    def timestamps(self) -> pd.DatetimeIndex | None:
        """The fitted records' labels as times (None where they do not read as times)."""
        try:
            with warnings.catch_warnings():
                # (pandas' notice that it parses each label alone: names that are no times)
                warnings.simplefilter("ignore", UserWarning)
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
            tops_below_reference=int(np.count_nonzero(self.turbulence_intensities <= 0.0)),
            baseline=None if self.baseline is None else self.baseline.sectors,
            cup_calibrations=self.cup_calibrations,
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
        a typical year's energy per calendar month, January to December, averaged over the
        years present, with each month's data coverage (None when the records' names are no
        time stamps; ``energy_by_month``).

        The records run as chunks of one vectorised FLORIS model each, with the per-record
        atmosphere block (as :meth:`apply`), never a model per class."""
        energy = record_energy(fmodel, self.time_series(), self.atmosphere,
                               [str(label) for label in self.labels], optimizer_class,
                               classes=list(self.stability_classes), **options)
        times = self.timestamps()
        if times is not None:
            energy = attrs.evolve(energy, by_month=energy_by_month(energy, times))
        return energy


def ambient_turbulence(abl, reference_height, measured, rows):
    """FLORIS's turbulence intensity per fitted record: the measured TI (``measured``: (height,
    values per record), or None) carried to the reference height by the fitted profile's own
    I_u shape (I_u(z_ref)/I_u(z_meas); at the same height the measured TI itself); the fitted
    I_u where none is measured (docs/measurements.md#reading-stability)."""
    model = np.asarray(abl.turbulence_intensity(reference_height), float).reshape(-1)
    if measured is None:
        return model
    height, values = measured
    at_height = np.asarray(abl.turbulence_intensity(height), float).reshape(-1)
    value = np.asarray(values, float)[rows]
    return np.where(np.isfinite(value), value * model / at_height, model)


def turbulence_factors(abl, measured, rows):
    """Per fitted record the atmosphere block's ``turbulence_factor``: the measured TI over the
    fitted ABL's I_u at the cups' height, so that the wake's ambient I_u (Eq. Iu_model times
    the factor, docs/atmosphere.md#ambient-turbulence) is the measured TI there and the
    profile's I_u shape carries it to other hub heights; 1 (the model's I_u) where none is
    measured, where the model's I_u there is 0 (a layer whose turbulence ends below the cups)
    or where the ratio leaves the factor's range. None without measured turbulence."""
    if measured is None:
        return None
    height, values = measured
    at_height = np.asarray(abl.turbulence_intensity(height), float).reshape(-1)
    value = np.asarray(values, float)[rows]
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = value / at_height
    usable = np.isfinite(factor) & (factor > 0) & (factor <= MAX_TURBULENCE_FACTOR)
    return np.where(usable, factor, 1.0)


def site_atmosphere(record_fit: RecordFit, instruments: Instruments, labels: list,
                    reference_height: float, baseline: NeutralBaseline | None = None, *,
                    stability_input: str = "stability_parameter") -> SiteAtmosphere:
    """The :class:`SiteAtmosphere` of stage 4's fit: FLORIS's inputs per record kept at
    ``reference_height`` (module docstring), what was left out and why, and what the
    instruments gave (offsets, cup pairs, values removed)."""
    excluded = record_fit.excluded
    rows = sorted(excluded)
    table = pd.DataFrame({"time": [labels[i] for i in rows],
                          "kind": [excluded[i][0] for i in rows],
                          "reason": [excluded[i][1] for i in rows]},
                         index=pd.Index(rows, name="row"))
    flags = instruments.flags.copy()
    flags.insert(1, "time", [labels[i] for i in flags["row"]])
    abl = record_fit.abl
    fit = abl.profile_fit
    z_ref = float(reference_height)
    turbulence = np.asarray(abl.turbulence_intensity(z_ref), float).reshape(-1)
    warn_tops_below(abl, list(fit.labels), z_ref, turbulence)
    return SiteAtmosphere(
        labels=list(fit.labels),
        abl=abl,
        reference_height=z_ref,
        wind_speeds=fit.speed(np.array([z_ref]))[:, 0],
        wind_directions=fit.direction(np.array([z_ref]))[:, 0],
        turbulence_intensities=ambient_turbulence(abl, z_ref, record_fit.measured_turbulence,
                                                  record_fit.rows),
        atmosphere=_with_turbulence(fit.atmosphere(stability_input), turbulence_factors(
            abl, record_fit.measured_turbulence, record_fit.rows)),
        dropped=list(table["time"]),
        excluded=table,
        rows=record_fit.rows,
        n_records=len(labels),
        offsets=instruments.offsets,
        cup_pairs=instruments.cup_pairs,
        flags=flags,
        baseline=baseline,
    )


def _with_turbulence(block: dict, factors) -> dict:
    """The atmosphere block with the records' ``turbulence_factor`` (a list, one per record; a
    float for one record, as the block's other values), unchanged without one."""
    if factors is None:
        return block
    single = not any(isinstance(v, list) for v in block.values())
    return {**block, "turbulence_factor": float(factors[0]) if single else factors.tolist()}


def warn_tops_below(abl: EkmanABL, labels: list, reference_height: float, turbulence) -> None:
    """A ShallowBoundaryLayerWarning naming the records whose fitted layer is so shallow
    (light-wind stable nights) that the model's turbulence ends below the reference height:
    I_u is continued above the layer top h to where its variance vanishes, 1.62 h, and is 0
    above (docs/atmosphere.md#shallow-boundary-layer), and so is their turbulence intensity at
    the reference height."""
    top = np.asarray(abl.boundary_layer_height, float).reshape(-1)
    none = np.flatnonzero(np.asarray(turbulence) <= 0.0)
    if none.size == 0:
        return
    shown = ", ".join(f"{labels[k]} (top {top[k]:.0f} m)" for k in none[:3])
    package_warnings.warn(
        f"fit_site: {none.size} of {top.size} fitted records have their boundary layer top so "
        f"far below the reference height {reference_height:g} m ({shown}"
        f"{', ...' if none.size > 3 else ''}) that their turbulence intensity there is 0 (the "
        "model's I_u ends at 1.62 times the top): light-wind stable layers, in which a wake at "
        "that height meets no ambient turbulence. Give records from a mast reaching the rotor's "
        "top, or leave such hours out (SiteAtmosphere.summary() counts them)",
        package_warnings.ShallowBoundaryLayerWarning)
