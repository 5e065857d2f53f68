"""Tests of floris_ekman_veer.wake.deflection against arithmetic done here by hand, and the limits
of docs/wake_model.md#limits (y_hat_c -> t/2, -> sgn(t)|t|/(2 pi); mirror symmetry; beta > 0 -> y_c < 0)."""

import math

import numpy as np
import pytest

from floris_ekman_veer.wake import deflection as wf

CT = 0.7491
R = 50.0
ZH = 90.0
BETA = math.radians(20.0)
USTAR = 0.45
UH = 9.0
UZ = 8.5
RTOL = 1e-12
PM1 = math.pi - 1.0


def hand_astar(ct, beta):
    s = math.sqrt(1.0 - ct * math.cos(beta) ** 2)
    return (1.0 + s) / (2.0 * s)


def hand_vortex_pair(t):
    """First term of Eq. (yhatc)."""
    num = PM1 * abs(t) ** 3 + 2 * math.sqrt(3) * math.pi**2 * t**2 + 48 * PM1**2 * abs(t)
    den = 2 * math.pi * PM1 * t**2 + 4 * math.sqrt(3) * math.pi**2 * abs(t) + 96 * PM1**2
    return num / den * math.copysign(1.0, t) if t != 0 else 0.0


def hand_ground_term(t, z, zh, r, ct, beta):
    """Second term of Eq. (yhatc), as printed (valid where ((z + zh)/rho) >= 1.4)."""
    rho = r * math.sqrt(hand_astar(ct, beta))
    return -2 / math.pi * t / (((z + zh) / rho) ** 2 - 1)


def hand_that(x, ustar, uh, uz, r, ct, beta):
    return (
        -1.44 * uh / ustar / math.sqrt(hand_astar(ct, beta)) * ct * math.cos(beta) ** 2
        * math.sin(beta) * (1 - math.exp(-0.35 * ustar / uz * x / r))
    )


# ------------------------------------------------------------------------- Eq. (yhatc)
@pytest.mark.parametrize("t", [-7.3, -1.1, -0.05, 0.3, 2.0, 15.0])
@pytest.mark.parametrize("z", [30.0, 90.0, 170.0])
def test_yaw_deflection_by_hand(t, z):
    got = wf.yaw_deflection(t, z, ZH, R, CT, BETA)
    expected = hand_vortex_pair(t) + hand_ground_term(t, z, ZH, R, CT, BETA)
    assert got == pytest.approx(expected, rel=RTOL)
    assert wf.yaw_deflection(t, z, ZH, R, CT, BETA, ground_image=False) == pytest.approx(
        hand_vortex_pair(t), rel=RTOL
    )


def test_yaw_deflection_numbers():
    # t = -2: numerator = (pi-1) 8 + 2 sqrt3 pi^2 4 + 48 (pi-1)^2 2, denominator
    # 2 pi (pi-1) 4 + 4 sqrt3 pi^2 2 + 96 (pi-1)^2 = 594.18 / 630.87 = 0.94184...
    num = (math.pi - 1) * 8 + 2 * math.sqrt(3) * math.pi**2 * 4 + 48 * (math.pi - 1) ** 2 * 2
    den = (
        2 * math.pi * (math.pi - 1) * 4 + 4 * math.sqrt(3) * math.pi**2 * 2
        + 96 * (math.pi - 1) ** 2
    )
    assert num / den == pytest.approx(0.9418407721586968, rel=1e-12)
    assert wf.yaw_deflection(-2.0, 0.0, ZH, R, CT, BETA, ground_image=False) == pytest.approx(
        -num / den, rel=RTOL
    )


def test_yaw_deflection_zero_at_zero_time():
    z = np.array([-500.0, -ZH, 0.0, 12.3, ZH, 400.0])
    np.testing.assert_array_equal(wf.yaw_deflection(0.0, z, ZH, R, CT, BETA), 0.0)
    # the unyawed fast path keeps the broadcast shape of t_hat and z
    assert wf.yaw_deflection(np.zeros((2, 1)), z, ZH, R, CT, BETA).shape == (2, z.size)


@pytest.mark.parametrize("t", [1e-4, 1e-6, -1e-5])
def test_small_time_limit_is_half_t(t):
    got = wf.yaw_deflection(t, ZH, ZH, R, CT, BETA, ground_image=False)
    assert got == pytest.approx(t / 2, rel=1e-8)  # the O(t) corrections cancel; error O(t^2)


@pytest.mark.parametrize("t", [1e6, -1e6, 1e8])
def test_large_time_limit_is_t_over_two_pi(t):
    got = wf.yaw_deflection(t, ZH, ZH, R, CT, BETA, ground_image=False)
    assert got == pytest.approx(t / (2 * math.pi), rel=1e-4)
    # Next order, by hand: ratio -> |t|/(2 pi) (1 + 2 sqrt3 pi /|t|), i.e. offset sgn(t) sqrt(3).
    assert got - t / (2 * math.pi) == pytest.approx(math.copysign(math.sqrt(3), t), abs=1e-4)


