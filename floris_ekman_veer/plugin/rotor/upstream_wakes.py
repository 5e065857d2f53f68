"""The upstream wakes kept at each rotor during one solve for the cumulative wake of Bastankhah
et al. (2021) on the rotor cells (``wake_superposition: cumulative``, wake/superposition.py,
docs/coupling.md#wakes-deep-in-an-array), and its centre deficits C_n in one compiled pass.

A new wake n reaching rotor j takes C_n = a - sqrt(a^2 - K U_n^2), a = U_0 - sum_i lambda_ni C_i,
over the wakes i that reached rotor j before it, at each of the kernel's sub-point rows (the
veer-sheared centres differ with height). A rotor keeps only the wakes that reached it, so the
store is sparse: a pool of entries, one per (wake, rotor) reached, in blocks of BLOCK
consecutive entries linked per rotor in the order of arrival (``head``/``tail``/``following``),
each entry holding what varies per row, C_i at the rows, and once what does not: sigma_i^2, the
centre's height and the wake centre's lateral offset at FLORIS's n grid-point heights (the rows'
centres are their linear interpolation, rotor_cells.row_interpolation, the same arithmetic as for
the new wake). A rotor's
blocks are returned to the pool when it becomes the source of a wake: the solver steps the
turbines downstream, so no later wake reaches it. The memory is that of the wakes kept at the
rotors still ahead of the sweep, not turbines^2 x rows per condition; the work is that of the
pairs of wakes that meet at a rotor. The sum runs over the kept wakes in their order of arrival,
the order of wake/superposition.py's numpy form (the tests' reference), and the compiled
arithmetic is that form's, so the deficits agree with it to round-off.
"""

from __future__ import annotations

import math

import attrs
import numba
import numpy as np

from floris_ekman_veer.plugin.rotor.rotor_cells import row_interpolation
from floris_ekman_veer.wake.fused import JIT
from floris_ekman_veer.wake.superposition import OVERLAP_EXPONENT_LIMIT

#: The pool grows by this factor when full (in place: ndarray.resize, no second copy alive).
GROWTH = 1.0625

#: A rotor's entries lie in blocks of this many consecutive entries (its first block holds its
#: first BLOCK wakes, and so on), so that the sum over them reads the pool in runs, not entry by
#: entry across it; a rotor's last block is part empty (on average BLOCK / 2 entries).
BLOCK = 8


@numba.njit(**JIT)
def _row_centres(lateral, offsets, interpolation, centre):
    """y at the rows of a wake's centre into ``centre``: its lateral position plus its offsets
    at the n grid-point heights interpolated to the rows, summed over the points in order (as
    numpy's sum over them)."""
    for r in range(centre.size):
        centre[r] = 0.0
    for k in range(offsets.size):
        for r in range(centre.size):
            centre[r] += offsets[k] * interpolation[k, r]
    for r in range(centre.size):
        centre[r] = lateral + centre[r]


#: exp(x) for -OVERLAP_EXPONENT_LIMIT <= x <= 0 as exp(-m / EXP_STEPS) (a table, numpy's exp)
#: times exp(y) on -1 / EXP_STEPS < y <= 0 by its Taylor polynomial (EXP_TAYLOR, truncation below
#: 1e-18): arithmetic and a table look-up only, so that the compiled loop over the rows can run
#: in SIMD lanes (math.exp is a scalar libm call). Within 2 units in the last place of numpy's exp
#: (tests/plugin/rotor/test_upstream_wakes.py).
EXP_STEPS = 8
EXP_TABLE = np.exp(-np.arange(int(OVERLAP_EXPONENT_LIMIT) * EXP_STEPS + 2) / EXP_STEPS)
EXP_TAYLOR = np.array([1.0 / math.factorial(k) for k in range(12)])


@numba.njit(**JIT)
def overlap_exp(x):
    """exp(x) on [-OVERLAP_EXPONENT_LIMIT, 0] (EXP_STEPS)."""
    step = math.floor(-x * EXP_STEPS)
    y = x + step * (1.0 / EXP_STEPS)
    value = EXP_TAYLOR[-1]
    for term in range(EXP_TAYLOR.size - 2, -1, -1):
        value = value * y + EXP_TAYLOR[term]
    return EXP_TABLE[int(step)] * value


