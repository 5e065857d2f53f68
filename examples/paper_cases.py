"""The single-turbine cases of Narasimhan, Gayme & Meneveau (JRSE 2025), run through FLORIS: wakes.

    python examples/paper_cases.py [--output DIR] [--gallery DIR]

Cases (paper Table 1): CNBL and SBL-1..6, one input each, ``inputs/cnbl.yaml``,
``inputs/sbl1.yaml`` ... ``inputs/sbl6.yaml`` (actuator disk C_T' = 1.33, D = z_h = 100 m;
G = 15 m/s, f_c = 1e-4 1/s, z0 = 0.1 m, N = 6.1e-3 1/s, Theta0 = 265 K, Q0 = C_r h). FLORIS is
driven by |(U, V)(z_h)| of the ABL with G = 15 m/s, which each file holds.

Models (paper Section 4.4): M-1 = ``ekman_veer`` velocity + deflection (yaw and veer); M-2 = the
same with the veer deflection off; M-3 = ``bastankhah2014`` (Bastankhah & Porte-Agel 2014) with
neither yaw nor veer deflection (behind a yawed disk it takes the rotor-normal loading,
docs/wake_model.md#m-3); and, on the same Ekman inflow, FLORIS's GCH (gauss velocity and
deflection, secondary steering, yaw-added recovery, Crespo-Hernandez turbulence) and cc (with the
same GCH settings, as FLORIS's own ``cc.yaml``), with the turbulence intensity I_u(z_h) of the
atmosphere and ``wind_veer = 0``. Yaw beta = 0, +20, -20 deg (FLORIS's positive yaw = the paper's
positive beta: wake to -y).

Prints, per case and yaw, the thrust coefficient the wake sees, x0/D (Eq. x0_transition),
C(x) = Delta u_max/U_h at 5 D and 10 D (Eq. Cx; at 10 D also read back from FLORIS) and the M-1
wake centre at 10 D at hub height and half a radius below/above it. Writes to DIR (default
./output), all figures of M-1 unless named otherwise:

* ``paper_cx.png``: C(x) for beta = 0, +-20 deg in CNBL, SBL-4, SBL-5, SBL-6, Eq. (Cx) and the
  largest deficit sampled through FLORIS, with the x0 lines (the paper's C(x) figure);
* ``paper_cross_planes_beta{0,+20,-20}.png``: Delta u/U_h at x/D = 1, 3, 5, 8, 11 for CNBL,
  SBL-4, SBL-5, SBL-6 with the rotor circle (the paper's contour figures);
* ``paper_vertical_planes.png``: Delta u/U_h in the plane y = 0 for the four cases and three yaws;
* ``paper_horizontal_planes_beta{0,+20,-20}.png``: Delta u/U_h at z - z_h = +D/2, 0, -D/2;
* ``paper_models_SBL-4_beta0.png``, ``paper_models_SBL-5_beta+20.png``,
  ``paper_models_SBL-6_beta-20.png``: M-1, M-2, M-3, GCH and cc at x/D = 4, 6, 8, 10 (the paper's
  model-comparison contour figures).

``--gallery DIR`` also writes small copies of a few figures for the README (``docs/``).
The power ratios are ``examples/paper_power.py``; the ABL profiles ``examples/abl_profiles.py``.
"""

from __future__ import annotations

import argparse
import copy
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

REPOSITORY = Path(__file__).resolve().parent.parent
import floris_ekman_veer  # noqa: F401  (registers the models and the Ekman inflow hook)

from floris import FlorisModel  # noqa: E402
from floris.cut_plane import rescale_axis  # noqa: E402
from floris.flow_visualization import visualize_cut_plane  # noqa: E402
from floris.utilities import load_yaml  # noqa: E402

from floris_ekman_veer import EkmanABL  # noqa: E402
from floris_ekman_veer.plugin.inflow.inflow import ambient_velocity  # noqa: E402
from floris_ekman_veer.studies.validity import validity_report, validity_summary  # noqa: E402
from floris_ekman_veer.wake.deficit import max_deficit, potential_core_length  # noqa: E402