def test_positive_yaw_sends_wake_to_minus_y():
    t = wf.time_like_variable(600.0, USTAR, UH, UZ, R, CT, BETA)
    assert t < 0
    for ground_image in (False, True):
        assert wf.yaw_deflection(t, ZH, ZH, R, CT, BETA, ground_image=ground_image) < 0
    offset = wf.wake_centre_offset(
        600.0, ZH, hub_height=ZH, radius=R, ct=CT, yaw=BETA, friction_velocity=USTAR,
        hub_speed=UH, local_speed=UZ, veer=False,
    )
    assert offset < 0


def test_ground_image_term_uses_local_height():
    t = -3.0
    values = [float(wf.yaw_deflection(t, z, ZH, R, CT, BETA)) for z in (40.0, 90.0, 160.0)]
    expected = [hand_vortex_pair(t) + hand_ground_term(t, z, ZH, R, CT, BETA)
                for z in (40.0, 90.0, 160.0)]
    np.testing.assert_allclose(values, expected, rtol=RTOL)
    assert len(set(values)) == 3


def test_ground_image_floor_below_image_vortex_core():
    # rho = R sqrt(A*) = 61.2 m here; eta = (z + z_h)/rho is floored at 1.4, i.e. below
    # z_floor = 1.4 rho - z_h = -4.3 m the term keeps its value at z_floor.
    t = -3.0
    rho = R * math.sqrt(hand_astar(CT, BETA))
    z_floor = 1.4 * rho - ZH
    at_floor = hand_vortex_pair(t) - 2 / math.pi * t / (1.4**2 - 1)
    assert wf.yaw_deflection(t, z_floor, ZH, R, CT, BETA) == pytest.approx(at_floor, rel=RTOL)
    # Singular heights of the printed formula: z = rho - z_h and z = -rho - z_h; and far below.
    for z in (rho - ZH, -rho - ZH, -ZH, z_floor - 1.0, -1e4):
        assert wf.yaw_deflection(t, z, ZH, R, CT, BETA) == pytest.approx(at_floor, rel=RTOL)
    # Continuous across the floor height; unchanged printed formula just above it.
    just_above = z_floor + 1e-9
    assert wf.yaw_deflection(t, just_above, ZH, R, CT, BETA) == pytest.approx(at_floor, rel=1e-9)
    assert wf.yaw_deflection(t, 0.0, ZH, R, CT, BETA) == pytest.approx(
        hand_vortex_pair(t) + hand_ground_term(t, 0.0, ZH, R, CT, BETA), rel=RTOL
    )
    # Bounded: |ground term| <= (2/pi) |t| / 0.96 everywhere.
    z = np.linspace(-1e3, 1e3, 4001)
    ground = wf.yaw_deflection(t, z, ZH, R, CT, BETA) - hand_vortex_pair(t)
    assert np.max(np.abs(ground)) == pytest.approx(2 / math.pi * abs(t) / 0.96, rel=RTOL)


def test_low_hub_singularity_in_the_fluid_is_finite():
    # z_h = 55 m < rho = R sqrt(A*) (C_T = 0.9): the printed term is singular at z = rho - z_h > 0.
    ct, zh = 0.9, 55.0
    rho = R * math.sqrt(hand_astar(ct, 0.3))
    z_sing = rho - zh
    assert z_sing > 0
    z = np.array([0.0, z_sing, z_sing + 1e-12, 0.5 * z_sing, 1.4 * rho - zh, 200.0])
    out = wf.yaw_deflection(-4.0, z, zh, R, ct, 0.3)
    assert np.all(np.isfinite(out))
    assert out[-1] == pytest.approx(
        hand_vortex_pair(-4.0) + hand_ground_term(-4.0, 200.0, zh, R, ct, 0.3), rel=RTOL
    )
    np.testing.assert_allclose(out[:5], out[4], rtol=RTOL)


# ------------------------------------------------------------------------- Eq. (yc_veer)
def test_veer_deflection_by_hand():
    assert wf.veer_deflection(700.0, 8.5, -0.6) == pytest.approx(700.0 * -0.6 / 8.5, rel=RTOL)
    np.testing.assert_array_equal(wf.veer_deflection(np.array([-50.0, 0.0]), 8.5, 0.6), 0.0)
    x = np.array([[100.0], [200.0]])
    out = wf.veer_deflection(x, np.array([7.0, 8.0]), np.array([0.7, -0.4]))
    np.testing.assert_allclose(out, [[10.0, -5.0], [20.0, -10.0]], rtol=RTOL)


@pytest.mark.parametrize("u", [0.0, -0.3, np.nan])
def test_veer_deflection_requires_positive_local_speed(u):
    with pytest.raises(ValueError, match="^local_speed must be"):
        wf.veer_deflection(np.array([100.0, 200.0]), np.array([8.0, u]), 0.1)


