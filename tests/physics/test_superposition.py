"""Zong & Porte-Agel's (2020) momentum-conserving superposition (wake/superposition.py,
plugin/rotor/convection.py, docs/coupling.md#wakes-deep-in-an-array): the closed-form plane
integrals, one wake unchanged, two equal wakes by hand, and the combined wake's convection
velocity against an independent quadrature of its definition."""

from __future__ import annotations

import math

import numpy as np
import pytest

from floris_ekman_veer.plugin.rotor.convection import WakeConvection
from floris_ekman_veer.wake.superposition import (
    convection_velocity,
    gaussian_product_integral,
    wake_convection_velocity,
)


def test_gaussian_product_integral_by_quadrature():
    """int g_a g_b dA of two Gaussians d apart against a plane quadrature; pi sigma^2 alone."""
    assert gaussian_product_integral(4.0, 4.0, 0.0) == pytest.approx(4.0 * math.pi, rel=1e-15)
    y, z = np.meshgrid(np.linspace(-40, 40, 1601), np.linspace(-40, 40, 1601))
    a = np.exp(-(y**2 + z**2) / (2 * 9.0))
    b = np.exp(-((y - 3.0) ** 2 + (z + 1.0) ** 2) / (2 * 16.0))
    quadrature = np.sum(a * b) * 0.05**2
    assert gaussian_product_integral(9.0, 16.0, 10.0) == pytest.approx(quadrature, rel=1e-9)


def _state(*wakes, ambient=8.0):
    state = WakeConvection.start(1, 4)
    velocity = None
    for incoming, centre_deficit, sigma, y in wakes:
        u_c = wake_convection_velocity(incoming, centre_deficit)
        velocity = state.add(np.array([0]), np.array([u_c * centre_deficit]),
                             np.array([sigma**2]), np.array([y]), np.array([90.0]),
                             np.array([ambient]))
    return velocity[0]


def test_one_wake_keeps_weight_one():
    """Behind an unwaked rotor (U_in = U_0) the combined wake is the wake: U_c = U_c,1 =
    U_0 - u_c/2, its weight 1."""
    assert _state((8.0, 2.0, 50.0, 0.0)) == pytest.approx(7.0, rel=1e-15)
    assert _state((8.0, 0.5, 80.0, 10.0)) == pytest.approx(7.75, rel=1e-15)


def test_two_equal_wakes_by_hand():
    """Two equal co-located wakes (U_0 = U_in = 8, u_c = 2: U_c,i = 7): Q = s = 14,
    U_c = (8 + sqrt(64 - 56)) / 2 = 4 + sqrt(2), so each weighs 7 / (4 + sqrt(2)) = 1.293 and
    the centre deficit is 5.17 m/s, more than the linear sum's 4 (the combined wake convects
    slower than either). Far apart they do not interact: U_c stays 7, both weigh 1."""
    assert _state((8.0, 2.0, 50.0, 0.0), (8.0, 2.0, 50.0, 0.0)) == pytest.approx(
        4.0 + math.sqrt(2.0), rel=1e-14)
    assert _state((8.0, 2.0, 50.0, 0.0), (8.0, 2.0, 50.0, 5000.0)) == pytest.approx(7.0,
                                                                                   rel=1e-14)
    assert convection_velocity(8.0, 17.0) == 4.0  # no real root: the limit U_0 / 2


def test_convection_velocity_is_its_definition():
    """U_c is the combined wake's int U (U_0 - U) dA / int (U_0 - U) dA with U_0 - U =
    sum_i (U_c,i / U_c) u_i: three offset wakes of different depths and widths, one behind a
    waked rotor, against a plane quadrature (the fixed point Zong & Porte-Agel iterate to)."""
    wakes = ((8.0, 2.0, 50.0, 0.0), (6.5, 1.5, 60.0, 40.0), (8.0, 1.0, 45.0, -70.0))
    u_c = _state(*wakes)
    y, z = np.meshgrid(np.linspace(-500, 500, 1001), np.linspace(-500, 500, 1001))
    deficit = sum(wake_convection_velocity(incoming, c) / u_c * c
                  * np.exp(-((y - centre) ** 2 + z**2) / (2 * sigma**2))
                  for incoming, c, sigma, centre in wakes)
    by_definition = np.sum((8.0 - deficit) * deficit) / np.sum(deficit)
    assert u_c == pytest.approx(by_definition, rel=1e-10)


def test_cumulative_wake_by_hand():
    """Bastankhah et al. (2021, Eqs. 4.9-4.10) with the model's momentum term K = 1 - (1 - C)^2:
    alone (no upstream wake, U_n = U_0) the wake is the model's, C_n = U_0 C; behind a
    co-located upstream wake of the same width (lambda = 2 sigma^2 / (2 sigma^2) = 1) with
    C_1 = 2.4 m/s, U_0 = 8, U_n = 6, C = 0.3: a = 5.6, K = 0.51,
    C_2 = 5.6 - sqrt(31.36 - 18.36) = 1.9945 m/s; no real root gives the core's 2a U_n."""
    from floris_ekman_veer.wake.superposition import cumulative_deficit, overlap_weight

    assert cumulative_deficit(0.3, 8.0, 8.0, 0.0, 5.0) == pytest.approx(2.4, rel=1e-14)
    assert overlap_weight(2500.0, 2500.0, 0.0) == 1.0
    assert overlap_weight(2500.0, 900.0, 40.0**2) == pytest.approx(
        2 * 900.0 / 3400.0 * math.exp(-1600.0 / 6800.0), rel=1e-15)
    assert cumulative_deficit(0.3, 8.0, 6.0, 2.4, 5.0) == pytest.approx(
        5.6 - math.sqrt(13.0), rel=1e-14)
    assert cumulative_deficit(0.3, 8.0, 6.0, 6.0, 2.9) == 2.9  # a^2 < K U_n^2
    assert cumulative_deficit(0.6, 8.0, 8.0, 0.0, 4.0) == 4.0  # beyond the core's 2a U_n
