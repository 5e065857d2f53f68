"""The upstream wakes kept at each rotor during one solve for the cumulative wake of Bastankhah
et al. (2021) on the rotor cells (``wake_superposition: cumulative``, wake/superposition.py,
docs/coupling.md#wakes-deep-in-an-array), and its centre deficits C_n in one compiled pass.

A new wake n reaching rotor j takes C_n = a - sqrt(a^2 - K U_n^2), a = U_0 - sum_i lambda_ni C_i,
over the wakes i that reached rotor j before it. C_n is evaluated where the deflection's centre
is (the veer-sheared centres differ with height), at the K = DEFICIT_HEIGHT_COUNT heights
DEFICIT_HEIGHTS of the rotor, the same whatever FLORIS's grid, and interpolated linearly to the
kernel's sub-point rows (:func:`height_interpolation`): K sums per wake and rotor, not one per
row (docs/coupling.md#wakes-deep-in-an-array). A rotor keeps only the wakes that reached it, so
the store is sparse: a pool of entries, one per (wake, rotor) reached, in blocks of BLOCK
consecutive entries linked per rotor in the order of arrival (``head``/``tail``/``following``),
each holding C_i and the centre's y at the K heights, sigma_i^2 and the centre's height. A rotor's blocks are returned to the pool when it becomes
the source of a wake: the solver steps the turbines downstream, so no later wake reaches it. The
memory is that of the wakes kept at the rotors still ahead of the sweep, not turbines^2 x rows
per condition; the work is that of the pairs of wakes that meet at a rotor. The sum runs over
the kept wakes in their order of arrival, the order of wake/superposition.py's numpy form (the
tests' reference), and the compiled arithmetic is that form's, so the deficits agree with it to
round-off.
"""

from __future__ import annotations

import attrs
import numba
import numpy as np
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic

from floris_ekman_veer.plugin.rotor.rotor_cells import height_interpolation
from floris_ekman_veer.plugin.rotor.rotor_threads import in_share, next_in_share, split_over_threads
from floris_ekman_veer.wake.fused import JIT, centre_offset, table_exp
from floris_ekman_veer.wake.superposition import OVERLAP_EXPONENT_LIMIT, cumulative_deficit

#: The heights [rotor radii from the hub] at which C_n is evaluated, the same for every turbine
#: grid: DEFICIT_HEIGHT_COUNT evenly over the whole rotor, z_h +- R, interpolated linearly to the
#: sub-point rows (:func:`height_interpolation`). Not FLORIS's n point heights (z_h +- R/2, C_n
#: constant beyond): with those a 2 x 2 grid had C_n at two heights, and the farm power of the
#: veer-sheared nights moved with n through C_n alone (docs/coupling.md#wakes-deep-in-an-array
#: gives the convergence in the count and its cost).
DEFICIT_HEIGHT_COUNT = 9
DEFICIT_HEIGHTS = np.linspace(-1.0, 1.0, DEFICIT_HEIGHT_COUNT)

#: No new wake left out (an empty mask of the passes' ``reach``).
_EVERY = np.zeros(0, dtype=np.bool_)

#: The pool grows by this factor when full (in place: ndarray.resize, no second copy alive).
GROWTH = 1.0625

#: A rotor's entries lie in blocks of this many consecutive entries (its first block holds its
#: first BLOCK wakes, and so on), so that the sum over them reads the pool in runs, not entry by
#: entry across it; a rotor's last block is part empty (on average BLOCK / 2 entries).
BLOCK = 8


@numba.njit(**JIT)
def _to_rows(values, interpolation, rows):
    """``values`` at the K heights interpolated to the rows into ``rows``
    (:func:`height_interpolation` (K, rows)), summed over the heights in order (as numpy's sum
    over them): at a row on one of the heights, its value exactly."""
    for r in range(rows.size):
        rows[r] = 0.0
    for k in range(values.size):
        for r in range(rows.size):
            rows[r] += values[k] * interpolation[k, r]


