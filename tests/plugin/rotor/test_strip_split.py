"""The strip a stable layer's top cuts, split per condition in its parts below and above the top
(plugin/rotor/strip_split.py) and integrated so by the rotor-cell kernel
(plugin/rotor/rotor_kernel.py): a step in height at the top is integrated exactly, a top off the
rotor changes no bit, the threads change no bit."""

from __future__ import annotations

from types import SimpleNamespace

import numba
import numpy as np
import pytest

from floris_ekman_veer.plugin.rotor.rotor_cells import rotor_cells, sub_quadrature
from floris_ekman_veer.plugin.rotor.rotor_kernel import (
    CONDITION_COLUMNS,
    PAIR_COLUMNS,
    integrate_wake,
)
from floris_ekman_veer.plugin.rotor.rotor_threads import ROTOR_BLOCK
from floris_ekman_veer.plugin.rotor.rotor_wakes import RotorWakes
from floris_ekman_veer.plugin.rotor.strip_split import StripSplit
from floris_ekman_veer.plugin.rotor.upstream_wakes import DEFICIT_HEIGHTS
from floris_ekman_veer.wake.fused import GAUSSIAN_SHAPE, WAKE_TABLE

HUB, RADIUS = 90.0, 63.0
U_BELOW, U_ABOVE = 8.0, 10.5  # [m/s] either side of the layer top: the step (a jet nose)


def step_profile(top):
    """(U, V) of a step at the layer top ``top`` (n_findex,) [m], for heights (n_findex, 1, 1,
    m) (the shape StripSplit.of and rows_profile pass)."""
    def profile(z):
        z = np.asarray(z, dtype=float)
        u = np.where(z < np.reshape(top, (-1, 1, 1, 1)), U_BELOW, U_ABOVE)
        return np.broadcast_to(u, np.broadcast_shapes(u.shape, z.shape)), np.zeros_like(u)
    return profile


def step_rotors(n, tops, deficit, turbines=2):
    """Per layer top (one condition each), ``turbines`` rotors of one kind in a row and the
    kernel's inputs of a wake of the first on the others that is ``deficit`` [m/s] wherever
    it reaches (a Gaussian of an unbounded width), centred on them."""
    cells = rotor_cells(n, *sub_quadrature(n, 2.0 * RADIUS))
    tops = np.asarray(tops, dtype=float)
    n_findex = tops.size
    heights = HUB + RADIUS * cells.row_z
    u = np.stack([step_profile(tops[f:f + 1])(heights.reshape(1, 1, 1, -1))[0].reshape(-1)
                  for f in range(n_findex)])[:, None, :]
    split = StripSplit.of(cells, np.array([HUB]), np.array([RADIUS]), tops, step_profile(tops))
    x = np.broadcast_to(500.0 * np.arange(turbines), (n_findex, turbines))
    rotor = SimpleNamespace(x=x, kind_u=u, kind_v=np.zeros_like(u),
                            kind_heights=heights[None, :], split=split)
    f, j = np.divmod(np.arange(n_findex * (turbines - 1)), turbines - 1)
    j = j + 1
    wake = np.zeros((f.size, len(WAKE_TABLE)))
    wake[:, WAKE_TABLE.index("amplitude")] = 1.0
    wake[:, WAKE_TABLE.index("kx")] = 1e12  # (the exponent below 1e-20: exp of it is 1)
    wake[:, WAKE_TABLE.index("shape")] = GAUSSIAN_SHAPE
    pair = np.zeros((f.size, len(PAIR_COLUMNS)))
    values = {"x": x[f, j], "offset": 0.0, "radius_j": RADIUS, "moment": 3.0,
              "reach_squared": np.inf, "overlap_edge": 0.05, "velocity_scale": deficit}
    for k, name in enumerate(PAIR_COLUMNS):
        pair[:, k] = values[name]
    per_condition = np.zeros((n_findex, len(CONDITION_COLUMNS)))
    per_condition[:, CONDITION_COLUMNS.index("cos")] = 1.0
    per_condition[:, CONDITION_COLUMNS.index("friction_velocity")] = 0.3
    per_condition[:, CONDITION_COLUMNS.index("radius")] = RADIUS
    per_condition[:, CONDITION_COLUMNS.index("hub_height")] = HUB
    per_condition[:, CONDITION_COLUMNS.index("centre_r_tube")] = 1.0
    return cells, rotor, wake, pair, per_condition, f * turbines + j


