"""Tests of floris_ekman_veer.atmosphere.ekman (paper Section 2.5, docs/atmosphere.md).

Expected values are hand arithmetic (plain ``math`` on scalars, the paper's equations written
out here) or the LES numbers of the paper's Table 1; no solver output is used as a reference.
"""

import math
import re

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from floris_ekman_veer.atmosphere import similarity
from floris_ekman_veer.atmosphere.ekman import EkmanABL, friction_velocity_fixed_point

KAPPA, C_G, GAMMA, C_TN, C_CN, C_NS = 0.41, 1.43, 0.83, 0.5, 1.6, 0.78
GRAV, OMEGA = 9.81, 7.27e-5

#: The paper's Table 1 set-up (caption).
PAPER = dict(
    geostrophic_wind=15.0, roughness_length=0.1, coriolis_parameter=1e-4,
    brunt_vaisala_frequency=6.1e-3, reference_potential_temperature=265.0,
)
#: Paper Table 1: mu, C_r [K/h], and the LES h [m], u* [m/s], |alpha_0| [deg].
TABLE1 = {
    "CNBL": (0.0, 0.0, 1157.0, 0.60, 21.0),
    "SBL-1": (5.62, -0.03, 1032.0, 0.59, 24.0),
    "SBL-2": (20.59, -0.125, 662.0, 0.53, 28.0),
    "SBL-3": (39.84, -0.25, 463.0, 0.46, 32.0),
    "SBL-4": (59.25, -0.375, 361.0, 0.41, 35.0),
    "SBL-5": (78.35, -0.5, 306.0, 0.38, 38.0),
    "SBL-6": (148.49, -1.0, 218.0, 0.34, 41.0),
}
CASES = list(TABLE1)
CLOSURES = ("stability_parameter", "cooling_rate")


def table_abl(case, closure, **overrides):
    mu, c_r, *_ = TABLE1[case]
    value = mu if closure == "stability_parameter" else c_r
    return EkmanABL(**{**PAPER, **overrides}, **{closure: value})


# A few distinct atmospheres for the structural tests (north, south, each closure).
STATES = {
    "CNBL": dict(PAPER),
    "SBL-6 mu": dict(PAPER, stability_parameter=148.49),
    "SBL-3 C_r": dict(PAPER, cooling_rate=-0.25),
    "south heat flux": dict(geostrophic_wind=9.0, latitude=-52.0, roughness_length=0.02,
                            surface_heat_flux=-0.01, lapse_rate=0.003),
    "Obukhov": dict(geostrophic_wind=22.0, latitude=60.0, roughness_length=0.5,
                    obukhov_length=200.0, brunt_vaisala_frequency=0.01),
}


@pytest.fixture(params=list(STATES), scope="module")
def abl(request):
    return EkmanABL(**STATES[request.param])


# ------------------------------------------------------------------------- hand arithmetic
def hand_h_hat(mu, mu_n):
    """Eq. (h_hat_model): 1/h_hat^2 = 1/C_TN^2 + mu_N/C_CN^2 + mu/C_NS^2."""
    return (1.0 / C_TN**2 + mu_n / C_CN**2 + mu / C_NS**2) ** -0.5


def hand_g(xi, hh):
    """Eq. (eqn:avoidnumbers1a), xi and hh dimensionless."""
    return C_G * (1.0 - math.exp(-xi / (GAMMA * hh)))


def hand_dg(xi, hh):
    """Eq. (eqn:avoidnumbers1b)."""
    return C_G / (GAMMA * hh) * math.exp(-xi / (GAMMA * hh))


def hand_a(mu, mu_n, hh, xi0):
    """Eq. (A_model_GDL) as printed, with 0.2 and 0.8."""
    xm = 0.2 * hh
    return -math.log(0.2 * hh) - KAPPA * (
        (5 * mu + 0.3 * mu_n) * (0.2 * hh - xi0)
        + hand_dg(xm, hh) * 0.8**1.5
        - hand_g(xm, hh) * (3.0 / (2.0 * hh)) * 0.8**0.5
    )


def hand_b(hh):
    """Eq. (B_model_GDL)."""
    return 3.0 * KAPPA / (2.0 * hh)


def hand_state(a):
    """Scalars of a solved scalar EkmanABL: u*, |f|, z0, mu, mu_N, h_hat(hand), U_g, V_g."""
    u = float(a.friction_velocity)
    f = abs(float(a.coriolis_parameter))
    mu, mu_n = float(a.stability_parameter), float(a.zilitinkevich_number)
    return u, f, float(a.roughness_length), mu, mu_n, hand_h_hat(mu, mu_n)


def hand_u_surface(z, a):
    """Eq. (U_vel), lower branch: (u*/kappa) ln(z/z0) + u* (5 mu + 0.3 mu_N)(z - z0) f/u*."""
    u, f, z0, mu, mu_n, _ = hand_state(a)
    return u / KAPPA * math.log(z / z0) + u * (5 * mu + 0.3 * mu_n) * (z - z0) * f / u


def hand_u_ekman(z, a):
    """Eq. (U_vel), upper branch."""
    u, f, _, _, _, hh = hand_state(a)
    xi = z * f / u
    ug = float(a.geostrophic_components[0])
    return u * (-hand_dg(xi, hh) * (1 - xi / hh) ** 1.5
                + 3 * hand_g(xi, hh) / (2 * hh) * math.sqrt(1 - xi / hh) + ug / u)


def hand_v(z, a):
    """Eq. (V_vel) as printed (northern form; times sign(f_c)), for g(xi) < 1."""
    u, f, _, _, _, hh = hand_state(a)
    xi = z * f / u
    g, dg = hand_g(xi, hh), hand_dg(xi, hh)
    vg = float(a.geostrophic_components[1])
    sign = math.copysign(1.0, float(a.coriolis_parameter))
    return u * sign * (g * dg / math.sqrt(1 - g**2) * (1 - xi / hh) ** 1.5
                       + 3 / (2 * hh) * math.sqrt(1 - g**2) * math.sqrt(1 - xi / hh)) + vg


# The height above which g > 1: 1 - exp(-eta/Gamma) = 1/c_g.
ETA_G1 = -GAMMA * math.log(1.0 - 1.0 / C_G)


