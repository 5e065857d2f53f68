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

import math

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
from .near_wake import BISECTION_STEPS, GAUSSIAN_ORDER

#: How the compiled functions are compiled: cached on disk, IEEE arithmetic (no fastmath).
JIT = {"cache": True, "fastmath": False, "error_model": "numpy"}

#: The Gaussian's radial exponent n of the shape exp(-(rho^2 / (2 sigma^2))^(n / 2)): 2 is the
#: paper's Gaussian (the only shape of Eq. du_model); the kernel takes n per wake and rotor, so
#: that another radial shape (a near wake's super-Gaussian) plugs into the same code.
GAUSSIAN_SHAPE = 2.0


#: exp(-e) for e >= 0 in the compiled functions (docs/performance.md#the-exponential):
#: exp(-e) = exp(-m / EXP_STEPS) exp(-y) with m = floor(e EXP_STEPS), 0 <= y < 1 / EXP_STEPS, the
#: first factor read from a table of numpy's exp, the second the Taylor polynomial of EXP_TAYLOR
#: terms (truncation below 1e-18 of it): within 2 units in the last place of numpy's exp with
#: arithmetic and a table look-up only (libm's exp is a call per value: 8 % of the rotor-cell
#: kernel's time, 2-4 x the cumulative wake's sum). From EXP_RANGE on the value is 0: exp(-64) =
#: 1.6e-28 of a centre deficit is below the round-off of any velocity it is added to.
EXP_STEPS = 256
EXP_RANGE = 64.0
EXP_TABLE = np.exp(-np.arange(int(EXP_RANGE) * EXP_STEPS + 2) / EXP_STEPS)
EXP_TAYLOR = np.array([1.0 / math.factorial(k) for k in range(7)])


@numba.njit(inline="always", **JIT)
def table_exp(e):
    """exp(-e) for 0 <= e < EXP_RANGE, unchecked (EXP_TABLE): for a caller that has bounded e
    already (the cumulative sum's exponents lie below OVERLAP_EXPONENT_LIMIT = 16);
    :func:`negative_exp` otherwise."""
    step = math.floor(e * EXP_STEPS)
    y = step * (1.0 / EXP_STEPS) - e
    value = EXP_TAYLOR[-1]
    for term in range(EXP_TAYLOR.size - 2, -1, -1):
        value = value * y + EXP_TAYLOR[term]
    return EXP_TABLE[int(step)] * value


@numba.njit(inline="always", **JIT)
def negative_exp(e):
    """exp(-e) to round-off for 0 <= e < EXP_RANGE (:func:`table_exp`), 0 from EXP_RANGE on;
    NaN and negative e (which no deficit has) get numpy's exp, never a read outside the table."""
    if not 0.0 <= e < EXP_RANGE:
        return 0.0 if e >= EXP_RANGE else np.exp(-e)
    return table_exp(e)


@numba.njit(inline="always", **JIT)
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


@numba.njit(inline="always", **JIT)
def point_exponent(dy, dz, polar_dy, kx, xi0, sin2b, q0, q1, q2, q3, q4):
    """rho^2 / (2 sigma^2) of Eq. (du_model) at one point (dy, dz) from the wake's centre: the
    width sigma = k_w x + xi0 xi_hat(theta) / sqrt(1 - sin^2 beta sin^2 theta) of Eqs.
    (sigma_width), (xi0_theta), the polar angle theta measured at (polar_dy, dz)
    (docs/wake_model.md#polar-angle; theta := 0 at the centre, where the Gaussian is 1 whatever
    the width). ``xi0`` = 0.4 R sqrt(A*) |cos beta|; (q0, ..., q4) of :func:`curl_polynomial`.
    No call and no branch but a select: the rotor-cell kernel evaluates it along a sub-point
    row in the compiler's vector instructions (IEEE-exact, as the scalar ones)."""
    squared = polar_dy * polar_dy + dz * dz
    c = polar_dy / np.sqrt(squared)
    c = c if squared > 0.0 else 1.0
    curl = q0 + c * (q1 + c * (q2 + c * (q3 + c * q4)))
    sigma = kx + xi0 / np.sqrt(1.0 - sin2b * (1.0 - c * c)) * curl
    return (dy * dy + dz * dz) / (2.0 * sigma * sigma)