def integrated(n, tops, deficit, split, turbines=2):
    """The kernel's (removed, overlap, reached) of the step rotors (each wake alone)."""
    cells, rotor, wake, pair, per_condition, flat = step_rotors(n, tops, deficit, turbines)
    wakes = RotorWakes.start(cells, len(np.atleast_1d(tops)), turbines, None, 0.06)
    centre = np.zeros((flat.size, cells.slots))
    return integrate_wake(wake, pair, per_condition, centre, flat, np.zeros(flat.size, int),
                          rotor, wakes, True, split=split)[:3]


def disk_below(s):
    """The share of the unit disk below height s (rotor radii from the hub), by hand:
    (s sqrt(1 - s^2) + arcsin s + pi / 2) / pi."""
    return (s * np.sqrt(1.0 - s * s) + np.arcsin(s) + 0.5 * np.pi) / np.pi


@pytest.mark.parametrize("n", [2, 3])
@pytest.mark.parametrize("top_offset", [-0.83, -0.31, 0.0137, 0.52, 0.9])
def test_split_strip_integrates_a_step_at_the_top_exactly(n, top_offset):
    """A uniform wake deficit du on a rotor whose inflow steps from U_below to U_above at the
    layer top h removes the moment A_below (U_below^3 - (U_below - du)^3) + A_above (U_above^3
    - (U_above - du)^3) (A the shares of the disk either side of h): with the cut strip split,
    to round-off; the shared strips count the whole cut strip on one side (an error of the
    order of the strip's share of the disk times the step)."""
    deficit = 1.3
    tops = [HUB + RADIUS * top_offset]
    below = disk_below(top_offset)
    exact = (below * (U_BELOW**3 - (U_BELOW - deficit) ** 3)
             + (1.0 - below) * (U_ABOVE**3 - (U_ABOVE - deficit) ** 3))
    removed, overlap, reached = integrated(n, tops, deficit, split=True)
    assert reached.all()
    assert removed.sum() == pytest.approx(exact, rel=1e-13)
    # (the overlap is the disk's area: the parts' weights sum to the strip's)
    assert overlap[0] == pytest.approx(1.0, rel=1e-13)
    shared = integrated(n, tops, deficit, split=False)[0].sum()
    rows = rotor_cells(n, *sub_quadrature(n, 2.0 * RADIUS)).rows
    step = (U_ABOVE**3 - (U_ABOVE - deficit) ** 3) - (U_BELOW**3 - (U_BELOW - deficit) ** 3)
    # the cut strip's part on the wrong side: at least 1e-3 of a strip's chord share
    assert abs(shared - exact) > 1e-3 * step / rows


@pytest.mark.parametrize("top", [HUB + 1.2 * RADIUS, HUB - 1.5 * RADIUS, np.inf,
                                 HUB + 0.5 * RADIUS])
def test_top_off_the_rotor_or_on_an_edge_leaves_the_slot_empty_and_the_bits(top):
    """A layer top above or below the rotor, none, or on a strip edge (h = hub + R/2 is one
    for 6 n and 8 n strips): no strip split, the extra slot weightless, the same bits as the shared
    strips."""
    cells, rotor, *_ = step_rotors(2, [top], 1.0)
    assert np.all(rotor.split.row == -1)
    with_split = integrated(2, [top], 1.0, split=True)
    without = integrated(2, [top], 1.0, split=False)
    for a, b in zip(with_split, without, strict=True):
        np.testing.assert_array_equal(a, b)


def test_parts_lie_either_side_of_the_top_with_their_exact_areas():
    """The parts' mid-heights are those of [edge below, h] and [h, edge above], their shares of
    the strip its exact areas (the hand formula), per condition: each condition its own h."""
    cells = rotor_cells(3, *sub_quadrature(3, 2.0 * RADIUS))
    offsets = np.array([-0.4, 0.05, 0.77, 2.0])
    tops = HUB + RADIUS * offsets
    split = StripSplit.of(cells, np.array([HUB]), np.array([RADIUS]), tops, step_profile(tops))
    for f, s in enumerate(offsets[:3]):
        r = split.row[f, 0]
        lower, upper = cells.edges[r], cells.edges[r + 1]
        assert lower < s < upper
        np.testing.assert_allclose(split.offset[f, 0], [(lower + s) / 2, (s + upper) / 2])
        strip = disk_below(upper) - disk_below(lower)
        np.testing.assert_allclose(split.fraction[f, 0], [(disk_below(s) - disk_below(lower))
                                                          / strip,
                                                          (disk_below(upper) - disk_below(s))
                                                          / strip], rtol=1e-12)
        np.testing.assert_array_equal(split.u[f, 0], [U_BELOW, U_ABOVE])
    assert split.row[3, 0] == -1


