"""Power of a disk in the wake of the paper's turbine, P/P0 of Eq. (P_ratio), through FLORIS.

    python examples/paper_power.py [--output DIR] [--gallery DIR]

The power losses of the paper's Section 4.4 (Narasimhan, Gayme & Meneveau, JRSE 2025): an
un-yawed actuator disk (the same as the upstream one, C_T' = 1.33, D = z_h = 100 m) at
x_T/D = 4, 6, 8, 10 and
y_T/D in [-4, 4] behind the paper's turbine yawed by beta = 0, +20, -20 deg, in CNBL, SBL-4,
SBL-5 and SBL-6 (``inputs/cnbl.yaml``, ``sbl4.yaml``, ``sbl5.yaml``, ``sbl6.yaml``), for M-1, M-2,
M-3 and FLORIS's GCH and cc on the same Ekman inflow (models as in ``examples/paper_cases.py``).

P/P0 = P(x_T, y_T) / P0 with P0 = 1/2 rho pi R^2 C_T' [U_h (1 - a)]^3 (Eq. P0_ref): P is the power
FLORIS gives the downstream ``actuator-disk`` turbine, 1/2 rho pi R^2 C_T' [(1 - a) U_d]^3 with
U_d its rotor average of u (Eqs. P_hyp, Ud), so P/P0 = (U_d/U_h)^3, Eq. (P_ratio). FLORIS runs
all cases and yaws as conditions of one model (per-condition atmospheres) and the y_T of one x_T as
a few rows of downstream turbines at least ``ROW_SPACING`` apart, which do not interact (no wake
reaches a turbine in the same rotor plane; tests/docs/test_examples.py checks a row against two-turbine
farms). The rotor average is
FLORIS's, on the quadrature ``ROTOR_SOLVERS`` (the inputs' turbine grid, whose rotor cells
integrate the disk, for M-1, M-2 and M-3; FLORIS's finest cubature for GCH and cc); it is checked against a direct disk integration of
Eq. (P_ratio): a polar Gauss rule (16 x 48 points) over the disk of the flow FLORIS samples behind
the upstream turbine alone. For GCH and cc behind a yawed turbine the two differ by more than the
quadrature: FLORIS computes their yaw-added recovery and secondary steering differently in its
turbine solve and in its flow sampling, also without this package
(tests/docs/test_examples.py::test_floris_gch_turbine_solve_and_flow_sampling_differ_behind_yaw); the
P/P0 shown is the turbine solve's, what FLORIS gives a farm.

Prints the minimum P/P0 and its y_T for each case, yaw, x_T and model, the differences between
models at y_T = 0 and at the minimum, and per model and case the largest difference between
FLORIS's rotor average and the disk integration. Writes to DIR (default ./output) ``paper_power_ratio_beta{0,+20,-20}.png``
(rows: cases, columns: x_T; lines: FLORIS, markers: the disk integration of M-1).
"""

from __future__ import annotations

import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from paper_cases import (  # noqa: E402
    BETAS,
    MODELS,
    STYLE,
    WAKE_CASES,
    Case,
    arguments,
    beta_tag,
    model_config,
    report,
)

from floris import FlorisModel  # noqa: E402

from floris_ekman_veer.plugin.rotor.turbine import induction_factor  # noqa: E402

#: FLORIS's rotor quadrature for the downstream disk, per model: the inputs' own 3 x 3 turbine
#: grid for this package's models, whose rotor cells integrate the disk
#: (docs/coupling.md#rotor-average); FLORIS's finest cubature for its own models, which take
#: point values.
CUBATURE = {"type": "turbine_cubature_grid", "turbine_grid_points": 10}
ROTOR_SOLVERS = {"M-1": None, "M-2": None, "M-3": None, "GCH": CUBATURE, "cc": CUBATURE}
X_T_OVER_D = (4.0, 6.0, 8.0, 10.0)
Y_T_OVER_D = np.linspace(-4.0, 4.0, 81)
#: Least lateral distance [D] of two downstream disks in one FLORIS run (rotors must not
#: intersect; a sparse row also keeps FLORIS's cost, quadratic in the turbine count, low).
ROW_SPACING = 1.05
#: Direct disk integration of Eq. P_ratio: Gauss-Legendre in r (weight r) x uniform in theta.
DISK_RADIAL, DISK_ANGULAR = 16, 48


