"""The convective (unstable) boundary layer beyond the paper (docs/atmosphere.md#convective-boundary-layer):
the Businger-Dyer stability functions against their published forms, the CNBL limit as
1/L -> 0 from below, continuity, the closures of either sign, the Panofsky et al. (1977)
turbulence, vectorisation, refusals and FLORIS runs on a convective input."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel
from scipy.integrate import quad

from conftest import EXAMPLE_WAKES, make_config
from floris_ekman_veer import EkmanABL
from floris_ekman_veer.atmosphere.constants import air_heat_capacity
from floris_ekman_veer.atmosphere.similarity import (
    boundary_layer_height_hat,
    gdl_coefficients,
    stability_term,
    unstable_phi_m,
    unstable_psi_m,
)
from floris_ekman_veer.atmosphere.turbulence import convective_variance

INPUTS = Path(__file__).resolve().parents[2] / "inputs"
SITE = dict(coriolis_parameter=1e-4, roughness_length=0.1, brunt_vaisala_frequency=6.1e-3,
            reference_potential_temperature=265.0)
HEIGHTS = np.array([1.0, 10.0, 50.0, 90.0, 150.0, 300.0, 600.0, 1000.0])


# ------------------------------------------------------------------ stability functions


def test_businger_dyer_phi_m_published_values():
    """phi_m = (1 - 16 z/L)^(-1/4) (Dyer 1974): 17^(-1/4) = 0.49248 at z/L = -1; Hogstrom (1988)
    with 19.3: 20.3^(-1/4) = 0.47111; 1 at neutral."""
    assert unstable_phi_m(-1.0) == pytest.approx(0.492479, abs=1e-6)
    assert unstable_phi_m(-1.0, 19.3) == pytest.approx(0.471114, abs=1e-6)
    assert unstable_phi_m(0.0) == 1.0
    assert unstable_phi_m(-0.5) == pytest.approx(9.0**-0.25, rel=1e-14)


def test_paulson_psi_m_hand_values_and_integral():
    """psi_m of Paulson (1970) by hand at z/L = -1 (x = 17^(1/4) = 2.030543):
    2 ln(1.515272) + ln(2.561553) - 2 atan(2.030543) + pi/2 = 1.116232; -0.1: 0.283614;
    Hogstrom's 19.3 at -1: 1.213415. And psi_m = int_zeta^0 (phi_m - 1)/zeta' dzeta', the
    definition, integrated independently."""
    assert unstable_psi_m(-1.0) == pytest.approx(1.116232, abs=1e-6)
    assert unstable_psi_m(-0.1) == pytest.approx(0.283614, abs=1e-6)
    assert unstable_psi_m(-1.0, 19.3) == pytest.approx(1.213415, abs=1e-6)
    for zeta in (-1e-3, -0.3, -2.0, -30.0):
        integral, _ = quad(lambda t: (1.0 - unstable_phi_m(t)) / t, 0.0, zeta, epsabs=1e-13)
        assert unstable_psi_m(zeta) == pytest.approx(integral, rel=1e-9, abs=1e-12)
    # psi_m -> 0 like -(gamma/4) zeta at neutral (phi_m ~ 1 + 4 zeta).
    assert unstable_psi_m(-1e-7) == pytest.approx(4e-7, rel=1e-6)
    assert unstable_psi_m(0.0) == pytest.approx(0.0, abs=1e-15)


def test_stability_term_is_the_papers_on_the_stable_side():
    """For mu >= 0 the term is the paper's 5 mu (xi - xi0) (psi_m = -5 z/L); for mu < 0 it is
    -(psi_m(z/L) - psi_m(z0/L))/kappa with z/L = kappa mu xi; continuous through mu = 0."""
    xi, xi0, kappa = 0.01, 1e-5, 0.41
    assert stability_term(3.0, xi, xi0, kappa) == pytest.approx(15.0 * (xi - xi0), rel=1e-14)
    mu = -50.0
    expected = -(unstable_psi_m(kappa * mu * xi) - unstable_psi_m(kappa * mu * xi0)) / kappa
    assert stability_term(mu, xi, xi0, kappa) == pytest.approx(expected, rel=1e-14)
    below, above = stability_term(-1e-9, xi, xi0, kappa), stability_term(1e-9, xi, xi0, kappa)
    assert abs(below - above) < 1e-10


# ------------------------------------------------------------------ the CNBL limit


def _compare(a, b):
    ua, va = a.velocity(HEIGHTS)
    ub, vb = b.velocity(HEIGHTS)
    g = float(np.hypot(*b.geostrophic_components))
    return dict(
        u_star=abs(a.friction_velocity / b.friction_velocity - 1),
        h=abs(a.boundary_layer_height / b.boundary_layer_height - 1),
        U=np.max(np.abs(ua - ub)) / g, V=np.max(np.abs(va - vb)) / g,
        k_w=abs(a.wake_expansion_rate(90.0) / b.wake_expansion_rate(90.0) - 1),
        I_u=abs(a.turbulence_intensity(90.0) / b.turbulence_intensity(90.0) - 1),
    )


@pytest.mark.parametrize("drive", ["geostrophic", "reference"])
def test_meets_the_cnbl_as_one_over_l_goes_to_zero_from_below(drive):
    """At L = -1e5 m, U, V (relative to G), u*, h (= z_i) and k_w are within 0.5 % of the
    paper's CNBL; the difference falls like 1/|L| (100 times smaller at L = -1e7 m)."""
    def abl(**stability):
        if drive == "geostrophic":
            return EkmanABL(geostrophic_wind=15.0, **SITE, **stability)
        return EkmanABL.from_reference_wind(8.0, 90.0, **SITE, **stability)

    cnbl = abl()
    near = _compare(abl(obukhov_length=-1e5), cnbl)
    nearer = _compare(abl(obukhov_length=-1e7), cnbl)
    for key, value in near.items():
        assert value < 5e-3, (key, value)
        assert nearer[key] < 0.02 * value + 1e-12, (key, nearer[key], value)
    assert near["u_star"] > 1e-5  # it is the convective branch, not the neutral one
    assert np.isinf(cnbl.obukhov_length) and cnbl.convective_variance == 0.0


