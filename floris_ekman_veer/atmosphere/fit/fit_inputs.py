"""The checks of the profile fit's options and data (docs/measurements.md): option names, the
noise, the shapes, directions in degrees (not radians), a measured turbulence intensity and the
directions' own heights, each refused with a ValueError naming it."""

from __future__ import annotations

import difflib
import inspect
from typing import NamedTuple

import numpy as np

from floris_ekman_veer._validation import real_array, require_at
from floris_ekman_veer.atmosphere.fit.fit_residuals import DEFAULT_SPEED_NOISE
from floris_ekman_veer.atmosphere.inputs.stability_inputs import STABILITY_INPUTS
from floris_ekman_veer.warnings import DirectionUnitsWarning, warn

#: Keyword options of the fit (all other keywords are fixed EkmanABL inputs).
FIT_OPTIONS = ("speed_noise", "direction_noise", "fit_roughness", "refusal_probability",
               "on_misfit", "labels", "max_iterations", "stability", "chunk_size",
               "turbulence_intensity", "turbulence_noise", "direction_model_error",
               "fit_mixed_layer_height", "direction_heights")
#: Default noise of a measured turbulence intensity, relative to its value: the order of the
#: sampling error of a 10-minute variance (docs/measurements.md#measured-turbulence).
DEFAULT_TURBULENCE_NOISE = 0.1
#: Records iterated together by default: the work arrays stay below about 100 MB.
DEFAULT_CHUNK_SIZE = 4096
#: The signs of 1/L a fit may take (``stability``): 1/L >= 0 (stable or neutral), 1/L <= 0
#: (convective or neutral), or either, chosen per record by the smaller misfit.
STABILITY_CHOICES = ("stable", "convective", "either")
#: A record is refused (or flagged) when the model plus the stated noise would give a misfit as
#: large as its best fit's with a probability below this (chi-square test of its residuals).
DEFAULT_REFUSAL_PROBABILITY = 1e-6
#: Default starting roughness length [m] when it is fitted and none is given.
DEFAULT_ROUGHNESS_START = 0.05


def check_option_names(abl_class, fixed_inputs):
    """An unknown keyword is a ValueError naming it, the closest valid name and the options."""
    inputs = [k for k in inspect.signature(abl_class.__init__).parameters if k != "self"]
    unknown = sorted(set(fixed_inputs) - set(inputs))
    if unknown:
        valid = list(FIT_OPTIONS) + [k for k in inputs if k not in STABILITY_INPUTS
                                     and k != "geostrophic_wind"]
        close = difflib.get_close_matches(unknown[0], valid, n=1)
        raise ValueError(
            f"fit_profile: unknown option or input {unknown[0]!r}"
            + (f" (did you mean {close[0]!r}?)" if close else "")
            + f"; the options are {list(FIT_OPTIONS)} and the fixed {abl_class.__name__} inputs "
            f"{valid[len(FIT_OPTIONS):]}")


#: [deg] A record whose directions all lie within 0 to 2 pi and spread over less than this
#: between its vanes (a veer and a vane noise of a few hundredths of a "degree") looks like
#: directions in radians: a warning.
RADIANS_VEER = 0.5

#: [deg] Winds within this of north, read beyond 2 pi in degrees (6.3 to 30 deg, 330 to 360
#: deg), show that a table's winds blow from the north: its records within 0 to 2 pi are
#: northerly winds too, not directions in radians.
NORTHERLY_SECTOR = 30.0


