"""Eq. (du_model) fused for the rotor cells' sub-points, compiled (numba).

The readable form of the deficit is :func:`floris_ekman_veer.wake.deficit.normalised_deficit`;
this module evaluates the same formula where most factors are shared: per wake (C(x), k_w x,
the stream-tube radius, beta: :func:`wake_deficit_parameters`, numpy) and per height (t_hat and
the three tanh of Eq. xi_emp depend on z only, through U(z): :func:`curl_polynomial`), leaving
per point only the polar harmonics, the width and the Gaussian (:func:`point_deficit`). The
compiled functions are called by the rotor-cell kernel (plugin/rotor/rotor_kernel.py) once per
sub-point; :func:`deficit_on_rows` runs them on arrays (tests/plugin/rotor/test_rotor_average.py
checks it against ``normalised_deficit`` to round-off). ``cache=True``: compiled once per
installation (numba's cache next to the module, or its user cache directory where the
package's folder is read-only; NUMBA_CACHE_DIR moves it), no fastmath (IEEE results, the same
on every thread).
"""

from __future__ import annotations

import numba
import numpy as np

from .deficit import (
    CURL_ALPHA,
    WIDTH_FACTOR,
    initial_radius,
    max_deficit,
    time_like_growth,
    time_like_strength,
)
from .deflection import IMAGE_CORE

#: How the compiled functions are compiled: cached on disk, IEEE arithmetic (no fastmath).
JIT = {"cache": True, "fastmath": False, "error_model": "numpy"}

#: The Gaussian's radial exponent n of the shape exp(-(rho^2 / (2 sigma^2))^(n / 2)): 2 is the
#: paper's Gaussian (the only shape of Eq. du_model); the kernel takes n per wake and rotor, so
#: that another radial shape (a near wake's super-Gaussian) plugs into the same code.
GAUSSIAN_SHAPE = 2.0


@numba.njit(**JIT)
def curl_polynomial(t_hat, alpha):
    """(q0, ..., q4) with xi_hat = sum_k q_k cos(theta)^k, Eq. (xi_emp):
    xi_hat = 1 - (a2 cos 2theta + a3 cos 3theta + a4 cos 4theta) with
    a2 = alpha (tanh(t^2/4alpha)/2 - 5/48 tanh(t^4/16alpha)), a3 = -alpha/4 tanh(t^3/8alpha),
    a4 = 7 alpha/48 tanh(t^4/16alpha), and (Chebyshev) cos 2t = 2c^2 - 1, cos 3t = 4c^3 - 3c,
    cos 4t = 8c^4 - 8c^2 + 1. t_hat = 0: (1, 0, 0, 0, 0)."""
    t2 = t_hat * t_hat
    tanh2 = np.tanh(t2 / (4.0 * alpha))
    tanh3 = np.tanh(t2 * t_hat / (8.0 * alpha))
    tanh4 = np.tanh(t2 * t2 / (16.0 * alpha))
    a2 = alpha * (0.5 * tanh2 - 5.0 / 48.0 * tanh4)
    a3 = -0.25 * alpha * tanh3
    a4 = 7.0 / 48.0 * alpha * tanh4
    return 1.0 + a2 - a4, 3.0 * a3, 8.0 * a4 - 2.0 * a2, -4.0 * a3, -8.0 * a4