# ----------------------------------------------------------------------------------- set-up
def conditions_model(cases: list[Case], name: str, betas=BETAS, solver="model"
                     ) -> tuple[FlorisModel, np.ndarray]:
    """One FLORIS model of ``name`` whose conditions are every (case, beta), case-major; the
    atmosphere inputs that differ between cases become per-condition lists. Returns the model
    (one turbine at the origin) and the upstream yaw of each condition. ``solver``: a FLORIS
    solver block, None for the input's, "model" for ROTOR_SOLVERS[name]."""
    config = model_config(cases[0].config, name)
    atmosphere = config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    for key in atmosphere:
        values = [case.atmosphere[key] for case in cases for _ in betas]
        atmosphere[key] = values if len(set(values)) > 1 else values[0]
    n = len(cases) * len(betas)
    config["flow_field"].update(
        wind_speeds=[case.wind_speed for case in cases for _ in betas],
        turbulence_intensities=[case.turbulence for case in cases for _ in betas],
        wind_directions=[270.0] * n,
    )
    if solver == "model":
        solver = ROTOR_SOLVERS[name]
    if solver is not None:
        config["solver"] = dict(solver)
    return FlorisModel(config), np.tile(np.asarray(betas, float), len(cases))


def reference_power(case: Case, air_density: float) -> float:
    """P0 of Eq. (P0_ref): the un-yawed disk in the hub-height wind U_h [W]."""
    a = induction_factor(case.ct_prime)
    area = np.pi * case.radius**2
    return 0.5 * air_density * area * case.ct_prime * (case.hub_speed * (1.0 - a)) ** 3


# ----------------------------------------------------------------------------------- P/P0
def separated_rows(y_t, spacing=ROW_SPACING) -> list[np.ndarray]:
    """Indices of y_T (in D) split into rows whose neighbours are at least ``spacing`` apart."""
    y_t = np.asarray(y_t, float)
    rows: list[list[int]] = []
    for k in np.argsort(y_t):
        row = next((row for row in rows if y_t[k] - y_t[row[-1]] >= spacing), None)
        if row is None:
            rows.append([k])
        else:
            row.append(k)
    return [np.array(row) for row in rows]


def floris_power_ratios(cases: list[Case], name: str, betas=BETAS, x_t=X_T_OVER_D,
                        y_t=Y_T_OVER_D, solver="model") -> np.ndarray:
    """P/P0 from FLORIS's power of the downstream disk, shape (cases, betas, x_t, y_t)."""
    fmodel, yaw = conditions_model(cases, name, betas, solver)
    D = cases[0].diameter
    density = fmodel.core.flow_field.air_density
    p0 = np.repeat([reference_power(case, density) for case in cases], len(betas))
    y_t = np.asarray(y_t, float)
    ratios = np.empty((len(cases) * len(betas), len(x_t), y_t.size))
    for k, x in enumerate(x_t):
        for row in separated_rows(y_t):
            yaw_angles = np.zeros((yaw.size, 1 + row.size))
            yaw_angles[:, 0] = yaw
            fmodel.set(layout_x=[0.0] + [x * D] * row.size, layout_y=[0.0] + list(y_t[row] * D),
                       yaw_angles=yaw_angles)
            fmodel.run()
            ratios[:, k, row] = fmodel.get_turbine_powers()[:, 1:] / p0[:, None]
    return ratios.reshape(len(cases), len(betas), len(x_t), y_t.size)


