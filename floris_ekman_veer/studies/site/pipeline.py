"""The site fit as its stages, in the order a reader follows them (docs/measurements.md#a-real-mast,
docs/architecture.md): a site's measured wind profiles as per-record FLORIS inputs.

Records are a pandas DataFrame, one row per record (a 10-minute mean, say), with columns
``speed_<height>m`` [m/s] and ``direction_<height>m`` [deg, meteorological] (e.g. ``speed_90m``,
``direction_90m``; NaN for a missing value), or a real mast's cups on booms, their standard
deviations and vanes at their own heights (columns.py), and optionally a ``time`` column naming
the records. :func:`fit_site` runs, each stage a module a user can call and inspect:

1. the instruments the columns hold (:func:`.columns.mast_columns`), named by the mast's IEA
   Wind Task 43 metadata file where one is given (:func:`.wra_file.read_wra_file`);
2. the cleaned readings: the cups' calibration certificates applied first where given
   (:func:`.readings.calibrated_cups`), bad and stuck readings removed and named, redundant cups
   out of the mast's wake (:func:`.readings.read_instruments`);
3. the site's neutral baseline (its roughness rose and neutral turbulence,
   :func:`.baseline.neutral_baseline`) and the vane offsets, both from the strong-wind,
   near-neutral records (:func:`.offsets.estimate_vane_offsets`);
4. the per-record fit: records no fit should see named, every other one fitted
   (:func:`.record_fit.fit_records`);
5. the atmospheres: FLORIS's inputs per record (:func:`.atmospheres.site_atmosphere`).
"""

from __future__ import annotations

import attrs
import numpy as np
import pandas as pd

from floris_ekman_veer.studies.site.atmospheres import SiteAtmosphere, site_atmosphere
from floris_ekman_veer.studies.site.baseline import checked_roughness, neutral_baseline
from floris_ekman_veer.studies.site.columns import mast_columns
from floris_ekman_veer.studies.site.offsets import estimate_vane_offsets
from floris_ekman_veer.studies.site.readings import (SHADOW_HALF_WIDTH, calibrated_cups,
                                                     read_instruments)
from floris_ekman_veer.studies.site.record_fit import fit_records
from floris_ekman_veer.studies.site.stability import checked_site_type
from floris_ekman_veer.studies.site.wra_file import read_wra_file

#: What :func:`fit_site` does with records that fit no atmosphere of the model.
MISFIT_POLICIES = ("raise", "drop")
#: The reference height may lie at most this many times above the highest measurement: the
#: fitted profile is not extrapolated further than the mast's own height again.
MAX_EXTRAPOLATION = 2.0