@intrinsic
def _prefetch(typingctx, array, index):
    """A hint to bring ``array[index]``'s cache line in for reading (LLVM's prefetch: no
    effect on any value; a no-op where the processor has no such instruction)."""
    if not (isinstance(array, types.Array) and array.ndim == 1
            and isinstance(index, types.Integer)):
        return None

    def codegen(context, builder, signature, arguments):
        array_type = signature.args[0]
        view = context.make_array(array_type)(context, builder, arguments[0])
        pointer = cgutils.get_item_pointer(context, builder, array_type, view, [arguments[1]],
                                           wraparound=False, boundscheck=False)
        word = ir.IntType(32)
        hint = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [cgutils.voidptr_t, word, word, word]),
            "llvm.prefetch.p0")
        # (read, the highest temporal locality, the data cache)
        builder.call(hint, [builder.bitcast(pointer, cgutils.voidptr_t), ir.Constant(word, 0),
                            ir.Constant(word, 3), ir.Constant(word, 1)])
        return context.get_dummy_value()

    return types.void(array, index), codegen


#: Values of the pool per cache line of 64 bytes: one hint per line.
_LINE = 8


@numba.njit(inline="always", **JIT)
def _fetch_entries(pool, width, block, remaining, following):
    """Prefetch hints for a rotor's entries (its blocks from ``block``, ``remaining`` entries) in
    the flat pool (``width`` values per entry)."""
    while block >= 0:
        start = block * BLOCK * width
        for value in range(start, start + min(BLOCK, remaining) * width, _LINE):
            _prefetch(pool, value)
        remaining -= BLOCK
        block = following[block]


