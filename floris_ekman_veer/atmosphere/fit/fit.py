"""The atmosphere from measured wind profiles: a least-squares fit of the Ekman-surface-layer
model to mast or lidar records (docs/measurements.md).

Data: per record (10-minute mean, say) wind speeds [m/s] and meteorological wind directions [deg,
where the wind comes from, clockwise from north] at a few heights. Unknowns (docs/measurements.md#unknowns):

* the friction velocity u*, equivalently the geostrophic wind G, which the drag law (Eq. GDL)
  makes explicit in u* for a given stability;
* one stability input, the inverse Obukhov length 1/L >= 0 (mu = u*/(kappa f L), 0 neutral):
  L rather than mu because the surface-layer shape U/u* = (ln(z/z0) + 5 z/L)/kappa depends on
  1/L alone, which keeps the two unknowns nearly independent;
* optionally (``fit_roughness=True``) the roughness length z0; otherwise z0 is a site input;
* in a convective fit without a given ``mixed_layer_height``, the mixed-layer depth z_i where the
  data reach it (a measurement at or above it, its top shown) and the default cannot follow
  them; elsewhere its default (docs/measurements.md#mixed-layer-depth);
* the wind direction is a free rotation (the direction of the surface stress): only the
  direction *change* between heights constrains the physics. It is eliminated in closed form
  (the weighted mean of the measured-minus-model directions) at every evaluation.

Latitude (or f_c), the free-atmosphere stratification and the model constants are site inputs,
fixed. The residuals are the speed and direction misfits divided by the measurement noise
(``speed_noise``, ``direction_noise``); their root-mean-square per degree of freedom is the
record's ``misfit``, about 1 when the data are the model plus that noise.

Solver: a Levenberg-Marquardt iteration over all records at once (forward-difference Jacobians
from the model's own vectorised profile, a 2x2 or 3x3 normal system per record solved as one
stacked array; 1/L kept >= 0 by an active bound), from the best of a few starting stabilities
(L = inf, 400, 200, 100, 50, 25 m); records that have converged are frozen. No Python loop runs
over records.

Optionally a measured turbulence intensity per record (``turbulence_intensity=(height, value)``)
adds one residual, the model's I_u there against it (docs/measurements.md#measured-turbulence).

A stable fit whose ABL top lies below the highest measurement is kept only where the data show
that top (a speed maximum, or the shear or the veer stopping at it); otherwise it is refused as
"no top" (docs/measurements.md#a-top-the-data-show).

Refusal: a record whose best fit misses the data by more than the model plus the stated noise
would with probability ``refusal_probability`` (1e-6; a chi-square test) fits no atmosphere of
the model. The test widens the direction variance by ``direction_model_error`` (1 deg: the
model's turning is that of a horizontally homogeneous Ekman layer, a few degrees of thermal-wind
turning across a mast are not in it, docs/measurements.md#direction-model-error); the fit itself
weighs the directions by their measurement noise alone (directions backing with height in the northern
hemisphere, speeds falling from the lowest height, a profile kinked beyond the model's...):
ValueError naming the record and what in its data the model cannot follow, unless
``on_misfit="flag"``, which keeps the fits and marks them in ``ProfileFit.fits``.

This module imports no FLORIS and not the ABL module either: ``EkmanABL.fit_profile`` passes its
class in, and the fit works on its public solver interface (docs/atmosphere.md#the-solvers-interface).
The fit's parts: its options' checks (`atmosphere.fit_inputs`), the noise model and residuals
(`atmosphere.fit_residuals`), the model at the data (`atmosphere.fit_model`), the iteration
(`atmosphere.least_squares`) and its starts (`atmosphere.multistart`), the refusals' reasons
(`atmosphere.misfit`) and the result (`atmosphere.fit_result`).
"""

from __future__ import annotations

import contextvars

import attrs
import numpy as np

