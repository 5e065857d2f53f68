"""Why M-1's wakes recovered too fast in tight arrays: its farm couplings on the measured farms.

    python -m benchmarks.deep_array_coupling

Runs M-1 through ``floris_ekman_veer.studies.validation`` (matched atmosphere, the measurements'
direction bins and direction uncertainty, as examples/validate.py) on Horns Rev 1 (rows 7 D
apart) and Lillgrund's rows B and D (4.3 and 3.3 D), one piece of the farm coupling changed at a
time (docs/coupling.md#wakes-deep-in-an-array):

    added turbulence  "max": the largest upstream wake's (FLORIS's combination, the package's
                      former ``local_turbulence``); "quadrature": every upstream wake's, their
                      variances summed (``array_turbulence``); "none": the paper's ambient k_w;
    overlap           the part of a rotor a wake's added turbulence is weighted with: "velocity",
                      where the wake's velocity exceeds 0.05 m/s (FLORIS's count), or "radius",
                      inside the wake radius 2 sigma (Niayifar & Porte-Agel 2016);
    added-turbulence  the added turbulence's form: Crespo-Hernandez with "FLORIS" (FLORIS 4.7's
    form              defaults: 0.9 a^0.8 I0^0.1 (x/D)^-0.32) or "1996" (Crespo & Hernandez's
                      published 0.73 a^0.8325 I0^0.0325 (x/D)^-0.32, as PyWake's Niayifar and
                      Zong models take them; "1996-" with the exponent -0.0325 of the paper's
                      scans), weighted with the overlap; or "Ishihara-Qian" (Ishihara & Qian
                      2018, ``wake_turbulence: ishihara_qian``), its ring-shaped profile
                      averaged over the rotor (its own overlap: the overlap column is "-");
    deficit scale     "free stream" (FLORIS's gauss) or "incoming" (Niayifar & Porte-Agel 2016);
    superposition     "sosfs" (squares summed), "fls" (summed), "zong" (Zong & Porte-Agel's
                      2020 momentum-conserving weights on the sum, ``wake_superposition:
                      momentum_conserving``) or "cumulative" (Bastankhah et al.'s 2021
                      cumulative wake, summed: ``wake_superposition: cumulative``).

Prints the RMSE (bias) of the direction-averaged P_i/P_1 over the waked positions (Horns Rev,
Lillgrund) and of Horns Rev's farm efficiency against the LES. Takes about 5 minutes.
"""

from __future__ import annotations


import floris_ekman_veer  # noqa: F401

from floris_ekman_veer.studies.validation import metrics, models  # noqa: E402
from floris_ekman_veer.studies.validation.cases import HORNS_REV, LILLGRUND  # noqa: E402

EXPANSION = {"max": "local_turbulence", "quadrature": "array_turbulence", "none": "ambient"}
OVERLAP = {"velocity": "wake_velocity", "radius": "wake_radius"}
CRESPO_HERNANDEZ = {
    "FLORIS": None,
    "1996": {"constant": 0.73, "ai": 0.8325, "initial": 0.0325, "downstream": -0.32},
    "1996-": {"constant": 0.73, "ai": 0.8325, "initial": -0.0325, "downstream": -0.32},
}
SCALE = {"free stream": "free_stream", "incoming": "incoming"}
SUPERPOSITION = {"sosfs": "combination_model", "fls": "combination_model",
                 "zong": "momentum_conserving", "cumulative": "cumulative"}