# ------------------------------------------------------------------------- Eq. (yc_xz)
def test_wake_centre_offset_by_hand():
    x, z, v = 800.0, 60.0, 0.35
    t = hand_that(x, USTAR, UH, UZ, R, CT, BETA)
    rho = R * math.sqrt(hand_astar(CT, BETA))
    yaw_part = (hand_vortex_pair(t) + hand_ground_term(t, z, ZH, R, CT, BETA)) * rho
    common = dict(hub_height=ZH, radius=R, ct=CT, yaw=BETA, friction_velocity=USTAR, hub_speed=UH,
                  local_speed=UZ)
    assert wf.wake_centre_offset(x, z, lateral_speed=v, **common) == pytest.approx(
        yaw_part + x * v / UZ, rel=RTOL
    )
    assert wf.wake_centre_offset(x, z, veer=False, **common) == pytest.approx(yaw_part, rel=RTOL)
    no_ground = hand_vortex_pair(t) * rho
    assert wf.wake_centre_offset(x, z, veer=False, ground_image=False, **common) == (
        pytest.approx(no_ground, rel=RTOL)
    )
    assert wf.wake_centre_offset(-10.0, z, lateral_speed=v, **common) == 0.0


def test_wake_centre_offset_mirror_symmetry_without_veer():
    x = np.linspace(-100, 3000, 31)[:, None]
    z = np.linspace(-50, 250, 25)[None, :]
    common = dict(hub_height=ZH, radius=R, ct=CT, friction_velocity=USTAR, hub_speed=UH,
                  local_speed=UZ, veer=False)
    plus = wf.wake_centre_offset(x, z, yaw=BETA, **common)
    minus = wf.wake_centre_offset(x, z, yaw=-BETA, **common)
    np.testing.assert_allclose(plus, -minus, rtol=RTOL, atol=0)
    assert np.any(plus != 0)


def test_wake_centre_offset_zero_yaw_is_pure_veer():
    x = np.array([0.0, 300.0, 900.0])
    common = dict(hub_height=ZH, radius=R, ct=CT, yaw=0.0, friction_velocity=USTAR, hub_speed=UH,
                  local_speed=UZ)
    np.testing.assert_allclose(
        wf.wake_centre_offset(x, 40.0, lateral_speed=0.5, **common), x * 0.5 / UZ, rtol=RTOL
    )


def test_no_nan_on_broad_grid_and_inputs_untouched():
    x = np.concatenate([[-1e4, 0.0], np.geomspace(1e-6, 1e5, 25)])[:, None]
    z = np.concatenate([[0.0, -ZH, -1e4], np.linspace(-300, 1e3, 60)])[None, :]
    uz = np.full(z.shape, 8.0)
    v = np.linspace(-1, 1, z.size)[None, :]
    copies = [a.copy() for a in (x, z, uz, v)]
    for a in (x, z, uz, v):
        a.setflags(write=False)
    for ct in (0.0, 0.5, CT, 0.97, 0.999):
        for beta in (-1.5, -0.3, 0.0, 0.3, 1.5):
            for zh in (30.0, ZH):
                out = wf.wake_centre_offset(
                    x, z, hub_height=zh, radius=R, ct=ct, yaw=beta, friction_velocity=USTAR,
                    hub_speed=UH, local_speed=uz, lateral_speed=v,
                )
                assert np.all(np.isfinite(out))
    for a, c in zip((x, z, uz, v), copies):
        np.testing.assert_array_equal(a, c)


INVALID = [
    (wf.yaw_deflection, dict(t_hat=1.0, z=0.0, hub_height=0.0, radius=R, ct=CT, yaw=0.1),
     "hub_height"),
    (wf.yaw_deflection, dict(t_hat=1.0, z=0.0, hub_height=ZH, radius=-1.0, ct=CT, yaw=0.1),
     "radius"),
    # C_T cos^2(yaw) = 1.02 cos^2(0.1) = 1.0098 >= 1: beyond momentum theory of the yawed rotor
    (wf.yaw_deflection, dict(t_hat=1.0, z=0.0, hub_height=ZH, radius=R, ct=1.02, yaw=0.1), "ct"),
    (wf.yaw_deflection, dict(t_hat=1.0, z=0.0, hub_height=ZH, radius=R, ct=CT, yaw=3.0), "yaw"),
    (wf.veer_deflection, dict(x=1.0, local_speed=-1.0, lateral_speed=0.0), "local_speed"),
    (wf.wake_centre_offset, dict(x=1.0, z=0.0, hub_height=ZH, radius=R, ct=CT, yaw=0.1,
                                 friction_velocity=USTAR, hub_speed=UH, local_speed=UZ),
     "lateral_speed"),
    (wf.wake_centre_offset, dict(x=1.0, z=0.0, hub_height=ZH, radius=R, ct=CT, yaw=0.1,
                                 friction_velocity=-USTAR, hub_speed=UH, local_speed=UZ,
                                 veer=False), "friction_velocity"),
]


@pytest.mark.parametrize("function, kwargs, name", INVALID)
def test_invalid_input_raises_value_error_naming_parameter(function, kwargs, name):
    with pytest.raises(ValueError, match=rf"^{name} must be"):
        function(**kwargs)