def test_continuous_through_neutral_from_either_side():
    """L = -1e6 and L = +1e6 straddle the CNBL: u* and h on either side, within 1e-3."""
    neutral = EkmanABL(geostrophic_wind=12.0, **SITE)
    unstable = EkmanABL(geostrophic_wind=12.0, obukhov_length=-1e6, **SITE)
    stable = EkmanABL(geostrophic_wind=12.0, obukhov_length=1e6, **SITE)
    for name in ("friction_velocity", "boundary_layer_height"):
        lo, mid, hi = (getattr(a, name) for a in (stable, neutral, unstable))
        assert lo < mid < hi and (hi - lo) / mid < 1e-3, name


def test_instability_raises_u_star_and_turbulence_monotonically():
    """From near-neutral to L = -50 m (G = 15 m/s, H = 793 W/m^2, near the physical domain's
    800): u* and I_u(90 m) grow (the Businger-Dyer surface layer drags more; buoyancy adds
    variance)."""
    lengths = np.array([-1e4, -1e3, -300.0, -100.0, -50.0])
    abl = EkmanABL(geostrophic_wind=15.0, obukhov_length=lengths, **SITE)
    assert np.all(np.diff(abl.friction_velocity) > 0)
    assert np.all(np.diff(abl.turbulence_intensity(90.0)) > 0)
    assert np.all(abl.stability_parameter < 0)
    np.testing.assert_allclose(abl.obukhov_length, lengths, rtol=1e-12)


# ------------------------------------------------------------------ the convective state