from floris_ekman_veer.atmosphere import stability_closures
from floris_ekman_veer.atmosphere.fit.fit_inputs import (
    DEFAULT_CHUNK_SIZE,
    DEFAULT_REFUSAL_PROBABILITY,
    DEFAULT_TURBULENCE_NOISE,
    STABILITY_CHOICES,
    at_direction_heights,
    check_option_names,
    checked_fit_data,
    require_distinct_heights,
    warn_if_radians,
)
from floris_ekman_veer.atmosphere.fit.fit_model import ProfileModel
from floris_ekman_veer.atmosphere.fit.fit_residuals import (
    DEFAULT_DIRECTION_MODEL_ERROR,
    DEFAULT_DIRECTION_NOISE,
    DEFAULT_SPEED_NOISE,
    noise_text,
)
from floris_ekman_veer.atmosphere.fit.fit_result import ProfileFit, stability_class
from floris_ekman_veer.atmosphere.fit.least_squares import covariance
from floris_ekman_veer.atmosphere.fit.misfit import CALM_SPEED, hidden_top, misfit_error
from floris_ekman_veer.atmosphere.fit.multistart import fit_mixed_layer, multistart, restart_misfits

#: True inside the two fits of one ``stability="either"`` fit (which warns once, on its own).
_ONE_OF_TWO_SIGNS = contextvars.ContextVar("one_of_two_signs", default=False)


