"""The validation cases and their reference data (measured, LES, RANS).

The data ship in ``floris_ekman_veer/studies/validation/data/`` (DTU PyWake's validation data, MIT
licence; attribution and the original studies in that folder's README.md and in
docs/validation.md#measured-wakes-and-farms). This module only reads them: each single-wake case
is a :class:`SingleWakeCase` with its arcs, Horns Rev 1 a :class:`HornsRevCase`.
"""

from __future__ import annotations

from functools import cached_property
from pathlib import Path

import numpy as np
from attrs import define, field

DATA = Path(__file__).resolve().parent / "data"

#: Relative wind directions compared on each arc [deg]: +-30, the span of the LES and RANS.
ARC_HALF_WIDTH = 30.0
#: Streamwise over total turbulence intensity of the single-wake references (PyWake's reading,
#: I_u = TI_total / 0.8).
STREAMWISE_FRACTION = 0.8
#: Roughness lengths of the "site" atmospheres [m]: open sea and open farmland.
SEA_ROUGHNESS = 2.0e-4
LAND_ROUGHNESS = 0.03


def _read(path: Path) -> np.ndarray:
    return np.atleast_2d(np.loadtxt(path, comments="#"))


def _distance_label(x_over_d: float) -> str:
    return (f"{x_over_d:g}").replace(".", "p")


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

    @property
    def streamwise_turbulence(self) -> float:
        """I_u at hub height, TI_total / 0.8."""
        return self.total_turbulence / STREAMWISE_FRACTION

    @property
    def site_roughness(self) -> float:
        return SEA_ROUGHNESS if self.offshore else LAND_ROUGHNESS

    def _file(self, kind: str, x_over_d: float) -> Path:
        return DATA / f"{self.name}_{kind}_{_distance_label(x_over_d)}D.dat"

    def _measured(self, x_over_d: float) -> np.ndarray | None:
        path = self._file("data", x_over_d)
        if not path.is_file():
            return None
        data = _read(path)
        if self.name.startswith("Wieringermeer"):
            # Absolute wind direction and speed [m/s]: centre the direction, normalise by U0.
            centre = 315.0 if self.name.endswith("West") else 31.0
            data = np.column_stack([data[:, 0] - centre, data[:, 1:3] / self.wind_speed, data[:, 3]])
        elif self.name == "Nordtank-500":
            # Columns: direction, y [m], U/U0, std; 74 ten-minute means per point (file header).
            data = np.column_stack([data[:, 0], data[:, 2], data[:, 3], np.full(len(data), 74.0)])
        return data[np.abs(data[:, 0]) <= ARC_HALF_WIDTH]

    def _simulated(self, kind: str, x_over_d: float) -> np.ndarray | None:
        path = self._file(kind, x_over_d)
        return _read(path) if path.is_file() else None

    @cached_property
    def arcs(self) -> tuple[Arc, ...]:
        return tuple(Arc(x, self._measured(x), self._simulated("LES", x), self._simulated("RANS", x))
                     for x in self.distances)


SINGLE_WAKE_CASES = {
    case.name: case for case in (
        SingleWakeCase("Wieringermeer-West", 10.7, 0.63, 0.08, 80.0, 80.0, 52.8, False, (2.5, 3.5, 7.5)),
        SingleWakeCase("Wieringermeer-East", 10.9, 0.63, 0.06, 80.0, 80.0, 52.8, False, (2.5, 3.5, 7.5)),
        SingleWakeCase("Nibe", 8.5, 0.89, 0.08, 40.0, 45.0, 57.0, False, (2.5, 4.0, 7.5)),
        SingleWakeCase("Nordtank-500", 7.45, 0.70, 0.112, 41.0, 36.0, 55.7, False,
                       (1.0, 2.0, 3.0, 4.0, 5.0, 7.5)),
        SingleWakeCase("NREL-5MW_TIlow", 8.0, 0.79, 0.04, 126.0, 90.0, 55.0, True, (2.5, 5.0, 7.5)),
        SingleWakeCase("NREL-5MW_TIhigh", 8.0, 0.79, 0.128, 126.0, 90.0, 55.0, False, (2.5, 5.0, 7.5)),
    )
}