INPUTS = REPOSITORY / "inputs"
#: The paper's Table 1 cases and their inputs.
CASE_FILES = {
    "CNBL": "cnbl.yaml", "SBL-1": "sbl1.yaml", "SBL-2": "sbl2.yaml", "SBL-3": "sbl3.yaml",
    "SBL-4": "sbl4.yaml", "SBL-5": "sbl5.yaml", "SBL-6": "sbl6.yaml",
}
#: The cases of the paper's wake and power figures (Sections 4.2 to 4.4).
WAKE_CASES = ("CNBL", "SBL-4", "SBL-5", "SBL-6")
MODELS = ("M-1", "M-2", "M-3", "GCH", "cc")
STYLE = {"M-1": dict(color="m", ls="-."), "M-2": dict(color="b", ls="-"),
         "M-3": dict(color="c", ls=":"), "GCH": dict(color="0.35", ls="--"),
         "cc": dict(color="tab:orange", ls=(0, (1, 1.5)))}
BETAS = (0.0, 20.0, -20.0)
CROSS_X_OVER_D = (1.0, 3.0, 5.0, 8.0, 11.0)
COMPARISON_X_OVER_D = (4.0, 6.0, 8.0, 10.0)
#: The paper's model-comparison contour figures: (case, beta).
COMPARISONS = (("SBL-4", 0.0), ("SBL-5", 20.0), ("SBL-6", -20.0))
HORIZONTAL_OFFSETS = (0.5, 0.0, -0.5)  # (z - z_h)/D
#: FLORIS's own parameter blocks (gauss, cc, crespo_hernandez) are those of the farm input.
BUILTIN_BLOCKS = INPUTS / "farm_sbl6.yaml"
DEFICIT_LEVELS = np.linspace(0.0, 0.5, 21)


def beta_tag(beta: float) -> str:
    """File-name tag of a yaw angle: 0, +20, -20."""
    return "0" if beta == 0 else f"{beta:+.0f}"


# ----------------------------------------------------------------------------------- set-up
def builtin_model_config(config: dict, velocity_model: str) -> dict:
    """``config`` with FLORIS's ``velocity_model`` (gauss or cc) in its GCH set-up (gauss
    deflection, secondary steering, yaw-added recovery, Crespo-Hernandez turbulence, sosfs), the
    atmosphere block kept, so the inflow stays the Ekman profile."""
    config = copy.deepcopy(config)
    blocks = load_yaml(BUILTIN_BLOCKS)["wake"]
    wake = config["wake"]
    wake["model_strings"].update(velocity_model=velocity_model, deflection_model="gauss",
                                 turbulence_model="crespo_hernandez", combination_model="sosfs")
    wake.update(enable_secondary_steering=True, enable_yaw_added_recovery=True,
                enable_transverse_velocities=True)
    for kind, name in (("wake_deflection_parameters", "gauss"),
                       ("wake_velocity_parameters", velocity_model),
                       ("wake_turbulence_parameters", "crespo_hernandez")):
        wake.setdefault(kind, {})[name] = blocks[kind][name]
    return config


def model_config(config: dict, name: str) -> dict:
    """The input ``config`` (an ekman_veer paper case) set up for model ``name`` of MODELS."""
    if name in ("GCH", "cc"):
        return builtin_model_config(config, "gauss" if name == "GCH" else "cc")
    config = copy.deepcopy(config)
    wake = config["wake"]
    deflection = wake["wake_deflection_parameters"]["ekman_veer"]
    if name == "M-2":
        deflection["veer"] = False
    elif name == "M-3":
        wake["model_strings"]["velocity_model"] = "bastankhah2014"
        # M-3 has neither yaw nor veer deflection, also behind a yawed rotor.
        deflection.update(veer=False, yaw_deflection=False)
        wake["wake_velocity_parameters"].setdefault("bastankhah2014", {})
    elif name != "M-1":
        raise ValueError(f"model must be one of {MODELS}, got {name!r}")
    return config