@numba.njit(nogil=True, **JIT)
def _cumulative_deficits(rotor, width_squared, lateral, offsets, height, single, ambient,
                         incoming, core, interpolation, slot_row, slot_weights, reach, head,
                         following, count, kept, deficit, row_deficit, first, stride):
    """C_n [m/s] of the new wakes (k, one per rotor ``rotor[k]``) at the K heights
    into ``deficit`` (k, K) and interpolated to the rows into ``row_deficit`` (k, rows): the
    upstream sum sum_i lambda_ni C_i over the kept entries of the rotor (``kept``, the class
    docstring) in their order of arrival (Bastankhah et al. 2021, Eq. 4.9) at each height, with
    the centres there, then Eq. 4.10 with the potential core's bound (wake/superposition.py
    ``overlap_weight``, ``cumulative_deficit``; exp to round-off, wake/fused.py ``table_exp``), then the
    rows' values, sum_q C_n(z_q) interpolation[q, r] (:func:`height_interpolation`, summed over
    the heights in order). With a strip cut by the layer top (``slot_row`` (k,) its row, -1:
    none; empty: no split in the step; plugin/rotor/strip_split.py), that row takes the part
    below the top and the extra row slot ``row_deficit[k, rows]`` the part above, each
    sum_q C_n(z_q) slot_weights[k, part, q]; the slot is 0 where nothing is cut. An entry whose
    overlap exponent is beyond OVERLAP_EXPONENT_LIMIT at every height adds nothing and costs no
    exp. A new wake that cannot reach its rotor (``reach[k]`` False; empty: all may) gets 0:
    the kernel reaches none of its rows, and only the rows reached read C_n. The new wakes of
    share ``first`` of ``stride`` (plugin/rotor/rotor_threads.py; each wake's arithmetic is
    the same on any thread: the same bits)."""
    n = deficit.shape[1]
    rows = interpolation.shape[1]
    new_points = np.empty(n)
    pool = kept.reshape(-1)
    every = reach.size == 0
    for k in range(rotor.size):
        if not in_share(k, first, stride):
            continue
        if not (every or reach[k]):
            deficit[k] = 0.0
            row_deficit[k] = 0.0
            continue
        # The next wake's rotor's entries are fetched while this one's are summed: the pool is
        # read a rotor at a time, scattered over memory far larger than the cache, and the sum
        # waited on memory about 2 / 3 of its time (docs/performance.md#the-cumulative-default).
        ahead = next_in_share(k, first, stride)
        while ahead < rotor.size and not (every or reach[ahead]):
            ahead = next_in_share(ahead, first, stride)
        if ahead < rotor.size:
            _fetch_entries(pool, kept.shape[1], head[rotor[ahead]], count[rotor[ahead]],
                           following)
        lowest, highest = np.inf, -np.inf
        for q in range(n):
            new_points[q] = lateral[k] + offsets[k, q]
            lowest = min(lowest, new_points[q])
            highest = max(highest, new_points[q])
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
                # (one division per entry, not one per height)
                inverse = 0.5 / total
                height_squared = (record[2 * n + 1] - height[k]) ** 2
                # (a bound first: the centres' lateral ranges at least this far apart at every
                # height, the entry beyond the limit at each, as the heights' loop would find)
                apart = max(0.0, record[2 * n + 2] - highest, lowest - record[2 * n + 3])
                if (apart * apart + height_squared) * inverse >= OVERLAP_EXPONENT_LIMIT:
                    continue
                share = 2.0 * old_width_squared / total
                for q in range(n):
                    gap = record[n + q] - new_points[q]
                    exponent = (gap * gap + height_squared) * inverse
                    if exponent < OVERLAP_EXPONENT_LIMIT:
                        upstream[q] += share * table_exp(exponent) * record[q]
            remaining -= BLOCK
            block = following[block]
        for q in range(n):
            upstream[q] = cumulative_deficit(single[k], ambient[k], incoming[k], upstream[q],
                                             core[k])
        _to_rows(upstream, interpolation, row_deficit[k, :rows])
        if slot_row.size:
            row_deficit[k, rows] = 0.0
            if slot_row[k] >= 0:
                below = 0.0
                above = 0.0
                for q in range(n):
                    below += upstream[q] * slot_weights[k, 0, q]
                    above += upstream[q] * slot_weights[k, 1, q]
                row_deficit[k, slot_row[k]] = below
                row_deficit[k, rows] = above


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
        lowest, highest = np.inf, -np.inf
        for q in range(n):
            record[q] = deficit[k, q]
            record[n + q] = lateral[k] + offsets[k, q]
            lowest = min(lowest, record[n + q])
            highest = max(highest, record[n + q])
        record[2 * n] = width_squared[k]
        record[2 * n + 1] = height[k]
        record[2 * n + 2] = lowest
        record[2 * n + 3] = highest
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
    entry (block * BLOCK + slot) one record of ``kept`` (capacity, 2 n + 4), read together by
    the sum: its C_i at the K heights ``heights`` [m/s], the centre's y there [m], sigma_i^2
    [m^2] and the centre's height [m]; ``interpolation`` (K, rows) :func:`height_interpolation`
    from the heights to the cells' sub-point rows."""

    head: np.ndarray
    tail: np.ndarray
    following: np.ndarray
    count: np.ndarray
    free: np.ndarray
    kept: np.ndarray
    interpolation: np.ndarray
    heights: np.ndarray

    @classmethod
    def start(cls, rotors: int, cells, capacity: int | None = None,
              heights: np.ndarray | None = None) -> UpstreamWakes:
        """An empty pool for ``rotors`` rotors on ``cells`` (RotorCells), room for ``capacity``
        entries (default: one per rotor; it grows as needed), C_n at ``heights`` [rotor radii
        from the hub, increasing; default DEFICIT_HEIGHTS]."""
        blocks = -(-max(int(rotors if capacity is None else capacity), 1) // BLOCK)
        heights = np.asarray(DEFICIT_HEIGHTS if heights is None else heights, dtype=float)
        interpolation = np.ascontiguousarray(height_interpolation(heights, cells.row_z))
        n = heights.size
        entries = blocks * BLOCK
        empty = lambda: np.full(rotors, -1, dtype=np.int64)  # noqa: E731
        return cls(empty(), empty(), np.full(blocks, -1, dtype=np.int64),
                   np.zeros(rotors, dtype=np.int64), np.array([-1, 0, 0, 0], dtype=np.int64),
                   np.zeros((entries, 2 * n + 4)), interpolation, heights)

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
                 incoming, core, slot_row=None, slot_weights=None, centres=None, reach=None
                 ) -> tuple[np.ndarray, np.ndarray]:
        """C_n [m/s] of new wakes at rotors ``rotor`` (k,) (flat indices) at the K heights
        (k, K) and interpolated to the rows (k, rows; with ``slot_row`` (k,), the strip the
        layer top cuts, -1: none, and ``slot_weights`` (k, 2, K), its parts' weights from the
        heights: (k, rows + 1), the row slots of plugin/rotor/strip_split.py): their sigma_n^2,
        lateral position and the centre's offsets at the K heights ((k, K),
        :func:`centres_at_heights`), centre height, the model's C(x) / U_h of the wake alone,
        U_0, U_n and the core bound 2a U_n [m/s] (wake/superposition.py ``cumulative_deficit``;
        all (k,) but ``offsets``). With ``centres``, the arguments of :func:`centres_at_heights`,
        the offsets are evaluated into ``offsets`` (k, K), C-contiguous, in the same pass (each
        thread its own wakes' first: one hand-over to the threads, not two). ``reach`` (k,): the
        new wakes that may reach a row of their rotor (plugin/rotor/rotor_kernel.py
        ``_may_reach``, in ``cumulative_step``); the others get 0 (and 0 offsets where evaluated here); None: all may."""
        arguments, outputs = self.sum_arguments(
            rotor, width_squared, lateral, offsets, height, single, ambient, incoming, core,
            slot_row, slot_weights, centres, reach)
        split_over_threads(centres_and_deficits, np.size(rotor), *arguments)
        return outputs

    def sum_arguments(self, rotor, width_squared, lateral, offsets, height, single, ambient,
                      incoming, core, slot_row=None, slot_weights=None, centres=None,
                      reach=None) -> tuple[tuple, tuple[np.ndarray, np.ndarray]]:
        """:meth:`deficits`'s compiled pass, :func:`centres_and_deficits`: its arguments (but
        the share's) and its outputs, C_n at the heights and at the row slots (for a caller
        that runs it in one hand-over to the threads with other work; ``reach`` may then be
        written by that work before the pass reads it, wake by wake)."""
        vector = lambda a: np.ascontiguousarray(np.broadcast_to(  # noqa: E731
            np.asarray(a, dtype=float), np.shape(rotor)))
        n, rows = self.interpolation.shape
        if slot_row is None:
            slot_row, slot_weights = np.zeros(0, dtype=np.int64), np.zeros((0, 2, n))
        else:
            rows += 1
        deficit = np.empty((np.size(rotor), n))
        row_deficit = np.empty((np.size(rotor), rows))
        arguments = (
            np.ascontiguousarray(rotor, dtype=np.int64), vector(width_squared), vector(lateral),
            np.ascontiguousarray(offsets, dtype=float), vector(height), vector(single),
            vector(ambient), vector(incoming), vector(core), self.interpolation,
            np.ascontiguousarray(slot_row, dtype=np.int64),
            np.ascontiguousarray(slot_weights, dtype=float),
            _EVERY if reach is None else np.ascontiguousarray(reach, dtype=np.bool_), self.head,
            self.following, self.count, self.kept, deficit, row_deficit)
        if centres is None:
            return _NO_CENTRES + arguments, (deficit, row_deficit)
        if arguments[3] is not offsets:
            raise ValueError("offsets: the centres are written into it, so it must be a "
                             "C-contiguous float array")
        return _centre_arguments(np.size(rotor), *centres) + arguments, (deficit, row_deficit)

    def keep(self, rotor, deficit, width_squared, lateral, offsets, height) -> None:
        """Keep one new wake at each rotor of ``rotor`` (flat indices, each once): its C_n at
        the K heights ((k, K)), sigma_n^2, lateral position, offsets ((k, K)) and
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


@numba.njit(nogil=True, **JIT)
def _centres_at_heights(x, condition, kind, heights, kind_u, kind_v, per_condition, reach,
                        centres, first, stride):
    every = reach.size == 0
    for k in range(x.size):
        if not in_share(k, first, stride):
            continue
        if not (every or reach[k]):
            centres[k] = 0.0
            continue
        f, kk = condition[k], kind[k]
        (cos_a, sin_a, u_star, radius, _, strength, r_tube, image_height, veer,
         ground_image) = per_condition[f]
        for q in range(heights.shape[1]):
            u, v = kind_u[f, kk, q], kind_v[f, kk, q]
            centres[k, q] = centre_offset(x[k], heights[kk, q], u * cos_a + v * sin_a,
                                          v * cos_a - u * sin_a, strength, r_tube,
                                          image_height, radius, u_star, veer, ground_image)


def centres_at_heights(x, condition, kind, heights, kind_u, kind_v, per_condition) -> np.ndarray:
    """The ekman_veer wake centre y_c(x, z) [m] (wake/fused.py ``centre_offset``, the rotor-cell
    kernel's) of one wake at the K heights of the rotors it reaches, (pairs, K): ``x`` (pairs,)
    behind the wake's rotor, the rotors' ``condition`` and ``kind`` (pairs,), the kinds'
    ``heights`` [m] (kinds, K) and ambient (U, V) there in FLORIS's frame ``kind_u``,
    ``kind_v`` (n_findex, kinds, K) (RotorAmbient.deficit_u, deficit_v); the wake's factors per
    condition ``per_condition``, the rotor-cell kernel's table (n_findex, plugin/rotor/
    rotor_kernel.py CONDITION_COLUMNS: the hub-height wind's direction, u*, the wake's radius
    and hub height, the centre's t_hat prefactor, R sqrt(A*), the image vortex's hub height,
    the veer and ground-image switches)."""
    centres = np.empty((np.size(x), heights.shape[1]))
    split_over_threads(_centres_at_heights, np.size(x),
                       *_centre_arguments(np.size(x), x, condition, kind, heights, kind_u,
                                          kind_v, per_condition), _EVERY, centres)
    return centres


def _centre_arguments(pairs, x, condition, kind, heights, kind_u, kind_v, per_condition):
    """:func:`centres_at_heights`'s arguments as its compiled pass takes them (one signature)."""
    index = lambda a: np.ascontiguousarray(np.broadcast_to(a, pairs), dtype=np.int64)  # noqa: E731
    return (np.ascontiguousarray(np.broadcast_to(x, pairs), dtype=float), index(condition),
            index(kind), *(np.ascontiguousarray(a, dtype=float)
                           for a in (heights, kind_u, kind_v, per_condition)))


#: No centres to evaluate (:func:`centres_and_deficits` with the offsets given).
_NO_CENTRES = (np.zeros(0), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
               np.zeros((0, 0)), np.zeros((0, 0, 0)), np.zeros((0, 0, 0)), np.zeros((0, 0)))


@numba.njit(nogil=True, **JIT)
def centres_and_deficits(x, condition, kind, heights, kind_u, kind_v, per_condition, rotor,
                         width_squared, lateral, offsets, height, single, ambient, incoming,
                         core, interpolation, slot_row, slot_weights, reach, head, following,
                         count, kept, deficit, row_deficit, first, stride):
    """:func:`_centres_at_heights` into ``offsets`` (none with ``x`` empty: the offsets given),
    then :func:`_cumulative_deficits` with them, on one share (each new wake reads its own
    offsets only)."""
    _centres_at_heights(x, condition, kind, heights, kind_u, kind_v, per_condition, reach,
                        offsets, first, stride)
    _cumulative_deficits(rotor, width_squared, lateral, offsets, height, single, ambient,
                         incoming, core, interpolation, slot_row, slot_weights, reach, head,
                         following, count, kept, deficit, row_deficit, first, stride)
