"""An isolated turbine and the arcs of its wake (docs/validation.md#single-wake-cases).

A :class:`SingleWakeCase` is one turbine (its C_T at every speed), its conditions and the
:class:`Arc` s on which references measured or simulated U/U0; the shipped ones read their arcs
from ``reference_data`` by the case's name.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
from attrs import define, field

from floris_ekman_veer.studies.validation.atmospheres import (
    site_roughness_length,
    streamwise_turbulence,
)
from floris_ekman_veer.studies.validation.reference_data import (
    read_measured_arc,
    read_simulated_arc,
)
from floris_ekman_veer.studies.validation.turbines import constant_thrust_turbine


@define(frozen=True)
class Arc:
    """Reference profiles on one arc x/D behind the turbine. Each array has rows
    (relative direction [deg], U/U0[, std of the bin means / U0, number of bins])."""

    x_over_d: float
    measured: np.ndarray | None
    les: np.ndarray | None
    rans: np.ndarray | None


@define(frozen=True)
class SingleWakeCase:
    """One isolated turbine and the arcs of its wake (docs/validation.md#single-wake-cases)."""

    name: str
    wind_speed: float          # U0 at hub height [m/s]
    thrust_coefficient: float  # C_T
    total_turbulence: float    # TI of the velocity magnitude as the references report it
    rotor_diameter: float      # D [m]
    hub_height: float          # z_h [m]
    latitude: float            # [deg]
    offshore: bool
    distances: tuple = field(converter=tuple)  # x/D of the arcs with any reference
    #: The arcs' references; default: read from the shipped data by the case's name.
    reference_arcs: tuple | None = field(default=None)

    @property
    def streamwise_turbulence(self) -> float:
        """I_u at hub height (atmospheres.streamwise_turbulence of the total TI)."""
        return streamwise_turbulence(self.total_turbulence)

    @property
    def site_roughness(self) -> float:
        return site_roughness_length(self.offshore)

    @cached_property
    def arcs(self) -> tuple[Arc, ...]:
        if self.reference_arcs is not None:
            return tuple(self.reference_arcs)
        return tuple(Arc(x, read_measured_arc(self.name, x, self.wind_speed),
                         read_simulated_arc(self.name, "LES", x),
                         read_simulated_arc(self.name, "RANS", x))
                     for x in self.distances)

    @property
    def turbine(self) -> dict:
        return constant_thrust_turbine(self)

    @property
    def layout(self) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros(1), np.zeros(1)