@pytest.mark.parametrize("heights", [np.array([-0.5, 0.0, 0.5]), DEFICIT_HEIGHTS],
                         ids=["grid points", "cumulative wake's heights"])
def test_parts_interpolated_from_the_held_heights_as_the_rows(heights):
    """``at_rows``: the shared rows as given, the cut strip's row and the extra slot the values
    held at some heights (FLORIS's 3 point heights, the cumulative wake's K) linearly
    interpolated to the parts' heights, 0 in the slot where nothing is cut."""
    cells = rotor_cells(3, *sub_quadrature(3, 2.0 * RADIUS))
    tops = HUB + RADIUS * np.array([0.3, 5.0])
    split = StripSplit.of(cells, np.array([HUB]), np.array([RADIUS]), tops, step_profile(tops))
    held = np.stack([1.0 + heights + 2.0 * heights ** 2, np.full(heights.size, 3.0)])
    rows = np.arange(2 * cells.rows, dtype=float).reshape(2, cells.rows)
    out = split.at_rows(held, rows, np.array([0, 1]), np.array([0, 0]), heights)
    r = split.row[0, 0]
    expected = np.interp(split.offset[0, 0], heights, held[0])
    np.testing.assert_allclose(out[0, [r, cells.rows]], expected, rtol=1e-15)
    np.testing.assert_array_equal(np.delete(out[0], [r, cells.rows]),
                                  np.delete(rows[0], r))
    np.testing.assert_array_equal(out[1], np.append(rows[1], 0.0))


def test_split_strips_give_the_same_bits_on_one_and_many_threads():
    """The kernel's shares of rotors (plugin/rotor/rotor_threads.py) with strips split at a
    different top per condition: the same bits on one thread and on every thread."""
    tops = HUB + RADIUS * np.linspace(-0.95, 0.95, 3 * ROTOR_BLOCK)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = integrated(2, tops, 0.9, split=True)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        many = integrated(2, tops, 0.9, split=True)
    finally:
        numba.set_num_threads(before)
    for a, b in zip(one, many, strict=True):
        np.testing.assert_array_equal(a, b)


def test_momentum_conserving_moments_of_two_equal_parts_are_the_strips():
    """plugin/rotor/convection.py ``removed_moments`` on row slots: a strip cut in two parts
    (shares 0.3 and 0.7) that hold the same wake and inflow as the whole strip removes the
    strip's moment from the same cells (the slot takes the strip's sub-points), to round-off;
    an empty slot (share 0) removes nothing."""
    from floris_ekman_veer.plugin.rotor.convection import removed_moments

    cells = rotor_cells(3, *sub_quadrature(3, 2.0 * RADIUS))
    rows, pairs = cells.rows, 3
    rng = np.random.default_rng(5)
    combined = rng.uniform(0.0, 2.0, (pairs * cells.slots, cells.sub_y.shape[1]))
    combined = combined.astype(np.float32)
    ambient_u = rng.uniform(6.0, 11.0, (pairs, rows))
    strips = np.tile(np.arange(rows + 1), (pairs, 1))
    strips[:, rows] = [7, 0, 15]
    fraction = np.ones((pairs, rows + 1))
    fraction[[0, 2], [7, 15]] = 0.3
    fraction[:, rows] = [0.7, 0.0, 0.7]
    blocks = combined.reshape(pairs, cells.slots, -1)
    blocks[:, rows] = blocks[np.arange(pairs), strips[:, rows]]
    slot_u = np.concatenate([ambient_u, ambient_u[np.arange(pairs), strips[:, rows]][:, None]],
                            axis=1)
    pair, convection, moment = np.arange(pairs), np.array([9.0, 8.5, 10.0]), np.array([3.0,
                                                                                       1.0,
                                                                                       3.0])
    whole = removed_moments(cells, combined, pair, convection, ambient_u, moment)
    parts = removed_moments(cells, combined, pair, convection, slot_u, moment,
                            (strips, fraction))
    np.testing.assert_allclose(parts, whole, rtol=1e-12)
