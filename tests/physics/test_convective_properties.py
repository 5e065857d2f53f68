"""Properties of the convective atmosphere over the ranges users meet (hypothesis; the CI and
hand-run profiles of tests/conftest.py): every state the model accepts lies inside the physical
domain, refusals say why; the convective layer meets the CNBL as 1/L -> 0; the reference wind is
met within the tolerance or said to be missed; a condition solves to the same bits alone as in a
batch (docs/atmosphere.md#physical-domain, #reference-wind-solve)."""

from __future__ import annotations

import re
import warnings

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from floris_ekman_veer import EkmanABL, ReferenceWindWarning
from floris_ekman_veer.atmosphere.physical_domain import PHYSICAL_DOMAIN, physical_domain

# The convective domain: Obukhov length -1e5 ... -1 m (log-uniform), mixed-layer depth 100 m to
# 5 km or the default (the neutral height), 2-30 m/s at 20-200 m, |latitude| 5-80 deg either
# hemisphere, z0 1e-4 to 1 m.
lengths = st.floats(0.0, 5.0).map(lambda e: -(10.0 ** e))
depths = st.none() | st.floats(100.0, 5000.0)
speeds = st.floats(2.0, 30.0)
heights = st.floats(20.0, 200.0)
latitudes = st.floats(5.0, 80.0) | st.floats(-80.0, -5.0)
roughness = st.floats(-4.0, 0.0).map(lambda e: 10.0 ** e)

REFUSED = re.compile(
    r"(leaves? the physical domain.*(sensible heat flux H|geostrophic wind G|cross-isobaric "
    r"angle alpha_0).* is \S+ (W/m\^2|m/s|deg), outside \S+ to \S+ |no ABL has a wind speed)")

#: Two fixed conditions solved beside the drawn one (batch independence).
OTHERS = dict(speed=np.array([6.0, 14.0]), height=np.array([90.0, 120.0]),
              obukhov_length=np.array([-200.0, -1e4]), latitude=np.array([45.0, -30.0]),
              roughness_length=np.array([0.05, 0.3]))


def solve(speed, height, length, z_i, latitude, z0):
    extra = {} if z_i is None else dict(mixed_layer_height=z_i)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ReferenceWindWarning)
        abl = EkmanABL.from_reference_wind(speed, height, obukhov_length=length, latitude=latitude,
                                           roughness_length=z0, **extra)
    return abl, [w for w in caught if issubclass(w.category, ReferenceWindWarning)]


@given(speed=speeds, height=heights, length=lengths, z_i=depths, latitude=latitudes, z0=roughness)
def test_accepted_convective_states_are_physical_met_and_batch_independent(
        speed, height, length, z_i, latitude, z0):
    try:
        abl, told = solve(speed, height, length, z_i, latitude, z0)
    except ValueError as refusal:
        assert REFUSED.search(str(refusal)), str(refusal)
        return
    # inside the physical domain, checked independently of physical_domain's own arithmetic
    h_flux = float(abl.sensible_heat_flux)
    low, high, _ = PHYSICAL_DOMAIN["sensible_heat_flux"]
    assert low <= h_flux <= high
    assert 0.0 < float(abl.geostrophic_wind) <= PHYSICAL_DOMAIN["geostrophic_wind"][1]
    assert abs(float(abl.cross_isobaric_angle)) <= PHYSICAL_DOMAIN["cross_isobaric_angle"][1]
    assert float(abl.stability_parameter) < 0 and h_flux > 0
    assert bool(abl.physical_domain().inside)
    if z_i is not None:
        assert float(abl.boundary_layer_height) == z_i
    # the reference wind within the tolerance, or said
    residual = abs(np.log(float(abl.speed(height)) / speed))
    assert residual == float(abl.reference_wind_residual) or np.isclose(
        residual, float(abl.reference_wind_residual), rtol=1e-6, atol=1e-15)
    assert residual <= 1e-13 or (told and float(abl.reference_wind_residual) > 1e-13)
    # the same bits in a batch
    extra = {} if z_i is None else dict(mixed_layer_height=np.array([z_i, 1500.0, 2000.0]))
    batch, _ = solve(np.r_[speed, OTHERS["speed"]], np.r_[height, OTHERS["height"]],
                     np.r_[length, OTHERS["obukhov_length"]], None, np.r_[latitude, OTHERS["latitude"]],
                     np.r_[z0, OTHERS["roughness_length"]]) if z_i is None else (
        EkmanABL.from_reference_wind(
            np.r_[speed, OTHERS["speed"]], np.r_[height, OTHERS["height"]],
            obukhov_length=np.r_[length, OTHERS["obukhov_length"]],
            latitude=np.r_[latitude, OTHERS["latitude"]],
            roughness_length=np.r_[z0, OTHERS["roughness_length"]], **extra), None)
    for name in ("friction_velocity", "geostrophic_wind", "boundary_layer_height",
                 "stability_parameter", "cross_isobaric_angle", "convective_variance"):
        assert getattr(batch, name)[0] == float(getattr(abl, name)), name
    z = np.array([10.0, 90.0, 150.0])
    np.testing.assert_array_equal(batch.speed(z[:, None])[:, 0], abl.speed(z))


