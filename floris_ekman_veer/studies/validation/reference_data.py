"""The shipped reference data and their readers (docs/validation.md#data-and-original-studies).

The files in ``floris_ekman_veer/studies/validation/data/`` (DTU PyWake's validation data, MIT
licence; that folder's README.md lists them) and the readers that turn them, or a user's files
of the same layout, into arrays: power/C_T tables, layouts, measured rows and the single-wake
arcs. What a case is made of them is ``cases``'s business.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "data"

#: Relative wind directions compared on each arc [deg]: +-30, the span of the LES and RANS.
ARC_HALF_WIDTH = 30.0


def read_table(path) -> np.ndarray:
    """The numbers of a whitespace-separated file (# comments skipped), one row at least."""
    return np.atleast_2d(np.loadtxt(path, comments="#"))


def _read_csv(path) -> np.ndarray:
    lines = [line for line in Path(path).read_text().splitlines() if not line.startswith("#")]
    return np.loadtxt(lines[1:], delimiter=",", ndmin=2)


def read_turbine_table(path) -> np.ndarray:
    """(wind speed [m/s], power [kW], C_T) rows of a CSV table with a header line (comment lines
    starting with # are skipped)."""
    return _read_csv(path)


def read_layout(path) -> tuple[np.ndarray, np.ndarray]:
    """x (east), y (north) [m] of a CSV layout (turbine index, easting, northing; one header
    line, # comments skipped), relative to the layout's south-west corner."""
    data = _read_csv(path)
    return data[:, 1] - data[:, 1].min(), data[:, 2] - data[:, 2].min()


def read_row_measurements(path) -> np.ndarray:
    """(position, P_i/P_1, standard error of P_i/P_1) of a measured row file (columns:
    position, mean power (ratio), standard deviation, number of 10-min samples; NaN at a gap):
    the mean normalised by its first turbine, the error bar std/sqrt(n) normalised alike."""
    data = read_table(path)
    first = data[0, 1]
    return np.column_stack([data[:, 0], data[:, 1] / first, data[:, 2] / np.sqrt(data[:, 3]) / first])


def _distance_label(x_over_d: float) -> str:
    return (f"{x_over_d:g}").replace(".", "p")


def arc_file(case_name: str, kind: str, x_over_d: float) -> Path:
    """The shipped file of a single-wake case's arc: kind ``data`` (measured), ``LES``, ``RANS``."""
    return DATA / f"{case_name}_{kind}_{_distance_label(x_over_d)}D.dat"


def read_measured_arc(case_name: str, x_over_d: float, wind_speed: float) -> np.ndarray | None:
    """The measured arc x/D of a shipped single wake, (relative direction [deg], U/U0, std / U0,
    number of 10-min means) within +-:data:`ARC_HALF_WIDTH`; None where nothing was measured."""
    path = arc_file(case_name, "data", x_over_d)
    if not path.is_file():
        return None
    data = read_table(path)
    if case_name.startswith("Wieringermeer"):
        # Absolute wind direction and speed [m/s]: centre the direction, normalise by U0.
        centre = 315.0 if case_name.endswith("West") else 31.0
        data = np.column_stack([data[:, 0] - centre, data[:, 1:3] / wind_speed, data[:, 3]])
    elif case_name == "Nordtank-500":
        # Columns: direction, y [m], U/U0, std; 74 ten-minute means per point (file header).
        data = np.column_stack([data[:, 0], data[:, 2], data[:, 3], np.full(len(data), 74.0)])
    return data[np.abs(data[:, 0]) <= ARC_HALF_WIDTH]


def read_simulated_arc(case_name: str, kind: str, x_over_d: float) -> np.ndarray | None:
    """The ``LES`` or ``RANS`` arc x/D of a shipped single wake as published; None without one."""
    path = arc_file(case_name, kind, x_over_d)
    return read_table(path) if path.is_file() else None