class Case:
    """One paper case: its FLORIS input (per model) and its ABL."""

    def __init__(self, name: str):
        self.name = name
        config = load_yaml(INPUTS / CASE_FILES[name])
        self.atmosphere = dict(config["wake"]["wake_velocity_parameters"]["ekman_veer"]
                               ["atmosphere"])
        turbine = config["farm"]["turbine_type"][0]
        self.diameter = float(turbine["rotor_diameter"])
        self.radius = 0.5 * self.diameter
        self.hub_height = float(turbine["hub_height"])
        self.ct_prime = float(turbine["power_thrust_table"]["ct_prime"])
        flow = config["flow_field"]
        self.reference_height = float(flow["reference_wind_height"])
        self.wind_speed = float(flow["wind_speeds"][0])
        # the ABL FLORIS solves from the file's wind speed (G = 15 m/s, tests/plugin/test_inputs.py)
        self.abl = EkmanABL.from_reference_wind(self.wind_speed, self.reference_height,
                                                **self.atmosphere)
        self.hub_speed = float(self.abl.speed(self.hub_height))
        self.turbulence = float(flow["turbulence_intensities"][0])
        self.k_w = float(self.abl.wake_expansion_rate(self.hub_height))
        self.config = config
        self._models: dict[str, FlorisModel] = {}
        self._yaw: dict[str, float] = {}

    def model(self, name: str, beta: float = 0.0) -> FlorisModel:
        """FLORIS model ``name`` with the turbine yawed by ``beta`` [deg] (FLORIS's set() rebuilds
        the whole model, so it is called only when the yaw changes)."""
        if name not in self._models:
            self._models[name] = FlorisModel(model_config(self.config, name))
        fmodel = self._models[name]
        if self._yaw.get(name) != beta:
            fmodel.set(yaw_angles=np.array([[beta]]))
            self._yaw[name] = beta
        return fmodel

    def ambient(self, z) -> np.ndarray:
        """Hub-aligned ambient U(z) (FLORIS's inflow: the reference height is the hub height)."""
        u, _ = ambient_velocity(self.abl, np.asarray(z, float), self.reference_height)
        return u

    def thrust_coefficient(self, beta: float) -> float:
        """The un-yawed-basis C_T the M-1 formulas use: FLORIS's ct_i / cos(beta)."""
        fmodel = self.model("M-1", beta)
        fmodel.run()
        ct_i = float(fmodel.get_turbine_thrust_coefficients()[0, 0])
        return ct_i / np.cos(np.deg2rad(beta))


# ----------------------------------------------------------------------------------- numbers
def cx_curve(case: Case, beta: float, x_over_d) -> tuple[np.ndarray, float]:
    """(C(x) of Eq. Cx at x/D, x0/D of Eq. x0_transition) behind the disk yawed by beta."""
    yaw, ct = np.deg2rad(beta), case.thrust_coefficient(beta)
    x = np.asarray(x_over_d, float) * case.diameter
    c = max_deficit(x, case.k_w, case.radius, ct, yaw)
    return np.asarray(c), float(potential_core_length(case.k_w, case.radius, ct, yaw)
                                / case.diameter)


def sampled_max_deficit(case: Case, beta: float, x_over_d, resolution: float = 0.02
                        ) -> np.ndarray:
    """Largest Delta u/U_h in each cross plane x/D, sampled through FLORIS (M-1) on a grid of
    ``resolution`` D over y in [-2.5 D, 2.5 D], z in [0.05 D, 2 D] (one call for all planes)."""
    D = case.diameter
    y = np.arange(-2.5, 2.5 + 1e-9, resolution) * D
    z = np.arange(0.05, 2.0 + 1e-9, resolution) * D
    x = np.asarray(x_over_d, float) * D
    xx, yy, zz = np.meshgrid(x, y, z, indexing="ij")
    u = case.model("M-1", beta).sample_flow_at_points(xx.ravel(), yy.ravel(), zz.ravel())[0]
    deficit = (case.ambient(zz.ravel()) - u).reshape(xx.shape) / case.hub_speed
    return deficit.reshape(x.size, -1).max(axis=1)


