"""Rotor cells: the area of the rotor disk that each point of FLORIS's turbine grid stands for.

FLORIS's ``turbine_grid`` puts n x n points at +-R/2 around each hub and takes the cubic mean of
the n^2 point velocities with equal weights for power and thrust. On the narrow, veer-sheared
wakes of stable nights a point value is not a rotor average (a sheared band a tenth of a rotor
thick falls between the points) and the +-R/2 points miss the strongly curved stable profile
(docs/coupling.md#rotor-average). This module divides the disk into n^2 cells of equal area,
one per point, each with a fine sub-quadrature, so that

* the inflow hook sets ``u_initial`` at a point to the cubic mean of the ambient U over its cell,
  ``U_k = <U^3>_k^(1/3)`` (:func:`cell_mean`), and
* the ``ekman_veer`` velocity models return at a point the deficit ``d_k`` whose cube removes
  the exact power deficit of the cell, ``U_k^3 (1 - (1 - d_k)^3) = n^2 sum_s w_s
  (U_s^3 - (U_s - Delta u_s)^3)`` over the cell's sub-points s (:func:`equivalent_deficit`),
  with Delta u_s all wakes so far superposed point-wise at the sub-points by FLORIS's own rule
  (:class:`RotorWakes`; each call returns the increment that FLORIS's combination of the point
  values turns into the combined cell deficit).

FLORIS's equal-weight cubic mean of ``U_k (1 - d_k)`` is then the sub-quadrature of the disk
integral of u^3 (ambient and all wakes), and its thrust and power follow. For a turbine whose
operation model takes the plain mean of u (the actuator disk) the same holds with the first
moment in place of the third (:data:`TURBINE_MOMENTS`). :func:`rotor_cell_deficit` integrates
one turbine's wake over the cells it reaches for the velocity models (plugin/models.py): the
culling of the rows out of reach, the chunking of the sub-points and the superposition. Pure
geometry and numpy (numexpr for the superposition): no FLORIS import.

The cells: the points are grouped into rings of equal distance from the hub (the centre point of
odd n alone); ring after ring (inwards out) takes an annulus whose area is its share of points
(a ring whose annulus would miss its own points joins the ring inside), and each annulus is
cut into equal sectors centred on its points. For n = 3: a central disk of radius R/3 and eight
45-degree sectors of the annulus R/3 < r < R, all of area pi R^2 / 9.
The sub-quadrature: ``rows`` horizontal strips of equal height (each weighted by its exact area
of the disk) times ``columns`` Gauss-Legendre points across the chord; a sub-point belongs to the
cell it lies in, and the weights of each cell are scaled to its exact area. Uniform strips
integrate a band crossing them spectrally (error ~ exp(-2 pi^2 s^2 / h^2) for a Gaussian of width
s in z sampled at spacing h), which is what the sheared wakes need.
"""

from __future__ import annotations

import concurrent.futures
import contextvars
import functools
import os
import threading
import warnings

import attrs
import numexpr as ne
import numpy as np

from floris_ekman_veer.wake.deficit import WIDTH_FACTOR, stream_tube_area_ratio

#: The moment m of the rotor average that each turbine's power and thrust take: FLORIS's power
#: curves take the cubic mean (m = 3) of the turbine grid; the actuator disk takes the plain
#: mean of u (m = 1, Eq. Ud, plugin/turbine.py). The cells then carry <U^m>_k^(1/m) and
#: deficits that remove the wake's exact share of <u^m> (docs/coupling.md#rotor-average).
PLAIN_MEAN_OPERATION_MODELS = frozenset({"actuator-disk"})

#: Per unsorted turbine, the moment of the farm being solved (set by the inflow hook's Core
#: wrappers, as the atmosphere is); None: m = 3 for every turbine.
TURBINE_MOMENTS: contextvars.ContextVar = contextvars.ContextVar(
    "rotor_average_moments", default=None
)


#: The wake models of the farm being solved (FLORIS's WakeModelManager, set by the inflow hook's
#: Core wrappers): its combination model says how the cells' sub-points superpose the wakes and
#: its turbulence model gives the wake-added turbulence (:class:`RotorWakes`); None: each call
#: returns its own wake's cell deficits (FLORIS then combines the cells).
WAKE_MODELS: contextvars.ContextVar = contextvars.ContextVar("rotor_wake_models", default=None)


def turbine_moments(turbine_definitions) -> np.ndarray:
    """m per turbine of a FLORIS farm's ``turbine_definitions`` (1 for plain-mean operation
    models, else 3)."""
    return np.array([
        1.0 if definition.get("operation_model") in PLAIN_MEAN_OPERATION_MODELS else 3.0
        for definition in turbine_definitions
    ])


def sorted_moments(grid) -> np.ndarray:
    """m per sorted turbine of a turbine grid, (n_findex, n_turbines)."""
    order = grid.sorted_indices[:, :, 0, 0]
    moments = TURBINE_MOMENTS.get()
    if moments is None or len(moments) != order.shape[1]:
        return np.full(order.shape, 3.0)
    return np.asarray(moments)[order]

#: Sub-quadrature of the inflow cell averages: the ambient profile is smooth apart from the kink
#: at the ABL top, and is evaluated once per run, so it is resolved finely.
AMBIENT_ROWS, AMBIENT_NODES = 256, 4


