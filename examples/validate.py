"""Validation against measured wakes and farms: the package's and FLORIS's models side by side.

    python examples/validate.py [--output DIR] [--gallery DIR]

Runs every case of ``floris_ekman_veer.studies.validation`` (six single wakes and Horns Rev 1, data
shipped in floris_ekman_veer/studies/validation/data/, DTU PyWake's validation data, MIT licence) with the
paper's M-1, M-2, M-3 and FLORIS's gauss, GCH, cc, TurbOPark-Gauss and empirical Gauss on the same
Ekman inflow, for two atmospheres per case: the paper's pure ABL with the site's roughness
("site") and the neutral ABL whose I_u(z_h) is the measured turbulence intensity ("matched",
docs/validation.md#the-atmosphere-of-a-case). Horns Rev's rows are averaged over the measured
direction bin (267-273 deg) and, in the "averaged" columns, over the wind-direction uncertainty
with FLORIS's UncertainFlorisModel (per-turbine sigma of van der Laan et al.).

Writes to DIR (default ./output) the error tables (markdown: ``validation_tables.md``; RMSE and
bias per case and model, single wakes by downstream distance, Horns Rev by row, the farm
efficiency against the LES) and the figures ``validation_arcs_<case>.png`` (U/U0 on the arcs with
the measurements' standard errors, the LES's band and the RANS), ``validation_horns_rev_rows.png``
and ``validation_horns_rev_efficiency.png``. With ``--gallery docs`` also the small PNGs of
docs/validation.md. Prints the tables. Takes 4 to 6 minutes on two (loaded) cores.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from tqdm import tqdm  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from paper_cases import arguments, report  # noqa: E402

from floris_ekman_veer.studies.validation.atmospheres import (  # noqa: E402
    ATMOSPHERES,
    atmosphere,
    hub_turbulence,
    wake_scales,
)
from floris_ekman_veer.studies.validation.cases import HORNS_REV, SINGLE_WAKE_CASES  # noqa: E402
from floris_ekman_veer.studies.validation.metrics import (  # noqa: E402
    arc_errors,
    efficiency_errors,
    markdown,
    pooled,
    reference_arc_errors,
    row_errors,
)
from floris_ekman_veer.studies.validation.models import (  # noqa: E402
    SINGLE_WAKE_MODELS,
    WAKE_MODELS,
    arc_directions,
    arc_profiles,
    horns_rev_efficiency,
    horns_rev_rows,
)

LABEL = {"measured": "measured", "les": "LES"}
#: Spacing of the wind-direction samples of the uncertainty average [deg].
SAMPLE_STEP = 1.0
#: Arc resolution [deg].
ARC_STEP = 0.5
STYLE = {
    "M-1": dict(color="C3", lw=2.0), "M-1, ambient k_w": dict(color="C3", lw=1.2, ls=":"),
    "M-2": dict(color="C1", lw=1.2, ls="--"), "M-3": dict(color="C5", lw=1.2, ls="-."),
    "gauss": dict(color="C0", lw=1.0, ls="--"), "GCH": dict(color="C0", lw=2.0),
    "cc": dict(color="C2", lw=1.2), "TurbOPark": dict(color="C4", lw=1.2),
    "empirical_gauss": dict(color="C8", lw=1.2),
}


# ------------------------------------------------------------------------------ computations
def single_wakes(cases=None, models=SINGLE_WAKE_MODELS, readings=ATMOSPHERES, step=ARC_STEP):
    """{(case, reading, model): U/U0 on the case's arcs} (models.arc_profiles)."""
    cases = list(SINGLE_WAKE_CASES) if cases is None else list(cases)
    jobs = [(c, r, m) for c in cases for r in readings for m in models]
    return {(c, r, m): arc_profiles(SINGLE_WAKE_CASES[c], r, m, step)
            for c, r, m in tqdm(jobs, desc="single wakes", leave=False)}


def single_wake_errors(profiles, step=ARC_STEP):
    """{(case, reading, model): metrics.arc_errors rows}."""
    return {key: arc_errors(SINGLE_WAKE_CASES[key[0]], profile, step)
            for key, profile in profiles.items()}


def horns_rev(models=tuple(WAKE_MODELS), readings=ATMOSPHERES, sample_step=SAMPLE_STEP,
              directions=None):
    """{(reading, model): {"raw": P_i/P_1, "averaged": P_i/P_1}} (models.horns_rev_rows)."""
    jobs = [(r, m) for r in readings for m in models]
    return {(r, m): horns_rev_rows(m, r, sample_step, directions)
            for r, m in tqdm(jobs, desc="Horns Rev rows", leave=False)}


def efficiency(models=tuple(WAKE_MODELS), readings=ATMOSPHERES, directions=None):
    """{(reading, model): farm efficiency at the LES's wind directions}."""
    directions = HORNS_REV.les_efficiency[:, 0] if directions is None else directions
    jobs = [(r, m) for r in readings for m in models]
    return {(r, m): horns_rev_efficiency(m, r, directions)
            for r, m in tqdm(jobs, desc="Horns Rev efficiency", leave=False)}


# ------------------------------------------------------------------------------------ tables
def _cell(rmse, bias):
    return f"{rmse:.3f} ({bias:+.3f})"


def case_table(errors, reading, reference):
    """Rows: model; columns: case; cells: RMSE (bias) of U/U0 pooled over the arcs."""
    cases = list(dict.fromkeys(k[0] for k in errors))
    models = list(dict.fromkeys(k[2] for k in errors))
    rows = []
    for model in models:
        row = [model]
        for case in cases:
            chosen = [e for e in errors[(case, reading, model)] if e["reference"] == reference]
            row.append(_cell(*pooled(chosen)[:2]) if chosen else "-")
        rows.append(row)
    if reference == "measured":
        for simulation in ("LES", "RANS"):
            row = [f"{simulation} (reference)"]
            for case in cases:
                chosen = [e for e in reference_arc_errors(SINGLE_WAKE_CASES[case])
                          if e["simulation"] == simulation]
                row.append(_cell(*pooled(chosen)[:2]) if chosen else "-")
            rows.append(row)
    return markdown(["model"] + cases, rows)


def distance_table(errors, reading):
    """Rows: case, x/D, reference; columns: model; cells: RMSE (bias)."""
    models = list(dict.fromkeys(k[2] for k in errors))
    cases = list(dict.fromkeys(k[0] for k in errors))
    rows = []
    for case in cases:
        arcs = [(e["x/D"], e["reference"]) for e in errors[(case, reading, models[0])]]
        for x, reference in arcs:
            row = [case, f"{x:g}", LABEL[reference]]
            for model in models:
                (e,) = [e for e in errors[(case, reading, model)]
                        if e["x/D"] == x and e["reference"] == reference]
                row.append(_cell(e["rmse"], e["bias"]))
            rows.append(row)
    return markdown(["case", "x/D", "against"] + models, rows)


def rows_error_table(rows):
    """Rows: model; columns: RMSE (bias) over rows 2-10, raw and averaged, per atmosphere."""
    readings = list(dict.fromkeys(k[0] for k in rows))
    models = list(dict.fromkeys(k[1] for k in rows))
    table = [[model] + [_cell(*row_errors(rows[(r, model)][kind]))
                        for r in readings for kind in ("averaged", "raw")] for model in models]
    rans = HORNS_REV.rans_rows
    table.append(["EllipSys3D RANS (published)"]
                 + [_cell(*row_errors(rans[:, col])) for _ in readings for col in (2, 1)])
    header = ["model"] + [f"{r}, {kind}" for r in readings for kind in ("averaged", "raw")]
    return markdown(header, table)


def rows_table(rows, reading, kind="averaged"):
    """P_i/P_1 by row i: measured, RANS and every model."""
    models = list(dict.fromkeys(k[1] for k in rows if k[0] == reading))
    measured = HORNS_REV.measured_rows
    rans = HORNS_REV.rans_rows[:, 2 if kind == "averaged" else 1]
    table = [[int(measured[i, 0]), f"{measured[i, 1]:.3f} +- {measured[i, 2]:.3f}", float(rans[i])]
             + [float(rows[(reading, m)][kind][i]) for m in models] for i in range(len(measured))]
    return markdown(["row", "measured", "RANS"] + models, table)


def efficiency_table(effs):
    readings = list(dict.fromkeys(k[0] for k in effs))
    models = list(dict.fromkeys(k[1] for k in effs))
    directions = HORNS_REV.les_efficiency[:, 0]
    table = [[m] + [_cell(*efficiency_errors(directions, effs[(r, m)])) for r in readings]
             for m in models]
    return markdown(["model"] + list(readings), table)


def atmosphere_table():
    """Per case: the measured I_u, and for each atmosphere z0, I_u(z_h), k_w and x0/D."""
    rows = []
    for case in list(SINGLE_WAKE_CASES.values()) + [HORNS_REV]:
        ct = getattr(case, "thrust_coefficient", None)
        if ct is None:  # Horns Rev: the V80's C_T at its wind speed
            ct = float(np.interp(case.wind_speed, *HORNS_REV.v80_table[:, [0, 2]].T))
        row = [case.name, f"{case.streamwise_turbulence:.3f}"]
        for reading in ATMOSPHERES:
            z0 = atmosphere(case, reading)["roughness_length"]
            k_w, x0 = wake_scales(case, z0, ct)
            row += [f"{z0:.3g}", f"{hub_turbulence(case, z0):.3f}", f"{k_w:.4f}", f"{x0:.2f}"]
        rows.append(row)
    header = ["case", "measured I_u(z_h)"]
    for reading in ATMOSPHERES:
        header += [f"{reading} z0 [m]", f"{reading} I_u(z_h)", f"{reading} k_w", f"{reading} x0/D"]
    return markdown(header, rows)


def tables(errors, rows, effs) -> str:
    parts = ["# Validation tables (examples/validate.py)", "",
             "## Atmospheres", "", atmosphere_table(), ""]
    for reading in ATMOSPHERES:
        for reference in ("measured", "les"):
            parts += [f"## Single wakes, {reading} atmosphere, against the {LABEL[reference]} arcs: "
                      "RMSE (bias) of U/U0", "", case_table(errors, reading, reference), ""]
    for reading in ATMOSPHERES:
        parts += [f"## Single wakes by downstream distance, {reading} atmosphere", "",
                  distance_table(errors, reading), ""]
    parts += ["## Horns Rev 1, P_i/P_1 over rows 2-10: RMSE (bias)", "", rows_error_table(rows), ""]
    for reading in ATMOSPHERES:
        parts += [f"## Horns Rev 1 by row, {reading} atmosphere, direction-averaged", "",
                  rows_table(rows, reading), ""]
    parts += ["## Horns Rev 1 farm efficiency against the LES: RMSE (bias)", "",
              efficiency_table(effs), ""]
    return "\n".join(parts)


# ----------------------------------------------------------------------------------- figures
def _references(ax, arc):
    if arc.les is not None:
        les = arc.les
        half = les[:, 2] / np.sqrt(les[:, 3])
        ax.fill_between(les[:, 0], les[:, 1] - half, les[:, 1] + half, color="0.6", alpha=0.4,
                        label="LES")
    if arc.rans is not None:
        ax.plot(arc.rans[:, 0], arc.rans[:, 1], color="k", lw=1.0, ls="-.", label="RANS")
    if arc.measured is not None:
        m = arc.measured
        if m.shape[1] >= 4:  # with the standard deviation and the number of 10-min means
            ax.errorbar(m[:, 0], m[:, 1], yerr=m[:, 2] / np.sqrt(m[:, 3]), fmt="ko", ms=3,
                        elinewidth=0.8, capsize=2, label="measured")
        else:
            ax.plot(m[:, 0], m[:, 1], "ko", ms=3, label="measured")


def arcs_figure(profiles, case_name, output, distances=None, dpi=100, models=None):
    case = SINGLE_WAKE_CASES[case_name]
    models = models or [k[2] for k in profiles if k[0] == case_name and k[1] == "matched"]
    arcs = [a for a in case.arcs if distances is None or a.x_over_d in distances]
    fig, axes = plt.subplots(1, len(arcs), figsize=(3.6 * len(arcs), 3.4), sharey=True,
                             squeeze=False)
    theta = arc_directions(ARC_STEP)
    for ax, arc in zip(axes[0], arcs):
        k = case.distances.index(arc.x_over_d)
        _references(ax, arc)
        for model in models:
            ax.plot(theta, profiles[(case_name, "matched", model)][k], label=model, **STYLE[model])
        if (case_name, "site", "M-1") in profiles:
            ax.plot(theta, profiles[(case_name, "site", "M-1")][k], color="C3", lw=1.0, ls="--",
                    label="M-1, site ABL")
        ax.set_title(f"{case_name}, x = {arc.x_over_d:g} D", fontsize=9)
        ax.set_xlabel("relative wind direction [deg]")
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("U/U0 at hub height")
    axes[0, -1].legend(fontsize=6, loc="lower right")
    fig.tight_layout()
    path = Path(output) / f"validation_arcs_{case_name.lower().replace('-', '_')}.png"
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def rows_figure(rows, output, dpi=100):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    measured, rans = HORNS_REV.measured_rows, HORNS_REV.rans_rows
    models = [k[1] for k in rows if k[0] == "matched"]
    for ax, kind, col in zip(axes, ("raw", "averaged"), (1, 2)):
        ax.errorbar(measured[:, 0], measured[:, 1], yerr=measured[:, 2], fmt="ko", ms=4,
                    capsize=3, label="measured")
        ax.plot(rans[:, 0], rans[:, col], "k-.", lw=1.0, label="RANS")
        for model in models:
            ax.plot(measured[:, 0], rows[("matched", model)][kind], label=model, **STYLE[model])
        ax.plot(measured[:, 0], rows[("site", "M-1")][kind], color="C3", lw=1.0, ls="--",
                label="M-1, site ABL")
        ax.set_title(f"Horns Rev 1, 270 +- 2.5 deg, 8 m/s: {kind}"
                     + (" (direction uncertainty)" if kind == "averaged" else ""), fontsize=9)
        ax.set_xlabel("turbine along the row")
        ax.set_xticks(measured[:, 0])
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("P_i/P_1, inner-row mean")
    axes[1].legend(fontsize=7, ncol=2)
    fig.tight_layout()
    path = Path(output) / "validation_horns_rev_rows.png"
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def efficiency_figure(effs, output, dpi=100):
    les = HORNS_REV.les_efficiency
    fig, ax = plt.subplots(figsize=(10, 3.6))
    ax.plot(les[:, 0], les[:, 1], "ko-", ms=3, lw=1.0, label="LES (Zong & Porte-Agel 2020)")
    for (reading, model), eff in effs.items():
        if reading == "matched":
            ax.plot(les[:, 0], eff, label=model, **STYLE[model])
    ax.set_xlabel("wind direction [deg]")
    ax.set_ylabel("farm power / 80 unwaked")
    ax.set_title("Horns Rev 1 farm efficiency, 8 m/s (matched atmosphere)", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=3)
    fig.tight_layout()
    path = Path(output) / "validation_horns_rev_efficiency.png"
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def main(argv=None) -> None:
    args = arguments(__doc__, argv)
    start = time.perf_counter()
    profiles = single_wakes()
    errors = single_wake_errors(profiles)
    rows = horns_rev()
    effs = efficiency()
    text = tables(errors, rows, effs)
    print(text)
    (args.output / "validation_tables.md").write_text(text + "\n")
    written = [arcs_figure(profiles, name, args.output) for name in SINGLE_WAKE_CASES]
    written += [rows_figure(rows, args.output), efficiency_figure(effs, args.output)]
    if args.gallery is not None:
        main_models = ["M-1", "M-3", "GCH", "cc", "TurbOPark"]
        for name in SINGLE_WAKE_CASES:
            distances = (2.0, 3.0, 5.0) if name == "Nordtank-500" else None
            written.append(arcs_figure(profiles, name, args.gallery, distances, dpi=80,
                                       models=main_models))
        written += [rows_figure(rows, args.gallery, dpi=70), efficiency_figure(effs, args.gallery, dpi=70)]
    report(written, start)


if __name__ == "__main__":
    main()
