"""Rotor cells: the area of the rotor disk that each point of FLORIS's turbine grid stands for,
and the inflow's mean over each cell.

FLORIS's ``turbine_grid`` puts n x n points at +-R/2 around each hub and takes the cubic mean of
the n^2 point velocities with equal weights for power and thrust. On the narrow, veer-sheared
wakes of stable nights a point value is not a rotor average (a sheared band a tenth of a rotor
thick falls between the points) and the +-R/2 points miss the strongly curved stable profile
(docs/coupling.md#rotor-average). This module divides the disk into n^2 cells of equal area,
one per point, each with a fine sub-quadrature, so that the inflow hook sets ``u_initial`` at a
point to the cubic mean of the ambient U over its cell, ``U_k = <U^3>_k^(1/3)``
(:func:`cell_mean`, :func:`turbine_grid_inflow`); the wakes are integrated over the same cells
(plugin/rotor/rotor.py, superposed by plugin/rotor/rotor_wakes.py). For a turbine whose operation model
takes the plain mean of u (the actuator disk) the same holds with the first moment in place of
the third (:data:`TURBINE_MOMENTS`). Pure geometry and numpy: no FLORIS import.

The cells: the points are grouped into rings of equal distance from the hub (the centre point of
odd n alone); ring after ring (inwards out) takes an annulus whose area is its share of points
(a ring whose annulus would miss its own points joins the ring inside), and each annulus is
cut into equal sectors centred on its points. For n = 3: a central disk of radius R/3 and eight
45-degree sectors of the annulus R/3 < r < R, all of area pi R^2 / 9.
The sub-quadrature: ``rows`` horizontal strips of equal height h, a row of sub-points at each
strip's mid-height weighted by the strip's exact area of the disk, times Gauss-Legendre points
on each cell's stretch of the row's chord; a sub-point belongs to the cell it lies in. A cell's
quadrature area is exact to the strips' resolution; the wake cells' deficits take the exact
1/n^2 (plugin/rotor/rotor_wakes.py), so FLORIS's mean of the cells is this sub-quadrature's
integral over the disk, whatever the cells.

Why equal strips (measured for issue 41, docs/coupling.md#rotor-average): a smooth band of
deficit is integrated with an error falling as h^2 (the exact strip areas against the chord at
mid-height; order 2.00 from 24 to 96 strips), below 2.1e-4 of the disk mean at the shipped 6 n
strips for n >= 2 [``test_wake_cell_strips_converge_as_the_square_of_their_height``]. That is
not what sets the rotor points a farm's power needs. In the stable layers whose top lies on the
rotor (the SBL-6 farm input: h from 57 to 102 m at 7-11 m/s) the inflow's jet nose there (U
changing by up to 0.5 m/s within 1-2 m)
and the veer deflection x V / U (a wake centre moving by up to a rotor radius within a few
metres below the top) are steps in height, at a height that moves with the condition. A step is
integrated to first order: the whole strip it cuts counts on one side of it
[``test_a_step_in_height_is_integrated_to_the_strip_it_cuts``], so the error is erratic in the
strip count (2 x 2 cells, wakes summed, the worst farm power over the 16 cases of
benchmarks/matched_accuracy.py against 20 x 20: 1.63 % with 16 strips, 1.66 % with 20, 1.17 %
with 24, 0.41 % with 28, 0.54 % with 32, 0.41 % with 48: benchmarks/layer_top_strips.py
``--sweep``). Other rules with the same rows (Gauss-Chebyshev rows, spectral on smooth bands;
two Gauss points per strip; area centroids) did no better there, and the kernel's work goes with
the rows more than with the sub-points (strips staggered between the disk's halves, twice the
heights at the same sub-points, cost as much as more strips), so equal strips stay. The step's
height is known per condition (the layer top h): a strip edge there
(``rotor_cells(..., step_height=...)``) takes the 2 x 2 cells to 0.45 % on the same 16 strips
(benchmarks/layer_top_strips.py), but the strips are shared by every condition of a rotor kind
and h moves with the condition: instead, per condition and rotor kind, the strip that h cuts is
integrated as its two parts below and above h, the part above in one extra row slot per rotor
(:attr:`RotorCells.slots`, plugin/rotor/strip_split.py).
"""

from __future__ import annotations

import contextvars
import functools

import attrs
import numpy as np

#: The moment m of the rotor average that each turbine's power and thrust take: FLORIS's power
#: curves take the cubic mean (m = 3) of the turbine grid; the actuator disk takes the plain
#: mean of u (m = 1, Eq. Ud, plugin/rotor/turbine.py). The cells then carry <U^m>_k^(1/m) and
#: deficits that remove the wake's exact share of <u^m> (docs/coupling.md#rotor-average).
PLAIN_MEAN_OPERATION_MODELS = frozenset({"actuator-disk"})

