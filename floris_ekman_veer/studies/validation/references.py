"""What a farm's measurements say, as the validation compares it (docs/validation.md#your-own-farm).

:class:`RowReference`: measured power ratios P_i/P_1 along a row of turbines for one wind
direction; :class:`EfficiencyReference`: the farm efficiency against wind direction, each with
its standard error; :class:`DirectionUncertainty`: how uncertain the measured wind direction is
at each turbine. Each is checked when it is built (``checks``): a ValueError or TypeError naming
the field and its valid range.
"""

from __future__ import annotations

import numpy as np
from attrs import define

from floris_ekman_veer._validation import real_array

from floris_ekman_veer.studies.validation.checks import (
    array,
    direction,
    indices,
    scalar,
    text,
    whole_number,
)

#: Measured P_i/P_1 beyond this is not a power ratio (a ratio in percent is refused).
MAX_POWER_RATIO = 1.5
#: Largest direction standard deviation [deg] (and its offset part) the averaging takes: beyond
#: it the +-3 sigma samples span more than a quarter turn.
MAX_DIRECTION_SIGMA = 30.0
#: Largest growth of the direction standard deviation with distance [deg/m] (Horns Rev: 0.00035).
MAX_DIRECTION_GROWTH = 0.01


def _set(instance, name, value):
    object.__setattr__(instance, name, value)  # the classes are frozen; checked values are set once


@define(frozen=True)
class DirectionUncertainty:
    """Standard deviation of the wind direction at each turbine [deg]:
    sigma = sqrt(constant^2 + (offset + growth d)^2), d the distance [m] to ``reference_turbine``
    (growth = offset = 0: one sigma for every turbine). The measured direction is the reference
    turbine's; van der Laan et al. (doi:10.1002/we.1804) use constant 2.5, offset 2.1,
    growth 0.00035 1/m at Horns Rev. ``constant`` and ``offset`` in [0, 30] deg (one of them
    > 0), ``growth`` in [0, 0.01] deg/m."""

    constant: float
    growth: float = 0.0
    offset: float = 0.0
    reference_turbine: int = 0

    def __attrs_post_init__(self):
        for name, high, unit in (("constant", MAX_DIRECTION_SIGMA, "deg"),
                                 ("growth", MAX_DIRECTION_GROWTH, "deg/m"),
                                 ("offset", MAX_DIRECTION_SIGMA, "deg")):
            _set(self, name, scalar(getattr(self, name), f"DirectionUncertainty: {name}",
                                    f"finite, in [0, {high:g}] {unit}",
                                    lambda v, high=high: np.isfinite(v) and 0.0 <= v <= high))
        if self.constant == 0 and self.offset == 0:
            raise ValueError("DirectionUncertainty: constant or offset must be > 0 (a zero sigma "
                             "at the reference turbine); got both 0")
        _set(self, "reference_turbine", whole_number(
            self.reference_turbine, "DirectionUncertainty: reference_turbine",
            ">= 0, a turbine index of the case's layout", lambda i: i >= 0))

    def sigma(self, x, y) -> np.ndarray:
        d = np.hypot(x - x[self.reference_turbine], y - y[self.reference_turbine])
        return np.sqrt((self.growth * d + self.offset) ** 2 + self.constant**2)