def test_surface_layer_is_businger_dyer_and_meets_the_mixed_layer():
    """Below 0.2 z_i: U/u* = [ln(z/z0) - psi_m(z/L) + psi_m(z0/L)]/kappa + 0.3 mu_N (xi - xi0);
    U continuous at the matching height (A from the same matching); z_i as given."""
    abl = EkmanABL(geostrophic_wind=10.0, obukhov_length=-40.0, mixed_layer_height=1200.0, **SITE)
    assert abl.boundary_layer_height == pytest.approx(1200.0, rel=1e-14)
    u_star, z0, L = abl.friction_velocity, 0.1, abl.obukhov_length
    mu_n = 6.1e-3 / 1e-4
    z = np.array([5.0, 30.0, 90.0, 200.0])
    expected = u_star * ((np.log(z / z0) - unstable_psi_m(z / L) + unstable_psi_m(z0 / L)) / 0.41
                         + 0.3 * mu_n * (z - z0) * 1e-4 / u_star)
    np.testing.assert_allclose(abl.velocity(z)[0], expected, rtol=1e-12)
    z_m = 0.2 * 1200.0
    below, above = abl.velocity(np.array([z_m * (1 - 1e-9), z_m * (1 + 1e-9)]))[0]
    assert below == pytest.approx(above, rel=1e-7)
    # the geostrophic drag law holds: kappa U_g/u* = ln Ro - A, kappa V_g/u* = -B
    u_g, v_g = abl.geostrophic_components
    assert 0.41 * u_g / u_star == pytest.approx(np.log(u_star / (1e-4 * z0)) - abl.gdl_a, rel=1e-12)
    assert 0.41 * v_g / u_star == pytest.approx(-abl.gdl_b, rel=1e-12)
    assert np.hypot(u_g, v_g) == pytest.approx(10.0, rel=1e-12)


def test_default_mixed_layer_is_the_neutral_height():
    """Without mixed_layer_height, z_i f/u* is Eq. (h_hat_model) at mu = 0."""
    abl = EkmanABL(geostrophic_wind=10.0, obukhov_length=-40.0, **SITE)
    h_hat = boundary_layer_height_hat(0.0, 61.0, 0.5, 1.6, 0.78)
    assert abl.h_hat == pytest.approx(h_hat, rel=1e-12)
    assert abl.boundary_layer_height == pytest.approx(h_hat * abl.friction_velocity / 1e-4, rel=1e-12)


def test_deep_mixed_layer_has_weak_shear_and_veer():
    """A deep convective layer (z_i = 2000 m, G = 8 m/s, L = -20 m) against the neutral one:
    about half the speed shear across a 27-153 m rotor (0.19 against 0.37) and above the surface
    layer (0.2 h to 0.9 h), and less turning of the wind over the layer (14 against 22 deg from
    0.2 h to h) and at the ground (cross-isobaric angle 13 against 20 deg)."""
    neutral = EkmanABL(geostrophic_wind=8.0, **SITE)
    mixed = EkmanABL(geostrophic_wind=8.0, obukhov_length=-20.0, mixed_layer_height=2000.0, **SITE)
    rotor = lambda a: a.speed(153.0) / a.speed(27.0) - 1  # noqa: E731
    bulk = lambda a: a.speed(0.9 * a.boundary_layer_height) / a.speed(  # noqa: E731
        0.2 * a.boundary_layer_height) - 1
    turn = lambda a: a.wind_direction_change(  # noqa: E731
        0.2 * a.boundary_layer_height, a.boundary_layer_height)
    assert 0 < rotor(mixed) < 0.6 * rotor(neutral)
    assert 0 < bulk(mixed) < 0.6 * bulk(neutral)
    assert 0 < turn(mixed) < 0.7 * turn(neutral)
    assert abs(mixed.cross_isobaric_angle) < 0.7 * abs(neutral.cross_isobaric_angle)
    # across the rotor both turn the wind by less than a degree (the published V backs there)
    assert abs(mixed.wind_direction_change(27.0, 153.0)) < 1.0


# ------------------------------------------------------------------ the drag law's A and B
#: The drag-law sweep of docs/atmosphere.md#the-geostrophic-drag-law-of-a-convective-layer.
#: To L = -30 m, H = 733 W/m^2 at 8 m/s at 90 m (L = -10 m would need 3.5 kW/m^2, outside the
#: physical domain, docs/atmosphere.md#physical-domain).
DRAG_LAW_LENGTHS = np.array([-1e5, -1e4, -1e3, -300.0, -100.0, -30.0])