#: Per unsorted turbine, the moment of the farm being solved (set by the inflow hook's Core
#: wrappers, as the atmosphere is); None: m = 3 for every turbine.
TURBINE_MOMENTS: contextvars.ContextVar = contextvars.ContextVar(
    "rotor_average_moments", default=None
)


#: The wake models of the farm being solved (FLORIS's WakeModelManager, set by the inflow hook's
#: Core wrappers): its combination model says how the cells' sub-points superpose the wakes and
#: its turbulence model gives the wake-added turbulence (plugin/rotor/rotor_wakes.py); None: each call
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
        edges: (rows + 1,) the strips' edges (None: not known).
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
    edges: np.ndarray | None = None

    @property
    def rows(self) -> int:
        return self.row_z.size

    @property
    def slots(self) -> int:
        """Row slots per rotor of the wakes' storage: the rows and one more, for the part above
        a layer top of the strip it cuts (plugin/rotor/strip_split.py)."""
        return self.rows + 1

    @functools.cached_property
    def row_width(self) -> np.ndarray:
        """(rows,) sub-points with weight in each row: the row's first ones (the rest pad)."""
        return np.count_nonzero(self.weight > 0.0, axis=1)

    @functools.cached_property
    def sub_y_columns(self) -> np.ndarray:
        """(columns, rows) :attr:`sub_y` column-major (the wakes' sub-points, plugin/rotor/rotor.py)."""
        return np.ascontiguousarray(self.sub_y.T)

    @functools.cached_property
    def weight_columns(self) -> np.ndarray:
        """(columns, rows) :attr:`weight` column-major."""
        return np.ascontiguousarray(self.weight.T)

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


def strip_area(a, b):
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
def rotor_cells(n: int, rows: int, nodes_per_interval: int,
                step_height: float | None = None) -> RotorCells:
    """The cells of an n x n turbine grid and their sub-quadrature (cached).

    ``rows`` strips of equal height, each weighted by its exact area of the disk; along the
    chord at the strip's centre, the stretch of each cell it crosses gets ``nodes_per_interval``
    Gauss-Legendre points. Every cell's area is thereby exact to the strips' resolution (it must
    be 1/n^2 of the disk: FLORIS weights the points equally). Rows crossing fewer cells are
    padded with zero-weight points, so that the sub-points form a (rows, columns) array.

    ``step_height`` (rotor radii from the hub, inside the disk): the strip edge nearest to it is
    moved there, so that a step in height at a known place (a stable layer's top) is integrated
    by whole strips on either side of it (the module docstring). The package's wake cells do not
    use it: their strips are shared by every condition of a rotor kind, while the layer top
    moves with the condition, so they split the strip it cuts per condition instead
    (plugin/rotor/strip_split.py); benchmarks/layer_top_strips.py compares the two.
    """
    if n < 1 or rows < 1 or nodes_per_interval < 1:
        raise ValueError(
            f"rotor cells need n, rows, nodes_per_interval >= 1; got {n}, {rows}, "
            f"{nodes_per_interval}"
        )
    edges = np.linspace(-1.0, 1.0, rows + 1)
    if step_height is not None and rows > 1:
        if not -1.0 < step_height < 1.0:
            raise ValueError(f"rotor cells: step_height must lie inside the disk (-1, 1) rotor "
                             f"radii from the hub, got {step_height!r}")
        nearest = 1 + int(np.argmin(np.abs(edges[1:-1] - step_height)))
        edges[nearest] = step_height
    row_z = 0.5 * (edges[1:] + edges[:-1])
    chord = np.sqrt(1.0 - row_z**2)
    strip = strip_area(edges[:-1], edges[1:]) / np.pi
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
                      nodes_per_interval, edges)


def row_cell_sums(values: np.ndarray, cells: RotorCells) -> np.ndarray:
    """sum over rows of ``values`` (..., rows) times each row's area weight in each cell:
    (..., n^2). Cost and memory in proportion to the (cell, row) pairs, not rows x n^2; and a
    segment sum per condition, not a matrix product, so that a condition's numbers do not
    depend on how many others share its batch (BLAS blocks a product by its size)."""
    row, weight, start = cells.row_cells
    weighted = np.take(values, row, axis=-1)
    weighted *= weight
    return np.add.reduceat(weighted, start, axis=-1)


