"""The cumulative wake's sparse store of upstream wakes (plugin/rotor/upstream_wakes.py) against
a dense numpy reference of Bastankhah et al.'s (2021) Eqs. 4.9-4.10 (wake/superposition.py's
``overlap_weight`` and ``cumulative_deficit`` over every rotor's wakes in order of arrival, at
each of the grid's point heights, then interpolated to the rows as the centre is);
its exp against numpy's; its memory on a farm against the dense tables it replaced."""

from __future__ import annotations

import tracemalloc
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from benchmarks import bench_models
from floris_ekman_veer.plugin.rotor.rotor_cells import grid_offsets, row_interpolation, rotor_cells
from floris_ekman_veer.plugin.rotor.upstream_wakes import (
    BLOCK,
    GROWTH,
    UpstreamWakes,
    overlap_exp,
)
from floris_ekman_veer.wake.superposition import (
    OVERLAP_EXPONENT_LIMIT,
    cumulative_deficit,
    overlap_weight,
)

CELLS = rotor_cells(3, 24, 2)


class DenseReference:
    """Every rotor's kept wakes as numpy rows, in order of arrival, per grid-point height (the
    upstream sum over them in order at each height, then Eq. 4.10, then the rows'
    interpolation), written independently of the store."""

    def __init__(self, rotors, cells):
        self.kept = [[] for _ in range(rotors)]
        self.interpolation = row_interpolation(cells.n, cells.row_z)

    def deficits(self, rotor, width_squared, lateral, offsets, height, single, ambient,
                 incoming, core):
        centre_y = lateral[:, None] + offsets  # (k, n): the centres at the grid's heights
        upstream = np.zeros(centre_y.shape)
        for k, j in enumerate(rotor):
            for c, w, y, z in self.kept[j]:
                upstream[k] += overlap_weight(width_squared[k], w,
                                              (y - centre_y[k]) ** 2 + (z - height[k]) ** 2) * c
        points = cumulative_deficit(single[:, None], ambient[:, None], incoming[:, None],
                                    upstream, core[:, None])
        return points, np.sum(points[:, :, None] * self.interpolation, axis=1)

    def keep(self, rotor, deficit, width_squared, lateral, offsets, height):
        for k, j in enumerate(rotor):
            self.kept[j].append((deficit[k], width_squared[k], lateral[k] + offsets[k],
                                 height[k]))

    def release(self, rotor):
        for j in rotor:
            self.kept[j] = []


def _wakes(rng, rotor, diameter=126.0):
    """Random wakes at ``rotor``: widths 0.2-0.8 D, centres within 2 D of the rotors' (veer
    offsets up to 0.5 D at the grid's heights), hub heights 80-100 m, C(x) 0.05-0.5."""
    k = rotor.size
    width_squared = (diameter * rng.uniform(0.2, 0.8, k)) ** 2
    lateral = diameter * rng.uniform(-2.0, 2.0, k)
    offsets = diameter * rng.uniform(-0.5, 0.5, (k, CELLS.n))
    height = rng.uniform(80.0, 100.0, k)
    single = rng.uniform(0.05, 0.5, k)
    ambient = rng.uniform(6.0, 12.0, k)
    incoming = ambient * rng.uniform(0.6, 1.0, k)
    core = rng.uniform(0.5, 1.0, k) * incoming
    return width_squared, lateral, offsets, height, single, ambient, incoming, core


@given(seed=st.integers(0, 2**32 - 1), rotors=st.integers(1, 40),
       steps=st.integers(1, 30))
