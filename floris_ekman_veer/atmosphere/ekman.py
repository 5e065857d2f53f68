"""Coupled Ekman-surface-layer ABL model (paper Section 2.5; Narasimhan et al., BLM 2024).

The unknowns u*, h, U_g, V_g (and alpha_0) follow from the ABL-height law
Eq. (h_hat_model) and the geostrophic drag law (GDL), Eqs. (GDL), (A_model_GDL),
(B_model_GDL), solved together for a given geostrophic wind G. The mean wind is then
Eq. (U_vel) (Monin-Obukhov surface layer below the matching height 0.2 h, Ekman layer
above) and Eq. (V_vel), closed below about e z0 by a roughness sublayer in which the wind
falls linearly to 0 at the ground (docs/atmosphere.md#roughness-sublayer).

Frames and signs (docs/conventions.md#frames-and-signs): x along the surface stress; in the northern
hemisphere kappa V_g/u* = -B < 0, so the signed cross-isobaric angle
alpha_0 = atan2(V_g, U_g) is negative; in the southern hemisphere V and V_g change sign.

Everything is vectorised: every input broadcasts by numpy rules, the solved scalars have
the broadcast shape of the inputs, and the profile methods broadcast heights against that
shape (give conditions shape ``(n, 1, 1, 1)`` to evaluate on FLORIS's 4-D grids).

Solver: with the stability closure written as mu(u*) (explicit for mu, Q0 or L; a cubic
for the cooling-rate closure Q0 = C_r h, solved by monotone Newton), the GDL reduces to one
scalar equation in ln u*, |(U_g, V_g)|(u*) = G, solved for all conditions at once by
fixed-point steps then bracketed secant steps on the physical branch U_g > 0. Driven by a
reference wind instead of G (`EkmanABL.from_reference_wind`), the same parametrisation by u*
makes the speed at the reference height explicit; its root is bracketed by the collapse threshold
(docs/atmosphere.md#reference-wind-solve, `atmosphere.reference_wind`).

The layer has one module per responsibility (docs/architecture.md): the constants, the inputs'
ranges and checks, the physical domain, the similarity functions, the stability closures, the
profiles of a solved state (`WindProfile`), the reference-wind solve and the profile fit; the
last two work on `EkmanABL`'s public solver interface (`condition_parameters`, `state_at`,
`set_state`, `solved_at`, ..., docs/atmosphere.md#the-solvers-interface).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from floris_ekman_veer.atmosphere import stability_closures
from floris_ekman_veer.atmosphere.inputs.abl_inputs import (
    checked_coriolis_parameter,
    checked_model_constants,
    checked_stability_input,
    free_atmosphere_frequency,
)
from floris_ekman_veer.atmosphere.constants import (
    BUSINGER_DYER_GAMMA,
    ENTRAINMENT_RATIO,
    PAPER_POTENTIAL_TEMPERATURE,
)
from floris_ekman_veer.atmosphere.fit.fit import fit_profile
from floris_ekman_veer.atmosphere.inputs.input_ranges import (
    MAX_MIXED_LAYER_HEIGHT,
    MAX_TURBULENCE_FACTOR,
    MIN_BOUNDARY_LAYER_HEIGHT,
    POTENTIAL_TEMPERATURE_RANGE,
    VALID_RANGES,
    checked,
    require_broadcastable,
)
from floris_ekman_veer.atmosphere.physical_domain import (
    DomainCheck,
    outside_domain_reason,
    physical_domain,
)
from floris_ekman_veer.atmosphere.reference_wind import solve_reference_wind
from floris_ekman_veer.atmosphere.root_finding import secant_root
from floris_ekman_veer.atmosphere.similarity import boundary_layer_height_hat, gdl_coefficients
from floris_ekman_veer.atmosphere.turbulence import convective_variance
from floris_ekman_veer.atmosphere.wind_profile import WindProfile

# Marks a construction that only validates the inputs (EkmanABL.check_inputs).
_INPUTS_ONLY = object()


class DragLawState(NamedTuple):
    """The ABL state of Eq. (GDL) at a trial friction velocity (`EkmanABL.state_at`): explicit in
    u* for a given stability closure. Arrays of the conditions' broadcast shape."""

    #: u* [m/s]
    friction_velocity: np.ndarray
    #: mu = u*/(kappa f_c L) of the closure at this u*
    stability_parameter: np.ndarray
    #: h f_c/u*, Eq. (h_hat_model) (a convective layer: z_i f_c/u*)
    h_hat: np.ndarray
    #: the drag law's coefficients A and B, Eqs. (A_model_GDL), (B_model_GDL)
    gdl_a: np.ndarray
    gdl_b: np.ndarray
    #: ln Ro - A = kappa U_g/u*: positive on the physical branch U_g > 0
    along_stress: np.ndarray