def warn_if_radians(fit):
    """:class:`DirectionUnitsWarning`, once, naming the records whose directions all lie within
    0 to 2 pi and turn by less than :data:`RADIANS_VEER` between their vanes: a real veer of a
    few degrees and a vane's noise, given in radians, are a few hundredths of a "degree" (in
    degrees a vane's noise alone spreads them wider). Two records or more all in radians are
    refused (`check_degrees`). A northerly wind within 6.3 deg of north, steady to 0.5 deg,
    looks alike: it is warned about alone, or among records of other directions, but not in a
    table that also holds northerly winds beyond 2 pi in degrees (within
    :data:`NORTHERLY_SECTOR` of north): there the wind has turned through north, as a mast's
    year does a few times."""
    if fit.directions is None:
        return
    d = np.atleast_2d(fit.directions)
    measured = np.sum(np.isfinite(d), axis=1) >= 2
    within = measured & np.all(~np.isfinite(d) | ((d >= 0.0) & (d <= 2.0 * np.pi)), axis=1)
    if not np.any(within):
        return
    from_north = np.abs(np.mod(d + 180.0, 360.0) - 180.0)
    with np.errstate(invalid="ignore"):
        if np.any((np.abs(d) > 2.0 * np.pi) & (from_north <= NORTHERLY_SECTOR)):
            return
    rows = np.flatnonzero(within)
    spread = np.nanmax(d[rows], axis=1) - np.nanmin(d[rows], axis=1)
    small = spread < RADIANS_VEER
    if not np.any(small):
        return
    labels = [fit.labels[i] for i in rows[small]]
    shown = ", ".join(str(k) for k in labels[:5]) + (", ..." if len(labels) > 5 else "")
    warn(f"fit_profile: the directions of {len(labels)} record(s) ({shown}) all lie within 0 to "
         f"2 pi and turn by only {float(spread[small][0]):.2g} deg between their vanes, as "
         "directions in radians would: give degrees (np.degrees); a northerly wind in degrees "
         "can be given as 360 + direction", DirectionUnitsWarning,
         items=[str(k) for k in labels])


def check_degrees(directions):
    """Directions given in radians are refused: all of them within +-2 pi in two records or
    more (a table of winds all within 6.3 deg of north). One record cannot tell: a northerly
    wind veering by a few degrees looks like radians."""
    finite = directions[np.isfinite(directions)]
    records = int(np.sum(np.any(np.isfinite(directions), axis=1)))
    if records >= 2 and np.all(np.abs(finite) <= 2.0 * np.pi):
        raise ValueError(
            f"fit_profile: directions must be in degrees; all {finite.size} given lie within "
            f"+-2 pi ({finite.min():.3g} to {finite.max():.3g}), as radians would. Convert "
            "radians with np.degrees; directions that are degrees within 6.3 deg of north can "
            "be given as 360 + direction")


def checked_turbulence(turbulence_intensity, noise, n, z0, fit_roughness):
    """(heights (n,), values (n,), relative noise (n,)) of ``turbulence_intensity=(height,
    value)``, or None; ValueError naming what is wrong."""
    if turbulence_intensity is None:
        return None
    if isinstance(noise, bool) or not np.isscalar(noise) or not np.isfinite(noise) or noise <= 0:
        raise ValueError(f"fit_profile: turbulence_noise must be a number > 0 (relative to the "
                         f"measured value); got {noise!r}")
    try:
        height, value = turbulence_intensity
    except (TypeError, ValueError):
        raise ValueError("fit_profile: turbulence_intensity must be (height [m], value), each a "
                         f"number or one per record ({n}); got {turbulence_intensity!r}") from None
    arrays = []
    for name, v in (("turbulence_intensity height", height), ("turbulence_intensity value", value)):
        array = real_array(name, v)
        if array.ndim > 1 or (array.ndim == 1 and array.size != n):
            raise ValueError(f"fit_profile: {name} must be a number or one per record ({n}); got "
                             f"shape {array.shape}")
        arrays.append(np.broadcast_to(array, (n,)).astype(float))
    height, value = arrays
    lowest = 0.0 if fit_roughness else np.broadcast_to(z0, (n,))
    require_at(np.isfinite(height) & (height > lowest), "turbulence_intensity height",
               "finite and > roughness_length z0", height)
    require_at(np.isnan(value) | ((value > 0) & (value < 1)), "turbulence_intensity value",
               "in (0, 1) (sigma_u/U; NaN: none for that record)", value)
    return height, value, np.full(n, float(noise))


def require_distinct_heights(name, heights):
    """ValueError naming a height given twice in one record's ``heights`` (or
    ``direction_heights``): two data at one height are two readings of one instrument, or a
    typing error; which one the profile should meet is unknown."""
    z = np.asarray(heights)
    if z.dtype.kind not in "iuf" or z.ndim not in (1, 2) or z.shape[-1] < 2:
        return  # (the shape and type checks name such heights)
    rows = np.atleast_2d(z).astype(float)
    ordered = np.sort(rows, axis=1)
    repeated = np.flatnonzero(np.any(np.diff(ordered, axis=1) == 0, axis=1))
    if repeated.size:
        i = int(repeated[0])
        value = ordered[i][:-1][np.diff(ordered[i]) == 0][0]
        where = np.flatnonzero(rows[i] == value).tolist()
        record = f" of record {i}" if z.ndim == 2 else ""
        raise ValueError(f"fit_profile: {name}{record} repeat {value:g} m (columns {where}); give "
                         "each height once (one speed or direction per height)")


