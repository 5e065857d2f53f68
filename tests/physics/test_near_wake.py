"""The near wake inside the potential core (wake/near_wake.py, docs/wake_model.md#near-wake):
the super-Gaussian of Blondel & Cathelain (2020) with the paper's centre deficit 2a and width,
its order the root of the momentum integral."""

from __future__ import annotations

import math

import numpy as np
import pytest

from floris_ekman_veer.wake import deficit as wd
from floris_ekman_veer.wake.near_wake import near_wake_shape, super_gaussian_order

RADIUS = 50.0
K_W = 0.0216


def _deficit(x, r, ct, shape, yaw=0.0):
    return wd.normalised_deficit(x, r, np.zeros_like(r), k_w=K_W, radius=RADIUS, ct=ct, yaw=yaw,
                                 curl=False, shape=shape)


@pytest.mark.parametrize("ct", [0.5, 0.75, 0.87])
def test_near_wake_is_the_paper_from_x0_on(ct):
    x0 = float(wd.potential_core_length(K_W, RADIUS, ct, 0.0))
    x = np.array([x0, x0 * 1.01, 2.0 * x0, 20.0 * RADIUS])
    order, factor = near_wake_shape(x, K_W, RADIUS, ct, 0.0)
    np.testing.assert_array_equal(order, 2.0)
    np.testing.assert_array_equal(factor, 1.0)
    r = np.linspace(0.0, 4.0 * RADIUS, 41)
    for xk in x:
        shape = near_wake_shape(xk, K_W, RADIUS, ct, 0.0)
        np.testing.assert_array_equal(_deficit(xk, r, ct, shape), _deficit(xk, r, ct, None))
    # Continuous at x0: the order and the width factor tend to the Gaussian's from inside.
    below = near_wake_shape(x0 * (1.0 - 1e-6), K_W, RADIUS, ct, 0.0)
    assert 2.0 < below[0] < 2.0 + 1e-4
    assert abs(below[1] - 1.0) < 1e-4


@pytest.mark.parametrize("ct, yaw", [(0.5, 0.0), (0.8, 0.0), (0.87, 0.0), (0.8, 0.35)])
@pytest.mark.parametrize("fraction", [0.0, 0.3, 0.7])
def test_near_wake_carries_the_thrust(ct, yaw, fraction):
    """Inside the core the profile's momentum deficit, integrated here on a fine radial grid,
    is the rotor's thrust C_T cos^3 beta pi R^2 / 2 (per rho U^2), with the centre at 2a."""
    x0 = float(wd.potential_core_length(K_W, RADIUS, ct, yaw))
    x = max(fraction * x0, 1e-3)
    order, factor = near_wake_shape(x, K_W, RADIUS, ct, yaw)
    assert order > 2.0
    # The un-curled, yawed width is elliptical; the momentum closure takes the paper's
    # sigma_tilde, the geometric mean of the two axes: integrate the round profile of that width.
    sigma = math.sqrt(float(wd.sigma_tilde_squared(x, K_W, RADIUS, ct, yaw)))
    centre = 2.0 * float(wd.axial_induction(ct, yaw))
    r = np.linspace(0.0, 12.0 * sigma, 200_001)
    profile = centre * np.exp(-(r**2 / (2.0 * (factor * sigma) ** 2)) ** (0.5 * order))
    momentum = np.trapezoid(profile * (1.0 - profile) * 2.0 * np.pi * r, r)
    thrust = ct * math.cos(yaw) ** 3 * math.pi * RADIUS**2 / 2.0
    assert momentum == pytest.approx(thrust, rel=1e-6)
    # The centre is the paper's potential-core deficit.
    assert float(_deficit(x, np.zeros(1), ct, (order, factor), yaw)[0]) == pytest.approx(centre)


def test_order_is_blondel_and_cathelains_closure_by_hand():
    """At the solved order, Blondel & Cathelain's printed C(n, sigma_tilde) is 2a."""
    ct, x = 0.8, 100.0
    width_squared = float(wd.sigma_tilde_squared(x, K_W, RADIUS, ct, 0.0)) / (2 * RADIUS) ** 2
    a = float(wd.axial_induction(ct, 0.0))
    n = float(super_gaussian_order(2.0 * a, ct, width_squared))
    printed = 2 ** (2 / n - 1) - math.sqrt(
        2 ** (4 / n - 2) - n * ct / (16.0 * math.gamma(2 / n) * width_squared ** (2 / n)))
    assert printed == pytest.approx(2.0 * a, rel=1e-12)
    # At n = 2 the same formula is Bastankhah & Porte-Agel's (2014) C, Eq. (Cx) beyond x0.
    x_far = 3.0 * float(wd.potential_core_length(K_W, RADIUS, ct, 0.0))
    s2 = float(wd.sigma_tilde_squared(x_far, K_W, RADIUS, ct, 0.0)) / (2 * RADIUS) ** 2
    gaussian = 1.0 - math.sqrt(1.0 - 2 * ct / (16.0 * math.gamma(1.0) * s2))
    assert gaussian == pytest.approx(float(wd.max_deficit(x_far, K_W, RADIUS, ct, 0.0)), rel=1e-12)


def test_near_wake_is_flatter_and_deeper_across_the_rotor():
    """Towards the rotor the order rises and the profile flattens: at the rotor's edge the wake
    is deeper than the paper's Gaussian, at the centre the same (2a)."""
    ct = 0.8
    x = np.array([1.0, 100.0, 200.0, 300.0, 400.0])
    order, factor = near_wake_shape(x, K_W, RADIUS, ct, 0.0)
    assert np.all(np.diff(order) < 0.0) and np.all(np.diff(factor) < 0.0)
    assert 3.0 < order[0] < 5.5  # Blondel & Cathelain's calibrated n(0): 5.5
    edge = np.array([RADIUS])
    for k, xk in enumerate(x):
        assert _deficit(xk, edge, ct, (order[k], factor[k]))[0] > _deficit(xk, edge, ct, None)[0]