def fit_site(records: pd.DataFrame, reference_height: float, *,
             stability_input: str = "stability_parameter", on_misfit: str = "raise",
             time_column: str | None = None, booms: dict | None = None,
             direction_offsets="estimate", shadow_half_width: float = SHADOW_HALF_WIDTH,
             roughness_length="estimate", metadata=None, site_type: str | None = None,
             longitude: float | None = None, time_zone: str | None = None,
             cup_calibrations: dict | None = None, **fit_options_and_inputs) -> SiteAtmosphere:
    """Fit every record of a site (module docstring) and give FLORIS's inputs per record.

    The mast's instruments are read first (columns.py, readings.py, offsets.py;
    docs/measurements.md#a-real-mast):
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
        roughness_length: ``"estimate"`` (default: the site's own effective roughness per
            30-deg sector from its strong-wind, near-neutral records, baseline.py and
            docs/measurements.md#the-sites-neutral-baseline), a number [m], one per record, or
            ``{sector centre deg: z0 m}`` (each record takes the sector nearest its direction).
        metadata: the path of the mast's IEA Wind Task 43 WRA data model file (JSON; wra_file.py,
            docs/measurements.md#the-masts-own-metadata): its logger columns are read as the
            records' columns (temperatures and pressures too), its booms as ``booms``, its
            location as ``latitude`` and ``longitude`` and its logger's offset from UTC as
            ``time_zone`` (where not given); given ``booms``, ``latitude`` or ``longitude``
            that contradict it, or a column it names that the records
            lack, are refused naming both.
        site_type: ``"onshore"`` (no convective state while the sun is below the horizon, the
            heat flux by day at most half the clear-sky irradiance: needs ``latitude``,
            ``longitude`` and the stamps' ``time_zone``), ``"offshore"`` or None (no bound
            from the sun) (docs/measurements.md#reading-stability).
        longitude: [deg, east positive] the site's, for the sun's position.
        time_zone: the time zone of naive time stamps ("UTC", "Europe/London", "+01:00"):
            never guessed; stamps that carry their offset need none.
        cup_calibrations: the cups' calibration certificates, ``{cup column: {"slope": s,
            "offset": o, "logger_slope": s_L, "logger_offset": o_L[, "uncertainty": u]}}``: each
            cup's readings re-calibrated from the logger's generic transfer function (s_L, o_L)
            to its certificate's (s, o) before anything else, as wind-resource practice does;
            ``u`` the certificate's relative uncertainty of the slope (readings.py's
            ``calibrated_cups``; docs/measurements.md#the-sites-neutral-baseline). A metadata
            file's sensor calibrations are read the same way; a cup the records lack, or a
            certificate that contradicts the file's, is refused naming both.
        **fit_options_and_inputs: ``EkmanABL.fit_profile``'s options and fixed inputs
            (``latitude``, ``roughness_length``, ``speed_noise``...).

    Returns:
        SiteAtmosphere: the records fitted (``labels``, ``profile_fit``, ``stability_classes``),
        FLORIS's inputs per record at ``reference_height`` (``wind_speeds``, ``wind_directions``,
        ``turbulence_intensities``, ``time_series()``, the per-record ``atmosphere`` block;
        ``apply(fmodel)`` and ``annual_energy(fmodel, ...)`` run them), the records left out
        with their reasons (``dropped``, ``excluded``) and the site report ``summary()``.

    Example (the package's 24 synthetic hourly records of a 150 m mast at 52 N):

        >>> import pandas as pd
        >>> import floris_ekman_veer
        >>> records = pd.read_csv(floris_ekman_veer.example_input("site/synthetic_mast.csv"),
        ...                       comment="#")
        >>> site = floris_ekman_veer.fit_site(records, 90.0, latitude=52.0,
        ...                                   roughness_length=0.05)
        >>> len(site.labels), site.stability_classes.tolist().count("stable")
        (24, 11)
        >>> site.wind_speeds[:3].round(2)    # FLORIS's wind speeds at 90 m [m/s]
        array([6.49, 5.9 , 5.35])
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
    # 1. the instruments (from the mast's metadata file where given)
    mast = None
    if metadata is not None:
        mast = read_wra_file(metadata)
        records = mast.named_records(records)
        if booms is not None and mast.booms and dict(booms) != mast.booms:
            raise ValueError(f"fit_site: booms={booms} contradicts the mast's metadata file "
                             f"{str(metadata)!r}, whose booms are {mast.booms}; give one of them")
        booms = booms if booms is not None else (mast.booms or None)
        given = fit_options_and_inputs.get("latitude", mast.latitude)
        if np.ndim(given) or not np.isclose(given, mast.latitude, atol=1e-6):
            raise ValueError(f"fit_site: latitude={given!r} contradicts the mast's metadata file "
                             f"{str(metadata)!r}, whose location is at {mast.latitude:g} deg; "
                             "give one of them")
        fit_options_and_inputs = {**fit_options_and_inputs, "latitude": mast.latitude}
        # The file's location and logger clock give the sun's position (site_type="onshore")
        # as the hand-given longitude and time_zone would; given ones must agree with it.
        if longitude is not None and not np.isclose(longitude, mast.longitude, atol=1e-6):
            raise ValueError(f"fit_site: longitude={longitude!r} contradicts the mast's metadata "
                             f"file {str(metadata)!r}, whose location is at {mast.longitude:g} "
                             "deg; give one of them")
        longitude = mast.longitude
        time_zone = time_zone if time_zone is not None else mast.time_zone
    checked_site_type(site_type, longitude, time_zone, fit_options_and_inputs)
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
    checked_roughness(roughness_length, float(reference_height))
    top = max(columns.cup_heights.max(), columns.vane_heights.max(initial=0.0))
    if reference_height > MAX_EXTRAPOLATION * top:
        raise ValueError(f"fit_site: reference_height must be at most {MAX_EXTRAPOLATION:g} "
                         f"times the highest measurement ({top:g} m: the fitted profile is not "
                         f"extrapolated further); got {reference_height!r} m")
    z_ref = float(reference_height)
    # 2. the cleaned readings: the cups' certificates first (every later stage reads them)
    records, calibrations = calibrated_cups(records, columns, _certificates(
        cup_calibrations, mast, metadata))
    instruments = read_instruments(records, columns, booms=booms,
                                   direction_offsets=direction_offsets,
                                   shadow_half_width=shadow_half_width, labels=labels)
    # 3. the neutral baseline and the vane offsets (whose reference turning is the neutral
    # surface layer's, the model's state at the site's roughness giving its depth: offsets.py)
    # (a height's speed is its cups' mean: its calibration uncertainty, relative, is theirs
    # combined over their number)
    per_height = calibrations.groupby("height")["uncertainty"].agg(
        lambda u: float(np.sqrt(np.sum(np.square(u))) / len(u)))
    baseline = neutral_baseline(instruments, z_ref, fit_options_and_inputs, roughness_length,
                                cups_per_height=[len(columns.cups[h]) for h in columns.cup_heights],
                                calibration_uncertainty=per_height.loc[columns.cup_heights])
    fit_inputs = {**fit_options_and_inputs, "roughness_length": (
        roughness_length if np.ndim(roughness_length) == 0 and not isinstance(
            roughness_length, (str, dict)) else baseline.roughness_lengths)}
    if isinstance(direction_offsets, str):
        instruments = estimate_vane_offsets(instruments, records, columns, z_ref, fit_inputs,
                                            booms=booms, shadow_half_width=shadow_half_width)
    # 4. the per-record fit
    record_fit = fit_records(instruments, columns, labels, z_ref, fit_inputs,
                             stability_input=stability_input, on_misfit=on_misfit,
                             records=records, site_type=site_type, longitude=longitude,
                             time_zone=time_zone, baseline=baseline)
    # 5. the atmospheres
    site = site_atmosphere(record_fit, instruments, labels, z_ref, baseline,
                           stability_input=stability_input)
    site = attrs.evolve(site, cup_calibrations=calibrations)
    return site if mast is None else attrs.evolve(site, metadata=mast)


def _certificates(cup_calibrations, mast, metadata):
    """The cups' certificates given and the metadata file's together (by the records' column
    names: the file's logger names are accepted too); ValueError where both give one cup's and
    they differ."""
    from_file = dict(mast.cup_calibrations) if mast is not None else {}
    if cup_calibrations is None:
        return from_file or None
    if not isinstance(cup_calibrations, dict):
        raise ValueError(f"fit_site: cup_calibrations must be {{cup column: certificate}}; got "
                         f"{type(cup_calibrations).__name__}")
    names = dict(zip(mast.columns["column"], mast.columns["name"])) if mast is not None else {}
    merged = dict(from_file)
    for column, certificate in cup_calibrations.items():
        name = names.get(column, column)
        if name in from_file and isinstance(certificate, dict) and any(
                not np.isclose(certificate.get(k, np.nan), v, rtol=1e-9, atol=0.0)
                for k, v in from_file[name].items() if k != "uncertainty"):
            raise ValueError(f"fit_site: cup_calibrations[{column!r}] = {certificate} contradicts "
                             f"the mast's metadata file {str(metadata)!r}, whose certificate of "
                             f"that cup is {from_file[name]}; give one of them")
        merged[name] = certificate
    return merged
