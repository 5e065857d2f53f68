"""Velocity deficit of one wake: Narasimhan, Gayme & Meneveau (JRSE 2025), Section 2.1-2.2.

    Delta u / U_h = C(x) exp[-((y - y_c)^2 + (z - z_h)^2) / (2 sigma(theta, x)^2)]   Eq. (du_model)

Every function is pure numpy and broadcasts its arguments by numpy rules, so the caller may pass
FLORIS's 4-D arrays or plain scalars. Conventions (docs/conventions.md#frames-and-signs): right-handed frame, x
downstream, y to the left looking downstream, z up; yaw ``beta`` in radians, positive yaw sends the
wake to -y. ``ct`` is always the UN-YAWED thrust coefficient C_T: the equations apply cos^2(beta)
and cos^3(beta) themselves (docs/conventions.md#thrust-coefficient-and-yaw). Lengths are in metres, speeds in m/s.

Invalid parameters raise ``ValueError`` naming the parameter and its valid range; nothing is
clipped silently and no function returns NaN for valid input.
"""

from __future__ import annotations

import numpy as np

from floris_ekman_veer._validation import positive, require

#: Empirical constant of the vortex-sheet shape, Eq. (xi_emp).
CURL_ALPHA = 1.263

#: Largest alpha for which xi_hat > 0 for all theta and t_hat: as |t_hat| -> inf every tanh in
#: Eq. (xi_emp) saturates and, at the polar angle of the kidney's notch, xi_hat -> 1 - alpha 38/48.
CURL_ALPHA_MAX = 48.0 / 38.0

#: sigma = k_w x + WIDTH_FACTOR xi, Eq. (sigma_width); the same 0.4 appears in Eq. (sigma_tilde).
WIDTH_FACTOR = 0.4


# --------------------------------------------------------------------------------------------
# Validation (shared with deflection.py and gaussian2014.py)
# --------------------------------------------------------------------------------------------


def unyawed_thrust_coefficient(ct) -> np.ndarray:
    """C_T of an unyawed formula (M-3) as a float array, required in [0, 1) (momentum theory)."""
    ct = np.asarray(ct, dtype=float)
    require((ct >= 0.0) & (ct < 1.0), "ct", "in [0, 1) (un-yawed thrust coefficient)", ct)
    return ct


def _yaw(yaw) -> np.ndarray:
    """Yaw in radians as a float array, required in (-pi/2, pi/2)."""
    yaw = np.asarray(yaw, dtype=float)
    require(np.abs(yaw) < 0.5 * np.pi, "yaw", "in (-pi/2, pi/2) radians", yaw)
    return yaw


def _momentum_root(ct, yaw) -> np.ndarray:
    """sqrt(1 - C_T cos^2 beta) = 1 - 2a: the root shared by Eqs. (A_star) and (ind_factor).

    The yawed rotor's momentum theory needs the normal loading C_T cos^2 beta below 1; the
    un-yawed C_T itself may exceed 1 (a yawed, heavily loaded rotor).
    """
    ct = np.asarray(ct, dtype=float)
    loading = ct * np.cos(_yaw(yaw)) ** 2
    require(
        np.isfinite(ct) & (ct >= 0.0) & (loading < 1.0), "ct",
        ">= 0 with ct cos^2(yaw) < 1 (un-yawed thrust coefficient; momentum theory)", ct,
    )
    return np.sqrt(1.0 - loading)


def initial_radius(radius, ct, yaw) -> np.ndarray:
    """R sqrt(A*), the radius of the expanded stream tube: the length unit of Eqs. (xi0_theta),
    (that) and (yhatc)."""
    return positive(radius, "radius") * np.sqrt(stream_tube_area_ratio(ct, yaw))


def _tube_radius(radius, root) -> np.ndarray:
    """:func:`initial_radius` from the momentum root (:func:`_momentum_root`)."""
    return radius * np.sqrt(_area_ratio(root))


# --------------------------------------------------------------------------------------------
# Momentum theory of the yawed rotor
# --------------------------------------------------------------------------------------------