def test_store_matches_the_dense_reference(seed, rotors, steps):
    """Random arrivals (each step a random set of rotors, in random order, each once), random
    releases, a pool that starts with room for one block and grows: every step's C_n at every
    grid-point height and every row equals the dense reference's to 1e-12 relative; the entries and blocks in use are those
    the reference holds, and freed blocks are taken again before the pool grows."""
    rng = np.random.default_rng(seed)
    store = UpstreamWakes.start(rotors, CELLS, capacity=1)
    reference = DenseReference(rotors, CELLS)
    most = 0
    for _ in range(steps):
        rotor = rng.permutation(rotors)[: rng.integers(1, rotors + 1)]
        wakes = _wakes(rng, rotor)
        expected = reference.deficits(rotor, *wakes)
        got, got_rows = store.deficits(rotor, *wakes)
        np.testing.assert_allclose(got, expected[0], rtol=1e-12, atol=0.0)
        np.testing.assert_allclose(got_rows, expected[1], rtol=1e-12, atol=0.0)
        kept = rng.random(rotor.size) < 0.8  # the rotors the kernel reached
        keep_args = (rotor[kept], got[kept], *(w[kept] for w in wakes[:4]))
        reference.keep(*keep_args)
        in_use = store.in_use
        store.keep(*keep_args)
        assert store.in_use == in_use + np.count_nonzero(kept)
        blocks = sum(-(-len(k) // BLOCK) for k in reference.kept)
        assert store.blocks_in_use == blocks
        most = max(most, blocks)
        # Freed blocks are taken again before the pool grows.
        assert store.capacity <= BLOCK * max(GROWTH * most + 1, 1)
        released = rng.permutation(rotors)[: rng.integers(0, 3)]
        reference.release(released)
        store.release(released)
        assert store.in_use == sum(len(k) for k in reference.kept)
        np.testing.assert_array_equal(store.count, [len(k) for k in reference.kept])


def test_wakes_at_the_overlap_limit():
    """Kept wakes whose centres lie just inside and just outside lambda's limit
    (exponent OVERLAP_EXPONENT_LIMIT) at some grid heights, and a centre line that crosses the
    new wake's between two grid heights: the store's sum skips only what the reference sets to
    0."""
    rotor = np.array([0])
    width_squared = np.array([50.0**2])
    limit = np.sqrt(2.0 * OVERLAP_EXPONENT_LIMIT * 2.0 * 50.0**2)  # equal widths: total 2 s^2
    store = UpstreamWakes.start(1, CELLS)
    reference = DenseReference(1, CELLS)
    for lateral, offsets in ((limit * (1.0 - 1e-9), [0.0, 0.0, 0.0]),
                             (limit * (1.0 + 1e-9), [0.0, 0.0, 0.0]),
                             (limit, [-40.0, 0.0, 40.0]),
                             (0.0, [-2.0 * limit, 0.0, 2.0 * limit])):
        wake = (width_squared, np.array([lateral]), np.array([offsets]), np.array([90.0]),
                np.array([0.3]), np.array([9.0]), np.array([8.0]), np.array([6.0]))
        expected = reference.deficits(rotor, *wake)
        got, got_rows = store.deficits(rotor, *wake)
        np.testing.assert_allclose(got, expected[0], rtol=1e-12, atol=0.0)
        np.testing.assert_allclose(got_rows, expected[1], rtol=1e-12, atol=0.0)
        reference.keep(rotor, got, *wake[:4])
        store.keep(rotor, got, *wake[:4])
    # A new wake on the first centre line reaches all four: each sum differs from the next.
    wake = (width_squared, np.array([0.0]), np.zeros((1, 3)), np.array([90.0]),
            np.array([0.3]), np.array([9.0]), np.array([8.0]), np.array([6.0]))
    for got, expected in zip(store.deficits(rotor, *wake), reference.deficits(rotor, *wake)):
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0.0)


def test_lone_wake_is_the_model_and_a_wake_ahead_deepens_it():
    """Without kept wakes and U_n = U_0, C_n = U_0 C(x) (Eq. 4.10 with a = U_0, K = 1 - (1 - C)^2:
    the model's own wake); a second, co-located equal-width wake (lambda = 1) behind a rotor
    whose incoming speed is 6 m/s takes a = U_0 - C_1 = 5.6 m/s, C = 5.6 - sqrt(5.6^2 - K 6^2),
    by hand."""
    store = UpstreamWakes.start(1, CELLS)
    rotor = np.array([0])
    geometry = (np.array([2500.0]), np.array([0.0]), np.zeros((1, 3)), np.array([90.0]),
                np.array([0.3]), np.array([8.0]))
    first, first_rows = store.deficits(rotor, *geometry, np.array([8.0]), np.array([8.0]))
    np.testing.assert_allclose(first, 2.4, rtol=1e-14)
    np.testing.assert_allclose(first_rows, 2.4, rtol=1e-14)
    store.keep(rotor, first, *geometry[:4])
    second, _ = store.deficits(rotor, *geometry, np.array([6.0]), np.array([8.0]))
    np.testing.assert_allclose(second, 5.6 - np.sqrt(5.6**2 - (1.0 - 0.7**2) * 36.0),
                               rtol=1e-14)


def test_the_rows_take_c_n_exactly_at_the_grid_heights_and_linearly_between():
    """C_n handed to rows on the grid's point heights is C_n there, bit for bit; at rows between
    two heights it is their linear interpolation, and beyond the outer heights the outer value
    (as the wake centre's, rotor_cells.row_interpolation)."""
    heights = grid_offsets(CELLS.n)
    between = np.array([-0.25, 0.125, 0.4])
    outer = np.array([-0.9, 0.8])
    cells = SimpleNamespace(n=CELLS.n, row_z=np.concatenate([heights, between, outer]))
    store = UpstreamWakes.start(1, cells)
    rotor = np.array([0])
    rng = np.random.default_rng(7)
    for _ in range(4):  # wakes with veer-sheared centres, each reaching the rotor
        wake = _wakes(rng, rotor)
        wake[1][:] = 0.0
        wake[4][:] = 0.1  # (shallow wakes: below the potential core's bound)
        wake[7][:] = wake[6]
        points, rows = store.deficits(rotor, *wake)
        np.testing.assert_array_equal(rows[:, :heights.size], points)
        np.testing.assert_allclose(
            rows[0, heights.size:heights.size + between.size],
            np.interp(between, heights, points[0]), rtol=1e-14)
        np.testing.assert_array_equal(rows[0, -outer.size:], points[0, [0, -1]])
        store.keep(rotor, points, *wake[:4])
    assert np.ptp(points) > 0.0  # the heights' values differ (the test is about them)


def testoverlap_exp_is_numpys_to_round_off():
    """The table exp on [-OVERLAP_EXPONENT_LIMIT, 0] within 2 units in the last place of numpy's."""
    x = np.concatenate([np.linspace(-OVERLAP_EXPONENT_LIMIT, 0.0, 20001),
                        -np.geomspace(1e-12, 1.0, 101)])
    got = np.array([overlap_exp(v) for v in x])
    np.testing.assert_allclose(got, np.exp(x), rtol=4.5e-16, atol=0.0)


def test_farm_memory_is_far_below_the_dense_tables():
    """10 x 10 NREL 5 MW x 20 yawed conditions (benchmarks/bench_peers.py's farm): the run's peak
    traced memory is a fraction of what the dense tables alone took (4 tables of conditions x
    turbines x turbines x rows float64: 154 MB), and no more than 3 x the summed wake's."""
    directions, speeds, yaw = bench_models.conditions(20, 1, 10)
    peaks = {}
    for superposition in ("cumulative", "combination_model"):
        config = bench_models.configuration("M-1", 10)
        config["wake"]["wake_velocity_parameters"]["ekman_veer"][
            "wake_superposition"] = superposition
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the SBL-6 night's shallow-layer summary
            from floris import FlorisModel

            fmodel = FlorisModel(config)
            fmodel.set(wind_directions=directions, wind_speeds=speeds,
                       turbulence_intensities=np.full(20, 0.06), yaw_angles=yaw)
            fmodel.run()  # compiled and cached before the measured run
            peaks[superposition] = bench_models.peak_memory(fmodel)
    dense = 4 * 20 * 100 * 100 * CELLS.rows * 8 / 1e6
    assert peaks["cumulative"] < dense / 10
    assert peaks["cumulative"] < 3.0 * peaks["combination_model"]
