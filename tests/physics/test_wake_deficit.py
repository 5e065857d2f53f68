"""Tests of floris_ekman_veer.wake.deficit: every equation against arithmetic done here by hand
(plain ``math`` on scalars), plus the limits and properties of docs/wake_model.md."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from floris_ekman_veer.wake import deficit as wd

# A CNBL-like case: actuator disk C_T' = 1.33 -> a = 1.33/5.33, C_T = 4a(1 - a) = 0.7491.
CT = 0.7491
R = 50.0
D = 2.0 * R
BETA = math.radians(20.0)
KW = 0.04
USTAR = 0.45
UH = 9.0
UZ = 8.5  # != UH on purpose: a swap of U_h and U(z) in Eq. (that) changes the result
RTOL = 1e-12


# ------------------------------------------------------------------------- hand arithmetic
def hand_root(ct, beta):
    return math.sqrt(1.0 - ct * math.cos(beta) ** 2)


def hand_astar(ct, beta):
    s = hand_root(ct, beta)
    return (1.0 + s) / (2.0 * s)


def hand_a(ct, beta):
    return 0.5 * (1.0 - hand_root(ct, beta))


def hand_two_a_bound(ct, beta):
    """2a in the rationalised form C_T cos^2 b / (1 + s): no cancellation at tiny C_T."""
    return ct * math.cos(beta) ** 2 / (1.0 + hand_root(ct, beta)) * (1 + 1e-12)


def hand_sigma_tilde2(x, kw, r, ct, beta):
    w = 0.4 * r * math.sqrt(hand_astar(ct, beta))
    return (kw * x + w) * (kw * x + w * math.cos(beta))


def hand_x0(kw, r, ct, beta):
    """Eq. (x0_transition) exactly as printed."""
    astar = hand_astar(ct, beta)
    a = hand_a(ct, beta)
    c = math.cos(beta)
    inner = r**2 * astar * (1 - c) ** 2 + 25 * r**2 / 2 * ct * c**3 / (1 - (1 - 2 * a) ** 2)
    return (math.sqrt(inner) + r * math.sqrt(astar) * (1 - c)) / (5 * kw) - 2 / (
        5 * kw
    ) * r * math.sqrt(astar)


def hand_c_decay(x, kw, r, ct, beta):
    return 1.0 - math.sqrt(
        1.0 - ct * math.cos(beta) ** 3 / (2.0 * hand_sigma_tilde2(x, kw, r, ct, beta) / r**2)
    )


def hand_that(x, ustar, uh, uz, r, ct, beta):
    astar = hand_astar(ct, beta)
    return (
        -1.44
        * uh
        / ustar
        * r
        / (r * math.sqrt(astar))
        * ct
        * math.cos(beta) ** 2
        * math.sin(beta)
        * (1.0 - math.exp(-0.35 * ustar / uz * x / r))
    )


def hand_xi_hat(t, theta, alpha=1.263):
    return 1.0 - alpha * (
        0.5 * math.tanh(t**2 / (4 * alpha)) * math.cos(2 * theta)
        - 0.25 * math.tanh(t**3 / (8 * alpha)) * math.cos(3 * theta)
        - 5 / 48 * math.tanh(t**4 / (16 * alpha)) * math.cos(2 * theta)
        + 7 / 48 * math.tanh(t**4 / (16 * alpha)) * math.cos(4 * theta)
    )


def hand_xi0(theta, r, ct, beta):
    return (
        r
        * math.sqrt(hand_astar(ct, beta))
        * abs(math.cos(beta))
        / math.sqrt(1 - math.sin(beta) ** 2 * math.sin(theta) ** 2)
    )


# ------------------------------------------------------------------------- momentum theory
def test_stream_tube_area_ratio_by_hand():
    s = math.sqrt(1 - 0.7491 * math.cos(BETA) ** 2)
    assert wd.stream_tube_area_ratio(CT, BETA) == pytest.approx((1 + s) / (2 * s), rel=RTOL)
    # Un-yawed CNBL disk: s = sqrt(0.2509) = 0.500899..., A* = 1.498205
    assert wd.stream_tube_area_ratio(CT, 0.0) == pytest.approx(1.4982048454657786, rel=RTOL)
    assert wd.stream_tube_area_ratio(0.0, 0.3) == 1.0


def test_axial_induction_by_hand_and_actuator_disk():
    assert wd.axial_induction(CT, BETA) == pytest.approx(
        0.5 * (1 - math.sqrt(1 - CT * math.cos(BETA) ** 2)), rel=RTOL
    )
    # Actuator disk C_T' = 1.33: a = C_T'/(4 + C_T'), C_T = 4a(1 - a) recovers a.
    a_disk = 1.33 / 5.33
    assert wd.axial_induction(4 * a_disk * (1 - a_disk), 0.0) == pytest.approx(a_disk, rel=RTOL)
    assert wd.axial_induction(0.0, 0.2) == 0.0


def test_yaw_enters_as_cos_squared_of_the_unyawed_ct():
    # C_T cos^2(beta) is what the momentum relations see.
    ct_eff = CT * math.cos(BETA) ** 2
    assert wd.axial_induction(CT, BETA) == pytest.approx(wd.axial_induction(ct_eff, 0.0), rel=RTOL)


# ------------------------------------------------------------------------- C(x)
def test_sigma_tilde_squared_by_hand():
    x = 300.0
    astar = hand_astar(CT, BETA)
    w = 0.4 * 50.0 * math.sqrt(astar)
    expected = (0.04 * 300.0 + w) * (0.04 * 300.0 + w * math.cos(BETA))
    assert wd.sigma_tilde_squared(x, KW, R, CT, BETA) == pytest.approx(expected, rel=RTOL)
    # Grows from x = 0, no virtual origin: sigma_tilde^2(0) = (0.4 R sqrt(A*))^2 cos(beta).
    assert wd.sigma_tilde_squared(0.0, KW, R, CT, BETA) == pytest.approx(
        w * w * math.cos(BETA), rel=RTOL
    )


@pytest.mark.parametrize("beta", [0.0, BETA, -BETA, math.radians(35.0)])
def test_potential_core_length_matches_printed_equation(beta):
    assert wd.potential_core_length(KW, R, CT, beta) == pytest.approx(
        hand_x0(KW, R, CT, beta), rel=RTOL
    )


def test_potential_core_length_inversely_proportional_to_kw():
    x0 = wd.potential_core_length(np.array([0.021, 0.0375, 0.06]), R, CT, BETA)
    np.testing.assert_allclose(x0 * np.array([0.021, 0.0375, 0.06]), x0[0] * 0.021, rtol=RTOL)


@pytest.mark.parametrize(
    "kw, x0_over_d", [(0.021, 5.1786206642341135), (0.0375, 2.900027571971104)]
)
def test_potential_core_length_cnbl_and_sbl_scale(kw, x0_over_d):
    # beta = 0: x0 = R (sqrt(25/2) - 2 sqrt(A*)) / (5 k_w). With k_w = 0.0375 (CNBL-like) and the
    # 0.021 floor of Eq. (kw_CNBL_SBL_model) (SBL-6-like) this is the paper's ~3 D and ~5 D.
    s = math.sqrt(1 - 0.7491)
    astar = (1 + s) / (2 * s)
    by_hand = R * (math.sqrt(12.5) - 2 * math.sqrt(astar)) / (5 * kw) / D
    assert by_hand == pytest.approx(x0_over_d, rel=RTOL)
    assert wd.potential_core_length(kw, R, CT, 0.0) / D == pytest.approx(by_hand, rel=RTOL)


@pytest.mark.parametrize("ct, beta", [(CT, 0.0), (CT, BETA), (0.3, -0.5), (0.95, 0.2), (1e-6, 0.0)])
def test_max_deficit_continuous_at_x0(ct, beta):
    x0 = float(wd.potential_core_length(KW, R, ct, beta))
    two_a = 2 * float(wd.axial_induction(ct, beta))
    assert wd.max_deficit(x0, KW, R, ct, beta) == two_a
    just_after = x0 + 1e-9 * max(abs(x0), R)
    assert wd.max_deficit(just_after, KW, R, ct, beta) == pytest.approx(two_a, rel=1e-9)
    # The decaying branch evaluated AT x0 is 2a: that is what Eq. (x0_transition) solves.
    if ct == CT:
        assert hand_c_decay(x0, KW, R, ct, beta) == pytest.approx(two_a, rel=1e-12)


def test_max_deficit_by_hand_both_branches():
    x0 = hand_x0(KW, R, CT, BETA)
    for x in (0.0, 0.5 * x0, x0):
        assert wd.max_deficit(x, KW, R, CT, BETA) == pytest.approx(2 * hand_a(CT, BETA), rel=RTOL)
    for x in (1.5 * x0, 800.0, 5000.0):
        assert wd.max_deficit(x, KW, R, CT, BETA) == pytest.approx(
            hand_c_decay(x, KW, R, CT, BETA), rel=RTOL
        )
    c = wd.max_deficit(np.linspace(x0, 20 * D, 200), KW, R, CT, BETA)
    assert np.all(np.diff(c) < 0)


def test_no_potential_core_at_very_high_thrust():
    # C_T cos^2 beta > 0.9637: A* > 3.125, x0 < 0 and C decays from the rotor on, below 2a.
    x0 = wd.potential_core_length(KW, R, 0.98, 0.0)
    assert x0 < 0
    c0 = wd.max_deficit(0.0, KW, R, 0.98, 0.0)
    assert c0 == pytest.approx(hand_c_decay(0.0, KW, R, 0.98, 0.0), rel=RTOL)
    assert c0 < 2 * hand_a(0.98, 0.0)


# ------------------------------------------------------------------------- polar angle
QUADRANT_POINTS = [
    (3.0, 1.0), (1.0, 3.0), (-1.0, 3.0), (-3.0, 1.0), (-3.0, -1.0), (-1.0, -3.0),
    (1.0, -3.0), (3.0, -1.0), (2.0, 0.0), (0.0, 2.0), (-2.0, 0.0), (0.0, -2.0), (1.0, 1.0),
]


@pytest.mark.parametrize("dy, dz", QUADRANT_POINTS)
def test_polar_harmonics_four_quadrant(dy, dz):
    theta = math.atan2(dz, dy)
    got = wd.polar_harmonics(dy, dz)
    expected = (math.cos(theta), math.sin(theta), math.cos(2 * theta), math.cos(3 * theta),
                math.cos(4 * theta))
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14)


def test_cos3_sign_in_each_quadrant_and_two_quadrant_arctan_would_flip_it():
    dy = np.array([3.0, -3.0, -3.0, 3.0])
    dz = np.array([1.0, 1.0, -1.0, -1.0])  # Q1, Q2, Q3, Q4, near the y axis
    cos3 = wd.polar_harmonics(dy, dz)[3]
    reference = np.cos(3 * np.arctan2(dz, dy))
    np.testing.assert_array_equal(np.sign(cos3), [1.0, -1.0, -1.0, 1.0])
    np.testing.assert_allclose(cos3, reference, atol=1e-14)
    two_quadrant = np.cos(3 * np.arctan(dz / dy))
    assert np.all(np.sign(two_quadrant[1:3]) != np.sign(cos3[1:3]))


def test_polar_harmonics_at_the_centre_and_broadcasting():
    cos_t, sin_t, cos2, cos3, cos4 = wd.polar_harmonics(0.0, 0.0)
    assert (cos_t, sin_t, cos2, cos3, cos4) == (1.0, 0.0, 1.0, 1.0, 1.0)
    out = wd.polar_harmonics(np.zeros((3, 1)), np.zeros((1, 4)))
    assert all(o.shape == (3, 4) for o in out)
    assert np.all(out[0] == 1.0) and np.all(out[1] == 0.0)


def test_polar_harmonics_identity():
    rng = np.random.default_rng(0)
    dy, dz = rng.normal(size=(2, 1000)) * 100
    cos_t, sin_t, *_ = wd.polar_harmonics(dy, dz)
    np.testing.assert_allclose(cos_t**2 + sin_t**2, 1.0, rtol=1e-14)


# ------------------------------------------------------------------------- wake shape
def test_initial_wake_shape_by_hand():
    rho = R * math.sqrt(hand_astar(CT, BETA))
    # theta = 0: the yawed disk's narrow axis, rho cos(beta); theta = pi/2: full height rho.
    assert wd.initial_wake_shape(0.0, R, CT, BETA) == pytest.approx(rho * math.cos(BETA), rel=RTOL)
    assert wd.initial_wake_shape(1.0, R, CT, BETA) == pytest.approx(rho, rel=RTOL)
    theta = 0.7
    assert wd.initial_wake_shape(math.sin(theta), R, CT, BETA) == pytest.approx(
        hand_xi0(theta, R, CT, BETA), rel=RTOL
    )
    assert wd.initial_wake_shape(0.3, R, CT, 0.0) == pytest.approx(
        R * math.sqrt(hand_astar(CT, 0.0)), rel=RTOL
    )


@pytest.mark.parametrize("t", [-2.5, -0.7, 0.4, 1.9])
@pytest.mark.parametrize("theta", [0.0, 0.6, 2.0, -2.7, math.pi / 2])
def test_curl_shape_by_hand(t, theta):
    got = wd.curl_shape(t, math.cos(2 * theta), math.cos(3 * theta), math.cos(4 * theta))
    assert got == pytest.approx(hand_xi_hat(t, theta), rel=RTOL)


def test_curl_shape_keeps_both_cos2_terms():
    # At t = 1 the two cos(2 theta) terms have different tanh factors; a merged coefficient
    # (1/2 - 5/48) tanh(t^2/(4 alpha)) would give a different value.
    alpha = 1.263
    merged = 1 - alpha * ((0.5 - 5 / 48) * math.tanh(1 / (4 * alpha)))
    got = wd.curl_shape(1.0, 1.0, 0.0, 0.0)
    expected = 1 - alpha * (0.5 * math.tanh(1 / (4 * alpha)) - 5 / 48 * math.tanh(1 / (16 * alpha)))
    assert got == pytest.approx(expected, rel=RTOL)
    assert abs(got - merged) > 1e-3


def test_curl_shape_kidney_for_positive_yaw():
    # beta > 0 -> t_hat < 0. For large |t_hat| every tanh saturates (to +1, -1, +1) and
    # xi_hat(theta=0) = 1 - alpha (1/2 + 1/4 - 5/48 + 7/48) = 1 - 1.263 * 38/48 = 1.25e-4 (notch)
    # xi_hat(pi)      = 1 - alpha (1/2 - 1/4 - 5/48 + 7/48) = 1 - 1.263 * 14/48 = 0.6316
    # xi_hat(+-pi/2)  = 1 - alpha (-1/2 + 5/48 + 7/48)      = 1 + 1.263 / 4    = 1.31575 (lobes)
    t = -10.0

    def xi_hat(theta):
        return wd.curl_shape(t, math.cos(2 * theta), math.cos(3 * theta), math.cos(4 * theta))

    assert xi_hat(0.0) == pytest.approx(1 - 1.263 * 38 / 48, abs=1e-14)
    assert xi_hat(math.pi) == pytest.approx(1 - 1.263 * 14 / 48, rel=1e-12)
    assert xi_hat(math.pi / 2) == pytest.approx(1 + 1.263 / 4, rel=1e-12)
    assert xi_hat(-math.pi / 2) == pytest.approx(1 + 1.263 / 4, rel=1e-12)
    assert 0 < xi_hat(0.0) < xi_hat(math.pi) < 1 < xi_hat(math.pi / 2)
    # Negative yaw mirrors the kidney: the notch moves to theta = pi (-y).
    assert wd.curl_shape(-t, 1.0, -1.0, 1.0) == pytest.approx(xi_hat(0.0), abs=1e-14)


def test_curl_shape_positive_everywhere():
    t = np.linspace(-60, 60, 2001)[:, None]
    theta = np.linspace(-np.pi, np.pi, 721)[None, :]
    xi = wd.curl_shape(t, np.cos(2 * theta), np.cos(3 * theta), np.cos(4 * theta))
    assert xi.min() > 1.2e-4
    unyawed = wd.curl_shape(np.zeros((3, 1)), np.cos(2 * theta), np.cos(3 * theta), np.cos(4 * theta))
    assert unyawed.shape == (3, theta.size) and np.all(unyawed == 1)


# ------------------------------------------------------------------------- t_hat, sigma
def test_time_like_variable_by_hand():
    x = 400.0
    astar = hand_astar(CT, BETA)
    expected = (
        -1.44 * (9.0 / 0.45) * (50.0 / (50.0 * math.sqrt(astar))) * 0.7491
        * math.cos(BETA) ** 2 * math.sin(BETA)
        * (1 - math.exp(-0.35 * (0.45 / 8.5) * 400.0 / 50.0))
    )
    got = wd.time_like_variable(x, USTAR, UH, UZ, R, CT, BETA)
    assert got == pytest.approx(expected, rel=RTOL)
    assert got < 0  # beta > 0 -> t_hat < 0
    mirrored = wd.time_like_variable(x, USTAR, UH, UZ, R, CT, -BETA)
    assert mirrored == pytest.approx(-expected, rel=RTOL)


def test_time_like_variable_limits():
    assert wd.time_like_variable(0.0, USTAR, UH, UZ, R, CT, BETA) == 0.0
    assert wd.time_like_variable(-300.0, USTAR, UH, UZ, R, CT, BETA) == 0.0
    assert wd.time_like_variable(500.0, USTAR, UH, UZ, R, CT, 0.0) == 0.0
    saturated = -1.44 * UH / USTAR / math.sqrt(hand_astar(CT, BETA)) * CT * math.cos(
        BETA) ** 2 * math.sin(BETA)
    assert wd.time_like_variable(1e7, USTAR, UH, UZ, R, CT, BETA) == pytest.approx(
        saturated, rel=RTOL
    )
    # Close to the rotor: t_hat ~ prefactor * 0.35 (u*/U) x/R, kept to full precision.
    x = 1e-9
    assert wd.time_like_variable(x, USTAR, UH, UZ, R, CT, BETA) == pytest.approx(
        saturated * 0.35 * USTAR / UZ * x / R, rel=1e-9
    )


def test_wake_width_by_hand():
    assert wd.wake_width(250.0, 0.04, 61.0) == pytest.approx(0.04 * 250.0 + 0.4 * 61.0, rel=RTOL)
    np.testing.assert_allclose(
        wd.wake_width(np.array([0.0, 100.0]), 0.03, np.array([[10.0], [20.0]])),
        [[4.0, 7.0], [8.0, 11.0]], rtol=RTOL,
    )


# ------------------------------------------------------------------------- the deficit
def hand_deficit(x, dy, dz, beta, curl=True, theta_dy=None):
    """Eq. (du_model) by hand, from the printed equations, for one point."""
    theta = math.atan2(dz, dy if theta_dy is None else theta_dy)
    xi = hand_xi0(theta, R, CT, beta)
    if curl:
        xi *= hand_xi_hat(hand_that(x, USTAR, UH, UZ, R, CT, beta), theta)
    sigma = KW * x + 0.4 * xi
    x0 = hand_x0(KW, R, CT, beta)
    c = 2 * hand_a(CT, beta) if x <= x0 else hand_c_decay(x, KW, R, CT, beta)
    return c * math.exp(-(dy**2 + dz**2) / (2 * sigma**2))


DEFICIT_KW = dict(k_w=KW, radius=R, ct=CT, friction_velocity=USTAR, hub_speed=UH, local_speed=UZ)
POINTS = [(150.0, 20.0, -10.0), (600.0, -35.0, 25.0), (1200.0, 10.0, 60.0), (900.0, -70.0, -40.0)]


@pytest.mark.parametrize("x, dy, dz", POINTS)
@pytest.mark.parametrize("beta", [0.0, BETA, -math.radians(25.0)])
def test_normalised_deficit_by_hand(x, dy, dz, beta):
    got = wd.normalised_deficit(x, dy, dz, yaw=beta, **DEFICIT_KW)
    assert got == pytest.approx(hand_deficit(x, dy, dz, beta), rel=RTOL)
    no_curl = wd.normalised_deficit(x, dy, dz, yaw=beta, curl=False, **DEFICIT_KW)
    assert no_curl == pytest.approx(hand_deficit(x, dy, dz, beta, curl=False), rel=RTOL)


def test_normalised_deficit_polar_angle_option():
    x, dy, dz, theta_dy = 700.0, 15.0, 30.0, -25.0
    got = wd.normalised_deficit(x, dy, dz, yaw=BETA, polar_dy=theta_dy, **DEFICIT_KW)
    assert got == pytest.approx(hand_deficit(x, dy, dz, BETA, theta_dy=theta_dy), rel=RTOL)
    assert got != pytest.approx(wd.normalised_deficit(x, dy, dz, yaw=BETA, **DEFICIT_KW), rel=1e-3)
    # No yaw: round initial shape and no curl, so the polar angle does not matter.
    assert wd.normalised_deficit(x, dy, dz, yaw=0.0, polar_dy=theta_dy, **DEFICIT_KW) == (
        pytest.approx(wd.normalised_deficit(x, dy, dz, yaw=0.0, **DEFICIT_KW), rel=RTOL)
    )


def test_normalised_deficit_zero_upstream_and_at_rotor():
    x = np.array([-500.0, -1e-9, 0.0])
    got = wd.normalised_deficit(x, 0.0, 0.0, yaw=BETA, **DEFICIT_KW)
    np.testing.assert_array_equal(got, 0.0)
    assert wd.normalised_deficit(1e-6, 0.0, 0.0, yaw=BETA, **DEFICIT_KW) == pytest.approx(
        2 * hand_a(CT, BETA), rel=RTOL
    )


def bpa2014_by_hand(x, dy, dz, ct, d, k_star, epsilon):
    sigma_d = k_star * x / d + epsilon
    c = 1 - math.sqrt(1 - ct / (8 * sigma_d**2))
    return c * math.exp(-(dy**2 + dz**2) / (2 * (sigma_d * d) ** 2))


@pytest.mark.parametrize("curl", [True, False])
def test_zero_yaw_is_bastankhah_porte_agel_2014_beyond_x0(curl):
    epsilon = 0.2 * math.sqrt(hand_astar(CT, 0.0))
    x0 = hand_x0(KW, R, CT, 0.0)
    for x in (x0, x0 + 1.0, 400.0, 1000.0, 3000.0):
        for dy, dz in ((0.0, 0.0), (40.0, -20.0), (-90.0, 70.0)):
            got = wd.normalised_deficit(x, dy, dz, yaw=0.0, curl=curl, **DEFICIT_KW)
            assert got == pytest.approx(bpa2014_by_hand(x, dy, dz, CT, D, KW, epsilon), rel=RTOL)


def test_mirror_symmetry_yaw_and_lateral():
    x = np.linspace(-100, 3000, 23)[:, None, None]
    dy = np.linspace(-250, 250, 21)[None, :, None]
    dz = np.linspace(-90, 150, 17)[None, None, :]
    for beta in (0.1, BETA, 0.6):
        plus = wd.normalised_deficit(x, dy, dz, yaw=beta, **DEFICIT_KW)
        minus = wd.normalised_deficit(x, -dy, dz, yaw=-beta, **DEFICIT_KW)
        np.testing.assert_allclose(plus, minus, rtol=RTOL, atol=0)
        assert not np.allclose(plus, wd.normalised_deficit(x, -dy, dz, yaw=beta, **DEFICIT_KW))


def test_broadcasting_of_4d_floris_shapes():
    # (n_findex, n_turbines, n_grid, n_grid) points with per-(findex, turbine) parameters.
    rng = np.random.default_rng(1)
    shape = (3, 2, 4, 4)
    x = rng.uniform(-200, 2000, shape)
    dy = rng.uniform(-200, 200, shape)
    dz = rng.uniform(-90, 150, shape)
    ct = np.array([0.5, 0.75, 0.8])[:, None, None, None]
    yaw = np.array([0.0, 0.3])[None, :, None, None]
    uz = rng.uniform(5, 10, shape)
    got = wd.normalised_deficit(
        x, dy, dz, k_w=KW, radius=R, ct=ct, yaw=yaw, friction_velocity=USTAR, hub_speed=UH,
        local_speed=uz,
    )
    assert got.shape == shape
    i = (2, 1, 3, 0)
    single = wd.normalised_deficit(
        x[i], dy[i], dz[i], k_w=KW, radius=R, ct=0.8, yaw=0.3, friction_velocity=USTAR,
        hub_speed=UH, local_speed=uz[i],
    )
    assert got[i] == pytest.approx(float(single), rel=RTOL)


def test_inputs_not_mutated_and_read_only_accepted():
    arrays = [np.linspace(-100, 2000, 12), np.linspace(-80, 80, 12), np.linspace(-90, 90, 12),
              np.full(12, 8.0)]
    copies = [a.copy() for a in arrays]
    for a in arrays:
        a.setflags(write=False)
    yaw = np.array(0.3)
    yaw.setflags(write=False)
    x, dy, dz, uz = arrays
    wd.normalised_deficit(x, dy, dz, k_w=KW, radius=R, ct=CT, yaw=yaw, friction_velocity=USTAR,
                          hub_speed=UH, local_speed=uz, polar_dy=dy)
    for a, c in zip(arrays, copies):
        np.testing.assert_array_equal(a, c)
    assert yaw == 0.3


def test_no_nan_on_broad_grid():
    x = np.concatenate([[-1e4, -1.0, 0.0, 1e-12], np.geomspace(1e-3, 1e5, 30)])[:, None, None]
    dy = np.concatenate([[0.0], np.linspace(-1e3, 1e3, 21)])[None, :, None]
    dz = np.concatenate([[0.0, -90.0], np.linspace(-300, 1e3, 21)])[None, None, :]
    for ct in (0.0, 1e-9, 0.5, CT, 0.97, 0.999):
        for beta in (-1.5, -0.5, 0.0, 0.4, 1.5):
            for curl in (True, False):
                out = wd.normalised_deficit(
                    x, dy, dz, yaw=beta, curl=curl,
                    **{**DEFICIT_KW, "ct": ct},
                )
                assert np.all(np.isfinite(out))
                assert np.all(out >= 0) and np.all(out <= hand_two_a_bound(ct, beta))


@settings(max_examples=200, deadline=None)
@given(
    x=st.floats(-1e4, 1e5),
    dy=st.floats(-1e4, 1e4),
    dz=st.floats(-1e4, 1e4),
    ct=st.floats(0.0, 0.999),
    beta=st.floats(-1.55, 1.55),
    kw=st.floats(1e-3, 0.2),
    ustar=st.floats(0.01, 2.0),
    uz=st.floats(0.01, 30.0),
)
def test_deficit_bounded_by_potential_core_value(x, dy, dz, ct, beta, kw, ustar, uz):
    out = wd.normalised_deficit(
        x, dy, dz, k_w=kw, radius=R, ct=ct, yaw=beta, friction_velocity=ustar, hub_speed=10.0,
        local_speed=uz,
    )
    assert np.isfinite(out)
    assert 0.0 <= out <= hand_two_a_bound(ct, beta)


# ------------------------------------------------------------------------- invalid input
INVALID = [
    (wd.stream_tube_area_ratio, dict(ct=1.0, yaw=0.0), "ct"),
    (wd.stream_tube_area_ratio, dict(ct=1.25, yaw=np.deg2rad(20.0)), "ct"),  # 1.25 cos^2 = 1.104
    (wd.stream_tube_area_ratio, dict(ct=-0.1, yaw=0.0), "ct"),
    (wd.stream_tube_area_ratio, dict(ct=np.array([0.5, np.nan]), yaw=0.0), "ct"),
    (wd.axial_induction, dict(ct=0.5, yaw=math.pi / 2), "yaw"),
    (wd.axial_induction, dict(ct=0.5, yaw=-2.0), "yaw"),
    (wd.sigma_tilde_squared, dict(x=1.0, k_w=0.0, radius=R, ct=CT, yaw=0.0), "k_w"),
    (wd.sigma_tilde_squared, dict(x=1.0, k_w=KW, radius=-5.0, ct=CT, yaw=0.0), "radius"),
    (wd.potential_core_length, dict(k_w=-0.01, radius=R, ct=CT, yaw=0.0), "k_w"),
    (wd.potential_core_length, dict(k_w=KW, radius=0.0, ct=CT, yaw=0.0), "radius"),
    (wd.max_deficit, dict(x=1.0, k_w=KW, radius=R, ct=1.2, yaw=0.0), "ct"),
    (wd.initial_wake_shape, dict(sin_t=1.5, radius=R, ct=CT, yaw=0.0), "sin_t"),
    (wd.curl_shape, dict(t_hat=1.0, cos2=1.0, cos3=1.0, cos4=1.0, alpha=1.3), "alpha"),
    (wd.curl_shape, dict(t_hat=1.0, cos2=1.0, cos3=1.0, cos4=1.0, alpha=0.0), "alpha"),
    (wd.time_like_variable, dict(x=1.0, friction_velocity=0.0, hub_speed=UH, local_speed=UZ,
                                 radius=R, ct=CT, yaw=0.1), "friction_velocity"),
    (wd.time_like_variable, dict(x=1.0, friction_velocity=USTAR, hub_speed=-1.0, local_speed=UZ,
                                 radius=R, ct=CT, yaw=0.1), "hub_speed"),
    (wd.time_like_variable, dict(x=1.0, friction_velocity=USTAR, hub_speed=UH,
                                 local_speed=np.array([8.0, 0.0]), radius=R, ct=CT, yaw=0.1),
     "local_speed"),
    (wd.wake_width, dict(x=1.0, k_w=np.inf, xi=10.0), "k_w"),
]


@pytest.mark.parametrize("function, kwargs, name", INVALID)
def test_invalid_input_raises_value_error_naming_parameter(function, kwargs, name):
    with pytest.raises(ValueError, match=rf"^{name} must be"):
        function(**kwargs)


def test_invalid_input_message_states_range():
    with pytest.raises(ValueError, match=r"ct must be >= 0 with ct cos\^2\(yaw\) < 1"):
        wd.axial_induction(1.13, 0.0)
    with pytest.raises(ValueError, match=r"yaw must be in \(-pi/2, pi/2\) radians"):
        wd.axial_induction(0.5, 1.6)


def test_deficit_requires_speeds_for_curl_only():
    with pytest.raises(ValueError, match="local_speed"):
        wd.normalised_deficit(100.0, 0.0, 0.0, k_w=KW, radius=R, ct=CT, yaw=0.2,
                              friction_velocity=USTAR, hub_speed=UH)
    out = wd.normalised_deficit(100.0, 0.0, 0.0, k_w=KW, radius=R, ct=CT, yaw=0.2, curl=False)
    assert out == pytest.approx(2 * hand_a(CT, 0.2), rel=RTOL)


def test_yawed_rotor_with_unyawed_ct_above_one_is_valid():
    """Only the normal loading C_T cos^2(beta) must stay below 1: C_T = 1.05 at 20 degrees
    (loading 0.927) is a valid yawed rotor, with A* and a from Eqs. (A_star), (ind_factor)."""
    beta = math.radians(20.0)
    loading = 1.05 * math.cos(beta) ** 2
    root = math.sqrt(1.0 - loading)
    assert wd.axial_induction(1.05, beta) == pytest.approx(0.5 * (1.0 - root), rel=1e-12)
    assert wd.stream_tube_area_ratio(1.05, beta) == pytest.approx(
        (1.0 + root) / (2.0 * root), rel=1e-12
    )