@given(speed=speeds, height=heights, latitude=latitudes, z0=roughness)
def test_the_convective_layer_meets_the_cnbl_as_one_over_l_vanishes(speed, height, latitude, z0):
    """With the default z_i, L = -1e7 m differs from the CNBL by less than 1e-4 relative in u*,
    h, G and the speed over the rotor (the difference falls like 1/|L|: 5e-4 at -1e5 m at 8 m/s
    and 45 deg, more where f is small), and by a hundredth of that at L = -1e9 m."""
    try:
        neutral, _ = solve(speed, height, np.inf, None, latitude, z0)
    except ValueError:
        assume(False)
    z = np.array([30.0, 90.0, 150.0])
    gaps = []
    for length in (-1e7, -1e9):
        near, _ = solve(speed, height, length, None, latitude, z0)
        gap = max(abs(float(getattr(near, name)) / float(getattr(neutral, name)) - 1.0)
                  for name in ("friction_velocity", "boundary_layer_height", "geostrophic_wind"))
        gaps.append(max(gap, float(np.max(np.abs(near.speed(z) / neutral.speed(z) - 1.0)))))
    assert gaps[0] < 1e-4
    assert gaps[1] < 1.1e-2 * gaps[0] + 1e-12  # like 1/|L|


def test_physical_domain_agrees_with_the_refusals_on_a_grid():
    """On a grid of convective inputs the constructor refuses exactly the states physical_domain
    marks outside (checked on the same states, solved without raising by a wider model)."""
    g = np.array([4.0, 8.0, 16.0, 30.0])
    length = np.array([-5.0, -50.0, -500.0])[:, None]
    inputs = dict(latitude=45.0, roughness_length=0.1, obukhov_length=length)
    accepted = np.zeros((3, 4), dtype=bool)
    for i in range(3):
        for j in range(4):
            try:
                EkmanABL(geostrophic_wind=g[j], **{**inputs, "obukhov_length": length[i, 0]})
                accepted[i, j] = True
            except ValueError as refusal:
                assert "physical domain" in str(refusal)
    marks = []
    for i in range(3):
        for j in range(4):
            abl = EkmanABL.solved_at(
                np.log(_u_star(g[j], length[i, 0])), g[j], **{**inputs, "obukhov_length": length[i, 0]})
            marks.append(bool(physical_domain(abl.sensible_heat_flux, abl.geostrophic_wind,
                                              abl.cross_isobaric_angle, abl.stability_parameter).inside))
    np.testing.assert_array_equal(accepted.ravel(), marks)
    assert accepted.any() and not accepted.all()


def _u_star(g, length):
    """u* of the drag law at G for the Obukhov length, by bisection in ln u* on the residual of
    |(U_g, V_g)| = G (the state is explicit in u*), independent of the package's solver."""
    lo, hi = np.log(1e-3 * g), np.log(0.2 * g)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        abl = EkmanABL.solved_at(mid, g, latitude=45.0, roughness_length=0.1, obukhov_length=length)
        u_g, v_g = abl.geostrophic_components
        if u_g > 0 and np.hypot(u_g, v_g) < g:
            lo = mid
        else:
            hi = mid
    return np.exp(0.5 * (lo + hi))