class EkmanSolver:
    """The solve of :class:`EkmanABL`: the geostrophic drag law in u* for each condition, and
    the solver's interface the reference-wind solve and the profile fit use
    (docs/atmosphere.md#the-solvers-interface): `condition_parameters`, `state_at`,
    `surface_layer_exists`, `set_state`, `require_depth`, `require_domain`. A base of EkmanABL
    (its inputs and constants are EkmanABL's), kept apart so that ``help(EkmanABL)`` shows the
    methods a user calls (``from_reference_wind``, ``fit_profile``, ``velocity``, ``speed``,
    ...) before these internals."""

    def _neutral_h_hat(self, p):
        """h_hat of Eq. (h_hat_model) at mu = 0."""
        return boundary_layer_height_hat(0.0, p["mu_n"], self.c_tn, self.c_cn, self.c_ns)

    def _convective_h_hat(self, u_star, p):
        """z_i f/u* of a convective layer: the given mixed_layer_height, else the neutral height
        of Eq. (h_hat_model) (docs/atmosphere.md#convective-boundary-layer)."""
        return np.where(np.isnan(p["zi"]), self._neutral_h_hat(p), p["zi"] * p["f"] / u_star)

    def _closure_mu(self, u_star, p):
        """mu as a function of u* for the chosen stability input (docs/atmosphere.md#stability-closures)."""
        value, f, theta0 = p["value"], p["f"], p["theta0"]
        if self.stability_input == "stability_parameter":
            return value + 0.0 * u_star
        if self.stability_input == "surface_heat_flux":
            return stability_closures.stability_from_heat_flux(value, u_star, f, theta0)
        if self.stability_input == "sensible_heat_flux":
            return stability_closures.stability_from_sensible_heat_flux(value, u_star, f, theta0)
        if self.stability_input == "obukhov_length":
            return u_star / (self.von_karman * f * value)
        a0 = 1.0 / self.c_tn**2 + p["mu_n"] / self.c_cn**2
        cooling = stability_closures.stability_from_cooling_rate(
            np.minimum(value, 0.0) / 3600.0, u_star, f, theta0, a0, self.c_ns
        )
        # Heating: the mixed layer warms at C_r, Q0 = C_r z_i / (1 + A_e) (Tennekes 1973).
        z_i = self._convective_h_hat(u_star, p) * u_star / f
        heat_flux = np.maximum(value, 0.0) / 3600.0 * z_i / (1.0 + ENTRAINMENT_RATIO)
        return np.where(value > 0, stability_closures.stability_from_heat_flux(
            heat_flux, u_star, f, theta0), cooling)

    def state_at(self, log_u_star, p) -> DragLawState:
        """The `DragLawState` (u*, mu, h_hat, A, B, ln Ro - A) at trial ln u* for the condition
        parameters ``p`` (`condition_parameters`): explicit in u* for the stability closure, so
        G = (u*/kappa) sqrt((ln Ro - A)^2 + B^2) needs no inner solve
        (docs/atmosphere.md#the-solvers-interface). Arrays broadcast together."""
        u_star = np.exp(log_u_star)
        mu = self._closure_mu(u_star, p)
        h_hat = np.where(
            mu < 0, self._convective_h_hat(u_star, p),
            boundary_layer_height_hat(np.maximum(mu, 0.0), p["mu_n"], self.c_tn, self.c_cn,
                                      self.c_ns),
        )
        rossby = u_star / (p["f"] * p["z0"])
        a, b = gdl_coefficients(
            mu, p["mu_n"], h_hat, rossby, self.von_karman, self.c_g,
            self.stress_decay, self.matching_fraction, self.businger_dyer_gamma,
        )
        return DragLawState(u_star, mu, h_hat, a, b, np.log(rossby) - a)

    def _residual(self, log_u_star, p):
        """ln(|(U_g, V_g)| / G): zero at the GDL solution, increasing on the physical branch
        U_g > 0 (ln Ro > A); -inf below that branch."""
        _, _, _, _, b, along = self.state_at(log_u_star, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = log_u_star + 0.5 * np.log(along**2 + b**2) - np.log(self.von_karman * p["g"])
        return np.where(along > 0, r, -np.inf)

    def _failure(self, mask, reason, lead="the ABL solve did not converge"):
        idx = tuple(np.argwhere(mask)[0])
        details = ", ".join(
            f"{name}={np.broadcast_to(np.asarray(value, float), mask.shape)[idx]:.6g}"
            for name, value in dict(
                geostrophic_wind=self.geostrophic_wind,
                coriolis_parameter=self.coriolis_parameter,
                roughness_length=self.roughness_length,
                **{self.stability_input: self.stability_value},
                brunt_vaisala_frequency=self.brunt_vaisala_frequency,
                **({} if self.mixed_layer_height is None
                   else {"mixed_layer_height": self.mixed_layer_height}),
            ).items()
        )
        return ValueError(f"{lead} ({reason}) for inputs {details}")

    def condition_parameters(self, geostrophic_wind, shape=()):
        """(parameters, shape): the per-condition parameters of the solve by name (``g`` the
        geostrophic wind, ``f`` |f_c|, ``z0``, ``value`` the stability input's, ``mu_n``,
        ``theta0``, ``zi`` z_i or NaN), broadcast together and to ``shape``, and that shape: what
        `state_at` and `set_state` take (docs/atmosphere.md#the-solvers-interface)."""
        params = dict(
            g=geostrophic_wind, f=self.coriolis_magnitude, z0=self.roughness_length,
            value=self.stability_value, mu_n=self.zilitinkevich_number,
            theta0=self.reference_potential_temperature,
            zi=np.nan if self.mixed_layer_height is None else self.mixed_layer_height,
        )
        shape = np.broadcast_shapes(shape, *(np.shape(v) for v in params.values()))
        return {k: np.broadcast_to(v, shape) for k, v in params.items()}, shape

    def surface_layer_exists(self, u_star, h_hat, p):
        """The state is a model state if the matching height (matching_fraction * h, which
        grows with u*) lies above z0; below it the stable boundary layer has collapsed."""
        return self.matching_fraction * h_hat * u_star / p["f"] > p["z0"]

    def _solve(self):
        params, shape = self.condition_parameters(self.geostrophic_wind)
        flat = {k: v.ravel() for k, v in params.items()}
        # A few steps of the contracting fixed-point form (rate ~ 1/(ln Ro - A) ~ 0.1) put
        # u* within ~0.1 %; bracketed secant steps then converge on the physical branch.
        log_kg = np.log(self.von_karman * flat["g"])
        x = log_kg + np.log(0.05)
        for _ in range(3):
            _, _, _, _, b, along = self.state_at(x, flat)
            with np.errstate(divide="ignore", invalid="ignore"):
                x = np.where(along > 0, log_kg - 0.5 * np.log(along**2 + b**2), x + 0.5)
        x, converged = secant_root(lambda x: self._residual(x, flat), x - 0.01, x + 0.01)
        if not np.all(converged):
            raise self._failure(
                ~converged.reshape(shape),
                "no physical solution with U_g > 0: the cooling is too strong for this wind, "
                "the stable boundary layer collapses",
            )
        # The root is unique, but it is a model state only if the surface layer exists:
        # the matching height (matching_fraction * h, which grows with u*) above z0.
        u_star, _, h_hat, _, _, _ = self.state_at(x, flat)
        collapsed = ~self.surface_layer_exists(u_star, h_hat, flat)
        if np.any(collapsed):
            raise self._failure(
                collapsed.reshape(shape),
                "matching height matching_fraction * h at or below roughness_length z0: "
                "the stable boundary layer collapses",
            )
        self.set_state(x.reshape(shape), {k: v.reshape(shape) for k, v in flat.items()})
        self.require_depth(lambda mask: self._failure(
            mask, f"the stable boundary layer collapses: h below {MIN_BOUNDARY_LAYER_HEIGHT:g} m, "
            "the shallowest the model accepts (docs/atmosphere.md#shallow-boundary-layer)",
            lead="no model ABL",
        ))
        self.require_domain(lambda mask, reason: self._failure(
            mask, reason, lead="the inputs leave the physical domain",
        ))

    def require_domain(self, error):
        """Raise ``error(mask of the offending conditions, reason)`` at the first condition
        outside the physical domain, the reason naming the implied quantity, its value and range."""
        check = self.physical_domain()
        if np.all(check.inside):
            return
        outside = np.atleast_1d(~check.inside).reshape(np.shape(check.inside) or (1,))
        first = tuple(np.argwhere(outside)[0])
        name = np.atleast_1d(check.binding).reshape(outside.shape)[first]
        value = np.broadcast_to(np.atleast_1d(check.values[name]).reshape(
            np.shape(check.values[name]) or (1,)), outside.shape)[first]
        raise error(outside, outside_domain_reason(name, value))

    def require_depth(self, error):
        """Raise ``error(mask of the offending conditions)`` where h < MIN_BOUNDARY_LAYER_HEIGHT."""
        shallow = np.asarray(self.boundary_layer_height) < MIN_BOUNDARY_LAYER_HEIGHT
        if np.any(shallow):
            raise error(np.atleast_1d(shallow).reshape(np.shape(shallow) or (1,)))

    def set_state(self, log_u_star, p):
        """Set the solved attributes (``friction_velocity``, ``stability_parameter``,
        ``boundary_layer_height``, ``geostrophic_components``, ``cross_isobaric_angle``, ...)
        at the root ln u* of the conditions' parameters ``p`` (`condition_parameters`); the
        caller vouches that it is a model state (docs/atmosphere.md#the-solvers-interface)."""
        # The state of one condition is computed as an array of one, not as numpy scalars:
        # ``**`` on a numpy scalar takes C's pow, whose last bit can differ from numpy's array
        # loop, and a condition must give the same bits alone as in a batch.
        shape = np.shape(log_u_star)
        z_i = np.broadcast_to(p["zi"], shape)
        if shape == ():
            log_u_star = np.reshape(log_u_star, 1)
            p = {k: np.reshape(v, 1) for k, v in p.items()}
        u_star, mu, h_hat, a, b, along = (
            np.reshape(x, shape) for x in self.state_at(log_u_star, p))
        kappa = self.von_karman
        self.friction_velocity = u_star[()]
        self.stability_parameter = np.asarray(mu, dtype=float)[()]
        self.h_hat = h_hat[()]
        self.gdl_a, self.gdl_b = a[()], b[()]
        # A given z_i is the convective layer's depth itself: z_i f/u* times u*/f would round
        # it (10 m to 9.999999999999998 m, below the shallowest depth accepted).
        depth = h_hat * u_star / self.coriolis_magnitude
        if not np.all(np.isnan(z_i)):
            depth = np.where((mu < 0) & ~np.isnan(z_i), z_i, depth)
        self.boundary_layer_height = depth[()]
        u_g = u_star * along / kappa
        v_g = -self.hemisphere * u_star * b / kappa
        self.geostrophic_components = (u_g[()], v_g[()])
        self.cross_isobaric_angle = np.rad2deg(np.arctan2(v_g, u_g))[()]
        self.convective_variance = convective_variance(
            self.boundary_layer_height, self.obukhov_length
        )[()]


class EkmanABL(WindProfile, EkmanSolver):
    """Coupled Ekman-surface-layer atmospheric boundary layer, solved for given G.

    Keyword inputs (all broadcast together; conditions may be arrays):

    - ``geostrophic_wind`` G [m/s], > 0.
    - Coriolis: ``coriolis_parameter`` f_c [1/s] (signed: negative in the southern
      hemisphere) or ``latitude`` [deg, negative = south]; |latitude| >= 1 degree, i.e.
      |f_c| >= 2 Omega sin(1 deg): the model has no solution at the equator.
    - ``roughness_length`` z0 [m], > 0.
    - Stability, at most one of, of either sign (negative mu or L, positive heat flux or
      heating rate: a convective layer, docs/atmosphere.md#convective-boundary-layer):
      ``stability_parameter`` mu = u*/(kappa f_c L); ``cooling_rate`` C_r [K/h] with
      Q0 = C_r h when cooling (paper Section 2.5), Q0 = C_r z_i/(1 + A_e) when heating;
      ``surface_heat_flux`` Q0 [K m/s]; ``sensible_heat_flux`` H [W/m^2] = rho c_p Q0;
      ``obukhov_length`` L [m] (+-inf = neutral). Default: neutral (mu = 0).
    - ``mixed_layer_height`` z_i [m], the depth of a convective layer (used where mu < 0;
      default the neutral height of Eq. h_hat_model at the same u*).
    - Free atmosphere, at most one of ``brunt_vaisala_frequency`` N [1/s] >= 0 or
      ``lapse_rate`` dTheta/dz [K/m] >= 0 (N = sqrt(g/Theta0 gamma)); default the paper's
      N_inf = 6.1e-3 1/s. Enters through the Zilitinkevich number mu_N = N/|f_c|.
    - ``reference_potential_temperature`` Theta0 [K], default the paper's 265 K.
    - ``turbulence_factor`` (beyond the paper; default None, the paper's I_u): the site's
      ambient streamwise turbulence as a factor on the model's I_u(z) of Eq. (Iu_model), > 0 and
      <= 10; it scales `turbulence_intensity` and hence the wake expansion rate k_w of
      Eq. (kw_CNBL_SBL_model), not the mean wind. A measured hub-height TI over the model's I_u
      there (terrain, upwind roughness: docs/atmosphere.md#ambient-turbulence).
    - Model constants: ``von_karman`` 0.41, ``c_g`` 1.43, ``stress_decay`` (Gamma) 0.83,
      ``c_tn`` 0.5, ``c_cn`` 1.6, ``c_ns`` 0.78, ``matching_fraction`` 0.2, and, beyond the
      paper, ``businger_dyer_gamma`` 16 (Dyer 1974; 19.3 for Hogstrom 1988).

    Solved attributes: ``friction_velocity`` [m/s], ``boundary_layer_height`` [m],
    ``cross_isobaric_angle`` [deg, signed, surface-stress frame], ``stability_parameter``
    (mu, also when derived from C_r, Q0 or L), ``zilitinkevich_number`` mu_N,
    ``geostrophic_components`` (U_g, V_g), ``coriolis_parameter`` (signed), and the
    dimensionless ``h_hat`` = h f_c/u* with the GDL coefficients ``gdl_a``, ``gdl_b`` (A, B);
    ``coriolis_magnitude`` |f_c| and ``hemisphere`` (+1 north, -1 south), the given stability
    input's name ``stability_input`` and value ``stability_value``.

    The solver's interface (docs/atmosphere.md#the-solvers-interface), which the reference-wind
    solve and the profile fit use: `solved_at` and, from the base :class:`EkmanSolver`,
    `condition_parameters`, `state_at`, `surface_layer_exists`, `set_state`, `require_depth`,
    `require_domain`.

    Example (a stable night, L = 100 m, with 8 m/s at a 90 m hub; ``from_reference_wind``
    solves the G that gives it):

        >>> from floris_ekman_veer import EkmanABL
        >>> abl = EkmanABL.from_reference_wind(8.0, 90.0, latitude=52.0, roughness_length=0.1,
        ...                                    obukhov_length=100.0)
        >>> round(float(abl.boundary_layer_height), 1)          # h [m]
        220.5
        >>> abl.speed([30.0, 90.0, 150.0]).round(2)             # |U(z)| [m/s]
        array([4.98, 8.  , 9.49])
        >>> round(float(abl.wind_direction_change(27.0, 153.0)), 1)  # veer across a rotor [deg]
        20.4
        >>> round(float(abl.turbulence_intensity(90.0)), 4)     # I_u at the hub
        0.0459
    """

    #: The entrainment ratio A_e of the heating-rate closure (`ENTRAINMENT_RATIO`).
    entrainment_ratio = ENTRAINMENT_RATIO


    def __init__(
        self,
        *,
        geostrophic_wind,
        coriolis_parameter=None,
        latitude=None,
        roughness_length,
        stability_parameter=None,
        cooling_rate=None,
        surface_heat_flux=None,
        obukhov_length=None,
        sensible_heat_flux=None,
        mixed_layer_height=None,
        brunt_vaisala_frequency=None,
        lapse_rate=None,
        reference_potential_temperature=PAPER_POTENTIAL_TEMPERATURE,
        turbulence_factor=None,
        von_karman=0.41,
        c_g=1.43,
        stress_decay=0.83,
        c_tn=0.5,
        c_cn=1.6,
        c_ns=0.78,
        matching_fraction=0.2,
        businger_dyer_gamma=BUSINGER_DYER_GAMMA,
    ):
        constants = checked_model_constants(
            von_karman=von_karman, c_g=c_g, stress_decay=stress_decay, c_tn=c_tn, c_cn=c_cn,
            c_ns=c_ns, matching_fraction=matching_fraction)
        self.von_karman, self.c_g, self.stress_decay = (
            constants["von_karman"], constants["c_g"], constants["stress_decay"])
        self.c_tn, self.c_cn, self.c_ns = constants["c_tn"], constants["c_cn"], constants["c_ns"]
        self.matching_fraction = constants["matching_fraction"]
        self.businger_dyer_gamma = float(checked(
            "businger_dyer_gamma", businger_dyer_gamma, lambda v: (v > 0) & (np.ndim(v) == 0)
        ))
        self.coriolis_parameter = checked_coriolis_parameter(coriolis_parameter, latitude)
        self.coriolis_magnitude = np.abs(self.coriolis_parameter)
        self.hemisphere = np.sign(self.coriolis_parameter)
        self.roughness_length = checked("roughness_length", roughness_length, lambda z0: z0 > 0)
        self.reference_potential_temperature = checked(
            "reference_potential_temperature", reference_potential_temperature,
            lambda t: (t >= POTENTIAL_TEMPERATURE_RANGE[0]) & (t <= POTENTIAL_TEMPERATURE_RANGE[1]),
        )
        self.brunt_vaisala_frequency = free_atmosphere_frequency(
            brunt_vaisala_frequency, lapse_rate, self.reference_potential_temperature)
        self.zilitinkevich_number = self.brunt_vaisala_frequency / self.coriolis_magnitude
        self.stability_input, self.stability_value = checked_stability_input(
            dict(stability_parameter=stability_parameter, cooling_rate=cooling_rate,
                 surface_heat_flux=surface_heat_flux, obukhov_length=obukhov_length,
                 sensible_heat_flux=sensible_heat_flux),
            self.reference_potential_temperature)
        self.mixed_layer_height = None if mixed_layer_height is None else checked(
            "mixed_layer_height", mixed_layer_height,
            lambda z: (z >= MIN_BOUNDARY_LAYER_HEIGHT) & (z <= MAX_MIXED_LAYER_HEIGHT),
        )
        #: The ambient turbulence over the model's I_u (None: the paper's I_u, no factor).
        self.turbulence_factor = None if turbulence_factor is None else checked(
            "turbulence_factor", turbulence_factor,
            lambda c: (c > 0) & (c <= MAX_TURBULENCE_FACTOR))[()]
        given = {
            "coriolis_parameter" if latitude is None else "latitude": self.coriolis_parameter,
            "roughness_length": self.roughness_length,
            "reference_potential_temperature": self.reference_potential_temperature,
            "lapse_rate" if lapse_rate is not None else "brunt_vaisala_frequency":
                self.brunt_vaisala_frequency,
            self.stability_input: self.stability_value,
        }
        if self.mixed_layer_height is not None:
            given["mixed_layer_height"] = self.mixed_layer_height
        if self.turbulence_factor is not None:
            given["turbulence_factor"] = self.turbulence_factor
        if geostrophic_wind is _INPUTS_ONLY:
            require_broadcastable(given)
            return
        self.geostrophic_wind = checked("geostrophic_wind", geostrophic_wind, lambda g: g > 0)
        require_broadcastable({"geostrophic_wind": self.geostrophic_wind, **given})
        self._solve()

    @classmethod
    def check_inputs(cls, **inputs):
        """Validate EkmanABL keyword inputs without the geostrophic wind (types, ranges and
        exclusive choices, as the constructor does) and return the unsolved instance; raises
        ValueError naming the input, its valid range (`VALID_RANGES`) and, for arrays, the
        index of the offending entries."""
        if "geostrophic_wind" in inputs:
            raise ValueError("check_inputs takes the inputs without geostrophic_wind")
        return cls(geostrophic_wind=_INPUTS_ONLY, **inputs)

    @classmethod
    def solved_at(cls, log_u_star, geostrophic_wind, **inputs):
        """The ABL of ``inputs`` and ``geostrophic_wind`` whose solve's root ln u* is already
        known: the state of Eq. (GDL) is explicit in u* for a given stability (the reference-wind
        solve's parametrisation, docs/atmosphere.md#reference-wind-solve), so a caller that
        found G from u* (the profile fit, docs/measurements.md#fit-time) sets the solution
        without solving for u* again. The caller vouches that the state is a model state (a
        physical GDL branch, a surface layer above z0, h at least the shallowest accepted)."""
        abl = cls.check_inputs(**inputs)
        abl.geostrophic_wind = np.asarray(geostrophic_wind, dtype=float)
        params, shape = abl.condition_parameters(abl.geostrophic_wind, np.shape(log_u_star))
        abl.set_state(np.broadcast_to(np.asarray(log_u_star, dtype=float), shape), params)
        return abl

    @staticmethod
    def valid_range(name):
        """The valid range of input ``name`` as the error messages state it (`VALID_RANGES`);
        ValueError naming the inputs for a name that is none of them."""
        if not isinstance(name, str) or name not in VALID_RANGES:
            raise ValueError(f"valid_range: name must be one of EkmanABL's inputs "
                             f"{sorted(VALID_RANGES)}; got {name!r}")
        return VALID_RANGES[name]

    def physical_domain(self) -> DomainCheck:
        """Where the solved states lie in the `PHYSICAL_DOMAIN` (`physical_domain`): the implied
        sensible heat flux, geostrophic wind and, where convective, cross-isobaric angle, per
        condition, without raising (docs/atmosphere.md#physical-domain)."""
        return physical_domain(self.sensible_heat_flux, self.geostrophic_wind,
                               self.cross_isobaric_angle, self.stability_parameter)

    # ----------------------------------------------------------------------------- drivers
    @classmethod
    def from_reference_wind(cls, speed, height, tolerance=1e-13, outside_domain="refuse",
                            **inputs):
        """Solve the ABL whose wind speed at ``height`` is ``speed`` (instead of giving G).

        FLORIS drives farms by the wind speed at a reference height. The solve is one scalar
        root per condition in ln u* (docs/atmosphere.md#reference-wind-solve): for a given u*
        the closure, h_hat, A, B and hence G = (u*/kappa) sqrt((ln Ro - A)^2 + B^2) are
        explicit, so the speed at ``height`` is an explicit, increasing function of u*. Its
        domain is bounded below by the collapse threshold (the physical GDL branch ln Ro > A
        and a surface layer, matching_fraction * h > z0, exist only above some u*); trial
        states below it count as "below the root", the bracket widens upward without bound
        (the speed grows with u*), and bracketed secant steps, bisecting where the secant
        leaves the bracket, converge whenever a solution exists. When none does (the speed is
        below the slowest wind the atmosphere supports at that height), the ValueError gives
        the condition, the speed and height asked for and that slowest speed.
        A state outside the physical domain is refused naming every speed that leaves it
        (``outside_domain="refuse"``, the default); ``outside_domain="limit"`` carries the
        conditions that leave it by their heat flux with their stability limited toward
        neutral to the bound (``domain_limited`` marks them,
        docs/atmosphere.md#a-fixed-stability-across-wind-speeds).
        Vectorised over arrays of speeds, heights and inputs (distinct conditions solved once).
        """
        if "geostrophic_wind" in inputs:
            raise ValueError("from_reference_wind takes speed and height instead of geostrophic_wind")
        return solve_reference_wind(cls, speed, height, tolerance, inputs, outside_domain)

    @classmethod
    def fit_profile(cls, heights, speeds, directions=None, **options_and_fixed_inputs):
        """The atmosphere whose profile best fits measured wind speeds [m/s] and meteorological
        directions [deg] at ``heights`` [m], per record (arrays (n_records, n_heights)): least
        squares in u* (hence G), the Obukhov length and optionally z0, the direction a free
        rotation; refuses records no atmosphere of the model fits. Options and fixed inputs:
        :func:`floris_ekman_veer.atmosphere.fit.fit.fit_profile` (docs/measurements.md)."""
        return fit_profile(cls, heights, speeds, directions, **options_and_fixed_inputs)

    def __repr__(self):
        return (
            f"EkmanABL(G={self.geostrophic_wind!r}, u*={self.friction_velocity!r}, "
            f"h={self.boundary_layer_height!r}, mu={self.stability_parameter!r}, "
            f"alpha_0={self.cross_isobaric_angle!r} deg)"
        )


def friction_velocity_fixed_point(abl, iterations=200):
    """Re-solve u* of a solved `EkmanABL` by the fixed-point form of the GDL,
    u* <- kappa G / sqrt((ln(u*/(f_c z0)) - A)^2 + B^2) (docs/atmosphere.md#stability-closures), from u* = 0.05 G.

    An independent route to the same root, used to check the bracketed solver.
    """
    u_star = 0.05 * np.broadcast_to(abl.geostrophic_wind, np.shape(abl.friction_velocity)).astype(float)
    for _ in range(iterations):
        _, _, _, _, b, along = abl.state_at(np.log(u_star), abl.condition_parameters(abl.geostrophic_wind)[0])
        u_star = abl.von_karman * abl.geostrophic_wind / np.sqrt(along**2 + b**2)
    return u_star