def disk_quadrature(radius: float, radial=DISK_RADIAL, angular=DISK_ANGULAR):
    """Offsets (dy, dz) and weights (sum 1) of a polar Gauss rule on a disk of ``radius``."""
    s, w = np.polynomial.legendre.leggauss(radial)
    s, w = 0.5 * (s + 1.0), 0.5 * w  # on [0, 1]
    theta = (np.arange(angular) + 0.5) * 2.0 * np.pi / angular
    r = radius * s[:, None]
    weights = (w * s)[:, None] * np.ones_like(theta)
    return (r * np.cos(theta)).ravel(), (r * np.sin(theta)).ravel(), \
        (weights / weights.sum()).ravel()


def disk_power_ratios(cases: list[Case], name: str, betas=BETAS, x_t=X_T_OVER_D,
                      y_t=Y_T_OVER_D, radial=DISK_RADIAL, angular=DISK_ANGULAR) -> np.ndarray:
    """Eq. (P_ratio) integrated directly: [mean over the disk of u]^3 / U_h^3 with u sampled
    through FLORIS behind the upstream turbine alone; shape (cases, betas, x_t, y_t)."""
    fmodel, yaw = conditions_model(cases, name, betas)
    fmodel.set(yaw_angles=yaw[:, None])
    D, hub = cases[0].diameter, cases[0].hub_height
    dy, dz, weights = disk_quadrature(0.5 * D, radial, angular)
    y_t = np.asarray(y_t, float)
    shape = (len(x_t), y_t.size, dy.size)
    x = np.broadcast_to(np.asarray(x_t)[:, None, None] * D, shape).ravel()
    y = np.broadcast_to(y_t[None, :, None] * D + dy, shape).ravel()
    z = np.broadcast_to(hub + dz, shape).ravel()
    u = fmodel.sample_flow_at_points(x, y, z).reshape((yaw.size,) + shape)
    u_h = np.repeat([case.hub_speed for case in cases], len(betas))
    ratios = (u @ weights / u_h[:, None, None]) ** 3
    return ratios.reshape(len(cases), len(betas), len(x_t), y_t.size)


def minima(ratios: np.ndarray, y_t=Y_T_OVER_D) -> tuple[np.ndarray, np.ndarray]:
    """(y_T/D, P/P0) of the minimum along the last axis, refined by a parabola through the
    three lowest samples."""
    y_t = np.asarray(y_t, float)
    i = np.clip(np.argmin(ratios, axis=-1), 1, y_t.size - 2)
    take = lambda k: np.take_along_axis(ratios, k[..., None], axis=-1)[..., 0]  # noqa: E731
    a, b, c = take(i - 1), take(i), take(i + 1)
    curvature = a - 2.0 * b + c
    shift = np.where(curvature > 0, 0.5 * (a - c) / np.where(curvature > 0, curvature, 1.0), 0.0)
    step = y_t[1] - y_t[0]
    return y_t[i] + shift * step, b - 0.25 * (a - c) * shift


