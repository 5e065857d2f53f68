"""Coupled Ekman-surface-layer ABL model (paper Section 2.5; Narasimhan et al., BLM 2024).

The unknowns u*, h, U_g, V_g (and alpha_0) follow from the ABL-height law
Eq. (h_hat_model) and the geostrophic drag law (GDL), Eqs. (GDL), (A_model_GDL),
(B_model_GDL), solved together for a given geostrophic wind G. The mean wind is then
Eq. (U_vel) (Monin-Obukhov surface layer below the matching height 0.2 h, Ekman layer
above) and Eq. (V_vel).

Frames and signs (docs/conventions.md#frames-and-signs): x along the surface stress; in the northern
hemisphere kappa V_g/u* = -B < 0, so the signed cross-isobaric angle
alpha_0 = atan2(V_g, U_g) is negative; in the southern hemisphere V and V_g change sign.

Everything is vectorised: every input broadcasts by numpy rules, the solved scalars have
the broadcast shape of the inputs, and the profile methods broadcast heights against that
shape (give conditions shape ``(n, 1, 1, 1)`` to evaluate on FLORIS's 4-D grids).

Solver: with the stability closure written as mu(u*) (explicit for mu, Q0 or L; a cubic
for the cooling-rate closure Q0 = C_r h, solved by monotone Newton), the GDL reduces to one
scalar equation in ln u*, |(U_g, V_g)|(u*) = G, solved for all conditions at once by
fixed-point steps then bracketed secant steps on the physical branch U_g > 0.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import elementwise

from floris_ekman_veer._validation import finite, require
from floris_ekman_veer.atmosphere.turbulence import (
    TOWNSEND_PERRY_A1,
    TOWNSEND_PERRY_B1,
    streamwise_turbulence_intensity,
    wake_expansion_rate,
)

#: Gravitational acceleration [m/s^2] (paper Section 2.5).
GRAVITY = 9.81
#: Earth's rotation rate Omega [1/s] (paper Section 2.5).
EARTH_ROTATION_RATE = 7.27e-5
#: Below this |latitude| the f-plane Ekman balance degenerates (f_c -> 0 at the equator).
MIN_ABS_LATITUDE = 1.0
#: Paper's free-atmosphere Brunt-Vaisala frequency N_inf [1/s] (Table 1 caption).
PAPER_BRUNT_VAISALA_FREQUENCY = 6.1e-3
#: Paper's reference potential temperature Theta_0 [K] (Table 1 caption).
PAPER_POTENTIAL_TEMPERATURE = 265.0

_STABILITY_INPUTS = ("stability_parameter", "cooling_rate", "surface_heat_flux", "obukhov_length")
_SOLVER_TOLERANCE = 1e-14
_SOLVER_MAX_ITERATIONS = 200


def coriolis_parameter_from_latitude(latitude):
    """f_c = 2 Omega sin(phi) [1/s]; latitude in degrees, negative in the south."""
    latitude = finite("latitude", latitude)
    require(
        (np.abs(latitude) >= MIN_ABS_LATITUDE) & (np.abs(latitude) <= 90.0),
        "latitude", "1 <= |latitude| <= 90 degrees (the Ekman model has no solution at the "
        "equator, where f_c = 0)", latitude,
    )
    return 2.0 * EARTH_ROTATION_RATE * np.sin(np.deg2rad(latitude))


def boundary_layer_height_hat(stability_parameter, zilitinkevich_number, c_tn, c_cn, c_ns):
    """h_hat = h f_c/u* from 1/h_hat^2 = 1/C_TN^2 + mu_N/C_CN^2 + mu/C_NS^2, Eq. (h_hat_model)."""
    return (1.0 / c_tn**2 + zilitinkevich_number / c_cn**2 + stability_parameter / c_ns**2) ** -0.5


def stress_shape(xi_over_h, h_hat, c_g, decay):
    """g and g' of Eq. (eqn:avoidnumbers1): g = c_g (1 - exp(-xi/(Gamma h_hat)))."""
    e = np.exp(-xi_over_h / decay)
    return c_g * (1.0 - e), c_g / (decay * h_hat) * e