@numba.njit(inline="always", **JIT)
def shaped_deficit(exponent, amplitude, shape):
    """Delta u / U_h = C exp(-(rho^2 / (2 sigma^2))^(shape / 2)) from :func:`point_exponent`'s
    ``exponent``: the radial shape (2: the Gaussian; a near wake's super-Gaussian order); the
    exp by the table (:func:`negative_exp`)."""
    if shape != GAUSSIAN_SHAPE:
        exponent = exponent ** (0.5 * shape)
    return amplitude * negative_exp(exponent)


@numba.njit(**JIT)
def point_deficit(dy, dz, polar_dy, amplitude, kx, xi0, sin2b, q0, q1, q2, q3, q4, shape):
    """Delta u / U_h of Eq. (du_model) at one point (dy, dz) from the wake's centre:
    :func:`shaped_deficit` of :func:`point_exponent` (the polar angle measured at
    (polar_dy, dz)); the radial shape exp(-(rho^2 / (2 sigma^2))^(shape / 2)) (2: the
    Gaussian)."""
    return shaped_deficit(point_exponent(dy, dz, polar_dy, kx, xi0, sin2b, q0, q1, q2, q3, q4),
                          amplitude, shape)


@numba.njit(inline="always", **JIT)
def centre_offset(x, z, local_u, local_v, strength, r_tube, hub_height, radius, friction_velocity,
                  veer, ground_image):
    """y_c(x, z) of Eq. (yc_xz) at one height z (x > 0), as wake/deflection.py's
    ``wake_centre_offset`` (the readable form): the vortex pair's y_hat_c of Eq. (yhatc) with
    its ground image (``ground_image`` 1, eta floored at 1 + IMAGE_CORE) times R sqrt(A*)
    (``r_tube``), t_hat = ``strength`` (1 - exp(-0.35 (u*/U(z)) x/R)) (Eq. that), plus
    ``veer`` times x V(z)/U(z) (Eq. yc_veer); 0 where there is no flow (U(z) <= 0)."""
    if not local_u > 0.0:
        return 0.0
    return grown_centre_offset(time_growth(x, local_u, radius, friction_velocity), x, z,
                               local_u, local_v, strength, r_tube, hub_height, veer,
                               ground_image)


@numba.njit(inline="always", **JIT)
def time_growth(x, speed, radius, friction_velocity):
    """1 - exp(-0.35 (u*/U) x/R), t_hat's growth of Eq. (that) at a height where the speed is
    U = ``speed`` > 0 (the centre's and the curl's t_hat at a row share it)."""
    return -np.expm1(-0.35 * (friction_velocity / speed) * x / radius)


@numba.njit(inline="always", **JIT)
def _vortex_pair_offset(abs_t):
    # |y_hat_c| of Eq. (yhatc) without the image, at |t_hat| = abs_t (increasing in abs_t).
    pm1 = np.pi - 1.0
    numerator = (pm1 * abs_t * abs_t * abs_t + 2.0 * np.sqrt(3.0) * np.pi**2 * abs_t * abs_t
                 + 48.0 * pm1**2 * abs_t)
    denominator = (2.0 * np.pi * pm1 * abs_t * abs_t + 4.0 * np.sqrt(3.0) * np.pi**2 * abs_t
                   + 96.0 * pm1**2)
    return numerator / denominator


@numba.njit(inline="always", **JIT)
def centre_offset_bound(x, z, local_u, local_v, strength, r_tube, hub_height, radius,
                        friction_velocity, veer, ground_image):
    """(drift, bound) with |:func:`centre_offset` - drift| <= bound, without its exponential
    (U(z) > 0): the veer's x V/U exactly, and the larger of the vortex pair's offset (Eq.
    yhatc, increasing in |t_hat|) and its ground image's (linear in it, of the opposite sign)
    at the bound
    |t_hat| <= |strength| min(2a / (2 + a), 1) of Eq. (that) (1 - exp(-a) <= 2a / (2 + a) for
    a = 0.35 (u*/U) x/R >= 0, exp's Pade bound); widened by a millionth and a micrometre for
    the round-off. The rotor-cell kernel skips the exact centre of the rows that this bound
    already puts out of a wake's reach."""
    drift = veer * (x * local_v / local_u)
    a = 0.35 * (friction_velocity / local_u) * x / radius
    t_bound = abs(strength) * min(2.0 * a / (2.0 + a), 1.0)
    offset = _vortex_pair_offset(t_bound)
    if ground_image:
        # The image's offset has the opposite sign: the difference is at most the larger.
        eta = max((z + hub_height) / r_tube, 1.0 + IMAGE_CORE)
        offset = max(offset, (2.0 / np.pi) * t_bound / (eta * eta - 1.0))
    return drift, r_tube * offset * (1.0 + 1e-6) + 1e-6


