"""The upstream wakes kept at each rotor during one solve for the cumulative wake of Bastankhah
et al. (2021) on the rotor cells (``wake_superposition: cumulative``, wake/superposition.py,
docs/coupling.md#wakes-deep-in-an-array), and its centre deficits C_n in one compiled pass.

A new wake n reaching rotor j takes C_n = a - sqrt(a^2 - K U_n^2), a = U_0 - sum_i lambda_ni C_i,
over the wakes i that reached rotor j before it. C_n is evaluated where the deflection's centre
is, at FLORIS's n grid-point heights of the rotor (the veer-sheared centres differ with height),
and interpolated to the kernel's sub-point rows as the centre is (rotor_cells.row_interpolation):
n sums per wake and rotor, not one per row (docs/coupling.md#wakes-deep-in-an-array). A rotor
keeps only the wakes that reached it, so the store is sparse: a pool of entries, one per
(wake, rotor) reached, in blocks of BLOCK consecutive entries linked per rotor in the order of
arrival (``head``/``tail``/``following``), each holding C_i and the centre's y at the n
grid-point heights, sigma_i^2 and the centre's height. A rotor's blocks are returned to the pool when it becomes
the source of a wake: the solver steps the turbines downstream, so no later wake reaches it. The
memory is that of the wakes kept at the rotors still ahead of the sweep, not turbines^2 x rows
per condition; the work is that of the pairs of wakes that meet at a rotor. The sum runs over
the kept wakes in their order of arrival, the order of wake/superposition.py's numpy form (the
tests' reference), and the compiled arithmetic is that form's, so the deficits agree with it to
round-off.
"""

from __future__ import annotations

import math

import attrs
import numba
import numpy as np

from floris_ekman_veer.plugin.rotor.rotor_cells import row_interpolation
from floris_ekman_veer.wake.fused import JIT
from floris_ekman_veer.wake.superposition import OVERLAP_EXPONENT_LIMIT, cumulative_deficit

#: The pool grows by this factor when full (in place: ndarray.resize, no second copy alive).
GROWTH = 1.0625

#: A rotor's entries lie in blocks of this many consecutive entries (its first block holds its
#: first BLOCK wakes, and so on), so that the sum over them reads the pool in runs, not entry by
#: entry across it; a rotor's last block is part empty (on average BLOCK / 2 entries).
BLOCK = 8


@numba.njit(**JIT)
def _to_rows(values, interpolation, rows):
    """``values`` at the n grid-point heights interpolated to the rows into ``rows``
    (rotor_cells.row_interpolation (n, rows)), summed over the points in order (as numpy's sum
    over them): at a row on a point's height, that point's value exactly."""
    for r in range(rows.size):
        rows[r] = 0.0
    for k in range(values.size):
        for r in range(rows.size):
            rows[r] += values[k] * interpolation[k, r]


#: exp(x) for -OVERLAP_EXPONENT_LIMIT <= x <= 0 as exp(-m / EXP_STEPS) (a table, numpy's exp)
#: times exp(y) on -1 / EXP_STEPS < y <= 0 by its Taylor polynomial (EXP_TAYLOR, truncation below
#: 1e-18): arithmetic and a table look-up only (math.exp is a libm call, measured 2-4 x
#: slower). Within 2 units in the last place of numpy's exp
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
                         incoming, core, interpolation, head, following, count, kept, deficit,
                         row_deficit):
    """C_n [m/s] of the new wakes (k, one per rotor ``rotor[k]``) at the n grid-point heights
    into ``deficit`` (k, n) and interpolated to the rows into ``row_deficit`` (k, rows): the
    upstream sum sum_i lambda_ni C_i over the kept entries of the rotor (``kept``, the class
    docstring) in their order of arrival (Bastankhah et al. 2021, Eq. 4.9) at each height, with
    the centres there, then Eq. 4.10 with the potential core's bound (wake/superposition.py
    ``overlap_weight``, ``cumulative_deficit``; exp to round-off, ``overlap_exp``), then the
    rows' values as the centre's, sum_q C_n(z_q) interpolation[q, r] (rotor_cells.
    row_interpolation, summed over the points in order). An entry whose overlap exponent is
    beyond OVERLAP_EXPONENT_LIMIT at every height adds nothing and costs no exp."""
    n = deficit.shape[1]
    new_points = np.empty(n)
    exponent = np.empty(n)
    for k in range(rotor.size):
        for q in range(n):
            new_points[q] = lateral[k] + offsets[k, q]
        upstream = deficit[k]
        for q in range(n):
            upstream[q] = 0.0
        block = head[rotor[k]]
        remaining = count[rotor[k]]
        while block >= 0:
            for entry in range(block * BLOCK, block * BLOCK + min(BLOCK, remaining)):
                record = kept[entry]
                old_width_squared = record[2 * n]
                total = width_squared[k] + old_width_squared
                height_squared = (record[2 * n + 1] - height[k]) ** 2
                least = np.inf
                for q in range(n):
                    gap = record[n + q] - new_points[q]
                    exponent[q] = (gap * gap + height_squared) / (2.0 * total)
                    least = min(least, exponent[q])
                if least >= OVERLAP_EXPONENT_LIMIT:
                    continue
                share = 2.0 * old_width_squared / total
                for q in range(n):
                    if exponent[q] < OVERLAP_EXPONENT_LIMIT:
                        upstream[q] += share * overlap_exp(-exponent[q]) * record[q]
            remaining -= BLOCK
            block = following[block]
        for q in range(n):
            upstream[q] = cumulative_deficit(single[k], ambient[k], incoming[k], upstream[q],
                                             core[k])
        _to_rows(upstream, interpolation, row_deficit[k])