def gdl_coefficients(
    stability_parameter, zilitinkevich_number, h_hat, rossby_number, kappa, c_g, decay, matching
):
    """GDL coefficients A and B, Eqs. (A_model_GDL) and (B_model_GDL).

    ``rossby_number`` is the surface Rossby number u*/(|f_c| z0) = 1/xi0_hat. The paper
    prints 0.2 and 0.8 = 1 - 0.2; ``matching`` is that fraction.
    """
    g_m, dg_m = stress_shape(matching, h_hat, c_g, decay)
    most_slope = 5.0 * stability_parameter + 0.3 * zilitinkevich_number
    a = -np.log(matching * h_hat) - kappa * (
        most_slope * (matching * h_hat - 1.0 / rossby_number)
        + dg_m * (1.0 - matching) ** 1.5
        - g_m * (1.5 / h_hat) * (1.0 - matching) ** 0.5
    )
    b = 1.5 * kappa / h_hat
    return a, b


def stability_from_cooling_rate(cooling_rate_per_second, friction_velocity, coriolis, theta0, a0, c_ns):
    """mu for the closure Q0 = C_r h (docs/atmosphere.md#stability-closures).

    mu = -(g/Theta0) C_r h_hat(mu) / (f_c^2 u*) with h_hat(mu) = (a0 + mu/C_NS^2)^(-1/2), i.e.
    mu^3/C_NS^2 + a0 mu^2 - c^2 = 0, c = -(g/Theta0) C_r/(f_c^2 u*) >= 0. The cubic is convex
    and increasing for mu > 0, so Newton started from an upper bound converges monotonically.
    """
    c2 = (-(GRAVITY / theta0) * cooling_rate_per_second / (coriolis**2 * friction_velocity)) ** 2
    inv_c2 = 1.0 / c_ns**2
    mu = np.minimum(np.cbrt(c2 / inv_c2), np.sqrt(c2 / a0))
    for _ in range(30):
        p = inv_c2 * mu**3 + a0 * mu**2 - c2
        dp = 3.0 * inv_c2 * mu**2 + 2.0 * a0 * mu
        d2p = 6.0 * inv_c2 * mu + 2.0 * a0
        # Halley's step: cubic convergence, and it stays above the root like Newton's here.
        denom = 2.0 * dp**2 - p * d2p
        step = np.divide(2.0 * p * dp, denom, out=np.zeros_like(mu), where=denom > 0)
        mu = mu - step
        if np.all(np.abs(step) <= 1e-14 * mu):
            break
    return mu


def secant_root(residual, lo, hi, tolerance=_SOLVER_TOLERANCE):
    """Element-wise roots of a smooth increasing residual over full arrays: the bracket
    [lo, hi] is widened (doubling) until it holds the sign change, then secant steps are
    taken, replaced by bisection whenever they leave the bracket. -inf in the residual marks
    points known to lie below the root. Returns (x, converged).

    Used for the GDL's u*, which a good start puts within ~0.1 % of the root, so a handful of
    whole-array steps beat a general method's per-element bookkeeping.
    """
    r_lo, r_hi = residual(lo), residual(hi)
    for _ in range(40):
        walk_lo, walk_hi = r_lo >= 0, r_hi < 0
        if not np.any(walk_lo | walk_hi):
            break
        width = hi - lo
        lo, hi = np.where(walk_lo, lo - width, lo), np.where(walk_hi, hi + width, hi)
        r_lo, r_hi = residual(lo), residual(hi)
    bracketed = (r_lo < 0) & (r_hi >= 0)
    x_prev, r_prev, x, r = lo, r_lo, hi, r_hi
    for _ in range(_SOLVER_MAX_ITERATIONS):
        if np.all(~bracketed | (np.abs(r) <= tolerance)):
            break
        with np.errstate(divide="ignore", invalid="ignore"):
            secant = x - r * (x - x_prev) / (r - r_prev)
        inside = np.isfinite(secant) & (secant > lo) & (secant < hi)
        x_prev, r_prev = x, r
        x = np.where(inside, secant, 0.5 * (lo + hi))
        r = residual(x)
        lo, hi = np.where(r < 0, x, lo), np.where(r < 0, hi, x)
    return x, bracketed & (np.abs(r) <= tolerance)


