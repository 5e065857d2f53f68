"""The cumulative wake's sparse store of upstream wakes (plugin/rotor/upstream_wakes.py) against
a dense numpy reference of Bastankhah et al.'s (2021) Eqs. 4.9-4.10 (wake/superposition.py's
``overlap_weight`` and ``cumulative_deficit`` over every rotor's wakes in order of arrival, at
each of the store's heights, then interpolated linearly to the rows); its exp against numpy's;
the wake centres at its heights against the kernel's at the rows; C_n on a farm the same
whatever FLORIS's grid; its memory on a farm against the dense tables it replaced."""

from __future__ import annotations

import tracemalloc
import warnings
from types import SimpleNamespace

import numba
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from benchmarks import bench_models
from floris_ekman_veer.plugin.rotor.rotor_cells import height_interpolation, rotor_cells
from floris_ekman_veer.plugin.rotor.rotor_kernel import CONDITION_COLUMNS
from floris_ekman_veer.plugin.rotor.rotor_threads import ROTOR_BLOCK
from floris_ekman_veer.plugin.rotor.upstream_wakes import (
    BLOCK,
    DEFICIT_HEIGHTS,
    GROWTH,
    UpstreamWakes,
    centres_at_heights,
)
from floris_ekman_veer.wake.fused import centre_offsets
from floris_ekman_veer.wake.superposition import (
    OVERLAP_EXPONENT_LIMIT,
    cumulative_deficit,
    overlap_weight,
)

CELLS = rotor_cells(3, 24, 2)
#: The store's heights [rotor radii from the hub].
HEIGHTS = DEFICIT_HEIGHTS.size


class DenseReference:
    """Every rotor's kept wakes as numpy rows, in order of arrival, per height of the store
    (the upstream sum over them in order at each height, then Eq. 4.10, then numpy's linear
    interpolation to the rows, constant beyond the outer heights), written independently of the
    store."""

    def __init__(self, rotors, cells):
        self.kept = [[] for _ in range(rotors)]
        self.row_z = cells.row_z

    def deficits(self, rotor, width_squared, lateral, offsets, height, single, ambient,
                 incoming, core):
        centre_y = lateral[:, None] + offsets  # (k, K): the centres at the store's heights
        upstream = np.zeros(centre_y.shape)
        for k, j in enumerate(rotor):
            for c, w, y, z in self.kept[j]:
                upstream[k] += overlap_weight(width_squared[k], w,
                                              (y - centre_y[k]) ** 2 + (z - height[k]) ** 2) * c
        points = cumulative_deficit(single[:, None], ambient[:, None], incoming[:, None],
                                    upstream, core[:, None])
        return points, np.array([np.interp(self.row_z, DEFICIT_HEIGHTS, p) for p in points])

    def keep(self, rotor, deficit, width_squared, lateral, offsets, height):
        for k, j in enumerate(rotor):
            self.kept[j].append((deficit[k], width_squared[k], lateral[k] + offsets[k],
                                 height[k]))

    def release(self, rotor):
        for j in rotor:
            self.kept[j] = []


