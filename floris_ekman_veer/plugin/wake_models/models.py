"""FLORIS wake models: thin wrappers of the pure functions in :mod:`floris_ekman_veer.wake`.

* ``EkmanVeerVelocityDeficit`` (registered as ``ekman_veer``): the paper's Eq. (du_model) with
  the curled, polar-angle dependent width (M-1; M-2 when the deflection model's veer is off).
* ``EkmanVeerVelocityDeflection`` (``ekman_veer``): y_c(x, z) of Eq. (yc_xz), yaw (CVP with
  ground image) plus veer, at every grid point: it varies with height, which is how veer shears
  the wake (defined in plugin/wake_models/deflection_model.py, read from here with the velocity models).
* ``Gaussian2014VelocityDeficit`` (``bastankhah2014``): the paper's M-3 (docs/wake_model.md#m-3).

Conventions (docs/conventions.md, docs/coupling.md), each pinned by tests:

* FLORIS's positive yaw sends the wake to -y, as the paper's positive beta: the yaw angle is
  passed unchanged (in radians) as beta.
* FLORIS hands the wake model ``ct_i``, for its cosine-loss (and this package's actuator-disk)
  operation model C_T cos(yaw); the paper's formulas take the un-yawed C_T and apply cos^2 and
  cos^3 themselves, so C_T = ct_i / cos(yaw) (otherwise yaw would be counted twice).
* Momentum theory, on which Eqs. (A_star), (ind_factor) and (Cx) rest, fails for heavily loaded
  rotors (C_T cos^2 beta -> 1 and beyond, e.g. the NREL 5 MW below 4 m/s). The wake is then
  evaluated at ``max_thrust_coefficient`` (default 0.96, i.e. a = 0.4, where the Glauert
  correction takes over from momentum theory) and a ``RuntimeWarning`` says so: a documented,
  deliberate limit rather than NaN. |yaw| >= 90 degrees raises ValueError.
* U_h is the ambient hub-height speed of the turbine's own hub height; U(z), V(z) are the ambient
  profile in the turbine's hub-aligned frame (V(z_h) = 0), docs/conventions.md#hub-aligned-frame and docs/wake_model.md#which-velocity-goes-where. FLORIS's frame
  is aligned with the wind at its reference height; for a hub at another height the profile is
  rotated by the direction difference (a few tenths of a degree across typical hub heights).
* The deficit is returned relative to the local inflow: FLORIS multiplies it by
  ``u_initial`` = U(z), so (Delta u / U_h) U_h / U(z) is returned. Where the inflow vanishes
  (heights at or below the roughness length) there is no flow and no wake: 0 is returned.
* Inputs are never mutated.
"""

from __future__ import annotations

import warnings
from abc import abstractmethod
from typing import Any

import numpy as np
from attrs import define, field
from floris.core import BaseModel, FlowField, Grid

from floris_ekman_veer._validation import boolean_field, choice_field, number_field
from floris_ekman_veer.atmosphere.turbulence import (
    ALPHA_PRIME,
    MERGE_EXPONENT,
    MIXING_LAYER_FLOOR,
    TOWNSEND_PERRY_A1,
    TOWNSEND_PERRY_B1,
    streamwise_turbulence_intensity,
    wake_expansion_rate,
)
from floris_ekman_veer.plugin.inflow.ambient import Ambient
from floris_ekman_veer.plugin.wake_models.deflection_model import EkmanVeerVelocityDeflection
from floris_ekman_veer.plugin.wake_models.names import GAUSSIAN_2014_NAME, VELOCITY_MODEL_NAME
from floris_ekman_veer.plugin.rotor.rotor import (
    DEFICIT_VELOCITIES,
    ROTOR_PLANE_MARGIN,
    TURBULENCE_OVERLAPS,
    WAKE_EXPANSIONS,
    WAKE_TURBULENCES,
    WAKE_MODELS,
    RotorWakes,
    TurbineWake,
    rotor_cell_deficit,
)
from floris_ekman_veer.plugin.inflow.shallow import POLICIES as SHALLOW_POLICIES
from floris_ekman_veer.plugin.rotor.rotor_wakes import WAKE_SUPERPOSITIONS
from floris_ekman_veer.plugin.rotor.turbine_states import handed as handed_turbine_states
from floris_ekman_veer.plugin.wake_models.wake_inputs import (
    GLAUERT_THRUST_COEFFICIENT,
    MERGE_EXPONENT_RANGE,
    NON_NEGATIVE,
    POSITIVE,
    THRUST_LIMIT_RANGE,
    from_input_block,
    unyawed_thrust_coefficient,
)
from floris_ekman_veer.wake.deficit import (
    CURL_ALPHA,
    WIDTH_FACTOR,
    axial_induction,
    max_deficit,
    normalised_deficit,
    stream_tube_area_ratio,
)
from floris_ekman_veer.wake.deflection import veer_deflection
from floris_ekman_veer.wake.fused import (
    GAUSSIAN_SHAPE,
    WAKE_TABLE,
    wake_deficit_parameters,
    wake_table,
)
from floris_ekman_veer.wake.gaussian2014 import bastankhah2014_deficit, bastankhah2014_wake
from floris_ekman_veer.wake.near_wake import NEAR_WAKES, near_wake_shape
from floris_ekman_veer.wake.superposition import cumulative_deficit, overlap_weight

