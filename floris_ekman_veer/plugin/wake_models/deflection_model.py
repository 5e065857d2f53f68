"""The FLORIS deflection model ``ekman_veer``: the wake-centre offset y_c(x, z) of Eq. (yc_xz),
yaw (counter-rotating vortex pair with its ground image) plus veer, at every grid point: it
varies with height, which is how veer shears the wake. A thin wrapper of
:func:`floris_ekman_veer.wake.deflection.wake_centre_offset`; its conventions are those of the
velocity models (plugin/wake_models/models.py).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from attrs import define
from floris.core import BaseModel, FlowField, Grid

from floris_ekman_veer._validation import boolean_field, number_field
from floris_ekman_veer.plugin.inflow.ambient import Ambient
from floris_ekman_veer.plugin.rotor.rotor import condition_column
from floris_ekman_veer.plugin.wake_models.names import DEFLECTION_MODEL_NAME
from floris_ekman_veer.plugin.wake_models.wake_inputs import (
    GLAUERT_THRUST_COEFFICIENT,
    THRUST_LIMIT_RANGE,
    from_input_block,
    unyawed_thrust_coefficient,
)
from floris_ekman_veer.wake.deficit import initial_radius, time_like_strength
from floris_ekman_veer.wake.deflection import wake_centre_offset
from floris_ekman_veer.wake.fused import centre_points


@define
class EkmanVeerVelocityDeflection(BaseModel):
    """Wake-centre offset y_c(x, z), Eq. (yc_xz): counter-rotating-vortex deflection with its
    ground image, Eq. (yhatc) with t_hat of Eq. (that), plus the veer shear x V(z)/U(z),
    Eq. (yc_veer). Returned at every grid point, so it varies with height.

    Parameters (``wake_deflection_parameters.ekman_veer``):
        veer: include y_c,veer (False gives the paper's M-2).
        yaw_deflection: include the yaw (vortex-pair) term; with ``veer`` also False the wake
            is not deflected at all, as in the paper's M-3 behind a yawed rotor (FLORIS's
            ``none`` deflection refuses non-zero yaw).
        ground_image: include the image-vortex term of Eq. (yhatc).
        max_thrust_coefficient: as for the velocity model.
    The atmosphere comes from the velocity block (``wake_velocity_parameters.ekman_veer``).
    """

    veer: bool = boolean_field(True)
    yaw_deflection: bool = boolean_field(True)
    ground_image: bool = boolean_field(True)
    max_thrust_coefficient: float = number_field(GLAUERT_THRUST_COEFFICIENT, *THRUST_LIMIT_RANGE)

    input_path = f"wake.wake_deflection_parameters.{DEFLECTION_MODEL_NAME}"
    from_dict = classmethod(from_input_block)

    def prepare_function(self, grid: Grid, flow_field: FlowField) -> dict[str, Any]:
        ambient = Ambient.of(grid, flow_field)
        # Turbine grid: the heights of the grid's point rows (the centre depends on height
        # only), contiguous once per solve rather than at every turbine's call.
        heights = (np.ascontiguousarray(grid.z_sorted[:, :, 0, :], dtype=float)
                   if ambient.rotor is not None else None)
        return {"x": grid.x_sorted, "z": grid.z_sorted, "ambient": ambient,
                "point_heights": heights}

    def function(
        self,
        x_i: np.ndarray,
        y_i: np.ndarray,
        yaw_i: np.ndarray,
        turbulence_intensity_i: np.ndarray,
        ct_i: np.ndarray,
        rotor_diameter_i: np.ndarray,
        *,
        x: np.ndarray,
        z: np.ndarray,
        ambient: Ambient,
        point_heights: np.ndarray | None = None,
    ) -> np.ndarray:
        hub_height = ambient.hub_height_at(x_i, y_i)
        # Without the vortex pair the yaw term vanishes: the offset is that of an unyawed rotor.
        yaw = np.deg2rad(yaw_i) if self.yaw_deflection else np.zeros_like(yaw_i, dtype=float)
        ct = unyawed_thrust_coefficient(ct_i, yaw, self.max_thrust_coefficient)
        radius = 0.5 * rotor_diameter_i
        if ambient.rotor is None:
            hub_speed, local_u, local_v = ambient.at_hub(hub_height)
            return self._offset(x - x_i, z, hub_height, radius, ct, yaw, hub_speed, local_u,
                                local_v, ambient.abl.friction_velocity)
        # Turbine grid: the centre depends on height only, so it is evaluated at the grid's point
        # heights, downstream of turbine i only (upstream there is no wake: 0), and at the rows
        # of the rotor cells (plugin/rotor/rotor.py) by the rotor-cell kernel, from the per-wake
        # factors of RotorDeflection.kernel_table, only for the rotors the velocity model
        # integrates.
        rotor = ambient.rotor
        hub_speed, cos_a, sin_a = ambient.hub_frame(hub_height)
        column = lambda a: condition_column(a, yaw.shape[0])  # noqa: E731
        radius_f, ct_f, yaw_f, u_star = (column(a) for a in (
            radius, ct, yaw, ambient.abl.friction_velocity))
        # The centre's per-wake factors, one per condition.
        table = {"strength": time_like_strength(u_star, column(hub_speed), ct_f, yaw_f),
                 "r_tube": initial_radius(radius_f, ct_f, yaw_f),
                 "image_height": column(hub_height), "veer": float(self.veer),
                 "ground_image": float(self.ground_image)}
        # The compiled centre of the rotor-cell kernel (wake/fused.py centre_offset).
        points = centre_points(
            rotor.x - x_i[:, 0, 0], z[:, :, 0, :] if point_heights is None else point_heights,
            ambient.u[:, :, 0, :],
            ambient.v[:, :, 0, :], column(cos_a), column(sin_a), table["strength"],
            table["r_tube"], table["image_height"], radius_f, u_star, self.veer,
            self.ground_image)
        field_ = np.broadcast_to(points[:, :, None, :], z.shape).view(RotorDeflection)
        field_.kernel_table = lambda: table
        return field_

    def _offset(self, dx, z, hub_height, radius, ct, yaw, hub_speed, local_u, local_v, u_star):
        flowing = local_u > 0
        offset = wake_centre_offset(
            dx, z, hub_height=hub_height, radius=radius, ct=ct, yaw=yaw,
            friction_velocity=u_star, hub_speed=hub_speed,
            local_speed=np.where(flowing, local_u, 1.0),
            lateral_speed=np.where(flowing, local_v, 0.0), veer=self.veer,
            ground_image=self.ground_image,
        )
        return np.where(flowing, offset, 0.0)


class RotorDeflection(np.ndarray):
    """The ekman_veer wake centre at FLORIS's turbine-grid points, carrying ``kernel_table()``:
    the wake's factors of its centre (t_hat's prefactor, R sqrt(A*), the image vortex's hub
    height, the veer and ground-image switches), one per condition, from which the rotor-cell
    kernel evaluates the centre at the rows of the rotors the wake can reach
    (plugin/rotor/rotor_kernel.py, wake/fused.py ``centre_offset``). Arithmetic on it gives plain arrays (FLORIS's own velocity models read
    it as the point field it is)."""

    kernel_table = None

    def __array_wrap__(self, array, context=None, return_scalar=False):
        result = array.view(np.ndarray)
        return result[()] if return_scalar else result