# ------------------------------------------------------------------------- profile structure
def test_eta_where_g_exceeds_one_is_0_9973():
    assert ETA_G1 == pytest.approx(0.9973, abs=1e-4)
    assert hand_g(ETA_G1 * 0.999, 1.0) < 1.0 < hand_g(ETA_G1 * 1.001, 1.0)


def test_u_continuous_at_matching_height(abl):
    """U is continuous at z_m = 0.2 h to round-off: just below z_m the code follows the MOST
    branch, just above the Ekman branch (each checked by hand), and the two agree at z_m."""
    z_m = abl.matching_fraction * float(abl.boundary_layer_height)
    below, above = z_m * (1 - 1e-12), z_m * (1 + 1e-12)
    u_below, u_above = (float(abl.velocity(z)[0]) for z in (below, above))
    assert u_below == pytest.approx(hand_u_surface(below, abl), rel=1e-12)
    assert u_above == pytest.approx(hand_u_ekman(above, abl), rel=1e-12)
    assert hand_u_ekman(z_m, abl) == pytest.approx(hand_u_surface(z_m, abl), rel=1e-12)
    assert abs(u_above - u_below) < 1e-11 * abs(u_below)


def test_du_dz_jumps_at_matching_height(abl):
    """A known property of the model: dU/dz is NOT continuous at 0.2 h. The MOST side has
    the hand slope u*/(kappa z) + (5 mu + 0.3 mu_N) f; the Ekman side differs by > 10 %."""
    u_star, f, _, mu, mu_n, _ = hand_state(abl)
    z_m = abl.matching_fraction * float(abl.boundary_layer_height)
    dz = 1e-6 * z_m
    z = np.array([z_m - 2 * dz, z_m - dz, z_m + dz, z_m + 2 * dz])
    u = abl.velocity(z)[0]
    left, right = (u[1] - u[0]) / dz, (u[3] - u[2]) / dz
    hand_left = u_star / (KAPPA * z_m) + (5 * mu + 0.3 * mu_n) * f
    assert left == pytest.approx(hand_left, rel=1e-4)
    assert abs(right - left) > 0.1 * abs(left)


def test_v_zero_at_ground(abl):
    """U = V = 0 exactly at the ground, and the printed V formula itself tends to 0 at the
    ground with no V_g offset left over (evaluated above the sublayer of a tiny z0)."""
    u0, v0 = abl.velocity(0.0)
    assert u0 == 0.0 and v0 == 0.0
    tiny = EkmanABL(**{**STATES["CNBL"], "roughness_length": 1e-12})
    v = tiny.velocity(np.array([1e-11, 1e-10]))[1]
    assert np.all(np.abs(v) < 1e-9)
    assert abs(v[1]) > abs(v[0])  # V ~ z near the ground, not round-off of V_g


def test_geostrophic_at_and_above_h(abl):
    h = float(abl.boundary_layer_height)
    u, v = abl.velocity(np.array([h, 1.0001 * h, 2 * h, 50 * h]))
    u_g, v_g = abl.geostrophic_components
    np.testing.assert_allclose(u, u_g, rtol=1e-14)
    np.testing.assert_allclose(v, v_g, rtol=1e-14)


def test_no_nan_where_g_exceeds_one(abl):
    """0.9973 h < z < h: the sqrt(1 - g^2) terms take their limit 0 (docs/atmosphere.md#lateral-velocity-near-the-abl-top)."""
    h = float(abl.boundary_layer_height)
    z = h * np.linspace(ETA_G1, 1.0, 50)[1:-1]
    with np.errstate(all="raise"):
        u, v = abl.velocity(z)
    assert np.all(np.isfinite(u))
    np.testing.assert_allclose(v, abl.geostrophic_components[1], rtol=1e-14)
    # just below the threshold V follows the printed formula and stays finite
    for s in (1e-3, 1e-6):
        z_s = h * ETA_G1 * (1 - s)
        assert float(abl.velocity(z_s)[1]) == pytest.approx(hand_v(z_s, abl), rel=1e-6)
    z_edge = h * ETA_G1 * (1 - np.logspace(-15, -7, 30))
    assert np.all(np.isfinite(abl.velocity(z_edge)[1]))


def test_profile_matches_printed_equations_inside_abl(abl):
    h = float(abl.boundary_layer_height)
    for eta in (0.05, 0.15, 0.3, 0.6, 0.9):
        z = eta * h
        if z <= float(abl.roughness_length):
            continue
        u, v = (float(c) for c in abl.velocity(z))
        hand = hand_u_surface(z, abl) if eta <= 0.2 else hand_u_ekman(z, abl)
        assert u == pytest.approx(hand, rel=1e-12)
        assert v == pytest.approx(hand_v(z, abl), rel=1e-9, abs=1e-12)


def hand_sublayer_height(a):
    """z_s = z0 exp(1 + kappa (5 mu + 0.3 mu_N) z0 f/u*): where the tangent of the surface-layer
    law passes through the ground, (u*/kappa) ln(z/z0) + m u* (xi - xi0) = z dU/dz."""
    u, f, z0, mu, mu_n, _ = hand_state(a)
    return z0 * math.exp(1 + KAPPA * (5 * mu + 0.3 * mu_n) * z0 * f / u)


