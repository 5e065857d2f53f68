"""The ambient atmosphere at a FLORIS grid, evaluated once per solve and shared by the wake
models of that solve (plugin/wake_models/models.py): the solved atmosphere (the inflow hook's,
plugin/inflow/inflow.py), its (U, V) at the grid's points or, on a turbine grid, at the rows of the
rotor cells (plugin/rotor/rotor.py), and the hub-height wind of each distinct hub height of the farm
(docs/coupling.md#call-signatures, docs/conventions.md#hub-aligned-frame).
"""

from __future__ import annotations

import weakref
from types import SimpleNamespace
from typing import Any

import numpy as np
from attrs import define, field
from floris.core import FlowField, Grid, TurbineCubatureGrid, TurbineGrid
from floris.utilities import rotate_coordinates_rel_west

from floris_ekman_veer.plugin.inflow.inflow import ambient_velocity, solved_atmosphere
from floris_ekman_veer.plugin.rotor.strip_split import StripSplit
from floris_ekman_veer.plugin.rotor.rotor_cells import (
    RotorCells,
    rotor_cells,
    rotor_geometry,
    rotor_kinds,
    rows_profile,
    sorted_moments,
    sub_quadrature,
)
from floris_ekman_veer.plugin.rotor.upstream_wakes import DEFICIT_HEIGHTS

#: The latest Ambient, keyed by the identities of its grid, flow field and inflow array.
_AMBIENTS: dict = {}


@define(frozen=True)
class Ambient:
    """The ambient atmosphere of one FLORIS grid, evaluated once per model preparation.

    Holds the ABL, the ambient (U, V) at the grid in FLORIS's frame (aligned with the wind at the
    reference height; 0 below the roughness length), and the hub-height speed and direction at
    each distinct hub height of the farm, so that no wake evaluates the profile again.

    FLORIS's deflection call carries no hub height (docs/coupling.md#call-signatures). Every grid holds the farm's
    ``turbine_coordinates`` (x, y, hub height) and rotates points about the centre of the farm's
    bounding box, as done here, so the turbine whose wake is computed is the one at (x_i, y_i).
    """

    abl: Any
    u: np.ndarray
    v: np.ndarray
    hub_heights: np.ndarray  # distinct hub heights of the farm, sorted
    hub_speed: np.ndarray  # (n_findex, n_hub_heights)
    hub_cos: np.ndarray  # direction of the hub-height wind in FLORIS's frame
    hub_sin: np.ndarray
    turbine_x: np.ndarray  # rotated turbine positions, (n_findex, n_turbines)
    turbine_y: np.ndarray
    turbine_hub_heights: np.ndarray  # (n_turbines,)
    floris_turbulence: np.ndarray  # FLORIS's ambient turbulence intensity, (n_findex, 1, 1, 1)
    rotor: RotorAmbient | None = None  # turbine grids: the rotor cells (plugin/rotor/rotor.py)
    #: Cubature grids: points per rotor side N (FLORIS's quadrature of point values), else None.
    cubature_points: int | None = None
    warned: set = field(factory=set)  # resolution warnings already given in this solve

    @classmethod
    def of(cls, grid: Grid, flow_field: FlowField) -> Ambient:
        """The ambient of ``grid`` for ``flow_field``'s current inflow, shared by the velocity
        and deflection models of one solve (built once per flow-field initialisation)."""
        key = (id(grid), id(flow_field), id(flow_field.u_initial_sorted))
        cached = _AMBIENTS.get(key)
        if cached is not None and cached[0]() is grid and cached[1]() is flow_field:
            return cached[2]
        ambient = cls._build(grid, flow_field)
        _AMBIENTS.clear()  # one solve at a time: keep only the latest
        _AMBIENTS[key] = (weakref.ref(grid), weakref.ref(flow_field), ambient)
        return ambient

    @classmethod
    def _build(cls, grid: Grid, flow_field: FlowField) -> Ambient:
        abl = solved_atmosphere(flow_field)
        reference_height = flow_field.reference_wind_height
        coordinates = np.asarray(grid.turbine_coordinates, dtype=float)
        hub_heights = np.unique(coordinates[:, 2])
        u_hub, v_hub = abl.hub_aligned_velocity(hub_heights.reshape(1, 1, 1, -1), reference_height)
        speed = np.hypot(u_hub, v_hub)
        x, y, _, _, _ = rotate_coordinates_rel_west(flow_field.wind_directions, coordinates)
        n_findex = len(flow_field.wind_directions)
        shape = (n_findex, hub_heights.size)
        rotor = RotorAmbient.of(grid, abl, reference_height) if is_rotor_grid(grid) else None
        if rotor is None:
            u, v = ambient_velocity(abl, grid.z_sorted, reference_height)
        else:
            # The cell path needs the ambient at the sub-point rows only; the deflection model's
            # point values (for models that read them) need it at the grid's heights, which on a
            # turbine grid are those of the rotor's point rows.
            u, v = ambient_velocity(abl, grid.z_sorted[:, :, :1, :], reference_height)
        return cls(
            abl, u, v, hub_heights,
            *(np.broadcast_to(a, (n_findex, 1, 1, hub_heights.size)).reshape(shape)
              for a in (speed, u_hub / speed, v_hub / speed)),
            x, y, coordinates[:, 2],
            np.asarray(flow_field.turbulence_intensities, dtype=float).reshape(-1, 1, 1, 1),
            rotor, grid.grid_resolution if isinstance(grid, TurbineCubatureGrid) else None,
        )

    def hub_height_at(self, x_i, y_i):
        """Hub height of the turbine at (x_i, y_i) (shapes (n_findex, 1, 1, 1))."""
        if self.hub_heights.size == 1:
            # One hub height in the farm: the search would find it whatever the turbine.
            return np.full((self.turbine_x.shape[0], 1, 1, 1), self.hub_heights[0])
        distance = (self.turbine_x - x_i[:, 0, 0]) ** 2 + (self.turbine_y - y_i[:, 0, 0]) ** 2
        return self.turbine_hub_heights[np.argmin(distance, axis=1)][:, None, None, None]

    def hub_frame(self, hub_height):
        """U_h and the direction (cos, sin) of the wind at ``hub_height`` in FLORIS's frame
        (shapes (n_findex, 1, 1, 1))."""
        if np.any(hub_height <= self.abl.roughness_length):
            raise ValueError("hub_height must be above the atmosphere's roughness_length")
        rows = np.arange(hub_height.shape[0])
        column = np.searchsorted(self.hub_heights, hub_height[:, 0, 0, 0])
        pick = lambda table: table[rows, column][:, None, None, None]  # noqa: E731
        return pick(self.hub_speed), pick(self.hub_cos), pick(self.hub_sin)

    def at_hub(self, hub_height):
        """U_h and the ambient (U, V) at the grid in the frame where V(hub_height) = 0
        (docs/conventions.md#hub-aligned-frame): FLORIS's frame rotated by the hub-height direction."""
        hub_speed, cos_a, sin_a = self.hub_frame(hub_height)
        u = self.u * cos_a + self.v * sin_a
        v = self.v * cos_a - self.u * sin_a
        return hub_speed, u, v