def stream_tube_area_ratio(ct, yaw):
    """Expanded stream-tube area over rotor frontal area, Eq. (A_star).

    A* = (1 + sqrt(1 - C_T cos^2 beta)) / (2 sqrt(1 - C_T cos^2 beta)).

    Parameters: ``ct`` un-yawed C_T in [0, 1); ``yaw`` beta in (-pi/2, pi/2) rad. A* >= 1, = 1 at
    C_T = 0.
    """
    return _area_ratio(_momentum_root(ct, yaw))


def _area_ratio(root):
    """A* of Eq. (A_star) from the momentum root s = sqrt(1 - C_T cos^2 beta)."""
    return (1.0 + root) / (2.0 * root)


def axial_induction(ct, yaw):
    """Axial induction factor a, Eq. (ind_factor): a = (1 - sqrt(1 - C_T cos^2 beta)) / 2.

    Evaluated in the algebraically identical form C_T cos^2 beta / (2 (1 + sqrt(...))), which keeps
    full relative precision for small C_T (the printed form loses it to cancellation).
    """
    return _induction(ct, yaw, _momentum_root(ct, yaw))


def _induction(ct, yaw, root):
    """a of Eq. (ind_factor) from the momentum root (:func:`axial_induction`'s form)."""
    return np.asarray(ct) * np.cos(yaw) ** 2 / (2.0 * (1.0 + root))


# --------------------------------------------------------------------------------------------
# Maximum deficit C(x)
# --------------------------------------------------------------------------------------------


def sigma_tilde_squared(x, k_w, radius, ct, yaw):
    """Effective squared width of the deficit magnitude, Eq. (sigma_tilde), in m^2.

    sigma_tilde^2 = (k_w x + 0.4 R sqrt(A*)) (k_w x + 0.4 R sqrt(A*) cos beta).

    Both factors grow from x = 0 (no virtual origin, docs/wake_model.md#wake-width). ``k_w`` > 0, ``radius`` > 0.
    """
    x = np.asarray(x, dtype=float)
    k_w = positive(k_w, "k_w")
    return _width_product(x, k_w, initial_radius(radius, ct, yaw), yaw)


def _width_product(x, k_w, r_tube, yaw):
    """sigma_tilde^2 of Eq. (sigma_tilde) from the stream tube's radius R sqrt(A*)."""
    width0 = WIDTH_FACTOR * r_tube
    return (k_w * x + width0) * (k_w * x + width0 * np.cos(yaw))


def potential_core_length(k_w, radius, ct, yaw):
    """End of the potential core x0, Eq. (x0_transition), in metres.

    x0 = [sqrt(R^2 A* (1 - cos b)^2 + 25 R^2/2 C_T cos^3 b / (1 - (1 - 2a)^2))
          + R sqrt(A*) (1 - cos b)] / (5 k_w) - 2 R sqrt(A*) / (5 k_w),

    the root of C_decay(x0) = 2a, so C(x) of Eq. (Cx) is continuous at x0; x0 is inversely
    proportional to k_w. Because 1 - (1 - 2a)^2 = C_T cos^2 beta exactly, the ratio
    C_T cos^3 b / (1 - (1 - 2a)^2) is evaluated as cos b, which keeps x0 finite at C_T = 0
    (where the printed form is 0/0).

    x0 < 0 when C_T cos^2 beta > 0.9637 (then A* > 3.125 and the stream tube is already wider than
    the width where C = 2a): there is no potential core and C(x) decays from the rotor on. The value
    is returned as is.
    """
    k_w = positive(k_w, "k_w")
    radius = positive(radius, "radius")
    return _core_length(k_w, radius, initial_radius(radius, ct, yaw), yaw)


def _core_length(k_w, radius, r_tube, yaw):
    """x0 of Eq. (x0_transition) from the stream tube's radius R sqrt(A*)."""
    cos_b = np.cos(yaw)
    root = np.sqrt(r_tube**2 * (1.0 - cos_b) ** 2 + 12.5 * radius**2 * cos_b)
    return (root + r_tube * (1.0 - cos_b) - 2.0 * r_tube) / (5.0 * k_w)


