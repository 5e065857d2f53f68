"""A farm, its conditions and its measured references: the public door for any farm
(docs/validation.md#your-own-farm).

A :class:`FarmCase` is a layout (any projected coordinates in metres), a FLORIS turbine (or one
built by ``turbines.turbine_from_table``), the conditions (hub-height speed, hub-height
streamwise TI or an atmosphere, the wind-direction uncertainty) and the references
(``references``). Everything is checked when the case is built: each field's type and range,
every row's turbines in the layout and standing one behind the other for its wind direction,
the atmosphere solvable and the turbulence reachable by the "matched" reading; a ValueError or
TypeError names the case and the field (docs/validation.md#bad-input).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from attrs import define, field

from floris_ekman_veer._validation import boolean
from floris_ekman_veer.atmosphere.inputs.input_ranges import MIN_ABS_LATITUDE
from floris_ekman_veer.studies.validation.atmospheres import (
    ROUGHNESS_RANGE,
    hub_turbulence,
    matched_turbulence_range,
    site_roughness_length,
)
from floris_ekman_veer.studies.validation.checks import array, instance, scalar, text
from floris_ekman_veer.studies.validation.references import (
    MAX_DIRECTION_SIGMA,
    DirectionUncertainty,
    EfficiencyReference,
    RowReference,
)
from floris_ekman_veer.studies.validation.turbines import MAX_SPEED, checked_turbine

#: The measurements' direction bin around each row's direction [deg] the model averages over.
DIRECTION_OFFSETS = (-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0)
#: Largest offset of a direction bin [deg].
MAX_DIRECTION_OFFSET = 30.0


def _set(instance_, name, value):
    object.__setattr__(instance_, name, value)  # frozen: each checked value is set once


@define(frozen=True)
class FarmCase:
    """A farm, its conditions and its measured references (docs/validation.md#your-own-farm).

    ``turbulence`` is the hub-height streamwise TI I_u in (0, 1) (a published total TI converts
    with ``atmospheres.streamwise_turbulence``; the "matched" atmosphere reaches it, the "site"
    one takes the roughness ``site_roughness``); or give ``atmosphere`` (an
    ``ekman_veer.atmosphere`` block, the "given" reading). ``offshore`` (required, keyword):
    the "site" reading's roughness, open sea or farmland, unless ``roughness_length`` [m] gives
    it. The model is averaged over the wind directions ``row direction + direction_offsets``
    (the measurements' bin) and, in the "averaged" results, over ``direction_uncertainty``."""

    name: str
    layout: tuple
    turbine: dict
    wind_speed: float
    latitude: float
    turbulence: float | None = None
    direction_uncertainty: DirectionUncertainty | None = None
    rows: tuple = ()
    efficiency: EfficiencyReference | None = None
    direction_offsets: tuple = DIRECTION_OFFSETS
    atmosphere: dict | None = None
    roughness_length: float | None = None
    offshore: bool = field(kw_only=True)

    def __attrs_post_init__(self):
        text(self.name, "FarmCase: name")
        owner = f"FarmCase {self.name!r}"
        self._check_layout(owner)
        _set(self, "turbine", checked_turbine(self.turbine, owner))
        _set(self, "offshore", boolean(self.offshore, f"{owner}: offshore"))
        _set(self, "wind_speed", scalar(self.wind_speed, f"{owner}: wind_speed",
                                        f"finite, in (0, {MAX_SPEED:g}) m/s",
                                        lambda u: np.isfinite(u) and 0.0 < u < MAX_SPEED))
        table = self.turbine["power_thrust_table"]
        if not np.interp(self.wind_speed, table["wind_speed"], table["power"]) > 0.0:
            raise ValueError(f"{owner}: wind_speed must be where the turbine produces power (its "
                             f"table's power > 0); got {self.wind_speed:g} m/s")
        _set(self, "latitude", scalar(
            self.latitude, f"{owner}: latitude",
            f"{MIN_ABS_LATITUDE:g} <= |latitude| <= 90 deg, negative in the south",
            lambda lat: np.isfinite(lat) and MIN_ABS_LATITUDE <= abs(lat) <= 90.0))
        if self.roughness_length is not None:
            _set(self, "roughness_length", scalar(
                self.roughness_length, f"{owner}: roughness_length",
                f"in [{ROUGHNESS_RANGE[0]:g}, {ROUGHNESS_RANGE[1]:g}] m",
                lambda z: np.isfinite(z) and ROUGHNESS_RANGE[0] <= z <= ROUGHNESS_RANGE[1]))
        self._check_atmosphere(owner)
        offsets = array(self.direction_offsets, f"{owner}: direction_offsets", 1,
                        f"finite, within +-{MAX_DIRECTION_OFFSET:g} deg",
                        lambda o: np.abs(o) <= MAX_DIRECTION_OFFSET)
        _set(self, "direction_offsets", tuple(float(o) for o in offsets))
        instance(self.efficiency, f"{owner}: efficiency", EfficiencyReference, optional=True)
        self._check_direction_uncertainty(owner)
        self._check_rows(owner)

    def _check_layout(self, owner):
        if not isinstance(self.layout, (tuple, list)) or len(self.layout) != 2:
            raise TypeError(f"{owner}: layout must be a pair (x, y) of 1-D arrays [m]; got "
                            f"{self.layout!r}")
        x, y = (array(v, f"{owner}: layout {axis}", 1, "finite [m]")
                for v, axis in zip(self.layout, "xy"))
        if x.shape != y.shape:
            raise ValueError(f"{owner}: layout x and y must be of one length; got {x.size} and "
                             f"{y.size}")
        _set(self, "layout", (x, y))

    def _check_spacing(self, owner):
        x, y = self.layout
        distance = np.hypot(x[:, None] - x[None, :], y[:, None] - y[None, :])
        np.fill_diagonal(distance, np.inf)
        if distance.size and distance.min() < self.rotor_diameter:
            i, j = np.unravel_index(np.argmin(distance), distance.shape)
            raise ValueError(f"{owner}: layout: turbines {i} and {j} stand {distance[i, j]:.3g} m "
                             f"apart, less than the rotor diameter {self.rotor_diameter:g} m "
                             "(a repeated position?)")

    def _check_atmosphere(self, owner):
        if self.turbulence is None and self.atmosphere is None:
            raise ValueError(f"{owner}: give turbulence (hub-height I_u) or atmosphere")
        if self.atmosphere is not None:
            if not isinstance(self.atmosphere, Mapping):
                raise TypeError(f"{owner}: atmosphere must be an ekman_veer.atmosphere block (a "
                                f"dict); got {self.atmosphere!r}")
            try:
                hub_turbulence(self, dict(self.atmosphere))
            except (TypeError, ValueError) as error:
                raise type(error)(f"{owner}: atmosphere: {error}") from None
        if self.turbulence is not None:
            _set(self, "turbulence", scalar(self.turbulence, f"{owner}: turbulence",
                                            "the streamwise I_u(z_h), in (0, 1)",
                                            lambda ti: 0.0 < ti < 1.0))
            low, high = matched_turbulence_range(self)
            if not low <= self.turbulence <= high:
                raise ValueError(
                    f"{owner}: turbulence must be an I_u(z_h) a neutral ABL reaches at this speed, "
                    f"hub height and latitude, in [{low:.3g}, {high:.3g}] (z0 in "
                    f"{ROUGHNESS_RANGE} m); got {self.turbulence!r}")

    def _check_direction_uncertainty(self, owner):
        uncertainty = instance(self.direction_uncertainty, f"{owner}: direction_uncertainty",
                               DirectionUncertainty, optional=True)
        if uncertainty is None:
            return
        n = self.layout[0].size
        if uncertainty.reference_turbine >= n:
            raise ValueError(f"{owner}: direction_uncertainty.reference_turbine must be a turbine "
                             f"of the layout, in [0, {n - 1}]; got {uncertainty.reference_turbine}")
        sigma = self.direction_sigma()
        if sigma.max() > MAX_DIRECTION_SIGMA:
            raise ValueError(f"{owner}: direction_uncertainty gives sigma up to "
                             f"{sigma.max():.3g} deg over the layout; it must stay <= "
                             f"{MAX_DIRECTION_SIGMA:g} deg")

    def _check_rows(self, owner):
        if not isinstance(self.rows, (tuple, list)) or not all(
                isinstance(r, RowReference) for r in self.rows):
            raise TypeError(f"{owner}: rows must be a tuple of RowReference; got {self.rows!r}")
        _set(self, "rows", tuple(self.rows))
        self._check_spacing(owner)
        x, y = self.layout
        for row in self.rows:
            if row.turbines.max() >= x.size:
                raise ValueError(f"{owner}: row {row.label!r}: turbine index "
                                 f"{row.turbines.max()} beyond the layout's {x.size} turbines")
            # The distance downwind of each turbine for the wind from the row's direction.
            theta = np.radians(row.wind_direction)
            downwind = -(x * np.sin(theta) + y * np.cos(theta))
            for column in row.turbines.T:
                placed = column[column >= 0]
                step = np.diff(downwind[placed])
                if np.any(step <= 0.0):
                    k = int(np.argmax(step <= 0.0))
                    raise ValueError(
                        f"{owner}: row {row.label!r}: the turbines must stand one behind the "
                        f"other, the first upstream, for the wind from {row.wind_direction:g} deg; "
                        f"turbine {placed[k + 1]} is not downwind of turbine {placed[k]} (is the "
                        "wind_direction in degrees, the row in order?)")

    @property
    def rotor_diameter(self) -> float:
        return float(self.turbine["rotor_diameter"])

    @property
    def hub_height(self) -> float:
        return float(self.turbine["hub_height"])

    @property
    def streamwise_turbulence(self) -> float:
        return self.turbulence

    @property
    def site_roughness(self) -> float:
        if self.roughness_length is not None:
            return self.roughness_length
        return site_roughness_length(self.offshore)

    def direction_sigma(self) -> np.ndarray:
        """Per-turbine standard deviation of the wind direction [deg]."""
        if self.direction_uncertainty is None:
            raise ValueError(f"FarmCase {self.name!r}: direction_uncertainty is None; the "
                             "direction average needs one (e.g. DirectionUncertainty(3.0))")
        return self.direction_uncertainty.sigma(*self.layout)

    @property
    def thrust_coefficient(self) -> float:
        """The turbine's C_T at the case's wind speed."""
        table = self.turbine["power_thrust_table"]
        return float(np.interp(self.wind_speed, table["wind_speed"], table["thrust_coefficient"]))