def wake_centres(case: Case, fmodel: FlorisModel, x: float, heights,
                 resolution: float = 0.005) -> tuple[np.ndarray, np.ndarray]:
    """(y_c, Delta u_max/U_h) at each height: the largest deficit along y, sampled through FLORIS
    on a ``resolution`` D grid over +-3 D and refined by a parabola through the three best points."""
    dy = resolution * case.diameter
    y = np.arange(-3.0 * case.diameter, 3.0 * case.diameter + 0.5 * dy, dy)
    heights = np.asarray(heights, float)
    yy, zz = np.meshgrid(y, heights)
    u = fmodel.sample_flow_at_points(np.full(yy.size, x), yy.ravel(), zz.ravel())[0]
    deficit = (case.ambient(zz) - u.reshape(zz.shape)) / case.hub_speed
    rows = np.arange(heights.size)
    i = np.clip(np.argmax(deficit, axis=1), 1, y.size - 2)
    a, b, c = deficit[rows, i - 1], deficit[rows, i], deficit[rows, i + 1]
    curvature = a - 2.0 * b + c
    shift = np.where(curvature < 0, 0.5 * (a - c) / np.where(curvature < 0, curvature, -1.0), 0.0)
    return y[i] + shift * dy, b - 0.25 * (a - c) * shift


def print_wake_table(cases: dict[str, Case]) -> None:
    heights_d = (-0.25, 0.0, 0.25)  # (z - z_h)/D: half a radius below, hub, half a radius above
    print("Wake of the disk (M-1; beta > 0 sends the wake to -y; C_T: the un-yawed-basis "
          "thrust coefficient FLORIS's actuator disk hands the wake)")
    print(f"  {'case':<6}{'beta':>6}{'C_T':>7}{'k_w':>8}{'x0/D':>7}{'C(5D)':>8}{'C(10D)':>8}"
          f"{'FLORIS':>8}   {'y_c/D at 10 D: z_h-R/2':>23}{'z_h':>7}{'z_h+R/2':>9}")
    for case in cases.values():
        for beta in BETAS:
            (c5, c10), x0 = cx_curve(case, beta, (5.0, 10.0))
            heights = case.hub_height + np.array(heights_d) * case.diameter
            centres, peaks = wake_centres(case, case.model("M-1", beta), 10.0 * case.diameter,
                                          heights)
            yc = centres / case.diameter
            print(f"  {case.name:<6}{beta:+6.0f}{case.thrust_coefficient(beta):7.4f}"
                  f"{case.k_w:8.4f}{x0:7.2f}{c5:8.4f}{c10:8.4f}{peaks[1]:8.4f}   "
                  f"{yc[0]:+23.3f}{yc[1]:+7.3f}{yc[2]:+9.3f}")
    print("  (FLORIS: the largest Delta u/U_h at hub height 10 D behind, sampled through FLORIS; "
          "it equals C(10D).\n   y_c: position of the largest deficit along y at that height: "
          "veer shifts the wake to +y below the hub and to -y above it)")


# ----------------------------------------------------------------------------------- planes
def deficit_plane(case: Case, plane, heights=None):
    """A FLORIS CutPlane with u replaced by Delta u/U_h = (U(z) - u)/U_h, axes in D."""
    z = plane.df.x2.to_numpy() if heights is None else heights
    deficit = (case.ambient(z) - plane.df.u.to_numpy()) / case.hub_speed
    plane.df["u"] = np.where(np.abs(deficit) < 1e-9, 0.0, deficit)  # round-off: -1e-16
    rescale_axis(plane, case.diameter, case.diameter)
    return plane


