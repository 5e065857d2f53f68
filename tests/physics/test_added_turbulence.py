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