def max_deficit(x, k_w, radius, ct, yaw):
    """Maximum normalised deficit C(x) = Delta u_max / U_h, Eq. (Cx).

    C = 2a for x <= x0 (potential core, Eq. ind_factor), and beyond
    C = 1 - sqrt(1 - C_T cos^3 beta / (2 sigma_tilde^2 / R^2)).

    Defined for every real x (x <= x0, upstream included, gives 2a); the caller decides where a
    wake exists. The decaying branch is evaluated as q / (1 + sqrt(1 - q)), identical to
    1 - sqrt(1 - q) but free of cancellation when C is small far downstream.
    """
    x = np.asarray(x, dtype=float)
    radius = positive(radius, "radius")
    k_w = positive(k_w, "k_w")
    # Momentum theory once for x0, sigma_tilde and 2a (the same operations as
    # potential_core_length, sigma_tilde_squared and axial_induction).
    root = _momentum_root(ct, yaw)
    r_tube = _tube_radius(radius, root)
    x0 = _core_length(k_w, radius, r_tube, yaw)
    # The decaying branch is real only for x >= x0; evaluate it there and nowhere else.
    x_decay = np.maximum(x, x0)
    q = np.asarray(ct) * np.cos(yaw) ** 3 * radius**2 / (
        2.0 * _width_product(x_decay, k_w, r_tube, yaw)
    )
    # Analytically 1 - q >= 1 - C_T cos^2 beta > 0 for x >= x0; the floor absorbs rounding only.
    decay = q / (1.0 + np.sqrt(np.maximum(1.0 - q, 0.0)))
    return np.where(x <= x0, 2.0 * _induction(ct, yaw, root), decay)


# --------------------------------------------------------------------------------------------
# Polar-angle dependent width sigma(theta, x)
# --------------------------------------------------------------------------------------------


def polar_harmonics(dy, dz):
    """cos(theta), sin(theta), cos(2 theta), cos(3 theta), cos(4 theta) of the polar angle
    theta = arctan2(dz, dy), Eq. (polar_angle) read four-quadrant (docs/wake_model.md#polar-angle).

    No trigonometric call: cos = dy/r, sin = dz/r with r = hypot(dy, dz), and the multiples follow
    from the Chebyshev recurrence T_{n+1} = 2 cos(theta) T_n - T_{n-1}, which keeps the quadrant
    information that a two-quadrant arctan(dz/dy) would lose (it flips cos(3 theta) for dy < 0).

    At the centre r = 0 theta is undefined; there theta := 0 (cos = 1, sin = 0). The choice is
    immaterial for the deficit, whose Gaussian factor is exp(0) = 1 at r = 0 for any width.
    Returns five arrays of the broadcast shape of ``dy`` and ``dz``.
    """
    dy, dz = np.broadcast_arrays(np.asarray(dy, dtype=float), np.asarray(dz, dtype=float))
    r = np.hypot(dy, dz)
    at_centre = r == 0.0
    r_safe = np.where(at_centre, 1.0, r)
    cos_t = np.where(at_centre, 1.0, dy / r_safe)
    sin_t = dz / r_safe  # dz = 0 at the centre, so sin = 0 there
    cos2 = 2.0 * cos_t * cos_t - 1.0
    cos3 = 2.0 * cos_t * cos2 - cos_t
    cos4 = 2.0 * cos_t * cos3 - cos2
    return cos_t, sin_t, cos2, cos3, cos4


def initial_wake_shape(sin_t, radius, ct, yaw):
    """Initial (x = 0) wake shape xi0(theta), Eq. (xi0_theta), in metres.

    xi0 = R sqrt(A*) |cos beta| / sqrt(1 - sin^2 beta sin^2 theta): the ellipse of the yawed disk's
    projection, narrow in y (theta = 0) and R sqrt(A*) tall in z. ``sin_t`` in [-1, 1].
    """
    sin_t = np.asarray(sin_t, dtype=float)
    require(np.abs(sin_t) <= 1.0, "sin_t", "in [-1, 1]", sin_t)
    sin_b = np.sin(yaw)
    return (
        initial_radius(radius, ct, yaw)
        * np.abs(np.cos(yaw))
        / np.sqrt(1.0 - sin_b**2 * sin_t**2)
    )