# ----------------------------------------------------------------------------------- output
def print_tables(results: dict, disks: dict) -> None:
    print("Minimum P/P0 over y_T/D in [-4, 4] and its y_T/D (FLORIS, Eq. P_ratio)")
    header = "".join(f"{f'x_T = {x:g} D':>15}" for x in X_T_OVER_D)
    for j, beta in enumerate(BETAS):
        print(f"\n beta = {beta:+g} deg\n  {'case':<6}{'model':>6}{header}")
        for i, case in enumerate(WAKE_CASES):
            for name in MODELS:
                y_min, p_min = minima(results[name][i, j])
                cells = "".join(f"{f'{p:.3f} ({y:+.2f})':>15}" for p, y in zip(p_min, y_min))
                print(f"  {case:<6}{name:>6}{cells}")
    centre = int(np.argmin(np.abs(Y_T_OVER_D)))
    print("\nModel differences: P/P0 at y_T = 0 minus M-1's, and min P/P0 minus M-1's "
          "(beta = 0 | +20 | -20; x_T = 6 D, 10 D)")
    for i, case in enumerate(WAKE_CASES):
        for name in MODELS[1:]:
            cells = []
            for j in range(len(BETAS)):
                for k in (1, 3):
                    at_0 = results[name][i, j, k, centre] - results["M-1"][i, j, k, centre]
                    at_min = minima(results[name][i, j, k])[1] - minima(results["M-1"][i, j, k])[1]
                    cells.append(f"{at_0:+.3f}/{at_min:+.3f}")
            print(f"  {case:<6}{name:>5}  " + "  ".join(cells))
    print("\nFLORIS rotor average (ROTOR_SOLVERS) against the direct disk integration "
          f"({DISK_RADIAL} x {DISK_ANGULAR}): largest |Delta P/P0| over x_T and y_T, "
          "beta = 0 | beta = +-20 deg")
    print(f"  {'model':<6}" + "".join(f"{case:>16}" for case in WAKE_CASES))
    for name in MODELS:
        difference = np.abs(results[name] - disks[name]).max(axis=(2, 3))
        print(f"  {name:<6}" + "".join(f"{f'{d[0]:.4f} | {d[1:].max():.4f}':>16}"
                                        for d in difference))
    print("  (GCH and cc behind a yawed turbine: FLORIS's turbine solve and its flow sampling "
          "differ, also without\n   this package: yaw-added recovery and secondary steering "
          "are computed differently on the two grids)")


def power_ratio_figure(results: dict, disk: np.ndarray, beta: float, output: Path,
                       cases=WAKE_CASES, dpi: int = 90) -> Path:
    j = BETAS.index(beta)
    rows = [WAKE_CASES.index(name) for name in cases]
    fig, axes = plt.subplots(len(rows), len(X_T_OVER_D), figsize=(14, 2.3 * len(rows) + 0.9),
                             sharex=True, sharey="row", constrained_layout=True, squeeze=False)
    for r, i in enumerate(rows):
        for k, x_t in enumerate(X_T_OVER_D):
            ax = axes[r, k]
            for name in MODELS:
                ax.plot(Y_T_OVER_D, results[name][i, j, k], lw=1.6, label=name, **STYLE[name])
            ax.plot(Y_T_OVER_D[::4], disk[i, j, k, ::4], "ko", ms=3, mfc="none",
                    label="M-1, disk integral")
            ax.set_title(f"{WAKE_CASES[i]}, $x_T/D$ = {x_t:g}", fontsize=10)
            ax.grid(alpha=0.3)
            if k == 0:
                ax.set_ylabel(r"$P/P_0$")
            if r == len(rows) - 1:
                ax.set_xlabel(r"$y_T/D$")
    axes[0, 0].legend(loc="lower left", fontsize=8)
    fig.suptitle(rf"P/P0 (Eq. P_ratio) of a disk behind a turbine yawed by $\beta$ = {beta:+g} deg")
    prefix = "paper" if tuple(cases) == WAKE_CASES else \
        "_".join(name.replace("-", "").lower() for name in cases)
    path = output / f"{prefix}_power_ratio_beta{beta_tag(beta)}.png"
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def main(argv=None) -> None:
    args = arguments(__doc__, argv)
    start = time.perf_counter()

    cases = [Case(name) for name in WAKE_CASES]
    results = {name: floris_power_ratios(cases, name) for name in MODELS}
    disks = {name: disk_power_ratios(cases, name) for name in MODELS}
    print_tables(results, disks)
    disk = disks["M-1"]
    written = [power_ratio_figure(results, disk, beta, args.output) for beta in BETAS]
    if args.gallery is not None:
        written.append(power_ratio_figure(results, disk, 0.0, args.gallery,
                                          cases=("CNBL", "SBL-6"), dpi=70))
    report(written, start)


if __name__ == "__main__":
    main()
