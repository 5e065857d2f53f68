"""A converged reference of turbine powers where several wakes overlap, independent of the
rotor cells that ship (plugin/rotor/rotor_cells.py); used by tests/plugin/rotor/test_multiwake.py and
benchmarks/bench_rotor_average.py (docs/coupling.md#rotor-average).

FLORIS's own sequential solver runs on a fine grid of point values in the slot of its
``turbine_cubature_grid``: an equal-area polar grid of ``rings`` x ``angles`` points per rotor
(default 32 x 128 = 4,096, and :func:`extrapolated_powers` from it and 64 x 256; ring k at the radius sqrt((k + 1/2) / rings) R that halves its annulus'
area, uniform angles), all of equal weight, and the cubic mean of the point velocities. On point
values FLORIS superposes the wakes point by point (its sosfs rule, sqrt of the sum of squared
wake velocities at every point), counts the wake-added-turbulence overlap as the fraction of the
points with a wake velocity above 0.05 m/s (on 4,096 points: the area fraction) and averages
power and thrust over the points: the disk integral of FLORIS's point-wise rules.
"""

from __future__ import annotations

import contextlib
import copy
import warnings
from pathlib import Path

import numpy as np
import floris
import floris.core.core as floris_core
from floris import FlorisModel
from floris.core import TurbineCubatureGrid
from floris.utilities import load_yaml

import floris_ekman_veer  # noqa: F401  (registers the models)
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning
from tests.conftest import table1_sbl6

INPUTS = Path(__file__).resolve().parents[3] / "inputs"
TURBINE_LIBRARY = Path(floris.__file__).parent / "turbine_library"

#: Atmospheres of the paper's cases (the inputs' blocks): SBL-6 of the farm input, SBL-4 and the
#: neutral CNBL of the paper's single-turbine inputs.
ATMOSPHERES = {"SBL-6": "farm_sbl6.yaml", "SBL-4": "sbl4.yaml", "neutral": "cnbl.yaml"}


def disk_quadrature(n_radial: int = 24, n_angle: int = 96):
    """Unit-disk nodes (y, z) and weights (summing to 1): Gauss-Legendre in r^2, uniform angle."""
    x, w = np.polynomial.legendre.leggauss(n_radial)
    r = np.sqrt(0.5 * (x + 1.0))
    theta = (np.arange(n_angle) + 0.5) * 2.0 * np.pi / n_angle
    rr, tt = np.meshgrid(r, theta, indexing="ij")
    weight = np.outer(0.5 * w, np.full(n_angle, 1.0 / n_angle))
    return (rr * np.cos(tt)).ravel(), (rr * np.sin(tt)).ravel(), weight.ravel()


def equal_area_disk(rings: int, angles: int):
    """Unit-disk points (y, z) of equal area: ``rings`` annuli of equal area, ``angles`` uniform
    sectors each (the point at the area-halving radius and the sector's middle angle)."""
    radius = np.sqrt((np.arange(rings) + 0.5) / rings)
    angle = (np.arange(angles) + 0.5) * 2.0 * np.pi / angles
    r, theta = np.meshgrid(radius, angle, indexing="ij")
    return (r * np.cos(theta)).ravel(), (r * np.sin(theta)).ravel()


