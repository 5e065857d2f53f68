"""Tests of floris_ekman_veer.atmosphere.turbulence: Eqs. (upup_var), (Iu_model) and
(kw_CNBL_SBL_model) against arithmetic done here by hand, their limits, and bad input."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from floris_ekman_veer.atmosphere import turbulence as tb
from floris_ekman_veer.atmosphere.ekman import EkmanABL


def test_paper_constants():
    assert (tb.TOWNSEND_PERRY_A1, tb.TOWNSEND_PERRY_B1) == (1.25, 0.6)
    assert (tb.ALPHA_PRIME, tb.MIXING_LAYER_FLOOR, tb.MERGE_EXPONENT) == (0.33, 0.021, 6.0)


def test_turbulence_intensity_hand_arithmetic():
    # u* = 0.4, h = 300, z = 100, U = 8: ln 3 = 1.0986122886681098
    # 1.25 * 1.0986122886681098 + 0.6 = 1.9732653608351374; sqrt(.) * 0.4/8 = 0.0702364819...
    expected = math.sqrt(1.9732653608351374) * 0.05
    assert tb.streamwise_turbulence_intensity(100.0, 0.4, 300.0, 8.0) == pytest.approx(
        expected, rel=1e-14)
    assert expected == pytest.approx(0.07023648198826479, rel=1e-14)
    # other constants: A1 = 2, B1 = 1: sqrt(2 ln 3 + 1) * 0.05
    assert tb.streamwise_turbulence_intensity(100.0, 0.4, 300.0, 8.0, A1=2.0, B1=1.0) == (
        pytest.approx(math.sqrt(2 * 1.0986122886681098 + 1) * 0.05, rel=1e-14))


def test_wake_expansion_rate_hand_arithmetic():
    i_u = math.sqrt(1.25 * math.log(3.0) + 0.6) * 0.05  # 0.0702364819...
    # (0.021^6 + (0.33 * 0.07023648)^6)^(1/6) = (8.5766e-11 + 1.5545e-10)^(1/6)
    expected = (0.021**6 + (0.33 * i_u) ** 6) ** (1.0 / 6.0)
    assert tb.wake_expansion_rate(0.4, 300.0, 100.0, 8.0) == pytest.approx(expected, rel=1e-14)
    assert 0.33 * i_u < expected < 0.33 * i_u * 2 ** (1 / 6)  # smooth max of the two
    # every constant overridable: A1=2, B1=1, alpha'=0.35, floor=0.01, n=4
    i_2 = math.sqrt(2 * math.log(3.0) + 1) * 0.05
    expected_2 = (0.01**4 + (0.35 * i_2) ** 4) ** 0.25
    assert tb.wake_expansion_rate(0.4, 300.0, 100.0, 8.0, A1=2.0, B1=1.0, alpha_prime=0.35,
                                  floor=0.01, n=4.0) == pytest.approx(expected_2, rel=1e-14)


def test_wake_expansion_rate_limits():
    # weak turbulence: the mixing-layer floor 0.021
    assert tb.wake_expansion_rate(1e-4, 300.0, 100.0, 8.0) == pytest.approx(0.021, rel=1e-12)
    # strong turbulence: alpha' I_u
    i_u = math.sqrt(1.25 * math.log(3.0) + 0.6) * 2.0 / 8.0
    assert tb.wake_expansion_rate(2.0, 300.0, 100.0, 8.0) == pytest.approx(0.33 * i_u, rel=1e-5)


def test_continued_above_abl_top_to_the_zero_of_the_variance():
    # docs/atmosphere.md#shallow-boundary-layer: sqrt(max(A1 ln(h/z) + B1, 0)) u*/U above h.
    # just below and at h: B1 alone, sqrt(0.6) u*/U (no jump at h)
    for z in (300.0 * (1 - 1e-12), 300.0):
        assert tb.streamwise_turbulence_intensity(z, 0.4, 300.0, 8.0) == (
            pytest.approx(math.sqrt(0.6) * 0.05, rel=1e-10))
    # 1.2 h: 1.25 ln(1/1.2) + 0.6 = 0.37209805...; sqrt(.) * 0.05
    assert tb.streamwise_turbulence_intensity(360.0, 0.4, 300.0, 8.0) == pytest.approx(
        math.sqrt(1.25 * math.log(1 / 1.2) + 0.6) * 0.05, rel=1e-14)
    # zero from z_t = h exp(B1/A1) = 1.6160744 h up
    z_t = 300.0 * math.exp(0.6 / 1.25)
    assert float(tb.turbulence_top(300.0)) == pytest.approx(z_t, rel=1e-15)
    z = np.array([z_t, 1.001 * z_t, 1000.0])
    np.testing.assert_array_equal(tb.streamwise_turbulence_intensity(z, 0.4, 300.0, 8.0), 0.0)


def test_vectorised_over_heights_and_states():
    z = np.array([[20.0, 50.0, 100.0], [30.0, 60.0, 90.0]])
    u_star = np.array([[0.3], [0.5]])
    h = np.array([[200.0], [800.0]])
    speed = np.array([[6.0], [11.0]])
    got = tb.streamwise_turbulence_intensity(z, u_star, h, speed)
    for i in range(2):
        for j in range(3):
            hand = math.sqrt(1.25 * math.log(h[i, 0] / z[i, j]) + 0.6) * u_star[i, 0] / speed[i, 0]
            assert got[i, j] == pytest.approx(hand, rel=1e-14)


@pytest.mark.parametrize("hub", [300.0, 450.0, 480.0, 2000.0])
def test_hub_at_or_above_h_takes_the_continued_law(hub):
    i_u = math.sqrt(max(1.25 * math.log(300.0 / hub) + 0.6, 0.0)) * 0.4 / 8.0
    expected = (0.021**6 + (0.33 * i_u) ** 6) ** (1 / 6)
    assert tb.wake_expansion_rate(0.4, 300.0, hub, 8.0) == pytest.approx(expected, rel=1e-14)
    if hub >= 300.0 * math.exp(0.6 / 1.25):  # no ambient turbulence: the floor
        assert tb.wake_expansion_rate(0.4, 300.0, hub, 8.0) == pytest.approx(0.021, rel=1e-15)


# ------------------------------------------------------------------------- through EkmanABL
def sbl6():
    return EkmanABL(geostrophic_wind=15.0, coriolis_parameter=1e-4, roughness_length=0.1,
                    cooling_rate=-1.0)


def test_ekman_turbulence_intensity_normalisation():
    a = sbl6()
    u, h = float(a.friction_velocity), float(a.boundary_layer_height)
    z = np.array([20.0, 60.0, 100.0, 150.0])
    local = a.turbulence_intensity(z)
    hub = a.turbulence_intensity(z, reference_height=100.0)
    u_h = float(a.speed(100.0))
    for k, zk in enumerate(z):
        variance = math.sqrt(1.25 * math.log(h / zk) + 0.6) * u
        assert local[k] == pytest.approx(variance / float(a.speed(zk)), rel=1e-13)
        assert hub[k] == pytest.approx(variance / u_h, rel=1e-13)
    assert local[2] == pytest.approx(hub[2], rel=1e-15)
    assert float(a.turbulence_intensity(1.7 * h)) == 0.0  # above h exp(B1/A1) = 1.62 h
    with pytest.raises(ValueError, match="z must be >= roughness_length z0"):
        a.turbulence_intensity(0.05)


def test_ekman_wake_expansion_passes_constants():
    a = sbl6()
    u, h = float(a.friction_velocity), float(a.boundary_layer_height)
    i_u = math.sqrt(1.5 * math.log(h / 100.0) + 0.4) * u / float(a.speed(100.0))
    expected = (0.03**8 + (0.3 * i_u) ** 8) ** (1 / 8)
    got = a.wake_expansion_rate(100.0, A1=1.5, B1=0.4, alpha_prime=0.3, floor=0.03, n=8.0)
    assert float(got) == pytest.approx(expected, rel=1e-13)


def test_stable_flow_has_smaller_wake_expansion():
    base = dict(geostrophic_wind=15.0, coriolis_parameter=1e-4, roughness_length=0.1)
    cnbl, stable = EkmanABL(**base), EkmanABL(**base, cooling_rate=-1.0)
    assert float(stable.wake_expansion_rate(100.0)) < float(cnbl.wake_expansion_rate(100.0))
    assert float(stable.turbulence_intensity(100.0)) < float(cnbl.turbulence_intensity(100.0))


@settings(max_examples=200, deadline=None)
@given(u_star=st.floats(0.01, 2.0), h=st.floats(50.0, 3000.0), frac=st.floats(1e-4, 2.0),
       speed=st.floats(1.0, 40.0))
def test_property_nonnegative_and_bounded(u_star, h, frac, speed):
    z = frac * h
    i_u = float(tb.streamwise_turbulence_intensity(z, u_star, h, speed))
    assert math.isfinite(i_u) and i_u >= 0
    assert (i_u == 0) == (z >= h * math.exp(0.6 / 1.25))
    k_w = float(tb.wake_expansion_rate(u_star, h, z, speed))
    lower = max(0.021, 0.33 * i_u)
    assert lower <= k_w <= lower * 2 ** (1 / 6) * (1 + 1e-12)
