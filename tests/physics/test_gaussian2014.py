"""Tests of the M-3 model, Bastankhah & Porte-Agel (2014), against arithmetic done here by hand."""

import math

import numpy as np
import pytest

from floris_ekman_veer.wake.deficit import normalised_deficit
from floris_ekman_veer.wake.gaussian2014 import bastankhah2014_deficit

CT = 0.7491
D = 100.0
KSTAR = 0.04
RTOL = 1e-12


def hand_beta(ct):
    return 0.5 * (1 + math.sqrt(1 - ct)) / math.sqrt(1 - ct)


def hand_sigma_d(x, ct, d, k_star):
    return k_star * x / d + 0.2 * math.sqrt(hand_beta(ct))


def hand_cap_distance(ct, d, k_star):
    """x where sigma/D = 1/sqrt(8), i.e. where the far-wake C equals 2a = 1 - sqrt(1 - C_T)."""
    return d * (1 / math.sqrt(8) - 0.2 * math.sqrt(hand_beta(ct))) / k_star


def test_far_wake_by_hand():
    # beta_BP = 0.5 (1 + sqrt(0.2509)) / sqrt(0.2509) = 1.4982; sigma/D at x = 600 m:
    # 0.04 * 6 + 0.2 sqrt(1.4982) = 0.24 + 0.244803 = 0.484803.
    x, dy, dz = 600.0, 30.0, -20.0
    beta_bp = 0.5 * (1 + math.sqrt(0.2509)) / math.sqrt(0.2509)
    sigma_d = 0.04 * 600.0 / 100.0 + 0.2 * math.sqrt(beta_bp)
    assert sigma_d == pytest.approx(0.4848026, rel=1e-6)
    c = 1 - math.sqrt(1 - 0.7491 / (8 * sigma_d**2))
    expected = c * math.exp(-(30.0**2 + 20.0**2) / (2 * (sigma_d * 100.0) ** 2))
    got = bastankhah2014_deficit(x, dy, dz, ct=CT, diameter=D, k_star=KSTAR)
    assert got == pytest.approx(expected, rel=RTOL)


def test_capped_at_potential_core_value_near_rotor():
    two_a = 1 - math.sqrt(1 - CT)
    x_cap = hand_cap_distance(CT, D, KSTAR)
    assert x_cap > 0
    for x in (1e-6, 0.5 * x_cap, x_cap):
        assert bastankhah2014_deficit(x, 0.0, 0.0, ct=CT, diameter=D, k_star=KSTAR) == (
            pytest.approx(two_a, rel=RTOL)
        )
    # Off-axis the Gaussian still uses the growing sigma, not the capped one.
    x, dy = 0.5 * x_cap, 25.0
    sigma = hand_sigma_d(x, CT, D, KSTAR) * D
    assert bastankhah2014_deficit(x, dy, 0.0, ct=CT, diameter=D, k_star=KSTAR) == pytest.approx(
        two_a * math.exp(-(dy**2) / (2 * sigma**2)), rel=RTOL
    )


@pytest.mark.parametrize("ct", [0.2, CT, 0.95])
def test_continuous_at_cap(ct):
    x_cap = hand_cap_distance(ct, D, KSTAR)
    eps = 1e-9 * D
    before = bastankhah2014_deficit(x_cap - eps, 0.0, 0.0, ct=ct, diameter=D, k_star=KSTAR)
    after = bastankhah2014_deficit(x_cap + eps, 0.0, 0.0, ct=ct, diameter=D, k_star=KSTAR)
    assert after == pytest.approx(before, rel=1e-9)
    assert after < before


def test_undefined_region_is_covered():
    # C_T = 0.95: at x = 0+ sigma/D = 0.2 sqrt(2.736) = 0.3308 < sqrt(0.95/8) = 0.3446, so the
    # printed root argument is negative there; the cap returns 2a.
    ct = 0.95
    sigma_d0 = 0.2 * math.sqrt(hand_beta(ct))
    assert 1 - ct / (8 * sigma_d0**2) < 0
    got = bastankhah2014_deficit(1e-3, 0.0, 0.0, ct=ct, diameter=D, k_star=KSTAR)
    assert got == pytest.approx(1 - math.sqrt(1 - ct), rel=RTOL)


def test_zero_upstream_and_no_nan():
    x = np.concatenate([[-1e4, -1.0, 0.0], np.geomspace(1e-9, 1e5, 40)])[:, None, None]
    dy = np.linspace(-1e3, 1e3, 21)[None, :, None]
    dz = np.linspace(-300, 1e3, 19)[None, None, :]
    for ct in (0.0, 1e-9, 0.5, CT, 0.97, 0.999):
        out = bastankhah2014_deficit(x, dy, dz, ct=ct, diameter=D, k_star=KSTAR)
        assert np.all(np.isfinite(out))
        assert np.all(out[:3] == 0.0)
        assert np.all(out <= 1 - math.sqrt(1 - ct) + 1e-15)


def test_equals_paper_model_at_zero_yaw_everywhere():
    # beta_BP is the un-yawed A*: M-3 with k* = k_w is Eq. (du_model) at beta = 0 incl. the core.
    x = np.linspace(-50, 3000, 61)[:, None, None]
    dy = np.linspace(-200, 200, 9)[None, :, None]
    dz = np.linspace(-90, 150, 7)[None, None, :]
    m3 = bastankhah2014_deficit(x, dy, dz, ct=CT, diameter=D, k_star=KSTAR)
    m2 = normalised_deficit(x, dy, dz, k_w=KSTAR, radius=D / 2, ct=CT, yaw=0.0, curl=False)
    np.testing.assert_allclose(m3, m2, rtol=1e-12, atol=1e-300)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(ct=1.0, diameter=D, k_star=KSTAR), "ct"),
        (dict(ct=-0.2, diameter=D, k_star=KSTAR), "ct"),
        (dict(ct=CT, diameter=0.0, k_star=KSTAR), "diameter"),
        (dict(ct=CT, diameter=D, k_star=-0.01), "k_star"),
    ],
)
def test_invalid_input_raises_value_error_naming_parameter(kwargs, name):
    with pytest.raises(ValueError, match=rf"^{name} must be"):
        bastankhah2014_deficit(100.0, 0.0, 0.0, **kwargs)