def test_roughness_sublayer(abl):
    """docs/atmosphere.md#roughness-sublayer: below z_s the wind is (z/z_s) (U, V)(z_s), the log
    law's tangent through the ground; U and dU/dz continuous at z_s, U > 0 for z > 0."""
    z_s = hand_sublayer_height(abl)
    assert float(abl.roughness_sublayer_height) == pytest.approx(z_s, rel=1e-12)
    assert 2.718 * float(abl.roughness_length) < z_s < 0.2 * float(abl.boundary_layer_height)
    u_s, v_s = hand_u_surface(z_s, abl), hand_v(z_s, abl)
    for fraction in (0.0, 1e-6, 0.3, 0.999999):
        u, v = (float(c) for c in abl.velocity(fraction * z_s))
        assert u == pytest.approx(fraction * u_s, rel=1e-12, abs=1e-300)
        assert v == pytest.approx(fraction * v_s, rel=1e-9, abs=1e-300)
    # continuity of U and of its slope at z_s (the tangent property), hand slope of the log law
    u_star, f, _, mu, mu_n, _ = hand_state(abl)
    hand_slope = u_star / (KAPPA * z_s) + (5 * mu + 0.3 * mu_n) * f
    assert u_s / z_s == pytest.approx(hand_slope, rel=1e-12)
    dz = 1e-7 * z_s
    u_lo, u_hi = abl.velocity(np.array([z_s - dz, z_s + dz]))[0]
    assert (u_hi - u_lo) / (2 * dz) == pytest.approx(hand_slope, rel=1e-5)
    # above z_s the printed law, at z0 no longer zero
    z = 1.5 * z_s
    assert float(abl.velocity(z)[0]) == pytest.approx(hand_u_surface(z, abl), rel=1e-12)
    z = np.geomspace(1e-6, 50.0, 400) * float(abl.roughness_length)
    u, _ = abl.velocity(z)
    assert np.all(u > 0) and np.all(np.diff(u) > 0)


def test_sublayer_capped_at_matching_height():
    """A boundary layer so shallow over rough ground (26 m deep, z0 = 1 m) that the sublayer
    reaches its matching height 0.2 h: the sublayer ends there (U continuous, its slope not)."""
    a = EkmanABL(
        geostrophic_wind=4.0, latitude=-38.0, roughness_length=1.0, brunt_vaisala_frequency=0.0137,
        surface_heat_flux=-0.0061,
    )
    z_m = 0.2 * float(a.boundary_layer_height)
    assert hand_sublayer_height(a) > z_m
    assert float(a.roughness_sublayer_height) == pytest.approx(z_m, rel=1e-14)
    u_m = float(a.velocity(z_m)[0])
    assert u_m == pytest.approx(hand_u_surface(z_m, a), rel=1e-12)
    assert float(a.velocity(0.5 * z_m)[0]) == pytest.approx(0.5 * u_m, rel=1e-12)


@pytest.mark.parametrize("method", ["velocity", "speed", "wind_angle"])
def test_heights_must_be_finite_and_above_ground(abl, method):
    call = getattr(abl, method)
    for bad in (np.nan, -1.0, [10.0, np.nan], "10", True):
        with pytest.raises(ValueError, match=r"^z must be"):
            call(bad)


def test_nan_heights_raise_in_every_profile_method(abl):
    """NaN never comes out (and V(NaN) is not a finite number): each method names its input."""
    calls = {
        "z": lambda x: abl.hub_aligned_velocity(x, 90.0),
        "reference_height": lambda x: abl.hub_aligned_velocity(50.0, x),
        "z1": lambda x: abl.wind_direction_change(x, 90.0),
        "z2": lambda x: abl.wind_direction_change(50.0, x),
        "hub_height": lambda x: abl.wake_expansion_rate(x),
    }
    for name, call in calls.items():
        with pytest.raises(ValueError, match=rf"^{name} must be .*got nan"):
            call(np.array([50.0, np.nan]))
    with pytest.raises(ValueError, match=r"^z must be >= roughness_length"):
        abl.turbulence_intensity(np.nan)
    with pytest.raises(ValueError, match=r"^reference_height must be >= roughness_length"):
        abl.turbulence_intensity(50.0, reference_height=np.nan)
    with pytest.raises(ValueError, match=r"^z must be >= roughness_length"):
        abl.turbulence_intensity(0.5 * float(abl.roughness_length))


# ------------------------------------------------------------------------- the GDL and the solve
def test_solved_state_satisfies_gdl(abl):
    """kappa U_g/u* = ln(u*/(f z0)) - A and kappa V_g/u* = -B (times the hemisphere sign),
    with A, B, h_hat written out here; |(U_g, V_g)| = G; h = h_hat u*/f."""
    u, f, z0, mu, mu_n, hh = hand_state(abl)
    xi0 = z0 * f / u
    u_g, v_g = (float(c) for c in abl.geostrophic_components)
    sign = math.copysign(1.0, float(abl.coriolis_parameter))
    assert KAPPA * u_g / u == pytest.approx(math.log(u / (f * z0)) - hand_a(mu, mu_n, hh, xi0),
                                            rel=1e-12)
    assert KAPPA * v_g / u == pytest.approx(-sign * hand_b(hh), rel=1e-12)
    assert math.hypot(u_g, v_g) == pytest.approx(float(abl.geostrophic_wind), rel=1e-12)
    assert float(abl.boundary_layer_height) == pytest.approx(hh * u / f, rel=1e-13)
    assert float(abl.cross_isobaric_angle) == pytest.approx(math.degrees(math.atan2(v_g, u_g)),
                                                            rel=1e-12)


def test_fixed_point_agrees_with_solver(abl):
    u_fp = friction_velocity_fixed_point(abl)
    assert float(u_fp) == pytest.approx(float(abl.friction_velocity), rel=1e-12)


def test_fixed_point_agrees_with_solver_vectorised():
    a = EkmanABL(**{**PAPER, "geostrophic_wind": np.linspace(3, 30, 12),
                    "cooling_rate": np.linspace(-1.0, 0.0, 12)})
    np.testing.assert_allclose(friction_velocity_fixed_point(a), a.friction_velocity, rtol=1e-12)


# ------------------------------------------------------------------------- formulas by hand
def test_h_hat_hand_arithmetic():
    # mu = 10, mu_N = 61: 1/h^2 = 1/0.5^2 + 61/1.6^2 + 10/0.78^2
    #                           = 4 + 23.828125 + 16.43655489809336 = 44.26467989809336
    expected = 44.26467989809336 ** -0.5  # = 0.150304276...
    assert similarity.boundary_layer_height_hat(10.0, 61.0, C_TN, C_CN, C_NS) == pytest.approx(
        expected, rel=1e-14)
    a = EkmanABL(**{**PAPER, "stability_parameter": 10.0, "brunt_vaisala_frequency": 6.1e-3})
    assert float(a.h_hat) == pytest.approx(expected, rel=1e-14)
    # neutral, no stratification: h_hat = C_TN = 0.5
    assert similarity.boundary_layer_height_hat(0.0, 0.0, C_TN, C_CN, C_NS) == 0.5