@numba.njit(**JIT)
def _keep(rotor, deficit, width_squared, lateral, offsets, height, head, tail, following,
          count, free, kept):
    """Append one entry per rotor ``rotor[k]`` (each once) at the end of its list: in its last
    block, or in a new one taken from the free list ``free[0]`` or the unused end of the pool
    ``free[1]`` (the caller made room)."""
    n = deficit.shape[1]
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
        record = kept[tail[j] * BLOCK + slot]
        for q in range(n):
            record[q] = deficit[k, q]
            record[n + q] = lateral[k] + offsets[k, q]
        record[2 * n] = width_squared[k]
        record[2 * n + 1] = height[k]
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
    entry (block * BLOCK + slot) one record of ``kept`` (capacity, 2 n + 2), read together by
    the sum: its C_i at the n grid-point heights [m/s], the centre's y there [m], sigma_i^2
    [m^2] and the centre's height [m]; ``interpolation`` (n, rows)
    rotor_cells.row_interpolation."""

    head: np.ndarray
    tail: np.ndarray
    following: np.ndarray
    count: np.ndarray
    free: np.ndarray
    kept: np.ndarray
    interpolation: np.ndarray

    @classmethod
    def start(cls, rotors: int, cells, capacity: int | None = None) -> UpstreamWakes:
        """An empty pool for ``rotors`` rotors on ``cells`` (RotorCells), room for ``capacity``
        entries (default: one per rotor; it grows as needed)."""
        blocks = -(-max(int(rotors if capacity is None else capacity), 1) // BLOCK)
        interpolation = np.ascontiguousarray(row_interpolation(cells.n, cells.row_z))
        n = interpolation.shape[0]
        entries = blocks * BLOCK
        empty = lambda: np.full(rotors, -1, dtype=np.int64)  # noqa: E731
        return cls(empty(), empty(), np.full(blocks, -1, dtype=np.int64),
                   np.zeros(rotors, dtype=np.int64), np.array([-1, 0, 0, 0], dtype=np.int64),
                   np.zeros((entries, 2 * n + 2)), interpolation)

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
                 incoming, core) -> tuple[np.ndarray, np.ndarray]:
        """C_n [m/s] of new wakes at rotors ``rotor`` (k,) (flat indices) at the n grid-point
        heights (k, n) and interpolated to the rows (k, rows): their sigma_n^2, lateral position
        and offsets at the grid-point heights ((k, n)), centre height, the model's C(x) / U_h of
        the wake alone, U_0, U_n and the core bound 2a U_n [m/s] (wake/superposition.py
        ``cumulative_deficit``; all (k,) but ``offsets``)."""
        vector = lambda a: np.ascontiguousarray(np.broadcast_to(  # noqa: E731
            np.asarray(a, dtype=float), np.shape(rotor)))
        n, rows = self.interpolation.shape
        deficit = np.empty((np.size(rotor), n))
        row_deficit = np.empty((np.size(rotor), rows))
        _cumulative_deficits(
            np.ascontiguousarray(rotor, dtype=np.int64), vector(width_squared), vector(lateral),
            np.ascontiguousarray(offsets, dtype=float), vector(height), vector(single),
            vector(ambient), vector(incoming), vector(core), self.interpolation, self.head,
            self.following, self.count, self.kept, deficit, row_deficit)
        return deficit, row_deficit

    def keep(self, rotor, deficit, width_squared, lateral, offsets, height) -> None:
        """Keep one new wake at each rotor of ``rotor`` (flat indices, each once): its C_n at
        the grid-point heights ((k, n)), sigma_n^2, lateral position, offsets ((k, n)) and
        height."""
        rotor = np.ascontiguousarray(rotor, dtype=np.int64)
        new_blocks = np.count_nonzero(self.count[rotor] % BLOCK == 0)
        if self.blocks_in_use + new_blocks > self.following.size:
            self._grow(self.blocks_in_use + new_blocks)
        vector = lambda a: np.ascontiguousarray(np.broadcast_to(  # noqa: E731
            np.asarray(a, dtype=float), rotor.shape))
        _keep(rotor, np.ascontiguousarray(deficit, dtype=float), vector(width_squared),
              vector(lateral), np.ascontiguousarray(offsets, dtype=float), vector(height),
              self.head, self.tail, self.following, self.count, self.free, self.kept)

    def release(self, rotor) -> None:
        """Free the entries kept at rotors ``rotor`` (flat indices): no later wake reaches a
        rotor once it is a wake's source."""
        _release(np.ascontiguousarray(rotor, dtype=np.int64), self.head, self.tail,
                 self.following, self.count, self.free)

    def _grow(self, blocks: int) -> None:
        """Room for ``blocks`` blocks in use, in place (ndarray.resize: the pool's table is
        referenced here only, and a reallocation keeps no second copy alive)."""
        blocks = max(int(GROWTH * self.following.size), blocks)
        self.kept.resize((blocks * BLOCK, self.kept.shape[1]), refcheck=False)
        self.following.resize(blocks, refcheck=False)
