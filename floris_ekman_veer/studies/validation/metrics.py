"""Error measures and tables of the validation (docs/validation.md#measured-wakes-and-farms).

RMSE and bias (model minus reference) of U/U0 on the single-wake arcs, of P_i/P_1 along a farm's
reference rows (every position but the first and the gaps), and of the farm efficiency against
wind direction; the tidy tables of ``validation.models`` in, tidy tables out.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

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


def _errors(group, value, reference, spread=None) -> pd.Series:
    inside = group[[value, reference]].notna().all(axis=1)
    chosen = group[inside]
    rmse, bias = rmse_bias(chosen[value], chosen[reference])
    result = {"n": int(inside.sum()), "rmse": rmse, "bias": bias}
    if spread is not None:
        # The reference's own standard error, as an RMS over the same points: an RMSE near it
        # is within what the measurements can tell apart.
        result["standard_error"] = float(np.sqrt(np.mean(chosen[spread] ** 2)))
    return pd.Series(result)


def row_errors(ratios: pd.DataFrame, by=("case", "reading", "model", "kind"),
               reference: str = "measured") -> pd.DataFrame:
    """RMSE, bias and the measurements' standard error of P_i/P_1 (``models.row_ratios``)
    against ``reference`` ("measured" or "rans"), over every position but each row's first and
    its gaps, per group ``by`` (add "row" and "wind_direction" for each row alone)."""
    waked = ratios[ratios["position"] > 1]
    spread = "standard_error" if reference == "measured" else None
    return (waked.groupby(list(by), sort=False)
            .apply(_errors, "ratio", reference, spread, include_groups=False).reset_index())


def reference_row_errors(ratios: pd.DataFrame, by=("case", "kind")) -> pd.DataFrame:
    """The published RANS against the measurements, as :func:`row_errors` (one model's rows
    carry them)."""
    first = ratios[(ratios["model"] == ratios["model"].iloc[0])
                   & (ratios["reading"] == ratios["reading"].iloc[0])]
    return row_errors(first.assign(ratio=first["rans"]), by=by)


def efficiency_errors(efficiency: pd.DataFrame, by=None) -> pd.DataFrame:
    """RMSE, bias and the reference's standard error (RMS over the same points; NaN where the
    reference gives none) of the farm efficiency (``models.farm_efficiency``) against its
    reference at the reference's directions, per group ``by`` (default: case, reading, model
    and kind, those of them the table has, so that a table built elsewhere without "kind" or
    "standard_error" columns is scored as well)."""
    if by is None:
        by = [c for c in ("case", "reading", "model", "kind") if c in efficiency]
    spread = "standard_error" if "standard_error" in efficiency else None
    return (efficiency.groupby(list(by), sort=False)
            .apply(_errors, "efficiency", "reference", spread, include_groups=False)
            .reset_index())


def markdown(header: list[str], rows: list[list]) -> str:
    """A markdown table (floats with 3 decimals)."""
    def cell(v):
        return f"{v:.3f}" if isinstance(v, float) else str(v)
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines)