def test_coriolis_from_latitude():
    # 2 * 7.27e-5 * sin(45 deg) = 1.4540e-4 * 0.70710678 = 1.02813e-4
    assert similarity.coriolis_parameter_from_latitude(45.0) == pytest.approx(1.0281332598452e-4,
                                                                         rel=1e-12)
    # sin(30 deg) = 1/2: f = 7.27e-5
    assert similarity.coriolis_parameter_from_latitude(30.0) == pytest.approx(7.27e-5, rel=1e-14)
    assert similarity.coriolis_parameter_from_latitude(-30.0) == pytest.approx(-7.27e-5, rel=1e-14)
    a = EkmanABL(geostrophic_wind=10.0, latitude=30.0, roughness_length=0.1)
    assert float(a.coriolis_parameter) == pytest.approx(7.27e-5, rel=1e-14)


def test_brunt_vaisala_from_lapse_rate():
    # N = sqrt(9.81/265 * 0.001) = sqrt(3.70188679e-5) = 6.0843133e-3; mu_N = N/1e-4 = 60.843
    a = EkmanABL(geostrophic_wind=15.0, coriolis_parameter=1e-4, roughness_length=0.1,
                 lapse_rate=0.001, reference_potential_temperature=265.0)
    assert float(a.brunt_vaisala_frequency) == pytest.approx(6.084313266468805e-3, rel=1e-12)
    assert float(a.zilitinkevich_number) == pytest.approx(60.84313266468805, rel=1e-12)
    b = EkmanABL(geostrophic_wind=15.0, coriolis_parameter=1e-4, roughness_length=0.1,
                 brunt_vaisala_frequency=6.084313266468805e-3)
    assert float(b.friction_velocity) == pytest.approx(float(a.friction_velocity), rel=1e-12)


def test_default_free_atmosphere_is_the_papers():
    a = EkmanABL(geostrophic_wind=15.0, coriolis_parameter=1e-4, roughness_length=0.1)
    assert float(a.zilitinkevich_number) == pytest.approx(61.0, rel=1e-12)


@pytest.mark.parametrize("c_r", [-0.03, -0.5, -2.0])
def test_cooling_rate_closure(c_r):
    """mu = -(g/Theta0) C_r h_hat(mu)/(f^2 u*), C_r in K/s; L_s from Q0 = C_r h gives it too."""
    a = EkmanABL(**PAPER, cooling_rate=c_r)
    u, f, _, mu, mu_n, hh = hand_state(a)
    c_r_si = c_r / 3600.0
    assert mu == pytest.approx(-(GRAV / 265.0) * c_r_si * hh / (f**2 * u), rel=1e-12)
    # via the Obukhov length: Q0 = C_r h, L_s = -u*^3/(kappa (g/Theta0) Q0), mu = u*/(kappa f L)
    q0 = c_r_si * hh * u / f
    l_s = -(u**3) / (KAPPA * (GRAV / 265.0) * q0)
    assert mu == pytest.approx(u / (KAPPA * f * l_s), rel=1e-12)
    assert float(a.boundary_layer_height) == pytest.approx(hh * u / f, rel=1e-12)


def test_obukhov_closure():
    a = EkmanABL(**PAPER, obukhov_length=150.0)
    u, f, _, mu, _, _ = hand_state(a)
    assert mu == pytest.approx(u / (KAPPA * f * 150.0), rel=1e-13)
    b = EkmanABL(**PAPER, stability_parameter=mu)  # the same atmosphere given by mu
    assert float(b.friction_velocity) == pytest.approx(u, rel=1e-12)


def test_obukhov_infinite_is_neutral():
    a = EkmanABL(**PAPER, obukhov_length=np.inf)
    b = EkmanABL(**PAPER)
    assert float(a.stability_parameter) == 0.0
    assert float(a.friction_velocity) == pytest.approx(float(b.friction_velocity), rel=1e-13)


def test_heat_flux_closure():
    a = EkmanABL(**PAPER, surface_heat_flux=-0.02)
    u, f, _, mu, _, _ = hand_state(a)
    assert mu == pytest.approx(-(GRAV / 265.0) * (-0.02) / (f * u**2), rel=1e-13)


def test_surface_layer_branch_by_hand():
    """SBL-3 with mu given, z = 30 m < 0.2 h (~102 m): the MOST branch written out."""
    a = EkmanABL(**PAPER, stability_parameter=39.84)
    u, f, z0, mu, mu_n, _ = hand_state(a)
    assert 30.0 < 0.2 * float(a.boundary_layer_height)
    # (u*/kappa) ln(30/0.1) + u* (5*39.84 + 0.3*61)(30 - 0.1) 1e-4/u*
    #   = (u*/0.41) * 5.703782474656201 + 217.5 * 29.9 * 1e-4
    expected = u / 0.41 * 5.703782474656201 + (5 * 39.84 + 0.3 * 61) * 29.9 * 1e-4
    assert float(a.velocity(30.0)[0]) == pytest.approx(expected, rel=1e-12)


def test_turbulence_intensity_and_wake_expansion_by_hand():
    """Eqs. (Iu_model), (kw_CNBL_SBL_model) with the solved u*, h and U_h = |(U, V)(100 m)|."""
    a = EkmanABL(**PAPER, cooling_rate=-1.0)
    u, h = float(a.friction_velocity), float(a.boundary_layer_height)
    u_h = math.hypot(*(float(c) for c in a.velocity(100.0)))
    i_u = math.sqrt(1.25 * math.log(h / 100.0) + 0.6) * u / u_h
    assert float(a.turbulence_intensity(100.0)) == pytest.approx(i_u, rel=1e-13)
    k_w = (0.021**6 + (0.33 * i_u) ** 6) ** (1 / 6)
    assert float(a.wake_expansion_rate(100.0)) == pytest.approx(k_w, rel=1e-13)
    # normalised by the hub speed at another height
    z = 50.0
    i_50 = math.sqrt(1.25 * math.log(h / z) + 0.6) * u / u_h
    assert float(a.turbulence_intensity(z, reference_height=100.0)) == pytest.approx(i_50,
                                                                                      rel=1e-13)