def at_direction_heights(heights, speeds, directions, direction_heights):
    """(heights, speeds, directions) on the heights of both the speeds and the directions
    (``fit_profile(direction_heights=...)``): the speeds NaN (missing) at a direction's height,
    the directions NaN at a speed's. Shared heights are merged (one column per height); per-record
    ones are put side by side."""
    if directions is None:
        raise ValueError("fit_profile: direction_heights is given but directions is None; give "
                         "the directions measured at those heights")
    z_s = real_array("heights", heights, "> 0 m")
    z_d = real_array("direction_heights", direction_heights, "> 0 m")
    require_at(np.isfinite(z_d) & (z_d > 0), "direction_heights", "finite and > 0 m", z_d)
    s = real_array("speeds", speeds, "real numbers (NaN: missing)")
    d = real_array("directions", directions, "real numbers (NaN: missing)")
    single = s.ndim == 1
    s, d = np.atleast_2d(s), np.atleast_2d(d)
    if s.ndim != 2 or d.ndim != 2 or d.shape[0] != s.shape[0] or (single and directions is not None
                                                                   and np.ndim(directions) != 1):
        raise ValueError(f"fit_profile: directions must be (n_records, n_direction_heights) like "
                         f"speeds (n_records, n_heights) = {np.shape(speeds)}; got shape "
                         f"{np.shape(directions)}")
    n, m_d = d.shape
    if z_d.shape not in ((m_d,), (n, m_d)) or (single and z_d.ndim != 1):
        raise ValueError(f"fit_profile: direction_heights must be (n_direction_heights,) = "
                         f"({m_d},) or (n_records, n_direction_heights) = ({n}, {m_d}), one per "
                         f"column of directions; got shape {z_d.shape}")
    if z_s.ndim == 1 and z_d.ndim == 1 and z_s.shape == (s.shape[1],):
        union = np.union1d(z_s, z_d)
        speeds_at = np.full((n, union.size), np.nan)
        directions_at = np.full((n, union.size), np.nan)
        speeds_at[:, np.searchsorted(union, z_s)] = s
        directions_at[:, np.searchsorted(union, z_d)] = d
    else:
        if z_s.shape not in ((s.shape[1],), s.shape):
            return heights, speeds, directions  # (fit_profile names the wrong shape)
        union = np.concatenate([np.broadcast_to(z_s, s.shape), np.broadcast_to(z_d, d.shape)],
                               axis=1)
        speeds_at = np.concatenate([s, np.full(d.shape, np.nan)], axis=1)
        directions_at = np.concatenate([np.full(s.shape, np.nan), d], axis=1)
    if single:
        return union if union.ndim == 1 else union[0], speeds_at[0], directions_at[0]
    return union, speeds_at, directions_at


def checked_speed_noise(speed_noise):
    """``speed_noise`` as given if valid: a number > 0 [m/s], or (absolute [m/s] > 0, relative
    in [0, 1)); ValueError naming it otherwise."""
    def number(v):
        return (not isinstance(v, bool) and isinstance(v, (int, float, np.integer, np.floating))
                and np.isfinite(v))

    if number(speed_noise) and speed_noise > 0:
        return float(speed_noise)
    if (isinstance(speed_noise, (tuple, list)) and len(speed_noise) == 2
            and all(number(v) for v in speed_noise) and speed_noise[0] > 0
            and 0 <= speed_noise[1] < 1):
        return (float(speed_noise[0]), float(speed_noise[1]))
    raise ValueError("fit_profile: speed_noise must be a number > 0 [m/s] or a pair (absolute "
                     "[m/s] > 0, relative to the speed in [0, 1)), e.g. the default "
                     f"{DEFAULT_SPEED_NOISE}; got {speed_noise!r}")