def cross_plane(case: Case, name: str, beta: float, x_over_d: float, resolution=(81, 49)):
    """Delta u/U_h in the cross plane x/D (y in [-2 D, 2 D], z in [0.02 D, 2 D])."""
    D = case.diameter
    plane = case.model(name, beta).calculate_cross_plane(
        downstream_dist=x_over_d * D, y_resolution=resolution[0], z_resolution=resolution[1],
        y_bounds=(-2.0 * D, 2.0 * D), z_bounds=(0.02 * D, 2.0 * D),
    )
    return deficit_plane(case, plane)


def vertical_plane(case: Case, beta: float, resolution=(121, 41)):
    """Delta u/U_h in the plane y = 0, x in [-1 D, 14 D], z in [0.02 D, 2 D] (M-1)."""
    D = case.diameter
    plane = case.model("M-1", beta).calculate_y_plane(
        crossstream_dist=0.0, x_resolution=resolution[0], z_resolution=resolution[1],
        x_bounds=(-1.0 * D, 14.0 * D), z_bounds=(0.02 * D, 2.0 * D),
    )
    return deficit_plane(case, plane)


def horizontal_plane(case: Case, beta: float, offset_d: float, resolution=(121, 61)):
    """Delta u/U_h at z = z_h + offset_d D, x in [-1 D, 14 D], y in [-2 D, 2 D] (M-1)."""
    D = case.diameter
    height = case.hub_height + offset_d * D
    plane = case.model("M-1", beta).calculate_horizontal_plane(
        height=height, x_resolution=resolution[0], y_resolution=resolution[1],
        x_bounds=(-1.0 * D, 14.0 * D), y_bounds=(-2.0 * D, 2.0 * D),
    )
    return deficit_plane(case, plane, heights=np.full(len(plane.df), height))


def draw(plane, ax, title: str) -> None:
    visualize_cut_plane(plane, ax=ax, min_speed=DEFICIT_LEVELS[0], max_speed=DEFICIT_LEVELS[-1],
                        clevels=DEFICIT_LEVELS, levels=DEFICIT_LEVELS[1::4], cmap="viridis")
    ax.set_title(title, fontsize=9)


def rotor_circle(ax, case: Case) -> None:
    """The rotor's edge; and +y on the left, as seen looking downstream. (FLORIS's
    visualize_cut_plane inverts the axis of each cross plane, which on shared axes toggles.)"""
    ax.set_xlim(2.0, -2.0)
    ax.add_patch(plt.Circle((0.0, case.hub_height / case.diameter), 0.5, fill=False, ls="--",
                            color="w", lw=0.8))


def colour_bar(fig, axes) -> None:
    fig.colorbar(np.ravel(axes)[0].collections[0], ax=axes, shrink=0.8, label=r"$\Delta u / U_h$")


# ----------------------------------------------------------------------------------- figures
def cx_figure(cases: dict[str, Case], output: Path) -> tuple[Path, dict]:
    x_d = np.linspace(0.0, 15.0, 301)
    marks = np.arange(1.0, 15.0, 1.0)
    fig, axes = plt.subplots(len(BETAS), len(WAKE_CASES), figsize=(14, 8.5), sharex=True,
                             sharey=True, constrained_layout=True)
    x0s = {}
    for i, beta in enumerate(BETAS):
        for j, name in enumerate(WAKE_CASES):
            case, ax = cases[name], axes[i, j]
            c, x0 = cx_curve(case, beta, x_d)
            x0s[(name, beta)] = x0
            ax.plot(x_d, c, "k-", lw=1.5, label="Eq. (Cx)")
            ax.plot(marks, sampled_max_deficit(case, beta, marks), "mo", ms=4, mfc="none",
                    label="largest deficit through FLORIS")
            ax.axvline(x0, color="k", ls=":", lw=1)
            ax.text(x0 + 0.2, 0.52, f"$x_0/D$ = {x0:.2f}", fontsize=8)
            ax.set_title(f"{name}, beta = {beta:+g} deg", fontsize=10)
            ax.grid(alpha=0.3)
            if i == len(BETAS) - 1:
                ax.set_xlabel("x/D")
            if j == 0:
                ax.set_ylabel(r"$C(x) = \Delta u_{max}/U_h$")
    axes[0, 0].set_ylim(0.0, 0.6)
    axes[0, 0].legend(fontsize=8, loc="lower left")
    fig.suptitle("Maximum velocity deficit C(x) (M-1) and the end of the potential core x0")
    path = output / "paper_cx.png"
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path, x0s


