"""Why M-1's wakes recovered too fast in tight arrays: its farm couplings on the measured farms.

    python -m benchmarks.deep_array_coupling

Runs M-1 through ``floris_ekman_veer.studies.validation`` (matched atmosphere, the measurements'
direction bins and direction uncertainty, as examples/validate.py) on Horns Rev 1 (rows 7 D
apart) and Lillgrund's rows B and D (4.3 and 3.3 D), one piece of the farm coupling changed at a
time (docs/coupling.md#wakes-deep-in-an-array):

    added turbulence  "max": the largest upstream wake's (FLORIS's combination, the package's
                      former ``local_turbulence``); "quadrature": every upstream wake's, their
                      variances summed (``array_turbulence``); "none": the paper's ambient k_w;
    deficit scale     "free stream" (FLORIS's gauss) or "incoming" (Niayifar & Porte-Agel 2016);
    superposition     "sosfs" (squares summed) or "fls" (summed).

Prints the RMSE (bias) of the direction-averaged P_i/P_1 over the waked positions (Horns Rev,
Lillgrund) and of Horns Rev's farm efficiency against the LES. Takes about 3 minutes.
"""

from __future__ import annotations


import floris_ekman_veer  # noqa: F401

from floris_ekman_veer.studies.validation import metrics, models  # noqa: E402
from floris_ekman_veer.studies.validation.cases import HORNS_REV, LILLGRUND  # noqa: E402

EXPANSION = {"max": "local_turbulence", "quadrature": "array_turbulence", "none": "ambient"}
SCALE = {"free stream": "free_stream", "incoming": "incoming"}
#: (added turbulence, deficit scale, superposition); the first is FLORIS's gauss coupling, the
#: last but one the package's default.
COUPLINGS = (
    ("max", "free stream", "sosfs"),
    ("max", "free stream", "fls"),
    ("max", "incoming", "fls"),
    ("quadrature", "free stream", "sosfs"),
    ("quadrature", "incoming", "fls"),
    ("none", "incoming", "fls"),
)


def setup(turbulence: str, scale: str, superposition: str):
    """A (name, set-up) pair of M-1 with this coupling (validation.models.WAKE_MODELS' form)."""
    strings, gch, parameters = models.WAKE_MODELS["M-1"]
    velocity = {"wake_expansion": EXPANSION[turbulence], "deficit_velocity": SCALE[scale]}
    return (f"{turbulence}, {scale}, {superposition}",
            ({**strings, "combination_model": superposition}, gch,
             {**parameters, "velocity": velocity}))


def _cell(errors, kind="averaged") -> str:
    (row,) = errors[errors["kind"] == kind].itertuples() if "kind" in errors else errors.itertuples()
    return f"{row.rmse:.3f} ({row.bias:+.3f})"


def main() -> None:
    print("| added turbulence | deficit scale | superposition | Horns Rev rows | "
          "Horns Rev efficiency | Lillgrund rows |")
    print("|---|---|---|---|---|---|")
    for coupling in COUPLINGS:
        model = setup(*coupling)
        horns_rev = metrics.row_errors(models.row_ratios(HORNS_REV, [model]))
        efficiency = metrics.efficiency_errors(models.farm_efficiency(HORNS_REV, [model]))
        lillgrund = metrics.row_errors(models.row_ratios(LILLGRUND, [model]))
        print(f"| {' | '.join(coupling)} | {_cell(horns_rev)} | {_cell(efficiency, "raw")} | "
              f"{_cell(lillgrund)} |", flush=True)


if __name__ == "__main__":
    main()
