"""The strip of the wake cells that a stable layer's top cuts, split per condition in two
(docs/coupling.md#rotor-average).

The wake cells' strips (plugin/rotor/rotor_cells.py) are shared by every condition of a rotor
kind; a step in height (the jet nose at the layer top h, and the veer deflection x V / U that
moves a wake centre by up to a radius within metres below it) is integrated by them to first
order: the strip h cuts counts on one side of it. Per condition and rotor kind whose h lies on
the rotor, that strip is integrated here as two parts, below and above h, each at its own
mid-height and with its exact area of the disk, at the strip's own sub-points across the chord
(its cells): the strip's row holds the part below h, the rotor's extra row slot
(``RotorCells.slots``) the part above. Where h is off the rotor (neutral layers, tall stable
ones) nothing is split: the slot has no weight and is skipped, and the results are those of
the shared strips bit for bit. Pure geometry and numpy: no FLORIS import.
"""

from __future__ import annotations

import attrs
import numpy as np

from floris_ekman_veer.plugin.rotor.rotor_cells import (
    RotorCells,
    height_interpolation,
    strip_area,
)


@attrs.define(frozen=True)
class StripSplit:
    """Per condition and rotor kind (n_findex, kinds): ``row`` the strip the layer top cuts
    (-1: none); per part (n_findex, kinds, 2), below then above the top: ``offset`` its
    mid-height in rotor radii from the hub, ``height`` [m], ``fraction`` its share of the
    strip's area (the two sum to 1) and the ambient ``u``, ``v`` there (FLORIS's frame)."""

    row: np.ndarray
    offset: np.ndarray
    height: np.ndarray
    fraction: np.ndarray
    u: np.ndarray
    v: np.ndarray
    weights: dict = attrs.field(factory=dict, eq=False, repr=False)

    @classmethod
    def of(cls, cells: RotorCells, hub_height, radius, top, profile) -> StripSplit:
        """The split of ``cells`` on rotor kinds of ``hub_height``, ``radius`` (kinds,) [m]
        under layer tops ``top`` (n_findex,) [m] (not finite: no top); ``profile(z)``, ``z``
        (n_findex, 1, 1, heights), returns the ambient (U, V) shaped like it."""
        top = np.asarray(top, dtype=float).reshape(-1, 1)
        offset = (np.where(np.isfinite(top), top, np.inf) - hub_height) / radius
        row = np.searchsorted(cells.edges, offset, side="right") - 1
        # (strictly inside a strip: a top on an edge is integrated exactly by the strips)
        inside = (row >= 0) & (row < cells.rows)
        row = np.where(inside, row, 0)
        lower, upper = cells.edges[row], cells.edges[row + 1]
        inside &= (offset > lower) & (offset < upper)
        offset = np.where(inside, offset, 0.5 * (lower + upper))
        parts = np.stack([0.5 * (lower + offset), 0.5 * (offset + upper)], axis=-1)
        strip = strip_area(lower, upper)
        fraction = np.stack([strip_area(lower, offset), strip_area(offset, upper)],
                            axis=-1) / strip[..., None]
        row = np.where(inside, row, -1)
        parts = np.where(inside[..., None], parts, 0.0)
        height = hub_height[:, None] + radius[:, None] * parts
        n_findex, kinds = row.shape
        u, v = (np.asarray(values).reshape(n_findex, kinds, 2)
                for values in profile(height.reshape(n_findex, 1, 1, -1)))
        return cls(row.astype(np.int64), parts, height, fraction, u, v)

    @property
    def any(self) -> bool:
        """Whether a layer top lies on a rotor of some condition."""
        return bool(np.any(self.row >= 0))

    def pair_rows(self, cells: RotorCells, kind_heights, kind_u, kind_v, f, kind):
        """The row slots of rotors (f, kind) as the kernel integrates them, (pairs, rows + 1)
        each: the strip row whose sub-points each slot takes (the extra slot: the cut strip's,
        or row 0 where nothing is cut), its share of that strip's area (0: an empty slot), its
        height [m] and ambient (U, V) (``kind_heights`` (kinds, rows), ``kind_u``, ``kind_v``
        (n_findex, kinds, rows): the shared rows')."""
        pairs, rows = f.size, cells.rows
        cut = self.row[f, kind]
        strip = np.tile(np.arange(rows + 1), (pairs, 1))
        strip[:, rows] = np.where(cut >= 0, cut, 0)
        fraction = np.ones((pairs, rows + 1))
        fraction[:, rows] = 0.0
        slot = lambda values: np.concatenate([values, values[:, :1]], axis=1)  # noqa: E731
        height, u, v = slot(kind_heights[kind]), slot(kind_u[f, kind]), slot(kind_v[f, kind])
        split = np.flatnonzero(cut >= 0)
        for part, column in enumerate((cut[split], rows)):
            at = (f[split], kind[split], part)
            fraction[split, column] = self.fraction[at]
            height[split, column] = self.height[at]
            u[split, column], v[split, column] = self.u[at], self.v[at]
        return strip, fraction, height, u, v

    def at_rows(self, values, row_values, f, kind, heights) -> np.ndarray:
        """Values held at m ``heights`` (rotor radii from the hub, increasing) of rotors
        (f, kind) (pairs, m) at their row slots (pairs, rows + 1): ``row_values`` (pairs, rows)
        at the shared rows, the split strip's parts interpolated linearly from the heights as
        the rows are (rotor_cells.height_interpolation: FLORIS's n point heights for the
        centre, the cumulative wake's K for C_n), 0 in the slot of the rotors not split."""
        pairs, rows = row_values.shape
        out = np.zeros((pairs, rows + 1))
        out[:, :rows] = row_values
        row = self.row[f, kind]
        split = np.flatnonzero(row >= 0)
        if split.size:
            weights = self.weights_from(heights)[f[split], kind[split]]
            parts = np.einsum("sq,spq->sp", values[split], weights)
            out[split, row[split]] = parts[:, 0]
            out[split, rows] = parts[:, 1]
        return out

    def weights_from(self, heights) -> np.ndarray:
        """The parts' interpolation weights from ``heights`` (n_findex, kinds, 2, m), once per
        solve and set of heights (a wake step reads them for every rotor it splits)."""
        heights = np.asarray(heights, dtype=float)
        key = heights.tobytes()
        if key not in self.weights:
            # (contiguous: a wake step gathers its rotors' rows, ten times faster than from
            # the axis-moved view)
            self.weights[key] = np.ascontiguousarray(
                np.moveaxis(height_interpolation(heights, self.offset), 0, -1))
        return self.weights[key]