def contour_figure(shape, figsize, panel, xlabel: str, ylabel: str, title: str, path: Path,
                   dpi: int = 90) -> Path:
    """A grid of Delta u/U_h contour panels, ``panel(ax, i, j)`` drawing panel (i, j)."""
    fig, axes = plt.subplots(*shape, figsize=figsize, sharex=True, sharey=True,
                             constrained_layout=True, squeeze=False)
    for (i, j), ax in np.ndenumerate(axes):
        panel(ax, i, j)
    for ax in axes[-1]:
        ax.set_xlabel(xlabel)
    for ax in axes[:, 0]:
        ax.set_ylabel(ylabel)
    colour_bar(fig, axes)
    fig.suptitle(title)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def cross_planes_figure(cases: dict[str, Case], beta: float, output: Path) -> Path:
    """M-1 cross planes at CROSS_X_OVER_D (columns) for the WAKE_CASES (rows)."""
    def panel(ax, i, j):
        case, x_d = cases[WAKE_CASES[i]], CROSS_X_OVER_D[j]
        draw(cross_plane(case, "M-1", beta, x_d), ax, f"{case.name}, x/D = {x_d:g}")
        rotor_circle(ax, case)

    return contour_figure(
        (len(WAKE_CASES), len(CROSS_X_OVER_D)), (14.5, 7.8), panel, "y/D (looking downstream)",
        "z/D", f"M-1 wake behind a disk yawed by beta = {beta:+g} deg (dashed: rotor)",
        output / f"paper_cross_planes_beta{beta_tag(beta)}.png",
    )


def gallery_cross_planes_figure(case: Case, output: Path) -> Path:
    """A small copy for the README: M-1 cross planes of one case, rows beta = 0, +20, -20."""
    def panel(ax, i, j):
        draw(cross_plane(case, "M-1", BETAS[i], CROSS_X_OVER_D[j]), ax,
             f"beta = {BETAS[i]:+g} deg, x/D = {CROSS_X_OVER_D[j]:g}")
        rotor_circle(ax, case)

    return contour_figure(
        (len(BETAS), len(CROSS_X_OVER_D)), (13, 5.6), panel, "y/D (looking downstream)", "z/D",
        rf"{case.name}: M-1 wake $\Delta u/U_h$ behind a disk yawed by $\beta$; dashed: rotor",
        output / f"{case.name.replace('-', '').lower()}_cross_planes.png", dpi=70,
    )


def vertical_planes_figure(cases: dict[str, Case], output: Path) -> Path:
    def panel(ax, i, j):
        draw(vertical_plane(cases[WAKE_CASES[i]], BETAS[j]), ax,
             f"{WAKE_CASES[i]}, beta = {BETAS[j]:+g} deg")
        ax.plot([0.0, 0.0], [0.5, 1.5], "w-", lw=2)  # the rotor

    return contour_figure((len(WAKE_CASES), len(BETAS)), (14, 8), panel, "x/D", "z/D",
                          "M-1 wake in the vertical plane y = 0",
                          output / "paper_vertical_planes.png")


