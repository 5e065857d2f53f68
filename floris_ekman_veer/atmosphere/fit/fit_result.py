"""What the profile fit found, per record (docs/measurements.md): `ProfileFit`, with the fitted
unknowns, residuals and refusals, the fitted speeds and directions, the atmosphere block a FLORIS
input takes, the turbulence intensity's confidence interval and the reason a record is refused."""

from __future__ import annotations

import attrs
import numpy as np

from floris_ekman_veer.atmosphere import stability_closures
from floris_ekman_veer.atmosphere.fit.fit_model import LENGTH_SCALE, ProfileModel
from floris_ekman_veer.atmosphere.fit.fit_residuals import (
    CONFIDENCE_CHI_SQUARE,
    normalised_residuals,
    record_sigma,
    speed_sigma,
)
from floris_ekman_veer.atmosphere.fit.misfit import hidden_top, hidden_top_reason, misfit_reason

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
    #: "convective", "neutral" or "stable" per record (`stability_class` of the fitted L).
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
                   LENGTH_SCALE / length]
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
        fit's own (`ProfileModel.abl_at`)."""
        n = np.size(self.misfit)
        rows = np.repeat(np.arange(n), x.shape[0] // n)
        fit_roughness = "roughness_length" in self.fitted
        z0 = np.broadcast_to(self.fixed_inputs.get("roughness_length", self.roughness_length),
                             (n,))
        fixed = {k: v for k, v in self.fixed_inputs.items() if k != "roughness_length"}
        model = ProfileModel(type(self.abl), np.ones((n, 1)), np.ones((n, 1)), None, fixed, z0,
                              fit_roughness, 1.0, 1.0, sign,
                              fit_mixed_layer=x.shape[1] > 2 + fit_roughness)
        unsigned = x.copy()
        unsigned[:, 1] *= sign[rows]
        abl, valid = model.abl_at(unsigned, rows)
        ref = () if reference_height is None else (reference_height,)
        intensity = np.reshape(np.asarray(abl.turbulence_intensity(height, *ref), float), -1)
        return np.where(valid, intensity, np.nan)

    def fitted_depth(self):
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
        heat_flux = stability_closures.surface_heat_flux(mu, f, u_star, theta0)
        with np.errstate(divide="ignore"):
            cooling_rate = stability_closures.cooling_rate(
                heat_flux, np.asarray(self.boundary_layer_height, float), mu < 0)
        values = {
            "stability_parameter": mu,
            "obukhov_length": np.where(
                mu != 0, stability_closures.obukhov_length(u_star, f, mu, self.abl.von_karman),
                np.inf),
            "surface_heat_flux": heat_flux,
            # heating (mu < 0): Q0 = C_r z_i / (1 + A_e) (docs/atmosphere.md#convective-boundary-layer)
            "cooling_rate": cooling_rate,
        }
        if stability_input not in values:
            raise ValueError(f"stability_input must be one of {list(values)}; got "
                             f"{stability_input!r}")
        block = dict(self.fixed_inputs) | self.fitted_depth()
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
        r, observations, _ = normalised_residuals(speed, angle, speeds, directions,
                                                speed_sigma(speeds, self.speed_noise),
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
                and hidden_top(self.heights[i : i + 1], self.speeds[i : i + 1], directions,
                                depth, record_sigma(self.speeds[i : i + 1], self.speed_noise),
                                np.hypot(self.direction_noise, self.direction_model_error))[0]):
            kind, text = "no top", hidden_top_reason(self.heights[i], self.speeds[i],
                                                      directions, depth[0], None,
                                                      self.direction_noise)
            if self.stability == "either":
                # (the convective fit was tried too, and missed as well)
                text = text.replace('stability="either" fits convective layers too',
                                    "its convective fit misses the data too")
            return kind, text
        return misfit_reason(self.heights[i], self.speeds[i],
                             None if self.directions is None else self.directions[i],
                             record_sigma(self.speeds[i], self.speed_noise),
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
        solved |= {k: per_record(v) for k, v in self.fitted_depth().items()}
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


#: |L| [m] above which a fit is classed neutral (Gryning et al. 2007's neutral class, |L| > 500 m).
NEUTRAL_OBUKHOV_LENGTH = 500.0


def stability_class(obukhov_length):
    """"convective" (-500 m <= L < 0), "neutral" (|L| > 500 m) or "stable" (0 < L <= 500 m)."""
    length = np.asarray(obukhov_length, dtype=float)
    return np.where(np.abs(length) > NEUTRAL_OBUKHOV_LENGTH, "neutral",
                    np.where(length < 0, "convective", "stable"))