@pytest.mark.parametrize("mixed_layer_height", [None, 1500.0])
def test_drag_law_a_is_the_neutral_a_plus_the_surface_layer_psi_m(mixed_layer_height):
    """A = A_N + psi_m(0.2 z_i/L) - psi_m(z0/L), A_N Eq. (A_model_GDL) at mu = 0 for the same
    h_hat and Ro, solved for all L at once; by hand at L = -100 m with the default z_i:
    0.2 h = 211.8 m, psi_m(-2.118) - psi_m(-0.001) = 1.525 (the page's table)."""
    extra = {} if mixed_layer_height is None else dict(mixed_layer_height=mixed_layer_height)
    abl = EkmanABL.from_reference_wind(8.0, 90.0, obukhov_length=DRAG_LAW_LENGTHS, **SITE, **extra)
    neutral_a, neutral_b = gdl_coefficients(
        0.0, 61.0, abl.h_hat, abl.friction_rossby_number, 0.41, 1.43, 0.83, 0.2)
    psi = unstable_psi_m(0.2 * abl.boundary_layer_height / DRAG_LAW_LENGTHS) - unstable_psi_m(
        0.1 / DRAG_LAW_LENGTHS)
    np.testing.assert_allclose(abl.gdl_a - neutral_a, psi, rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(abl.gdl_b, neutral_b, rtol=1e-14)
    assert np.all(np.diff(abl.gdl_a) > 0)  # A grows with instability
    if mixed_layer_height is None:
        k = list(DRAG_LAW_LENGTHS).index(-100.0)
        z_m = 0.2 * abl.boundary_layer_height[k]
        x_m, x_0 = (1.0 + 16.0 * z_m / 100.0) ** 0.25, (1.0 + 16.0 * 0.1 / 100.0) ** 0.25
        by_hand = [2 * np.log((1 + x) / 2) + np.log((1 + x * x) / 2) - 2 * np.arctan(x) + np.pi / 2
                   for x in (x_m, x_0)]
        assert z_m == pytest.approx(211.8, abs=0.1)
        assert abl.gdl_a[k] - neutral_a[k] == pytest.approx(by_hand[0] - by_hand[1], rel=1e-12)
        assert abl.gdl_a[k] - neutral_a[k] == pytest.approx(1.525, abs=5e-4)


@pytest.mark.parametrize("mixed_layer_height", [None, 1500.0])
def test_surface_layer_top_wind_is_brutsaerts_bulk_mixed_layer_speed(mixed_layer_height):
    """Brutsaert (1999)'s bulk similarity of the convective layer (a Monin-Obukhov surface layer
    to alpha_t h_i under a mixed slab): U_m = (u*/kappa) [ln(h_i/z0) - B_w], B_w = -ln(alpha_t) +
    psi_m(alpha_t h_i/L) - psi_m(z0/L). With alpha_t the matching fraction 0.2 and h_i = z_i, the
    model's U at the top of its surface layer is that U_m plus the paper's CNBL term
    0.3 mu_N u* (xi_m - xi_0), for every L: the drag law's A - A_N (test above) is B_w's
    stability part (docs/atmosphere.md#the-geostrophic-drag-law-of-a-convective-layer). B_w
    computed here from Paulson's psi_m by hand."""
    extra = {} if mixed_layer_height is None else dict(mixed_layer_height=mixed_layer_height)
    abl = EkmanABL.from_reference_wind(8.0, 90.0, obukhov_length=DRAG_LAW_LENGTHS, **SITE, **extra)
    z_i, u_star, z0 = abl.boundary_layer_height, abl.friction_velocity, 0.1

    def psi(zeta):
        x = (1.0 - 16.0 * zeta) ** 0.25
        return 2 * np.log((1 + x) / 2) + np.log((1 + x * x) / 2) - 2 * np.arctan(x) + np.pi / 2

    alpha_t = 0.2
    b_w = -np.log(alpha_t) + psi(alpha_t * z_i / DRAG_LAW_LENGTHS) - psi(z0 / DRAG_LAW_LENGTHS)
    u_m = u_star / 0.41 * (np.log(z_i / z0) - b_w)
    cnbl = 0.3 * abl.zilitinkevich_number * 1e-4 * (alpha_t * z_i - z0)  # u* 0.3 mu_N (xi - xi0)
    top = np.diagonal(abl.velocity((alpha_t * z_i)[:, None])[0])
    np.testing.assert_allclose(top, u_m + cnbl, rtol=1e-12)


def test_drag_law_a_grows_like_ln_minus_mu_in_strong_convection():
    """For -0.2 h/L >> 1 psi_m -> ln(1 - gamma z/L) - 3 ln 2 - pi/2, so at fixed h_hat and Ro
    d A/d ln(-mu) -> 1 and A -> ln(-kappa mu) + ln(gamma/8) - pi/2 - psi_m(z0/L) - kappa E
    (E the bracket of Eq. A_model_GDL without its stability term), for both gammas; the slope is
    below 1 and rises towards it, A stays above the limit and closes on it (psi_m approaches
    its asymptote like (-z/L)^(-1/4)). A limit of the formula: Ro = 1e16 keeps z0/L small while
    -0.2 h/L reaches 1e10."""
    h_hat, rossby, mu_n = 0.19, 1e16, 61.0
    mu = -np.logspace(2, 12, 11)
    for gamma in (16.0, 19.3):
        a, _ = gdl_coefficients(mu, mu_n, h_hat, rossby, 0.41, 1.43, 0.83, 0.2, gamma)
        slope = np.diff(a) / np.diff(np.log(-mu))
        assert np.all(np.diff(slope) > 0) and np.all(slope < 1.0)
        assert slope[-1] == pytest.approx(1.0, abs=3e-3)
        neutral, _ = gdl_coefficients(0.0, mu_n, h_hat, rossby, 0.41, 1.43, 0.83, 0.2)
        kappa_e = -np.log(0.2 * h_hat) - neutral
        limit = (np.log(-0.41 * mu) + np.log(gamma / 8) - np.pi / 2
                 - unstable_psi_m(0.41 * mu / rossby, gamma) - kappa_e)
        gap = a - limit
        assert np.all(gap > 0) and np.all(np.diff(gap) < 0) and gap[-1] < 1e-2


def test_drag_law_b_is_the_mixed_layer_momentum_budget():
    """B = 1.5 kappa u*/(f z_i): with the default z_i the CNBL's B at every L; with z_i = 1500 m
    B grows with u*, hence with instability; and f int_0^z_i (V - V_g) dz = u*^2 (the mixed
    layer's momentum budget) by quadrature at every L."""
    cnbl = EkmanABL.from_reference_wind(8.0, 90.0, **SITE)
    default = EkmanABL.from_reference_wind(8.0, 90.0, obukhov_length=DRAG_LAW_LENGTHS, **SITE)
    np.testing.assert_allclose(default.gdl_b, cnbl.gdl_b, rtol=1e-12)
    deep = EkmanABL.from_reference_wind(8.0, 90.0, obukhov_length=DRAG_LAW_LENGTHS,
                                        mixed_layer_height=1500.0, **SITE)
    np.testing.assert_allclose(deep.gdl_b, 1.5 * 0.41 * deep.friction_velocity / (1e-4 * 1500.0),
                               rtol=1e-12)
    assert np.all(np.diff(deep.gdl_b) > 0)
    z = np.linspace(0.0, 1500.0, 20001)[:, None]
    v = deep.velocity(z)[1]
    budget = 1e-4 * np.trapezoid(v - deep.geostrophic_components[1], z[:, 0], axis=0)
    np.testing.assert_allclose(budget / deep.friction_velocity**2, 1.0, atol=2e-4)


def test_roughness_sublayer_is_the_tangent_in_a_convective_layer():
    """z_s: U(z_s) = z_s dU/dz(z_s), the tangent through the ground, also with psi_m."""
    abl = EkmanABL(geostrophic_wind=6.0, obukhov_length=-10.0, roughness_length=0.5,
                   coriolis_parameter=1e-4)
    z_s = float(abl.roughness_sublayer_height)
    assert 0.5 * np.e * 0.9 < z_s < 0.5 * np.e * 1.1
    step = 1e-5 * z_s
    slope = (abl.velocity(z_s + step)[0] - abl.velocity(z_s)[0]) / step
    assert abl.velocity(z_s)[0] == pytest.approx(z_s * slope, rel=1e-4)


# ------------------------------------------------------------------ closures of either sign


def test_heat_flux_inputs_agree():
    """sensible_heat_flux H [W/m^2] = rho c_p Q0 with rho c_p = 1005 * 1e5/(287.05 Theta0)
    (1321.1 at 265 K); Q0, H and the solved L give one state; the reported flux is the input's."""
    assert air_heat_capacity(265.0) == pytest.approx(1005.0 * 1e5 / (287.05 * 265.0), rel=1e-14)
    by_h = EkmanABL(geostrophic_wind=10.0, sensible_heat_flux=200.0, **SITE)
    by_q = EkmanABL(geostrophic_wind=10.0, surface_heat_flux=200.0 / air_heat_capacity(265.0),
                    **SITE)
    by_l = EkmanABL(geostrophic_wind=10.0, obukhov_length=float(by_h.obukhov_length), **SITE)
    for other in (by_q, by_l):
        assert other.friction_velocity == pytest.approx(by_h.friction_velocity, rel=1e-10)
    assert by_h.sensible_heat_flux == pytest.approx(200.0, rel=1e-12)
    # L = -u*^3 Theta0 / (kappa g Q0)
    q0 = 200.0 / air_heat_capacity(265.0)
    assert by_h.obukhov_length == pytest.approx(
        -by_h.friction_velocity**3 * 265.0 / (0.41 * 9.81 * q0), rel=1e-12)


def test_heating_rate_closure():
    """A heating rate C_r > 0 [K/h]: the mixed layer warms at C_r with an entrainment flux of
    -0.2 Q0 at z_i (Tennekes 1973), so Q0 = C_r z_i / 1.2."""
    abl = EkmanABL(geostrophic_wind=10.0, cooling_rate=0.8, mixed_layer_height=1500.0, **SITE)
    assert abl.surface_heat_flux == pytest.approx(0.8 / 3600.0 * 1500.0 / 1.2, rel=1e-12)
    default = EkmanABL(geostrophic_wind=10.0, cooling_rate=0.8, **SITE)
    assert default.surface_heat_flux == pytest.approx(
        0.8 / 3600.0 * default.boundary_layer_height / 1.2, rel=1e-12)
    # cooling keeps the paper's closure Q0 = C_r h
    night = EkmanABL(geostrophic_wind=10.0, cooling_rate=-0.5, **SITE)
    assert night.surface_heat_flux == pytest.approx(-0.5 / 3600.0 * night.boundary_layer_height,
                                                    rel=1e-10)


def test_mixed_signs_solve_together_as_apart():
    """One array of conditions of both signs (and neutral, +-inf) gives each condition the state
    it has alone: vectorised, batch-independent, broadcasting to FLORIS's 4-D grids."""
    lengths = np.array([-25.0, np.inf, 150.0, -np.inf, -400.0, 60.0])
    speeds = np.array([5.0, 7.0, 9.0, 11.0, 13.0, 6.0])
    together = EkmanABL.from_reference_wind(speeds[:, None, None, None], 90.0,
                                            obukhov_length=lengths[:, None, None, None], **SITE)
    z = np.array([10.0, 90.0, 150.0]).reshape(1, 1, 1, -1)
    u_all, v_all = together.velocity(z)
    k_all = together.wake_expansion_rate(90.0)
    for i, (speed, length) in enumerate(zip(speeds, lengths)):
        alone = EkmanABL.from_reference_wind(speed, 90.0, obukhov_length=length, **SITE)
        u, v = alone.velocity(z[0, 0, 0])
        np.testing.assert_allclose(u_all[i, 0, 0], u, rtol=1e-10)
        np.testing.assert_allclose(v_all[i, 0, 0], v, rtol=1e-10, atol=1e-12)
        assert k_all[i, 0, 0, 0] == pytest.approx(alone.wake_expansion_rate(90.0), rel=1e-10)
    assert u_all.shape == (6, 1, 1, 3)


# ------------------------------------------------------------------ turbulence


def test_convective_turbulence_by_hand():
    """I_u = [A1 ln(z_i/z) + B1 + (12 - 0.5 z_i/L)^(2/3) - 12^(2/3)]^(1/2) u*/U_h and
    k_w = [0.021^6 + (0.33 I_u)^6]^(1/6): Eq. (kw_CNBL_SBL_model) kept with the Panofsky et al. (1977) variance."""
    abl = EkmanABL.from_reference_wind(6.0, 90.0, obukhov_length=-30.0, mixed_layer_height=1400.0,
                                       **SITE)
    u_star = abl.friction_velocity
    excess = (12.0 + 0.5 * 1400.0 / 30.0) ** (2 / 3) - 12.0 ** (2 / 3)
    assert abl.convective_variance == pytest.approx(excess, rel=1e-14)
    i_u = np.sqrt(1.25 * np.log(1400.0 / 90.0) + 0.6 + excess) * u_star / 6.0
    assert abl.turbulence_intensity(90.0, reference_height=90.0) == pytest.approx(i_u, rel=1e-12)
    assert abl.wake_expansion_rate(90.0) == pytest.approx(
        (0.021**6 + (0.33 * i_u) ** 6) ** (1 / 6), rel=1e-12)
    # strongly convective: sigma_u -> (0.5 z_i/(-L))^(1/3) u*, about 0.59 w* (Panofsky et al.)
    strong = np.sqrt(convective_variance(1000.0, -1.0))
    assert strong == pytest.approx((12.0 + 500.0) ** (1 / 3), rel=0.05)
    assert convective_variance(1000.0, 50.0) == 0.0 and convective_variance(1000.0, np.inf) == 0.0


def test_convective_variance_tapers_above_z_i():
    """Above z_i the buoyant variance tapers linearly to 0 at the turbulence top z_i exp(B1/A1)
    with the paper's law: I_u is continuous there and 0 above."""
    abl = EkmanABL(geostrophic_wind=5.0, obukhov_length=-5.0, mixed_layer_height=300.0, **SITE)
    top = 300.0 * np.exp(0.6 / 1.25)
    values = abl.turbulence_intensity(np.array([300.0, 300.0 + 1e-9, 0.5 * (300 + top),
                                                top * (1 - 1e-9), top * 1.01]), reference_height=90.0)
    assert values[0] == pytest.approx(values[1], rel=1e-8)
    assert values[3] < 1e-3 * values[0] and values[4] == 0.0


# ------------------------------------------------------------------ inputs and FLORIS


@pytest.mark.parametrize("key, value, pattern", [
    ("sensible_heat_flux", 1500.0, r"sensible_heat_flux must be -300 to 800 W/m\^2.*; got 1500"),
    ("obukhov_length", 0.0, r"obukhov_length must be > 0 m stable, < 0 m convective.*; got 0"),
    ("mixed_layer_height", 5.0, r"mixed_layer_height must be 10 to 5000 m.*; got 5"),
    ("cooling_rate", 12.0, r"cooling_rate must be -10 to 10 K/h.*; got 12"),
    ("surface_heat_flux", 120.0, r"surface_heat_flux must be the kinematic upward heat flux Q0 \[K m/s\] with rho c_p Q0 within -300 to 800 W/m\^2.*; got 120"),
])
def test_floris_input_refusals_name_path_value_and_range(key, value, pattern):
    atmosphere = dict(SITE, **{key: value})
    if key == "mixed_layer_height":
        atmosphere["obukhov_length"] = -50.0
    with pytest.raises(ValueError, match=r"wake\.wake_velocity_parameters\.ekman_veer\.atmosphere\."
                                         + pattern):
        FlorisModel(make_config("gauss", atmosphere=atmosphere))


def test_two_stability_inputs_are_refused_in_floris():
    atmosphere = dict(SITE, sensible_heat_flux=100.0, obukhov_length=-50.0)
    with pytest.raises(ValueError, match=r"contradictory keys \['obukhov_length', "
                                         r"'sensible_heat_flux'\]"):
        FlorisModel(make_config("gauss", atmosphere=atmosphere))


@pytest.mark.parametrize("wake", sorted(EXAMPLE_WAKES))
def test_every_floris_model_runs_on_a_convective_day(wake):
    """FLORIS's own models on the convective inflow (the same hook): finite powers, and each
    condition's powers the same run alone as in a batch."""
    atmosphere = dict(SITE, sensible_heat_flux=150.0, mixed_layer_height=1500.0)
    speeds = (4.0, 8.0, 12.0)
    batch = FlorisModel(make_config(wake, atmosphere=atmosphere, wind_speeds=speeds,
                                    wind_directions=(270.0,) * 3))
    batch.run()
    powers = batch.get_turbine_powers()
    assert np.all(np.isfinite(powers)) and np.all(powers >= 0) and np.all(powers[:, 0] > 0)
    for i, speed in enumerate(speeds):
        alone = FlorisModel(make_config(wake, atmosphere=atmosphere, wind_speeds=(speed,)))
        alone.run()
        np.testing.assert_allclose(alone.get_turbine_powers()[0], powers[i], rtol=1e-10)


def test_gauss_and_ekman_veer_run_on_the_shipped_convective_day():
    """inputs/farm_day.yaml (H = +150 W/m^2, z_i = 1500 m) with ekman_veer and with FLORIS's gauss
    on the same inflow: finite; the convective inflow's higher I_u widens the ekman_veer wakes,
    so the waked rows lose less than on the neutral day (cnbl.yaml's atmosphere)."""
    from floris_ekman_veer.plugin.inflow.inflow import set_atmosphere

    fmodel = FlorisModel(INPUTS / "farm_day.yaml")
    fmodel.set(wind_speeds=[6.0, 9.0], wind_directions=[270.0, 270.0],
               turbulence_intensities=[0.06, 0.06])
    config = fmodel.core.as_dict()
    config["wake"]["model_strings"].update(velocity_model="gauss", deflection_model="gauss")
    gauss = FlorisModel(config)
    for model in (fmodel, gauss):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model.run()
        assert np.all(np.isfinite(model.get_turbine_powers()))
    day = fmodel.get_turbine_powers()
    neutral = fmodel.copy()
    cnbl = dict(SITE, cooling_rate=0.0)
    set_atmosphere(neutral, cnbl, wind_speeds=[6.0, 9.0], wind_directions=[270.0, 270.0],
                   turbulence_intensities=[0.06, 0.06])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        neutral.run()
    night_like = neutral.get_turbine_powers()
    # front row (x = 0: turbines 0-2) unwaked; back rows relative to the front
    ratio = lambda p: p[:, 6:].sum(axis=1) / p[:, :3].sum(axis=1)  # noqa: E731
    assert np.all(ratio(day) > ratio(night_like))


def test_rotor_shear_above_neutral_comes_from_the_neutral_defect_of_a_shallow_mixed_layer():
    """3 m/s at 90 m, latitude 50, z0 = 1 mm (docs/atmosphere.md#rotor-layer-shear-in-a-shallow-mixed-layer):
    with the default z_i (the neutral height, 172-219 m here) U(153)/U(27) rises from 1.254
    (CNBL) to 1.324 at L = -5 m, because above 0.2 z_i the model keeps the paper's Ekman-layer
    velocity defect (U_g - U)/u* at each z/h, identical to the CNBL's, while U_g/u* falls with
    instability (A grows): the same defect is a larger part of a smaller wind. With the rotor
    inside the surface layer (z_i = 1500 m, 0.2 z_i = 300 m) instability flattens the shear,
    1.254 -> 1.139."""
    site = dict(latitude=50.0, roughness_length=1e-3)
    lengths = np.array([np.inf, -1000.0, -100.0, -20.0, -5.0])
    shallow = EkmanABL.from_reference_wind(3.0, 90.0, obukhov_length=lengths, **site)
    shear = shallow.speed(153.0) / shallow.speed(27.0)
    np.testing.assert_allclose(shear[[0, -1]], [1.2543, 1.3239], atol=1e-4)
    assert np.all(np.diff(shear) > 0) and np.all(0.2 * shallow.boundary_layer_height < 153.0)
    eta = np.array([0.3, 0.5, 0.8])[:, None]
    defect = (shallow.geostrophic_components[0] - shallow.velocity(
        eta * shallow.boundary_layer_height)[0]) / shallow.friction_velocity
    np.testing.assert_allclose(defect, defect[:, :1] * np.ones(len(lengths)), rtol=1e-10)
    assert np.all(np.diff(shallow.geostrophic_components[0] / shallow.friction_velocity) < 0)
    deep = EkmanABL.from_reference_wind(3.0, 90.0, obukhov_length=lengths,
                                        mixed_layer_height=1500.0, **site)
    deep_shear = deep.speed(153.0) / deep.speed(27.0)
    np.testing.assert_allclose(deep_shear[[0, -1]], [1.2543, 1.1393], atol=1e-4)
    assert np.all(np.diff(deep_shear) < 0)