# ------------------------------------------------------------------------- the paper's Table 1
@pytest.mark.parametrize("closure", CLOSURES)
@pytest.mark.parametrize("case", CASES)
def test_table1_against_les(case, closure):
    """h and u* within 15 % of the LES; |alpha_0| below the LES by at most 6 degrees."""
    _, _, h_les, u_les, alpha_les = TABLE1[case]
    a = table_abl(case, closure)
    assert abs(float(a.boundary_layer_height) / h_les - 1) < 0.15
    assert abs(float(a.friction_velocity) / u_les - 1) < 0.15
    alpha = float(a.cross_isobaric_angle)
    assert alpha < 0  # northern hemisphere, surface-stress frame
    assert 0 < alpha_les - abs(alpha) <= 6.0


def test_table1_mu_closure_reproduces_table_mu():
    for case in CASES:
        a = table_abl(case, "stability_parameter")
        assert float(a.stability_parameter) == TABLE1[case][0]


@pytest.mark.parametrize("closure", CLOSURES)
def test_table1_trends(closure):
    """As cooling strengthens (CNBL -> SBL-6): h and u* fall, |alpha_0| and the rotor-layer
    veer (50 m -> 150 m) rise, monotonically, as in the LES."""
    ablx = [table_abl(case, closure) for case in CASES]
    h = [float(a.boundary_layer_height) for a in ablx]
    u = [float(a.friction_velocity) for a in ablx]
    alpha = [abs(float(a.cross_isobaric_angle)) for a in ablx]
    veer = [float(a.wind_direction_change(50.0, 150.0)) for a in ablx]
    assert all(np.diff(h) < 0) and all(np.diff(u) < 0)
    assert all(np.diff(alpha) > 0) and all(np.diff(veer) > 0)
    # the LES columns themselves have these trends
    les = np.array([TABLE1[c][2:] for c in CASES])
    assert all(np.diff(les[:, 0]) < 0) and all(np.diff(les[:, 1]) < 0)
    assert all(np.diff(les[:, 2]) > 0)
    assert veer[-1] > 15.0  # strongly stable: large veer across the rotor


def test_table1_cooling_closure_sbl6_mu():
    """docs/validation.md#table-1: Q0 = C_r h with C_r = -1 K/h gives mu ~ 169 (the table lists 148.5)."""
    a = table_abl("SBL-6", "cooling_rate")
    assert float(a.stability_parameter) == pytest.approx(169.0, rel=0.01)


def test_table1_vectorised_equals_cases():
    c_r = np.array([TABLE1[c][1] for c in CASES])
    a = EkmanABL(**PAPER, cooling_rate=c_r)
    for i, case in enumerate(CASES):
        s = table_abl(case, "cooling_rate")
        assert a.friction_velocity[i] == pytest.approx(float(s.friction_velocity), rel=1e-13)
        assert a.boundary_layer_height[i] == pytest.approx(float(s.boundary_layer_height),
                                                           rel=1e-13)


# ------------------------------------------------------------------------- hemispheres
@pytest.mark.parametrize("stability", [dict(), dict(cooling_rate=-0.5),
                                       dict(stability_parameter=80.0)])
def test_southern_hemisphere_mirrors_northern(stability):
    base = dict(geostrophic_wind=12.0, roughness_length=0.05, **stability)
    north = EkmanABL(latitude=40.0, **base)
    south = EkmanABL(latitude=-40.0, **base)
    assert float(south.coriolis_parameter) == -float(north.coriolis_parameter)
    for name in ("friction_velocity", "boundary_layer_height", "stability_parameter"):
        assert float(getattr(south, name)) == pytest.approx(float(getattr(north, name)),
                                                            rel=1e-14)
    assert float(south.geostrophic_components[0]) == pytest.approx(
        float(north.geostrophic_components[0]), rel=1e-14)
    assert float(south.geostrophic_components[1]) == pytest.approx(
        -float(north.geostrophic_components[1]), rel=1e-14)
    assert float(north.cross_isobaric_angle) < 0 < float(south.cross_isobaric_angle)
    assert float(south.cross_isobaric_angle) == pytest.approx(
        -float(north.cross_isobaric_angle), rel=1e-14)
    z = np.geomspace(0.1, 2 * float(north.boundary_layer_height), 200)
    (un, vn), (us, vs) = north.velocity(z), south.velocity(z)
    np.testing.assert_allclose(us, un, rtol=1e-14)
    np.testing.assert_allclose(vs, -vn, rtol=1e-14, atol=1e-15)
    veer_n = float(north.wind_direction_change(50.0, 150.0))
    veer_s = float(south.wind_direction_change(50.0, 150.0))
    assert veer_s == pytest.approx(-veer_n, rel=1e-12)
    if stability:  # stable: veering with height in the north, backing in the south
        assert veer_n > 0 > veer_s


# ------------------------------------------------------------------------- frames and drivers
def test_hub_aligned_velocity(abl):
    z_ref = min(100.0, 0.5 * float(abl.boundary_layer_height))
    z = np.geomspace(1.0, 2 * float(abl.boundary_layer_height), 50)
    u_a, v_a = abl.hub_aligned_velocity(np.append(z, z_ref), z_ref)
    assert abs(v_a[-1]) < 1e-12
    assert u_a[-1] == pytest.approx(float(abl.speed(z_ref)), rel=1e-14)
    np.testing.assert_allclose(np.hypot(u_a, v_a)[:-1], abl.speed(z), rtol=1e-14)
    # a rotation: the turning between two heights is unchanged
    turn = np.rad2deg(np.arctan2(v_a[0], u_a[0]) - np.arctan2(v_a[-2], u_a[-2]))
    turn_raw = float(abl.wind_angle(z[0]) - abl.wind_angle(z[-1]))
    assert turn == pytest.approx(turn_raw, rel=1e-10)


ATMOSPHERE = dict(latitude=45.0, roughness_length=0.1, cooling_rate=-0.5)