def chandrupatla_root(residual, lo, hi, args, tolerance):
    """Element-wise roots of an increasing residual that may kink: SciPy's vectorised
    bracket search from [lo, hi], then Chandrupatla's method; ``residual(x, *args)`` is
    called on the unconverged elements only. Returns (x, converged)."""
    bracket = elementwise.bracket_root(residual, lo, hi, args=args)
    xl, xr = bracket.bracket
    found = elementwise.find_root(
        residual, (np.where(bracket.success, xl, lo), np.where(bracket.success, xr, hi)),
        args=args, tolerances=dict(xatol=0.0, xrtol=4 * np.finfo(float).eps, fatol=tolerance),
    )
    return found.x, bracket.success & found.success


class EkmanABL:
    """Coupled Ekman-surface-layer atmospheric boundary layer, solved for given G.

    Keyword inputs (all broadcast together; conditions may be arrays):

    - ``geostrophic_wind`` G [m/s], > 0.
    - Coriolis: ``coriolis_parameter`` f_c [1/s] (signed: negative in the southern
      hemisphere) or ``latitude`` [deg, negative = south]; |latitude| >= 1 degree, i.e.
      |f_c| >= 2 Omega sin(1 deg): the model has no solution at the equator.
    - ``roughness_length`` z0 [m], > 0.
    - Stability, at most one of: ``stability_parameter`` mu = u*/(kappa f_c L) >= 0;
      ``cooling_rate`` C_r [K/h] <= 0 with Q0 = C_r h (paper Section 2.5);
      ``surface_heat_flux`` Q0 [K m/s] <= 0; ``obukhov_length`` L [m] > 0 (inf = neutral).
      Default: neutral (mu = 0). Unstable (heating) input is outside this model and raises.
    - Free atmosphere, at most one of ``brunt_vaisala_frequency`` N [1/s] >= 0 or
      ``lapse_rate`` dTheta/dz [K/m] >= 0 (N = sqrt(g/Theta0 gamma)); default the paper's
      N_inf = 6.1e-3 1/s. Enters through the Zilitinkevich number mu_N = N/|f_c|.
    - ``reference_potential_temperature`` Theta0 [K], default the paper's 265 K.
    - Model constants: ``von_karman`` 0.41, ``c_g`` 1.43, ``stress_decay`` (Gamma) 0.83,
      ``c_tn`` 0.5, ``c_cn`` 1.6, ``c_ns`` 0.78, ``matching_fraction`` 0.2.

    Solved attributes: ``friction_velocity`` [m/s], ``boundary_layer_height`` [m],
    ``cross_isobaric_angle`` [deg, signed, surface-stress frame], ``stability_parameter``
    (mu, also when derived from C_r, Q0 or L), ``zilitinkevich_number`` mu_N,
    ``geostrophic_components`` (U_g, V_g), ``coriolis_parameter`` (signed), and the
    dimensionless ``h_hat`` = h f_c/u* with the GDL coefficients ``gdl_a``, ``gdl_b`` (A, B).
    """

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
        brunt_vaisala_frequency=None,
        lapse_rate=None,
        reference_potential_temperature=PAPER_POTENTIAL_TEMPERATURE,
        von_karman=0.41,
        c_g=1.43,
        stress_decay=0.83,
        c_tn=0.5,
        c_cn=1.6,
        c_ns=0.78,
        matching_fraction=0.2,
    ):
        self._set_constants(von_karman, c_g, stress_decay, c_tn, c_cn, c_ns, matching_fraction)

        g_wind = finite("geostrophic_wind", geostrophic_wind)
        require(g_wind > 0, "geostrophic_wind", "> 0 m/s", g_wind)
        self.geostrophic_wind = g_wind
        self._set_coriolis(coriolis_parameter, latitude)

        z0 = finite("roughness_length", roughness_length)
        require(z0 > 0, "roughness_length", "> 0 m", z0)
        self.roughness_length = z0

        theta0 = finite("reference_potential_temperature", reference_potential_temperature)
        require(theta0 > 0, "reference_potential_temperature", "> 0 K", theta0)
        self.reference_potential_temperature = theta0
        self._set_free_atmosphere(brunt_vaisala_frequency, lapse_rate)
        self._set_stability_closure(
            stability_parameter, cooling_rate, surface_heat_flux, obukhov_length
        )
        self._solve()

    # ----------------------------------------------------------------------------- inputs
    def _set_constants(self, kappa, c_g, decay, c_tn, c_cn, c_ns, matching):
        for name, value in dict(
            von_karman=kappa, c_g=c_g, stress_decay=decay, c_tn=c_tn, c_cn=c_cn, c_ns=c_ns
        ).items():
            if not (np.isscalar(value) and np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive finite number; got {value!r}")
        if not (np.isscalar(matching) and 0.0 < matching < 1.0):
            raise ValueError(f"matching_fraction must be in (0, 1); got {matching!r}")
        self.von_karman, self.c_g, self.stress_decay = float(kappa), float(c_g), float(decay)
        self.c_tn, self.c_cn, self.c_ns = float(c_tn), float(c_cn), float(c_ns)
        self.matching_fraction = float(matching)

    def _set_coriolis(self, coriolis_parameter, latitude):
        if (coriolis_parameter is None) == (latitude is None):
            raise ValueError(
                "give exactly one of coriolis_parameter [1/s] or latitude [deg]; got "
                f"coriolis_parameter={coriolis_parameter!r}, latitude={latitude!r}"
            )
        if latitude is not None:
            f_c = coriolis_parameter_from_latitude(latitude)
        else:
            f_c = finite("coriolis_parameter", coriolis_parameter)
            f_min = 2.0 * EARTH_ROTATION_RATE * np.sin(np.deg2rad(MIN_ABS_LATITUDE))
            require(
                np.abs(f_c) >= f_min,
                "coriolis_parameter", f"|f_c| >= {f_min:.4g} 1/s (|latitude| >= 1 deg; the Ekman "
                "balance has no solution at the equator, f_c = 0)", f_c,
            )
        self.coriolis_parameter = f_c
        self._f = np.abs(f_c)
        self._hemisphere = np.sign(f_c)

    def _set_free_atmosphere(self, brunt_vaisala_frequency, lapse_rate):
        if brunt_vaisala_frequency is not None and lapse_rate is not None:
            raise ValueError(
                "give at most one of brunt_vaisala_frequency [1/s] or lapse_rate [K/m]"
            )
        if lapse_rate is not None:
            gamma = finite("lapse_rate", lapse_rate)
            require(
                gamma >= 0, "lapse_rate",
                ">= 0 K/m (a neutral or stably stratified free atmosphere)", gamma,
            )
            n_inf = np.sqrt(GRAVITY / self.reference_potential_temperature * gamma)
        else:
            if brunt_vaisala_frequency is None:
                brunt_vaisala_frequency = PAPER_BRUNT_VAISALA_FREQUENCY
            n_inf = finite("brunt_vaisala_frequency", brunt_vaisala_frequency)
            require(n_inf >= 0, "brunt_vaisala_frequency", ">= 0 1/s", n_inf)
        self.brunt_vaisala_frequency = n_inf
        self.zilitinkevich_number = n_inf / self._f

    def _set_stability_closure(self, mu, cooling_rate, heat_flux, obukhov_length):
        given = {
            name: value
            for name, value in zip(_STABILITY_INPUTS, (mu, cooling_rate, heat_flux, obukhov_length))
            if value is not None
        }
        if len(given) > 1:
            raise ValueError(
                "give at most one stability input among stability_parameter, cooling_rate, "
                f"surface_heat_flux, obukhov_length; got {sorted(given)}"
            )
        self.stability_input = next(iter(given), "stability_parameter")
        raw = given.get(self.stability_input, 0.0)
        value = np.asarray(raw, dtype=float)
        unstable = "unstable (convective) conditions are not covered by this model"
        # L = +inf is the neutral limit of the Obukhov length; everything else must be finite.
        neutral_obukhov = (value == np.inf) & (self.stability_input == "obukhov_length")
        require(np.isfinite(value) | neutral_obukhov, self.stability_input, "finite", value)
        valid, valid_range = {
            "stability_parameter": (value >= 0, ">= 0"),
            "cooling_rate": (value <= 0, "<= 0 K/h (surface cooling)"),
            "surface_heat_flux": (value <= 0, "<= 0 K m/s (downward heat flux)"),
            "obukhov_length": (value > 0, "> 0 m (stable; np.inf for neutral)"),
        }[self.stability_input]
        require(valid, self.stability_input, f"{valid_range}: {unstable}", value)
        self._stability_value = value

    # ----------------------------------------------------------------------------- solver
    def _closure_mu(self, u_star, p):
        """mu as a function of u* for the chosen stability input (docs/atmosphere.md#stability-closures)."""
        value, f, theta0 = p["value"], p["f"], p["theta0"]
        if self.stability_input == "stability_parameter":
            return value + 0.0 * u_star
        if self.stability_input == "surface_heat_flux":
            return -(GRAVITY / theta0) * value / (f * u_star**2)
        if self.stability_input == "obukhov_length":
            return u_star / (self.von_karman * f * value)
        a0 = 1.0 / self.c_tn**2 + p["mu_n"] / self.c_cn**2
        return stability_from_cooling_rate(value / 3600.0, u_star, f, theta0, a0, self.c_ns)

    def _state(self, log_u_star, p):
        """ABL state for trial ln u* and condition parameters p: (u*, mu, h_hat, A, B, ln Ro - A)."""
        u_star = np.exp(log_u_star)
        mu = self._closure_mu(u_star, p)
        h_hat = boundary_layer_height_hat(mu, p["mu_n"], self.c_tn, self.c_cn, self.c_ns)
        rossby = u_star / (p["f"] * p["z0"])
        a, b = gdl_coefficients(
            mu, p["mu_n"], h_hat, rossby, self.von_karman, self.c_g,
            self.stress_decay, self.matching_fraction,
        )
        return u_star, mu, h_hat, a, b, np.log(rossby) - a

    def _residual(self, log_u_star, p):
        """ln(|(U_g, V_g)| / G): zero at the GDL solution, increasing on the physical branch
        U_g > 0 (ln Ro > A); -inf below that branch."""
        _, _, _, _, b, along = self._state(log_u_star, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = log_u_star + 0.5 * np.log(along**2 + b**2) - np.log(self.von_karman * p["g"])
        return np.where(along > 0, r, -np.inf)

    def _failure(self, mask, reason):
        idx = tuple(np.argwhere(mask)[0])
        details = ", ".join(
            f"{name}={np.broadcast_to(np.asarray(value, float), mask.shape)[idx]:.6g}"
            for name, value in dict(
                geostrophic_wind=self.geostrophic_wind,
                coriolis_parameter=self.coriolis_parameter,
                roughness_length=self.roughness_length,
                **{self.stability_input: self._stability_value},
                brunt_vaisala_frequency=self.brunt_vaisala_frequency,
            ).items()
        )
        return ValueError(f"the ABL solve did not converge ({reason}) for inputs {details}")

    def _solve(self):
        params = dict(
            g=self.geostrophic_wind, f=self._f, z0=self.roughness_length,
            value=self._stability_value, mu_n=self.zilitinkevich_number,
            theta0=self.reference_potential_temperature,
        )
        shape = np.broadcast_shapes(*(np.shape(v) for v in params.values()))
        flat = {k: np.broadcast_to(v, shape).ravel() for k, v in params.items()}
        # A few steps of the contracting fixed-point form (rate ~ 1/(ln Ro - A) ~ 0.1) put
        # u* within ~0.1 %; bracketed secant steps then converge on the physical branch.
        log_kg = np.log(self.von_karman * flat["g"])
        x = log_kg + np.log(0.05)
        for _ in range(3):
            _, _, _, _, b, along = self._state(x, flat)
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
        u_star, _, h_hat, _, _, _ = self._state(x, flat)
        collapsed = self.matching_fraction * h_hat * u_star / flat["f"] <= flat["z0"]
        if np.any(collapsed):
            raise self._failure(
                collapsed.reshape(shape),
                "matching height matching_fraction * h at or below roughness_length z0: "
                "the stable boundary layer collapses",
            )
        self._params = {k: v.reshape(shape) for k, v in flat.items()}
        self._set_solution(x.reshape(shape), self._params)

    def _set_solution(self, log_u_star, p):
        u_star, mu, h_hat, a, b, along = self._state(log_u_star, p)
        kappa = self.von_karman
        self.friction_velocity = u_star[()]
        self.stability_parameter = np.asarray(mu, dtype=float)[()]
        self.h_hat = h_hat[()]
        self.gdl_a, self.gdl_b = a[()], b[()]
        self.boundary_layer_height = (h_hat * u_star / self._f)[()]
        u_g = u_star * along / kappa
        v_g = -self._hemisphere * u_star * b / kappa
        self.geostrophic_components = (u_g[()], v_g[()])
        self.cross_isobaric_angle = np.rad2deg(np.arctan2(v_g, u_g))[()]

    # ----------------------------------------------------------------------------- profiles
    def _heights(self, z, below_roughness):
        z = np.asarray(z, dtype=float)
        if below_roughness not in ("raise", "zero"):
            raise ValueError(f"below_roughness must be 'raise' or 'zero'; got {below_roughness!r}")
        under = z < self.roughness_length
        if below_roughness == "raise" and np.any(under):
            raise ValueError(
                "heights z must be >= roughness_length z0 (the log law is undefined below z0; "
                f"pass below_roughness='zero' for U = V = 0 there); got min z = {np.min(z):.6g} m"
            )
        return z, under

    def velocity(self, z, below_roughness="raise"):
        """(U, V)(z) [m/s] in the surface-stress frame, Eqs. (U_vel) and (V_vel).

        U: Monin-Obukhov law up to the matching height 0.2 h, Ekman layer up to h, U_g above;
        continuous at 0.2 h by construction of A (dU/dz jumps there). V: one expression on
        0 <= z <= h with V(0) = 0 exactly; where g(xi) >= 1 (z > 0.9973 h, since c_g > 1)
        the sqrt(1 - g^2) terms take their physical limit 0 (docs/atmosphere.md#lateral-velocity-near-the-abl-top). The slight
        backing of V near the ground is a property of the published formula and is kept.
        At z = z0, U = 0; for z < z0 raise (default) or return 0 with below_roughness='zero'.
        """
        z, under = self._heights(z, below_roughness)
        u_star, h_hat, f = self.friction_velocity, self.h_hat, self._f
        xi = z * f / u_star
        xi0 = self.roughness_length * f / u_star
        # z/h; the profile formulas live on [0, h]. Taken as z/h (not xi/h_hat) so that
        # z = h gives eta = 1 exactly: sqrt(1 - eta) would turn round-off into ~1e-8 of U.
        eta = np.clip(z / self.boundary_layer_height, 0.0, 1.0)
        g, dg = stress_shape(eta, h_hat, self.c_g, self.stress_decay)
        stress = (1.0 - eta) ** 1.5
        u_g = self.geostrophic_components[0]
        ekman_u = -dg * stress + 1.5 * g / h_hat * np.sqrt(1.0 - eta) + u_g / u_star
        most_slope = 5.0 * self.stability_parameter + 0.3 * self.zilitinkevich_number
        safe_xi = np.where(under, xi0, xi)
        surface_u = np.log(safe_xi / xi0) / self.von_karman + most_slope * (safe_xi - xi0)
        u = np.where(eta <= self.matching_fraction, surface_u, ekman_u) * u_star

        one_minus_g2 = 1.0 - g**2
        real = one_minus_g2 > 0
        root = np.sqrt(np.where(real, one_minus_g2, 1.0))
        # kappa V_g/u* = -B = -3 kappa/(2 h_hat): writing V_g through B makes V(0) = 0 exact.
        veer_terms = g * dg / root * stress + 1.5 / h_hat * (root * np.sqrt(1.0 - eta) - 1.0)
        v = self._hemisphere * u_star * np.where(real, veer_terms, -1.5 / h_hat)
        u = np.where(under, 0.0, u)
        v = np.where(under, 0.0, v)
        return u, v

    def wind_angle(self, z, below_roughness="raise"):
        """Mathematical flow angle atan2(V, U) [deg] in the surface-stress frame."""
        u, v = self.velocity(z, below_roughness)
        return np.rad2deg(np.arctan2(v, u))

    def hub_aligned_velocity(self, z, reference_height, below_roughness="raise"):
        """(U, V)(z) rotated so that V(reference_height) = 0 and U(reference_height) > 0.

        This is the frame of the wake model (docs/conventions.md#hub-aligned-frame): x along the wind at hub height.
        """
        u_ref, v_ref = self.velocity(reference_height)
        speed = np.hypot(u_ref, v_ref)
        cos_a, sin_a = u_ref / speed, v_ref / speed
        u, v = self.velocity(z, below_roughness)
        return u * cos_a + v * sin_a, v * cos_a - u * sin_a

    def speed(self, z, below_roughness="raise"):
        """Horizontal wind speed |(U, V)|(z) [m/s]."""
        return np.hypot(*self.velocity(z, below_roughness))

    def wind_direction_change(self, z1, z2):
        """Change of wind direction from z1 to z2 [deg], positive = veering (clockwise with
        height, as the meteorological direction increases). Northern-hemisphere Ekman
        layers veer with height, so this is positive there for z2 > z1."""
        return self.wind_angle(z1) - self.wind_angle(z2)

    def turbulence_intensity(self, z, reference_height=None, A1=TOWNSEND_PERRY_A1, B1=TOWNSEND_PERRY_B1):
        """Streamwise turbulence intensity I_u(z), Eq. (Iu_model).

        Normalised by the speed at ``reference_height`` (the paper's U_h) when given, else by
        the local speed |(U, V)(z)| (the two agree at the reference height). Above h the
        variance law is continued to its zero at h exp(B1/A1) and is zero higher up
        (docs/atmosphere.md#shallow-boundary-layer).
        """
        z = np.asarray(z, dtype=float)
        reference_speed = self.speed(z if reference_height is None else reference_height)
        self._heights(z, "raise")
        return streamwise_turbulence_intensity(
            z, self.friction_velocity, self.boundary_layer_height, reference_speed, A1, B1
        )

    def wake_expansion_rate(self, hub_height, **constants):
        """k_w at a hub height, Eq. (kw_CNBL_SBL_model), with U_h = |(U, V)(z_h)|.

        ``constants`` may override A1, B1, alpha_prime, floor and n. A hub at or above h takes
        the continued law (docs/atmosphere.md#shallow-boundary-layer): the floor from
        h exp(B1/A1) up.
        """
        return wake_expansion_rate(
            self.friction_velocity, self.boundary_layer_height, hub_height,
            self.speed(hub_height), **constants,
        )

    # ----------------------------------------------------------------------------- drivers
    @classmethod
    def from_reference_wind(cls, speed, height, tolerance=1e-13, **inputs):
        """Solve the ABL whose wind speed at ``height`` is ``speed`` (instead of giving G).

        FLORIS drives farms by the wind speed at a reference height; here G is found so that
        |(U, V)(height)| = speed, vectorised over arrays of speeds (and of other inputs), by
        SciPy's bracketed Chandrupatla iteration on ln G (see `chandrupatla_root`).
        """
        if "geostrophic_wind" in inputs:
            raise ValueError("from_reference_wind takes speed and height instead of geostrophic_wind")
        speed = finite("speed", speed)
        require(speed > 0, "speed", "> 0 m/s", speed)
        height = finite("height", height)
        if "roughness_length" in inputs:
            z0 = finite("roughness_length", inputs["roughness_length"])
            require(height > z0, "height", "above roughness_length", height)

        # Conditions repeat (a wind rose has few distinct speeds): solve each distinct
        # (speed, height, atmosphere) once.
        arrays = {k: np.asarray(v, float) for k, v in inputs.items() if np.ndim(v) > 0}
        shape = np.broadcast_shapes(np.shape(speed), np.shape(height), *map(np.shape, arrays.values()))
        columns = np.stack(
            [np.broadcast_to(a, shape).ravel() for a in (speed, height, *arrays.values())], axis=1
        )
        distinct, inverse = np.unique(columns, axis=0, return_inverse=True)
        scalars = {k: v for k, v in inputs.items() if k not in arrays}

        def log_speed_error(log_g, idx):
            row = distinct[idx]
            abl = cls(
                geostrophic_wind=np.exp(log_g), **scalars,
                **{k: row[:, 2 + i] for i, k in enumerate(arrays)},
            )
            return np.log(abl.speed(row[:, 1])) - np.log(row[:, 0])

        # U(height; G) is increasing but its log-slope ranges ~0.3 to ~5 and kinks where the
        # ABL top crosses the height: start the bracket search at G = speed.
        log_g0 = np.log(distinct[:, 0])
        log_g, converged = chandrupatla_root(
            log_speed_error, log_g0 - 0.1, log_g0 + 0.1, args=(np.arange(len(distinct)),),
            tolerance=tolerance,
        )
        if not np.all(converged):
            bad = distinct[~converged][0]
            raise ValueError(
                f"from_reference_wind found no ABL with speed {bad[0]:.6g} m/s at height "
                f"{bad[1]:.6g} m for the inputs {inputs!r}"
            )
        geostrophic_wind = np.exp(log_g)[inverse.ravel()].reshape(shape)
        return cls(geostrophic_wind=geostrophic_wind, **inputs)

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
        _, _, _, _, b, along = abl._state(np.log(u_star), abl._params)
        u_star = abl.von_karman * abl.geostrophic_wind / np.sqrt(along**2 + b**2)
    return u_star
