"""The wind and turbulence profiles of a solved Ekman-surface-layer ABL (paper Eqs. U_vel, V_vel,
Iu_model, kw_CNBL_SBL_model; docs/atmosphere.md): the mean wind (U, V)(z) with its roughness
sublayer, directions, speeds, the hub-aligned frame, the turbulence intensity and the wake
expansion rate, and the stability quantities the solved state implies (L, Q0, H, Ro).

`WindProfile` is the part of `EkmanABL` that reads a solved state: the attributes set by
`EkmanABL.set_state` (``friction_velocity``, ``boundary_layer_height``, ``h_hat``,
``stability_parameter``, ``geostrophic_components``, ``convective_variance``) and the inputs
(``roughness_length``, ``coriolis_magnitude``, ``hemisphere``, the model constants,
``turbulence_factor``).
"""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.atmosphere import stability_closures
from floris_ekman_veer.atmosphere.constants import air_heat_capacity
from floris_ekman_veer.atmosphere.inputs.input_ranges import checked, checked_turbulence_constants
from floris_ekman_veer.atmosphere.similarity import (
    stability_term,
    stress_shape,
    unstable_phi_m,
    unstable_psi_m,
)
from floris_ekman_veer.atmosphere.turbulence import (
    TOWNSEND_PERRY_A1,
    TOWNSEND_PERRY_B1,
    streamwise_turbulence_intensity,
    wake_expansion_rate,
)


