"""Error measures and tables of the validation (docs/validation.md#measured-wakes-and-farms).

RMSE and bias (model minus reference) of U/U0 on the single-wake arcs, of P_i/P_1 over Horns
Rev's rows 2-10, and of the farm efficiency against wind direction.
"""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.studies.validation.cases import HORNS_REV
from floris_ekman_veer.studies.validation.models import arc_directions

#: Reference kinds of a single-wake arc, in the order the tables give them.
REFERENCES = ("measured", "les")


def rmse_bias(model, reference) -> tuple[float, float]:
    """(root-mean-square error, mean error) of ``model`` against ``reference``."""
    error = np.asarray(model, dtype=float) - np.asarray(reference, dtype=float)
    return float(np.sqrt(np.mean(error**2))), float(np.mean(error))


def arc_errors(case, profile: np.ndarray, step: float = 0.5) -> list[dict]:
    """Errors of one model's ``profile`` (``models.arc_profiles``) against each reference arc:
    the model interpolated (linearly, on its ``step`` grid) to the reference's directions.
    One row per arc and reference that exists: case, x/D, reference, n, rmse, bias."""
    directions = arc_directions(step)
    rows = []
    for arc, values in zip(case.arcs, profile):
        for kind in REFERENCES:
            data = getattr(arc, kind)
            if data is None:
                continue
            inside = np.abs(data[:, 0]) <= directions[-1]
            model = np.interp(data[inside, 0], directions, values)
            rmse, bias = rmse_bias(model, data[inside, 1])
            rows.append({"case": case.name, "x/D": arc.x_over_d, "reference": kind,
                         "n": int(inside.sum()), "rmse": rmse, "bias": bias})
    return rows


def reference_arc_errors(case) -> list[dict]:
    """LES and RANS against the measurements on each measured arc, as :func:`arc_errors`
    (the "reference" column names the simulation)."""
    rows = []
    for arc in case.arcs:
        if arc.measured is None:
            continue
        for kind in ("les", "rans"):
            simulation = getattr(arc, kind)
            if simulation is None:
                continue
            data = arc.measured
            model = np.interp(data[:, 0], simulation[:, 0], simulation[:, 1])
            rmse, bias = rmse_bias(model, data[:, 1])
            rows.append({"case": case.name, "x/D": arc.x_over_d, "reference": "measured",
                         "simulation": kind.upper(), "n": len(data), "rmse": rmse, "bias": bias})
    return rows


def pooled(rows: list[dict]) -> tuple[float, float, int]:
    """RMSE and bias over all points of several arcs' rows (weighted by their point counts)."""
    n = np.array([r["n"] for r in rows], dtype=float)
    rmse = np.array([r["rmse"] for r in rows])
    bias = np.array([r["bias"] for r in rows])
    return float(np.sqrt(np.sum(n * rmse**2) / n.sum())), float(np.sum(n * bias) / n.sum()), int(n.sum())


def row_errors(ratios: np.ndarray) -> tuple[float, float]:
    """RMSE and bias of P_i/P_1 over rows 2-10 against the measured inner-row mean."""
    return rmse_bias(ratios[1:], HORNS_REV.measured_rows[1:, 1])


def efficiency_errors(directions, efficiency) -> tuple[float, float]:
    """RMSE and bias of the farm efficiency against the LES at the LES's directions."""
    les = HORNS_REV.les_efficiency
    model = np.interp(les[:, 0], np.asarray(directions, dtype=float), efficiency)
    return rmse_bias(model, les[:, 1])


def markdown(header: list[str], rows: list[list]) -> str:
    """A markdown table (floats with 3 decimals)."""
    def cell(v):
        return f"{v:.3f}" if isinstance(v, float) else str(v)
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines)
