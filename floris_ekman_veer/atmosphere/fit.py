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
class in (imports point one way, docs/coupling.md#registry).
"""

from __future__ import annotations

import contextvars
import difflib
import importlib
import inspect

import attrs
import numpy as np

from floris_ekman_veer.atmosphere.stability_inputs import STABILITY_INPUTS
from floris_ekman_veer._validation import real_array, require_at
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
#: Default noise of a 10-minute mean speed (docs/measurements.md#noise-model): (absolute [m/s],
#: relative to the speed), sigma_U = sqrt(0.1^2 + (0.02 U)^2): the cup's calibration (about
#: 0.05 m/s + 0.5 %) and operational class (1.7/sqrt(3) = 1.0 %, IEC 61400-12-1 class 1.7A),
#: its mounting on a boom (0.5-1 %, IEC 61400-12-1 Annex G), the part of the 10-minute mean's
#: sampling error not shared by the heights (about 1.3 %), and the model's own error in a
#: profile's shape (1 %), in quadrature; 0.1 m/s of resolution and starting threshold below.
DEFAULT_SPEED_NOISE = (0.1, 0.02)
#: Default noise of a 10-minute mean direction [deg]: the vane's resolution (1.4 deg steps,
#: sigma 0.4 deg), its alignment after a boom survey or the offsets estimated from the records
#: (about 0.7 deg), the 10-minute mean's sampling (about 0.5 deg), in quadrature about 1 deg
#: (docs/measurements.md#noise-model). A vane offset not removed is a few degrees: remove it
#: first or state it here.
DEFAULT_DIRECTION_NOISE = 1.0
#: Default model error of the directions [deg], added in variance to ``direction_noise`` in the
#: chi-square refusal only (docs/measurements.md#direction-model-error): a neutral layer with 5 deg
#: of thermal-wind turning between 30 and 150 m is accepted at 0.5 deg of vane noise.
DEFAULT_DIRECTION_MODEL_ERROR = 1.0
#: A record is refused (or flagged) when the model plus the stated noise would give a misfit as
#: large as its best fit's with a probability below this (chi-square test of its residuals).
DEFAULT_REFUSAL_PROBABILITY = 1e-6
#: Starting Obukhov lengths [m] of the multi-start (inf: neutral).
STARTING_OBUKHOV_LENGTHS = (np.inf, 400.0, 200.0, 100.0, 50.0, 25.0)
#: Starting Obukhov lengths [m] of the second, dense start of records the first one leaves
#: refused: 40 from 10 m to 2 km, geometric.
RESTART_OBUKHOV_LENGTHS = tuple(np.geomspace(10.0, 2000.0, 40))
#: Factors on the best end point's 1/L of the restarts across the profile's step near h.
_POLISH_FACTORS = (0.9, 0.97, 1.03, 1.1)
#: ... for records whose fitted ABL top is below this times their highest measurement.
_POLISH_HEIGHT_RATIO = 1.2
#: A state whose chi-square exceeds the fit's by at most this lies in the fit's two-sigma
#: confidence region (one parameter): the data cannot tell it from the fit.
CONFIDENCE_CHI_SQUARE = 4.0
#: Default starting roughness length [m] when it is fitted and none is given.
DEFAULT_ROUGHNESS_START = 0.05
#: Scale of the stability unknown: lam = _LENGTH_SCALE / L.
_LENGTH_SCALE = 100.0
#: The relative slack a fitted state keeps inside the physical domain's bounds
#: (`DomainCheck.margin`): far above the round-off of the ABL re-solved from its G.
_DOMAIN_MARGIN = 1e-9
_JACOBIAN_STEP = 1e-7
_STEP_TOLERANCE = 1e-10


@attrs.define(eq=False)
class ProfileFit:
    """What :func:`fit_profile` found, per record (arrays of shape ``(n_records,)``; scalars for
    one record given as 1-D data).

    Attributes:
        abl: The fitted EkmanABL (the same object whose ``profile_fit`` this is).
        heights, speeds, directions: The data as fitted, ``(n_records, n_heights)`` (NaN:
            missing; directions None when not given).
        fitted: Names of the unknowns: ``("friction_velocity", "obukhov_length")`` and
            ``"roughness_length"`` when fitted.
        friction_velocity [m/s], geostrophic_wind [m/s], obukhov_length [m] (inf: neutral),
        stability_parameter mu, roughness_length [m], boundary_layer_height [m].
        direction_offset: [deg] the free rotation: the model's meteorological direction is
            ``direction_offset - abl.wind_angle(z)`` (see :meth:`direction`).
        speed_residual: rms of model minus measured speed [m/s].
        direction_residual: rms of the direction misfit [deg] (NaN without directions).
        misfit: rms normalised residual per degree of freedom (about 1 for the model plus the
            stated noise).
        fits: the record passes the chi-square test of ``refusal_probability``: its
            ``refusal_misfit`` at most ``misfit_tolerance``.
        refusal_misfit: ``misfit`` with the direction residuals normalised by
            sqrt(direction_noise^2 + direction_model_error^2) (equal to it without directions or
            with ``direction_model_error=0``).
        iterations, converged: of the Levenberg-Marquardt iteration.
        labels: Record names used in messages (index by default).
        fixed_inputs: The fixed EkmanABL inputs as given.
        stability_class: "convective" (-500 m <= L < 0), "neutral" (|L| > 500 m, Gryning et al.
            2007's neutral class) or "stable" (0 < L <= 500 m); with ``stability="either"`` L
            takes the sign whose fit misses the data less.
        mixed_layer_height [m], mixed_layer_height_fitted: a convective record's z_i (NaN
            otherwise) and whether the fit determined it: only where the data reach it (at or
            below the highest measurement, its top shown); elsewhere the given
            ``mixed_layer_height`` or the default, the neutral height of Eq. (h_hat_model)
            (docs/measurements.md#mixed-layer-depth).
    """

    abl: object
    heights: np.ndarray
    speeds: np.ndarray
    directions: np.ndarray | None
    fitted: tuple
    friction_velocity: np.ndarray
    geostrophic_wind: np.ndarray
    obukhov_length: np.ndarray
    stability_parameter: np.ndarray
    roughness_length: np.ndarray
    boundary_layer_height: np.ndarray
    direction_offset: np.ndarray
    speed_residual: np.ndarray
    direction_residual: np.ndarray
    misfit: np.ndarray
    fits: np.ndarray
    iterations: np.ndarray
    converged: np.ndarray
    labels: list
    fixed_inputs: dict
    speed_noise: float
    direction_noise: float
    single: bool
    #: "convective", "neutral" or "stable" per record (`_stability_class` of the fitted L).
    stability_class: np.ndarray | str | None = None
    #: The refusal threshold of ``refusal_misfit`` per record (the chi-square test).
    misfit_tolerance: np.ndarray | float = np.inf
    #: The misfit the chi-square test reads: directions with their model error added.
    refusal_misfit: np.ndarray | float | None = None
    #: [deg] the directions' model error of the refusal (docs/measurements.md#direction-model-error).
    direction_model_error: float = 0.0
    #: [m] the mixed-layer depth z_i of each convective record (NaN for stable and neutral ones):
    #: fitted where ``mixed_layer_height_fitted``, else the given or default one
    #: (docs/measurements.md#mixed-layer-depth).
    mixed_layer_height: np.ndarray | float = np.nan
    #: Whether z_i was fitted (the data reach it) or kept at its given or default value.
    mixed_layer_height_fitted: np.ndarray | bool = False
    #: (n_records, p, p) the linearised covariance of the unknowns (ln u*, 100 m/L,
    #: [ln z0], [ln z_i]) at the fit, (J^T J)^-1 of the noise-normalised residuals (the stated
    #: noise, not the misfit); z_i's row and column 0 where not fitted; NaN where no state
    #: (docs/measurements.md#how-well-the-data-pin-the-turbulence).
    covariance: np.ndarray | None = None
    #: The sign of 1/L fitted: "either" (the default), "stable" or "convective".
    stability: str = "stable"
    #: Per record, the bound of the physical domain on which its best fit lies, where that
    #: fit is refused ("" elsewhere): the data ask for a state beyond it
    #: (docs/measurements.md#physical-domain).
    bound: np.ndarray | str | None = None

    def turbulence_intensity_interval(self, height, reference_height=None):
        """(low, high): the fitted I_u at ``height`` (`EkmanABL.turbulence_intensity`) minus and
        plus two linearised standard deviations from :attr:`covariance` (the two-sigma
        confidence region of :data:`CONFIDENCE_CHI_SQUARE`), low clipped at 0. It measures
        how well the data and their stated noise pin I_u; a profile whose shape is not the
        model's (docs/measurements.md#how-well-the-data-pin-the-turbulence) can lie outside it."""
        x, sign = self._unknowns()
        z = float(height)
        ref = None if reference_height is None else float(reference_height)
        centre = self._intensity_at(x, sign, z, ref)
        p = x.shape[1]
        step = 1e-6
        # (the stability step on the fit's own side of neutral: the two sides are two models)
        trial = x[:, None, :] + step * np.eye(p)[None] * np.where(
            np.arange(p) == 1, sign[:, None], 1.0)[:, None, :]
        shifted = self._intensity_at(trial.reshape(-1, p), sign, z, ref).reshape(-1, p)
        gradient = (shifted - centre[:, None]) / step
        # (a fit on a bound of the physical domain: the backward step, inside it)
        backward = 2.0 * x[:, None, :] - trial
        behind = self._intensity_at(backward.reshape(-1, p), sign, z, ref).reshape(-1, p)
        gradient = np.where(np.isfinite(shifted), gradient, (centre[:, None] - behind) / step)
        gradient[:, 1] *= sign
        cov = np.reshape(self.covariance, (-1, p, p))
        sigma = np.sqrt(np.einsum("kp,kpq,kq->k", gradient, cov, gradient))
        shape = (lambda a: a[0]) if self.single else (lambda a: a)
        return shape(np.maximum(centre - 2.0 * sigma, 0.0)), shape(centre + 2.0 * sigma)

    def _unknowns(self):
        """(x (n, p), sign (n,)): the unknowns as :attr:`covariance` orders them, 100 m/L
        signed, and the side of neutral each fit lies on (+1 stable or neutral, -1 convective)."""
        length = np.reshape(np.asarray(self.obukhov_length, float), -1)
        columns = [np.log(np.reshape(np.asarray(self.friction_velocity, float), -1)),
                   _LENGTH_SCALE / length]
        if "roughness_length" in self.fitted:
            columns.append(np.log(np.reshape(np.asarray(self.roughness_length, float), -1)))
        if np.shape(self.covariance)[-1] > len(columns):
            z_i = np.reshape(np.asarray(self.mixed_layer_height, float), -1)
            columns.append(np.log(np.where(np.isfinite(z_i), z_i, 1000.0)))
        return np.stack(columns, axis=1), np.where(length < 0, -1.0, 1.0)

    def _intensity_at(self, x, sign, height, reference_height):
        """I_u at ``height`` of the model states x and sides of neutral ``sign`` (as
        :meth:`_unknowns`), one per row; rows are the records repeated in blocks (x.shape[0] a
        multiple of the records); NaN where a state is no model state. The states are the
        fit's own (`_ProfileModel.abl_at`)."""
        n = np.size(self.misfit)
        rows = np.repeat(np.arange(n), x.shape[0] // n)
        fit_roughness = "roughness_length" in self.fitted
        z0 = np.broadcast_to(self.fixed_inputs.get("roughness_length", self.roughness_length),
                             (n,))
        fixed = {k: v for k, v in self.fixed_inputs.items() if k != "roughness_length"}
        model = _ProfileModel(type(self.abl), np.ones((n, 1)), np.ones((n, 1)), None, fixed, z0,
                              fit_roughness, 1.0, 1.0, sign,
                              fit_mixed_layer=x.shape[1] > 2 + fit_roughness)
        unsigned = x.copy()
        unsigned[:, 1] *= sign[rows]
        abl, valid = model.abl_at(unsigned, rows)
        ref = () if reference_height is None else (reference_height,)
        intensity = np.reshape(np.asarray(abl.turbulence_intensity(height, *ref), float), -1)
        return np.where(valid, intensity, np.nan)

    def _fitted_depth(self):
        """{"mixed_layer_height": z_i per record} where some record's z_i was fitted (the
        others' z_i as they have it, given or default: the same state; a stable or neutral
        record's boundary layer height, never read), else {}."""
        if not np.any(self.mixed_layer_height_fitted):
            return {}
        z_i = np.asarray(self.mixed_layer_height, float)
        depth = np.asarray(self.boundary_layer_height, float)
        depth = np.where(np.isfinite(depth) & (depth >= 10.0), depth, 1000.0)
        return {"mixed_layer_height": np.where(np.isfinite(z_i), z_i, depth)[()]}

    def speed(self, heights):
        """Fitted speed [m/s] at ``heights`` ((n_heights,) or (n_records, n_heights)), shaped
        (n_records, n_heights)."""
        return self._per_record(self.abl.speed, heights)

    def direction(self, heights):
        """Fitted meteorological wind direction [deg, 0-360) at ``heights``, shaped as
        :meth:`speed`."""
        angle = self._per_record(self.abl.wind_angle, heights)
        return np.mod(np.reshape(self.direction_offset, (-1, 1)) - angle, 360.0)

    def _per_record(self, profile, heights):
        z = np.asarray(heights, dtype=float)
        if self.single:
            return np.atleast_2d(profile(z))
        # The fitted ABL has shape (n_records,): heights go on the leading axis.
        return np.transpose(profile(np.transpose(np.atleast_2d(z))))

    def atmosphere(self, stability_input: str = "stability_parameter",
                   reference_height=None) -> dict:
        """The fitted inputs as the ``ekman_veer.atmosphere`` block of a FLORIS input: the fixed
        inputs, the roughness length and the stability as ``stability_input`` (one of
        ``stability_parameter``, ``obukhov_length``, ``surface_heat_flux``, ``cooling_rate``);
        lists with one entry per record, plain floats for one record (YAML-safe).

        The block holds no wind: driven by the fitted speed at a reference height (FLORIS's
        wind speed, :meth:`speed`), it gives back the fitted ABL: the four stability inputs are
        the same state at that speed, but the reference-wind solve takes the deepest ABL with
        that speed (docs/atmosphere.md#reference-wind-solve), and a closure may have a second,
        deeper one (a surface heat flux does at strong stability,
        docs/measurements.md#from-the-fit-to-floris). Given ``reference_height`` [m], the block
        is solved from the fitted speed there and ValueError names the records it does not
        give back (to 1e-6 in G).
        """
        mu = np.asarray(self.stability_parameter, float)
        u_star = np.asarray(self.friction_velocity, float)
        f = np.abs(np.asarray(self.abl.coriolis_parameter, float))
        theta0 = np.asarray(self.abl.reference_potential_temperature, float)
        gravity_ratio = 9.81 / theta0
        with np.errstate(divide="ignore"):
            values = {
                "stability_parameter": mu,
                "obukhov_length": np.where(mu != 0, u_star / (self.abl.von_karman * f
                                                               * np.where(mu != 0, mu, 1.0)), np.inf),
                "surface_heat_flux": -mu * f * u_star**2 / gravity_ratio,
                # heating (mu < 0): Q0 = C_r z_i / (1 + A_e) (docs/atmosphere.md#convective-boundary-layer)
                "cooling_rate": -mu * f * u_star**2 / gravity_ratio
                / np.asarray(self.boundary_layer_height, float) * 3600.0
                * np.where(mu < 0, 1.0 + self.abl.entrainment_ratio, 1.0),
            }
        if stability_input not in values:
            raise ValueError(f"stability_input must be one of {list(values)}; got "
                             f"{stability_input!r}")
        block = dict(self.fixed_inputs) | self._fitted_depth()
        if "roughness_length" in self.fitted:
            block["roughness_length"] = self.roughness_length
        block[stability_input] = values[stability_input]
        block = {k: _yaml_value(v, self.single) for k, v in block.items()}
        if reference_height is not None:
            self._check_block(block, stability_input, reference_height)
        return block

    def given_back(self, block, reference_height):
        """Per record: does the atmosphere ``block`` (:meth:`atmosphere`), driven by the fitted
        speed at ``reference_height``, give back the fit? (bool array, and the ABL it gives.)

        It does when the reference-wind solve finds the fitted state (G to 1e-6), or, where the
        speed at that height has two states a hair apart (a fitted ABL top h next to a
        measurement height, where the profile has its kinks: h, and the direction's step at
        0.9973 h, docs/atmosphere.md#lateral-velocity-near-the-abl-top), when the state it finds
        lies in the fit's two-sigma confidence region: its chi-square on the record's data at
        most :data:`CONFIDENCE_CHI_SQUARE` above the fit's. (A second state that the data tell
        apart, e.g. the heat-flux closure's deeper one, is not given back.)
        """
        speed = self.speed(np.reshape(float(reference_height), (1,)))[:, 0]
        again = type(self.abl).from_reference_wind(speed if not self.single else speed[0],
                                                   float(reference_height), **block)
        error = np.reshape(np.abs(np.asarray(again.geostrophic_wind) / self.geostrophic_wind
                                  - 1.0), -1)
        same = error <= 1e-6
        if not np.all(same):
            other = np.flatnonzero(~same)
            chi2_again, _ = self._chi_square(again, other)
            chi2_fit, _ = self._chi_square(self.abl, other)
            same[other] = chi2_again - chi2_fit <= CONFIDENCE_CHI_SQUARE
        return same, again

    def misfit_of(self, abl, index):
        """The ``misfit`` of ``abl`` (an EkmanABL of this fit's shape) on the data of records
        ``index``, as the fit measures it."""
        chi2, dof = self._chi_square(abl, index)
        return np.sqrt(chi2 / dof)

    def _chi_square(self, abl, index):
        heights, speeds = self.heights[index], self.speeds[index]
        directions = None if self.directions is None else self.directions[index]
        if self.single:
            speed = np.atleast_2d(abl.speed(heights[0]))
            angle = np.atleast_2d(abl.wind_angle(heights[0]))
        else:
            z = np.transpose(self.heights)
            speed = np.transpose(abl.speed(z))[index]
            angle = np.transpose(abl.wind_angle(z))[index]
        r, observations, _ = _normalised_residuals(speed, angle, speeds, directions,
                                                _speed_sigma(speeds, self.speed_noise),
                                                self.direction_noise)
        depth = np.reshape(np.asarray(self.mixed_layer_height_fitted, int), -1)
        depth = np.broadcast_to(depth, np.shape(self.misfit) or (1,))[index]
        return np.sum(r**2, axis=1), np.maximum(observations - len(self.fitted) - depth, 1)

    def reason(self, i):
        """(kind, text): why record ``i`` fits no atmosphere of the model (:func:`misfit_reason`;
        for a record that fits, its kind is whatever its data look like)."""
        reason = self._data_reason(i)
        bound = "" if self.bound is None else str(np.reshape(self.bound, -1)[i])
        if bound and reason[0] == "misfit":
            # (what the data show comes first: calm, falling speeds, backing...)
            return "physical bound", (
                f"its best fit inside the model's physical domain lies on the bound of the "
                f"{bound} and misses the data (misfit "
                f"{np.reshape(self.refusal_misfit, -1)[i]:.3g}, refused above "
                f"{np.reshape(self.misfit_tolerance, -1)[i]:.3g}): the data ask for a state "
                "beyond it, one the atmosphere refuses as input "
                "(docs/measurements.md#physical-domain)")
        return reason

    def _data_reason(self, i):
        hemisphere = np.sign(np.reshape(np.broadcast_to(self.abl.coriolis_parameter,
                                                        np.shape(self.misfit)), -1)[i])
        depth = np.reshape(self.boundary_layer_height, -1)[i : i + 1]
        directions = None if self.directions is None else self.directions[i : i + 1]
        if (np.reshape(self.obukhov_length, -1)[i] > 0
                and np.reshape(self.refusal_misfit, -1)[i]
                <= np.reshape(self.misfit_tolerance, -1)[i]
                and _hidden_top(self.heights[i : i + 1], self.speeds[i : i + 1], directions,
                                depth, _record_sigma(self.speeds[i : i + 1], self.speed_noise),
                                np.hypot(self.direction_noise, self.direction_model_error))[0]):
            kind, text = "no top", _hidden_top_reason(self.heights[i], self.speeds[i],
                                                      directions, depth[0], None,
                                                      self.direction_noise)
            if self.stability == "either":
                # (the convective fit was tried too, and missed as well)
                text = text.replace('stability="either" fits convective layers too',
                                    "its convective fit misses the data too")
            return kind, text
        return misfit_reason(self.heights[i], self.speeds[i],
                             None if self.directions is None else self.directions[i],
                             _record_sigma(self.speeds[i], self.speed_noise),
                             self.direction_noise, hemisphere,
                             np.reshape(self.roughness_length, -1)[i], self.stability)

    def subset(self, index):
        """The fitted EkmanABL of records ``index`` only (shape (len(index),)), with its
        ``profile_fit``: the same fits, not re-fitted."""
        index = np.asarray(index, int)
        if self.single:
            raise ValueError("subset: this fit is of one record")
        per_record = lambda v: np.asarray(v)[index]  # noqa: E731
        fixed = {k: (v if np.ndim(v) == 0 else per_record(v)) for k, v in self.fixed_inputs.items()}
        solved = {k: v for k, v in fixed.items() if k != "roughness_length"}
        solved |= {k: per_record(v) for k, v in self._fitted_depth().items()}
        abl = type(self.abl)(
            geostrophic_wind=np.where(np.isfinite(self.geostrophic_wind), self.geostrophic_wind,
                                      10.0)[index],
            stability_parameter=np.where(np.isfinite(self.geostrophic_wind),
                                         self.stability_parameter, 0.0)[index],
            roughness_length=per_record(self.roughness_length), **solved,
        )
        values = {a.name: getattr(self, a.name) for a in attrs.fields(type(self))}
        for name, value in values.items():
            if name in ("abl", "fitted", "labels", "fixed_inputs", "speed_noise",
                        "direction_noise", "single"):
                continue
            if isinstance(value, np.ndarray) and value.ndim >= 1 and value.shape[0] == len(self.labels):
                values[name] = value[index]
        values.update(abl=abl, labels=[self.labels[i] for i in index], fixed_inputs=fixed)
        fit = type(self)(**values)
        abl.profile_fit = fit
        return abl

    def _check_block(self, block, stability_input, reference_height):
        same, again = self.given_back(block, reference_height)
        wrong = np.flatnonzero(~same)
        if wrong.size:
            speed = self.speed(np.reshape(float(reference_height), (1,)))[:, 0]
            i = int(wrong[0])
            raise ValueError(
                f"the atmosphere block with {stability_input}, driven by the fitted speed "
                f"{speed[i]:.4g} m/s at {reference_height:g} m, gives a different ABL than the "
                f"fit of record {self.labels[i]} (G {np.reshape(again.geostrophic_wind, -1)[i]:.4g}"
                f" instead of {np.reshape(self.geostrophic_wind, -1)[i]:.4g} m/s; "
                f"{wrong.size} record(s)): that closure has two states with this speed there "
                "and the reference-wind solve takes the deeper one, which does not fit the "
                "record's data; give the stability as stability_parameter or obukhov_length"
                + (f" (records {', '.join(str(self.labels[k]) for k in wrong[:5])}"
                   f"{', ...' if wrong.size > 5 else ''})" if wrong.size > 1 else "")
            )


def _yaml_value(value, single):
    array = np.asarray(value, dtype=float)
    if array.ndim == 0 or single:
        return float(array.reshape(-1)[0]) if array.size == 1 else array.reshape(-1).tolist()
    return [float(v) for v in array.reshape(-1)]


def _wrap(angle):
    """Angle difference in (-180, 180] degrees."""
    return angle - 360.0 * np.round(angle / 360.0)


def _noise_pair(speed_noise):
    """(absolute [m/s], relative) of ``speed_noise``: a number is absolute alone."""
    if np.ndim(speed_noise) == 0:
        return float(speed_noise), 0.0
    absolute, relative = speed_noise
    return float(absolute), float(relative)


def _speed_sigma(speeds, speed_noise):
    """[m/s] the noise of each measured speed, sqrt(a^2 + (r U)^2) (a where missing)."""
    absolute, relative = _noise_pair(speed_noise)
    return np.hypot(absolute, relative * np.where(np.isfinite(speeds), speeds, 0.0))


def _record_sigma(speeds, speed_noise):
    """[m/s] per record (rows of ``speeds``), the noise at its largest speed: the scale of the
    tests on what its data show (a speed maximum, a fall, a shear deficit)."""
    absolute, relative = _noise_pair(speed_noise)
    largest = np.max(np.where(np.isfinite(speeds), speeds, 0.0), axis=-1)
    return np.hypot(absolute, relative * largest)


def _noise_text(speed_noise):
    absolute, relative = _noise_pair(speed_noise)
    return (f"{absolute:g} m/s" if relative == 0 else
            f"({absolute:g} m/s, {relative:g}): {absolute:g} m/s and {100 * relative:g} % of the "
            "speed in quadrature")


class _ProfileModel:
    """The model's speeds and direction changes at the data heights for unknowns
    x = (ln u*, lam = 100 m/L, [ln z0], [ln z_i]) per record, and the normalised residuals
    (``fit_mixed_layer``: the convective mixed-layer depth z_i is the last unknown,
    docs/measurements.md#mixed-layer-depth)."""

    def __init__(self, abl_class, heights, speeds, directions, fixed, z0, fit_roughness,
                 speed_noise, direction_noise, sign=1.0, turbulence=None, fit_mixed_layer=False):
        self.cls, self.fixed, self.fit_roughness = abl_class, fixed, fit_roughness
        self.fit_mixed_layer = fit_mixed_layer
        # A measured turbulence intensity per record: (heights (n,), values (n,) NaN missing,
        # relative noise), or None (docs/measurements.md#measured-turbulence).
        self.turbulence = turbulence
        # The sign of 1/L: the unknown lam >= 0 is 100 m/|L| (convective fits: sign -1); one
        # per record where the records' signs differ (ProfileFit's states of an "either" fit).
        self.sign = np.asarray(sign, float) if np.ndim(sign) else float(sign)
        self.z, self.s, self.d = heights, speeds, directions
        # the noise of each speed ((n, m), docs/measurements.md#noise-model) and per record
        self.noise = speed_noise
        self.sigma_s = _speed_sigma(speeds, speed_noise)
        self.sigma_record = _record_sigma(speeds, speed_noise)
        self.sigma_d = direction_noise
        self.ms = np.isfinite(speeds)
        self.md = None if directions is None else np.isfinite(directions)
        n = speeds.shape[0]
        self.z0 = np.broadcast_to(z0, (n,)).astype(float)
        # A template of the fixed inputs: the drag law's coefficients are explicit in u* for
        # a given mu (the reference-wind solve's parametrisation, docs/atmosphere.md#reference-wind-solve).
        self.template = abl_class.check_inputs(
            stability_parameter=np.zeros(n), roughness_length=self.z0, **fixed
        )
        params, _ = self.template._parameters(np.nan, (n,))
        self.params = params
        self.f = params["f"]
        self.kappa = self.template.von_karman
        # The shallowest boundary layer the ABL class accepts (a state below it is no model state).
        physics = importlib.import_module(abl_class.__module__)
        self.min_depth = float(getattr(physics, "MIN_BOUNDARY_LAYER_HEIGHT", 0.0))
        self.max_mixed_layer_height = float(getattr(physics, "MAX_MIXED_LAYER_HEIGHT", np.inf))
        # The physical domain of the ABL's solved states (its module's `physical_domain`, the
        # bounds `PHYSICAL_DOMAIN`), and what the implied quantities need.
        self.physical_domain = getattr(physics, "physical_domain", None)
        self.domain_bounds = getattr(physics, "PHYSICAL_DOMAIN", {})
        self.heat_capacity = getattr(physics, "air_heat_capacity", None)
        self.gravity = float(getattr(physics, "GRAVITY", 9.81))
        self.hemisphere = np.broadcast_to(np.sign(self.template.coriolis_parameter), (n,))

    def fixed_at(self, index):
        return {k: (v if np.ndim(v) == 0 else np.asarray(v)[index]) for k, v in self.fixed.items()}

    def state(self, x, index):
        """(G, mu, z0, valid, h) for unknowns x of records ``index``."""
        # (unbound: `_DefaultDepth` evaluates through it too)
        return _ProfileModel._evaluate(self, x, index)[:5]

    def _evaluate(self, x, index):
        """(G, mu, z0, valid, h, where each state lies in the physical domain: a `DomainCheck`
        of the ABL's module, or None without one) for unknowns x of records ``index``."""
        log_u = x[:, 0]
        # (a trial step may run far: its overflow is a state the validity below discards)
        with np.errstate(all="ignore"):
            u_star = np.exp(log_u)
            z0 = np.exp(x[:, 2]) if self.fit_roughness else self.z0[index]
            sign = self.sign if np.ndim(self.sign) == 0 else self.sign[index]
            mu = sign * u_star * x[:, 1] / (_LENGTH_SCALE * self.kappa * self.f[index])
        p = {k: v[index] for k, v in self.params.items()}
        p["value"], p["z0"] = mu, z0
        with np.errstate(all="ignore"):
            if self.fit_mixed_layer:
                p["zi"] = np.exp(x[:, -1])
            _, _, h_hat, _, b, along = self.template._state(log_u, p)
            g = u_star * np.hypot(along, b) / self.kappa
            h = h_hat * u_star / p["f"]
            valid = (
                (x[:, 1] >= 0) & (along > 0) & np.isfinite(g) & np.isfinite(mu)
                # a surface layer above the roughness, with margin for the re-solve's round-off
                & (self.template.matching_fraction * h > 1.001 * z0)
                # a layer as deep as the ABL class accepts (light winds: u* -> 0, h -> 0)
                & (h >= 1.001 * self.min_depth)
            )
            if self.fit_mixed_layer:
                # z_i an input the ABL class accepts, whatever the sign the state takes
                valid &= (np.isfinite(p["zi"]) & (p["zi"] >= 1.001 * self.min_depth)
                          & (p["zi"] <= self.max_mixed_layer_height))
            # inside the physical domain of the ABL's solved states (heat flux, G, the
            # convective turning): a trial state outside it is no state the fit may reach
            # (docs/measurements.md#physical-domain)
            check = None
            if self.physical_domain is not None:
                heat_flux = (-mu * p["f"] * u_star**2 * p["theta0"] / self.gravity
                             * self.heat_capacity(p["theta0"]))
                angle = np.rad2deg(np.arctan2(-self.hemisphere[index] * b, along))
                check = self.physical_domain(heat_flux, g, angle, mu)
                # (with a margin: the ABL re-solved from G must land inside too)
                valid &= check.inside & (check.margin > _DOMAIN_MARGIN)
        return g, mu, z0, valid, h, check

    def bound(self, x, index):
        """Per state of unknowns x of records ``index``: the bound of the physical domain that
        binds, as text ("sensible heat flux 800 W/m^2"), "" where none does: the state pushed a
        little further from neutral (its 1/L times 1.02) leaves the domain across it."""
        pushed = x.copy()
        pushed[:, 1] *= 1.02
        check = self._evaluate(pushed, index)[5]
        if check is None:
            return np.full(x.shape[0], "", dtype=object)
        names = np.reshape(check.binding, -1)
        text = np.full(names.size, "", dtype=object)
        for name in set(names) - {""}:
            low, high, unit = self.domain_bounds[name]
            value = np.reshape(check.values[name], -1)
            edge = np.where(value < low, low, high)
            here = names == name
            text[here] = [f"{name.replace('_', ' ')} {e:g} {unit}" for e in edge[here]]
        return text

    def abl(self, log_u, g, mu, z0, valid, index, mixed_layer_height=None):
        """The ABLs of states (ln u*, g, mu, z0) of records ``index``, set at their known u*
        (``EkmanABL._solved_at``: G was computed from u*, the fit never solves for it again).
        A state that is no model state (``valid`` False, from :meth:`state`) is replaced by a
        neutral stand-in, G = 10 m/s, solved for those records only: one record's trial step
        never aborts the others'."""
        fixed = self.fixed_at(index)
        if mixed_layer_height is not None:
            # (a stand-in's z_i is never read: it is neutral)
            fixed["mixed_layer_height"] = np.where(valid, mixed_layer_height, 1000.0)
        if not np.all(valid):
            bad = np.flatnonzero(~valid)
            stand_in = self.cls(geostrophic_wind=10.0, stability_parameter=0.0,
                                roughness_length=np.broadcast_to(z0, valid.shape)[bad],
                                **{k: (v if np.ndim(v) == 0 else np.asarray(v)[bad])
                                   for k, v in fixed.items() if k != "mixed_layer_height"})
            log_u, g, mu = log_u.copy(), g.copy(), mu.copy()
            log_u[bad] = np.log(stand_in.friction_velocity)
            g[bad], mu[bad] = 10.0, 0.0
        return self.cls._solved_at(log_u, g, stability_parameter=mu, roughness_length=z0,
                                   **fixed)

    def abl_at(self, x, index):
        """(the ABLs of unknowns x of records ``index``, valid (k,)): :meth:`state` and
        :meth:`abl`, an invalid state evaluated at a harmless stand-in (to be discarded)."""
        g, mu, z0, valid, _ = self.state(x, index)
        z0 = np.where(valid, z0, self.z0[index] if not self.fit_roughness else 0.05)
        with np.errstate(over="ignore"):
            depth = np.exp(x[:, -1]) if self.fit_mixed_layer else None
        abl = self.abl(x[:, 0], g, mu, z0, valid, index, depth)
        return abl, valid

    def residuals(self, x, index):
        """(normalised residuals (k, n_obs), valid (k,), direction offset (k,))."""
        abl, valid = self.abl_at(x, index)
        # One evaluation of the profile gives the speeds and the flow angles.
        u, v = abl._velocity(np.transpose(self.z[index]))
        speed = np.transpose(np.hypot(u, v))
        angle = None if self.d is None else np.transpose(np.rad2deg(np.arctan2(v, u)))
        r, _, offset = _normalised_residuals(
            speed, angle, self.s[index], None if self.d is None else self.d[index],
            self.sigma_s[index], self.sigma_d, offset=True)
        if self.turbulence is not None:
            r = np.concatenate([r, _turbulence_residual(abl, self.turbulence, index)], axis=1)
        return r, valid, offset


def _turbulence_residual(abl, turbulence, index):
    """(k, 1): the model's I_u = sigma_u/U at the measured height (Eq. Iu_model, with the
    convective variance of docs/atmosphere.md#convective-turbulence) minus the measured one,
    divided by its noise; 0 where none is measured."""
    heights, values, noise = (np.asarray(a)[index] for a in turbulence)
    measured = np.isfinite(values)
    model = np.asarray(abl.turbulence_intensity(heights), float).reshape(-1)
    return np.where(measured, (model - np.where(measured, values, 0.0))
                    / (noise * np.where(measured, values, 1.0)), 0.0)[:, None]


def _normalised_residuals(speed, angle, speeds, directions, sigma_s, sigma_d, offset=False):
    """Normalised residuals (k, n_obs) of model speeds and flow angles (k, m) against measured
    speeds and directions (NaN: missing), the number of observations per record, and (with
    ``offset``) the free rotation of the directions: measured direction plus the model's flow
    angle is constant for a perfect fit; its mean is eliminated."""
    ms = np.isfinite(speeds)
    r_s = np.where(ms, (speed - np.where(ms, speeds, 0.0)) / sigma_s, 0.0)
    observations = np.sum(ms, axis=1)
    if directions is None:
        return r_s, observations, np.zeros(len(speeds))
    md = np.isfinite(directions)
    e = np.where(md, directions, 0.0) + angle
    first = np.argmax(md, axis=1)
    e_ref = e[np.arange(len(speeds)), first]
    relative = np.where(md, _wrap(e - e_ref[:, None]), 0.0)
    count = np.maximum(np.sum(md, axis=1), 1)
    mean = np.sum(relative, axis=1) / count
    r_d = np.where(md, (relative - mean[:, None]) / sigma_d, 0.0)
    observations = observations + np.maximum(np.sum(md, axis=1) - 1, 0)
    return np.concatenate([r_s, r_d], axis=1), observations, e_ref + mean


def _solve_normal(jtj, jtr, damping, x_lam, bounded):
    """LM step of stacked systems (k, p, p); where ``bounded`` the stability unknown (index 1)
    is held at its bound 0 (step -x_lam) and the others solved with it fixed."""
    p = jtj.shape[-1]
    diag = np.einsum("kii->ki", jtj)
    a = jtj + (damping[:, None] * diag + 1e-30)[:, :, None] * np.eye(p)
    rhs = -jtr
    if np.any(bounded):
        fixed_step = -x_lam
        column = a[:, :, 1].copy()
        rhs = np.where(bounded[:, None], rhs - column * fixed_step[:, None], rhs)
        a = a.copy()
        a[bounded, :, 1] = 0.0
        a[bounded, 1, :] = 0.0
        a[bounded, 1, 1] = 1.0
        rhs[bounded, 1] = fixed_step[bounded]
    return _stacked_solve(a, rhs)


def _stacked_solve(a, rhs):
    """x of a x = rhs for stacked systems (k, p, p), each record on its own: the
    minimum-norm least-squares step (pseudo-inverse) where a record's system is singular to
    round-off (a Jacobian of rank below p: e.g. a state whose speeds do not move with its
    stability, the damping spent), no step where it is not finite. One record's system never
    aborts the others' (NumPy's stacked solve raises for the whole stack)."""
    finite = np.all(np.isfinite(a), axis=(1, 2)) & np.all(np.isfinite(rhs), axis=1)
    a = np.where(finite[:, None, None], a, np.eye(a.shape[-1]))
    rhs = np.where(finite[:, None], rhs, 0.0)
    try:
        # (the stack at once where no system is singular: the usual case, and the cheapest)
        return np.linalg.solve(a, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:
        pass
    singular_values = np.linalg.svd(a, compute_uv=False)
    regular = singular_values[:, -1] > 1e-13 * singular_values[:, 0]
    x = np.zeros_like(rhs)
    if np.any(regular):
        x[regular] = np.linalg.solve(a[regular], rhs[regular][..., None])[..., 0]
    if not np.all(regular):
        x[~regular] = np.einsum("kpq,kq->kp", np.linalg.pinv(a[~regular]), rhs[~regular])
    return x


def _jacobian(model, x, r, records):
    """(k, p, m): the forward-difference Jacobian of ``model``'s normalised residuals r (k, m)
    at unknowns x (k, p) of ``records`` (k,), all unknowns and records in one evaluation; 0
    where a step leaves the model's states."""
    k, p = x.shape
    steps = _JACOBIAN_STEP * np.eye(p)[None]
    trial = (x[:, None, :] + steps).reshape(-1, p)
    rows = np.repeat(records, p)
    rt, vt, _ = model.residuals(trial, rows)
    jac = (rt - np.repeat(r, p, axis=0)) / _JACOBIAN_STEP
    # A state on a bound of the physical domain (or next to a collapse): its forward step
    # leaves the model's states, the backward one gives the slope inside.
    out = np.flatnonzero(~vt)
    if out.size:
        back = (x[:, None, :] - steps).reshape(-1, p)[out]
        rb, vb, _ = model.residuals(back, rows[out])
        jac[out] = (np.repeat(r, p, axis=0)[out] - rb) / _JACOBIAN_STEP
        vt = vt.copy()
        vt[out] = vb
    jac = jac.reshape(k, p, -1)
    return np.where(vt.reshape(k, p)[:, :, None], jac, 0.0)


def _levenberg_marquardt(model, x, max_iterations, records):
    """LM iterations for unknowns x (k, p) of ``records`` (k,) (a record may appear with
    several starting points); converged rows are frozen."""
    n, p = x.shape
    r, valid, _ = model.residuals(x, records)
    cost = np.where(valid, np.sum(r**2, axis=1), np.inf)
    damping = np.full(n, 1e-3)
    active = valid.copy()
    converged = np.zeros(n, bool)
    iterations = np.zeros(n, int)
    for _ in range(max_iterations):
        index = np.flatnonzero(active)
        if index.size == 0:
            break
        xa, ra = x[index], r[index]
        jac = _jacobian(model, xa, ra, records[index])
        jtj = np.einsum("kpm,kqm->kpq", jac, jac)
        jtr = np.einsum("kpm,km->kp", jac, ra)
        step = _solve_normal(jtj, jtr, damping[index], xa[:, 1], np.zeros(index.size, bool))
        # The stability bound: a step below 1/L = 0 is replaced by one held on the bound.
        bounded = xa[:, 1] + step[:, 1] < 0
        if np.any(bounded):
            held = _solve_normal(jtj, jtr, damping[index], xa[:, 1], bounded)
            step = np.where(bounded[:, None], held, step)
        x_new = xa + step
        x_new[:, 1] = np.maximum(x_new[:, 1], 0.0)
        r_new, v_new, _ = model.residuals(x_new, records[index])
        cost_new = np.where(v_new, np.sum(r_new**2, axis=1), np.inf)
        accept = cost_new <= cost[index]
        iterations[index] += 1
        small = np.max(np.abs(step), axis=1) < _STEP_TOLERANCE
        flat = accept & (cost[index] - cost_new <= 1e-14 * np.maximum(cost[index], 1e-300))
        x[index] = np.where(accept[:, None], x_new, xa)
        r[index] = np.where(accept[:, None], r_new, ra)
        cost[index] = np.where(accept, cost_new, cost[index])
        damping[index] = np.where(accept, damping[index] / 3.0, damping[index] * 4.0)
        done = (accept & (small | flat)) | (damping[index] > 1e12)
        converged[index] |= accept & (small | flat)
        active[index] = ~done
    return x, cost, converged, iterations


def _check_option_names(abl_class, fixed_inputs):
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
#: True inside the two fits of one ``stability="either"`` fit (which warns once, on its own).
_ONE_OF_TWO_SIGNS = contextvars.ContextVar("one_of_two_signs", default=False)


def _warn_if_radians(fit):
    """:class:`DirectionUnitsWarning`, once, naming the records whose directions all lie within
    0 to 2 pi and turn by less than :data:`RADIANS_VEER` between their vanes: a real veer of a
    few degrees and a vane's noise, given in radians, are a few hundredths of a "degree" (in
    degrees a vane's noise alone spreads them wider). Two records or more all in radians are
    refused (`_check_degrees`); a northerly wind within 6.3 deg of north, steady to 0.5 deg, is
    warned about too."""
    if fit.directions is None:
        return
    d = np.atleast_2d(fit.directions)
    measured = np.sum(np.isfinite(d), axis=1) >= 2
    within = measured & np.all(~np.isfinite(d) | ((d >= 0.0) & (d <= 2.0 * np.pi)), axis=1)
    if not np.any(within):
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


def _check_degrees(directions):
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


def _checked_turbulence(turbulence_intensity, noise, n, z0, fit_roughness):
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


def _at_direction_heights(heights, speeds, directions, direction_heights):
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


def _checked_speed_noise(speed_noise):
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


def _checked_data(name, value, shape=None):
    array = real_array(name, value, "real numbers (NaN: missing)")
    if shape is not None and array.shape != shape:
        raise ValueError(f"fit_profile: {name} must have the shape of speeds {shape}; got "
                         f"{array.shape}")
    require_at(~np.isinf(array), name, "finite (NaN: missing)", array)
    return array


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
    _check_option_names(abl_class, fixed_inputs)
    if direction_heights is not None:
        heights, speeds, directions = _at_direction_heights(heights, speeds, directions,
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
    speeds = _checked_data("speeds", speeds)
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
        directions = np.atleast_2d(_checked_data("directions", directions,
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
        _check_degrees(directions)
    speed_noise = _checked_speed_noise(speed_noise)
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

    turbulence = _checked_turbulence(turbulence_intensity, turbulence_noise, n, z0_array,
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

    sign = -1.0 if stability == "convective" else 1.0
    # z_i an unknown of convective fits where not given (docs/measurements.md#mixed-layer-depth)
    zi_stage = sign < 0 and fit_mixed_layer_height and "mixed_layer_height" not in fixed
    model = _ProfileModel(abl_class, heights, speeds, directions, fixed, z0_array, fit_roughness,
                          speed_noise, float(direction_noise), sign, turbulence)
    from scipy.stats import chi2

    dof = np.maximum(observations - n_unknowns, 1)
    misfit_tolerance = np.sqrt(chi2.isf(refusal_probability, dof) / dof)
    # The iteration in chunks of records: its work arrays (records x starts x unknowns x data)
    # stay bounded, whatever the number of records.
    parts = []
    for chunk in np.array_split(np.arange(n), -(-n // chunk_size)):
        def part_model(fit_mixed_layer=False, chunk=chunk):
            return _ProfileModel(
                abl_class, heights[chunk], speeds[chunk],
                None if directions is None else directions[chunk],
                {k: (v if np.ndim(v) == 0 else v[chunk]) for k, v in fixed.items()},
                z0_array if z0_array.ndim == 0 else z0_array[chunk], fit_roughness,
                speed_noise, float(direction_noise), sign,
                None if turbulence is None else tuple(a[chunk] for a in turbulence),
                fit_mixed_layer)
        part = model if chunk.size == n else part_model()
        result = _multistart(part, chunk.size, max_iterations)
        _restart_misfits(part, *result, (misfit_tolerance**2 * dof)[chunk], max_iterations)
        if zi_stage:
            result = _fit_mixed_layer(part_model(True), *result,
                                      (misfit_tolerance**2 * dof)[chunk], max_iterations,
                                      float(direction_model_error))
        else:
            result = (*result, np.zeros(chunk.size, bool))
        parts.append(result)
    x, cost, converged, iterations, zi_fitted = (np.concatenate(a) for a in zip(*parts))
    index = np.arange(n)
    if np.any(zi_fitted):
        # every record's state with its z_i (fitted, or the default's own depth: the same state)
        model = _ProfileModel(abl_class, heights, speeds, directions, fixed, z0_array,
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
        fits &= ~(valid & _hidden_top(heights, speeds, directions, depth, model.sigma_record,
                                      float(np.hypot(direction_noise, direction_model_error))))
    # where a refused fit lies on a bound of the physical domain: the bound that binds
    bound = np.full(n, "", dtype=object)
    refused = np.flatnonzero(~fits & valid)
    if refused.size:
        bound[refused] = model.bound(x[refused], refused)
    if on_misfit == "raise" and not np.all(fits):
        raise _misfit_error(np.flatnonzero(~fits), labels, heights, speeds, directions,
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
    kappa_f = model.kappa * model.f
    with np.errstate(divide="ignore"):
        obukhov = np.where(mu != 0, u_star / (kappa_f * np.where(mu != 0, mu, 1.0)), np.inf)
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
        stability_class=shape(_stability_class(obukhov)),
        misfit_tolerance=shape(misfit_tolerance), refusal_misfit=shape(refusal_misfit),
        direction_model_error=float(direction_model_error),
        mixed_layer_height=shape(mixed_layer), mixed_layer_height_fitted=shape(zi_fitted),
        covariance=shape(_covariance(model, x, valid,
                                     zi_fitted if model.fit_mixed_layer else None)),
        stability=stability, bound=shape(bound),
    )
    abl.profile_fit = fit
    if not _ONE_OF_TWO_SIGNS.get():
        _warn_if_radians(fit)
    return abl


#: |L| [m] above which a fit is classed neutral (Gryning et al. 2007's neutral class, |L| > 500 m).
NEUTRAL_OBUKHOV_LENGTH = 500.0


def _stability_class(obukhov_length):
    """"convective" (-500 m <= L < 0), "neutral" (|L| > 500 m) or "stable" (0 < L <= 500 m)."""
    length = np.asarray(obukhov_length, dtype=float)
    return np.where(np.abs(length) > NEUTRAL_OBUKHOV_LENGTH, "neutral",
                    np.where(length < 0, "convective", "stable"))


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
            f"model plus the stated noise (speed_noise={_noise_text(fit.speed_noise)}"
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
    fixed.update(fit._fitted_depth())
    abl = abl_class(
        geostrophic_wind=np.where(valid, fit.geostrophic_wind, 10.0)[()],
        stability_parameter=np.where(valid, mu, 0.0)[()],
        **fixed,
        **({"roughness_length": fit.roughness_length} if "roughness_length" in fit.fitted else {}),
    )
    fit.abl = abl
    fit.boundary_layer_height = np.asarray(abl.boundary_layer_height)
    abl.profile_fit = fit
    _warn_if_radians(fit)
    return abl


def _starts(model, lams):
    """Starting unknowns (n * k, p) for stabilities lam (n, k): u* from the lowest speed by the
    log-linear law U = (u*/kappa) (ln(z/z0) + 5 z/L), z0 its given (starting) value."""
    n, k = lams.shape
    rows = np.arange(n)
    lowest = np.argmin(np.where(model.ms, model.z, np.inf), axis=1)
    z1, s1 = model.z[rows, lowest][:, None], model.s[rows, lowest][:, None]
    # (convective fits start from the neutral log law: the log-linear form is the stable one)
    stable = 5.0 * z1 * lams / _LENGTH_SCALE * (model.sign > 0)
    u_star = model.kappa * s1 / (np.log(z1 / model.z0[:, None]) + stable)
    columns = [np.log(u_star), lams]
    if model.fit_roughness:
        columns.append(np.broadcast_to(np.log(model.z0)[:, None], (n, k)))
    return np.stack([np.asarray(c, float) for c in columns], axis=-1).reshape(n * k, -1)


def _best(x, cost, n, k):
    """Index (into n * k rows) of each record's best end point; among equally good ones (data
    that do not pin the state, e.g. one speed and one direction change) the weakest stability:
    a deeper boundary layer rather than one collapsed below the heights."""
    cost = cost.reshape(n, k)
    tie = cost <= np.min(cost, axis=1, keepdims=True) * (1.0 + 1e-6) + 1e-12
    best = np.argmin(np.where(tie, x.reshape(n, k, -1)[:, :, 1], np.inf), axis=1)
    return np.arange(n) * k + best


def _multistart(model, n, max_iterations):
    """Levenberg-Marquardt from each starting stability, all records and starts in one batch,
    then from a few stabilities next to the best end point; the best end point per record.

    Several starts because the objective has kinks and a step: where the ABL top h, or the
    matching height 0.2 h, crosses a measurement height the profile's slope jumps, and where
    0.9973 h does the direction steps (docs/atmosphere.md#lateral-velocity-near-the-abl-top);
    an iteration can stop there, a local minimum, while a start on the other side reaches the
    fit.
    """
    rows = np.arange(n)
    grid = np.broadcast_to(_LENGTH_SCALE / np.asarray(STARTING_OBUKHOV_LENGTHS), (n, len(STARTING_OBUKHOV_LENGTHS)))
    x, cost, converged, iterations = _levenberg_marquardt(
        model, _starts(model, grid), max_iterations, np.repeat(rows, grid.shape[1])
    )
    pick = _best(x, cost, n, grid.shape[1])
    x, cost, converged, iterations = x[pick], cost[pick], converged[pick], iterations[pick]
    # Records whose fitted ABL top lies within or just above the heights, where the step is:
    # restarts next to the end point, its 1/L times a few factors either side, with u* from
    # the log-linear law and from the end point's own state, u* moved with the stability as at
    # a fixed speed aloft (u* ~ L^-1/2 there).
    _, _, _, valid, h = model.state(x, rows)
    near_top = np.flatnonzero(valid & (x[:, 1] > 0)
                              & (h < _POLISH_HEIGHT_RATIO * np.max(model.z, axis=1)))
    if near_top.size:
        factors = np.asarray(_POLISH_FACTORS)
        m, k = near_top.size, 2 * factors.size
        best = x[near_top]
        near = np.repeat(best, factors.size, axis=0)
        near[:, 1] *= np.tile(factors, m)
        near[:, 0] += 0.5 * np.log(np.tile(factors, m))
        sub = _SubsetModel(model, near_top)
        starts = np.concatenate([
            _starts(sub, best[:, 1][:, None] * factors[None, :]).reshape(m, factors.size, -1),
            near.reshape(m, factors.size, -1),
        ], axis=1).reshape(m * k, -1)
        x2, cost2, converged2, iterations2 = _levenberg_marquardt(
            model, starts, max_iterations, np.repeat(near_top, k)
        )
        pick = _best(x2, cost2, m, k)
        better = cost2[pick] < cost[near_top] * (1.0 - 1e-6) - 1e-12
        chosen = near_top[better]
        x[chosen], cost[chosen] = x2[pick][better], cost2[pick][better]
        converged[chosen], iterations[chosen] = converged2[pick][better], iterations2[pick][better]
    return x, cost, converged, iterations


def _restart_misfits(model, x, cost, converged, iterations, refused_cost, max_iterations):
    """Records whose best end point the chi-square test would refuse start again from a dense
    set of stabilities (:data:`RESTART_OBUKHOV_LENGTHS`): in a strongly stable light wind the
    objective's valleys, between the kinks where h crosses a measurement height, are narrower
    than the multi-start's spacing. Only the refused records pay for it; in place."""
    refused = np.flatnonzero(~(cost <= refused_cost))
    if refused.size == 0:
        return
    sub = _SubsetModel(model, refused)
    lams = _LENGTH_SCALE / np.asarray(RESTART_OBUKHOV_LENGTHS)
    k = lams.size
    x2, cost2, converged2, iterations2 = _levenberg_marquardt(
        model, _starts(sub, np.broadcast_to(lams, (refused.size, k))), max_iterations,
        np.repeat(refused, k))
    pick = _best(x2, cost2, refused.size, k)
    better = cost2[pick] < cost[refused] * (1.0 - 1e-6) - 1e-12
    chosen = refused[better]
    x[chosen], cost[chosen] = x2[pick][better], cost2[pick][better]
    converged[chosen], iterations[chosen] = converged2[pick][better], iterations2[pick][better]


#: Starting Obukhov lengths [m] of the fit of the mixed-layer depth (with the default-z_i fit's
#: own end point), each with z_i at these fractions of the record's highest measurement.
MIXED_LAYER_STARTING_LENGTHS = (400.0, 100.0, 30.0)
MIXED_LAYER_STARTING_FRACTIONS = (0.5, 0.75, 1.0)


def _covariance(model, x, valid, fitted_depth=None):
    """(n, p, p): (J^T J)^-1 of the noise-normalised residuals at the fitted unknowns x, the
    stability unknown signed (100 m/L); z_i's row and column 0 where ``fitted_depth`` is False
    (it was not an unknown there); NaN where ``valid`` is False."""
    rows = np.arange(x.shape[0])
    r0, _, _ = model.residuals(x, rows)
    # (forward steps: on the fit's own side of neutral for a fit held at 1/L = 0)
    jac = _jacobian(model, x, r0, rows)
    jac[:, 1, :] *= model.sign
    if fitted_depth is not None:
        jac[~fitted_depth, -1, :] = 0.0
    jtj = np.einsum("kpm,kqm->kpq", jac, jac)
    if fitted_depth is not None:
        jtj[~fitted_depth, -1, -1] = 1.0
    # (a record whose Jacobian is not finite has no covariance: NaN, the others unaffected)
    finite = np.all(np.isfinite(jtj), axis=(1, 2))
    valid = valid & finite
    cov = np.linalg.pinv(np.where(finite[:, None, None], jtj, np.eye(jtj.shape[-1])))
    if fitted_depth is not None:
        cov[~fitted_depth, -1, :] = 0.0
        cov[~fitted_depth, :, -1] = 0.0
    cov[~valid] = np.nan
    return cov


def _fit_mixed_layer(model, x, cost, converged, iterations, refused_cost, max_iterations,
                     model_error):
    """The convective fit with the mixed-layer depth z_i as a further unknown, for the records
    whose default-z_i fit the chi-square test would refuse (``cost`` above ``refused_cost``: the
    default depth cannot follow their data), kept per record only where the data reach z_i
    (docs/measurements.md#mixed-layer-depth): the fitted z_i at or below the highest
    measurement, the data showing that top (a speed maximum, or the shear or the veer stopping
    at it: the test of a stable top, `_hidden_top`), and the chi-square below the default-z_i
    fit's by more than :data:`CONFIDENCE_CHI_SQUARE`. ``model``: the `_ProfileModel` with
    ``fit_mixed_layer``; x, cost, ...: the default-z_i fit (2 or 3 unknowns). Returns the
    states with ln z_i appended (the default's own depth where not fitted: the same state) and
    whether fitted."""
    n = x.shape[0]
    rows = np.arange(n)
    # The default fit's depth: for a convective state its z_i, else the neutral height (unused).
    _, _, _, _, depth = _ProfileModel.state(_DefaultDepth(model), x, rows)
    base = np.concatenate([x, np.log(np.where(np.isfinite(depth) & (depth > 0), depth,
                                              1000.0))[:, None]], axis=1)
    fitted = np.zeros(n, bool)
    cost, converged, iterations = cost.copy(), converged.copy(), iterations.copy()
    candidates = np.flatnonzero(~(cost <= refused_cost))
    m = candidates.size
    if m == 0:
        return base, cost, converged, iterations, fitted
    top = np.nanmax(np.where(model.ms, model.z, np.nan), axis=1)[candidates]
    lams = np.concatenate([x[candidates, 1:2], np.broadcast_to(
        _LENGTH_SCALE / np.asarray(MIXED_LAYER_STARTING_LENGTHS), (m, len(MIXED_LAYER_STARTING_LENGTHS)))],
        axis=1)
    fractions = np.asarray(MIXED_LAYER_STARTING_FRACTIONS)
    k_l, k_f = lams.shape[1], fractions.size
    starts = _starts(_SubsetModel(model, candidates), lams).reshape(m, k_l, -1)
    # the default fit's own u* at its end point
    starts[:, 0, 0] = x[candidates, 0]
    starts = np.repeat(starts, k_f, axis=1)
    log_zi = np.log(np.maximum(top[:, None] * np.tile(fractions, k_l)[None, :],
                               2.0 * model.min_depth))
    starts = np.concatenate([starts, log_zi[:, :, None]], axis=2).reshape(m * k_l * k_f, -1)
    x2, cost2, converged2, iterations2 = _levenberg_marquardt(
        model, starts, max_iterations, np.repeat(candidates, k_l * k_f))
    pick = _best(x2, cost2, m, k_l * k_f)
    x2, cost2 = x2[pick], cost2[pick]
    _, _, _, valid, h = model.state(x2, candidates)
    reached = valid & (x2[:, 1] > 0) & (np.exp(x2[:, -1]) <= top * (1.0 + 1e-9))
    better = cost2 < cost[candidates] - CONFIDENCE_CHI_SQUARE
    d = None if model.d is None else model.d[candidates]
    shown = ~_hidden_top(model.z[candidates], model.s[candidates], d,
                         np.where(reached, h, np.inf), model.sigma_record[candidates],
                         float(np.hypot(model.sigma_d, model_error)))
    keep = reached & better & shown
    chosen = candidates[keep]
    fitted[chosen] = True
    base[chosen], cost[chosen] = x2[keep], cost2[keep]
    converged[chosen], iterations[chosen] = converged2[pick][keep], iterations2[pick][keep]
    return base, cost, converged, iterations, fitted


class _DefaultDepth:
    """A `_ProfileModel` seen without its z_i unknown (the default mixed-layer depth), for the
    state of a default-z_i fit's unknowns."""

    def __init__(self, model):
        self.__dict__.update(model.__dict__)
        self.fit_mixed_layer = False


class _SubsetModel:
    """The data of some records of a `_ProfileModel`, for `_starts`."""

    def __init__(self, model, index):
        self.ms, self.z, self.s = model.ms[index], model.z[index], model.s[index]
        self.z0, self.kappa, self.fit_roughness = model.z0[index], model.kappa, model.fit_roughness
        self.fit_mixed_layer = model.fit_mixed_layer
        self.sign = model.sign


#: Below this speed [m/s] at every height a record is calm: cup anemometers and vanes start
#: at about 0.5 to 1 m/s, and a vane below it points anywhere.
CALM_SPEED = 1.0


def misfit_reason(heights, speeds, directions, speed_noise, direction_noise, hemisphere,
                  roughness_length, stability="stable"):
    """(kind, text): why one record (heights, speeds, directions or None: its data) fits no
    atmosphere of the model, as a person reads it. ``hemisphere``: the sign of the Coriolis
    parameter.

    Kinds, in this order: ``calm`` (every speed below :data:`CALM_SPEED`), ``falling speeds``,
    ``convective`` (``stability="stable"`` only: less shear between the lowest and highest
    speeds than the neutral surface layer's log law, by more than three standard deviations of
    the noise: an unstable layer, a class the stable fit does not have), ``backing`` (the direction turns the other way than an Ekman layer),
    ``misfit``.
    """
    order = np.argsort(heights)
    z, s = heights[order], speeds[order]
    ok = np.isfinite(s)
    zs, ss = z[ok], s[ok]
    if zs.size and np.max(ss) < CALM_SPEED:
        return "calm", (f"calm: every speed below {CALM_SPEED:g} m/s (at most {np.max(ss):.2g} "
                        "m/s), where the vanes point anywhere and the layer has no Ekman profile")
    if zs.size >= 2:
        drops = ss[1:] - ss[:-1]
        if ss[-1] < ss[0] - 2.0 * speed_noise:
            return "falling speeds", (
                f"the speed falls from {ss[0]:.3g} m/s at {zs[0]:.4g} m to {ss[-1]:.3g} m/s at "
                f"{zs[-1]:.4g} m (the model's wind grows with height from the ground up to its "
                "low-level jet)")
        if drops[0] < -2.0 * speed_noise:
            return "falling speeds", (f"the speed falls with height from {zs[0]:.4g} m to "
                                      f"{zs[1]:.4g} m by {-drops[0]:.3g} m/s")
    if zs.size >= 2 and ss[0] > 0:
        log_law = np.log(zs[-1] / roughness_length) / np.log(zs[0] / roughness_length)
        spread = 3.0 * speed_noise * np.hypot(1.0, ss[-1] / ss[0]) / ss[0]
        if stability == "stable" and ss[-1] / ss[0] < log_law - spread:
            return "convective", (
                f"less shear than a neutral boundary layer, the least the model has (the speed "
                f"grows {ss[-1] / ss[0]:.3g} times from {zs[0]:.4g} m to {zs[-1]:.4g} m, the "
                f"neutral log law {log_law:.3g} times): an unstable (convective) layer, outside "
                "the stable fit's classes (neutral CNBL and stable SBL; stability=\"either\" "
                "fits convective layers too, docs/atmosphere.md#convective-boundary-layer)")
    if directions is not None:
        d = directions[order]
        okd = np.isfinite(d)
        zd, dd = z[okd], d[okd]
        if zd.size >= 2:
            change = _wrap(dd[-1] - dd[0])
            north = hemisphere > 0
            # (beyond three standard deviations of a difference of two vane readings)
            if hemisphere * change < -3.0 * np.sqrt(2.0) * direction_noise:
                return "backing", (
                    f"the direction {'backs' if north else 'veers'} with height by "
                    f"{abs(change):.3g} deg from {zd[0]:.4g} m to {zd[-1]:.4g} m (a front or "
                    f"cold-air advection; an Ekman layer in the "
                    f"{'northern' if north else 'southern'} hemisphere "
                    f"{'veers' if north else 'backs'}: the direction turns "
                    f"{'clockwise' if north else 'anticlockwise'} with height)"
                )
    looks = ""
    if zs.size >= 2 and ss[0] > 0:
        looks = (f": the speed grows {ss[-1] / ss[0]:.3g} times from {zs[0]:.4g} m to "
                 f"{zs[-1]:.4g} m (the neutral log law {log_law:.3g} times)")
        if directions is not None and zd.size >= 2:
            looks += (f" and the direction turns {_wrap(dd[-1] - dd[0]):+.3g} deg from "
                      f"{zd[0]:.4g} m to {zd[-1]:.4g} m")
    return "misfit", ("the shape of its profile is outside the model's (speed and direction "
                      "change together set u*, L and z0; a profile kinked beyond the model's, "
                      "or directions turning more than its stability allows with that shear)"
                      + looks)


def _top_changes(heights, speeds, directions, depth):
    """Per record: the speed and direction changes from the lowest height to the lowest one at
    or above ``depth`` (across the layer) and from there to the highest (above it), the largest
    speed minus the highest one's, and whether a measurement lies below ``depth``."""
    z = np.where(np.isfinite(speeds), heights, np.nan)
    rows = np.arange(len(z))
    low = np.nanargmin(z, axis=1)
    high = np.nanargmax(z, axis=1)
    above = np.where(z >= depth[:, None], z, np.inf)
    cross = np.where(np.isfinite(np.min(above, axis=1)), np.argmin(above, axis=1), high)
    s = np.where(np.isfinite(speeds), speeds, np.nan)
    changes = {
        "speed_below": s[rows, cross] - s[rows, low],
        "speed_above": s[rows, high] - s[rows, cross],
        "peak": np.nanmax(s, axis=1) - s[rows, high],
        "below": z[rows, low] < depth,
    }
    if directions is not None:
        # (the vanes' own heights: a vane need not stand at a cup's height)
        measured = np.isfinite(directions)
        d = np.where(measured, directions, np.nan)
        zd = np.where(measured, heights, np.nan)
        low_d = np.argmin(np.where(measured, zd, np.inf), axis=1)
        high_d = np.argmax(np.where(measured, zd, -np.inf), axis=1)
        above_d = np.where(measured & (zd >= depth[:, None]), zd, np.inf)
        cross_d = np.where(np.isfinite(np.min(above_d, axis=1)), np.argmin(above_d, axis=1),
                           high_d)
        changes["turn_below"] = _wrap(d[rows, cross_d] - d[rows, low_d])
        changes["turn_above"] = _wrap(d[rows, high_d] - d[rows, cross_d])
    return changes


def _hidden_top(heights, speeds, directions, depth, sigma_s, sigma_d):
    """Records whose boundary layer top ``depth`` lies below their highest measurement although
    their data show no top there: none of a speed maximum below the highest height (by more
    than two noise standard deviations), the shear stopping at the top (the speed grows from the
    lowest height to the first one at or above the top by more than three standard deviations of
    a difference more than it changes from there to the highest) or the veer stopping (the same
    for the direction's turning). A top below the lowest measurement is never shown: above it
    the model's wind is uniform, and no measurement reaches below it."""
    top = np.nanmax(np.where(np.isfinite(speeds), heights, np.nan), axis=1)
    shallow = np.isfinite(depth) & (depth < top)
    if not np.any(shallow):
        return shallow
    c = _top_changes(heights, speeds, directions, np.where(shallow, depth, np.inf))
    step_s, step_d = 3.0 * np.sqrt(2.0) * sigma_s, 3.0 * np.sqrt(2.0) * sigma_d
    shown = c["below"] & (c["peak"] > 2.0 * sigma_s)
    shown |= c["below"] & (c["speed_below"] - np.abs(c["speed_above"]) > step_s)
    if directions is not None:
        shown |= c["below"] & (np.abs(c["turn_below"]) - np.abs(c["turn_above"]) > step_d)
    return shallow & ~shown


def _hidden_top_reason(heights, speeds, directions, depth, sigma_s, sigma_d):
    """What the data of a record refused by `_hidden_top` look like, as a sentence."""
    z = heights[np.isfinite(speeds)]
    s = speeds[np.isfinite(speeds)]
    order = np.argsort(z)
    z, s = z[order], s[order]
    turn = ""
    if directions is not None:
        okd = np.isfinite(directions[0])
        zd, dd = heights[okd], directions[0][okd]
        o = np.argsort(zd)
        if zd.size >= 2:
            turn = (f" and the direction turns {_wrap(dd[o][-1] - dd[o][0]):+.3g} deg from "
                    f"{zd[o][0]:.4g} to {zd[o][-1]:.4g} m")
    return (f"its best fit is a stable layer only {float(depth):.3g} m deep, below the highest "
            f"measurement ({z[-1]:.4g} m), but the data show no top there (no speed maximum, "
            f"and neither the shear nor the veer stops at it): the speed grows from "
            f"{s[0]:.3g} m/s at {z[0]:.4g} m to {s[-1]:.3g} m/s at {z[-1]:.4g} m{turn}. A layer "
            "mixed above its surface layer (a convective afternoon) looks like this: "
            "stability=\"either\" fits convective layers too "
            "(docs/measurements.md#a-top-the-data-show)")


def _misfit_error(failing, labels, heights, speeds, directions, speed_rms, direction_rms, misfit,
                  model, tolerance, probability, depth=None, model_error=0.0, bound=None):
    i = int(failing[0])
    hemisphere = np.sign(np.broadcast_to(model.template.coriolis_parameter, (len(speeds),))[i])
    kind, reason = misfit_reason(heights[i], speeds[i],
                                 None if directions is None else directions[i],
                                 model.sigma_record[i], model.sigma_d, hemisphere, model.z0[i],
                              "stable" if np.all(model.sign > 0) else "convective")
    if bound is not None and bound[i] and kind == "misfit":
        reason = (f"its best fit inside the model's physical domain lies on the bound of the "
                  f"{bound[i]}: the data ask for a state beyond it "
                  "(docs/measurements.md#physical-domain)")
    if depth is not None and misfit[i] <= tolerance[i]:
        d = None if directions is None else directions[i:i + 1]
        reason = _hidden_top_reason(heights[i], speeds[i], d, depth[i], None, model.sigma_d)
        return ValueError(
            f"fit_profile: record {labels[i]} fits no atmosphere of the model: {reason}"
            + (f"; {failing.size - 1} more record(s) fail" if failing.size > 1 else "")
            + ". Give on_misfit='flag' to keep the fits and read profile_fit.fits")
    more = ""
    if failing.size > 1:
        shown = ", ".join(str(labels[k]) for k in failing[1:6])
        more = (f"; {failing.size - 1} more record(s) fail ({shown}"
                f"{', ...' if failing.size > 6 else ''})")
    direction = "" if directions is None else f" and the directions by {direction_rms[i]:.3g} deg"
    if not np.isfinite(misfit[i]):
        return ValueError(
            f"fit_profile: record {labels[i]} fits no atmosphere of the model: no state of the "
            f"model reaches its data: {reason}{more}. Give on_misfit='flag' to keep the other "
            "records' fits and read profile_fit.fits")
    return ValueError(
        f"fit_profile: record {labels[i]} fits no atmosphere of the model: its best fit misses "
        f"the speeds by {speed_rms[i]:.3g} m/s{direction} rms, {misfit[i]:.3g} times the noise "
        f"(speed_noise={_noise_text(model.noise)}, direction_noise={model.sigma_d:g} deg"
        + (f" with direction_model_error={model_error:g} deg" if directions is not None else "")
        + "; refused "
        f"above {tolerance[i]:.3g}, refusal_probability={probability:g}): "
        f"{reason}{more}. Give "
        "on_misfit='flag' to keep the fits and read profile_fit.fits"
    )