__all__ = ["EkmanVeerVelocityDeficit", "EkmanVeerVelocityDeflection", "EkmanWakeModel",
           "Gaussian2014VelocityDeficit"]


@define
class EkmanWakeModel(BaseModel):
    """Parameters shared by the velocity models that draw on the Ekman atmosphere, and their
    integration over the rotor cells (plugin/rotor/rotor.py); plugin/floris_hooks/solver.py runs the solver of the
    models of this class."""

    #: The atmosphere (EkmanABL inputs without the wind speed). It is read and validated by the
    #: inflow hook, which also drives FLORIS's inflow with it; see floris_ekman_veer.plugin.inflow.inflow.
    atmosphere: dict | None = field(default=None)
    A1: float = number_field(TOWNSEND_PERRY_A1, *POSITIVE)
    B1: float = number_field(TOWNSEND_PERRY_B1, *NON_NEGATIVE)
    alpha_prime: float = number_field(ALPHA_PRIME, *POSITIVE)
    k_w_floor: float = number_field(MIXING_LAYER_FLOOR, *POSITIVE)
    k_w_exponent: float = number_field(MERGE_EXPONENT, *MERGE_EXPONENT_RANGE)
    #: "ambient": k_w from the ABL's I_u(z_h), Eq. (kw_CNBL_SBL_model), as in the paper.
    #: "local_turbulence": the same with FLORIS's wake-added turbulence at the turbine (from its
    #: turbulence model, the largest of the upstream wakes' as FLORIS combines it) added in
    #: quadrature to I_u(z_h) (see expansion_rate). "array_turbulence" (the default): the
    #: upstream wakes' added turbulence intensities summed in quadrature, their variances
    #: adding (docs/coupling.md#wakes-deep-in-an-array). An unwaked rotor gets the paper's k_w
    #: with each.
    wake_expansion: str = choice_field("array_turbulence", WAKE_EXPANSIONS)
    #: The velocity a waked rotor's wake deficit C(x) scales with: "incoming" (the default,
    #: Niayifar & Porte-Agel 2016) its rotor-averaged incoming speed, with the deficits summed
    #: (FLORIS's combination ``fls``); "free_stream" the ambient U_h, as FLORIS's gauss
    #: (docs/coupling.md#wakes-deep-in-an-array). An unwaked rotor's wake is the paper's with each.
    deficit_velocity: str = choice_field("incoming", DEFICIT_VELOCITIES)
    #: The part of a rotor a wake's added turbulence is weighted with (turbine grid):
    #: "wake_radius" (the default), the area inside the wake radius 2 sigma (Niayifar &
    #: Porte-Agel 2016), or "wake_velocity", the area where the wake's velocity exceeds 0.05 m/s
    #: (FLORIS's count) (docs/coupling.md#wakes-deep-in-an-array).
    turbulence_overlap: str = choice_field("wake_radius", TURBULENCE_OVERLAPS)
    #: The form of a wake's added turbulence (turbine grid): "crespo_hernandez" (the default),
    #: FLORIS's turbulence model weighted with ``turbulence_overlap``; "ishihara_qian", Ishihara
    #: & Qian (2018, wake/added_turbulence.py) averaged over the rotor, its ring-shaped profile
    #: its own overlap (docs/coupling.md#wakes-deep-in-an-array).
    wake_turbulence: str = choice_field("crespo_hernandez", WAKE_TURBULENCES)
    #: How the wakes superpose (docs/coupling.md#wakes-deep-in-an-array): "cumulative" (the
    #: default), the cumulative wake of Bastankhah et al. (2021, wake/superposition.py): each
    #: wake's centre deficit carries its rotor's thrust through the upstream wakes there, at
    #: each height of the rotor, the deficits summed (with FLORIS's ``fls``; with another
    #: combination each wake is combined by it alone); "combination_model", FLORIS's
    #: combination model point-wise with C(x) scaled by ``deficit_velocity``;
    #: "momentum_conserving", Zong & Porte-Agel (2020, plugin/rotor/convection.py; turbine grid
    #: only), with ``fls``.
    wake_superposition: str = choice_field("cumulative", WAKE_SUPERPOSITIONS)
    max_thrust_coefficient: float = number_field(GLAUERT_THRUST_COEFFICIENT, *THRUST_LIMIT_RANGE)
    #: Conditions with a rotor top above h: "warn" (counted in a ShallowBoundaryLayerWarning)
    #: or "raise"; read by the inflow hook when the model is built (plugin/inflow/shallow.py).
    shallow_boundary_layer: str = choice_field("warn", SHALLOW_POLICIES)

    #: Where the block sits in a FLORIS input (error messages name it).
    input_path = f"wake.wake_velocity_parameters.{VELOCITY_MODEL_NAME}"
    from_dict = classmethod(from_input_block)

    def expansion_rate(self, abl, hub_height, hub_speed, turbulence_intensity,
                       floris_turbulence):
        """k_w of the wake, Eq. (kw_CNBL_SBL_model) or its wake-added-turbulence variants.

        ``turbulence_intensity`` is the turbulence at the turbine, TI_0 plus the upstream wakes'
        added turbulence (on a turbine grid the rotor cells' own, the wakes' overlaps as areas,
        the largest wake's for "local_turbulence" and all of them in quadrature for
        "array_turbulence": plugin/rotor/rotor.py ``RotorWakes``; elsewhere FLORIS's), with
        ``floris_turbulence`` its ambient TI_0. Both keep the paper's ambient I_u(z_h) and add
        the wake-added part: I^2 = I_u^2 + max(TI^2 - TI_0^2, 0), so an unwaked turbine gets the
        paper's k_w exactly, whatever TI_0 FLORIS was given
        (docs/coupling.md#wake-expansion-in-farms). The ambient I_u(z_h) is scaled by the
        atmosphere's ``turbulence_factor`` where it has one (a site's measured turbulence,
        docs/atmosphere.md#ambient-turbulence).
        """
        if self.wake_expansion == "ambient":
            return wake_expansion_rate(
                abl.friction_velocity, abl.boundary_layer_height, hub_height, hub_speed,
                A1=self.A1, B1=self.B1, alpha_prime=self.alpha_prime, floor=self.k_w_floor,
                n=self.k_w_exponent, convective=abl.convective_variance,
                turbulence_factor=abl.turbulence_factor,
            )
        ambient = streamwise_turbulence_intensity(
            hub_height, abl.friction_velocity, abl.boundary_layer_height, hub_speed, self.A1,
            self.B1, abl.convective_variance, abl.turbulence_factor,
        )
        added_squared = np.maximum(
            np.asarray(turbulence_intensity, dtype=float) ** 2 - floris_turbulence**2, 0.0
        )
        turbulent = self.alpha_prime * np.sqrt(ambient**2 + added_squared)
        return (self.k_w_floor**self.k_w_exponent + turbulent**self.k_w_exponent) ** (
            1.0 / self.k_w_exponent
        )

    def prepare_function(self, grid: Grid, flow_field: FlowField) -> dict[str, Any]:
        ambient = Ambient.of(grid, flow_field)
        wakes = None
        # FLORIS's wake models only if they are the ones calling this model.
        wake_models = WAKE_MODELS.get()
        if wake_models is not None and wake_models.velocity_model is not self:
            wake_models = None
        if ambient.rotor is not None:
            # A fresh superposition per solve (plugin/rotor/rotor.py).
            wakes = RotorWakes.start(ambient.rotor.cells, *ambient.rotor.x.shape, wake_models,
                                     ambient.floris_turbulence, self.wake_superposition)
        return {
            "x": grid.x_sorted,
            "y": grid.y_sorted,
            "z": grid.z_sorted,
            "u_initial": flow_field.u_initial_sorted,
            "ambient": ambient,
            "wakes": wakes,
            # Other grids: the turbine grid's rotor states, when the solve hands them
            # (plugin/rotor/turbine_states.py, docs/coupling.md#one-physics-on-every-grid).
            "states": None if ambient.rotor is not None else handed_turbine_states(),
            # Other grids with the cumulative wake: the upstream wakes' centre deficits, widths
            # and centres at every point, appended wake by wake (:meth:`_cumulative_scale`).
            "upstream": [] if ambient.rotor is None and self._cumulative(wake_models) else None,
        }

    def _cumulative(self, wake_models) -> bool:
        """Whether the cumulative wake runs: ``wake_superposition: cumulative`` with FLORIS's
        ``fls`` (with another combination each wake is combined by it alone)."""
        return (self.wake_superposition == "cumulative" and wake_models is not None
                and type(wake_models.combination_model).__name__ == "FLS")

    def function(
        self,
        x_i: np.ndarray,
        y_i: np.ndarray,
        z_i: np.ndarray,
        axial_induction_i: np.ndarray,
        deflection_field_i: np.ndarray,
        yaw_angle_i: np.ndarray,
        turbulence_intensity_i: np.ndarray,
        ct_i: np.ndarray,
        hub_height_i: np.ndarray,
        rotor_diameter_i: np.ndarray,
        *,
        x: np.ndarray,
        y: np.ndarray,
        z: np.ndarray,
        u_initial: np.ndarray,
        ambient: Ambient,
        wakes: RotorWakes | None = None,
        states=None,
        upstream: list | None = None,
    ) -> np.ndarray:
        """FLORIS's velocity-model call: Delta u / u_initial of turbine i's wake at the grid.

        On a turbine grid, the rotor-cell deficit d_k of each point (docs/coupling.md#rotor-average);
        on other grids (planes, points, cubature), the point value, with the turbine grid's
        rotor states where the solve hands them (``states``, plugin/rotor/turbine_states.py).
        """
        abl = ambient.abl
        yaw = np.deg2rad(yaw_angle_i)
        ct = self.wake_thrust_coefficient(ct_i, yaw)
        if ambient.rotor is not None:
            return rotor_cell_deficit(
                self, x_i, y_i, hub_height_i, deflection_field_i, yaw, ct,
                0.5 * rotor_diameter_i, turbulence_intensity_i, axial_induction_i, u_initial,
                ambient, wakes,
            )
        hub_speed, local_u, local_v = ambient.at_hub(hub_height_i)
        # One expansion rate per wake, from its rotor's mean turbulence (FLORIS's cubature
        # grids carry the turbulence per point), and C(x) scaled with the free stream, unless
        # the turbine grid's solve hands its rotors' array turbulence and incoming speeds.
        turbulence = np.mean(turbulence_intensity_i, axis=(2, 3), keepdims=True)
        speed_fraction = 1.0
        if states is not None:
            fraction, tracked = states.at(x_i, y_i)
            if self.deficit_velocity == "incoming":
                speed_fraction = fraction
            if self.wake_expansion == "array_turbulence":
                turbulence = tracked
        dx = x - x_i
        wake = TurbineWake(
            dx=np.where(dx > ROTOR_PLANE_MARGIN, dx, 0.0),  # dx = 0 means "no wake"
            dy=y - y_i - deflection_field_i,
            dz=z - hub_height_i,
            yaw=yaw,
            ct=ct,
            radius=0.5 * rotor_diameter_i,
            hub_speed=hub_speed,
            k_w=self.expansion_rate(abl, hub_height_i, hub_speed, turbulence,
                                    ambient.floris_turbulence),
            local_u=local_u,
            local_v=local_v,
            friction_velocity=abl.friction_velocity,
        )
        if ambient.cubature_points is not None:
            self._check_cubature(wake, deflection_field_i, ambient)
        deficit = self.normalised_deficit(wake)
        scale = hub_speed * speed_fraction
        if upstream is not None:
            fraction = 1.0 if states is None else states.at(x_i, y_i)[0]
            scale = self._cumulative_scale(wake, y_i + deflection_field_i, hub_height_i,
                                           hub_speed * fraction, upstream)
        # FLORIS multiplies the returned deficit by u_initial: return Delta u / u_initial. Where
        # there is no inflow (at and below z0) there is no wake. A wake at most stops the flow:
        # where the Gaussian's tail, scaled by U_h, reaches an inflow slower than itself (next to
        # the ground, where U(z) -> 0) Delta u is limited to U(z) (docs/wake_model.md#which-velocity-goes-where).
        flowing = (u_initial > 0) & (local_u > 0)
        safe_u = np.where(flowing, u_initial, 1.0)
        return np.where(flowing, np.minimum(deficit * scale / safe_u, 1.0), 0.0)

    def _cumulative_scale(self, wake: TurbineWake, centre_y, centre_z, incoming_speed,
                          upstream: list):
        """C_n / C(x) at the points of a grid other than the turbine grid: the cumulative wake's
        centre deficit (Bastankhah et al. 2021, wake/superposition.py) over the model's own, with
        the upstream wakes of ``upstream`` at each point; this wake is appended to it (0 where
        the points are not downstream). The turbine grid does the same per rotor
        (plugin/rotor/convection.py)."""
        args = (wake.dx, wake.k_w, wake.radius, wake.ct, wake.yaw)
        single = self.centre_deficit(*args)
        table = self.kernel_table(*args, wake.friction_velocity, wake.hub_speed)
        width_squared = (table["kx"] + table["xi0"]) ** 2
        overlap = sum((overlap_weight(width_squared, w, (centre_y - y) ** 2 + (centre_z - z) ** 2)
                       * c for c, w, y, z in upstream), np.zeros_like(single))
        deficit = cumulative_deficit(single, wake.hub_speed, incoming_speed, overlap,
                                     self.core_deficit(wake.ct, wake.yaw) * incoming_speed)
        deficit = np.where(wake.dx > 0.0, deficit, 0.0)
        upstream.append((deficit, width_squared, centre_y, centre_z))
        return deficit / np.where(single > 0.0, single, 1.0)

    def wake_thrust_coefficient(self, ct_i, yaw):
        """The thrust coefficient the model's formulas take: the paper's un-yawed-basis C_T."""
        return unyawed_thrust_coefficient(ct_i, yaw, self.max_thrust_coefficient)

    @abstractmethod
    def kernel_table(self, x, k_w, radius, ct, yaw, friction_velocity, hub_speed) -> dict:
        """The deficit's factors that depend on the wake only, for the rotor-cell kernel
        (plugin/rotor/rotor_kernel.py ``WAKE_COLUMNS``: Delta u / U_h = amplitude
        exp(-(rho^2 / (2 sigma^2))^(shape / 2)) with sigma = kx + xi0 xi_hat(theta) /
        sqrt(1 - sin2b sin^2 theta), xi_hat of Eq. xi_emp with t_hat's prefactor ``strength``),
        per wake and rotor reached (1-D arrays or scalars); each model defines them, as FLORIS's
        BaseModel leaves ``prepare_function`` and ``function`` to its models."""

    def wake_table(self, x, k_w, radius, ct, yaw, friction_velocity, hub_speed,
                   bound_only=False) -> np.ndarray:
        """(pairs, wake/fused.py ``WAKE_TABLE``): :meth:`kernel_table`'s columns, then
        :meth:`width_bound`, :meth:`amplitude_bound` and :meth:`centre_deficit`, per wake and
        rotor (1-D arrays ``x`` > 0, the rest per pair): what the rotor cells take of the model
        (plugin/rotor/rotor.py) in one table. With ``bound_only`` a model may leave costly
        columns for later (``shape`` wake/fused.py DEFERRED_ORDER) where its bounds still
        hold, its other rows exact: the deferred rows of the rotors kept are evaluated
        again."""
        table = self.kernel_table(x, k_w, radius, ct, yaw, friction_velocity, hub_speed)
        table = {**table, "width_bound": self.width_bound(x, k_w, radius, ct, yaw),
                 "amplitude_bound": self.amplitude_bound(x, k_w, radius, ct, yaw),
                 "centre_deficit": self.centre_deficit(x, k_w, radius, ct, yaw)}
        return np.stack([np.broadcast_to(table[k], np.shape(x)) for k in WAKE_TABLE], axis=1)

    def amplitude_bound(self, x, k_w, radius, ct, yaw):
        """The largest deficit Delta u / U_h of the wake at x: C(x), Eq. (Cx)."""
        return max_deficit(x, k_w, radius, ct, yaw)

    def centre_deficit(self, x, k_w, radius, ct, yaw):
        """Delta u / U_h at the wake's centre at x: C(x), Eq. (Cx)."""
        return max_deficit(x, k_w, radius, ct, yaw)

    def core_deficit(self, ct, yaw):
        """The potential core's deficit 2a / U_n, the cumulative wake's bound
        (wake/superposition.py): a of Eq. (ind_factor) behind the yawed rotor."""
        return 2.0 * axial_induction(ct, yaw)

    def width_bound(self, x, k_w, radius, ct, yaw):
        """An upper bound of the wake width sigma(theta, x) over all polar angles [m]."""
        r_tube = radius * np.sqrt(stream_tube_area_ratio(ct, yaw))
        return k_w * x + WIDTH_FACTOR * r_tube * (1.0 + CURL_ALPHA)

    def _check_cubature(self, wake, deflection_field, ambient):
        """Warn once per solve when, on a cubature grid (point values), a wake band within reach
        of a rotor is thinner than the spacing of its points, 2 R / N."""
        if "cubature" in ambient.warned:
            return
        downstream = wake.dx[..., 0, 0] > 0.0  # (n_findex, n_turbines)
        if not np.any(downstream):
            return
        radius = np.broadcast_to(wake.radius[..., 0, 0], downstream.shape)
        width = self.width_bound(wake.dx[..., 0, 0], wake.k_w[..., 0, 0], radius,
                                 wake.ct[..., 0, 0], wake.yaw[..., 0, 0]) / (1.0 + CURL_ALPHA)
        centre = np.asarray(deflection_field)
        spread = np.max(centre, axis=(2, 3)) - np.min(centre, axis=(2, 3))
        height = np.max(wake.dz, axis=(2, 3)) - np.min(wake.dz, axis=(2, 3))
        shear = spread / np.where(height > 0, height, 1.0)
        thickness = width / np.sqrt(1.0 + shear**2)
        near = downstream & (np.min(np.abs(wake.dy), axis=(2, 3)) < 3.0 * width + radius)
        spacing = 2.0 * radius / ambient.cubature_points
        if np.any(near & (thickness < spacing)):
            ambient.warned.add("cubature")
            warnings.warn(
                "a wake band is thinner than the spacing of the turbine_cubature_grid points "
                f"(N = {ambient.cubature_points}), whose point values cannot resolve it: use "
                "solver type turbine_grid (rotor-cell averages, docs/coupling.md#rotor-average)",
                RuntimeWarning,
                stacklevel=4,
            )

    def normalised_deficit(self, wake: TurbineWake) -> np.ndarray:
        """Delta u / U_h of one wake; each model defines it."""
        raise NotImplementedError("BaseModel.normalised_deficit")


