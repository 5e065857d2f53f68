"""Validation against measured wakes and farms: the package's and FLORIS's models side by side.

    python examples/validate.py [--output DIR] [--gallery DIR] [--site-measured-turbulence]

Runs every case of ``floris_ekman_veer.studies.validation`` (six single wakes, Horns Rev 1 and
Lillgrund's rows B and D, data shipped in floris_ekman_veer/studies/validation/data/, DTU PyWake's
validation data, MIT licence) through its public API with the paper's M-1 (and two farm
couplings of it for comparison), M-2, M-3 and FLORIS's gauss, GCH, cc, TurbOPark-Gauss and
empirical Gauss on the same Ekman inflow, for two atmospheres per case: the paper's pure ABL
with the site's roughness ("site") and the neutral ABL whose I_u(z_h) is the measured turbulence
intensity ("matched", docs/validation.md#the-atmosphere-of-a-case); with
``--site-measured-turbulence`` also a third reading, the site's roughness with the measured
turbulence in the wake as ``fit_site`` gives it (the atmosphere block's ``turbulence_factor``),
whose tables follow the two others'. A farm's rows are averaged
over the measured direction bin (+-3 deg) and, in the "averaged" columns, over the
wind-direction uncertainty with FLORIS's UncertainFlorisModel (Horns Rev: per-turbine sigma of
van der Laan et al.; Lillgrund: 3.3 deg).

Writes to DIR (default ./output) the error tables (markdown: ``validation_tables.md``; RMSE and
bias per case and model, single wakes by downstream distance, each farm's rows by position, the
farm efficiency against the LES), the tidy tables as CSV (``validation_rows.csv``,
``validation_efficiency.csv``) and the figures ``validation_arcs_<case>.png`` (U/U0 on the arcs
with the measurements' standard errors, the LES's band and the RANS),
``validation_horns_rev_rows.png``, ``validation_lillgrund_rows.png`` and
``validation_horns_rev_efficiency.png``. With ``--gallery docs`` also the small PNGs of
docs/validation.md. Prints the tables. Takes 6 to 10 minutes on two (loaded) cores.
"""

from __future__ import annotations

import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from tqdm import tqdm  # noqa: E402

from paper_cases import arguments, report  # noqa: E402

from floris_ekman_veer.studies.validation.atmospheres import (  # noqa: E402
    ATMOSPHERES,
    SITE_MEASURED_TURBULENCE,
    atmosphere,
    hub_turbulence,
    wake_scales,
)
from floris_ekman_veer.studies.validation.cases import (  # noqa: E402
    FARM_CASES,
    HORNS_REV,
    LILLGRUND,
    SINGLE_WAKE_CASES,
)
from floris_ekman_veer.studies.validation.metrics import (  # noqa: E402
    arc_errors,
    efficiency_errors,
    markdown,
    pooled,
    reference_arc_errors,
    reference_row_errors,
    row_errors,
)
from floris_ekman_veer.studies.validation.models import (  # noqa: E402
    SINGLE_WAKE_MODELS,
    WAKE_MODELS,
    arc_directions,
    arc_profiles,
    farm_efficiency,
    row_ratios,
)

