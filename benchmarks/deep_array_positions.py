"""Lillgrund's rows B and D position by position for M-1 with the shipped coupling and with the
published candidates of docs/coupling.md#wakes-deep-in-an-array (matched atmosphere, direction-
averaged, error = model - measured), and each candidate's Horns Rev row ratios.

    python -m benchmarks.deep_array_positions

Takes about 3 minutes.
"""

from __future__ import annotations

import numpy as np

import floris_ekman_veer  # noqa: F401

from benchmarks.deep_array_coupling import setup
from floris_ekman_veer.studies.validation import models
from floris_ekman_veer.studies.validation.cases import HORNS_REV, LILLGRUND

#: The former default (the wakes summed), the shipped default (the cumulative wake) and the
#: other candidates (docs/coupling.md's table).
CANDIDATES = {
    "summed (fls)": ("quadrature", "radius", "FLORIS", "incoming", "fls"),
    "default (cumulative)": ("quadrature", "radius", "FLORIS", "incoming", "cumulative"),
    "zong": ("max", "radius", "FLORIS", "incoming", "zong"),
    "Ishihara-Qian": ("quadrature", "-", "Ishihara-Qian", "incoming", "fls"),
}


def table(case) -> str:
    ratios = {name: models.row_ratios(case, [setup(*coupling)])
              for name, coupling in CANDIDATES.items()}
    ratios = {name: r[r["kind"] == "averaged"].reset_index(drop=True)
              for name, r in ratios.items()}
    first = next(iter(ratios.values()))
    header = ["row, direction", "position", "measured +- s.e.", "RANS"]
    header += [f"{n} (error)" for n in CANDIDATES]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for index, point in enumerate(first.itertuples()):
        if np.isnan(point.measured):
            continue
        cells = [f"{point.row}, {point.wind_direction:g}", str(point.position),
                 f"{point.measured:.3f} +- {point.standard_error:.3f}",
                 "-" if np.isnan(point.rans) else f"{point.rans:.3f}"]
        for name in CANDIDATES:
            value = float(ratios[name]["ratio"].iloc[index])
            cells.append(f"{value:.3f} ({value - point.measured:+.3f})")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    for case in (LILLGRUND, HORNS_REV):
        print(f"\n{case.name}\n")
        print(table(case), flush=True)


if __name__ == "__main__":
    main()