def horizontal_planes_figure(cases: dict[str, Case], beta: float, output: Path) -> Path:
    def panel(ax, i, j):
        offset = HORIZONTAL_OFFSETS[i]
        draw(horizontal_plane(cases[WAKE_CASES[j]], beta, offset), ax,
             f"{WAKE_CASES[j]}, $(z - z_h)/D$ = {offset:+g}")
        ax.plot([0.0, 0.0], [-0.5, 0.5], "w-", lw=2)

    return contour_figure(
        (len(HORIZONTAL_OFFSETS), len(WAKE_CASES)), (15, 7), panel, "x/D", "y/D",
        f"M-1 wake in horizontal planes, beta = {beta:+g} deg (veer: +y below the hub, -y above)",
        output / f"paper_horizontal_planes_beta{beta_tag(beta)}.png",
    )


def models_figure(case: Case, beta: float, output: Path) -> Path:
    def panel(ax, i, j):
        draw(cross_plane(case, MODELS[i], beta, COMPARISON_X_OVER_D[j]), ax,
             f"{MODELS[i]}, x/D = {COMPARISON_X_OVER_D[j]:g}")
        rotor_circle(ax, case)

    return contour_figure(
        (len(MODELS), len(COMPARISON_X_OVER_D)), (11.5, 8), panel, "y/D (looking downstream)",
        "z/D", f"{case.name}, beta = {beta:+g} deg: M-1 (yaw + veer), M-2 (veer off), M-3 "
        "(Bastankhah & Porte-Agel 2014), FLORIS GCH and cc on the same inflow",
        output / f"paper_models_{case.name}_beta{beta_tag(beta)}.png",
    )


def report(written, start: float) -> None:
    """Print the figures written and the time taken since ``start`` (perf_counter)."""
    print("\nFigures:")
    for path in written:
        print(f"  {path}")
    print(f"Done in {time.perf_counter() - start:.1f} s")


def arguments(doc: str, argv=None, gallery: bool = True, flags=()) -> argparse.Namespace:
    """The examples' command line: --output DIR (created) and, for some, --gallery DIR; each
    of ``flags``, (name, help) pairs, an on/off option of the script."""
    parser = argparse.ArgumentParser(description=doc.split("\n")[0])
    parser.add_argument("--output", type=Path, default=Path("output"),
                        help="directory for the figures (default ./output)")
    if gallery:
        parser.add_argument("--gallery", type=Path, default=None,
                            help="also write the README gallery's small PNGs to this directory")
    for name, text in flags:
        parser.add_argument(name, action="store_true", help=text)
    args = parser.parse_args(argv)
    args.output.mkdir(parents=True, exist_ok=True)
    if gallery and args.gallery is not None:
        args.gallery.mkdir(parents=True, exist_ok=True)
    return args

# ----------------------------------------------------------------------------------- main
def main(argv=None) -> None:
    args = arguments(__doc__, argv)
    start = time.perf_counter()

    cases = {name: Case(name) for name in WAKE_CASES}
    for name in WAKE_CASES:  # the paper's own cases: inside its envelope by construction
        case_input = INPUTS / f"{name.lower().replace('-', '')}.yaml"
        print(validity_summary(validity_report(FlorisModel(case_input)), name))
    print_wake_table(cases)
    path, x0s = cx_figure(cases, args.output)
    written = [path]
    print("\nx0/D (Eq. x0_transition): " + ", ".join(
        f"{name} {x0s[(name, 0.0)]:.2f}" for name in WAKE_CASES) + " (beta = 0)")
    for beta in BETAS:
        written.append(cross_planes_figure(cases, beta, args.output))
        written.append(horizontal_planes_figure(cases, beta, args.output))
    written.append(vertical_planes_figure(cases, args.output))
    for name, beta in COMPARISONS:
        written.append(models_figure(cases[name], beta, args.output))
    if args.gallery is not None:
        written.append(gallery_cross_planes_figure(cases["SBL-6"], args.gallery))
    report(written, start)


if __name__ == "__main__":
    main()