def test_from_reference_wind_round_trip():
    speeds = np.linspace(3.0, 25.0, 45)
    a = EkmanABL.from_reference_wind(speeds, 100.0, **ATMOSPHERE)
    np.testing.assert_allclose(a.speed(100.0), speeds, rtol=1e-10)
    above = a.boundary_layer_height <= 100.0  # weak winds: a shallow SBL, 100 m above h
    assert 0 < np.sum(above) < len(speeds)
    np.testing.assert_allclose(a.geostrophic_wind[above], speeds[above], rtol=1e-10)
    assert np.all(a.geostrophic_wind[speeds >= 12] > speeds[speeds >= 12])
    b = EkmanABL(geostrophic_wind=a.geostrophic_wind, **ATMOSPHERE)
    np.testing.assert_allclose(b.speed(100.0), speeds, rtol=1e-10)
    np.testing.assert_allclose(b.friction_velocity, a.friction_velocity, rtol=1e-14)


def test_from_reference_wind_per_element_atmospheres():
    speeds = np.array([4.0, 8.0, 8.0, 12.0, 20.0])
    c_r = np.array([-0.1, -0.5, 0.0, -1.0, -2.0])
    heights = np.array([60.0, 100.0, 100.0, 150.0, 90.0])
    inputs = dict(latitude=50.0, roughness_length=0.05)
    a = EkmanABL.from_reference_wind(speeds, heights, cooling_rate=c_r, **inputs)
    np.testing.assert_allclose(a.speed(heights), speeds, rtol=1e-10)
    for i in range(len(speeds)):
        s = EkmanABL.from_reference_wind(speeds[i], heights[i], cooling_rate=c_r[i], **inputs)
        assert a.geostrophic_wind[i] == pytest.approx(float(s.geostrophic_wind), rel=1e-10)
        assert a.friction_velocity[i] == pytest.approx(float(s.friction_velocity), rel=1e-10)


#: Inputs the former solve (Chandrupatla on ln G) failed although an ABL reaches the speed.
EDGE_CASES = [
    (11.27, 136.6, dict(surface_heat_flux=-0.014, roughness_length=0.28, latitude=19.8)),
    (11.27, 136.6, dict(surface_heat_flux=-0.014, roughness_length=0.28, latitude=19.8,
                        brunt_vaisala_frequency=0.0161)),
    (17.42, 69.09, dict(latitude=-12.40, roughness_length=1.434e-4,
                        brunt_vaisala_frequency=0.01667, surface_heat_flux=-0.02187)),
    (9.24, 37.42, dict(latitude=-19.94, roughness_length=0.02054,
                       brunt_vaisala_frequency=0.005411, surface_heat_flux=-0.01659)),
]


@pytest.mark.parametrize("speed, height, inputs", EDGE_CASES)
def test_from_reference_wind_finds_the_collapse_edge_cases(speed, height, inputs):
    """Near the collapse threshold: the solve returns a valid ABL with the speed, which the
    forward solve from its G reproduces (an independent route to the same state)."""
    a = EkmanABL.from_reference_wind(speed, height, **inputs)
    assert float(a.speed(height)) == pytest.approx(speed, rel=1e-12)
    assert 0.2 * float(a.boundary_layer_height) > inputs["roughness_length"]
    assert float(a.geostrophic_components[0]) > 0
    b = EkmanABL(geostrophic_wind=a.geostrophic_wind, **inputs)
    assert float(b.friction_velocity) == pytest.approx(float(a.friction_velocity), rel=1e-10)
    assert float(b.speed(height)) == pytest.approx(speed, rel=1e-10)


def test_a_found_state_outside_the_physical_domain_is_refused_naming_the_heat_flux():
    """The former solve's third edge case is found (its speed is reached) but implies a surface
    heat flux of -1,014 W/m^2, beyond the physical domain's -300 (docs/atmosphere.md#physical-domain)."""
    with pytest.raises(ValueError, match=r"15.36 m/s at 26.36 m .* leaves the physical domain: "
                       r"the surface sensible heat flux H they imply is -1014 W/m\^2, outside "
                       r"-300 to 800 W/m\^2"):
        EkmanABL.from_reference_wind(15.36, 26.36, latitude=-15.52, roughness_length=0.7517,
                                     brunt_vaisala_frequency=0.01746, cooling_rate=-1.748)


def test_from_reference_wind_takes_the_deepest_of_two_states():
    """Near collapse the speed at a fixed height can fall while G grows: at 8.7 m/s and 136.6 m
    two states qualify (G between 12 and 13.5 m/s, and above 13.5 m/s); the deeper one is taken."""
    inputs = dict(surface_heat_flux=-0.014, roughness_length=0.28, latitude=19.8)
    g = np.linspace(12.0, 13.5, 7)
    speeds = EkmanABL(geostrophic_wind=g, **inputs).speed(136.6)
    assert np.all(np.diff(speeds) < 0)  # the fold: speed falls as G grows
    a = EkmanABL.from_reference_wind(8.7, 136.6, **inputs)
    assert float(a.speed(136.6)) == pytest.approx(8.7, rel=1e-12)
    assert float(a.geostrophic_wind) > 13.5
    shallow = g[np.argmin(np.abs(speeds - 8.7))]
    assert float(EkmanABL(geostrophic_wind=shallow, **inputs).boundary_layer_height) < float(
        a.boundary_layer_height)


def test_from_reference_wind_above_abl_top_gives_g():
    """A reference height above h: the speed there is G itself."""
    a = EkmanABL.from_reference_wind(10.0, 1500.0, **ATMOSPHERE)
    assert float(a.boundary_layer_height) < 1500.0
    assert float(a.geostrophic_wind) == pytest.approx(10.0, rel=1e-10)


