"""Lateral displacement of one wake's centre: Narasimhan, Gayme & Meneveau (JRSE 2025), Section 2.4.

    y_c(x, z) = y_hat_c(t_hat) R sqrt(A*) + y_c,veer                                  Eq. (yc_xz)

y_hat_c (Eq. yhatc) is the sidewash of the yaw-induced counter-rotating vortex pair plus that of its
ground image; y_c,veer (Eq. yc_veer) is the shear of the wake by the veering inflow. Pure numpy,
broadcasting by numpy rules; yaw in radians; ``ct`` the un-yawed C_T. Frame: x downstream, y to the
left looking downstream, z up; beta > 0 gives t_hat < 0 and y_c < 0 (docs/conventions.md#frames-and-signs).
"""

from __future__ import annotations

import numpy as np

from floris_ekman_veer._validation import positive

from .deficit import (
    WIDTH_FACTOR,
    initial_radius,
    time_like_variable,
)

#: Distance, in units of R sqrt(A*), below which the ground-image vortex's sidewash stops growing.
#: It is the wake's initial Gaussian width 0.4 R sqrt(A*) (Eq. sigma_width at x = 0, beta = 0): a
#: point vortex is a model of a vorticity distribution that wide, not a singularity.
IMAGE_CORE = WIDTH_FACTOR


def yaw_deflection(t_hat, z, hub_height, radius, ct, yaw, ground_image=True):
    """Dimensionless yaw-induced deflection y_hat_c, Eq. (yhatc).

    y_hat_c = sgn(t) [(pi-1)|t|^3 + 2 sqrt3 pi^2 t^2 + 48 (pi-1)^2 |t|]
                     / [2 pi (pi-1) t^2 + 4 sqrt3 pi^2 |t| + 96 (pi-1)^2]
              - (2/pi) t / (eta^2 - 1),    eta = (z + z_h) / (R sqrt(A*)) at the LOCAL z.

    The first term goes from t/2 (small |t|) to sgn(t)|t|/(2 pi) (large |t|); both vanish at
    t_hat = 0. ``ground_image=False`` drops the second term.

    The image term is the on-axis sidewash of the image vortex pair centred at z = -z_h, whose
    upper vortex sits at eta = 1; it is singular there and changes sign below it. In the fluid
    (z > 0) that happens only if z_h < R sqrt(A*), i.e. the expanded stream tube reaches the ground
    and the image construction has broken down; FLORIS grids may also hold points at z <= 0. To
    stay finite everywhere, eta is floored at 1 + IMAGE_CORE = 1.4: within 0.4 R sqrt(A*) of the
    image vortex (and everywhere below that height, underground included) the term keeps its value
    at eta = 1.4, |term| <= (2/pi) |t_hat| / 0.96. Where eta >= 1.4 (at every z >= 0 when
    z_h >= 1.4 R sqrt(A*)) the printed formula is returned unchanged. The result is continuous in z.

    ``hub_height`` > 0 (m), ``radius`` > 0 (m), ``ct`` in [0, 1), ``yaw`` in (-pi/2, pi/2).
    """
    t_hat = np.asarray(t_hat, dtype=float)
    if not np.any(t_hat):
        # Unyawed rotors (t_hat = 0 everywhere): both terms vanish exactly; skip the work.
        positive(hub_height, "hub_height")
        return np.zeros(np.broadcast_shapes(t_hat.shape, np.shape(z)))
    abs_t = np.abs(t_hat)
    pm1 = np.pi - 1.0
    numerator = pm1 * abs_t**3 + 2.0 * np.sqrt(3.0) * np.pi**2 * abs_t**2 + 48.0 * pm1**2 * abs_t
    denominator = (
        2.0 * np.pi * pm1 * abs_t**2 + 4.0 * np.sqrt(3.0) * np.pi**2 * abs_t + 96.0 * pm1**2
    )
    vortex_pair = np.sign(t_hat) * numerator / denominator
    if not ground_image:
        return vortex_pair * np.ones_like(np.asarray(z, dtype=float))
    hub_height = positive(hub_height, "hub_height")
    r_tube = initial_radius(radius, ct, yaw)
    eta = np.maximum((np.asarray(z, dtype=float) + hub_height) / r_tube, 1.0 + IMAGE_CORE)
    return vortex_pair - (2.0 / np.pi) * t_hat / (eta**2 - 1.0)


def veer_deflection(x, local_speed, lateral_speed):
    """Lateral wake displacement by wind veer y_c,veer = x V(z) / U(z), Eq. (yc_veer), in metres.

    ``local_speed`` U(z) and ``lateral_speed`` V(z) are the inflow components in the frame where
    the hub-height wind is along +x (docs/conventions.md#hub-aligned-frame). Zero for x <= 0 (no wake upstream).

    U(z) must be finite and > 0 everywhere, else ValueError: a parcel with U <= 0 (at or below the
    roughness height, where the log law changes sign) never reaches x > 0, and x V/U has no finite
    limit as U -> 0+, so no value would be honest. The caller decides how the roughness sublayer is
    treated (e.g. evaluate the inflow no lower than a small height above z0).
    """
    u_local = positive(local_speed, "local_speed")
    lateral = np.asarray(lateral_speed, dtype=float)
    return np.maximum(np.asarray(x, dtype=float), 0.0) * lateral / u_local


def wake_centre_offset(
    x,
    z,
    *,
    hub_height,
    radius,
    ct,
    yaw,
    friction_velocity,
    hub_speed,
    local_speed,
    lateral_speed=None,
    veer=True,
    ground_image=True,
):
    """Lateral offset of the wake centre from the rotor centre y_c(x, z), Eq. (yc_xz), in metres.

    y_c = y_hat_c(t_hat) R sqrt(A*) + y_c,veer, with t_hat from Eq. (that) (``friction_velocity``
    u*, ``hub_speed`` U_h, ``local_speed`` U(z)) and y_c,veer from Eq. (yc_veer)
    (``lateral_speed`` V(z), required when ``veer`` is True). ``veer=False`` gives the yaw-only
    centre (model M-2, and the centre of the polar angle in the authors' code, docs/wake_model.md#polar-angle).
    x is the streamwise distance behind the rotor; y_c = 0 for x <= 0.
    """
    t_hat = time_like_variable(x, friction_velocity, hub_speed, local_speed, radius, ct, yaw)
    y_hat = yaw_deflection(t_hat, z, hub_height, radius, ct, yaw, ground_image=ground_image)
    offset = y_hat * initial_radius(radius, ct, yaw)
    if not veer:
        return offset
    if lateral_speed is None:
        raise ValueError("lateral_speed must be given (V(z), m/s) when veer=True")
    return offset + veer_deflection(x, local_speed, lateral_speed)
