"""Validation cases and their reference data (measured, LES, RANS): the public door for any farm.

A farm is a :class:`FarmCase`: a layout (any projected coordinates in metres), a FLORIS turbine
(or one built from a power/C_T table by :func:`turbine_from_table`), the conditions (hub-height
speed, hub-height streamwise TI or an atmosphere, the wind-direction uncertainty
:class:`DirectionUncertainty`) and its measured references: :class:`RowReference` (power ratios
along rows named by turbine indices, gaps allowed) and :class:`EfficiencyReference` (farm
efficiency against wind direction). An isolated wake is a :class:`SingleWakeCase` with its
:class:`Arc` s. ``validation.models`` runs any set of FLORIS models on them and
``validation.metrics`` gives the tidy error tables (docs/validation.md#your-own-farm).

The shipped cases (Horns Rev 1, Lillgrund rows B and D, six single wakes) are built here through
the same classes from the data in ``floris_ekman_veer/studies/validation/data/`` (DTU PyWake's
validation data, MIT licence; attribution and the original studies in that folder's README.md and
in docs/validation.md#measured-wakes-and-farms).
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
    #: The arcs' references; default: read from the shipped data by the case's name.
    reference_arcs: tuple | None = field(default=None)

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
        if self.reference_arcs is not None:
            return tuple(self.reference_arcs)
        return tuple(Arc(x, self._measured(x), self._simulated("LES", x), self._simulated("RANS", x))
                     for x in self.distances)

    @property
    def turbine(self) -> dict:
        return constant_thrust_turbine(self)

    @property
    def layout(self) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros(1), np.zeros(1)


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


def turbine_from_table(name: str, rotor_diameter: float, hub_height: float, wind_speed,
                       power, thrust_coefficient) -> dict:
    """A FLORIS turbine definition from a power [kW] and thrust-coefficient table against wind
    speed [m/s] (cosine-loss operation model, FLORIS's defaults for the rest), zero power and
    thrust from 0 m/s to 0.1 m/s below the table's first speed and from 0.1 m/s above its last
    to 50 m/s (cut-in and cut-out)."""
    speed = np.asarray(wind_speed, dtype=float)
    power = np.asarray(power, dtype=float)
    thrust = np.asarray(thrust_coefficient, dtype=float)
    if speed.ndim != 1 or speed.size < 2 or power.shape != speed.shape or thrust.shape != speed.shape:
        raise ValueError("turbine_from_table: wind_speed, power and thrust_coefficient must be 1-D "
                         f"tables of one length >= 2; got shapes {speed.shape}, {power.shape}, "
                         f"{thrust.shape}")
    if np.any(np.diff(speed) <= 0) or speed[0] <= 0.1 or speed[-1] >= 49.9:
        raise ValueError("turbine_from_table: wind_speed must increase strictly within (0.1, 49.9) "
                         f"m/s; got {speed.tolist()}")
    zeros = [0.0, 0.0]
    return _turbine(name, rotor_diameter, hub_height,
                    np.concatenate([[0.0, speed[0] - 0.1], speed, [speed[-1] + 0.1, 50.0]]),
                    np.concatenate([zeros, power, zeros]), np.concatenate([zeros, thrust, zeros]))


def read_turbine_table(path) -> np.ndarray:
    """(wind speed [m/s], power [kW], C_T) rows of a CSV table with a header line (comment lines
    starting with # are skipped)."""
    return _read_csv(path)


def _read_csv(path) -> np.ndarray:
    lines = [line for line in Path(path).read_text().splitlines() if not line.startswith("#")]
    return np.loadtxt(lines[1:], delimiter=",", ndmin=2)


def read_layout(path) -> tuple[np.ndarray, np.ndarray]:
    """x (east), y (north) [m] of a CSV layout (turbine index, easting, northing; one header
    line, # comments skipped), relative to the layout's south-west corner."""
    data = _read_csv(path)
    return data[:, 1] - data[:, 1].min(), data[:, 2] - data[:, 2].min()


def read_row_measurements(path) -> np.ndarray:
    """(position, P_i/P_1, standard error of P_i/P_1) of a measured row file (columns:
    position, mean power (ratio), standard deviation, number of 10-min samples; NaN at a gap):
    the mean normalised by its first turbine, the error bar std/sqrt(n) normalised alike."""
    data = _read(path)
    first = data[0, 1]
    return np.column_stack([data[:, 0], data[:, 1] / first, data[:, 2] / np.sqrt(data[:, 3]) / first])


@define(frozen=True)
class DirectionUncertainty:
    """Standard deviation of the wind direction at each turbine [deg]:
    sigma = sqrt(constant^2 + (offset + growth d)^2), d the distance [m] to ``reference_turbine``
    (growth = offset = 0: one sigma for every turbine). The measured direction is the reference
    turbine's; van der Laan et al. (doi:10.1002/we.1804) use constant 2.5, offset 2.1,
    growth 0.00035 1/m at Horns Rev."""

    constant: float
    growth: float = 0.0
    offset: float = 0.0
    reference_turbine: int = 0

    def __attrs_post_init__(self):
        for name in ("constant", "growth", "offset"):
            value = getattr(self, name)
            if not np.isfinite(value) or value < 0:
                raise ValueError(f"DirectionUncertainty.{name} must be finite and >= 0; got {value!r}")
        if self.constant == 0 and self.offset == 0:
            raise ValueError("DirectionUncertainty: constant or offset must be > 0 (a zero sigma "
                             "at the reference turbine); got both 0")

    def sigma(self, x, y) -> np.ndarray:
        d = np.hypot(x - x[self.reference_turbine], y - y[self.reference_turbine])
        return np.sqrt((self.growth * d + self.offset) ** 2 + self.constant**2)


@define(frozen=True)
class RowReference:
    """Measured power ratios P_i/P_1 along a row for the wind from ``wind_direction`` [deg].

    ``turbines``: the turbine indices (of the case's layout) at each position of the row, first
    the upstream one; -1 marks a gap (a position without a turbine, NaN in the tables); a 2-D
    array (positions, rows) is a mean over parallel rows (Horns Rev's inner-row mean).
    ``measured``: (position, P_i/P_1, standard error) per position
    (:func:`read_row_measurements`); ``rans``: optional (position, raw, direction-averaged)."""

    label: str
    wind_direction: float
    turbines: np.ndarray = field(converter=lambda a: np.atleast_2d(np.asarray(a, dtype=int).T).T)
    measured: np.ndarray = field(converter=lambda a: np.asarray(a, dtype=float))
    rans: np.ndarray | None = None

    def __attrs_post_init__(self):
        if self.measured.shape != (len(self.turbines), 3):
            raise ValueError(f"RowReference {self.label!r}: measured must have one (position, "
                             f"ratio, standard error) row per position ({len(self.turbines)}); "
                             f"got shape {self.measured.shape}")
        if self.turbines[0].min() < 0:
            raise ValueError(f"RowReference {self.label!r}: the first position must be a turbine")

    @property
    def gaps(self) -> np.ndarray:
        return self.turbines[:, 0] < 0


@define(frozen=True)
class EfficiencyReference:
    """Farm power over n unwaked turbines' power against wind direction [deg] (``source``
    names the reference, e.g. an LES or SCADA)."""

    directions: np.ndarray = field(converter=lambda a: np.asarray(a, dtype=float))
    efficiency: np.ndarray = field(converter=lambda a: np.asarray(a, dtype=float))
    source: str = "reference"


@define(frozen=True)
class FarmCase:
    """A farm, its conditions and its measured references (docs/validation.md#your-own-farm).

    ``turbulence`` is the hub-height streamwise TI (the "matched" atmosphere reaches it, the
    "site" one takes the roughness ``site_roughness``); or give ``atmosphere`` (an
    ``ekman_veer.atmosphere`` block, the "given" reading). The model is averaged over the
    wind directions ``row direction + direction_offsets`` (the measurements' bin) and, in the
    "averaged" results, over the direction uncertainty."""

    name: str
    layout: tuple = field(converter=lambda xy: tuple(np.asarray(v, dtype=float) for v in xy))
    turbine: dict
    wind_speed: float
    latitude: float
    turbulence: float | None = None
    direction_uncertainty: DirectionUncertainty | None = None
    rows: tuple = field(default=(), converter=tuple)
    efficiency: EfficiencyReference | None = None
    offshore: bool = True
    direction_offsets: tuple = field(default=(-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0), converter=tuple)
    atmosphere: dict | None = None
    roughness_length: float | None = None

    def __attrs_post_init__(self):
        x, y = self.layout
        if x.ndim != 1 or x.shape != y.shape or x.size == 0:
            raise ValueError(f"FarmCase {self.name!r}: layout must be two 1-D arrays of one length; "
                             f"got shapes {x.shape}, {y.shape}")
        if self.turbulence is None and self.atmosphere is None:
            raise ValueError(f"FarmCase {self.name!r}: give turbulence (hub-height I_u) or atmosphere")
        if self.turbulence is not None and not 0.0 < self.turbulence < 1.0:
            raise ValueError(f"FarmCase {self.name!r}: turbulence must be in (0, 1); got {self.turbulence!r}")
        for row in self.rows:
            if row.turbines.max() >= x.size:
                raise ValueError(f"FarmCase {self.name!r}, row {row.label!r}: turbine index "
                                 f"{row.turbines.max()} beyond the layout's {x.size} turbines")

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
        return SEA_ROUGHNESS if self.offshore else LAND_ROUGHNESS

    def direction_sigma(self) -> np.ndarray:
        """Per-turbine standard deviation of the wind direction [deg]."""
        return self.direction_uncertainty.sigma(*self.layout)

    @property
    def thrust_coefficient(self) -> float:
        """The turbine's C_T at the case's wind speed."""
        table = self.turbine["power_thrust_table"]
        return float(np.interp(self.wind_speed, table["wind_speed"], table["thrust_coefficient"]))



def horns_rev() -> FarmCase:
    """Horns Rev 1: 80 V80s, the wind from 270 +- 2.5 deg along rows 7 D apart, 8 m/s, hub TI
    0.056, direction uncertainty of van der Laan et al. about G2 (turbine 6); the measured
    inner-row mean with the RANS, and the LES's farm efficiency (docs/validation.md#horns-rev-1)."""
    table = read_turbine_table(DATA / "V80_power_ct.csv")
    columns = np.arange(80).reshape(10, 8)
    rans = _read(DATA / "Hornsrev1_RANS_wd270_InnerRowMean.dat")
    les = _read(DATA / "Hornsrev1_LES_WFeff.dat")
    return FarmCase(
        name="Hornsrev1", layout=read_layout(DATA / "Hornsrev1_layout.csv"),
        turbine=turbine_from_table("V80", 80.0, 70.0, *table.T), wind_speed=8.0, latitude=55.5,
        turbulence=0.056,
        direction_uncertainty=DirectionUncertainty(2.5, growth=0.00035, offset=2.1, reference_turbine=6),
        rows=(RowReference("inner rows", 270.0, columns[:, 1:-1],
                           read_row_measurements(DATA / "Hornsrev1_WFdata_wd270_InnerRowMean.dat"),
                           rans),),
        efficiency=EfficiencyReference(les[:, 0], les[:, 1], "LES (Zong & Porte-Agel 2020)"),
    )


#: Lillgrund's rows as the measurements name them (turbine indices of Lillgrund_layout.csv,
#: upstream first for the wind from the south-west; -1: the gap in row D).
LILLGRUND_ROWS = {"B": (14, 13, 12, 11, 10, 9, 8, 7), "D": (29, 28, 27, -1, 26, 25, 24, 23)}


def lillgrund() -> FarmCase:
    """Lillgrund: 48 SWT-2.3-93s, rows B and D for the wind from 222 deg (along the rows, 4.3 D
    apart) and 207 deg, 9 m/s, hub TI 0.048, a constant 3.3-deg direction uncertainty (the
    published comparisons'); measured and RANS (docs/validation.md#lillgrund)."""
    table = read_turbine_table(DATA / "SWT-2.3-93_power_ct.csv")
    rows = []
    for direction in (222, 207):
        for label, turbines in LILLGRUND_ROWS.items():
            stem = f"wd{direction}_Row{label}.dat"
            rows.append(RowReference(
                f"row {label}", float(direction), turbines,
                read_row_measurements(DATA / f"Lillgrund_WFdata_{stem}"),
                _read(DATA / f"Lillgrund_RANS_{stem}")))
    return FarmCase(
        name="Lillgrund", layout=read_layout(DATA / "Lillgrund_layout.csv"),
        turbine=turbine_from_table("SWT-2.3-93", 92.6, 65.0, *table.T), wind_speed=9.0,
        latitude=55.5, turbulence=0.048, direction_uncertainty=DirectionUncertainty(3.3),
        rows=tuple(rows),
    )


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


HORNS_REV = horns_rev()
LILLGRUND = lillgrund()
#: The shipped farm cases.
FARM_CASES = {case.name: case for case in (HORNS_REV, LILLGRUND)}