# --------------------------------------------------------------------------------- M-1 / M-2
@define
class EkmanVeerVelocityDeficit(EkmanWakeModel):
    """Veer-corrected curled-wake deficit, Eq. (du_model) of Narasimhan, Gayme & Meneveau (2025).

    Delta u / U_h = C(x) exp(-((y - y_c)^2 + (z - z_h)^2) / (2 sigma(theta, x)^2)), with C(x) of
    Eq. (Cx), sigma(theta, x) = k_w x + 0.4 xi0(theta) xi_hat(theta, t_hat) (Eqs. sigma_width,
    xi0_theta, xi_emp, that) and k_w of Eq. (kw_CNBL_SBL_model). The centre y_c is FLORIS's
    deflection field (this package's ``ekman_veer`` deflection: yaw + veer, varying with z).

    Parameters (``wake_velocity_parameters.ekman_veer``):
        atmosphere: the Ekman atmosphere (see floris_ekman_veer.plugin.inflow.inflow).
        curl: polar-angle dependent (curled) width; False keeps the initial ellipse xi_hat = 1.
        polar_angle_centre: "wake_centre" (paper: theta about the full yaw + veer centre) or
            "yaw_centre" (the authors' published code: theta about the yaw-only centre while the
            Gaussian sits on the full centre, docs/wake_model.md#polar-angle; needs the ekman_veer deflection).
        A1, B1, alpha_prime, k_w_floor, k_w_exponent, wake_expansion: Eq. (kw_CNBL_SBL_model).
        max_thrust_coefficient: momentum-theory limit of C_T cos^2(yaw) (see module docstring).
    """

    curl: bool = boolean_field(True)
    polar_angle_centre: str = choice_field("wake_centre", ("wake_centre", "yaw_centre"))
    #: Inside the potential core (x < x0): "super_gaussian" (the default), the profile that
    #: carries the rotor's thrust with the paper's centre deficit 2a and width (Blondel &
    #: Cathelain 2020's super-Gaussian, wake/near_wake.py, beyond the paper); "potential_core",
    #: the paper's Gaussian there. From x0 on both are the paper's wake
    #: (docs/wake_model.md#near-wake).
    near_wake: str = choice_field("super_gaussian", NEAR_WAKES)

    def near_wake_shape(self, x, k_w, radius, ct, yaw):
        """(n, m) of the wake (wake/near_wake.py), or None for the paper's Gaussian."""
        if self.near_wake != "super_gaussian":
            return None
        return near_wake_shape(x, k_w, radius, ct, yaw)

    def width_bound(self, x, k_w, radius, ct, yaw):
        bound = super().width_bound(x, k_w, radius, ct, yaw)
        shape = self.near_wake_shape(x, k_w, radius, ct, yaw)
        # The super-Gaussian of order n > 2 and width m sigma falls below the Gaussian of width
        # m sigma beyond it: m sigma bounds its reach.
        return bound if shape is None else bound * shape[1]

    def kernel_table(self, x, k_w, radius, ct, yaw, friction_velocity, hub_speed) -> dict:
        # The same Eq. (du_model), fused (wake/fused.py): shared factors per wake and height.
        # Inside a potential core the near wake's super-Gaussian: its order n is the shape
        # column, its width factor m scales k_w x and xi0 (wake/fused.py).
        table = wake_deficit_parameters(x, k_w, radius, ct, yaw, friction_velocity, hub_speed,
                                        curl=self.curl,
                                        shape=self.near_wake_shape(x, k_w, radius, ct, yaw))
        table.setdefault("strength", 0.0)  # (t_hat = 0: xi_hat = 1)
        table.setdefault("shape", GAUSSIAN_SHAPE)
        table["polar_veer"] = float(self.polar_angle_centre == "yaw_centre")
        return table

    def wake_table(self, x, k_w, radius, ct, yaw, friction_velocity, hub_speed,
                   bound_only=False) -> np.ndarray:
        # kernel_table, width_bound and C(x) at once, compiled (wake/fused.py wake_table).
        return wake_table(x, k_w, radius, ct, yaw, friction_velocity, hub_speed, curl=self.curl,
                          near_wake=self.near_wake == "super_gaussian",
                          polar_veer=float(self.polar_angle_centre == "yaw_centre"),
                          bound_only=bound_only)

    def normalised_deficit(self, wake: TurbineWake) -> np.ndarray:
        flowing = wake.local_u > 0
        safe_u = np.where(flowing, wake.local_u, 1.0)
        polar_dy = None
        if self.polar_angle_centre == "yaw_centre":
            polar_dy = wake.dy + veer_deflection(
                wake.dx, safe_u, np.where(flowing, wake.local_v, 0.0)
            )
        return normalised_deficit(
            wake.dx, wake.dy, wake.dz, k_w=wake.k_w, radius=wake.radius, ct=wake.ct,
            yaw=wake.yaw, friction_velocity=wake.friction_velocity, hub_speed=wake.hub_speed,
            local_speed=safe_u, curl=self.curl, polar_dy=polar_dy,
            shape=self.near_wake_shape(wake.dx, wake.k_w, wake.radius, wake.ct, wake.yaw),
        )