@numba.njit(**JIT)
def point_deficit(dy, dz, polar_dy, amplitude, kx, xi0, sin2b, q0, q1, q2, q3, q4, shape):
    """Delta u / U_h of Eq. (du_model) at one point (dy, dz) from the wake's centre: the width
    sigma = k_w x + xi0 xi_hat(theta) / sqrt(1 - sin^2 beta sin^2 theta) of Eqs.
    (sigma_width), (xi0_theta), the polar angle theta measured at (polar_dy, dz)
    (docs/wake_model.md#polar-angle; theta := 0 at the centre, where the Gaussian is 1 whatever
    the width), and the radial shape exp(-(rho^2 / (2 sigma^2))^(shape / 2)) (2: the Gaussian).
    ``xi0`` = 0.4 R sqrt(A*) |cos beta|; (q0, ..., q4) of :func:`curl_polynomial`."""
    squared = polar_dy * polar_dy + dz * dz
    c = polar_dy / np.sqrt(squared) if squared > 0.0 else 1.0
    curl = q0 + c * (q1 + c * (q2 + c * (q3 + c * q4)))
    sigma = kx + xi0 / np.sqrt(1.0 - sin2b * (1.0 - c * c)) * curl
    exponent = (dy * dy + dz * dz) / (2.0 * sigma * sigma)
    if shape != GAUSSIAN_SHAPE:
        exponent = exponent ** (0.5 * shape)
    return amplitude * np.exp(-exponent)


@numba.njit(**JIT)
def centre_offset(x, z, local_u, local_v, strength, r_tube, hub_height, radius, friction_velocity,
                  veer, ground_image):
    """y_c(x, z) of Eq. (yc_xz) at one height z (x > 0), as wake/deflection.py's
    ``wake_centre_offset`` (the readable form): the vortex pair's y_hat_c of Eq. (yhatc) with
    its ground image (``ground_image`` 1, eta floored at 1 + IMAGE_CORE) times R sqrt(A*)
    (``r_tube``), t_hat = ``strength`` (1 - exp(-0.35 (u*/U(z)) x/R)) (Eq. that), plus
    ``veer`` times x V(z)/U(z) (Eq. yc_veer); 0 where there is no flow (U(z) <= 0)."""
    if not local_u > 0.0:
        return 0.0
    t_hat = strength * -np.expm1(-0.35 * (friction_velocity / local_u) * x / radius)
    abs_t = abs(t_hat)
    pm1 = np.pi - 1.0
    numerator = (pm1 * abs_t * abs_t * abs_t + 2.0 * np.sqrt(3.0) * np.pi**2 * abs_t * abs_t
                 + 48.0 * pm1**2 * abs_t)
    denominator = (2.0 * np.pi * pm1 * abs_t * abs_t + 4.0 * np.sqrt(3.0) * np.pi**2 * abs_t
                   + 96.0 * pm1**2)
    y_hat = np.sign(t_hat) * numerator / denominator
    if ground_image:
        eta = max((z + hub_height) / r_tube, 1.0 + IMAGE_CORE)
        y_hat -= (2.0 / np.pi) * t_hat / (eta * eta - 1.0)
    return y_hat * r_tube + veer * (x * local_v / local_u)


@numba.njit(**JIT)
def _centre_offsets(x, z, local_u, local_v, strength, r_tube, hub_height, radius,
                    friction_velocity, veer, ground_image):
    out = np.empty(x.size)
    for k in range(x.size):
        out[k] = centre_offset(x[k], z[k], local_u[k], local_v[k], strength[k], r_tube[k],
                               hub_height[k], radius[k], friction_velocity[k], veer,
                               ground_image)
    return out


def centre_offsets(x, z, local_u, local_v, strength, r_tube, hub_height, radius,
                   friction_velocity, veer=True, ground_image=True):
    """:func:`centre_offset` on broadcast arrays (for the tests' comparison)."""
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (
        x, z, local_u, local_v, strength, r_tube, hub_height, radius, friction_velocity)))
    flat = [np.ascontiguousarray(a).ravel() for a in arrays]
    return _centre_offsets(*flat, float(veer), float(ground_image)).reshape(arrays[0].shape)


@numba.njit(**JIT)
def _deficits(dy, dz, amplitude, kx, xi0, sin2b, q, shape):
    out = np.empty(dy.size)
    for k in range(dy.size):
        out[k] = point_deficit(dy[k], dz[k], dy[k], amplitude[k], kx[k], xi0[k], sin2b[k],
                               q[k, 0], q[k, 1], q[k, 2], q[k, 3], q[k, 4], shape[k])
    return out