def checked_data(name, value, shape=None):
    array = real_array(name, value, "real numbers (NaN: missing)")
    if shape is not None and array.shape != shape:
        raise ValueError(f"fit_profile: {name} must have the shape of speeds {shape}; got "
                         f"{array.shape}")
    require_at(~np.isinf(array), name, "finite (NaN: missing)", array)
    return array


class FitData(NamedTuple):
    """The profile fit's data and fixed inputs as checked (`checked_fit_data`)."""

    #: [m] (n_records, n_heights)
    heights: np.ndarray
    #: [m/s] (n_records, n_heights), NaN missing
    speeds: np.ndarray
    #: [deg] (n_records, n_heights) or None
    directions: np.ndarray | None
    #: one record given as 1-D data
    single: bool
    labels: list
    #: a number [m/s] or (absolute [m/s], relative)
    speed_noise: float | tuple
    #: the fixed EkmanABL inputs but the roughness length: numbers or one per record
    fixed: dict
    #: [m] the roughness length (the starting value where fitted)
    z0: np.ndarray
    #: (heights, values, relative noise) of a measured turbulence intensity, or None
    turbulence: tuple | None
    #: per record: the speeds measured, the unknowns, the data (speeds, direction changes, I_u)
    valid_speeds: np.ndarray
    n_unknowns: int
    observations: np.ndarray