# --------------------------------------------------------------------------------- M-3
@define
class Gaussian2014VelocityDeficit(EkmanWakeModel):
    """The paper's M-3: Bastankhah & Porte-Agel (2014) Gaussian, no yaw or veer physics
    (docs/wake_model.md#m-3), on the Ekman inflow; centred on FLORIS's deflection field.

    k* = ``k_star`` if given, else the paper's k_w (Eq. kw_CNBL_SBL_model, or the local
    turbulence variant), so that M-1 and M-3 differ only by their physics, not their mixing.
    The deficit is relative to U_h, the ambient hub-height speed.

    Thrust coefficient behind a yawed rotor (docs/wake_model.md#m-3): the Gaussian of 2014 knows
    no yaw, only a thrust coefficient, and is given the rotor-normal loading
    C_T cos^2(beta) = ct_i cos(beta) (for the paper's fixed-C_T' disk 4a(1 - a) with the yawed
    disk's induction a(beta) of Eq. ind_factor: 0.7491 un-yawed, 0.7018 at 20 deg). Its
    momentum theory then returns the disk's own induction (potential-core deficit 2a(beta), as
    M-1's), and its wake is shallower behind a yawed rotor than behind the un-yawed one, as the
    momentum the disk removes says. FLORIS's gauss uses the same product, ct_i cos(yaw), in its
    far-wake deficit. The un-yawed-basis C_T(beta) (0.7948 at 20 deg) would be the thrust of a
    rotor facing the wind with the yawed disk's loading, deeper than the un-yawed wake.
    """

    k_star: float | None = number_field(None, *POSITIVE, optional=True)
    input_path = f"wake.wake_velocity_parameters.{GAUSSIAN_2014_NAME}"

    def wake_thrust_coefficient(self, ct_i, yaw):
        """Rotor-normal loading C_T cos^2(yaw), limited like M-1's (see the class docstring)."""
        return unyawed_thrust_coefficient(ct_i, yaw, self.max_thrust_coefficient) * np.cos(yaw) ** 2

    def amplitude_bound(self, x, k_w, radius, ct, yaw):
        return 1.0  # C <= 2a < 1

    def centre_deficit(self, x, k_w, radius, ct, yaw):
        k_star = k_w if self.k_star is None else self.k_star
        return bastankhah2014_deficit(x, 0.0, 0.0, ct=ct, diameter=2.0 * radius, k_star=k_star)

    def core_deficit(self, ct, yaw):
        # ct is already the rotor-normal loading (wake_thrust_coefficient): 2a = 1 - sqrt(1 - ct),
        # the Gaussian's own cap, with no second cos^2(yaw).
        return 2.0 * axial_induction(ct, 0.0)

    def width_bound(self, x, k_w, radius, ct, yaw):
        k_star = k_w if self.k_star is None else self.k_star
        return k_star * x + WIDTH_FACTOR * radius * np.sqrt(stream_tube_area_ratio(ct, 0.0))

    def kernel_table(self, x, k_w, radius, ct, yaw, friction_velocity, hub_speed) -> dict:
        sigma, magnitude = bastankhah2014_wake(
            x, ct=ct, diameter=2.0 * radius, k_star=k_w if self.k_star is None else self.k_star)
        return {"amplitude": magnitude, "kx": sigma, "xi0": 0.0, "sin2b": 0.0, "strength": 0.0,
                "polar_veer": 0.0, "shape": GAUSSIAN_SHAPE}

    def normalised_deficit(self, wake: TurbineWake) -> np.ndarray:
        k_star = wake.k_w if self.k_star is None else self.k_star
        diameter = 2.0 * wake.radius
        return bastankhah2014_deficit(
            wake.dx, wake.dy, wake.dz, ct=wake.ct, diameter=diameter, k_star=k_star
        )