def _wakes(rng, rotor, diameter=126.0):
    """Random wakes at ``rotor``: widths 0.2-0.8 D, centres within 2 D of the rotors' (veer
    offsets up to 0.5 D at the store's heights), hub heights 80-100 m, C(x) 0.05-0.5."""
    k = rotor.size
    width_squared = (diameter * rng.uniform(0.2, 0.8, k)) ** 2
    lateral = diameter * rng.uniform(-2.0, 2.0, k)
    offsets = diameter * rng.uniform(-0.5, 0.5, (k, HEIGHTS))
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
    height of the store and every row equals the dense reference's to 1e-12 relative (also with
    a strip cut by a layer top: its parts at their mid-heights); the entries and blocks in use are those
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
        # A strip cut by a layer top at some rotors: its row the part below, the extra slot
        # the part above, each C_n interpolated from the heights at the part's mid-height.
        cut = np.where(rng.random(rotor.size) < 0.5, rng.integers(0, CELLS.rows, rotor.size), -1)
        parts = rng.uniform(-1.0, 1.0, (rotor.size, 2))
        weights = np.moveaxis(height_interpolation(DEFICIT_HEIGHTS, parts), 0, -1)
        _, slotted = store.deficits(rotor, *wakes, cut, weights)
        expected_slots = np.concatenate([expected[1], np.zeros((rotor.size, 1))], axis=1)
        for k in np.flatnonzero(cut >= 0):
            expected_slots[k, [cut[k], CELLS.rows]] = np.interp(parts[k], DEFICIT_HEIGHTS,
                                                                 expected[0][k])
        np.testing.assert_allclose(slotted, expected_slots, rtol=1e-12, atol=1e-300)
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
    (exponent OVERLAP_EXPONENT_LIMIT) at some heights, and a centre line that crosses the
    new wake's between two heights: the store's sum skips only what the reference sets to 0."""
    rotor = np.array([0])
    width_squared = np.array([50.0**2])
    limit = np.sqrt(2.0 * OVERLAP_EXPONENT_LIMIT * 2.0 * 50.0**2)  # equal widths: total 2 s^2
    store = UpstreamWakes.start(1, CELLS)
    reference = DenseReference(1, CELLS)
    # (Veer-sheared centre lines: offsets linear in height, crossing the first line.)
    for lateral, offsets in ((limit * (1.0 - 1e-9), 0.0 * DEFICIT_HEIGHTS),
                             (limit * (1.0 + 1e-9), 0.0 * DEFICIT_HEIGHTS),
                             (limit, 40.0 * DEFICIT_HEIGHTS),
                             (0.0, 2.0 * limit * DEFICIT_HEIGHTS)):
        wake = (width_squared, np.array([lateral]), np.array([offsets]), np.array([90.0]),
                np.array([0.3]), np.array([9.0]), np.array([8.0]), np.array([6.0]))
        expected = reference.deficits(rotor, *wake)
        got, got_rows = store.deficits(rotor, *wake)
        np.testing.assert_allclose(got, expected[0], rtol=1e-12, atol=0.0)
        np.testing.assert_allclose(got_rows, expected[1], rtol=1e-12, atol=0.0)
        reference.keep(rotor, got, *wake[:4])
        store.keep(rotor, got, *wake[:4])
    # A new wake on the first centre line reaches all four: each sum differs from the next.
    wake = (width_squared, np.array([0.0]), np.zeros((1, HEIGHTS)), np.array([90.0]),
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
    geometry = (np.array([2500.0]), np.array([0.0]), np.zeros((1, HEIGHTS)), np.array([90.0]),
                np.array([0.3]), np.array([8.0]))
    first, first_rows = store.deficits(rotor, *geometry, np.array([8.0]), np.array([8.0]))
    np.testing.assert_allclose(first, 2.4, rtol=1e-14)
    np.testing.assert_allclose(first_rows, 2.4, rtol=1e-14)
    store.keep(rotor, first, *geometry[:4])
    second, _ = store.deficits(rotor, *geometry, np.array([6.0]), np.array([8.0]))
    np.testing.assert_allclose(second, 5.6 - np.sqrt(5.6**2 - (1.0 - 0.7**2) * 36.0),
                               rtol=1e-14)


def test_the_rows_take_c_n_exactly_at_the_store_heights_and_linearly_between():
    """C_n handed to rows on the store's heights is C_n there, bit for bit; at rows between
    two heights it is their linear interpolation, and beyond the outer heights (a rotor's rows
    lie within them) the outer value."""
    heights = DEFICIT_HEIGHTS
    between = np.array([-0.9, -0.3, 0.125, 0.4, 0.99])
    outer = np.array([-1.1, 1.2])
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


def _row_c_n(monkeypatch, points, rows=96):
    """The C_n [m/s] that the store hands the kernel's rows for each wake reaching a rotor that
    has one already, (rotor, rows) per wake step, on an n x n grid whose cells have ``rows``
    sub-point rows whatever n: three NREL 5 MW in the night's veer-sheared inflow
    (inputs/farm_night.yaml, 8 m/s from the west), the second 1.5 D beside the first and
    1.5 D behind it (at the edge of its wake), the third 10 D behind the first, between the
    two: the two wakes reach it shifted differently with height (the veer's x V/U grows with
    x), so they overlap at some heights and hardly at others."""
    from floris import FlorisModel
    from floris.utilities import load_yaml

    import floris_ekman_veer.plugin.inflow.ambient as ambient_module

    monkeypatch.setattr(ambient_module, "sub_quadrature", lambda n, diameter=0.0: (rows, 2))
    from floris_ekman_veer.plugin.rotor import rotor as rotor_module

    seen = []
    step = rotor_module.cumulative_step

    def spy(*args, **kwargs):
        # (a wake step's sums and kernel: the C_n at the rows of the rotors it reaches that
        # have a wake already; the step's rotors by flat index, args[4])
        store, rotor = args[7].convection, args[4]
        waked = store.count[rotor] > 0
        result = step(*args, **kwargs)
        seen.append(result[0][1][waked & result[1][2]])
        return result

    monkeypatch.setattr(rotor_module, "cumulative_step", spy)
    config = load_yaml(bench_models.REPOSITORY / "inputs" / "farm_night.yaml")
    config["farm"]["layout_x"] = [0.0, 189.0, 1260.0]
    config["farm"]["layout_y"] = [0.0, 189.0, 95.0]
    fmodel = FlorisModel(config)
    fmodel.set(solver_settings={"type": "turbine_grid", "turbine_grid_points": points},
               wind_directions=[270.0], wind_speeds=[8.0], turbulence_intensities=[0.06])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the night's shallow-layer summary
        fmodel.run()
    return [s for s in seen if s.size]


def test_c_n_on_a_farm_no_longer_depends_on_the_grid(monkeypatch):
    """The third rotor meets the second wake behind the first: its C_n varies with height (the
    two wakes' veer-sheared centres cross the rotor at different heights). On 2 x 2 and 4 x 4
    grids whose cells share one fine sub-quadrature, the C_n the rows take agrees to 5e-4
    relative (4e-5: what is left is the second rotor's incoming speed, a mean over its cells);
    with C_n at the grid's point heights, constant beyond +-R/2 (before), the two differed by
    4.5e-3 and C_n varied half as much over the rotor."""
    coarse, fine = _row_c_n(monkeypatch, 2), _row_c_n(monkeypatch, 4)
    assert len(coarse) == len(fine) == 1 and coarse[0].shape == fine[0].shape == (1, 96)
    assert np.ptp(fine[0]) > 0.04 * np.max(fine[0])  # C_n varies over the rotor
    np.testing.assert_allclose(coarse[0], fine[0], rtol=5e-4, atol=0.0)


def _centre_table(rng, n_findex, veer, image):
    """Random per-condition values of the kernel's centre columns, by name and as its table."""
    values = {"cos": rng.uniform(0.9, 1.0, n_findex), "sin": rng.uniform(-0.3, 0.3, n_findex),
              "friction_velocity": rng.uniform(0.2, 0.5, n_findex),
              "radius": rng.uniform(60.0, 80.0, n_findex),
              "hub_height": rng.uniform(80.0, 130.0, n_findex),
              "centre_strength": rng.uniform(-1.0, 1.0, n_findex),
              "centre_r_tube": rng.uniform(60.0, 90.0, n_findex),
              "centre_image_height": rng.uniform(80.0, 130.0, n_findex),
              "centre_veer": np.full(n_findex, veer),
              "centre_ground_image": np.full(n_findex, image)}
    return values, np.stack([values[name] for name in CONDITION_COLUMNS], axis=1)


def test_centres_at_the_heights_are_the_kernels_centre():
    """The wake centre at the store's heights of the rotors a wake reaches, gathered per rotor
    (its condition, its kind's heights and ambient) from the rotor-cell kernel's per-condition
    table (rotor_kernel.CONDITION_COLUMNS), is wake/fused.py's centre_offset (tested against the
    readable Eq. yc_xz in test_rotor_average.py) of each pair's own values, bit for bit: random
    conditions, two kinds of rotor, veer and ground image on and off."""
    rng = np.random.default_rng(3)
    n_findex, kinds, pairs = 4, 2, 30
    heights = np.array([[90.0], [120.0]]) + np.array([[63.0], [80.0]]) * DEFICIT_HEIGHTS
    kind_u = rng.uniform(4.0, 12.0, (n_findex, kinds, HEIGHTS))
    kind_v = rng.uniform(-2.0, 2.0, (n_findex, kinds, HEIGHTS))
    condition = rng.integers(0, n_findex, pairs)
    kind = rng.integers(0, kinds, pairs)
    x = rng.uniform(300.0, 2500.0, pairs)
    for veer, image in ((1.0, 1.0), (0.0, 1.0), (1.0, 0.0)):
        values, table = _centre_table(rng, n_findex, veer, image)
        got = centres_at_heights(x, condition, kind, heights, kind_u, kind_v, table)
        column = lambda name: values[name][condition][:, None]  # noqa: E731
        u, v = kind_u[condition, kind], kind_v[condition, kind]
        cos_a, sin_a = column("cos"), column("sin")
        expected = centre_offsets(
            x[:, None], heights[kind], u * cos_a + v * sin_a, v * cos_a - u * sin_a,
            column("centre_strength"), column("centre_r_tube"), column("centre_image_height"),
            column("radius"), column("friction_velocity"), veer, image)
        np.testing.assert_array_equal(got, expected)
        assert np.ptp(got, axis=1).min() > 1.0 or veer == 0.0  # the veer shears the centre


@pytest.mark.parametrize("threads", [1, 2])
def test_the_sums_evaluate_the_centres_as_the_centres_pass(threads):
    """Given the centres' inputs, the upstream sums' pass evaluates the wakes' centres at the
    heights itself (one hand-over to the threads per wake step, not two): the same centres and
    the same C_n, bit for bit, as the centres' own pass followed by the sums, over several
    blocks of rotors on 1 and 2 threads; an offsets array it cannot write into is refused."""
    rng = np.random.default_rng(11)
    n_findex, kinds, rotors = 3, 2, 3 * ROTOR_BLOCK + 7
    store = UpstreamWakes.start(rotors, CELLS)
    for _ in range(4):  # wakes kept before
        rotor = rng.permutation(rotors)[: rotors // 2]
        wakes = _wakes(rng, rotor)
        store.keep(rotor, store.deficits(rotor, *wakes)[0], *wakes[:4])
    heights = np.array([[90.0], [120.0]]) + np.array([[63.0], [80.0]]) * DEFICIT_HEIGHTS
    centres = (rng.uniform(300.0, 2500.0, rotors), rng.integers(0, n_findex, rotors),
               rng.integers(0, kinds, rotors), heights,
               rng.uniform(4.0, 12.0, (n_findex, kinds, HEIGHTS)),
               rng.uniform(-2.0, 2.0, (n_findex, kinds, HEIGHTS)),
               _centre_table(rng, n_findex, 1.0, 1.0)[1])
    rotor = rng.permutation(rotors)
    width_squared, lateral, _, height, *rest = _wakes(rng, rotor)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        offsets = centres_at_heights(*centres)
        expected = store.deficits(rotor, width_squared, lateral, offsets, height, *rest)
        into = np.empty_like(offsets)
        got = store.deficits(rotor, width_squared, lateral, into, height, *rest,
                             centres=centres)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(into, offsets)
    for value, reference in zip(got, expected):
        np.testing.assert_array_equal(value, reference)
    # The wakes left out (rotor_kernel._may_reach: none of their rows reached) get 0, the others
    # the same bits, their neighbours' prefetched entries notwithstanding.
    reach = rng.random(rotors) < 0.6
    into = np.empty_like(offsets)
    left = store.deficits(rotor, width_squared, lateral, into, height, *rest, centres=centres,
                          reach=reach)
    np.testing.assert_array_equal(into[reach], offsets[reach])
    assert not np.any(into[~reach])
    for value, reference in zip(left, expected):
        np.testing.assert_array_equal(value[reach], reference[reach])
        assert not np.any(value[~reach])
    with pytest.raises(ValueError, match="offsets"):
        store.deficits(rotor, width_squared, lateral, np.empty_like(offsets, order="F"),
                       height, *rest, centres=centres)