def column_sums(values: np.ndarray) -> np.ndarray:
    """The sums of the columns of ``values`` (w, entries), bit for bit numpy's ``np.sum`` of
    each entry's w values held in a row (its pairwise sum: eight running sums from eight
    values on, combined pairwise, the rest added in turn), at the cost of w adds of rows."""
    w = values.shape[0]
    if w < 8:
        return functools.reduce(np.add, values, np.zeros(values.shape[1]))
    sums = list(values[:8])
    start = 8
    while start < w - w % 8:
        sums = [total + value for total, value in zip(sums, values[start:start + 8])]
        start += 8
    total = (((sums[0] + sums[1]) + (sums[2] + sums[3]))
             + ((sums[4] + sums[5]) + (sums[6] + sums[7])))
    return functools.reduce(np.add, values[start:], total)


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


#: Sub-quadrature of the wake cells per point of FLORIS's n x n grid: ROWS_PER_POINT n strips
#: and NODES_PER_INTERVAL points on each cell's stretch of every strip, so that a finer turbine
#: grid (``solver.turbine_grid_points``) also refines the cells' quadrature. 6 strips per point
#: since the strip split integrates the layer top's step (8 before, when the step set the count):
#: the worst farm power of benchmarks/matched_accuracy.py's 16 cases against its own 20 x 20
#: answer is 0.79 % on 2 x 2 cells and 0.60 % on 3 x 3 (8: 0.62 % and 0.66 %), for about a tenth
#: less CPU (docs/coupling.md#rotor-average, docs/performance.md).
ROWS_PER_POINT, NODES_PER_INTERVAL = 6, 2

#: ...and strips, on the shipped 3 x 3 grid, no thicker than this [m] (a finer or coarser grid
#: refines or coarsens them in proportion, as above): the stable layer's features (its top,
#: where the inflow turns geostrophic, and the veer-sheared wake bands) are tens of metres
#: whatever the rotor, so a larger rotor needs more strips per point. 18 strips over the NREL
#: 5 MW's 126 m (7 m); the IEA 15 MW's 242 m with 24 strips (10 m) erred by up to 1.1 % before
#: the strip split (SBL-6, layer top 135 m below its 150 m hub), with 36 (6.7 m) now by 0.12 %
#: on single wakes and 0.25 % on its 4 x 4 farm (tests/plugin/rotor/test_multiwake.py).
MAX_ROW_SPACING = 126.0 / 18.0


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
    kinds, kind = rotor_kinds(grid)
    heights = kinds[:, :1] + kinds[:, 1:] * cells.row_z  # (kinds, rows)
    distinct, inverse = np.unique(heights, return_inverse=True)
    inverse = inverse.reshape(heights.shape)
    n_findex = kind.shape[0]
    out = []
    for values in profile(distinct.reshape(1, 1, 1, -1)):
        values = np.broadcast_to(values, (n_findex, 1, 1, distinct.size)).reshape(n_findex, -1)
        out.append(values[:, inverse])
    return kind, heights, *out


def rotor_kinds(grid) -> tuple[np.ndarray, np.ndarray]:
    """The distinct (hub height, radius) of a FLORIS grid's rotors, (kinds, 2) [m], and the
    kind of each sorted turbine, (n_findex, n_turbines)."""
    _, _, _, _, order = rotor_geometry(grid)
    coordinates = np.asarray(grid.turbine_coordinates, dtype=float)
    radius = 0.5 * np.asarray(grid.turbine_diameters, dtype=float)
    kinds, kind_of = np.unique(np.stack([coordinates[:, 2], radius], axis=1), axis=0,
                               return_inverse=True)
    return kinds, kind_of.ravel()[order]


def height_interpolation(heights: np.ndarray, row_z) -> np.ndarray:
    """(K, *row_z.shape) weights interpolating values at ``heights`` (K,) linearly to the
    heights ``row_z`` (any shape; both in rotor radii from the hub, ``heights`` increasing;
    constant beyond the outer heights)."""
    heights = np.asarray(heights, dtype=float)
    if heights.size == 1:
        return np.ones((1, *np.shape(row_z)))
    return np.stack([np.interp(row_z, heights, np.eye(heights.size)[k])
                     for k in range(heights.size)])


def row_interpolation(n: int, row_z) -> np.ndarray:
    """(n, rows) matrix interpolating values at the grid's point heights linearly to the rows
    (constant beyond the outer points): the wake centre of a deflection model that gives it at
    FLORIS's points only. (``row_z`` of any shape: (n, *row_z.shape).)"""
    return height_interpolation(grid_offsets(n), row_z)


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