def test_compiled_order_is_the_bisection_root():
    """The rotor cells' compiled order (wake/fused.py super_gaussian_order, Newton kept in the
    bracket) is the numpy bisection's root to float64 resolution, across loadings, centre
    deficits on both sides of 1/2 (the two brackets) and widths, and 2 where the Gaussian
    already carries the thrust."""
    from floris_ekman_veer.wake.fused import super_gaussian_order as compiled_order

    rng = np.random.default_rng(11)
    centre = rng.uniform(0.2, 0.7, 2000)
    loading = rng.uniform(0.3, 0.95, 2000)
    width_squared = rng.uniform(0.002, 0.3, 2000)
    bisection = super_gaussian_order(centre, loading, width_squared)
    newton = np.array([compiled_order(*point) for point in zip(centre, loading, width_squared)])
    shaped = bisection != 2.0
    assert 500 < np.count_nonzero(shaped) < 1900 and np.any(centre[shaped] > 0.5)
    np.testing.assert_array_equal(newton[~shaped], 2.0)
    np.testing.assert_allclose(newton, bisection, rtol=4e-15, atol=0.0)


@pytest.mark.parametrize("near_wake", ["super_gaussian", "potential_core"])
@pytest.mark.parametrize("polar_angle_centre", ["wake_centre", "yaw_centre"])
def test_compiled_wake_table_equals_the_model_methods(near_wake, polar_angle_centre):
    """M-1's compiled table for the rotor cells (wake/fused.py wake_table: C(x), x0, the
    near wake's order and width factor, the kernel's factors, the width bound, in one pass)
    equals the model's numpy methods (kernel_table, width_bound, amplitude_bound,
    centre_deficit: EkmanWakeModel.wake_table) inside and beyond the potential core, yawed
    both ways, with and without the curl."""
    from floris_ekman_veer.plugin.wake_models.models import (
        EkmanVeerVelocityDeficit,
        EkmanWakeModel,
    )

    rng = np.random.default_rng(3)
    pairs = 400
    x = rng.uniform(0.2, 40.0, pairs) * RADIUS
    k_w = rng.uniform(0.01, 0.08, pairs)
    ct = rng.uniform(0.1, 0.95, pairs)
    yaw = rng.uniform(-0.5, 0.5, pairs)
    friction_velocity = rng.uniform(0.1, 0.6, pairs)
    hub_speed = rng.uniform(4.0, 14.0, pairs)
    for curl in (True, False):
        model = EkmanVeerVelocityDeficit(near_wake=near_wake, curl=curl,
                                         polar_angle_centre=polar_angle_centre)
        arguments = (x, k_w, np.full(pairs, RADIUS), ct, yaw, friction_velocity, hub_speed)
        compiled = model.wake_table(*arguments)
        readable = EkmanWakeModel.wake_table(model, *arguments)
        inside = x < wd.potential_core_length(k_w, RADIUS, ct, yaw)
        assert 20 < np.count_nonzero(inside) < pairs - 20
        assert (near_wake == "potential_core") == np.all(compiled[:, 6] == 2.0)
        np.testing.assert_allclose(compiled, readable, rtol=1e-13, atol=0.0)


def test_wake_table_by_wake_and_its_reach_bound():
    """The compiled table evaluates a wake's own factors once for its run of pairs: rows of
    pairs that share a wake (as the rotor cells hand them, wake by wake) equal the rows of the
    same pairs alone, bit for bit. With ``bound_only`` a near-wake pair's order is left for
    later (shape DEFERRED_ORDER) and its width bound is at least the exact one, whatever the
    order (the rotors it keeps get their exact table, plugin/rotor/rotor.py); the other
    columns of the other pairs are the exact table's."""
    from floris_ekman_veer.wake.fused import DEFERRED_ORDER, WAKE_TABLE, wake_table

    rng = np.random.default_rng(5)
    wakes, per_wake = 40, 25
    by_wake = lambda a: np.repeat(a, per_wake)  # noqa: E731
    x = rng.uniform(0.2, 40.0, wakes * per_wake) * RADIUS
    arguments = (x, by_wake(rng.uniform(0.01, 0.08, wakes)), np.full(x.size, RADIUS),
                 by_wake(rng.uniform(0.1, 0.95, wakes)), by_wake(rng.uniform(-0.5, 0.5, wakes)),
                 by_wake(rng.uniform(0.1, 0.6, wakes)), by_wake(rng.uniform(4.0, 14.0, wakes)))
    exact = wake_table(*arguments)
    alone = np.concatenate([wake_table(*(a[[p]] for a in arguments)) for p in range(x.size)])
    np.testing.assert_array_equal(exact, alone)

    bound = wake_table(*arguments, bound_only=True)
    shape, width = WAKE_TABLE.index("shape"), WAKE_TABLE.index("width_bound")
    deferred = bound[:, shape] == DEFERRED_ORDER
    inside = x < wd.potential_core_length(arguments[1], RADIUS, arguments[3], arguments[4])
    np.testing.assert_array_equal(deferred, inside)
    assert 50 < np.count_nonzero(deferred) < x.size - 50
    assert np.all(bound[deferred, width] >= exact[deferred, width])
    np.testing.assert_array_equal(bound[~deferred], exact[~deferred])
    for column in ("amplitude_bound", "centre_deficit"):
        k = WAKE_TABLE.index(column)
        np.testing.assert_array_equal(bound[:, k], exact[:, k])