LABEL = {"measured": "measured", "les": "LES"}
#: Spacing of the wind-direction samples of the uncertainty average [deg].
SAMPLE_STEP = 1.0
#: Arc resolution [deg].
ARC_STEP = 0.5
STYLE = {
    "M-1": dict(color="C3", lw=2.0), "M-1, ambient k_w": dict(color="C3", lw=1.2, ls=":"),
    "M-1, FLORIS-style": dict(color="C3", lw=1.0, ls="--"),
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


def farm_rows(cases=tuple(FARM_CASES), models=tuple(WAKE_MODELS), readings=ATMOSPHERES,
              sample_step=SAMPLE_STEP, offsets=None):
    """The tidy P_i/P_1 table of every farm case's rows (models.row_ratios)."""
    jobs = [(c, m) for c in cases for m in models]
    return pd.concat([row_ratios(FARM_CASES[c], [m], readings, sample_step, offsets)
                      for c, m in tqdm(jobs, desc="farm rows", leave=False)], ignore_index=True)


def efficiency(models=tuple(WAKE_MODELS), readings=ATMOSPHERES, directions=None):
    """The tidy farm-efficiency table of Horns Rev at the LES's directions."""
    return pd.concat([farm_efficiency(HORNS_REV, [m], readings, directions)
                      for m in tqdm(models, desc="Horns Rev efficiency", leave=False)],
                     ignore_index=True)


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


def rows_error_table(rows, case):
    """Rows: model; columns: RMSE (bias) over the waked positions, averaged and raw, per
    atmosphere; the measurements' standard error and the published RANS below."""
    errors = row_errors(rows[rows["case"] == case])
    readings = list(dict.fromkeys(errors["reading"]))
    table = []
    for model in dict.fromkeys(errors["model"]):
        cells = []
        for reading in readings:
            for kind in ("averaged", "raw"):
                (e,) = errors[(errors["model"] == model) & (errors["reading"] == reading)
                              & (errors["kind"] == kind)].itertuples()
                cells.append(_cell(e.rmse, e.bias))
        table.append([model] + cells)
    rans = reference_row_errors(rows[rows["case"] == case])
    if rans["n"].gt(0).all():
        by_kind = {e.kind: _cell(e.rmse, e.bias) for e in rans.itertuples()}
        table.append(["EllipSys3D RANS (published)"]
                     + [by_kind[kind] for _ in readings for kind in ("averaged", "raw")])
    error = {e.kind: e.standard_error for e in rans.itertuples()}
    table.append(["measurements' standard error (RMS)"]
                 + [f"{error[kind]:.3f}" for _ in readings for kind in ("averaged", "raw")])
    header = ["model"] + [f"{r}, {kind}" for r in readings for kind in ("averaged", "raw")]
    return markdown(header, table)


def rows_table(rows, case, reading, kind="averaged"):
    """P_i/P_1 by row and position: measured, RANS and every model."""
    chosen = rows[(rows["case"] == case) & (rows["reading"] == reading) & (rows["kind"] == kind)]
    models = list(dict.fromkeys(chosen["model"]))
    first = chosen[chosen["model"] == models[0]]
    several = first["row"].nunique() > 1 or first["wind_direction"].nunique() > 1
    table = []
    for index, point in enumerate(first.itertuples()):
        if np.isnan(point.measured):
            continue
        label = ([f"{point.row}, {point.wind_direction:g} deg"] if several else []) + [point.position]
        values = [float(chosen[chosen["model"] == m]["ratio"].iloc[index]) for m in models]
        rans = [] if np.isnan(point.rans) else [float(point.rans)]
        table.append(label + [f"{point.measured:.3f} +- {point.standard_error:.3f}"]
                     + (rans if not np.isnan(first["rans"]).all() else []) + values)
    header = (["row"] if several else []) + ["position", "measured"]
    header += [] if np.isnan(first["rans"]).all() else ["RANS"]
    return markdown(header + models, table)


def efficiency_table(effs):
    errors = efficiency_errors(effs[effs["kind"] == "raw"])
    readings = list(dict.fromkeys(errors["reading"]))
    table = []
    for model in dict.fromkeys(errors["model"]):
        row = [model]
        for reading in readings:
            (e,) = errors[(errors["model"] == model) & (errors["reading"] == reading)].itertuples()
            row.append(_cell(e.rmse, e.bias))
        table.append(row)
    return markdown(["model"] + readings, table)


def atmosphere_table(readings=ATMOSPHERES):
    """Per case: the measured I_u, and for each atmosphere z0, I_u(z_h), k_w and x0/D."""
    rows = []
    for case in list(SINGLE_WAKE_CASES.values()) + list(FARM_CASES.values()):
        ct = case.thrust_coefficient  # a farm's: its turbine's at the case's wind speed
        row = [case.name, f"{case.streamwise_turbulence:.3f}"]
        for reading in readings:
            block = atmosphere(case, reading)
            k_w, x0 = wake_scales(case, block, ct)
            row += [f"{block['roughness_length']:.3g}", f"{hub_turbulence(case, block):.3f}",
                    f"{k_w:.4f}", f"{x0:.2f}"]
        rows.append(row)
    header = ["case", "measured I_u(z_h)"]
    for reading in readings:
        header += [f"{reading} z0 [m]", f"{reading} I_u(z_h)", f"{reading} k_w", f"{reading} x0/D"]
    return markdown(header, rows)


def tables(errors, rows, effs, readings=ATMOSPHERES) -> str:
    parts = ["# Validation tables (examples/validate.py)", "",
             "## Atmospheres", "", atmosphere_table(readings), ""]
    for reading in readings:
        for reference in ("measured", "les"):
            parts += [f"## Single wakes, {reading} atmosphere, against the {LABEL[reference]} arcs: "
                      "RMSE (bias) of U/U0", "", case_table(errors, reading, reference), ""]
    for reading in readings:
        parts += [f"## Single wakes by downstream distance, {reading} atmosphere", "",
                  distance_table(errors, reading), ""]
    for case in dict.fromkeys(rows["case"]):
        parts += [f"## {case}, P_i/P_1 over the waked positions: RMSE (bias)", "",
                  rows_error_table(rows, case), ""]
        for reading in readings:
            parts += [f"## {case} by position, {reading} atmosphere, direction-averaged", "",
                      rows_table(rows, case, reading), ""]
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


def _row_panel(ax, rows, row, direction, kind, models):
    chosen = rows[(rows["row"] == row) & (rows["wind_direction"] == direction)
                  & (rows["kind"] == kind)]
    first = chosen[(chosen["model"] == models[0]) & (chosen["reading"] == "matched")]
    ax.errorbar(first["position"], first["measured"], yerr=first["standard_error"], fmt="ko",
                ms=4, capsize=3, label="measured")
    if not first["rans"].isna().all():
        ax.plot(first["position"], first["rans"], "k-.", lw=1.0, label="RANS")
    for model in models:
        line = chosen[(chosen["model"] == model) & (chosen["reading"] == "matched")]
        ax.plot(line["position"], line["ratio"], label=model, **STYLE[model])
    ax.set_xticks(first["position"])
    ax.grid(alpha=0.3)


def rows_figure(rows, output, dpi=100):
    rows = rows[rows["case"] == HORNS_REV.name]
    models = list(dict.fromkeys(rows["model"]))
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    for ax, kind in zip(axes, ("raw", "averaged")):
        _row_panel(ax, rows, "inner rows", 270.0, kind, models)
        site = rows[(rows["model"] == "M-1") & (rows["reading"] == "site") & (rows["kind"] == kind)]
        ax.plot(site["position"], site["ratio"], color="C3", lw=1.0, ls="-.", label="M-1, site ABL")
        ax.set_title(f"Horns Rev 1, 270 +- 2.5 deg, 8 m/s: {kind}"
                     + (" (direction uncertainty)" if kind == "averaged" else ""), fontsize=9)
        ax.set_xlabel("turbine along the row")
    axes[0].set_ylabel("P_i/P_1, inner-row mean")
    axes[1].legend(fontsize=7, ncol=2)
    fig.tight_layout()
    path = Path(output) / "validation_horns_rev_rows.png"
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def lillgrund_figure(rows, output, dpi=100):
    """Lillgrund's rows B and D at 222 and 207 deg, direction-averaged, matched atmosphere."""
    rows = rows[rows["case"] == LILLGRUND.name]
    models = list(dict.fromkeys(rows["model"]))
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharey=True)
    for ax, reference in zip(axes.ravel(), LILLGRUND.rows):
        direction, row = reference.wind_direction, reference.label
        _row_panel(ax, rows, row, direction, "averaged", models)
        ax.set_title(f"Lillgrund {row}, {direction:g} +- 2.5 deg, 9 m/s, sigma 3.3 deg", fontsize=9)
        ax.set_xlabel("position along the row (gap in row D: no turbine)")
    for ax in axes[:, 0]:
        ax.set_ylabel("P_i/P_1")
    axes[0, 1].legend(fontsize=7, ncol=2)
    fig.tight_layout()
    path = Path(output) / "validation_lillgrund_rows.png"
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def efficiency_figure(effs, output, dpi=100):
    les = HORNS_REV.efficiency
    fig, ax = plt.subplots(figsize=(10, 3.6))
    ax.plot(les.directions, les.efficiency, "ko-", ms=3, lw=1.0, label=les.source)
    matched = effs[(effs["reading"] == "matched") & (effs["kind"] == "raw")]
    for model in dict.fromkeys(matched["model"]):
        line = matched[matched["model"] == model]
        ax.plot(line["wind_direction"], line["efficiency"], label=model, **STYLE[model])
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
    args = arguments(__doc__, argv, flags=[(
        "--site-measured-turbulence", "also the site's roughness with the measured turbulence "
        "in the wake (the atmosphere block's turbulence_factor, as fit_site sets it)")])
    readings = ATMOSPHERES + ((SITE_MEASURED_TURBULENCE,) if args.site_measured_turbulence else ())
    start = time.perf_counter()
    profiles = single_wakes(readings=readings)
    errors = single_wake_errors(profiles)
    rows = farm_rows(readings=readings)
    effs = efficiency(readings=readings)
    text = tables(errors, rows, effs, readings)
    print(text)
    (args.output / "validation_tables.md").write_text(text + "\n")
    rows.to_csv(args.output / "validation_rows.csv", index=False)
    effs.to_csv(args.output / "validation_efficiency.csv", index=False)
    written = [arcs_figure(profiles, name, args.output) for name in SINGLE_WAKE_CASES]
    written += [rows_figure(rows, args.output), lillgrund_figure(rows, args.output),
                efficiency_figure(effs, args.output)]
    if args.gallery is not None:
        main_models = ["M-1", "M-3", "GCH", "cc", "TurbOPark"]
        for name in SINGLE_WAKE_CASES:
            distances = (2.0, 3.0, 5.0) if name == "Nordtank-500" else None
            written.append(arcs_figure(profiles, name, args.gallery, distances, dpi=80,
                                       models=main_models))
        written += [rows_figure(rows, args.gallery, dpi=70),
                    lillgrund_figure(rows, args.gallery, dpi=70),
                    efficiency_figure(effs, args.gallery, dpi=70)]
    report(written, start)


if __name__ == "__main__":
    main()
