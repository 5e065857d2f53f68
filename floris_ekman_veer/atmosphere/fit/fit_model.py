"""The model the profile fit evaluates (docs/measurements.md#unknowns): the speeds and direction
changes of the Ekman-surface-layer ABL at the data heights for unknowns x = (ln u*, 100 m/L,
[ln z0], [ln z_i]) per record, the states' validity (a model state inside the physical domain,
docs/measurements.md#physical-domain) and the normalised residuals. It sets each trial state at
its u* through the ABL class's public solver interface (`EkmanABL.condition_parameters`,
`EkmanABL.state_at`, `EkmanABL.solved_at`, docs/atmosphere.md#the-solvers-interface)."""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.atmosphere import stability_closures
from floris_ekman_veer.atmosphere.constants import air_heat_capacity
from floris_ekman_veer.atmosphere.fit.fit_residuals import (
    normalised_residuals,
    record_sigma,
    speed_sigma,
    turbulence_residual,
)
from floris_ekman_veer.atmosphere.inputs.input_ranges import (
    MAX_MIXED_LAYER_HEIGHT,
    MIN_BOUNDARY_LAYER_HEIGHT,
)
from floris_ekman_veer.atmosphere.physical_domain import PHYSICAL_DOMAIN, physical_domain
from floris_ekman_veer.atmosphere.fit.stability_data import stability_residuals

#: Scale of the stability unknown: lam = LENGTH_SCALE / L.
LENGTH_SCALE = 100.0
#: The relative slack a fitted state keeps inside the physical domain's bounds
#: (`DomainCheck.margin`): far above the round-off of the ABL re-solved from its G.
_DOMAIN_MARGIN = 1e-9
#: The largest coefficient of mu_N z f/u* in the profile's surface layer (wind_profile.py:
#: 0.3; 1 for margin): a state where it is no finite number is refused.
_SURFACE_TERM = 1.0