def fit_profile(abl_class, heights, speeds, directions=None, *,
                speed_noise=DEFAULT_SPEED_NOISE, direction_noise=DEFAULT_DIRECTION_NOISE,
                fit_roughness=False, refusal_probability=DEFAULT_REFUSAL_PROBABILITY,
                on_misfit="raise", labels=None, max_iterations=100, stability="either",
                chunk_size=DEFAULT_CHUNK_SIZE, turbulence_intensity=None,
                turbulence_noise=DEFAULT_TURBULENCE_NOISE,
                direction_model_error=DEFAULT_DIRECTION_MODEL_ERROR, fit_mixed_layer_height=True,
                direction_heights=None, **fixed_inputs):
    """The atmosphere whose profile best fits measured speeds and directions (module docstring);
    ``EkmanABL.fit_profile`` is this with its class.

    Args:
        heights: [m] (n_heights,) shared by all records, or (n_records, n_heights); > z0.
        speeds: [m/s] (n_records, n_heights), or (n_heights,) for one record; > 0, NaN missing.
        directions: [deg] meteorological, same shape (NaN missing), or None (speeds only);
            with ``direction_heights``, (n_records, n_direction_heights) (or
            (n_direction_heights,) for one record).
        direction_heights: [m] the heights of the directions where the vanes are not at the
            cups' heights (the usual mast: vanes a few metres below the cups), (n_dir,) shared
            or (n_records, n_dir); each direction is fitted at its own height (the model's
            flow angle there), no interpolation. None: the directions are at ``heights``.
            ``ProfileFit.heights`` then holds the heights of both, the speeds NaN at a
            direction's height and the directions NaN at a speed's.
        speed_noise: the noise of a measured speed weighting its residual: a number [m/s], or
            (absolute [m/s], relative): sqrt(absolute^2 + (relative U)^2) at a measured speed U;
            default (0.1 m/s, 0.02), the noise model of 10-minute cup means
            (docs/measurements.md#noise-model).
        direction_noise: the noise of a measured direction [deg], default 1 (a vane whose
            offset is removed, docs/measurements.md#noise-model).
        fit_roughness: fit z0 too (``roughness_length`` is then the starting value).
        refusal_probability: a record whose sum of squared normalised residuals chi^2 exceeds
            the chi-square quantile of this upper-tail probability (degrees of freedom: data
            minus unknowns) fits no atmosphere of the model: with dof = 11 (7 heights, speeds
            and directions) that is a ``refusal_misfit`` above 2.11, with dof = 1 above 4.9.
        direction_model_error: [deg] >= 0, default 1: added in variance to
            ``direction_noise`` in that test only (not in the fit's weights): the model's
            turning with height is the Ekman layer's, and a measured one differs by a few
            degrees of thermal-wind turning either way, veering or backing
            (docs/measurements.md#direction-model-error); 0 tests against the noise alone.
        on_misfit: ``"raise"`` (ValueError naming the first such record) or ``"flag"``.
        labels: a name per record for messages (e.g. time stamps); default its index.
        max_iterations: of the Levenberg-Marquardt iteration.
        stability: the sign of 1/L fitted: ``"either"`` (the default: both signs, each record
            taking the one whose fit misses its data less, ``ProfileFit.stability_class`` says
            which: a site's days and nights alike), ``"stable"`` (1/L >= 0: stable or neutral
            only) or ``"convective"`` (1/L <= 0: the convective layer of
            docs/atmosphere.md#convective-boundary-layer, its mixed-layer depth a fixed
            ``mixed_layer_height``, else fitted where the data reach it and the default
            elsewhere).
        turbulence_intensity: a measured streamwise turbulence intensity sigma_u/U (or
            sigma_u divided by the measured speed at its height): ``(height, value)``, each a
            number or one per record (NaN: none for that record); an extra residual, the
            model's I_u at that height (Eq. Iu_model) against it, which constrains u* and the
            stability (docs/measurements.md#measured-turbulence).
        turbulence_noise: its noise relative to its value (default 0.1).
        fit_mixed_layer_height: (convective fits without a given ``mixed_layer_height``) fit
            the mixed-layer depth z_i too where the data reach it: for records whose default-z_i
            fit is refused, z_i at or below the highest measurement, the data showing that top
            and telling it from the default; elsewhere
            z_i keeps its default (``ProfileFit.mixed_layer_height_fitted`` says which,
            docs/measurements.md#mixed-layer-depth). False: the default everywhere.
        chunk_size: records iterated together (bounds the memory; the fits do not depend on
            it: each record's iteration is its own).
        **fixed_inputs: EkmanABL inputs other than the wind and the stability: ``latitude`` or
            ``coriolis_parameter`` (required), ``roughness_length`` (required unless fitted),
            ``brunt_vaisala_frequency`` or ``lapse_rate``, ``reference_potential_temperature``,
            model constants; numbers or arrays of one per record.

    Returns:
        The fitted EkmanABL, shape (n_records,) (scalar for 1-D data), with ``profile_fit``: the
        :class:`ProfileFit` (unknowns, direction offset, residuals per record).
    """
    check_option_names(abl_class, fixed_inputs)
    require_distinct_heights("heights", heights)
    if direction_heights is not None:
        require_distinct_heights("direction_heights", direction_heights)
        heights, speeds, directions = at_direction_heights(heights, speeds, directions,
                                                            direction_heights)
    if stability not in STABILITY_CHOICES:
        raise ValueError(f"fit_profile: stability must be one of {list(STABILITY_CHOICES)}; got "
                         f"{stability!r}")
    if on_misfit not in ("raise", "flag"):
        raise ValueError(f"fit_profile: on_misfit must be 'raise' or 'flag'; got {on_misfit!r}")
    if stability == "either":
        return _fit_either_sign(
            abl_class, heights, speeds, directions, speed_noise=speed_noise,
            direction_noise=direction_noise, fit_roughness=fit_roughness,
            refusal_probability=refusal_probability, on_misfit=on_misfit, labels=labels,
            max_iterations=max_iterations, chunk_size=chunk_size,
            turbulence_intensity=turbulence_intensity, turbulence_noise=turbulence_noise,
            direction_model_error=direction_model_error,
            fit_mixed_layer_height=fit_mixed_layer_height, **fixed_inputs)
    data = checked_fit_data(
        abl_class, heights, speeds, directions, labels=labels, speed_noise=speed_noise,
        direction_noise=direction_noise, refusal_probability=refusal_probability,
        direction_model_error=direction_model_error, on_misfit=on_misfit,
        fit_roughness=fit_roughness, fit_mixed_layer_height=fit_mixed_layer_height,
        max_iterations=max_iterations, chunk_size=chunk_size,
        turbulence_intensity=turbulence_intensity, turbulence_noise=turbulence_noise,
        fixed_inputs=fixed_inputs)
    heights, speeds, directions, single, labels, speed_noise = (
        data.heights, data.speeds, data.directions, data.single, data.labels, data.speed_noise)
    fixed, z0_array, turbulence = data.fixed, data.z0, data.turbulence
    valid_speeds, n_unknowns, observations = data.valid_speeds, data.n_unknowns, data.observations
    n, m = speeds.shape

    sign = -1.0 if stability == "convective" else 1.0
    # z_i an unknown of convective fits where not given (docs/measurements.md#mixed-layer-depth)
    zi_stage = sign < 0 and fit_mixed_layer_height and "mixed_layer_height" not in fixed
    model = ProfileModel(abl_class, heights, speeds, directions, fixed, z0_array, fit_roughness,
                          speed_noise, float(direction_noise), sign, turbulence)
    from scipy.stats import chi2

    dof = np.maximum(observations - n_unknowns, 1)
    misfit_tolerance = np.sqrt(chi2.isf(refusal_probability, dof) / dof)
    # The iteration in chunks of records: its work arrays (records x starts x unknowns x data)
    # stay bounded, whatever the number of records.
    parts = []
    for chunk in np.array_split(np.arange(n), -(-n // chunk_size)):
        def part_model(fit_mixed_layer=False, chunk=chunk):
            return ProfileModel(
                abl_class, heights[chunk], speeds[chunk],
                None if directions is None else directions[chunk],
                {k: (v if np.ndim(v) == 0 else v[chunk]) for k, v in fixed.items()},
                z0_array if z0_array.ndim == 0 else z0_array[chunk], fit_roughness,
                speed_noise, float(direction_noise), sign,
                None if turbulence is None else tuple(a[chunk] for a in turbulence),
                fit_mixed_layer)
        part = model if chunk.size == n else part_model()
        result = multistart(part, chunk.size, max_iterations)
        restart_misfits(part, *result, (misfit_tolerance**2 * dof)[chunk], max_iterations)
        if zi_stage:
            result = fit_mixed_layer(part_model(True), *result,
                                      (misfit_tolerance**2 * dof)[chunk], max_iterations,
                                      float(direction_model_error))
        else:
            result = (*result, np.zeros(chunk.size, bool))
        parts.append(result)
    x, cost, converged, iterations, zi_fitted = (np.concatenate(a) for a in zip(*parts))
    index = np.arange(n)
    if np.any(zi_fitted):
        # every record's state with its z_i (fitted, or the default's own depth: the same state)
        model = ProfileModel(abl_class, heights, speeds, directions, fixed, z0_array,
                              fit_roughness, speed_noise, float(direction_noise), sign,
                              turbulence, True)
        # one unknown more where z_i is fitted
        dof = np.maximum(observations - n_unknowns - zi_fitted, 1)
        misfit_tolerance = np.sqrt(chi2.isf(refusal_probability, dof) / dof)
    else:
        x = x[:, : n_unknowns]
    g, mu, z0_fit, valid, _ = model.state(x, index)
    r, _, offset = model.residuals(x, index)
    misfit = np.where(valid, np.sqrt(cost / dof), np.inf)
    speed_rms = np.sqrt(np.sum((r[:, :m] * model.sigma_s) ** 2, axis=1) / valid_speeds)
    if directions is None:
        direction_rms = np.full(n, np.nan)
    else:
        count = np.maximum(np.sum(np.isfinite(directions), axis=1), 1)
        direction_rms = np.sqrt(np.sum(r[:, m:2 * m] ** 2, axis=1) / count) * direction_noise
    # The refusal's chi-square: the direction residuals (columns m to 2 m) with the model's
    # direction error added to their variance (docs/measurements.md#direction-model-error).
    widen = np.ones(r.shape[1])
    if directions is not None:
        widen[m:2 * m] = direction_noise**2 / (direction_noise**2 + direction_model_error**2)
    refusal_misfit = np.where(valid, np.sqrt(np.sum(r**2 * widen, axis=1) / dof), np.inf)
    fits = refusal_misfit <= misfit_tolerance
    # A calm record is refused whatever its fit: below the cups' and vanes' starting speeds
    # the readings are no profile (misfit_reason names it "calm").
    fits &= ~(np.nanmax(np.where(np.isfinite(speeds), speeds, -np.inf), axis=1) < CALM_SPEED)
    if sign > 0:
        # A stable layer shallower than the highest measurement only where the data show its
        # top (docs/measurements.md#a-top-the-data-show).
        _, _, _, _, depth = model.state(x, index)
        # (a veer stopping is a top only beyond the directions' model error too)
        fits &= ~(valid & hidden_top(heights, speeds, directions, depth, model.sigma_record,
                                      float(np.hypot(direction_noise, direction_model_error))))
    # where a refused fit lies on a bound of the physical domain: the bound that binds
    bound = np.full(n, "", dtype=object)
    refused = np.flatnonzero(~fits & valid)
    if refused.size:
        bound[refused] = model.bound(x[refused], refused)
    if on_misfit == "raise" and not np.all(fits):
        raise misfit_error(np.flatnonzero(~fits), labels, heights, speeds, directions,
                            speed_rms, direction_rms, refusal_misfit, model, misfit_tolerance,
                            float(refusal_probability), depth if sign > 0 else None,
                            float(direction_model_error), bound)

    g = np.where(valid, g, np.nan)
    safe = valid | (on_misfit == "raise")
    shape = (lambda a: a[0]) if single else (lambda a: a)
    fitted_depth = {}
    if np.any(zi_fitted):
        # (a stable, neutral or stand-in record's z_i is never read)
        fitted_depth["mixed_layer_height"] = shape(np.where(safe & valid, np.exp(x[:, -1]),
                                                            1000.0))
    abl = abl_class(
        geostrophic_wind=shape(np.where(safe, g, 10.0)),
        stability_parameter=shape(np.where(safe, mu, 0.0)),
        roughness_length=shape(z0_fit) if fit_roughness or z0_array.ndim else float(z0_array),
        **({k: shape(v) if np.ndim(v) else v for k, v in fixed.items()}), **fitted_depth,
    )
    convective = np.reshape(np.asarray(abl.stability_parameter), -1) < 0
    mixed_layer = np.where(convective & valid,
                           np.reshape(np.asarray(abl.boundary_layer_height), -1), np.nan)
    u_star = np.exp(x[:, 0])
    obukhov = np.where(mu != 0, stability_closures.obukhov_length(u_star, model.f, mu, model.kappa),
                       np.inf)
    fit = ProfileFit(
        abl=abl, heights=heights, speeds=speeds, directions=directions,
        fitted=("friction_velocity", "obukhov_length") + (("roughness_length",) if fit_roughness else ()),
        friction_velocity=shape(u_star), geostrophic_wind=shape(g), obukhov_length=shape(obukhov),
        stability_parameter=shape(mu), roughness_length=shape(np.broadcast_to(z0_fit, (n,))),
        boundary_layer_height=np.asarray(abl.boundary_layer_height),
        direction_offset=shape(np.mod(offset, 360.0)), speed_residual=shape(speed_rms),
        direction_residual=shape(direction_rms), misfit=shape(misfit), fits=shape(fits),
        iterations=shape(iterations), converged=shape(converged), labels=labels,
        fixed_inputs={k: (v if np.ndim(v) == 0 else shape(v)) for k, v in fixed.items()}
        | ({} if fit_roughness else {"roughness_length": z0_array[()]}),
        speed_noise=speed_noise, direction_noise=float(direction_noise), single=single,
        stability_class=shape(stability_class(obukhov)),
        misfit_tolerance=shape(misfit_tolerance), refusal_misfit=shape(refusal_misfit),
        direction_model_error=float(direction_model_error),
        mixed_layer_height=shape(mixed_layer), mixed_layer_height_fitted=shape(zi_fitted),
        covariance=shape(covariance(model, x, valid,
                                     zi_fitted if model.fit_mixed_layer else None)),
        stability=stability, bound=shape(bound),
    )
    abl.profile_fit = fit
    if not _ONE_OF_TWO_SIGNS.get():
        warn_if_radians(fit)
    return abl


def _fit_either_sign(abl_class, heights, speeds, directions, *, on_misfit, labels, **options):
    """``fit_profile(stability="either")``: the stable and the convective fits of every record,
    each record keeping the one with the smaller misfit; refused (``on_misfit="raise"``) where
    neither passes the chi-square test, the message naming both misfits."""
    inner = _ONE_OF_TWO_SIGNS.set(True)
    try:
        fits = [
            fit_profile(abl_class, heights, speeds, directions, on_misfit="flag", labels=labels,
                        stability=sign, **options).profile_fit
            for sign in ("stable", "convective")
        ]
    finally:
        _ONE_OF_TWO_SIGNS.reset(inner)
    stable, convective = fits
    passes_s, passes_c = np.asarray(stable.fits), np.asarray(convective.fits)
    # Convective where it misses the data less; among equally good fits (data that do not tell
    # the signs apart, e.g. two speeds for two unknowns, both met to round-off) the stable or
    # neutral one, the paper's classes, whatever the round-off of the two iterations.
    m_s, m_c = np.asarray(stable.misfit), np.asarray(convective.misfit)
    better = m_c < m_s * (1.0 - 1e-6) - 1e-6
    take = np.where(passes_s == passes_c, better, passes_c)
    chosen = {}
    for field in attrs.fields(ProfileFit):
        a, b = getattr(stable, field.name), getattr(convective, field.name)
        if field.name in ("abl", "heights", "speeds", "directions", "labels", "fixed_inputs",
                          "speed_noise", "direction_noise", "single", "fitted",
                          "direction_model_error"):
            chosen[field.name] = a
        elif field.name == "stability":
            chosen[field.name] = "either"
        elif field.name == "covariance":
            # the stable fit has no z_i unknown: its row and column 0
            a, b = np.reshape(a, (len(stable.labels), *np.shape(a)[-2:])), np.reshape(
                b, (len(stable.labels), *np.shape(b)[-2:]))
            if b.shape[-1] > a.shape[-1]:
                a = np.pad(a, ((0, 0), (0, 1), (0, 1)))
            merged = np.where(np.reshape(take, (-1, 1, 1)), b, a)
            chosen[field.name] = merged[0] if stable.single else merged
        else:
            chosen[field.name] = np.where(take, b, a)[()]
    fit = ProfileFit(**chosen)
    passes = np.atleast_1d(fit.fits)
    if on_misfit == "raise" and not np.all(passes):
        i = int(np.argmin(passes))
        raise ValueError(
            f"fit_profile: record {fit.labels[i]} fits no atmosphere of the model, stable or "
            f"convective: misfit {np.atleast_1d(stable.refusal_misfit)[i]:.3g} stable, "
            f"{np.atleast_1d(convective.refusal_misfit)[i]:.3g} convective, about 1 for the "
            f"model plus the stated noise (speed_noise={noise_text(fit.speed_noise)}"
            + ("" if fit.directions is None else
               f", direction_noise={fit.direction_noise:g} deg with direction_model_error="
               f"{fit.direction_model_error:g} deg")
            + f"; refused above {np.atleast_1d(stable.misfit_tolerance)[i]:.3g}, "
            f"refusal_probability={options['refusal_probability']:g}; {np.sum(~passes)} "
            f"record(s) refused): {fit.reason(i)[1]}. Give on_misfit='flag' to keep the fits "
            "and read profile_fit.fits"
        )
    mu = np.asarray(fit.stability_parameter, float)
    valid = np.isfinite(np.asarray(fit.geostrophic_wind, float))
    fixed = {k: v for k, v in fit.fixed_inputs.items()}
    fixed.update(fit.fitted_depth())
    abl = abl_class(
        geostrophic_wind=np.where(valid, fit.geostrophic_wind, 10.0)[()],
        stability_parameter=np.where(valid, mu, 0.0)[()],
        **fixed,
        **({"roughness_length": fit.roughness_length} if "roughness_length" in fit.fitted else {}),
    )
    fit.abl = abl
    fit.boundary_layer_height = np.asarray(abl.boundary_layer_height)
    abl.profile_fit = fit
    warn_if_radians(fit)
    return abl