@attrs.define(eq=False)
class RotorCells:
    """Cells of the unit disk for an n x n FLORIS turbine grid and their sub-quadrature.

    Attributes (lengths in rotor radii, positions relative to the hub, y lateral, z up):
        n: points per side of FLORIS's grid (point (iy, iz) is cell iy * n + iz).
        row_z: (rows,) heights of the sub-point rows.
        sub_y: (rows, columns) lateral positions of the sub-points.
        weight: (rows, columns) area weights over the disk area, summing to 1.
        area: (n^2,) the cells' areas in this quadrature (exact: 1/n^2 each).
        cell: (rows * columns,) cell index of each sub-point.
        row_chord: (rows,) half-chord of the disk at each row height.
        nodes: sub-points per stretch of a row in one cell (each row: stretches of ``nodes``
            consecutive sub-points, padding included).

    Nothing here is dense in (sub-points x cells): a fine grid's n^2 cells cost memory and work
    in proportion to the sub-points (:attr:`row_cells`).
    """

    n: int
    row_z: np.ndarray
    sub_y: np.ndarray
    weight: np.ndarray
    cell: np.ndarray
    row_chord: np.ndarray
    area: np.ndarray
    nodes: int = 1

    @property
    def rows(self) -> int:
        return self.row_z.size

    @functools.cached_property
    def row_width(self) -> np.ndarray:
        """(rows,) sub-points with weight in each row: the row's first ones (the rest pad)."""
        return np.count_nonzero(self.weight > 0.0, axis=1)

    @functools.cached_property
    def row_start(self) -> np.ndarray:
        """(rows,) position of each row's first sub-point among the sub-points with weight."""
        return np.concatenate([[0], np.cumsum(self.row_width)[:-1]])

    @functools.cached_property
    def row_cells(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The area weight of each sub-point row in each cell, sparse: ``(row, weight, start)``
        with one entry per (cell, row) the cell crosses, ordered by cell then row, and
        ``start`` (n^2,) the first entry of each cell (:func:`row_cell_sums`)."""
        weight = self.weight.ravel()
        kept = weight > 0.0
        row = np.repeat(np.arange(self.rows), self.sub_y.shape[1])[kept]
        key = self.cell[kept] * self.rows + row
        keys, inverse = np.unique(key, return_inverse=True)
        sums = np.bincount(inverse, weights=weight[kept], minlength=keys.size)
        cells = keys // self.rows
        return keys % self.rows, sums, np.searchsorted(cells, np.arange(self.n**2))

    @functools.cached_property
    def cell_grid(self) -> np.ndarray:
        """(rows, columns) cell index of each sub-point."""
        return self.cell.reshape(self.sub_y.shape)


def grid_offsets(n: int) -> np.ndarray:
    """FLORIS's turbine-grid offsets in rotor radii: linspace(-1/2, 1/2, n) (0 for n = 1)."""
    return np.zeros(1) if n == 1 else np.linspace(-0.5, 0.5, n)


def _strip_area(a, b):
    """Area of the unit disk between heights a < b."""
    primitive = lambda z: z * np.sqrt(1.0 - z * z) + np.arcsin(z)  # noqa: E731
    return primitive(b) - primitive(a)


def _cell_of(n: int, r: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Cell index (iy * n + iz) of the points at polar (r, phi) of the unit disk."""
    g = grid_offsets(n)
    py, pz = np.meshgrid(g, g, indexing="ij")
    radius = np.round(np.hypot(py, pz).ravel(), 12)
    angle = np.arctan2(pz, py).ravel()
    cell = np.empty(r.shape, dtype=int)
    # Rings inwards out; a ring whose annulus (its share of the area) would not contain its own
    # points' radius joins the ring inside it (n = 3: the edge and corner points form one ring).
    rings = []
    for value in np.unique(radius):
        rings.append([value])
        while len(rings) > 1:
            counts = np.cumsum([np.count_nonzero(np.isin(radius, ring)) for ring in rings])
            inner = np.sqrt(counts[-2] / n**2)
            if min(rings[-1]) >= inner:
                break
            rings[-2:] = [rings[-2] + rings[-1]]
    counts = [np.count_nonzero(np.isin(radius, ring)) for ring in rings]
    bounds = np.sqrt(np.cumsum(counts) / n**2)
    ring_of = np.minimum(np.searchsorted(bounds, r, side="right"), len(rings) - 1)
    for k, ring in enumerate(rings):
        members = np.flatnonzero(np.isin(radius, ring))
        members = members[np.argsort(angle[members])]
        m = members.size
        width = 2.0 * np.pi / m
        # Sector centres at phi0 + j width, phi0 the mean offset of the sorted points (exact
        # for the symmetric rings of a square grid).
        phi0 = np.mean(np.mod(angle[members] - np.arange(m) * width + np.pi, 2 * np.pi) - np.pi)
        inside = ring_of == k
        sector = np.floor(np.mod(phi[inside] - phi0 + 0.5 * width, 2 * np.pi) / width)
        cell[inside] = members[np.minimum(sector.astype(int), m - 1)]
    return cell


#: Resolution of the row sampling that locates the cells' edges along each row (in chords).
_EDGE_SAMPLES = 4096


def _row_intervals(n: int, z: float):
    """The cells crossed by the chord at height ``z``, as (cell, y_start, y_end) in order."""
    chord = np.sqrt(1.0 - z * z)
    edges = np.linspace(-chord, chord, _EDGE_SAMPLES + 1)
    centres = 0.5 * (edges[1:] + edges[:-1])
    label = _cell_of(n, np.hypot(centres, z), np.arctan2(np.full_like(centres, z), centres))
    change = np.flatnonzero(np.diff(label)) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [label.size]])
    return [(label[a], edges[a], edges[b]) for a, b in zip(starts, ends)]


@functools.lru_cache(maxsize=32)
def rotor_cells(n: int, rows: int, nodes_per_interval: int) -> RotorCells:
    """The cells of an n x n turbine grid and their sub-quadrature (cached).

    ``rows`` strips of equal height, each weighted by its exact area of the disk; along the
    chord at the strip's centre, the stretch of each cell it crosses gets ``nodes_per_interval``
    Gauss-Legendre points. Every cell's area is thereby exact to the strips' resolution (it must
    be 1/n^2 of the disk: FLORIS weights the points equally). Rows crossing fewer cells are
    padded with zero-weight points, so that the sub-points form a (rows, columns) array.
    """
    if n < 1 or rows < 1 or nodes_per_interval < 1:
        raise ValueError(
            f"rotor cells need n, rows, nodes_per_interval >= 1; got {n}, {rows}, "
            f"{nodes_per_interval}"
        )
    edges = np.linspace(-1.0, 1.0, rows + 1)
    row_z = 0.5 * (edges[1:] + edges[:-1])
    chord = np.sqrt(1.0 - row_z**2)
    strip = _strip_area(edges[:-1], edges[1:]) / np.pi
    nodes, gl = np.polynomial.legendre.leggauss(nodes_per_interval)
    intervals = [_row_intervals(n, z) for z in row_z]
    columns = nodes_per_interval * max(len(row) for row in intervals)
    sub_y = np.zeros((rows, columns))
    weight = np.zeros((rows, columns))
    cell = np.zeros((rows, columns), dtype=int)
    for r, row in enumerate(intervals):
        for k, (label, a, b) in enumerate(row):
            block = slice(k * nodes_per_interval, (k + 1) * nodes_per_interval)
            sub_y[r, block] = 0.5 * (a + b) + 0.5 * (b - a) * nodes
            weight[r, block] = strip[r] * (b - a) / (2.0 * chord[r]) * 0.5 * gl
            cell[r, block] = label
    cell, weight = cell.ravel(), weight.ravel()
    totals = np.bincount(cell, weights=weight, minlength=n * n)
    if np.any(totals == 0.0):
        raise ValueError(
            f"{rows} sub-quadrature rows leave cells of the {n} x {n} turbine grid empty: use "
            "more rows"
        )
    return RotorCells(n, row_z, sub_y, weight.reshape(sub_y.shape), cell, chord, totals,
                      nodes_per_interval)


def row_cell_sums(values: np.ndarray, cells: RotorCells) -> np.ndarray:
    """sum over rows of ``values`` (..., rows) times each row's area weight in each cell:
    (..., n^2). Cost and memory in proportion to the (cell, row) pairs, not rows x n^2; and a
    segment sum per condition, not a matrix product, so that a condition's numbers do not
    depend on how many others share its batch (BLAS blocks a product by its size)."""
    row, weight, start = cells.row_cells
    weighted = np.take(values, row, axis=-1)
    weighted *= weight
    return np.add.reduceat(weighted, start, axis=-1)


#: Conditions per piece of :func:`cell_mean`: the piece's gathered rows (a few hundred (cell,
#: row) pairs each) stay in cache.
_CELL_PIECE = 128


def cell_mean(u, index, moment: float, cells: RotorCells) -> np.ndarray:
    """<U^m>_k^(1/m) of each cell, (n_findex, n^2) in FLORIS's point order, from U held by
    height (U depends on height only): ``u`` (heights, n_findex), ``index`` (rows,) the height
    of each sub-point row, ``moment`` m (1 or 3).

    Each cell's sum over its (cell, row) pairs is numpy's ``add.reduceat`` segment, as in
    :func:`row_cell_sums` of the rows (n_findex, rows): its pairwise sum runs along the segment
    whatever axis holds it, so the numbers are those of :func:`row_cell_sums` bit for bit.
    Done a piece of conditions at a time, so that the cubes and the gathered rows stay in cache.
    """
    row, weight, start = cells.row_cells
    rows_of_pairs = index[row]
    weight = weight[:, None]
    n_findex = u.shape[1]
    sums = np.empty((start.size, n_findex))
    for c in range(0, n_findex, _CELL_PIECE):
        values = u[:, c:c + _CELL_PIECE]
        if moment != 1.0:
            values = values**3
        weighted = np.take(values, rows_of_pairs, axis=0)
        weighted *= weight
        sums[:, c:c + _CELL_PIECE] = np.add.reduceat(weighted, start, axis=0)
    mean = sums.T / cells.area
    return mean if moment == 1.0 else np.cbrt(mean)


def equivalent_deficit(removed, u_cell, moment) -> np.ndarray:
    """d_k of each cell from the cell's removed moment n^2 sum_{s in k} w_s (U_s^m - u_s^m)
    (m = 3: power; m = 1: the velocity deficit itself): U_k^m (1 - (1 - d_k)^m) = removed.

    ``removed``, ``u_cell`` (the cells' U_k): (..., n^2); ``moment`` (..., 1). A cell without
    inflow (U_k = 0) has no wake.
    """
    cubic = moment == 3.0
    ambient = np.where(cubic, u_cell**3, u_cell)
    flowing = ambient > 0.0
    fraction = np.where(flowing, removed / np.where(flowing, ambient, 1.0), 0.0)
    # The cells' quadrature areas are exact to the strips' resolution (a few per cent for the
    # wake cells): a wake that stops nearly all flow through a cell could exceed it by as much.
    # The cell then has no flow (d = 1) rather than a negative one.
    fraction = np.minimum(fraction, 1.0)
    return np.where(cubic, 1.0 - np.cbrt(1.0 - fraction), fraction)


#: FLORIS's combination models (class names) as the point-wise rules that superpose wake
#: velocities du [m/s] at the cells' sub-points: sum of squares (sosfs), linear sum (fls), max.
COMBINATION_RULES = {"SOSFS": "sosfs", "FLS": "fls", "MAX": "max"}

#: FLORIS's sequential solver counts a rotor point as overlapped by a wake where the wake's
#: velocity there exceeds this [m/s]; the rotor cells take the area of the disk where it does.
WAKE_OVERLAP_VELOCITY = 0.05

_SUPERPOSED = {"sosfs": "sqrt(old**2 + du**2)", "fls": "old + du",
               "max": "where(du > old, du, old)", None: "du"}
# weight (u_old^m - u_new^m) with u = U - wake: the moment the new wake removes at a sub-point.
_REMOVED = ("where(U > 0, weight * where(m > 2, (new - old) * ((U - old)**2 + (U - old) * "
            "(U - new) + (U - new)**2), new - old), 0)")


@attrs.define(eq=False)
class RotorWakes:
    """The wakes superposed so far at the cells' sub-points of every rotor, during one solve.

    FLORIS's solver combines the values the velocity model returns at the grid's points; on
    rotor cells, combining the cells' deficits would combine wakes that do not overlap inside
    a cell as if they did (two bands side by side), and the sum of squares of cube-equivalent
    deficits is not the sum of squares of the velocities. So the wakes are superposed here,
    point-wise at the sub-points by FLORIS's own rule, and each call returns the increment that
    FLORIS's combination of the cell values turns into the cell's exact share of the combined
    wakes' moment (docs/coupling.md#rotor-average). The turbulence at each rotor is the
    wake-added turbulence with the overlap as the area of the disk in the wake.

    Attributes:
        cells: the rotor cells.
        rule: "sosfs", "fls", "max" (FLORIS's combination model), or None: unknown, each call
            returns its own wake's cell deficits.
        combined: (n_findex * n_turbines * sub-points with weight,) combined wake velocity
            [m/s] at the sub-points, row by row (RotorCells.row_start).
        removed: (n_findex * n_turbines, n^2) n^2 sum_{s in k} w_s (U_s^m - u_s^m) of the
            combined wakes.
        wake: (n_findex * n_turbines, n^2) the wake velocity U_k d_k FLORIS holds at each point.
        turbulence: (n_findex, n_turbines) turbulence intensity at each rotor, starting at the
            ambient one.
        turbulence_model: FLORIS's wake-added turbulence model, or None.
    """

    cells: RotorCells
    rule: str | None
    combined: np.ndarray
    removed: np.ndarray
    wake: np.ndarray
    turbulence: np.ndarray
    turbulence_model: object = None

    @classmethod
    def start(cls, cells: RotorCells, n_findex: int, n_turbines: int, wake_models,
              ambient_turbulence) -> RotorWakes:
        """An empty farm for ``wake_models`` (FLORIS's WakeModelManager or None)."""
        rule = None
        turbulence_model = None
        if wake_models is not None:
            rule = COMBINATION_RULES.get(type(wake_models.combination_model).__name__)
            turbulence_model = wake_models.turbulence_model
        pairs = n_findex * n_turbines
        # Single precision: a round-off of 1e-7 of the wake velocity, far below the cells'
        # quadrature error, for half the memory.
        combined = np.zeros(pairs * int(cells.row_width.sum()) if rule else 0, dtype=np.float32)
        turbulence = np.broadcast_to(np.reshape(ambient_turbulence, (-1, 1)),
                                     (n_findex, n_turbines)).copy()
        return cls(cells, rule, combined, np.zeros((pairs, cells.n**2)),
                   np.zeros((pairs, cells.n**2)), turbulence, turbulence_model)

    def superpose(self, pair, row, du, ambient_u, moment) -> np.ndarray:
        """Add one wake at sub-point rows: ``pair`` (entries,) flat rotor index (condition *
        n_turbines + turbine), ``row`` (entries,) the row, ``du`` (entries, w) the wake's velocity
        deficit [m/s] at the row's first w sub-points (w at least each row's width; beyond it,
        the zero-weight padding), ``ambient_u`` (entries, 1) U at
        the row (0 where there is no flow), ``moment`` (entries, 1). Returns (entries, w) the
        moment the wake removes at each sub-point, weight (u_before^m - u_after^m)."""
        cells = self.cells
        width = du.shape[1]
        if self.rule is None:
            old = np.zeros_like(du)
        else:
            columns = np.arange(width)
            flat = (pair * int(cells.row_width.sum()) + cells.row_start[row])[:, None] + columns
            # Rows narrower than ``width`` (padding with zero weight) keep their storage.
            used = columns < cells.row_width[row][:, None]
            if used.all():
                old = self.combined[flat].astype(float)
            else:
                flat = flat[used]
                old = np.zeros(du.shape)
                old[used] = self.combined[flat]
        new = ne.evaluate(_SUPERPOSED[self.rule], local_dict={"old": old, "du": du})
        if self.rule is not None:
            self.combined[flat] = new if used.all() else new[used]
        return ne.evaluate(_REMOVED, local_dict={
            "old": old, "new": new, "U": ambient_u, "weight": cells.weight[row, :width],
            "m": moment})

    def cell_returns(self, pair, removed, u_cell, moment) -> np.ndarray:
        """What the velocity model returns at the cells of rotors ``pair`` (flat indices, each
        once) after its wake was superposed, removing ``removed`` (pairs, n^2) of the cells'
        moment (sum_{s in k} w_s (u_before^m - u_after^m)): the deficit d whose combination by
        FLORIS's rule with the points' current wake velocity gives U_k d_k of the combined
        wakes; ``u_cell`` (pairs, n^2) the cells' U_k, ``moment`` (pairs, 1). Returns
        (pairs, n^2)."""
        removed = self.cells.n**2 * removed
        if self.rule is not None:
            removed += self.removed[pair]
            self.removed[pair] = removed
        total = u_cell * equivalent_deficit(removed, u_cell, moment)
        if self.rule == "sosfs":
            increment = np.sqrt(np.maximum(total**2 - self.wake[pair] ** 2, 0.0))
        elif self.rule == "fls":
            increment = total - self.wake[pair]
        else:  # max, or each wake alone
            increment = total
        if self.rule is not None:
            self.wake[pair] = total
        flowing = u_cell > 0.0
        return np.where(flowing, increment / np.where(flowing, u_cell, 1.0), 0.0)

    def add_turbulence(self, f, j, added, ambient, rule="max") -> None:
        """One wake's added turbulence at rotors (f, j) (each once): ``max`` is FLORIS's
        combination, TI = max(TI, sqrt(added^2 + TI_0^2)); ``quadrature`` adds its variance,
        TI = sqrt(TI^2 + added^2), so that TI^2 = TI_0^2 + the sum over the upstream wakes
        (docs/coupling.md#wakes-deep-in-an-array)."""
        if rule == "quadrature":
            self.turbulence[f, j] = np.hypot(self.turbulence[f, j], added)
        else:
            self.turbulence[f, j] = np.maximum(self.turbulence[f, j], np.hypot(added, ambient))

    def incoming_fraction(self, pair, u_cell) -> np.ndarray:
        """U_i / U_i,0 of rotors ``pair`` (flat indices): the mean over their cells of the
        velocity in the wakes superposed so far, U_k - U_k d_k, over that of the inflow U_k
        (``u_cell``, (pairs, n^2)); 1 for a rotor no wake has reached."""
        ambient = u_cell.sum(axis=1)
        waked = self.wake[pair].sum(axis=1)
        return 1.0 - waked / np.where(ambient > 0.0, ambient, 1.0)


#: Sub-quadrature of the wake cells per point of FLORIS's n x n grid: ROWS_PER_POINT n strips
#: and NODES_PER_INTERVAL points on each cell's stretch of every strip, so that a finer turbine
#: grid (``solver.turbine_grid_points``) also refines the cells' quadrature.
ROWS_PER_POINT, NODES_PER_INTERVAL = 8, 2

#: ...and strips, on the shipped 3 x 3 grid, no thicker than this [m] (a finer or coarser grid
#: refines or coarsens them in proportion, as above): the stable layer's features (its top,
#: where the inflow turns geostrophic, and the veer-sheared wake bands) are tens of metres
#: whatever the rotor, so a larger rotor needs more strips per point. 24 strips over the NREL
#: 5 MW's 126 m (5.25 m) give its single wakes within 0.04 % of the converged reference; the IEA
#: 15 MW's 242 m with 24 strips (10 m) erred by up to 1.1 % (SBL-6, layer top 135 m below its
#: 150 m hub), with 48 by 0.15 % (tests/plugin/test_multiwake.py).
MAX_ROW_SPACING = 126.0 / 24.0


def sub_quadrature(n: int, diameter: float = 0.0) -> tuple[int, int]:
    """(rows, nodes per interval) of the wake cells' sub-quadrature for an n x n turbine grid
    on rotors up to ``diameter`` [m]: ROWS_PER_POINT rows per grid point, more on rotors whose
    3 x 3 grid would have strips thicker than MAX_ROW_SPACING (a geometric choice: the same for
    every condition of a batch)."""
    per_point = int(np.ceil(diameter / (3.0 * MAX_ROW_SPACING) - 1e-9))
    return max(ROWS_PER_POINT, per_point) * n, NODES_PER_INTERVAL


def rotor_geometry(grid):
    """Rotor centres, radii and turbine order of a FLORIS turbine grid, per sorted turbine.

    Returns x, y, z (hub height), radius, each (n_findex, n_turbines), and ``order``, the
    unsorted turbine index of each sorted turbine (FLORIS's ``sorted_indices``).
    """
    order = grid.sorted_indices[:, :, 0, 0]
    x = grid.x_sorted[:, :, 0, 0]
    y = np.mean(grid.y_sorted, axis=(2, 3))
    z = np.mean(grid.z_sorted, axis=(2, 3))
    radius = 0.5 * np.asarray(grid.turbine_diameters, dtype=float)[order]
    return x, y, z, radius, order


def rows_profile(profile, grid, cells: RotorCells):
    """A height profile at the sub-point rows of every kind of rotor (hub height, radius) of
    the farm, evaluated once per distinct row height (one hub height and diameter: ``rows``
    heights, whatever n_findex), so that the work and memory do not grow with the turbines.

    ``profile(z)``, ``z`` shaped (1, 1, 1, heights), returns arrays broadcasting to
    (n_findex, 1, 1, heights). Returns ``kind`` (n_findex, n_turbines), the kind of each sorted
    turbine, ``heights`` (kinds, rows) the rows' heights, and per output of ``profile`` its
    values (n_findex, kinds, rows).
    """
    _, _, _, _, order = rotor_geometry(grid)
    coordinates = np.asarray(grid.turbine_coordinates, dtype=float)
    radius = 0.5 * np.asarray(grid.turbine_diameters, dtype=float)
    kinds, kind_of = np.unique(np.stack([coordinates[:, 2], radius], axis=1), axis=0,
                               return_inverse=True)
    heights = kinds[:, :1] + kinds[:, 1:] * cells.row_z  # (kinds, rows)
    distinct, inverse = np.unique(heights, return_inverse=True)
    inverse = inverse.reshape(heights.shape)
    n_findex = order.shape[0]
    out = []
    for values in profile(distinct.reshape(1, 1, 1, -1)):
        values = np.broadcast_to(values, (n_findex, 1, 1, distinct.size)).reshape(n_findex, -1)
        out.append(values[:, inverse])
    return kind_of.ravel()[order], heights, *out


def row_interpolation(n: int, row_z: np.ndarray) -> np.ndarray:
    """(n, rows) matrix interpolating values at the grid's point heights linearly to the rows
    (constant beyond the outer points): the wake centre of a deflection model that gives it at
    FLORIS's points only."""
    g = grid_offsets(n)
    if n == 1:
        return np.ones((1, row_z.size))
    return np.stack([np.interp(row_z, g, np.eye(n)[k]) for k in range(n)])


def turbine_grid_inflow(profile, grid) -> np.ndarray:
    """u_initial of a FLORIS turbine grid: U_k = <U^m>_k^(1/m) over each rotor cell (m of
    :func:`sorted_moments`).

    ``profile(heights)`` returns the inflow U at 1-D ``heights`` for every condition,
    (heights, n_findex) (or (heights, 1): the same for all). Returns (n_findex, n_turbines,
    n, n). The cells are averaged once per distinct (hub height, radius, m) of the farm and
    gathered to the turbines, so the work and memory do not grow with the number of turbines.
    """
    cells = rotor_cells(grid.grid_resolution, AMBIENT_ROWS, AMBIENT_NODES)
    order = grid.sorted_indices[:, :, 0, 0]
    coordinates = np.asarray(grid.turbine_coordinates, dtype=float)
    radius = 0.5 * np.asarray(grid.turbine_diameters, dtype=float)
    moments = TURBINE_MOMENTS.get()
    if moments is None or len(moments) != radius.size:
        moments = np.full(radius.size, 3.0)
    kinds, kind_of = np.unique(np.stack([coordinates[:, 2], radius, moments], axis=1), axis=0,
                               return_inverse=True)
    heights = kinds[:, :1] + kinds[:, 1:2] * cells.row_z  # (kinds, rows)
    distinct, inverse = np.unique(heights, return_inverse=True)
    inverse = inverse.reshape(heights.shape)
    n_findex = order.shape[0]
    u = np.broadcast_to(profile(distinct), (distinct.size, n_findex))
    means = np.empty((n_findex, len(kinds), cells.n**2))
    for k, moment in enumerate(kinds[:, 2]):
        means[:, k] = cell_mean(u, inverse[k], moment, cells)
    means = means.reshape(n_findex, len(kinds), cells.n, cells.n)
    return np.take_along_axis(means, kind_of.ravel()[order][:, :, None, None], axis=1)


# ------------------------------------------------------------- a wake on the rotor cells
#: A wake starts this far [m] behind its rotor plane. FLORIS passes x_i as the mean of the rotor's
#: points (turbine grids) and rotates sampled points (points and planar grids), so a turbine's own
#: rotor points can lie a round-off (~1e-13 m) downstream of x_i, where the wake is already 2a
#: deep: without the margin a turbine sits in its own wake (tests/plugin/test_models.py). FLORIS's gauss
#: model uses the same 0.1 m.
ROTOR_PLANE_MARGIN = 0.1

#: A sub-point row of a rotor is integrated in a wake where the deficit, with the widest width
#: the wake can have, exceeds this fraction of U_h somewhere on the row; elsewhere the wake is 0
#: (a power change of at most 3e-5 of a turbine that sees no other wake, far less where wakes
#: combine).
NEGLIGIBLE_DEFICIT = 1e-5

#: Rotors whose wake centre is evaluated at their sub-point rows at once.
PAIR_CHUNK = 1024

#: The velocity models' ``wake_expansion`` choices (plugin/models.py): the paper's ambient k_w,
#: and the two that add the upstream wakes' turbulence at a rotor (its largest, as FLORIS
#: combines it; all of them, their variances summed), tracked here on a turbine grid.
WAKE_EXPANSIONS = ("ambient", "local_turbulence", "array_turbulence")
ADDED_TURBULENCE = {"local_turbulence": "max", "array_turbulence": "quadrature"}

#: The velocity models' ``deficit_velocity`` choices: the speed a wake's C(x) scales with.
DEFICIT_VELOCITIES = ("incoming", "free_stream")

#: Sub-point rows (of a rotor in a wake) integrated at once: bounds the sub-point arrays to
#: about 0.3 MB each.
ROW_CHUNK = 4096

#: A sheared band thinner than this many sub-row spacings (its Gaussian width across the band)
#: is no longer integrated to 1 % in power by the rotor cells (benchmarks/bench_rotor_average.py).
MIN_BAND_PER_ROW = 0.4


#: The thread pool of :func:`map_pieces`, per process (a forked worker makes its own: the
#: parent's threads do not exist in it) and number of threads.
_POOL: dict = {}
_POOL_LOCK = threading.Lock()


def worker_threads() -> int:
    """Threads a wake's pieces run on: numexpr's, i.e. the cores FLORIS's gauss runs its sums
    on (``numexpr.set_num_threads`` or NUMEXPR_NUM_THREADS set both)."""
    return ne.get_num_threads()


def map_pieces(function, pieces) -> list:
    """``[function(piece) for piece in pieces]``, on :func:`worker_threads` threads (numpy and
    numexpr release the GIL). A piece's numbers do not depend on the thread that runs it or on
    what runs beside it: the results are the same bit for bit with 1 or N threads."""
    threads = min(worker_threads(), len(pieces))
    if threads <= 1:
        return [function(piece) for piece in pieces]
    key = (os.getpid(), threads)
    with _POOL_LOCK:  # (solves in several threads of a process share the pool)
        pool = _POOL.get(key)
        if pool is None:
            _POOL.clear()  # (another process's or size's pool: not ours to use)
            pool = _POOL[key] = concurrent.futures.ThreadPoolExecutor(
                threads, thread_name_prefix="floris_ekman_veer")
    return list(pool.map(function, pieces))


@attrs.define(frozen=True)
class TurbineWake:
    """Turbine i's quantities at the points where its wake is evaluated (the grid's points, or
    the sub-points of the rotor cells it reaches), as the velocity models take them (radians,
    metres)."""

    dx: np.ndarray
    dy: np.ndarray
    dz: np.ndarray
    yaw: np.ndarray
    ct: np.ndarray
    radius: np.ndarray
    hub_speed: np.ndarray
    k_w: np.ndarray
    local_u: np.ndarray
    local_v: np.ndarray
    friction_velocity: np.ndarray


def rotor_cell_deficit(
    model, x_i, y_i, hub_height_i, deflection_field_i, yaw, ct, radius_i,
    turbulence_intensity_i, axial_induction_i, u_initial, ambient, wakes,
):
    """d_k of every rotor cell of the grid after turbine i's wake (the module docstring), for a
    velocity model's call on a turbine grid (docs/coupling.md#rotor-average).

    Only the sub-point rows of the rotors downstream of turbine i that its wake can reach
    (the deficit above NEGLIGIBLE_DEFICIT U_h somewhere on the row, with the widest possible
    width) are integrated; the wake is 0 elsewhere. The wake is superposed on the others at
    the sub-points (``wakes``, :class:`RotorWakes`) and each reached cell returns the
    increment FLORIS's combination turns into the combined cell deficit; the rest 0.

    ``model`` is the velocity model (plugin/models.py): its ``expansion_rate`` (k_w),
    ``width_bound`` and ``amplitude_bound`` (how far its wake reaches), ``sub_point_deficit``
    (Delta u / U_h of a :class:`TurbineWake`), ``wake_expansion`` and ``deficit_velocity``
    (with "incoming" the wake's velocity is scaled by turbine i's U_i / U_i,0 of the wakes
    superposed so far, docs/coupling.md#wakes-deep-in-an-array). ``ambient`` is the grid's
    :class:`~floris_ekman_veer.plugin.ambient.Ambient` with its ``rotor``, ``wakes`` the solve's
    :class:`RotorWakes`; yaw in radians, ct the model's thrust coefficient.
    """
    rotor = ambient.rotor
    cells = rotor.cells
    n_findex, n_turbines = rotor.x.shape
    result = np.zeros((n_findex, n_turbines, cells.n**2))
    dx = rotor.x - x_i[:, 0, 0]
    f, j = np.nonzero(dx > ROTOR_PLANE_MARGIN)
    if f.size == 0:
        return result.reshape(u_initial.shape)
    abl = ambient.abl
    hub_speed, cos_a, sin_a = ambient.hub_frame(hub_height_i)
    added_rule = ADDED_TURBULENCE.get(model.wake_expansion)
    track = (added_rule is not None and wakes.rule is not None
             and wakes.turbulence_model is not None)
    incoming = model.deficit_velocity == "incoming" and wakes.rule is not None
    if track or incoming:
        # Turbine i among the rotors, per condition.
        source = np.argmin((rotor.x - x_i[:, 0, 0]) ** 2 + (rotor.y - y_i[:, 0, 0]) ** 2,
                           axis=1)
    # U_i / U_i,0 of turbine i: its wake's C(x) scales with the speed it stands in
    # (docs/coupling.md#wakes-deep-in-an-array); 1 for an unwaked rotor.
    speed_fraction = 1.0
    if incoming:
        conditions = np.arange(n_findex)
        speed_fraction = wakes.incoming_fraction(
            conditions * n_turbines + source,
            u_initial.reshape(n_findex, n_turbines, -1)[conditions, source],
        )[:, None, None, None]
    if track:
        # The turbulence at turbine i with the overlaps as areas (RotorWakes).
        turbulence = wakes.turbulence[np.arange(n_findex), source][:, None, None, None]
    else:
        # FLORIS's turbulence at turbine i may vary over its rotor points (wake-added
        # turbulence is counted per point); its wake takes one expansion rate, from the
        # rotor's mean.
        turbulence = np.mean(turbulence_intensity_i, axis=(2, 3), keepdims=True)
    k_w = model.expansion_rate(abl, hub_height_i, hub_speed, turbulence,
                              ambient.floris_turbulence)
    pick = lambda a: np.broadcast_to(a, (n_findex, 1, 1, 1))[f, 0, 0, 0]  # noqa: E731
    per_pair = {
        "yaw": yaw, "ct": ct, "radius": radius_i, "hub_speed": hub_speed, "k_w": k_w,
        "cos": cos_a, "sin": sin_a, "friction_velocity": abl.friction_velocity,
        "speed_fraction": speed_fraction,
    }
    per_pair = {k: pick(v) for k, v in per_pair.items()}
    x_pair = dx[f, j]
    width = model.width_bound(x_pair, per_pair["k_w"], per_pair["radius"], per_pair["ct"],
                             per_pair["yaw"])
    # The deficit C(x) exp(-gap^2 / (2 sigma^2)) stays below NEGLIGIBLE_DEFICIT beyond
    # gap^2 = 2 sigma^2 ln(C / NEGLIGIBLE_DEFICIT).
    amplitude = model.amplitude_bound(x_pair, per_pair["k_w"], per_pair["radius"],
                                     per_pair["ct"], per_pair["yaw"])
    reach_squared = 2.0 * width**2 * np.log(
        np.maximum(amplitude, NEGLIGIBLE_DEFICIT) / NEGLIGIBLE_DEFICIT)
    rows_at = getattr(deflection_field_i, "rows_at", None)
    if rows_at is not None and cells.n > 1:
        # Rotors out of reach by the centre at the grid's points (heights z_h, z_h +- R/2)
        # widened by its spread plus R/4 on either side (the centre at the rows beyond
        # +-R/2, twice the linear extrapolation, and between them) are not integrated and
        # their rows not evaluated.
        # (the n point heights' extremes column by column: numpy's reductions along a short
        # axis cost more than the comparisons)
        points = deflection_field_i[f, j, 0, :].T
        top, bottom = functools.reduce(np.maximum, points), functools.reduce(np.minimum, points)
        margin = top - bottom + 0.25 * rotor.radius[f, j]
        offset = rotor.y[f, j] - y_i[f, 0, 0, 0]
        lateral_gap = np.maximum(np.maximum(offset - top, bottom - offset)
                                 - margin - rotor.radius[f, j], 0.0)
        vertical_gap = np.maximum(np.abs(rotor.z[f, j] - hub_height_i[f, 0, 0, 0])
                                  - rotor.radius[f, j], 0.0)
        near = lateral_gap**2 + vertical_gap**2 < reach_squared
        f, j, x_pair, reach_squared = f[near], j[near], x_pair[near], reach_squared[near]
        per_pair = {k: v[near] for k, v in per_pair.items()}
        if f.size == 0:
            return result.reshape(u_initial.shape)
    if rows_at is None:
        # Another deflection model: its centre at the point rows, interpolated in height.
        # (A sum over the n points, not a matrix product: BLAS would block the product by
        # the number of pairs, i.e. by the batch.)
        centre = np.sum(deflection_field_i[f, j, 0, :, None]
                        * row_interpolation(cells.n, cells.row_z), axis=1)
    else:
        # In chunks of rotors, so that the deflection's temporaries stay small.
        centre = np.concatenate(map_pieces(
            lambda k: rows_at(f[k:k + PAIR_CHUNK], j[k:k + PAIR_CHUNK]),
            range(0, f.size, PAIR_CHUNK)))
    lateral = (rotor.y[f, j] - y_i[f, 0, 0, 0])[:, None] - centre  # (pairs, rows)
    dz = rotor.kind_heights[rotor.kind[f, j]] - hub_height_i[f, 0, 0, 0][:, None]
    kind = rotor.kind[f, j]
    radius_j = rotor.radius[f, j][:, None]
    gap = np.maximum(np.abs(lateral) - radius_j * cells.row_chord, 0.0) ** 2 + dz**2
    # Row by row: only the rows the wake reaches are integrated.
    p, r = np.nonzero(gap < reach_squared[:, None])  # (pair, row) entries
    if p.size == 0:
        return result.reshape(u_initial.shape)
    reached = p[np.flatnonzero(np.diff(p, prepend=-1))]  # p is sorted
    _check_resolution(x_pair[reached], per_pair, reached, centre[reached],
                      radius_j[reached], cells, rotor.warned)
    flat = f * n_turbines + j
    moment = rotor.moment[f, j]
    n2 = cells.n**2
    # Per entry (a pair's row): the moment removed on each cell stretch the row crosses
    # and the row's overlap, summed into the pairs' cells once after the loop, in entry
    # order (a pair's rows in ascending order): a condition's sums then do not depend on
    # the grouping and chunking below, which depend on the whole batch.
    nodes = cells.nodes
    stretches = np.zeros((p.size, cells.sub_y.shape[1] // nodes))
    row_overlap = np.zeros(p.size) if track else None
    # Many rows: rows of equal width (sub-points with weight) together, in chunks, without
    # padding; few: all at once (the padding costs less than more calls).
    widths = cells.row_width[r]
    if p.size <= ROW_CHUNK:
        groups = [np.arange(p.size)]
    else:
        order = np.argsort(widths, kind="stable")
        groups = np.split(order, np.flatnonzero(np.diff(widths[order])) + 1)
    # The deficit's factors that depend on the wake only, once per rotor reached.
    wake_parameters = model.wake_parameters(x_pair, *(per_pair[k] for k in (
        "k_w", "radius", "ct", "yaw", "friction_velocity", "hub_speed")))
    pieces = [(group[start:start + ROW_CHUNK], int(np.max(widths[group])))
              for group in groups for start in range(0, group.size, ROW_CHUNK)]

    def integrate(piece):
        """Superpose the wake on one piece of (pair, row) entries: pieces touch disjoint
        entries and sub-points, so they run at once (:func:`map_pieces`)."""
        chunk, width = piece
        pe, re = p[chunk], r[chunk]
        fe = f[pe]
        pair = {k: v[pe][:, None] for k, v in per_pair.items()}
        u_rows = rotor.kind_u[fe, kind[pe], re][:, None]
        v_rows = rotor.kind_v[fe, kind[pe], re][:, None]
        dy = lateral[pe, re][:, None] + radius_j[pe] * cells.sub_y[re, :width]
        wake = TurbineWake(
            dx=x_pair[pe][:, None],
            dy=dy,
            dz=dz[pe, re][:, None],
            yaw=pair["yaw"],
            ct=pair["ct"],
            radius=pair["radius"],
            hub_speed=pair["hub_speed"],
            k_w=pair["k_w"],
            local_u=u_rows * pair["cos"] + v_rows * pair["sin"],
            local_v=v_rows * pair["cos"] - u_rows * pair["sin"],
            friction_velocity=pair["friction_velocity"],
        )
        # No flow (at and below z0): no wake.
        ambient_u = np.where(wake.local_u > 0, u_rows, 0.0)
        du = model.sub_point_deficit(
            wake, {k: v[pe][:, None] for k, v in wake_parameters.items()},
        ) * (pair["hub_speed"] * pair["speed_fraction"])
        removed = wakes.superpose(flat[pe], re, du, ambient_u, moment[pe][:, None])
        # Each stretch's nodes added in turn: numpy's sum of fewer than 8 numbers, at less
        # cost than a reduction along a short axis.
        stretch = removed[:, ::nodes]
        for node in range(1, nodes):
            stretch = stretch + removed[:, node::nodes]
        stretches[chunk, :width // nodes] = stretch
        if track:
            # FLORIS's overlap: wake velocity above 0.05 m/s within 2 D of the wake's
            # rotor laterally, here as the area of the disk where it holds.
            inside = (du > WAKE_OVERLAP_VELOCITY) & (
                np.abs(dy + centre[pe, re][:, None]) < 4.0 * pair["radius"])
            row_overlap[chunk] = np.sum(cells.weight[re, :width] * inside, axis=1)

    map_pieces(integrate, pieces)
    removed = np.bincount((p[:, None] * n2 + cells.cell_grid[r, ::nodes]).ravel(),
                          weights=stretches.ravel(), minlength=f.size * n2)
    overlap = np.bincount(p, weights=row_overlap, minlength=f.size) if track else None
    u_cell = u_initial.reshape(n_findex, n_turbines, -1)[f[reached], j[reached]]
    result[f[reached], j[reached]] = wakes.cell_returns(
        flat[reached], removed.reshape(f.size, n2)[reached], u_cell,
        moment[reached][:, None])
    if track:
        _add_turbulence(wakes, f[reached], j[reached], x_i, radius_i,
                        axial_induction_i, overlap[reached], ambient, added_rule)
    return result.reshape(u_initial.shape)


def _add_turbulence(wakes, f, j, x_i, radius_i, axial_induction_i, overlap, ambient, rule):
    """FLORIS's wake-added turbulence at rotors (f, j) from turbine i, with the overlap
    the area fraction of the disk (RotorWakes), within 15 D downstream as FLORIS has it,
    combined by ``rule`` (RotorWakes.add_turbulence)."""
    column = lambda a: np.broadcast_to(a, (x_i.shape[0], 1, 1, 1))[f, 0, 0, 0]  # noqa: E731
    x_j, x_source = ambient.rotor.x[f, j], column(x_i)
    diameter = 2.0 * column(radius_i)
    ambient_turbulence = column(ambient.floris_turbulence)
    added = wakes.turbulence_model.function(
        ambient_turbulence, x_j, x_source, diameter, column(axial_induction_i))
    added = overlap * np.nan_to_num(np.asarray(added, dtype=float), posinf=0.0) * (
        x_j <= x_source + 15.0 * diameter)
    wakes.add_turbulence(f, j, added, ambient_turbulence, rule)


def _check_resolution(x, per_pair, reached, centre, radius_j, cells, warned):
    """Warn once per run when a wake band is thinner than the cells' sub-row spacing."""
    if "rows" in warned:
        return
    k_w, radius, ct, yaw = (per_pair[k][reached] for k in ("k_w", "radius", "ct", "yaw"))
    width = k_w * x + WIDTH_FACTOR * radius * np.sqrt(
        stream_tube_area_ratio(ct, yaw)) * np.cos(yaw)
    height = radius_j[:, 0] * (cells.row_z[-1] - cells.row_z[0])
    shear = np.abs(centre[:, -1] - centre[:, 0]) / height
    thickness = width / np.sqrt(1.0 + shear**2)
    spacing = 2.0 * radius_j[:, 0] / cells.rows
    if np.any(thickness < MIN_BAND_PER_ROW * spacing):
        warned.add("rows")
        ratio = float(np.min(thickness / spacing))
        warnings.warn(
            f"a veer-sheared wake band is {ratio:.2f} sub-row spacings thin on a rotor, "
            f"below the {MIN_BAND_PER_ROW} that its rotor-cell average resolves to 1 % in "
            f"power: raise solver.turbine_grid_points (now {cells.n}; the cells' "
            f"sub-quadrature has {cells.rows} rows per rotor, {ROWS_PER_POINT} per grid "
            "point)",
            RuntimeWarning,
            stacklevel=4,
        )