@numba.njit(**JIT)
def _cumulative_deficits(rotor, width_squared, lateral, offsets, height, single, ambient,
                         incoming, core, interpolation, head, following, count, kept_deficit,
                         kept_width_squared, kept_lateral, kept_offsets, kept_height, deficit):
    """C_n [m/s] at every row of the new wakes (k, one per rotor ``rotor[k]``) into ``deficit``
    (k, rows): the upstream sum sum_i lambda_ni C_i over the kept entries of the rotor in their
    order of arrival (Bastankhah et al. 2021, Eq. 4.9), then Eq. 4.10 with the potential core's
    bound (wake/superposition.py ``overlap_weight``, ``cumulative_deficit``: the same operations
    in the same order, exp to round-off, ``overlap_exp``). An entry whose centre lies more than
    the overlap's limit away at every row adds nothing (lambda is 0 there) and is passed over
    from its gaps at the grid-point heights, of which the rows' are the interpolation."""
    rows = deficit.shape[1]
    n = interpolation.shape[0]
    new_centre = np.empty(rows)
    new_points = np.empty(n)
    old_centre = np.empty(rows)
    weight = np.empty(rows)
    for k in range(rotor.size):
        _row_centres(lateral[k], offsets[k], interpolation, new_centre)
        for q in range(n):
            new_points[q] = lateral[k] + offsets[k, q]
        upstream = deficit[k]
        for r in range(rows):
            upstream[r] = 0.0
        block = head[rotor[k]]
        remaining = count[rotor[k]]
        while block >= 0:
            for entry in range(block * BLOCK, block * BLOCK + min(BLOCK, remaining)):
                old_width_squared = kept_width_squared[entry]
                total = width_squared[k] + old_width_squared
                height_squared = (kept_height[entry] - height[k]) ** 2
                # The least gap over the rows: 0 where the gaps at the points change sign.
                low, high = np.inf, -np.inf
                for q in range(n):
                    gap = (kept_lateral[entry] + kept_offsets[entry, q]) - new_points[q]
                    low, high = min(low, gap), max(high, gap)
                least = max(low, -high, 0.0)
                # (a margin for the rows' round-off)
                if (least * least + height_squared) / (2.0 * total) \
                        <= (1.0 + 1e-9) * OVERLAP_EXPONENT_LIMIT:
                    share = 2.0 * old_width_squared / total
                    _row_centres(kept_lateral[entry], kept_offsets[entry], interpolation,
                                 old_centre)
                    for r in range(rows):
                        gap = old_centre[r] - new_centre[r]
                        exponent = (gap * gap + height_squared) / (2.0 * total)
                        lam = share * overlap_exp(-min(exponent, OVERLAP_EXPONENT_LIMIT))
                        weight[r] = lam if exponent < OVERLAP_EXPONENT_LIMIT else 0.0
                    for r in range(rows):
                        upstream[r] += weight[r] * kept_deficit[entry, r]
            remaining -= BLOCK
            block = following[block]
        momentum = 1.0 - (1.0 - single[k]) ** 2
        for r in range(rows):
            a = ambient[k] - upstream[r]
            root = a**2 - momentum * incoming[k] ** 2
            value = a - math.sqrt(max(root, 0.0))
            upstream[r] = value if root > 0.0 and value <= core[k] else core[k]


@numba.njit(**JIT)
def _keep(rotor, deficit, width_squared, lateral, offsets, height, head, tail, following,
          count, free, kept_deficit, kept_width_squared, kept_lateral, kept_offsets,
          kept_height):
    """Append one entry per rotor ``rotor[k]`` (each once) at the end of its list: in its last
    block, or in a new one taken from the free list ``free[0]`` or the unused end of the pool
    ``free[1]`` (the caller made room)."""
    for k in range(rotor.size):
        j = rotor[k]
        slot = count[j] % BLOCK
        if slot == 0:
            block = free[0]
            if block >= 0:
                free[0] = following[block]
            else:
                block = free[1]
                free[1] += 1
            following[block] = -1
            if tail[j] >= 0:
                following[tail[j]] = block
            else:
                head[j] = block
            tail[j] = block
            free[3] += 1
        entry = tail[j] * BLOCK + slot
        kept_deficit[entry] = deficit[k]
        kept_width_squared[entry] = width_squared[k]
        kept_lateral[entry] = lateral[k]
        kept_offsets[entry] = offsets[k]
        kept_height[entry] = height[k]
        count[j] += 1
    free[2] += rotor.size


@numba.njit(**JIT)
def _release(rotor, head, tail, following, count, free):
    """Return the blocks of rotors ``rotor`` to the free list (the rotors' lists emptied)."""
    for j in rotor:
        if head[j] >= 0:
            following[tail[j]] = free[0]
            free[0] = head[j]
            head[j] = -1
            tail[j] = -1
            free[2] -= count[j]
            free[3] -= (count[j] + BLOCK - 1) // BLOCK
            count[j] = 0