def _disk_grid_class(rings: int, angles: int):
    if round(np.sqrt(rings * angles)) ** 2 != rings * angles:
        raise ValueError(f"rings x angles must be a square number; got {rings} x {angles}")
    y_unit, z_unit = equal_area_disk(rings, angles)

    class EqualAreaDiskGrid(TurbineCubatureGrid):
        """FLORIS's cubature-grid slot holding the equal-area polar points (cubic mean)."""

        average_method = "cubic-cubature"

        def __attrs_post_init__(self) -> None:
            self.set_grid()

        def set_grid(self) -> None:
            saved = TurbineCubatureGrid.get_cubature_coefficients
            points = y_unit.size
            # FLORIS reads a cubature grid of resolution N as N^2 points (its turbulence
            # overlap divides the count by N^2): N = sqrt(points).
            side = int(round(np.sqrt(points)))
            coefficients = {"r": np.ones(1), "q": y_unit, "t": z_unit,
                            "A": np.ones(points // side), "B": np.full(points, np.pi / points)}
            try:
                TurbineCubatureGrid.get_cubature_coefficients = classmethod(
                    lambda cls, n: coefficients)
                self.grid_resolution = side
                super().set_grid()
            finally:
                TurbineCubatureGrid.get_cubature_coefficients = saved

    return EqualAreaDiskGrid


@contextlib.contextmanager
def _equal_area_disk_grids(rings: int, angles: int):
    saved = floris_core.TurbineCubatureGrid
    floris_core.TurbineCubatureGrid = _disk_grid_class(rings, angles)
    try:
        yield
    finally:
        floris_core.TurbineCubatureGrid = saved


def farm_config(atmosphere: str = "SBL-6", turbine: str = "nrel_5MW", layout=((0.0,), (0.0,)),
                wind_speed: float = 9.0) -> dict:
    """The farm input (M-1, crespo_hernandez, 3 x 3 rotor cells) with the coupling FLORIS's
    point-wise solver expresses (free-stream wakes, sosfs, the largest upstream wake's added
    turbulence: ``local_turbulence``, counted where the wake's velocity exceeds 0.05 m/s:
    ``turbulence_overlap: wake_velocity``), ``atmosphere``'s block, ``turbine`` (FLORIS's library) and
    ``layout`` (x, y) in rotor diameters; the reference wind height is the turbine's hub
    height."""
    config = load_yaml(INPUTS / "farm_sbl6.yaml")
    config["wake"]["model_strings"]["combination_model"] = "sosfs"
    config["wake"]["wake_velocity_parameters"]["ekman_veer"].update(
        wake_expansion="local_turbulence", deficit_velocity="free_stream",
        turbulence_overlap="wake_velocity")
    block = load_yaml(INPUTS / ATMOSPHERES[atmosphere])["wake"]["wake_velocity_parameters"]
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"] = copy.deepcopy(
        block["ekman_veer"]["atmosphere"])
    if atmosphere == "SBL-6":  # Table 1's state, h above the hub (tests.conftest.table1_sbl6)
        config = table1_sbl6(config)
    config["farm"]["turbine_type"] = [turbine]
    definition = load_yaml(TURBINE_LIBRARY / f"{turbine}.yaml")
    diameter = float(definition["rotor_diameter"])
    config["flow_field"]["reference_wind_height"] = float(definition["hub_height"])
    config["flow_field"]["wind_speeds"] = [wind_speed]
    config["farm"]["layout_x"] = [float(x) * diameter for x in layout[0]]
    config["farm"]["layout_y"] = [float(y) * diameter for y in layout[1]]
    return config


def _run(config: dict, set_kwargs: dict) -> FlorisModel:
    with warnings.catch_warnings():
        # Resolution advice for cubature grids does not apply to 4,096 points.
        warnings.simplefilter("ignore", RuntimeWarning)
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)  # said by the inputs
        fmodel = FlorisModel(copy.deepcopy(config))
        fmodel.set(**copy.deepcopy(set_kwargs))
        fmodel.run()
    return fmodel


def reference_powers(config: dict, set_kwargs: dict | None = None, rings: int = 32,
                     angles: int = 128) -> np.ndarray:
    """Turbine powers (n_findex, n_turbines) [W] of FLORIS's point-wise rules on the fine
    equal-area disk grid of every rotor (module docstring)."""
    config = copy.deepcopy(config)
    config["solver"] = {"type": "turbine_cubature_grid", "turbine_grid_points": 3}
    with _equal_area_disk_grids(rings, angles):
        fmodel = _run(config, set_kwargs or {})
        return fmodel.get_turbine_powers()


def extrapolated_powers(config: dict, set_kwargs: dict | None = None, rings: int = 32,
                        angles: int = 128) -> np.ndarray:
    """The reference extrapolated to infinitely many points (Richardson): the equal-area grid's
    midpoint rule errs as h^2 in the point spacing h (the error falls fourfold from 32 x 128 to
    64 x 256 points; tests/plugin/rotor/test_multiwake.py::test_reference_is_converged), so
    P = P_2h' + (P_h - P_2h) / 3 with h halved in rings and angles. 32 x 128 alone is off by up
    to 0.04 % (single wakes) and 0.17 % (where wakes overlap); this by 0.002 %."""
    coarse = reference_powers(config, set_kwargs, rings, angles)
    fine = reference_powers(config, set_kwargs, 2 * rings, 2 * angles)
    return fine + (fine - coarse) / 3.0


def shipped_powers(config: dict, set_kwargs: dict | None = None) -> np.ndarray:
    """Turbine powers with the solver settings as given (the shipped: 3 x 3 rotor cells)."""
    return _run(config, set_kwargs or {}).get_turbine_powers()


def power_errors(config: dict, set_kwargs: dict | None = None, **reference) -> np.ndarray:
    """P / P_ref - 1 per condition and turbine, P_ref extrapolated (:func:`extrapolated_powers`)."""
    return shipped_powers(config, set_kwargs) / extrapolated_powers(config, set_kwargs,
                                                                    **reference) - 1.0


# Layouts (x, y) in rotor diameters, wind from 270 degrees along +x.
SIDE_BY_SIDE = ((0.0, 0.0, 7.0), (-0.6, 0.6, 0.0))
def row(spacing: float, turbines: int = 5):
    return (tuple(spacing * k for k in range(turbines)), (0.0,) * turbines)


FARM_3X3 = ((0, 0, 0, 7, 7, 7, 14, 14, 14), (0, 7, 14, 0, 7, 14, 0, 7, 14))