@numba.njit(inline="always", **JIT)
def rotor_centre_offset_bound(x, slowest_u, strength, r_tube, radius, friction_velocity,
                              image_factor):
    """A bound of :func:`centre_offset_bound`'s ``bound`` at every row of a rotor, one per wake
    and rotor: the same formula at the rotor's slowest speed ``slowest_u`` > 0 (its smallest
    U(z) > 0: a, hence the bound of |t_hat|, is largest there) with the image's factor
    ``image_factor`` the largest of (2/pi) / (eta^2 - 1) over the rotor's rows (0 without the
    ground image), widened by another millionth and micrometre for the round-off of the
    factored forms. The rotor-cell kernel skips a row that this bound puts out of a wake's
    reach before it evaluates the row's own bound: a row skipped here is skipped by that one
    too, so the results are the same bits."""
    a = 0.35 * (friction_velocity / slowest_u) * x / radius
    t_bound = abs(strength) * min(2.0 * a / (2.0 + a), 1.0)
    offset = max(_vortex_pair_offset(t_bound), image_factor * t_bound)
    return r_tube * offset * (1.0 + 2e-6) + 2e-6


@numba.njit(inline="always", **JIT)
def image_factor(z, hub_height, r_tube):
    """(2/pi) / (eta^2 - 1), the ground image's offset per unit |t_hat| at height ``z`` of Eq.
    (yhatc) (eta floored as :func:`centre_offset` floors it)."""
    eta = max((z + hub_height) / r_tube, 1.0 + IMAGE_CORE)
    return (2.0 / np.pi) / (eta * eta - 1.0)


@numba.njit(inline="always", **JIT)
def grown_centre_offset(growth, x, z, local_u, local_v, strength, r_tube, hub_height, veer,
                        ground_image):
    """:func:`centre_offset` with t_hat's growth (:func:`time_growth`) given (U(z) > 0)."""
    t_hat = strength * growth
    y_hat = np.sign(t_hat) * _vortex_pair_offset(abs(t_hat))
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


@numba.njit(**JIT)
def _centre_points(dx, z, u, v, cos_a, sin_a, strength, r_tube, hub_height, radius,
                   friction_velocity, veer, ground_image, points):
    for f in range(dx.shape[0]):
        for j in range(dx.shape[1]):
            if not dx[f, j] > 0.0:
                continue
            for h in range(z.shape[2]):
                u_fjh, v_fjh = u[f, j, h], v[f, j, h]
                points[f, j, h] = centre_offset(
                    dx[f, j], z[f, j, h], u_fjh * cos_a[f] + v_fjh * sin_a[f],
                    v_fjh * cos_a[f] - u_fjh * sin_a[f], strength[f], r_tube[f], hub_height[f],
                    radius[f], friction_velocity[f], veer, ground_image)


def _contiguous(value, shape) -> np.ndarray:
    """``value`` as a contiguous float array of ``shape`` (broadcast; as it is if it already
    is one)."""
    value = np.asarray(value, dtype=float)
    if value.shape != shape:
        value = np.broadcast_to(value, shape)
    return np.ascontiguousarray(value)


def centre_points(dx, z, u, v, cos_a, sin_a, strength, r_tube, hub_height, radius,
                  friction_velocity, veer=True, ground_image=True):
    """:func:`centre_offset` of one wake at the points of every rotor downstream of it (0
    elsewhere): ``dx`` (n_findex, n_turbines) the rotors' distances behind the wake's rotor,
    ``z``, ``u``, ``v`` (n_findex, n_turbines, heights) the points' heights and the ambient
    (U, V) there in FLORIS's frame, turned into the hub-height wind's by (``cos_a``,
    ``sin_a``); the wake's factors per condition (n_findex,). Returns (n_findex, n_turbines,
    heights)."""
    arrays = [np.ascontiguousarray(a, dtype=float) for a in (dx, z, u, v)]
    per_condition = [_contiguous(a, dx.shape[:1]) for a in (
        cos_a, sin_a, strength, r_tube, hub_height, radius, friction_velocity)]
    points = np.zeros(arrays[1].shape)
    _centre_points(*arrays, *per_condition, float(veer), float(ground_image), points)
    return points


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


