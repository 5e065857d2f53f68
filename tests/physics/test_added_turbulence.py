"""Ishihara & Qian's (2018) wake-added turbulence (wake/added_turbulence.py,
docs/coupling.md#wakes-deep-in-an-array): values by hand from the published constants, its
limits and symmetries."""

from __future__ import annotations

import math

import numpy as np
import pytest

from floris_ekman_veer.wake.added_turbulence import ishihara_qian_added_turbulence

D, H = 126.0, 90.0


def _decay(x_d, ct, ia):
    """1 / (d + e x/D + f (1 + x/D)^-2) with the published d, e, f, written out by hand."""
    d = 2.3 * ct ** (-1.2)
    e = 1.0 * ia**0.1
    f = 0.7 * ct ** (-3.2) * ia ** (-0.45)
    return 1.0 / (d + e * x_d + f / (1.0 + x_d) ** 2)


def _width(x_d, ct, ia):
    return 0.11 * ct**1.07 * ia**0.2 * x_d + 0.23 * ct ** (-0.25) * ia**0.17


@pytest.mark.parametrize("x_d, ct, ia", [(3.3, 0.8, 0.05), (7.0, 0.75, 0.08), (12.0, 0.4, 0.12)])
def test_values_by_hand(x_d, ct, ia):
    """At the rotor's edge r = D/2 at hub height, k1 = 1, k2 = cos^2(pi/2) = 0 and the ring's
    Gaussian is 1: Delta I = 1 / (d + e x/D + f (1 + x/D)^-2). On the axis k1 = k2 = 1/2 and
    both Gaussians are exp(-(1/2)^2 / (2 sigma~^2)). Beyond the edge k1 = 1, k2 = 0."""
    iq = lambda r, z=H: ishihara_qian_added_turbulence(x_d * D, r, z, ct, ia, D, H)  # noqa: E731
    assert iq(0.5 * D) == pytest.approx(_decay(x_d, ct, ia), rel=1e-14)
    w = _width(x_d, ct, ia)
    assert iq(0.0) == pytest.approx(math.exp(-0.125 / w**2) * _decay(x_d, ct, ia), rel=1e-14)
    assert iq(1.2 * D) == pytest.approx(math.exp(-0.49 / (2 * w**2)) * _decay(x_d, ct, ia),
                                        rel=1e-14)
    # Halfway out, r = D/4: k1 = cos^2(-pi/8), k2 = cos^2(3 pi/8), Gaussians at -1/4 and 3/4.
    by_hand = (math.cos(math.pi / 8) ** 2 * math.exp(-0.0625 / (2 * w**2))
               + math.cos(3 * math.pi / 8) ** 2 * math.exp(-0.5625 / (2 * w**2)))
    assert iq(0.25 * D) == pytest.approx(by_hand * _decay(x_d, ct, ia), rel=1e-14)


def test_ground_term_below_the_hub_only():
    """delta(z) = I_a sin^2(pi (H - z)/H) below the hub: I_a at z = H/2, 0 at and above H, and
    at z = H/4 I_a / 2; the ring part depends only on r."""
    ia = 0.08
    iq = lambda r, z: ishihara_qian_added_turbulence(5 * D, r, z, 0.8, ia, D, H)  # noqa: E731
    ring = iq(0.3 * D, H + 10.0)
    assert iq(0.3 * D, H) == ring
    assert iq(0.3 * D, 0.5 * H) == pytest.approx(ring - ia, rel=1e-13)
    assert iq(0.3 * D, 0.25 * H) == pytest.approx(ring - 0.5 * ia, rel=1e-13)


def test_ring_peaks_at_the_edge_and_fills_the_axis_downstream():
    """The tip shear layer: near the rotor the added turbulence peaks at r = D/2 and is low on
    the axis; further down the ring widens and the axis gains on the edge; it decays with x
    (monotonically beyond the near-wake term's peak) and is continuous at r = D/2."""
    r = np.linspace(0.0, 1.5 * D, 301)
    near = ishihara_qian_added_turbulence(2 * D, r, H, 0.8, 0.06, D, H)
    assert r[np.argmax(near)] == pytest.approx(0.5 * D)
    far = ishihara_qian_added_turbulence(12 * D, r, H, 0.8, 0.06, D, H)
    assert far[0] / far.max() > near[0] / near.max()
    edge = ishihara_qian_added_turbulence(np.array([5 * D]), 0.5 * D * (1 + np.array([-1, 1]) * 1e-9),
                                          H, 0.8, 0.06, D, H)
    assert edge[0] == pytest.approx(edge[1], rel=1e-8)
    xs = np.arange(4.0, 20.0) * D
    along = ishihara_qian_added_turbulence(xs, 0.5 * D, H, 0.8, 0.06, D, H)
    assert np.all(np.diff(along) < 0.0)


@pytest.mark.parametrize("parameters", [(0.9, 0.8, 0.1, -0.32), (0.73, 0.8325, -0.0325, -0.32),
                                        (1.2, 0.5, 0.3, -0.5)])
def test_compiled_crespo_hernandez_is_floris_s(parameters):
    """wake/added_turbulence.py's compiled Crespo-Hernandez is FLORIS's CrespoHernandez model
    (its numexpr formula and its masks around the rotor plane) bit for bit, times the overlap,
    with FLORIS's solver's factors (NaN and +inf as 0, downstream, within 2 D laterally,
    within 15 D) as FLORIS's sequential solver writes them, on random points including the
    +-0.1 m band at the rotor plane and zero induction."""
    from floris.core.wake_turbulence.crespo_hernandez import CrespoHernandez

    from floris_ekman_veer.wake.added_turbulence import crespo_hernandez_overlap

    floris = CrespoHernandez(**dict(zip(("constant", "ai", "initial", "downstream"),
                                        parameters)))
    rng = np.random.default_rng(11)
    pairs, points = 5000, 9
    x_source = rng.uniform(-500.0, 500.0, (pairs, 1))
    x = x_source + rng.uniform(-300.0, 3000.0, (pairs, points))
    x[:200] = x_source[:200] + rng.uniform(-0.2, 0.2, (200, points))
    y_source = rng.uniform(-500.0, 500.0, (pairs, 1))
    y = y_source + rng.uniform(-400.0, 400.0, (pairs, points))
    diameter = rng.uniform(50.0, 200.0, (pairs, 1))
    ambient = rng.uniform(0.01, 0.3, (pairs, 1))
    induction = rng.uniform(0.0, 0.5, (pairs, 1))
    induction[:50] = 0.0
    overlap = rng.uniform(0.0, 1.0, (pairs, 1))
    reference = floris.function(ambient, x, x_source, diameter, induction)
    alone = crespo_hernandez_overlap(ambient, x, x_source, diameter, induction,
                                     np.ones((pairs, 1)), parameters)
    in_reach = (x > x_source) & (x <= 15 * diameter + x_source)
    np.testing.assert_array_equal(alone, reference * in_reach)
    solver = (overlap * np.nan_to_num(reference, posinf=0.0) * (x > x_source)
              * (np.abs(y_source - y) < 2 * diameter) * (x <= 15 * diameter + x_source))
    compiled = crespo_hernandez_overlap(ambient, x, x_source, diameter, induction, overlap,
                                        parameters, y, y_source)
    np.testing.assert_array_equal(compiled, solver)
    assert 0.2 < np.mean(compiled > 0.0) < 0.8