class ProfileModel:
    """The model's speeds and direction changes at the data heights for unknowns
    x = (ln u*, lam = 100 m/L, [ln z0], [ln z_i]) per record, and the normalised residuals
    (``fit_mixed_layer``: the convective mixed-layer depth z_i is the last unknown,
    docs/measurements.md#mixed-layer-depth)."""

    def __init__(self, abl_class, heights, speeds, directions, fixed, z0, fit_roughness,
                 speed_noise, direction_noise, sign=1.0, turbulence=None, fit_mixed_layer=False,
                 stability_terms=None):
        self.cls, self.fixed, self.fit_roughness = abl_class, fixed, fit_roughness
        # The prior on 1/L, a measured 1/L and the sun's heat-flux bound per record
        # (`StabilityTerms`, docs/measurements.md#reading-stability), or None.
        self.stability_terms = stability_terms
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
        self.sigma_s = speed_sigma(speeds, speed_noise)
        self.sigma_record = record_sigma(speeds, speed_noise)
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
        params, _ = self.template.condition_parameters(np.nan, (n,))
        self.params = params
        self.f = params["f"]
        self.kappa = self.template.von_karman
        # The shallowest boundary layer the ABL class accepts (a state below it is no model state).
        self.min_depth = MIN_BOUNDARY_LAYER_HEIGHT
        self.max_mixed_layer_height = MAX_MIXED_LAYER_HEIGHT
        self.hemisphere = np.broadcast_to(np.sign(self.template.coriolis_parameter), (n,))

    def fixed_at(self, index):
        return {k: (v if np.ndim(v) == 0 else np.asarray(v)[index]) for k, v in self.fixed.items()}

    def state(self, x, index):
        """(G, mu, z0, valid, h) for unknowns x of records ``index``."""
        # (unbound: `DefaultDepth` evaluates through it too)
        return ProfileModel._evaluate(self, x, index)[:5]

    def inverse_length(self, x, index):
        """[1/m] the signed 1/L of unknowns x of records ``index``."""
        sign = self.sign if np.ndim(self.sign) == 0 else self.sign[index]
        return sign * x[:, 1] / LENGTH_SCALE

    def _evaluate(self, x, index):
        """(G, mu, z0, valid, h, where each state lies in the physical domain: a
        `DomainCheck`) for unknowns x of records ``index``."""
        log_u = x[:, 0]
        # (a trial step may run far: its overflow is a state the validity below discards)
        with np.errstate(all="ignore"):
            u_star = np.exp(log_u)
            z0 = np.exp(x[:, 2]) if self.fit_roughness else self.z0[index]
            sign = self.sign if np.ndim(self.sign) == 0 else self.sign[index]
            mu = sign * u_star * x[:, 1] / (LENGTH_SCALE * self.kappa * self.f[index])
        p = {k: v[index] for k, v in self.params.items()}
        p["value"], p["z0"] = mu, z0
        with np.errstate(all="ignore"):
            if self.fit_mixed_layer:
                p["zi"] = np.exp(x[:, -1])
            _, _, h_hat, _, b, along = self.template.state_at(log_u, p)
            g = u_star * np.hypot(along, b) / self.kappa
            h = h_hat * u_star / p["f"]
            valid = (
                (x[:, 1] >= 0) & (along > 0) & np.isfinite(g) & np.isfinite(mu)
                # a surface layer above the roughness, with margin for the re-solve's round-off
                & (self.template.matching_fraction * h > 1.001 * z0)
                # a layer as deep as the ABL class accepts (light winds: u* -> 0, h -> 0)
                & (h >= 1.001 * self.min_depth)
                # the profile is written in units of u* (u = u* F(z f/u*, ...)): a state whose
                # u* has run to underflow (a calm reached by a long trial step, u* ~ 1e-309 with
                # G ~ 0.2 m/s) has its surface terms (mu_N z f/u*: the free atmosphere's
                # stratification over u*) beyond any number, no state of the model
                & np.isfinite(_SURFACE_TERM * p["mu_n"] * np.abs(p["f"])
                              * np.nanmax(np.where(self.ms[index], self.z[index], 0.0), axis=1)
                              / u_star)
            )
            if self.fit_mixed_layer:
                # z_i an input the ABL class accepts, whatever the sign the state takes
                valid &= (np.isfinite(p["zi"]) & (p["zi"] >= 1.001 * self.min_depth)
                          & (p["zi"] <= self.max_mixed_layer_height))
            # inside the physical domain of the ABL's solved states (heat flux, G, the
            # convective turning): a trial state outside it is no state the fit may reach
            # (docs/measurements.md#physical-domain)
            heat_flux = (stability_closures.surface_heat_flux(mu, p["f"], u_star, p["theta0"])
                         * air_heat_capacity(p["theta0"]))
            angle = np.rad2deg(np.arctan2(-self.hemisphere[index] * b, along))
            check = physical_domain(heat_flux, g, angle, mu)
            # (with a margin: the ABL re-solved from G must land inside too)
            valid &= check.inside & (check.margin > _DOMAIN_MARGIN)
            if self.stability_terms is not None:
                # the sun's bound (docs/measurements.md#reading-stability): at night (0) only
                # neutral or stable states
                valid &= heat_flux <= self.stability_terms.max_heat_flux[index] * (
                    1.0 - _DOMAIN_MARGIN)
        return g, mu, z0, valid, h, check, heat_flux

    def bound(self, x, index):
        """Per state of unknowns x of records ``index``: the bound of the physical domain that
        binds, as text ("sensible heat flux 800 W/m^2"), "" where none does: the state pushed a
        little further from neutral (its 1/L times 1.02) leaves the domain across it."""
        pushed = x.copy()
        pushed[:, 1] *= 1.02
        _, _, _, _, _, check, heat_flux = self._evaluate(pushed, index)
        names = np.reshape(check.binding, -1)
        text = np.full(names.size, "", dtype=object)
        if self.stability_terms is not None:
            cap = self.stability_terms.max_heat_flux[index]
            sun = (names == "") & (heat_flux > cap) & (x[:, 1] > 0)
            text[sun] = [f"sensible heat flux the sun allows, {c:.4g} W/m^2 (the clear-sky "
                         "irradiance's share; 0 at night)" for c in cap[sun]]
        for name in set(names) - {""}:
            low, high, unit = PHYSICAL_DOMAIN[name]
            value = np.reshape(check.values[name], -1)
            edge = np.where(value < low, low, high)
            here = names == name
            text[here] = [f"{name.replace('_', ' ')} {e:g} {unit}" for e in edge[here]]
        return text

    def abl(self, log_u, g, mu, z0, valid, index, mixed_layer_height=None):
        """The ABLs of states (ln u*, g, mu, z0) of records ``index``, set at their known u*
        (``EkmanABL.solved_at``: G was computed from u*, the fit never solves for it again).
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
        return self.cls.solved_at(log_u, g, stability_parameter=mu, roughness_length=z0,
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
        u, v = abl.velocity(np.transpose(self.z[index]))
        speed = np.transpose(np.hypot(u, v))
        angle = None if self.d is None else np.transpose(np.rad2deg(np.arctan2(v, u)))
        r, _, offset = normalised_residuals(
            speed, angle, self.s[index], None if self.d is None else self.d[index],
            self.sigma_s[index], self.sigma_d, offset=True)
        if self.turbulence is not None:
            r = np.concatenate([r, turbulence_residual(abl, self.turbulence, index)], axis=1)
        if self.stability_terms is not None:
            r = np.concatenate([r, stability_residuals(self.stability_terms.at(index),
                                                       self.inverse_length(x, index))], axis=1)
        return r, valid, offset


class DefaultDepth:
    """A `ProfileModel` seen without its z_i unknown (the default mixed-layer depth), for the
    state of a default-z_i fit's unknowns."""

    def __init__(self, model):
        self.__dict__.update(model.__dict__)
        self.fit_mixed_layer = False


class SubsetModel:
    """The data of some records of a `ProfileModel`, for `starting_points`."""

    def __init__(self, model, index):
        self.ms, self.z, self.s = model.ms[index], model.z[index], model.s[index]
        self.z0, self.kappa, self.fit_roughness = model.z0[index], model.kappa, model.fit_roughness
        self.fit_mixed_layer = model.fit_mixed_layer
        self.sign = model.sign