#: (added turbulence, overlap, Crespo-Hernandez, deficit scale, superposition); the first is
#: FLORIS's gauss coupling, "quadrature, radius, FLORIS, incoming, cumulative" the package's
#: default (before issue 40: "quadrature, radius, FLORIS, incoming, fls").
COUPLINGS = (
    ("max", "velocity", "FLORIS", "free stream", "sosfs"),
    ("max", "velocity", "FLORIS", "free stream", "fls"),
    ("max", "velocity", "FLORIS", "incoming", "fls"),
    ("quadrature", "velocity", "FLORIS", "free stream", "sosfs"),
    ("quadrature", "velocity", "FLORIS", "incoming", "fls"),
    ("none", "velocity", "FLORIS", "incoming", "fls"),
    ("max", "velocity", "1996", "incoming", "fls"),
    ("quadrature", "velocity", "1996", "incoming", "fls"),
    ("quadrature", "velocity", "1996-", "incoming", "fls"),
    ("max", "radius", "FLORIS", "incoming", "fls"),
    ("max", "radius", "1996", "incoming", "fls"),
    ("max", "radius", "1996-", "incoming", "fls"),
    ("quadrature", "radius", "1996", "incoming", "fls"),
    ("quadrature", "radius", "1996-", "incoming", "fls"),
    ("quadrature", "radius", "FLORIS", "incoming", "fls"),
    ("quadrature", "-", "Ishihara-Qian", "incoming", "fls"),
    ("max", "-", "Ishihara-Qian", "incoming", "fls"),
    ("quadrature", "radius", "FLORIS", "incoming", "zong"),
    ("quadrature", "radius", "1996-", "incoming", "zong"),
    ("quadrature", "velocity", "1996-", "incoming", "zong"),
    ("quadrature", "-", "Ishihara-Qian", "incoming", "zong"),
    ("max", "radius", "FLORIS", "incoming", "zong"),
    ("max", "radius", "1996-", "incoming", "zong"),
    ("max", "velocity", "FLORIS", "incoming", "zong"),
    ("quadrature", "radius", "FLORIS", "incoming", "cumulative"),
    ("max", "radius", "FLORIS", "incoming", "cumulative"),
    ("quadrature", "radius", "1996-", "incoming", "cumulative"),
    ("quadrature", "-", "Ishihara-Qian", "incoming", "cumulative"),
)


def setup(turbulence: str, overlap: str, constants: str, scale: str, superposition: str):
    """A (name, set-up) pair of M-1 with this coupling (validation.models.WAKE_MODELS' form)."""
    strings, gch, parameters = models.WAKE_MODELS["M-1"]
    velocity = {"wake_expansion": EXPANSION[turbulence], "deficit_velocity": SCALE[scale]}
    if constants == "Ishihara-Qian":
        velocity["wake_turbulence"] = "ishihara_qian"
        crespo_hernandez = None
    else:
        velocity["turbulence_overlap"] = OVERLAP[overlap]
        crespo_hernandez = CRESPO_HERNANDEZ[constants]
    # (every row names its superposition: the default is the cumulative wake)
    velocity["wake_superposition"] = SUPERPOSITION[superposition]
    summed = superposition in ("zong", "cumulative")
    return (f"{turbulence}, {overlap}, {constants}, {scale}, {superposition}",
            ({**strings, "combination_model": "fls" if summed else superposition},
             gch,
             {**parameters, "velocity": velocity,
              "turbulence": {"crespo_hernandez": crespo_hernandez}}))


def _cell(errors, kind="averaged") -> str:
    (row,) = errors[errors["kind"] == kind].itertuples() if "kind" in errors else errors.itertuples()
    return f"{row.rmse:.3f} ({row.bias:+.3f})"


def main(couplings=COUPLINGS) -> None:
    print("| added turbulence | overlap | added-turbulence form | deficit scale | superposition | "
          "Horns Rev rows | Horns Rev efficiency | Lillgrund rows |")
    print("|---|---|---|---|---|---|---|---|")
    for coupling in couplings:
        model = setup(*coupling)
        horns_rev = metrics.row_errors(models.row_ratios(HORNS_REV, [model]))
        efficiency = metrics.efficiency_errors(models.farm_efficiency(HORNS_REV, [model]))
        lillgrund = metrics.row_errors(models.row_ratios(LILLGRUND, [model]))
        print(f"| {' | '.join(coupling)} | {_cell(horns_rev)} | {_cell(efficiency, 'raw')} | "
              f"{_cell(lillgrund)} |", flush=True)


if __name__ == "__main__":
    import sys

    # ``python -m benchmarks.deep_array_coupling 15 16``: only those rows of COUPLINGS (0-based).
    main([COUPLINGS[int(k)] for k in sys.argv[1:]] or COUPLINGS)
