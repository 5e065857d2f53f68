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
from floris_ekman_veer.plugin.wake_models.names import DEFLECTION_MODEL_NAME
from floris_ekman_veer.plugin.wake_models.wake_inputs import (
    GLAUERT_THRUST_COEFFICIENT,
    THRUST_LIMIT_RANGE,
    from_input_block,
    unyawed_thrust_coefficient,
)
from floris_ekman_veer.wake.deflection import wake_centre_offset


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
        return {"x": grid.x_sorted, "z": grid.z_sorted, "ambient": Ambient.of(grid, flow_field)}

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
        # of the rotor cells (plugin/rotor/rotor.py) only for the rotors the velocity model
        # integrates (RotorDeflection.rows_at).
        rotor = ambient.rotor
        hub_speed, cos_a, sin_a = ambient.hub_frame(hub_height)
        dx = rotor.x - x_i[:, 0, 0]
        per_condition = [np.broadcast_to(a, yaw.shape)[:, 0, 0, 0] for a in (
            cos_a, sin_a, hub_height, radius, ct, yaw, hub_speed,
            ambient.abl.friction_velocity)]

        def centre(f, j, heights, u, v):
            """The centre at ``heights`` (pairs, h) of rotors (f, j) downstream, from the ambient
            (u, v) there in FLORIS's frame."""
            cos_p, sin_p, *pair = (a[f][:, None] for a in per_condition)
            return self._offset(dx[f, j][:, None], heights, *pair[:5],
                                u * cos_p + v * sin_p, v * cos_p - u * sin_p, pair[5])

        points = np.zeros(z[:, :, 0, :].shape)
        f, j = np.nonzero(dx > 0.0)
        if f.size:
            u = np.broadcast_to(ambient.u[:, :, 0, :], points.shape)
            v = np.broadcast_to(ambient.v[:, :, 0, :], points.shape)
            points[f, j] = centre(f, j, z[f, j, 0, :], u[f, j], v[f, j])
        field_ = np.broadcast_to(points[:, :, None, :], z.shape).view(RotorDeflection)
        field_.rows_at = lambda f, j: centre(f, j, *rotor.rows(f, j))  # noqa: E731
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
    """The ekman_veer wake centre at FLORIS's turbine-grid points, carrying ``rows_at(f, j)``:
    the centre at the rows of the rotor cells' sub-quadrature of rotors (f, j) downstream
    (index arrays; returns (pairs, rows)), for the velocity model's rotor-cell average, which
    evaluates it only where the wake can reach. Arithmetic on it gives plain arrays (FLORIS's
    own velocity models read it as the point field it is)."""

    rows_at = None

    def __array_wrap__(self, array, context=None, return_scalar=False):
        result = array.view(np.ndarray)
        return result[()] if return_scalar else result