def test_broadcasting_conditions_against_4d_heights():
    n = 3
    g = np.array([8.0, 14.0, 25.0]).reshape(n, 1, 1, 1)
    c_r = np.array([0.0, -0.3, -1.2]).reshape(n, 1, 1, 1)
    a = EkmanABL(geostrophic_wind=g, cooling_rate=c_r, latitude=40.0, roughness_length=0.1)
    assert a.friction_velocity.shape == (n, 1, 1, 1)
    rng = np.random.default_rng(1)
    z = rng.uniform(0.2, 400.0, size=(n, 2, 3, 4))
    u, v = a.velocity(z)
    assert u.shape == v.shape == (n, 2, 3, 4)
    i_u = a.turbulence_intensity(z)
    assert i_u.shape == (n, 2, 3, 4)
    for i in range(n):
        s = EkmanABL(geostrophic_wind=g[i].item(), cooling_rate=c_r[i].item(), latitude=40.0,
                     roughness_length=0.1)
        assert a.friction_velocity[i, 0, 0, 0] == pytest.approx(float(s.friction_velocity),
                                                                rel=1e-13)
        us, vs = s.velocity(z[i])
        np.testing.assert_allclose(u[i], us, rtol=1e-12)
        np.testing.assert_allclose(v[i], vs, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(i_u[i], s.turbulence_intensity(z[i]), rtol=1e-12)


# ------------------------------------------------------------------------- properties
COLLAPSE = "the stable boundary layer collapses"
#: The refusal of a state outside the physical domain (docs/atmosphere.md#physical-domain).
OUTSIDE = "physical domain"


def refused_for_a_reason(message):
    """A solve's refusal: the layer collapses, or it leaves the physical domain naming the
    implied quantity and its range."""
    if OUTSIDE in message:
        return re.search(r"(sensible heat flux H|geostrophic wind G|cross-isobaric angle).* is "
                         r"\S+ (W/m\^2|m/s|deg), outside \S+ to \S+ ", message) is not None
    return COLLAPSE in message

lat_st = st.floats(5.0, 90.0) | st.floats(-90.0, -5.0)
common = dict(
    g=st.floats(2.0, 40.0), z0=st.floats(1e-4, 2.0), lat=lat_st, n=st.floats(0.0, 0.03),
)


def check_valid_state(a, lat):
    u, h = float(a.friction_velocity), float(a.boundary_layer_height)
    u_g, v_g = (float(c) for c in a.geostrophic_components)
    values = [u, h, u_g, v_g, float(a.cross_isobaric_angle), float(a.stability_parameter)]
    assert all(math.isfinite(x) for x in values)
    assert u > 0 and h > 0 and u_g > 0
    assert float(a.stability_parameter) >= 0
    assert math.hypot(u_g, v_g) == pytest.approx(float(a.geostrophic_wind), rel=1e-10)
    alpha = float(a.cross_isobaric_angle)
    assert (alpha < 0) if lat > 0 else (alpha > 0)
    z0 = float(a.roughness_length)
    assert a.matching_fraction * h > z0
    z = np.concatenate([z0 * (1 + np.geomspace(1e-9, 1.0, 8)),
                        np.linspace(z0, 2.0 * h, 60)[1:]])
    u_z, v_z = a.velocity(z)
    assert np.all(np.isfinite(u_z)) and np.all(np.isfinite(v_z))
    assert np.all(u_z > 0)
    i_u = a.turbulence_intensity(z)
    assert np.all(np.isfinite(i_u)) and np.all(i_u >= 0)


@settings(max_examples=200, deadline=None)
@given(mu=st.floats(0.0, 300.0), **common)
def test_property_mu_closure(mu, g, z0, lat, n):
    try:
        a = EkmanABL(geostrophic_wind=g, roughness_length=z0, latitude=lat,
                     stability_parameter=mu, brunt_vaisala_frequency=n)
    except ValueError as err:
        assert refused_for_a_reason(str(err))
        return
    check_valid_state(a, lat)


@settings(max_examples=200, deadline=None)
@given(c_r=st.floats(-3.0, 0.0), **common)
def test_property_cooling_rate_closure(c_r, g, z0, lat, n):
    try:
        a = EkmanABL(geostrophic_wind=g, roughness_length=z0, latitude=lat,
                     cooling_rate=c_r, brunt_vaisala_frequency=n)
    except ValueError as err:
        assert refused_for_a_reason(str(err))
        assert "geostrophic_wind=" in str(err) and "cooling_rate=" in str(err)
        return
    check_valid_state(a, lat)
    # the cooling-rate closure holds at the solution
    u, f, _, mu, mu_n, hh = hand_state(a)
    assert mu == pytest.approx(-(GRAV / 265.0) * (c_r / 3600) * hh / (f**2 * u),
                               rel=1e-10, abs=1e-12)


@settings(max_examples=50, deadline=None)
@given(speed=st.floats(3.0, 25.0), height=st.floats(20.0, 200.0),
       c_r=st.floats(-1.0, 0.0), z0=st.floats(1e-3, 0.5))
def test_property_from_reference_wind(speed, height, c_r, z0):
    try:
        a = EkmanABL.from_reference_wind(speed, height, latitude=45.0, roughness_length=z0,
                                         cooling_rate=c_r)
    except ValueError as err:
        assert refused_for_a_reason(str(err))
        return
    assert float(a.speed(height)) == pytest.approx(speed, rel=1e-10)


# ------------------------------------------------------------------------- bad input
BASE = dict(geostrophic_wind=10.0, latitude=45.0, roughness_length=0.1)


@pytest.mark.parametrize("changes, pattern", [
    (dict(roughness_length=0.0), r"roughness_length must be > 0 m"),
    (dict(roughness_length=-0.1), r"roughness_length must be > 0 m"),
    (dict(geostrophic_wind=0.0), r"geostrophic_wind must be > 0 m/s"),
    (dict(geostrophic_wind=-5.0), r"geostrophic_wind must be > 0 m/s"),
    (dict(geostrophic_wind=np.nan), r"geostrophic_wind must be > 0 m/s; got nan"),
    (dict(geostrophic_wind=np.inf), r"geostrophic_wind must be > 0 m/s; got inf"),
    (dict(latitude=None, coriolis_parameter=0.0),
     r"coriolis_parameter must be .* <= \|f_c\| <= 2 Omega = 0.0001454 1/s \(\|latitude\| 1 to 90"),
    (dict(latitude=None, coriolis_parameter=0.01),
     r"coriolis_parameter must be .* <= \|f_c\| <= 2 Omega.*; got 0.01"),
    (dict(latitude=0.5), r"latitude must be 1 <= \|latitude\| <= 90 deg"),
    (dict(latitude=-0.5), r"latitude must be 1 <= \|latitude\| <= 90 deg"),
    (dict(latitude=95.0), r"latitude must be 1 <= \|latitude\| <= 90 deg"),
    (dict(coriolis_parameter=1e-4),
     r"give exactly one of coriolis_parameter \[1/s\] or latitude \[deg\]"),
    (dict(latitude=None), r"give exactly one of coriolis_parameter \[1/s\] or latitude \[deg\]"),
    (dict(stability_parameter=10.0, cooling_rate=-0.5),
     r"give at most one stability input .*cooling_rate.*stability_parameter"),
    (dict(surface_heat_flux=-0.01, obukhov_length=100.0),
     r"give at most one stability input .*obukhov_length.*surface_heat_flux"),
    (dict(cooling_rate=15.0),
     r"cooling_rate must be -10 to 10 K/h.*positive: heating, a convective layer\); got 15"),
    # unit mistakes: K/day for K/h, Celsius for kelvin, K/km for K/m
    (dict(cooling_rate=-100.0), r"cooling_rate must be -10 to 10 K/h, the surface's rate of "
                                r"temperature change in kelvin per hour.*; got -100"),
    (dict(reference_potential_temperature=15.0),
     r"reference_potential_temperature must be 200 to 350 K \(a potential temperature in "
     r"kelvin, not degrees Celsius\); got 15"),
    (dict(reference_potential_temperature=400.0), r"reference_potential_temperature must be 200 to 350 K"),
    (dict(stability_parameter=np.nan), r"stability_parameter must be finite; .*got nan"),
    # a heat flux in W/m^2 given as the kinematic flux (K m/s)
    (dict(surface_heat_flux=150.0),
     r"surface_heat_flux must be the kinematic upward heat flux Q0 .*for W/m\^2 use sensible_heat_flux\)"
     r"; got 150"),
    (dict(obukhov_length=0.0), r"obukhov_length must be > 0 m stable, < 0 m convective.*; got 0"),
    (dict(sensible_heat_flux=1500.0),
     r"sensible_heat_flux must be -300 to 800 W/m\^2, the upward surface sensible heat flux"
     r".*; got 1500"),
    (dict(obukhov_length=-50.0, mixed_layer_height=5.0),
     r"mixed_layer_height must be 10 to 5000 m, the convective mixed-layer depth z_i"
     r".*; got 5"),
    (dict(brunt_vaisala_frequency=0.01, lapse_rate=0.003),
     r"give at most one of brunt_vaisala_frequency \[1/s\] or lapse_rate \[K/m\]"),
    (dict(brunt_vaisala_frequency=-0.01), r"brunt_vaisala_frequency must be >= 0 1/s"),
    (dict(lapse_rate=-0.001), r"lapse_rate must be 0 to 0.1 K/m"),
    (dict(lapse_rate=3.5), r"lapse_rate must be 0 to 0.1 K/m .*in K/m, not K/km\); got 3.5"),
    (dict(c_g=0.0), r"c_g must be > 0 and finite \(a model constant\); got 0"),
    (dict(matching_fraction=1.2), r"matching_fraction must be in \(0, 1\)"),
])
def test_bad_input_raises(changes, pattern):
    inputs = {k: v for k, v in {**BASE, **changes}.items() if v is not None}
    with pytest.raises(ValueError, match=pattern):
        EkmanABL(**inputs)


def test_bad_input_in_arrays_names_offending_values():
    with pytest.raises(ValueError, match=r"roughness_length must be > 0 m; got -1 at condition 1, 0 at condition 3"):
        EkmanABL(**{**BASE, "roughness_length": np.array([0.1, -1.0, 0.2, 0.0])})


def test_hub_at_or_above_h_is_continuous_down_to_the_floor():
    # docs/atmosphere.md#shallow-boundary-layer
    a = EkmanABL(**BASE, cooling_rate=-1.0)
    h = float(a.boundary_layer_height)
    below, at = float(a.wake_expansion_rate(h * (1 - 1e-12))), float(a.wake_expansion_rate(h))
    assert at == pytest.approx(below, rel=1e-8)  # U(z) ~ sqrt(h - z) just below h
    assert float(a.wake_expansion_rate(0.5 * h)) >= at >= float(a.wake_expansion_rate(1.5 * h))
    assert float(a.wake_expansion_rate(1.7 * h)) == pytest.approx(0.021, rel=1e-15)


@pytest.mark.parametrize("speed, height, pattern", [
    (8.0, 0.1, r"height must be > roughness_length z0; got 0.1"),
    (8.0, 0.05, r"height must be > roughness_length z0; got 0.05"),
    (0.0, 100.0, r"speed must be > 0 m/s"),
    (-3.0, 100.0, r"speed must be > 0 m/s"),
])
def test_from_reference_wind_bad_input(speed, height, pattern):
    with pytest.raises(ValueError, match=pattern):
        EkmanABL.from_reference_wind(speed, height, latitude=45.0, roughness_length=0.1)


def test_from_reference_wind_rejects_geostrophic_wind():
    with pytest.raises(ValueError, match="takes speed and height instead of geostrophic_wind"):
        EkmanABL.from_reference_wind(8.0, 100.0, geostrophic_wind=10.0, latitude=45.0,
                                     roughness_length=0.1)


@pytest.mark.parametrize("g, c_r", [(2.0, -10.0), (2.0, -5.0), (1.0, -10.0)])
def test_collapsed_sbl_raises_naming_inputs(g, c_r):
    """Too strong cooling for a weak wind: no model ABL (the SBL collapses)."""
    with pytest.raises(ValueError) as info:
        EkmanABL(geostrophic_wind=g, latitude=45.0, roughness_length=0.1, cooling_rate=c_r)
    message = str(info.value)
    assert COLLAPSE in message
    assert f"geostrophic_wind={g:.6g}" in message and f"cooling_rate={c_r:.6g}" in message
    assert "roughness_length=0.1" in message and "coriolis_parameter=" in message


def test_collapse_reported_for_the_offending_element():
    with pytest.raises(ValueError, match=r"geostrophic_wind=2, .*cooling_rate=-10"):
        EkmanABL(geostrophic_wind=np.array([15.0, 2.0]), latitude=45.0, roughness_length=0.1,
                 cooling_rate=np.array([-1.0, -10.0]))