@attrs.define(eq=False)
class UpstreamWakes:
    """The pool of kept wakes (the module docstring) in blocks of BLOCK entries, per rotor (flat
    index condition * n_turbines + turbine): ``head``/``tail`` its first and last block (-1:
    none), ``count`` its entries (the first ``count`` of its blocks' slots, in order of
    arrival); ``following`` the next block of a block's rotor (or of the free list); ``free``
    [first free block (-1: none), first never-used block, entries in use, blocks in use]; per
    entry (block * BLOCK + slot) its C_i at the rows [m/s] (``deficit``, (capacity, rows)),
    sigma_i^2 [m^2], lateral position [m], offsets at the n grid-point heights [m]
    ((capacity, n)) and centre height [m]; ``interpolation`` (n, rows)
    rotor_cells.row_interpolation."""

    head: np.ndarray
    tail: np.ndarray
    following: np.ndarray
    count: np.ndarray
    free: np.ndarray
    deficit: np.ndarray
    width_squared: np.ndarray
    lateral: np.ndarray
    offsets: np.ndarray
    height: np.ndarray
    interpolation: np.ndarray

    @classmethod
    def start(cls, rotors: int, cells, capacity: int | None = None) -> UpstreamWakes:
        """An empty pool for ``rotors`` rotors on ``cells`` (RotorCells), room for ``capacity``
        entries (default: one per rotor; it grows as needed)."""
        blocks = -(-max(int(rotors if capacity is None else capacity), 1) // BLOCK)
        interpolation = np.ascontiguousarray(row_interpolation(cells.n, cells.row_z))
        n, rows = interpolation.shape
        entries = blocks * BLOCK
        empty = lambda: np.full(rotors, -1, dtype=np.int64)  # noqa: E731
        return cls(empty(), empty(), np.full(blocks, -1, dtype=np.int64),
                   np.zeros(rotors, dtype=np.int64), np.array([-1, 0, 0, 0], dtype=np.int64),
                   np.zeros((entries, rows)), np.zeros(entries), np.zeros(entries),
                   np.zeros((entries, n)), np.zeros(entries), interpolation)

    @property
    def capacity(self) -> int:
        """Entries the pool holds."""
        return self.following.size * BLOCK

    @property
    def in_use(self) -> int:
        """Entries kept at the rotors now."""
        return int(self.free[2])

    @property
    def blocks_in_use(self) -> int:
        return int(self.free[3])

    def deficits(self, rotor, width_squared, lateral, offsets, height, single, ambient,
                 incoming, core) -> np.ndarray:
        """(k, rows) C_n [m/s] of new wakes at rotors ``rotor`` (k,) (flat indices): their
        sigma_n^2, lateral position and offsets at the grid-point heights ((k, n)), centre
        height, the model's C(x) / U_h of the wake alone, U_0, U_n and the core bound 2a U_n
        [m/s] (wake/superposition.py ``cumulative_deficit``; all (k,) but ``offsets``)."""
        vector = lambda a: np.ascontiguousarray(np.broadcast_to(  # noqa: E731
            np.asarray(a, dtype=float), np.shape(rotor)))
        deficit = np.empty((np.size(rotor), self.interpolation.shape[1]))
        _cumulative_deficits(
            np.ascontiguousarray(rotor, dtype=np.int64), vector(width_squared), vector(lateral),
            np.ascontiguousarray(offsets, dtype=float), vector(height), vector(single),
            vector(ambient), vector(incoming), vector(core), self.interpolation, self.head,
            self.following, self.count, self.deficit, self.width_squared, self.lateral,
            self.offsets, self.height, deficit)
        return deficit

    def keep(self, rotor, deficit, width_squared, lateral, offsets, height) -> None:
        """Keep one new wake at each rotor of ``rotor`` (flat indices, each once): its C_n at
        the rows ((k, rows)), sigma_n^2, lateral position, offsets ((k, n)) and height."""
        rotor = np.ascontiguousarray(rotor, dtype=np.int64)
        new_blocks = np.count_nonzero(self.count[rotor] % BLOCK == 0)
        if self.blocks_in_use + new_blocks > self.following.size:
            self._grow(self.blocks_in_use + new_blocks)
        vector = lambda a: np.ascontiguousarray(np.broadcast_to(  # noqa: E731
            np.asarray(a, dtype=float), rotor.shape))
        _keep(rotor, np.ascontiguousarray(deficit, dtype=float), vector(width_squared),
              vector(lateral), np.ascontiguousarray(offsets, dtype=float), vector(height),
              self.head, self.tail, self.following, self.count, self.free, self.deficit,
              self.width_squared, self.lateral, self.offsets, self.height)

    def release(self, rotor) -> None:
        """Free the entries kept at rotors ``rotor`` (flat indices): no later wake reaches a
        rotor once it is a wake's source."""
        _release(np.ascontiguousarray(rotor, dtype=np.int64), self.head, self.tail,
                 self.following, self.count, self.free)

    def _grow(self, blocks: int) -> None:
        """Room for ``blocks`` blocks in use, in place (ndarray.resize: the pool's arrays are
        referenced here only, and a reallocation keeps no second copy alive)."""
        blocks = max(int(GROWTH * self.following.size), blocks)
        for name in ("deficit", "width_squared", "lateral", "offsets", "height"):
            table = getattr(self, name)
            table.resize((blocks * BLOCK, *table.shape[1:]), refcheck=False)
        self.following.resize(blocks, refcheck=False)