def is_rotor_grid(grid: Grid) -> bool:
    """FLORIS's turbine grid (n x n points per rotor, equal-weight cubic mean): the grid on which
    the models return rotor-cell averages (docs/coupling.md#rotor-average)."""
    return isinstance(grid, TurbineGrid)


@define(frozen=True)
class RotorAmbient:
    """The rotor cells of a turbine grid (plugin/rotor/rotor.py) and the ambient at their rows.

    Per sorted turbine (n_findex, n_turbines): rotor centre ``x``, ``y``, hub height ``z``,
    radius and ``kind`` (distinct hub height and radius); per kind and sub-point row: height
    (kinds, rows) and the ambient (U, V) in FLORIS's frame (n_findex, kinds, rows; U is
    FLORIS's inflow component, V the lateral one); ``split`` the strip each condition's layer
    top cuts on each kind (plugin/rotor/strip_split.py); the same at the heights where the
    cumulative wake takes its centre deficits (plugin/rotor/upstream_wakes.py DEFICIT_HEIGHTS):
    ``deficit_heights`` (kinds, K), ``deficit_u``, ``deficit_v`` (n_findex, kinds, K).
    """

    cells: RotorCells
    moment: np.ndarray  # (n_findex, n_turbines): 3 (cubic mean) or 1 (plain mean), rotor.py
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    radius: np.ndarray
    kind: np.ndarray
    kind_heights: np.ndarray
    kind_u: np.ndarray
    kind_v: np.ndarray
    split: StripSplit
    deficit_heights: np.ndarray
    deficit_u: np.ndarray
    deficit_v: np.ndarray
    warned: set = field(factory=set)

    @classmethod
    def of(cls, grid: Grid, abl, reference_height) -> RotorAmbient:
        cells = rotor_cells(grid.grid_resolution, *sub_quadrature(
            grid.grid_resolution, float(np.max(grid.turbine_diameters))))
        x, y, z, radius, _ = rotor_geometry(grid)
        profile = lambda heights: ambient_velocity(abl, heights, reference_height)  # noqa: E731
        kind, heights, u, v = rows_profile(profile, grid, cells)
        kinds, _ = rotor_kinds(grid)
        # (conditions at rest have no layer top)
        top = np.where(abl.at_rest, np.inf, np.reshape(abl.boundary_layer_height, -1))
        split = StripSplit.of(cells, kinds[:, 0], kinds[:, 1],
                              np.broadcast_to(top, x.shape[:1]), profile)
        # (rows_profile reads the rows' heights only.)
        _, deficit_heights, deficit_u, deficit_v = rows_profile(
            profile, grid, SimpleNamespace(row_z=DEFICIT_HEIGHTS))
        # (contiguous: every wake step's compiled passes and gathers read them)
        contiguous = np.ascontiguousarray
        return cls(cells, sorted_moments(grid), contiguous(x), y, z, radius, kind, heights,
                   contiguous(u), contiguous(v), split, deficit_heights, contiguous(deficit_u),
                   contiguous(deficit_v))

    def rows(self, f, j):
        """Heights and ambient (U, V) at the sub-point rows of rotors (f, j): (pairs, rows)."""
        kind = self.kind[f, j]
        return self.kind_heights[kind], self.kind_u[f, kind], self.kind_v[f, kind]