@define(frozen=True)
class RowReference:
    """Measured power ratios P_i/P_1 along a row for the wind from ``wind_direction`` [deg,
    in [0, 360]].

    ``turbines``: the turbine indices (of the case's layout) at each position of the row, first
    the upstream one, each index once; -1 marks a gap (a position without a turbine, NaN in the
    tables); a 2-D array (positions, rows) is a mean over parallel rows (Horns Rev's inner-row
    mean). ``measured``: (position, P_i/P_1, standard error) per position
    (``reference_data.read_row_measurements``): positions whole and increasing, P_1/P_1 = 1,
    ratios in [0, 1.5], standard errors >= 0, all finite except at gaps; ``rans``: optional
    (position, raw, direction-averaged) of the same shape."""

    label: str
    wind_direction: float
    turbines: np.ndarray
    measured: np.ndarray
    rans: np.ndarray | None = None

    def __attrs_post_init__(self):
        text(self.label, "RowReference: label")
        owner = f"RowReference {self.label!r}"
        _set(self, "wind_direction", direction(self.wind_direction, f"{owner}: wind_direction"))
        turbines = indices(self.turbines, f"{owner}: turbines",
                           "turbine indices >= 0 of the case's layout, -1 for a gap")
        turbines = np.atleast_2d(turbines.T).T
        if turbines.ndim != 2 or turbines.shape[0] < 2:
            raise ValueError(f"{owner}: turbines must name two positions at least (1-D, or 2-D "
                             f"(positions, rows)); got shape {np.shape(self.turbines)}")
        if turbines.min() < -1:
            raise ValueError(f"{owner}: turbines must be >= 0, or -1 for a gap; got "
                             f"{turbines.min()}")
        if turbines[0].min() < 0:
            raise ValueError(f"{owner}: turbines: the first position must be a turbine (not a gap)")
        placed = turbines[turbines >= 0]
        if np.unique(placed).size != placed.size:
            values, counts = np.unique(placed, return_counts=True)
            raise ValueError(f"{owner}: turbines must name each turbine once; got "
                             f"{values[counts > 1].tolist()} repeated")
        _set(self, "turbines", turbines)
        gaps = self.gaps[:, None]
        shape = (len(turbines), 3)
        for name in ("measured", "rans"):
            value = getattr(self, name)
            if value is None and name == "rans":
                continue
            columns = "standard error" if name == "measured" else "averaged"
            row = f"(position, ratio, {columns})"
            valid = f"{row} rows, finite but at gaps"
            values = real_array(f"{owner}: {name}", value, valid)
            if values.shape != shape:
                raise ValueError(f"{owner}: {name} must have one {row} row per position "
                                 f"({len(turbines)}); got shape {values.shape}")
            _set(self, name, array(values, f"{owner}: {name}", 2, valid,
                                   allow=np.broadcast_to(gaps, shape)))
        positions = self.measured[:, 0]
        if np.any(positions != np.round(positions)) or np.any(np.diff(positions) <= 0):
            raise ValueError(f"{owner}: measured positions (first column) must be whole numbers, "
                             f"increasing; got {positions.tolist()}")
        waked = ~self.gaps
        ratios = self.measured[waked, 1]
        if np.any((ratios < 0) | (ratios > MAX_POWER_RATIO)) or abs(self.measured[0, 1] - 1.0) > 1e-9:
            raise ValueError(f"{owner}: measured P_i/P_1 (second column) must be 1 at the first "
                             f"position and in [0, {MAX_POWER_RATIO:g}] (ratios, not percent); got "
                             f"{ratios.tolist()}")
        if np.any(self.measured[waked, 2] < 0):
            raise ValueError(f"{owner}: measured standard errors (third column) must be >= 0; "
                             f"got {self.measured[waked, 2].tolist()}")

    @property
    def gaps(self) -> np.ndarray:
        return self.turbines[:, 0] < 0


@define(frozen=True)
class EfficiencyReference:
    """Farm power over n unwaked turbines' power against wind direction [deg] (``source``
    names the reference, e.g. an LES or SCADA): ``directions`` in [0, 360], ``efficiency`` in
    (0, 1], ``standard_error`` (of each efficiency, >= 0; None: not known, NaN in the tables),
    1-D arrays of one length."""

    directions: np.ndarray
    efficiency: np.ndarray
    source: str = "reference"
    standard_error: np.ndarray | None = None

    def __attrs_post_init__(self):
        text(self.source, "EfficiencyReference: source")
        owner = f"EfficiencyReference {self.source!r}"
        _set(self, "directions", array(self.directions, f"{owner}: directions", 1,
                                       "finite, in [0, 360] deg", lambda d: (d >= 0) & (d <= 360)))
        n = self.directions.size
        for name, valid, ok in (("efficiency", "finite, in (0, 1]", lambda e: (e > 0) & (e <= 1)),
                                ("standard_error", "finite, >= 0", lambda s: s >= 0)):
            value = getattr(self, name)
            if value is None:
                continue
            values = array(value, f"{owner}: {name}", 1, valid, ok)
            if values.size != n:
                raise ValueError(f"{owner}: {name} must have one value per direction ({n}); got "
                                 f"{values.size}")
            _set(self, name, values)
        if self.efficiency is None:
            raise ValueError(f"{owner}: efficiency must be given (one value per direction)")

    @property
    def standard_errors(self) -> np.ndarray:
        """The standard error at each direction, NaN where not known."""
        if self.standard_error is None:
            return np.full(self.directions.size, np.nan)
        return self.standard_error