def curl_shape(t_hat, cos2, cos3, cos4, alpha=CURL_ALPHA):
    """Dimensionless vortex-sheet radius xi_hat(theta, t_hat), Eq. (xi_emp) (dimensionless).

    xi_hat = 1 - alpha [ 1/2 tanh(t^2/(4 alpha)) cos 2theta - 1/4 tanh(t^3/(8 alpha)) cos 3theta
                         - 5/48 tanh(t^4/(16 alpha)) cos 2theta
                         + 7/48 tanh(t^4/(16 alpha)) cos 4theta ].

    The two cos(2 theta) terms are kept separate as printed (docs/wake_model.md#curled-shape). xi_hat = 1 at
    t_hat = 0. For t_hat < 0 (beta > 0) the notch of the kidney is at theta = 0 (+y side) and the
    lobes stretch vertically. ``alpha`` in (0, 48/38): beyond 48/38 xi_hat turns negative at the
    notch for large |t_hat|, and the wake width with it.
    """
    t_hat = np.asarray(t_hat, dtype=float)
    alpha = np.asarray(alpha, dtype=float)
    require((alpha > 0.0) & (alpha < CURL_ALPHA_MAX), "alpha", "in (0, 48/38)", alpha)
    if not np.any(t_hat):
        # Unyawed rotors (t_hat = 0 everywhere): xi_hat = 1 exactly; skip the work.
        return np.ones(np.broadcast_shapes(t_hat.shape, *map(np.shape, (cos2, cos3, cos4, alpha))))
    tanh2 = np.tanh(t_hat**2 / (4.0 * alpha))
    tanh3 = np.tanh(t_hat**3 / (8.0 * alpha))
    tanh4 = np.tanh(t_hat**4 / (16.0 * alpha))
    bracket = (
        0.5 * tanh2 * cos2
        - 0.25 * tanh3 * cos3
        - 5.0 / 48.0 * tanh4 * cos2
        + 7.0 / 48.0 * tanh4 * cos4
    )
    return 1.0 - alpha * bracket


def time_like_variable(x, friction_velocity, hub_speed, local_speed, radius, ct, yaw):
    """Dimensionless time-like variable t_hat(x, z), Eq. (that).

    t_hat = -1.44 (U_h/u*) (R / (R sqrt(A*))) C_T cos^2 beta sin beta
            [1 - exp(-0.35 (u*/U(z)) x/R)].

    U_h (``hub_speed``) sets the circulation of the vortex pair (prefactor); the local U(z)
    (``local_speed``) sets the advection time to x (exponential), docs/wake_model.md#which-velocity-goes-where. beta > 0 gives
    t_hat < 0. Time counts from the rotor plane, so t_hat = 0 for x <= 0. All speeds must be
    finite and > 0: U(z) <= 0 (at or below the roughness height) carries nothing downstream.
    1 - exp(-y) is evaluated as -expm1(-y) to keep precision close to the rotor.
    """
    return time_like_strength(friction_velocity, hub_speed, ct, yaw) * time_like_growth(
        x, friction_velocity, local_speed, radius)


def time_like_strength(friction_velocity, hub_speed, ct, yaw):
    """The prefactor of t_hat, Eq. (that): -1.44 (U_h/u*) C_T cos^2 beta sin beta / sqrt(A*),
    one per wake (:func:`time_like_variable`)."""
    u_star = positive(friction_velocity, "friction_velocity")
    u_hub = positive(hub_speed, "hub_speed")
    sqrt_area = np.sqrt(stream_tube_area_ratio(ct, yaw))
    yaw_thrust = np.asarray(ct) * np.cos(yaw) ** 2 * np.sin(yaw)
    return -1.44 * (u_hub / u_star) / sqrt_area * yaw_thrust


def time_like_growth(x, friction_velocity, local_speed, radius):
    """The advection factor of t_hat, Eq. (that): 1 - exp(-0.35 (u*/U(z)) x/R), 0 for x <= 0
    (:func:`time_like_variable`)."""
    x = np.asarray(x, dtype=float)
    u_star = positive(friction_velocity, "friction_velocity")
    u_local = positive(local_speed, "local_speed")
    radius = positive(radius, "radius")
    return -np.expm1(-0.35 * (u_star / u_local) * np.maximum(x, 0.0) / radius)