def checked_fit_data(abl_class, heights, speeds, directions, *, labels, speed_noise,
                     direction_noise, refusal_probability, direction_model_error, on_misfit,
                     fit_roughness, fit_mixed_layer_height, max_iterations, chunk_size,
                     turbulence_intensity, turbulence_noise, fixed_inputs) -> FitData:
    """``fit_profile``'s data, options and fixed inputs checked (ValueError naming what is
    wrong, the record and the value) and shaped as the fit takes them."""
    speeds = checked_data("speeds", speeds)
    single = speeds.ndim == 1
    speeds = np.atleast_2d(speeds)
    if speeds.ndim != 2:
        raise ValueError(f"fit_profile: speeds must be (n_records, n_heights) or (n_heights,); "
                         f"got shape {speeds.shape}")
    n, m = speeds.shape
    if n == 0 or m == 0:
        raise ValueError(f"fit_profile: speeds hold no records (shape {speeds.shape}); give "
                         "(n_records, n_heights) with at least one record and one height")
    if (isinstance(max_iterations, bool) or not isinstance(max_iterations, (int, np.integer))
            or max_iterations < 1):
        raise ValueError(f"fit_profile: max_iterations must be an integer >= 1; got "
                         f"{max_iterations!r}")
    if (isinstance(chunk_size, bool) or not isinstance(chunk_size, (int, np.integer))
            or chunk_size < 1):
        raise ValueError(f"fit_profile: chunk_size must be an integer >= 1; got {chunk_size!r}")
    heights = real_array("heights", heights, "> 0 m")
    require_at(np.isfinite(heights) & (heights > 0), "heights", "finite and > 0 m", heights)
    if heights.shape not in ((m,), (n, m)):
        raise ValueError(f"fit_profile: heights must be (n_heights,) = ({m},) or (n_records, "
                         f"n_heights) = ({n}, {m}); got shape {heights.shape}")
    heights = np.broadcast_to(heights, (n, m)).astype(float)
    if directions is not None:
        directions = np.atleast_2d(checked_data("directions", directions,
                                                 np.shape(speeds[0] if single else speeds)))
    labels = list(range(n)) if labels is None else list(labels)
    if len(labels) != n:
        raise ValueError(f"fit_profile: labels must name the {n} records; got {len(labels)}")
    bad = ~(np.isnan(speeds) | (speeds > 0))
    if np.any(bad):
        i, j = np.argwhere(bad)[0]
        raise ValueError(
            f"fit_profile: speeds must be > 0 m/s (NaN: missing); record {labels[i]} has "
            f"{speeds[i, j]:g} m/s at {heights[i, j]:g} m"
            + (f" ({int(bad.sum()) - 1} more value(s) in {int(bad.any(axis=1).sum())} "
               "record(s))" if bad.sum() > 1 else "")
            + ": a zero reading is a calm or a stalled anemometer; give NaN (missing) there")
    if directions is not None:
        check_degrees(directions)
    speed_noise = checked_speed_noise(speed_noise)
    for name, value in (("direction_noise", direction_noise),
                        ("refusal_probability", refusal_probability)):
        upper = 1.0 if name == "refusal_probability" else np.inf
        if (isinstance(value, bool) or not np.isscalar(value) or not np.isfinite(value)
                or not 0 < value < upper):
            valid = "in (0, 1)" if name == "refusal_probability" else "> 0"
            raise ValueError(f"fit_profile: {name} must be a number {valid}; got {value!r}")
    if (isinstance(direction_model_error, bool)
            or not isinstance(direction_model_error, (int, float, np.integer, np.floating))
            or not np.isfinite(direction_model_error) or direction_model_error < 0):
        raise ValueError(f"fit_profile: direction_model_error must be a number >= 0 [deg]; got "
                         f"{direction_model_error!r}")
    if on_misfit not in ("raise", "flag"):
        raise ValueError(f"fit_profile: on_misfit must be 'raise' or 'flag'; got {on_misfit!r}")
    if not isinstance(fit_roughness, bool):
        raise ValueError(f"fit_profile: fit_roughness must be True or False; got {fit_roughness!r}")
    if not isinstance(fit_mixed_layer_height, bool):
        raise ValueError(f"fit_profile: fit_mixed_layer_height must be True or False; got "
                         f"{fit_mixed_layer_height!r}")

    given = sorted(k for k in fixed_inputs if k in STABILITY_INPUTS or k == "geostrophic_wind")
    if given:
        raise ValueError(
            f"fit_profile fits the wind and the stability; {given} cannot be fixed inputs (an "
            "atmosphere from a known wind and stability is EkmanABL.from_reference_wind(speed, "
            "height, obukhov_length=..., ...), docs/measurements.md#simpler-site-inputs)"
        )
    if "latitude" not in fixed_inputs and "coriolis_parameter" not in fixed_inputs:
        raise ValueError("fit_profile needs the site's latitude [deg] or coriolis_parameter "
                         "[1/s] as a fixed input")
    z0 = fixed_inputs.pop("roughness_length", DEFAULT_ROUGHNESS_START if fit_roughness else None)
    if z0 is None:
        raise ValueError("fit_profile needs roughness_length [m] as a fixed input (or "
                         "fit_roughness=True, where it is the starting value)")
    fixed = {}
    for k, v in fixed_inputs.items():
        array = real_array(k, v)
        if array.ndim > 1 or (array.ndim == 1 and array.size != n):
            raise ValueError(f"fit_profile: fixed input {k} must be a number or one per record "
                             f"({n}); got shape {array.shape}")
        fixed[k] = float(array) if array.ndim == 0 else array
    z0_array = real_array("roughness_length", z0, "> 0 m")
    if z0_array.ndim > 1 or (z0_array.ndim == 1 and z0_array.size != n):
        raise ValueError(f"fit_profile: roughness_length must be a number or one per record "
                         f"({n}); got shape {z0_array.shape}")
    abl_class.check_inputs(roughness_length=z0_array, **fixed)  # ranges, named as EkmanABL names them
    if not fit_roughness:
        low = heights <= np.reshape(z0_array, (-1, 1))
        require_at(~low, "heights", "> roughness_length z0", heights)

    turbulence = checked_turbulence(turbulence_intensity, turbulence_noise, n, z0_array,
                                     fit_roughness)
    valid_speeds = np.sum(np.isfinite(speeds), axis=1)
    n_unknowns = 3 if fit_roughness else 2
    observations = valid_speeds + (0 if directions is None
                                   else np.maximum(np.sum(np.isfinite(directions), axis=1) - 1, 0))
    if turbulence is not None:
        observations = observations + np.isfinite(turbulence[1])
    short = (valid_speeds < 1) | (observations < n_unknowns)
    if np.any(short):
        i = int(np.argmax(short))
        raise ValueError(
            f"fit_profile: record {labels[i]} has {valid_speeds[i]} speeds and "
            f"{observations[i] - valid_speeds[i]} direction changes; the fit needs a speed and "
            f"{n_unknowns} data in all ({n_unknowns} unknowns)"
        )
    return FitData(heights, speeds, directions, single, labels, speed_noise, fixed, z0_array,
                   turbulence, valid_speeds, n_unknowns, observations)