@numba.njit(**JIT)
def _curl_polynomials(t_hat, alpha):
    q = np.empty((t_hat.size, 5))
    for k in range(t_hat.size):
        q[k, 0], q[k, 1], q[k, 2], q[k, 3], q[k, 4] = curl_polynomial(t_hat[k], alpha)
    return q


def wake_deficit_parameters(x, k_w, radius, ct, yaw, friction_velocity, hub_speed, curl=True,
                            shape=None):
    """The per-wake factors of Eq. (du_model) (see :func:`rows_deficit_parameters`), evaluated
    once per wake: C(x), k_w x, xi0 / |cos beta|'s numerator, sin^2 beta and t_hat's prefactor;
    with ``shape`` = (n, m) of the near wake (wake/near_wake.py) also the radial shape exponent
    n ("shape") and the width factor m scaling k_w x and xi0 (sigma is linear in both; where
    n = 2, m = 1 and they stay bit for bit)."""
    r_tube = initial_radius(radius, ct, yaw)
    parameters = {
        "amplitude": max_deficit(x, k_w, radius, ct, yaw),
        "kx": np.asarray(k_w) * np.asarray(x),
        "xi0": WIDTH_FACTOR * r_tube * np.abs(np.cos(yaw)),
        "sin2b": np.sin(yaw) ** 2,
    }
    if shape is not None:
        order, factor = shape
        parameters["kx"] = parameters["kx"] * factor
        parameters["xi0"] = parameters["xi0"] * factor
        parameters["shape"] = order
    if curl:
        parameters["strength"] = time_like_strength(friction_velocity, hub_speed, ct, yaw)
    return parameters


def rows_deficit_parameters(x, k_w, radius, ct, yaw, friction_velocity, hub_speed, local_speed,
                            curl=True, wake=None):
    """The per-wake and per-height factors of Eq. (du_model) (see :func:`deficit_on_rows`).

    ``x`` (> 0), ``k_w``, ``radius``, ``ct``, ``yaw``, ``friction_velocity``, ``hub_speed``
    broadcast per wake; ``local_speed`` U(z) per height (> 0). ``wake``: the per-wake factors
    of :func:`wake_deficit_parameters` at the same points, if already evaluated (once per wake,
    then gathered to its heights). Returns a dict of arrays.
    """
    if wake is None:
        wake = wake_deficit_parameters(x, k_w, radius, ct, yaw, friction_velocity, hub_speed,
                                       curl)
    t_hat = np.zeros(1)
    if curl:
        t_hat = wake["strength"] * time_like_growth(x, friction_velocity, local_speed, radius)
    q = _curl_polynomials(np.ravel(t_hat).astype(float), CURL_ALPHA).T.reshape(
        (5, *np.shape(t_hat)))
    return {**{k: wake[k] for k in ("amplitude", "kx", "xi0", "sin2b")},
            "shape": wake.get("shape", GAUSSIAN_SHAPE), **{f"q{k}": q[k] for k in range(5)}}


def deficit_on_rows(dy, dz, parameters):
    """Delta u / U_h of Eq. (du_model) at points (dy, dz) from the factors of
    :func:`rows_deficit_parameters` (:func:`point_deficit` at every point of the broadcast
    arrays; the radial shape exponent "shape", 2 if absent)."""
    names = ("amplitude", "kx", "xi0", "sin2b", "q0", "q1", "q2", "q3", "q4")
    shape = parameters.get("shape", GAUSSIAN_SHAPE)
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (
        dy, dz, *(parameters[k] for k in names), shape)))
    flat = [np.ascontiguousarray(a).ravel() for a in arrays]
    q = np.stack(flat[6:11], axis=1)
    return _deficits(*flat[:6], q, flat[11]).reshape(arrays[0].shape)