def wake_width(x, k_w, xi):
    """Polar-angle dependent wake width sigma(theta, x) = k_w x + 0.4 xi(theta, x), Eq.
    (sigma_width), in metres (xi = xi0 xi_hat, Eq. wake_shape_function, carries the length)."""
    x = np.asarray(x, dtype=float)
    return positive(k_w, "k_w") * x + WIDTH_FACTOR * np.asarray(xi, dtype=float)


# --------------------------------------------------------------------------------------------
# The deficit
# --------------------------------------------------------------------------------------------


def normalised_deficit(
    x,
    dy,
    dz,
    *,
    k_w,
    radius,
    ct,
    yaw,
    friction_velocity=None,
    hub_speed=None,
    local_speed=None,
    curl=True,
    polar_dy=None,
    shape=None,
):
    """Normalised velocity deficit Delta u / U_h of one wake, Eq. (du_model).

    Parameters
    ----------
    x : streamwise distance behind the rotor (m). The deficit is 0 for x <= 0.
    dy : y - y_c, lateral distance from the full wake centre (yaw + veer, Eq. yc_xz) (m).
    dz : z - z_h (m).
    k_w, radius, ct, yaw : wake expansion rate (> 0), rotor radius (> 0), un-yawed C_T in [0, 1),
        yaw in (-pi/2, pi/2) rad.
    friction_velocity, hub_speed, local_speed : u*, U_h and U(z) of Eq. (that), needed when
        ``curl`` is True.
    curl : False sets xi_hat = 1 (the initial ellipse only, no curling).
    polar_dy : if given, the lateral distance used ONLY for the polar angle theta. The paper
        measures theta from the full centre (default, ``polar_dy=None``); the authors' published
        code measures it from the yaw-only centre while centring the Gaussian on the full one
        (docs/wake_model.md#polar-angle): pass y - y_c,yaw to reproduce that.
    shape : None (the paper's Gaussian), or (n, m) of wake/near_wake.py's ``near_wake_shape``:
        the profile exp(-(rho^2 / (2 (m sigma)^2))^(n/2)), the super-Gaussian that carries the
        rotor's thrust inside the potential core (docs/wake_model.md#near-wake; beyond the
        paper); where n = 2 the Gaussian itself (bit for bit), and the centre deficit is C(x).

    sigma(theta, x) > 0 for x >= 0 (xi0 > 0 and xi_hat > 0 for alpha < 48/38), so the Gaussian is
    always defined.
    """
    x = np.asarray(x, dtype=float)
    dy = np.asarray(dy, dtype=float)
    dz = np.asarray(dz, dtype=float)
    # Upstream points carry no wake; evaluating them at the rotor plane keeps every term finite.
    x_wake = np.maximum(x, 0.0)
    _, sin_t, cos2, cos3, cos4 = polar_harmonics(dy if polar_dy is None else polar_dy, dz)
    xi = initial_wake_shape(sin_t, radius, ct, yaw)
    if curl:
        speeds = {"friction_velocity": friction_velocity, "hub_speed": hub_speed,
                  "local_speed": local_speed}
        for name, value in speeds.items():
            if value is None:
                raise ValueError(f"{name} must be given (finite and > 0) when curl=True")
        t_hat = time_like_variable(
            x_wake, friction_velocity, hub_speed, local_speed, radius, ct, yaw
        )
        xi = xi * curl_shape(t_hat, cos2, cos3, cos4)
    sigma = wake_width(x_wake, k_w, xi)
    gaussian = np.exp(-(dy**2 + dz**2) / (2.0 * sigma**2))
    if shape is not None:
        order, factor = shape
        shaped = np.exp(-((dy**2 + dz**2) / (2.0 * (factor * sigma) ** 2)) ** (0.5 * order))
        gaussian = np.where(order == 2.0, gaussian, shaped)
    return np.where(x > 0.0, max_deficit(x_wake, k_w, radius, ct, yaw) * gaussian, 0.0)