#: The columns of :func:`wake_table`, one row per wake and rotor: the kernel's per-wake factors
#: (plugin/rotor/rotor_kernel.py reads the first seven), then how far the wake reaches (the
#: largest width over all polar angles and the largest deficit) and its centre deficit C(x).
WAKE_TABLE = ("amplitude", "kx", "xi0", "sin2b", "strength", "polar_veer", "shape",
              "width_bound", "amplitude_bound", "centre_deficit")

#: The ``shape`` of a near-wake pair whose order :func:`wake_table` left for later
#: (``bound_only``): its ``width_bound`` holds for every order (the rotor's reach is bounded
#: before the order's root is solved; the rotors kept get their exact table).
DEFERRED_ORDER = 0.0


@numba.njit(**JIT)
def _digamma(x):
    # psi(x), x > 0: the recurrence psi(x) = psi(x + 1) - 1/x up to x >= 6, then the asymptotic
    # series (to ~1e-13: it sets only the Newton steps of super_gaussian_order, not the root).
    result = 0.0
    while x < 6.0:
        result -= 1.0 / x
        x += 1.0
    inverse = 1.0 / x
    inverse2 = inverse * inverse
    return result + np.log(x) - 0.5 * inverse - inverse2 * (
        1.0 / 12.0 - inverse2 * (1.0 / 120.0 - inverse2 * (1.0 / 252.0 - inverse2 * (
            1.0 / 240.0 - inverse2 / 132.0))))


@numba.njit(**JIT)
def _momentum_excess(n, c, loading, log_width_squared):
    # wake/near_wake.py's _momentum_excess at one point, n C_T' / (16 Gamma(2/n) s^(4/n)) -
    # c (2^(2/n) - c), with s^(4/n) = exp((2/n) ln s^2), and its derivative in n (Newton).
    t = 2.0 / n
    carried = n * loading / (16.0 * math.gamma(t) * np.exp(t * log_width_squared))
    power = np.exp(t * np.log(2.0))
    slope = (carried * (1.0 / n + 0.5 * t * t * (_digamma(t) + log_width_squared))
             + c * power * np.log(2.0) * 0.5 * t * t)
    return carried - c * (power - c), slope


@numba.njit(**JIT)
def super_gaussian_order(centre_deficit, loading, width_squared):
    """wake/near_wake.py's ``super_gaussian_order`` at one point: the same root in the same
    bracket, by Newton's method kept inside the bracket (a bisection step where Newton would
    leave it; a handful of evaluations of the momentum integral where the bisection takes 60),
    down to the resolution of float64, where the bisection ends too
    (tests/physics/test_near_wake.py)."""
    log_width_squared = np.log(width_squared)
    lower = GAUSSIAN_ORDER
    upper = 2.0 / (1.0 + np.log2(centre_deficit)) if centre_deficit > 0.5 else 64.0
    excess, slope = _momentum_excess(lower, centre_deficit, loading, log_width_squared)
    if not excess > 0.0:
        return GAUSSIAN_ORDER
    order = lower
    for _ in range(2 * BISECTION_STEPS):
        step = excess / slope
        trial = order - step
        if not (trial > lower and trial < upper):
            trial = 0.5 * (lower + upper)
        if abs(trial - order) <= 2e-16 * order or not (lower < trial < upper):
            break
        order = trial
        excess, slope = _momentum_excess(order, centre_deficit, loading, log_width_squared)
        if excess > 0.0:
            lower = order
        elif excess < 0.0:
            upper = order
        else:
            break
    return order