class WindProfile:
    """The profiles and implied stability quantities of a solved ABL (the methods of
    `EkmanABL` that read its solved state; module docstring)."""

    #: The ambient turbulence over the model's I_u (an input of EkmanABL beyond the paper,
    #: docs/atmosphere.md#ambient-turbulence); None: the paper's I_u.
    turbulence_factor = None

    # ----------------------------------------------------------------------------- stability
    @property
    def obukhov_length(self):
        """L [m] = u*/(kappa f mu): > 0 stable, < 0 convective, inf neutral."""
        return stability_closures.obukhov_length(
            self.friction_velocity, self.coriolis_magnitude,
            np.asarray(self.stability_parameter, dtype=float), self.von_karman)[()]

    @property
    def surface_heat_flux(self):
        """The kinematic surface heat flux Q0 = -u*^3/(kappa (g/Theta0) L) [K m/s] (upward > 0)."""
        return stability_closures.surface_heat_flux(
            self.stability_parameter, self.coriolis_magnitude, self.friction_velocity,
            self.reference_potential_temperature)[()]

    @property
    def sensible_heat_flux(self):
        """The surface sensible heat flux H = rho c_p Q0 [W/m^2] (upward > 0; `air_heat_capacity`)."""
        return (self.surface_heat_flux * air_heat_capacity(self.reference_potential_temperature))[()]

    @property
    def friction_rossby_number(self):
        """Ro = u*/(|f_c| z0), the paper's Table 1 friction Rossby number."""
        return (self.friction_velocity / (self.coriolis_magnitude * self.roughness_length))[()]

    # ----------------------------------------------------------------------------- profiles
    @property
    def roughness_sublayer_height(self):
        """z_s [m], the top of the roughness sublayer (docs/atmosphere.md#roughness-sublayer).

        The height where the tangent of the surface-layer law U(z) passes through the ground,
        z_s = z0 exp(1 + kappa (5 mu + 0.3 mu_N) z0 f_c/u*) (about e z0), capped at the matching
        height matching_fraction * h (reached only by a boundary layer near collapse). In a
        convective layer the tangent condition ln(z_s/z0) = phi_m(z_s/L) + psi_m(z_s/L)
        - psi_m(z0/L) + 0.3 kappa mu_N z0 f_c/u* is solved by fixed-point steps from e z0.
        """
        mu = np.asarray(self.stability_parameter, dtype=float)
        most_slope = 5.0 * np.maximum(mu, 0.0) + 0.3 * self.zilitinkevich_number
        xi0 = self.roughness_length * self.coriolis_magnitude / self.friction_velocity
        # (exponent capped where z_s would be > e^50 z0: far above the matching height anyway)
        tangent = self.roughness_length * np.exp(np.minimum(1.0 + self.von_karman * most_slope * xi0, 50.0))
        if np.any(mu < 0):
            # phi_m + psi_m varies slowly (1 at neutral), so these steps contract fast.
            inverse_l = self.von_karman * np.minimum(mu, 0.0) * self.coriolis_magnitude / self.friction_velocity
            gamma, z0 = self.businger_dyer_gamma, self.roughness_length
            offset = 0.3 * self.von_karman * self.zilitinkevich_number * xi0 - unstable_psi_m(
                z0 * inverse_l, gamma)
            z_s = tangent
            for _ in range(30):
                zeta = z_s * inverse_l
                z_s = z0 * np.exp(np.minimum(
                    unstable_phi_m(zeta, gamma) + unstable_psi_m(zeta, gamma) + offset, 50.0))
            tangent = np.where(mu < 0, z_s, tangent)
        return np.minimum(tangent, self.matching_fraction * self.boundary_layer_height)

    def _heights(self, z, name, ok=lambda z: z >= 0, valid=">= 0 m (at or above the ground)"):
        return checked(name, z, ok, valid)

    def _direction_heights(self, z, name):
        return self._heights(z, name, lambda z: z > 0, "> 0 m (the wind has no direction at the ground)")

    def velocity(self, z):
        """(U, V)(z) [m/s] in the surface-stress frame, Eqs. (U_vel) and (V_vel); heights z >= 0.

        U: Monin-Obukhov law up to the matching height 0.2 h, Ekman layer up to h, U_g above;
        continuous at 0.2 h by construction of A (dU/dz jumps there). V: one expression on
        0 <= z <= h, V_g above; where g(xi) >= 1 (z > 0.9973 h, since c_g > 1)
        the sqrt(1 - g^2) terms take their physical limit 0 (docs/atmosphere.md#lateral-velocity-near-the-abl-top). The slight
        backing of V near the ground is a property of the published formula and is kept.

        Roughness sublayer (docs/atmosphere.md#roughness-sublayer): below z_s =
        `roughness_sublayer_height` (about e z0, where the log law's tangent passes through the
        ground) the wind is (z/z_s) (U, V)(z_s): zero at the ground, positive for z > 0, U
        continuous with its slope at z_s, the direction that of z_s. The log law alone would
        give U = 0 at z0 while V(z0) != 0, hence a wind at right angles to the surface stress
        and U < 0 below z0.
        """
        return self._velocity(self._heights(z, "z"))

    def _velocity(self, z):
        u_star, h_hat = self.friction_velocity, self.h_hat
        z_s = self.roughness_sublayer_height
        # Heights all above every condition's sublayer (rotor heights): scale 1, nothing to
        # replace (u * 1.0 is u exactly), without the full-size mask and quotient.
        scale = None
        if not np.min(z, initial=np.inf) >= np.max(z_s):
            sublayer = z < z_s
            scale = np.where(sublayer, z / z_s, 1.0)
            z = np.where(sublayer, z_s, z)
        xi = z * self.coriolis_magnitude / u_star
        xi0 = self.roughness_length * self.coriolis_magnitude / u_star
        # z/h; the profile formulas live on [0, h]. Taken as z/h (not xi/h_hat) so that
        # z = h gives eta = 1 exactly: sqrt(1 - eta) would turn round-off into ~1e-8 of U.
        eta = np.minimum(z / self.boundary_layer_height, 1.0)
        g, dg = stress_shape(eta, h_hat, self.c_g, self.stress_decay)
        # 1 - eta and its root once (U and V both take them: the same numbers, fewer passes).
        depth = 1.0 - eta
        stress = np.power(depth, 1.5)
        depth_root = np.sqrt(depth)
        u_g = self.geostrophic_components[0]
        # The sums below are accumulated in place, term by term in the order written
        # (-dg stress + 1.5 g / h_hat sqrt(1 - eta) + U_g/u*): the same roundings, fewer arrays.
        ekman_u = -dg * stress
        ekman_u += 1.5 * g / h_hat * depth_root
        ekman_u += u_g / u_star
        surface_u = np.log(xi / xi0)
        surface_u /= self.von_karman
        surface_u += stability_term(self.stability_parameter, xi, xi0, self.von_karman,
                                    self.businger_dyer_gamma)
        surface_u += 0.3 * self.zilitinkevich_number * (xi - xi0)
        u = np.where(eta <= self.matching_fraction, surface_u, ekman_u)
        u *= u_star

        one_minus_g2 = 1.0 - g**2
        real = one_minus_g2 > 0
        # (g < 1 everywhere but within 0.3 % of h below the top: no masking needed there)
        everywhere = bool(np.all(real))
        root = np.sqrt(one_minus_g2 if everywhere else np.where(real, one_minus_g2, 1.0))
        # kappa V_g/u* = -B = -3 kappa/(2 h_hat): writing V_g through B makes V(0) = 0 exact.
        veer_terms = g * dg / root * stress
        veer_terms += 1.5 / h_hat * (root * depth_root - 1.0)
        v = self.hemisphere * u_star * (veer_terms if everywhere
                                         else np.where(real, veer_terms, -1.5 / h_hat))
        return (u, v) if scale is None else (u * scale, v * scale)

    def wind_angle(self, z):
        """Mathematical flow angle atan2(V, U) [deg] in the surface-stress frame (z > 0)."""
        return self._wind_angle(z, "z")

    def _wind_angle(self, z, name):
        u, v = self._velocity(self._direction_heights(z, name))
        return np.rad2deg(np.arctan2(v, u))

    def hub_frame(self, reference_height):
        """(cos a, sin a) of the wind's angle a at ``reference_height`` (> 0) in the
        surface-stress frame: the rotation of :meth:`hub_aligned_velocity`, to compute once for
        many evaluations at the same reference height."""
        u_ref, v_ref = self._velocity(self._direction_heights(reference_height, "reference_height"))
        speed = np.hypot(u_ref, v_ref)
        return u_ref / speed, v_ref / speed

    def hub_aligned_velocity(self, z, reference_height, frame=None):
        """(U, V)(z) rotated so that V(reference_height) = 0 and U(reference_height) > 0.

        This is the frame of the wake model (docs/conventions.md#hub-aligned-frame): x along the
        wind at hub height. Heights z >= 0; reference_height > 0. ``frame``: the rotation
        :meth:`hub_frame` gives for ``reference_height`` (then not computed again).
        """
        cos_a, sin_a = self.hub_frame(reference_height) if frame is None else frame
        u, v = self.velocity(z)
        return u * cos_a + v * sin_a, v * cos_a - u * sin_a

    def speed(self, z):
        """Horizontal wind speed |(U, V)|(z) [m/s], heights z >= 0."""
        return np.hypot(*self.velocity(z))

    def wind_direction_change(self, z1, z2):
        """Change of wind direction from z1 to z2 [deg], positive = veering (clockwise with
        height, as the meteorological direction increases). Northern-hemisphere Ekman
        layers veer with height, so this is positive there for z2 > z1."""
        return self._wind_angle(z1, "z1") - self._wind_angle(z2, "z2")

    def _log_layer_heights(self, z, name):
        return self._heights(
            z, name, lambda z: z >= self.roughness_length,
            ">= roughness_length z0 (the Townsend-Perry law holds above the roughness)",
        )

    def turbulence_intensity(self, z, reference_height=None, A1=TOWNSEND_PERRY_A1, B1=TOWNSEND_PERRY_B1):
        """Streamwise turbulence intensity I_u(z), Eq. (Iu_model), for z >= z0.

        Normalised by the speed at ``reference_height`` (the paper's U_h) when given, else by
        the local speed |(U, V)(z)| (the two agree at the reference height). Above h the
        variance law is continued to its zero at h exp(B1/A1) and is zero higher up
        (docs/atmosphere.md#shallow-boundary-layer). Times ``turbulence_factor`` where the ABL
        was given one (docs/atmosphere.md#ambient-turbulence).
        """
        z = self._log_layer_heights(z, "z")
        A1, B1 = checked_turbulence_constants(A1=A1, B1=B1).values()
        if reference_height is None:
            reference_speed = np.hypot(*self._velocity(z))
        else:
            reference_speed = np.hypot(
                *self._velocity(self._log_layer_heights(reference_height, "reference_height"))
            )
        return streamwise_turbulence_intensity(
            z, self.friction_velocity, self.boundary_layer_height, reference_speed, A1, B1,
            self.convective_variance, self.turbulence_factor,
        )

    def wake_expansion_rate(self, hub_height, **constants):
        """k_w at a hub height, Eq. (kw_CNBL_SBL_model), with U_h = |(U, V)(z_h)|.

        ``constants`` may override A1, B1, alpha_prime, floor and n. A hub at or above h takes
        the continued law (docs/atmosphere.md#shallow-boundary-layer): the floor from
        h exp(B1/A1) up. Raises ValueError for a hub below the roughness length.
        """
        hub_height = self._log_layer_heights(hub_height, "hub_height")
        constants = checked_turbulence_constants(**constants)
        return wake_expansion_rate(
            self.friction_velocity, self.boundary_layer_height, hub_height,
            np.hypot(*self._velocity(hub_height)), convective=self.convective_variance,
            turbulence_factor=self.turbulence_factor, **constants,
        )