@define(frozen=True)
class HornsRevCase:
    """Horns Rev 1: 80 V80 turbines, wind from 270 +- 2.5 deg at 8 m/s, near neutral
    (docs/validation.md#horns-rev-1)."""

    name: str = "Hornsrev1"
    wind_speed: float = 8.0
    wind_direction: float = 270.0
    #: Direction bin of the measurements: the model is averaged over these integer directions.
    direction_bin: tuple = (267.0, 268.0, 269.0, 270.0, 271.0, 272.0, 273.0)
    turbulence: float = 0.056   # measured hub-height TI in this sector and speed bin
    rotor_diameter: float = 80.0
    hub_height: float = 70.0
    latitude: float = 55.5
    offshore: bool = True
    reference_turbine: int = 6  # G2, whose direction and power the measurements refer to
    n_rows: int = 8             # turbines per column (the rows the wind at 270 deg runs along)

    @property
    def streamwise_turbulence(self) -> float:
        return self.turbulence

    @property
    def site_roughness(self) -> float:
        return SEA_ROUGHNESS

    @cached_property
    def layout(self) -> tuple[np.ndarray, np.ndarray]:
        """x (east), y (north) [m] relative to the south-west corner of the layout."""
        data = np.loadtxt(DATA / "Hornsrev1_layout.csv", delimiter=",", skiprows=2)
        x, y = data[:, 1], data[:, 2]
        return x - x.min(), y - y.min()

    @property
    def inner_rows(self) -> np.ndarray:
        """Turbine indices (n_columns, 6): the 6 inner rows of each column (index = 8 col + row)."""
        n_columns = len(self.layout[0]) // self.n_rows
        return np.arange(n_columns * self.n_rows).reshape(n_columns, self.n_rows)[:, 1:-1]

    def direction_sigma(self) -> np.ndarray:
        """Per-turbine standard deviation of the wind direction [deg], van der Laan et al.
        (doi:10.1002/we.1804): sqrt((0.00035 d + 2.1)^2 + 2.5^2), d the distance to G2 [m]."""
        x, y = self.layout
        d = np.hypot(x - x[self.reference_turbine], y - y[self.reference_turbine])
        return np.sqrt((0.00035 * d + 2.1) ** 2 + 2.5**2)

    @cached_property
    def measured_rows(self) -> np.ndarray:
        """(row number, P_i/P_1, standard error of P_i/P_1): the inner-row mean normalised by its
        first turbine, the error bar std/sqrt(n) normalised alike (as PyWake plots them)."""
        data = _read(DATA / "Hornsrev1_WFdata_wd270_InnerRowMean.dat")
        first = data[0, 1]
        return np.column_stack([data[:, 0], data[:, 1] / first, data[:, 2] / np.sqrt(data[:, 3]) / first])

    @cached_property
    def rans_rows(self) -> np.ndarray:
        """(row number, P_i/P_1 raw, P_i/P_1 direction-averaged) of EllipSys3D RANS."""
        return _read(DATA / "Hornsrev1_RANS_wd270_InnerRowMean.dat")

    @cached_property
    def les_efficiency(self) -> np.ndarray:
        """(wind direction [deg], farm power / (80 x unwaked power)) of the LES."""
        return _read(DATA / "Hornsrev1_LES_WFeff.dat")

    @cached_property
    def v80_table(self) -> np.ndarray:
        """(wind speed [m/s], power [kW], C_T) of the V80."""
        return np.loadtxt(DATA / "V80_power_ct.csv", delimiter=",", skiprows=2)


HORNS_REV = HornsRevCase()


def v80_turbine() -> dict:
    """FLORIS turbine definition of the Vestas V80 from ``V80_power_ct.csv`` (cosine-loss
    operation model, FLORIS's defaults for the rest), zero below cut-in and above the table."""
    table = HORNS_REV.v80_table
    speed = np.concatenate([[0.0, 2.9], table[:, 0], [table[-1, 0] + 0.1, 50.0]])
    power = np.concatenate([[0.0, 0.0], table[:, 1], [0.0, 0.0]])
    thrust = np.concatenate([[0.0, 0.0], table[:, 2], [0.0, 0.0]])
    return _turbine("V80", HORNS_REV.rotor_diameter, HORNS_REV.hub_height, speed, power, thrust)


def constant_thrust_turbine(case: SingleWakeCase) -> dict:
    """The single-wake case's turbine: its C_T at every speed (the references give C_T only).
    Power, required by FLORIS and unused here, is the actuator disk's 1/2 rho A 4a(1-a)^2 U^3
    with a from C_T = 4a(1 - a)."""
    speed = np.arange(0.0, 31.0, 1.0)
    a = 0.5 * (1.0 - np.sqrt(1.0 - case.thrust_coefficient))
    area = 0.25 * np.pi * case.rotor_diameter**2
    power = 0.5 * 1.225 * area * 4.0 * a * (1.0 - a) ** 2 * speed**3 / 1e3
    thrust = np.full_like(speed, case.thrust_coefficient)
    return _turbine(case.name, case.rotor_diameter, case.hub_height, speed, power, thrust)


def _turbine(name, diameter, hub_height, speed, power, thrust) -> dict:
    return {
        "turbine_type": name,
        "rotor_diameter": float(diameter),
        "hub_height": float(hub_height),
        "TSR": 8.0,
        "operation_model": "cosine-loss",
        "power_thrust_table": {
            "ref_air_density": 1.225,
            "ref_tilt": 0.0,
            "cosine_loss_exponent_yaw": 1.88,
            "cosine_loss_exponent_tilt": 1.88,
            "wind_speed": [float(v) for v in speed],
            "power": [float(v) for v in power],
            "thrust_coefficient": [float(v) for v in thrust],
        },
    }