@numba.njit(**JIT)
def _wake_table(x, k_w, radius, ct, yaw, friction_velocity, hub_speed, curl, near_wake,
                polar_veer, bound_only, out):
    # The factors of the wake alone (its rotor's k_w, R, ct, yaw, U_h, u*), evaluated again only
    # where they change from one pair to the next (the pairs come wake by wake: one per
    # condition).
    kw = r = c_t = beta = speed = u_star = np.nan
    cos_b = root = induction = core = width0 = cos_cubed = np.nan
    xi0 = sin2b = strength = bound0 = np.nan
    for k in range(x.size):
        xk = x[k]
        if not (k_w[k] == kw and radius[k] == r and ct[k] == c_t and yaw[k] == beta
                and hub_speed[k] == speed and friction_velocity[k] == u_star):
            kw, r, c_t, beta = k_w[k], radius[k], ct[k], yaw[k]
            speed, u_star = hub_speed[k], friction_velocity[k]
            cos_b, sin_b = np.cos(beta), np.sin(beta)
            # Momentum theory of the yawed rotor, Eqs. (A_star), (ind_factor) (wake/deficit.py).
            root = np.sqrt(1.0 - c_t * (cos_b * cos_b))
            area = (1.0 + root) / (2.0 * root)
            r_tube = r * np.sqrt(area)
            induction = c_t * (cos_b * cos_b) / (2.0 * (1.0 + root))
            # x0, Eq. (x0_transition), with sigma_tilde^2 of Eq. (sigma_tilde).
            core = (np.sqrt(r_tube**2 * (1.0 - cos_b) ** 2 + 12.5 * r**2 * cos_b)
                    + r_tube * (1.0 - cos_b) - 2.0 * r_tube) / (5.0 * kw)
            width0 = WIDTH_FACTOR * r_tube
            cos_cubed = cos_b**3.0
            xi0 = WIDTH_FACTOR * r_tube * abs(cos_b)
            sin2b = sin_b**2
            # t_hat's prefactor, Eq. (that) (0: no curl, xi_hat = 1).
            strength = (-1.44 * (speed / u_star) / np.sqrt(area)
                        * (c_t * (cos_b * cos_b) * sin_b)) if curl else 0.0
            bound0 = WIDTH_FACTOR * r_tube * (1.0 + CURL_ALPHA)
        # C(x), Eq. (Cx).
        x_decay = max(xk, core)
        q = c_t * cos_cubed * r**2 / (2.0 * ((kw * x_decay + width0)
                                            * (kw * x_decay + width0 * cos_b)))
        decay = q / (1.0 + np.sqrt(max(1.0 - q, 0.0)))
        amplitude = 2.0 * induction if xk <= core else decay
        # The near wake's super-Gaussian inside the core (wake/near_wake.py near_wake_shape).
        order, factor = GAUSSIAN_ORDER, 1.0
        x_wake = max(xk, 0.0)
        if near_wake and x_wake < core:
            width_squared = ((kw * x_wake + width0) * (kw * x_wake + width0 * cos_b)
                             / (2.0 * r) ** 2)
            if bound_only:
                # m = (2 w^2)^(1/n - 1/2) with n >= 2 is at most 1 / sqrt(2 w^2) below
                # 2 w^2 = 1, at most 1 above (widened by the round-off).
                order = DEFERRED_ORDER
                factor = (1.0 + 1e-12) * (1.0 / np.sqrt(2.0 * width_squared)
                                          if 2.0 * width_squared < 1.0 else 1.0)
            else:
                order = super_gaussian_order(2.0 * induction, c_t * cos_cubed, width_squared)
                if order != GAUSSIAN_ORDER:
                    factor = (2.0 * width_squared) ** (1.0 / order - 0.5)
        out[k, 0] = amplitude
        out[k, 1] = kw * xk * factor
        out[k, 2] = xi0 * factor
        out[k, 3] = sin2b
        out[k, 4] = strength
        out[k, 5] = polar_veer
        out[k, 6] = order
        out[k, 7] = (kw * xk + bound0) * factor
        out[k, 8] = amplitude
        out[k, 9] = amplitude


def wake_table(x, k_w, radius, ct, yaw, friction_velocity, hub_speed, curl=True,
               near_wake=True, polar_veer=0.0, bound_only=False):
    """The per-wake factors of Eq. (du_model) for the rotor-cell kernel and the wake's reach,
    (pairs, :data:`WAKE_TABLE`), compiled, one row per wake and rotor: the same numbers as
    :func:`wake_deficit_parameters` with wake/near_wake.py's ``near_wake_shape`` (with
    ``near_wake``) and the bounds of the M-1 velocity model (``width_bound``: k_w x +
    0.4 R sqrt(A*) (1 + alpha), times the near wake's width factor; ``amplitude_bound`` and
    ``centre_deficit``: C(x)), in one pass (tests/physics/test_near_wake.py compares them).
    Arguments: 1-D arrays of the pairs (``x`` > 0 the distance behind the rotor; the
    thrust coefficient ``ct`` within momentum theory, as the velocity model limits it).
    ``bound_only``: a near-wake pair's order is not solved (``shape`` DEFERRED_ORDER) and its
    ``width_bound`` is the bound over every order: the table to choose the rotors a wake
    reaches by, cheaply, before their exact table."""
    arrays = [_contiguous(a, np.shape(x))
              for a in (x, k_w, radius, ct, yaw, friction_velocity, hub_speed)]
    out = np.empty((arrays[0].size, len(WAKE_TABLE)))
    _wake_table(*arrays, bool(curl), bool(near_wake), float(polar_veer), bool(bound_only), out)
    return out
