"""FLORIS integration of the ekman_veer wake models (plugin/wake_models/models.py), in FLORIS's regression style.

Everything here goes through FLORIS itself (FlorisModel built from the package's YAML inputs, its
turbine, cubature, planar and points grids, its solvers), and checks the result against the
paper's formulas written out independently in this file (Narasimhan, Gayme & Meneveau, JRSE 2025,
Section 2; docs/conventions.md, docs/coupling.md):

1. the YAML switch on every FLORIS grid, finite fields down to the ground, turbine grid = points;
2. limits: zero yaw without veer is Bastankhah & Porte-Agel (2014) with k* = k_w for x >= x0,
   the potential core, the yaw mirror and the southern-hemisphere mirror;
3. directions: veer shifts the wake to +y below and -y above hub height, positive yaw to -y (as
   FLORIS's gauss), and the yawed wake centre of Eq. (yhatc);
4. regression baselines (FLORIS style arrays of rotor-averaged velocity, Ct, power and axial
   induction), rotation invariance and vectorised = one-at-a-time conditions;
6. bad input (item 5, registration, is tests/test_registry.py).

Regression baselines are marked as such: they were generated once from this code (set DEBUG = True
to print them) and are pinned to catch unintended changes; the physics assertions next to them are
what establishes correctness.
"""

from __future__ import annotations

import copy
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel, flow_visualization
from floris.core.rotor_velocity import average_velocity
from floris.utilities import load_yaml

import floris_ekman_veer  # noqa: F401  (registers the models)
from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.plugin.inflow.inflow import ambient_velocity
from floris_ekman_veer.plugin.wake_models.models import (
    EkmanVeerVelocityDeficit,
    EkmanVeerVelocityDeflection,
    Gaussian2014VelocityDeficit,
)
from floris_ekman_veer.wake.deficit import potential_core_length
from tests.conftest import TABLE1_SBL6_MU, own_turbine

DEBUG = False

INPUTS = Path(__file__).resolve().parents[3] / "inputs"

# The paper's actuator disk (inputs/turbines/actuator_disk_les.yaml): D = z_h = 100 m, C_T' = 1.33.
D, R, HUB = 100.0, 50.0, 100.0
CT_PRIME = 1.33
AIR_DENSITY = 1.225

# The farm turbine (NREL 5 MW of FLORIS's library) of inputs/farm_sbl6.yaml; farm spacing 5 D is
# 630 m, as in FLORIS's own regression tests.
D_5MW, HUB_5MW = 125.88, 90.0
SPACING = 630.0


# ----------------------------------------------------------------------------------------------
# Independent formulas (written here from the paper, not imported from the package)


# The stable atmospheres of these farms give, in some conditions and by design, boundary layers
# shallower than the NREL 5 MW rotor top (153 m); their ShallowBoundaryLayerWarning is not what
# is tested here (tests/physics/test_shallow_abl.py and tests/test_user_inputs_and_warnings.py are).
pytestmark = pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")


def disk_thrust_coefficient(yaw_deg=0.0):
    """Un-yawed-basis C_T(beta) = 16 C_T' / (4 + C_T' cos^2 beta)^2 of the fixed-C_T' disk."""
    cos2 = np.cos(np.deg2rad(yaw_deg)) ** 2
    return 16.0 * CT_PRIME / (4.0 + CT_PRIME * cos2) ** 2


def disk_induction(yaw_deg=0.0):
    cos2 = np.cos(np.deg2rad(yaw_deg)) ** 2
    return CT_PRIME * cos2 / (4.0 + CT_PRIME * cos2)


def paper_k_w(abl, hub_height):
    """Eq. (kw_CNBL_SBL_model) with the paper's constants."""
    u_star, h = abl.friction_velocity, abl.boundary_layer_height
    turbulent = 0.33 * np.sqrt(1.25 * np.log(h / hub_height) + 0.6) * u_star / abl.speed(hub_height)
    return (0.021**6 + turbulent**6) ** (1.0 / 6.0)


def bp2014(x_over_d, ct, k):
    """Bastankhah & Porte-Agel (2014): (C, sigma/D) at x/D."""
    beta_bp = 0.5 * (1.0 + np.sqrt(1.0 - ct)) / np.sqrt(1.0 - ct)
    sigma = k * x_over_d + 0.2 * np.sqrt(beta_bp)
    return 1.0 - np.sqrt(1.0 - ct / (8.0 * sigma**2)), sigma


def yaw_wake_centre(abl, x, z, yaw_deg, ct, radius, hub_height, u_local):
    """y_c of Eqs. (yc_xz), (yhatc), (that) without the veer term (metres)."""
    beta = np.deg2rad(yaw_deg)
    root = np.sqrt(1.0 - ct * np.cos(beta) ** 2)
    a_star = (1.0 + root) / (2.0 * root)
    u_star, u_h = abl.friction_velocity, abl.speed(hub_height)
    t = (-1.44 * u_h / u_star / np.sqrt(a_star) * ct * np.cos(beta) ** 2 * np.sin(beta)
         * (1.0 - np.exp(-0.35 * u_star / u_local * x / radius)))
    at, pi = abs(t), np.pi
    cvp = ((pi - 1) * at**3 + 2 * np.sqrt(3) * pi**2 * t**2 + 48 * (pi - 1) ** 2 * at) / (
        2 * pi * (pi - 1) * t**2 + 4 * np.sqrt(3) * pi**2 * at + 96 * (pi - 1) ** 2) * np.sign(t)
    image = -2.0 / pi * t / (((z + hub_height) / (radius * np.sqrt(a_star))) ** 2 - 1.0)
    return (cvp + image) * radius * np.sqrt(a_star)


# ----------------------------------------------------------------------------------------------
# Helpers


#: The exclusive stability inputs of an atmosphere block (docs/atmosphere.md#input-ranges).
STABILITY_INPUTS = {"stability_parameter", "cooling_rate", "surface_heat_flux", "sensible_heat_flux",
                    "obukhov_length"}


def config(case, *, veer=None, curl=None, atmosphere=None, **flow_field):
    """An input of inputs/<case>.yaml as a dict, with a few changes."""
    cfg = load_yaml(str(INPUTS / f"{case}.yaml"))
    wake = cfg["wake"]
    if veer is not None:
        wake["wake_deflection_parameters"]["ekman_veer"]["veer"] = veer
    if curl is not None:
        wake["wake_velocity_parameters"]["ekman_veer"]["curl"] = curl
    if atmosphere is not None:
        block = wake["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
        if STABILITY_INPUTS & set(atmosphere):  # a stability given replaces the input's
            for key in STABILITY_INPUTS:
                block.pop(key, None)
        block.update(atmosphere)
    cfg["flow_field"].update(flow_field)
    return cfg


def atmosphere_of(cfg, findex=0):
    atm = cfg["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"]
    flow = cfg["flow_field"]
    return EkmanABL.from_reference_wind(
        flow["wind_speeds"][findex], flow["reference_wind_height"], **atm
    )


def sample(fmodel, x, y, z, findex=0):
    """u at the broadcast points (x, y, z), shaped like them."""
    x, y, z = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (x, y, z)))
    u = fmodel.sample_flow_at_points(x.ravel(), y.ravel(), z.ravel())
    return u[findex].reshape(x.shape)


def wake_centre(fmodel, x, z, y_bounds):
    """y of the deficit maximum (velocity minimum) along y at (x, z): 1 m scan, then 0.025 m
    scan around the minimum and a parabola through the three lowest points."""
    ys = np.arange(y_bounds[0], y_bounds[1] + 1e-9, 1.0)
    u = sample(fmodel, x, ys, z)
    i = int(np.argmin(u))
    assert 0 < i < ys.size - 1, "wake centre outside the scanned range"
    fine = ys[i] + np.arange(-1.5, 1.5 + 1e-9, 0.025)
    u = sample(fmodel, x, fine, z)
    j = int(np.argmin(u))
    f0, f1, f2 = u[j - 1], u[j], u[j + 1]
    return fine[j] + 0.5 * 0.025 * (f0 - f2) / (f0 - 2.0 * f1 + f2)


def results_array(fmodel):
    """FLORIS regression layout: (n_findex, n_turbines, [velocity, Ct, power, axial induction])."""
    return np.stack(
        [
            fmodel.turbine_average_velocities,
            fmodel.get_turbine_thrust_coefficients(),
            fmodel.get_turbine_powers(),
            fmodel.get_turbine_ais(),
        ],
        axis=-1,
    )


def print_baseline(results):
    for condition in results:
        print("[")
        for v, ct, p, ai in condition:
            print(f"    [{v:.7f}, {ct:.7f}, {p:.7f}, {ai:.7f}],")
        print("],")


def assert_results_arrays(test, baseline):
    assert np.shape(test) == np.shape(baseline)
    np.testing.assert_allclose(test, baseline, rtol=1e-6, atol=1e-8)


def finite_and_physical(u, inflow):
    """No NaN/inf, no negative speed, and no speed-up: every deficit is >= 0."""
    assert np.all(np.isfinite(u))
    assert np.all(u >= 0.0)
    assert np.all(u <= inflow + 1e-9)


# ==============================================================================================
# 1. The YAML switch, every FLORIS grid, finite fields


@pytest.mark.parametrize("case", ["cnbl", "sbl6", "farm_sbl6"])
def test_package_inputs_select_and_run_the_models(case):
    fmodel = FlorisModel(str(INPUTS / f"{case}.yaml"))
    assert type(fmodel.core.wake.velocity_model) is EkmanVeerVelocityDeficit
    assert type(fmodel.core.wake.deflection_model) is EkmanVeerVelocityDeflection
    fmodel.run()
    powers = fmodel.get_turbine_powers()
    assert np.all(np.isfinite(fmodel.core.flow_field.u)) and np.all(powers > 0)
    if case == "farm_sbl6":  # 3 x 3 at 7 D, wind from the west: columns at x = 0, 882, 1764 m
        columns = powers.reshape(3, 3)  # turbine order: x-major
        assert np.all(columns[1] < 0.8 * columns[0]) and np.all(columns[2] < columns[0])
        unwaked = FlorisModel(str(INPUTS / f"{case}.yaml"))
        unwaked.run_no_wake()
        np.testing.assert_array_equal(powers[0, :3], unwaked.get_turbine_powers()[0, :3])


def test_switching_model_names_keeps_the_ekman_inflow():
    """bastankhah2014 (M-3) and FLORIS's gauss run on the same input by name, on the same Ekman
    inflow (identical unwaked turbines). At zero yaw M-3 centred by the ekman_veer deflection is
    M-1 (t_hat = 0: no curl, same sigma and C), through FLORIS's solver and wake combination;
    yawed, it is not (no curl, no yaw-dependent C)."""
    def run(velocity, deflection, yaw=0.0):
        cfg = config("farm_sbl6")
        cfg["wake"]["model_strings"].update(velocity_model=velocity, deflection_model=deflection)
        if velocity == "gauss":  # FLORIS's gauss as FLORIS runs it (its wakes' squares summed)
            cfg["wake"]["model_strings"]["combination_model"] = "sosfs"
        cfg["wake"]["wake_velocity_parameters"].setdefault(velocity, {})  # FLORIS needs a block
        fmodel = FlorisModel(cfg)
        fmodel.set(yaw_angles=np.full((1, 9), yaw))
        fmodel.run()
        velocities = fmodel.turbine_average_velocities[0]
        assert np.all(np.isfinite(velocities))
        return fmodel, velocities

    fmodel, m1 = run("ekman_veer", "ekman_veer")
    assert type(fmodel.core.wake.velocity_model) is EkmanVeerVelocityDeficit
    fmodel, m3 = run("bastankhah2014", "ekman_veer")
    assert type(fmodel.core.wake.velocity_model) is Gaussian2014VelocityDeficit
    _, gauss = run("gauss", "gauss")
    np.testing.assert_array_equal(gauss[:3], m1[:3])  # x = 0: unwaked, same inflow
    # To the rotor cells' cut-off: sub-point rows where a wake stays below 1e-5 U_h are not
    # integrated, and the two models bound their wakes differently (plugin/wake_models/models.py).
    np.testing.assert_allclose(m3, m1, rtol=1e-6)
    assert np.max(np.abs(gauss[3:] - m1[3:])) > 0.05

    _, m1_yawed = run("ekman_veer", "ekman_veer", yaw=20.0)
    _, m3_yawed = run("bastankhah2014", "ekman_veer", yaw=20.0)
    assert np.max(np.abs(m3_yawed[3:] - m1_yawed[3:])) > 0.05


@pytest.mark.parametrize("case", ["cnbl", "sbl6"])
def test_planes_are_finite_down_to_the_ground_and_match_points(case):
    cfg = config(case)
    abl = atmosphere_of(cfg)
    fmodel = FlorisModel(cfg)
    fmodel.set(layout_x=[0.0, 500.0], layout_y=[0.0, 30.0], yaw_angles=[[20.0, -10.0]])

    def inflow(z):
        return ambient_velocity(abl, z, HUB)[0]

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no divide-by-zero or invalid values
        hub_plane = fmodel.calculate_horizontal_plane(
            height=HUB, x_resolution=41, y_resolution=21, x_bounds=(-200, 1500),
            y_bounds=(-300, 300)).df
        ground_plane = fmodel.calculate_horizontal_plane(
            height=0.0, x_resolution=11, y_resolution=7, x_bounds=(-200, 1500),
            y_bounds=(-300, 300)).df
        cross = fmodel.calculate_cross_plane(
            downstream_dist=800.0, y_resolution=25, z_resolution=31, y_bounds=(-300, 300),
            z_bounds=(0.0, 300.0)).df
        vertical = fmodel.calculate_y_plane(
            crossstream_dist=0.0, x_resolution=31, z_resolution=31, x_bounds=(-200, 1500),
            z_bounds=(0.0, 300.0)).df

    finite_and_physical(hub_plane.u.values, inflow(HUB))
    assert hub_plane.u.min() < 0.8 * abl.speed(HUB)  # the wakes are in the plane
    np.testing.assert_allclose(hub_plane.u[hub_plane.x1 < -100], abl.speed(HUB), rtol=1e-12)
    assert np.all(ground_plane.u.values == 0.0)  # z = 0 < z0: no flow, no wake, no NaN
    finite_and_physical(cross.u.values, inflow(cross.x2.values))
    finite_and_physical(vertical.u.values, inflow(vertical.x2.values))
    assert np.all(cross.u[cross.x2 < 0.1] == 0.0) and np.all(vertical.u[vertical.x2 < 0.1] == 0.0)

    # FLORIS's plotting of the plane (a headless matplotlib Figure, no pyplot state).
    from matplotlib.figure import Figure

    ax = Figure().subplots()
    flow_visualization.visualize_cut_plane(fmodel.calculate_horizontal_plane(
        height=HUB, x_resolution=21, y_resolution=11), ax=ax)
    assert np.all(np.isfinite(ax.collections[0].get_array()))

    # Planar grid = points grid at the same points.
    np.testing.assert_allclose(
        hub_plane.u, sample(fmodel, hub_plane.x1, hub_plane.x2, HUB), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(
        cross.u, sample(fmodel, 800.0, cross.x1, cross.x2), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(
        vertical.u, sample(fmodel, vertical.x1, 0.0, vertical.x2), rtol=1e-12, atol=1e-12)


#: The cubature grid's resolution advice (EkmanWakeModel._check_cubature), a RuntimeWarning.
CUBATURE_ADVICE = "thinner than the spacing of the turbine_cubature_grid points"


@pytest.mark.parametrize("wind_direction", [270.0, 263.0, 280.0])
def test_cubature_grid_equals_sampled_points(wind_direction):
    """FLORIS's cubature points (point values), sampled again with sample_flow_at_points, give
    the same velocities, and the actuator disk's power from the plain disk mean. (Turbine-grid
    points carry rotor-cell averages instead: tests/plugin/rotor/test_rotor_average.py.)"""
    yaw = np.array([20.0, -10.0, 0.0])
    fmodel = FlorisModel(config("sbl6"))
    fmodel.set(layout_x=[0.0, 500.0, 1000.0], layout_y=[0.0, 30.0, -20.0],
               wind_directions=[wind_direction], yaw_angles=[yaw],
               solver_settings={"type": "turbine_cubature_grid", "turbine_grid_points": 3})
    # 3 x 3 point values do not resolve SBL-6's sheared bands: said once, naming turbine_grid.
    with pytest.warns(RuntimeWarning, match=CUBATURE_ADVICE) as record:
        fmodel.run()
    assert sum("turbine_cubature_grid" in str(w.message) for w in record) == 1
    grid, u = fmodel.core.grid, fmodel.core.flow_field.u_sorted
    sampled = sample(fmodel, grid.x_sorted_inertial_frame, grid.y_sorted_inertial_frame,
                     grid.z_sorted_inertial_frame)
    np.testing.assert_allclose(sampled, u, rtol=1e-12, atol=1e-12)

    sampled = np.take_along_axis(sampled, grid.unsorted_indices, axis=1)
    # FLORIS 4.7's get_turbine_powers averages the rotor points with its default method (equal
    # weights, whatever the grid), so the disk's plain mean is that of the points.
    disk_mean = sampled.mean(axis=(2, 3))[0]
    cos_b = np.cos(np.deg2rad(yaw))
    a = CT_PRIME * cos_b**2 / (4.0 + CT_PRIME * cos_b**2)
    power = 0.5 * AIR_DENSITY * np.pi * R**2 * CT_PRIME * ((1.0 - a) * disk_mean * cos_b) ** 3
    np.testing.assert_allclose(fmodel.get_turbine_powers()[0], power, rtol=1e-10)


def test_isolated_turbines_never_sit_in_their_own_wake():
    """Regression of a bug found here: FLORIS takes x_i as the mean of a rotor's points, which can
    land a round-off upstream of the points themselves; the model then put the turbine in its own
    potential core (rotor speed down by about 2a U_h, e.g. 13.05 -> 10.06 m/s). Two turbines 4 km
    apart on a north-south line, wind from 30 to 150 and 210 to 330 deg (>= 2 km lateral offset):
    both must equal the no-wake run."""
    directions = np.concatenate([np.arange(30.0, 150.1, 4.0), np.arange(210.0, 330.1, 4.0)])
    speed = config("sbl6")["flow_field"]["wind_speeds"][0]
    cfg = config("sbl6", wind_directions=list(directions), wind_speeds=[speed] * directions.size,
                 turbulence_intensities=[0.029] * directions.size)
    cfg["farm"]["layout_x"], cfg["farm"]["layout_y"] = [0.0, 0.0], [0.0, 4000.0]
    wake = FlorisModel(cfg)
    wake.run()
    no_wake = FlorisModel(cfg)
    no_wake.run_no_wake()
    np.testing.assert_allclose(wake.get_turbine_powers(), no_wake.get_turbine_powers(), rtol=1e-13)


def test_cubature_and_rectangular_turbine_grids():
    """turbine_cubature_grid averages the unwaked disk like an independent polar quadrature of
    U(z) (rtol 1e-6); both turbine solvers run a yawed two-turbine case with finite results."""
    cfg = config("sbl6")
    abl = atmosphere_of(cfg)
    radii = np.sqrt((np.arange(400) + 0.5) / 400) * R  # equal-area rings
    angles = np.linspace(0.0, 2.0 * np.pi, 256, endpoint=False)
    disk = abl.hub_aligned_velocity(HUB + radii[:, None] * np.sin(angles), HUB)[0].mean()

    fmodel = FlorisModel(cfg)
    fmodel.set(solver_settings={"type": "turbine_cubature_grid", "turbine_grid_points": 5})
    fmodel.run()
    np.testing.assert_allclose(fmodel.turbine_average_velocities[0, 0], disk, rtol=1e-6)

    powers = {}
    for solver in ("turbine_grid", "turbine_cubature_grid"):
        fmodel = FlorisModel(cfg)
        fmodel.set(layout_x=[0.0, 500.0], layout_y=[0.0, 30.0], yaw_angles=[[20.0, 0.0]],
                   solver_settings={"type": solver, "turbine_grid_points": 3})
        if solver == "turbine_cubature_grid":
            # SBL-6's band is thinner than the 3 cubature points' spacing: said once.
            with pytest.warns(RuntimeWarning, match=CUBATURE_ADVICE) as record:
                fmodel.run()
            assert len([w for w in record if "turbine_cubature_grid" in str(w.message)]) == 1
        else:
            fmodel.run()
        assert np.all(np.isfinite(fmodel.core.flow_field.u))
        powers[solver] = fmodel.get_turbine_powers()[0]
        assert powers[solver][1] < powers[solver][0]
    # Two quadratures of the same disk (a 3 x 3 square and a 3-ring cubature): within 5 %.
    np.testing.assert_allclose(powers["turbine_grid"], powers["turbine_cubature_grid"], rtol=0.05)


def test_velocity_deficit_profiles_are_finite():
    fmodel = FlorisModel(config("sbl6"))
    fmodel.set(yaw_angles=[[20.0]])
    profiles = fmodel.sample_velocity_deficit_profiles(
        direction="cross-stream", downstream_dists=[500.0, 1000.0], resolution=41)
    profiles += fmodel.sample_velocity_deficit_profiles(
        direction="vertical", downstream_dists=[1000.0], resolution=21)
    for profile in profiles:
        assert np.all(np.isfinite(profile.velocity_deficit.values))


# ==============================================================================================
# 2. Limits


PAPER_CASES = {
    # case: (x0/D range the paper's text implies, C(5 D), C(10 D) regression baselines)
    "cnbl": ((2.85, 2.95), 0.2962457, 0.1318163),
    "sbl6": ((5.1, 5.3), 0.4990619, 0.2597346),
}


@pytest.mark.parametrize("case", ["cnbl", "sbl6"])
def test_zero_yaw_without_veer_is_bastankhah_porte_agel_2014(case):
    """u = U(z) - C U_h exp(-r^2 / (2 sigma^2)) with the BP14 C and sigma, k* = k_w, x >= x0;
    C = 2a in the potential core. Curl on or off makes no difference at zero yaw."""
    cfg = config(case, veer=False, curl=False)
    abl = atmosphere_of(cfg)
    k_w = paper_k_w(abl, HUB)
    np.testing.assert_allclose(abl.wake_expansion_rate(HUB), k_w, rtol=1e-12)
    ct = disk_thrust_coefficient()
    np.testing.assert_allclose(ct, 0.7490610, atol=1e-7)  # 4a(1 - a), a = 1.33/5.33
    u_h = abl.speed(HUB)

    x0 = potential_core_length(k_w, R, ct, 0.0)
    x0_range, c5_baseline, c10_baseline = PAPER_CASES[case]
    assert x0_range[0] < x0 / D < x0_range[1]
    c_x0, _ = bp2014(x0 / D, ct, k_w)
    np.testing.assert_allclose(c_x0, 2.0 * disk_induction(), rtol=1e-10)  # C continuous at x0

    fmodel = FlorisModel(cfg)
    fmodel.run()
    np.testing.assert_allclose(fmodel.get_turbine_thrust_coefficients()[0, 0], ct, rtol=1e-12)

    x_d = np.array([x0 / D, x0 / D + 0.5, 6.0, 8.0, 10.0, 15.0])[:, None, None]
    y = np.linspace(-1.5, 1.5, 7)[None, :, None] * D
    z = np.linspace(20.0, 200.0, 10)[None, None, :]
    u = sample(fmodel, x_d * D, y, z)
    c, sigma_d = bp2014(x_d, ct, k_w)
    inflow = abl.hub_aligned_velocity(z, HUB)[0]
    expected = inflow - c * u_h * np.exp(-(y**2 + (z - HUB) ** 2) / (2.0 * (sigma_d * D) ** 2))
    np.testing.assert_allclose(u, expected, rtol=0.0, atol=1e-9 * u_h)

    # Potential core: C = 2a on the axis for 0 < x <= x0.
    core = sample(fmodel, np.array([0.5, 0.99]) * x0, 0.0, HUB)
    np.testing.assert_allclose((u_h - core) / u_h, 2.0 * disk_induction(), rtol=1e-12)

    # C(5 D) and C(10 D) on the axis: BP14 beyond x0, 2a inside it.
    c_axis = (u_h - sample(fmodel, np.array([5.0, 10.0]) * D, 0.0, HUB)) / u_h
    expected_c = [bp2014(5.0, ct, k_w)[0] if 5.0 * D >= x0 else 2.0 * disk_induction(),
                  bp2014(10.0, ct, k_w)[0]]
    np.testing.assert_allclose(c_axis, expected_c, rtol=1e-12)
    # Regression baselines of the same two numbers (CNBL: BP14 at 5 D; SBL-6: 5 D < x0, 2a).
    np.testing.assert_allclose(c_axis, [c5_baseline, c10_baseline], rtol=1e-6)

    curled = FlorisModel(config(case, veer=False, curl=True))
    np.testing.assert_array_equal(sample(curled, x_d * D, y, z), u)


def test_yaw_mirror_symmetry_without_veer():
    """Veer off: u(x, y, z; beta) = u(x, -y, z; -beta), curl and ground image included; veer on
    breaks it (the test would notice a missing mirror)."""
    x = np.array([1.0, 3.0, 6.0, 10.0])[:, None, None] * D
    y = np.linspace(-2.0, 2.0, 17)[None, :, None] * D
    z = np.array([5.0, 40.0, 80.0, 100.0, 120.0, 160.0, 190.0])[None, None, :]
    for veer in (False, True):
        fields = {}
        for yaw in (25.0, -25.0):
            fmodel = FlorisModel(config("sbl6", veer=veer))
            fmodel.set(yaw_angles=[[yaw]])
            fields[yaw] = sample(fmodel, x, y, z)
        mirrored = fields[-25.0][:, ::-1, :]
        assert np.max(np.abs(fields[25.0] - fields[-25.0])) > 1.0  # yaw does something
        if veer:
            assert np.max(np.abs(fields[25.0] - mirrored)) > 1.0
        else:
            np.testing.assert_allclose(fields[25.0], mirrored, rtol=0.0, atol=1e-12)


def test_m3_behind_a_yawed_rotor_is_undeflected():
    """M-3 (bastankhah2014 with the ekman_veer deflection's yaw and veer terms off) has no
    deflection: behind a yawed rotor its wake is symmetric in y, centred on y = 0, and the same
    for +beta and -beta (the paper: M-3 always places the power minimum at y_T = 0)."""
    x = np.array([4.0, 10.0])[:, None, None] * D
    y = np.linspace(-2.0, 2.0, 17)[None, :, None] * D
    z = np.array([60.0, 100.0, 140.0])[None, None, :]
    fields = {}
    for yaw in (20.0, -20.0):
        cfg = config("sbl6")
        cfg["wake"]["model_strings"]["velocity_model"] = "bastankhah2014"
        cfg["wake"]["wake_deflection_parameters"]["ekman_veer"].update(
            veer=False, yaw_deflection=False
        )
        fmodel = FlorisModel(cfg)
        fmodel.set(yaw_angles=[[yaw]])
        fields[yaw] = sample(fmodel, x, y, z)
    np.testing.assert_allclose(fields[20.0], fields[20.0][:, ::-1, :], rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(fields[20.0], fields[-20.0], rtol=0.0, atol=1e-12)
    # the wake is there: the centre line is slower than 2 D to the side
    assert np.all(fields[20.0][:, 8, 1] < fields[20.0][:, 0, 1] - 0.5)


@pytest.mark.parametrize("case", ["cnbl", "sbl6"])
def test_m3_behind_a_yawed_disk_takes_the_rotor_normal_loading(case):
    """M-3 has no yaw: behind the fixed-C_T' disk yawed by beta it is the Gaussian of 2014 with
    the disk's rotor-normal loading C_T(beta) cos^2(beta) = 4 a(beta) (1 - a(beta))
    (docs/wake_model.md#m-3), written out here: its potential core is M-1's 2 a(beta), and the
    wake is shallower than behind the un-yawed disk (never deeper, as C_T(beta) would make it)."""
    cfg = config(case)
    cfg["wake"]["model_strings"]["velocity_model"] = "bastankhah2014"
    cfg["wake"]["wake_deflection_parameters"]["ekman_veer"].update(veer=False, yaw_deflection=False)
    abl = atmosphere_of(cfg)
    k_w, u_h = paper_k_w(abl, HUB), abl.speed(HUB)
    x_d = np.array([0.5, 4.0, 6.0, 10.0])[:, None]
    y, z = np.array([0.0, 30.0, -70.0])[None, :], HUB + 20.0
    inflow = abl.hub_aligned_velocity(z, HUB)[0]
    centre = {}
    for yaw in (0.0, 20.0, -20.0):
        fmodel = FlorisModel(cfg)
        fmodel.set(yaw_angles=[[yaw]])
        a = disk_induction(yaw)
        ct = 4.0 * a * (1.0 - a)
        assert ct == pytest.approx(disk_thrust_coefficient(yaw) * np.cos(np.deg2rad(yaw)) ** 2)
        beta_bp = 0.5 * (1.0 + np.sqrt(1.0 - ct)) / np.sqrt(1.0 - ct)
        sigma_d = k_w * x_d + 0.2 * np.sqrt(beta_bp)
        # far wake of Bastankhah & Porte-Agel (2014), capped at the core deficit 2a
        c = np.minimum(1.0 - np.sqrt(np.clip(1.0 - ct / (8.0 * sigma_d**2), 0.0, 1.0)), 2.0 * a)
        expected = inflow - c * u_h * np.exp(-(y**2 + (z - HUB) ** 2) / (2 * (sigma_d * D) ** 2))
        np.testing.assert_allclose(sample(fmodel, x_d * D, y, z), expected, rtol=0.0, atol=1e-9)
        # half a diameter behind the rotor the deficit is the potential core's 2a(beta), as M-1's
        assert c[0, 0] == pytest.approx(2.0 * a, rel=1e-12)
        centre[yaw] = c[:, 0]
    assert disk_induction(20.0) == pytest.approx(0.226966, abs=1e-6)
    np.testing.assert_array_equal(centre[20.0], centre[-20.0])
    assert np.all(centre[20.0] < centre[0.0])


def test_southern_hemisphere_is_the_mirror_image():
    """f_c -> -f_c with veer on: the field at (x, y, z) with yaw beta in the south equals the
    northern one at (x, -y, z) with yaw -beta; so do the powers of a mirrored farm."""
    x = np.array([1.0, 3.0, 6.0, 10.0])[:, None, None] * D
    y = np.linspace(-2.0, 2.0, 17)[None, :, None] * D
    z = np.array([5.0, 40.0, 80.0, 100.0, 120.0, 160.0, 190.0])[None, None, :]
    south_atmosphere = {"coriolis_parameter": -1.0e-4}
    north = FlorisModel(config("sbl6"))
    south = FlorisModel(config("sbl6", atmosphere=south_atmosphere))
    north.set(layout_x=[0.0, 500.0], layout_y=[0.0, -40.0], yaw_angles=[[-20.0, 10.0]])
    south.set(layout_x=[0.0, 500.0], layout_y=[0.0, 40.0], yaw_angles=[[20.0, -10.0]])
    u_north, u_south = sample(north, x, y, z), sample(south, x, -y, z)
    np.testing.assert_allclose(u_south, u_north, rtol=0.0, atol=1e-10)
    north.run()
    south.run()
    np.testing.assert_allclose(south.get_turbine_powers(), north.get_turbine_powers(), rtol=1e-12)

    # The southern veer is real: without the mirror the fields differ.
    same_side = FlorisModel(config("sbl6", atmosphere=south_atmosphere))
    same_side.set(layout_x=[0.0, 500.0], layout_y=[0.0, -40.0], yaw_angles=[[-20.0, 10.0]])
    assert np.max(np.abs(sample(same_side, x, y, z) - u_north)) > 1.0


# ==============================================================================================
# 3. Directions


def sbl4_config():
    """SBL-4 of the paper's Table 1: G = 15 m/s, C_r = -0.375 K/h; FLORIS's wind speed is the
    speed of that ABL at the reference height."""
    atmosphere = dict(coriolis_parameter=1.0e-4, roughness_length=0.1, cooling_rate=-0.375,
                      brunt_vaisala_frequency=6.1e-3, reference_potential_temperature=265.0)
    speed = float(EkmanABL(geostrophic_wind=15.0, **atmosphere).speed(HUB))
    cfg = config("sbl6", atmosphere=atmosphere, wind_speeds=[speed])
    np.testing.assert_allclose(atmosphere_of(cfg).geostrophic_wind, 15.0, rtol=1e-9)
    return cfg


def test_sbl4_veer_moves_the_wake_to_plus_y_below_and_minus_y_above_the_hub():
    cfg = sbl4_config()
    abl = atmosphere_of(cfg)
    fmodel = FlorisModel(cfg)
    x = 8.0 * D
    centres = {}
    for dz in (-0.4 * D, 0.0, 0.4 * D):
        centres[dz] = wake_centre(fmodel, x, HUB + dz, (-150.0, 150.0))
        U, V = abl.hub_aligned_velocity(HUB + dz, HUB)
        np.testing.assert_allclose(centres[dz], x * V / U, atol=0.05)  # Eq. (yc_veer), zero yaw
    assert centres[-0.4 * D] > 0.3 * D  # +0.51 D
    assert centres[0.4 * D] < -0.3 * D  # -0.59 D
    assert abs(centres[0.0]) < 0.05


def test_positive_yaw_moves_the_wake_to_minus_y_like_floris_gauss():
    defaults = FlorisModel.get_defaults()["wake"]
    centres = {}
    for model in ("ekman_veer", "gauss"):
        cfg = config("cnbl")
        cfg["wake"]["model_strings"].update(velocity_model=model, deflection_model=model,
                                            combination_model=defaults["model_strings"][
                                                "combination_model"] if model == "gauss" else "fls")
        cfg["wake"]["wake_velocity_parameters"]["gauss"] = defaults["wake_velocity_parameters"]["gauss"]
        cfg["wake"]["wake_deflection_parameters"]["gauss"] = (
            defaults["wake_deflection_parameters"]["gauss"])
        for yaw in (20.0, -20.0):
            fmodel = FlorisModel(cfg)
            fmodel.set(yaw_angles=[[yaw]])
            centres[model, yaw] = wake_centre(fmodel, 10.0 * D, HUB, (-200.0, 200.0))
    for model in ("ekman_veer", "gauss"):
        assert centres[model, 20.0] < -0.2 * D
        assert centres[model, -20.0] > 0.2 * D


@pytest.mark.parametrize(
    "case, baseline",
    # Regression baselines of the hub-height wake centre at 10 D for beta = +20 deg [m].
    [("cnbl", -41.381694), ("sbl6", -45.843920)],
)
def test_yawed_hub_height_wake_centre_at_10d(case, baseline):
    """beta = +20 deg: the sampled hub-height deficit maximum at 10 D is y_c of Eq. (yhatc) with
    t_hat of Eq. (that) and C_T(beta) of the fixed-C_T' disk; V(z_h) = 0, so no veer term."""
    cfg = config(case)
    abl = atmosphere_of(cfg)
    fmodel = FlorisModel(cfg)
    fmodel.set(yaw_angles=[[20.0]])
    fmodel.run()
    ct = disk_thrust_coefficient(20.0)
    np.testing.assert_allclose(ct, 0.7947826, atol=1e-7)
    # FLORIS hands the wake model ct_i = C_T(beta) cos(beta).
    np.testing.assert_allclose(fmodel.get_turbine_thrust_coefficients()[0, 0],
                               ct * np.cos(np.deg2rad(20.0)), rtol=1e-12)
    x = 10.0 * D
    expected = yaw_wake_centre(abl, x, HUB, 20.0, ct, R, HUB, abl.speed(HUB))
    centre = wake_centre(fmodel, x, HUB, (-150.0, 50.0))
    np.testing.assert_allclose(centre, expected, atol=0.05)
    np.testing.assert_allclose(centre, baseline, atol=0.05)
    assert -0.6 * D < centre < -0.3 * D


# ==============================================================================================
# 4. FLORIS regression style: NREL 5 MW farms in Table 1's SBL-6 state (farm_sbl6's blocks)


WIND_DIRECTIONS = [270.0, 270.0, 270.0, 280.0, 280.0, 280.0, 285.0, 285.0, 285.0]
WIND_SPEEDS = [8.0, 9.0, 10.0, 8.0, 9.0, 10.0, 8.0, 9.0, 10.0]
ROW = ([0.0, SPACING, 2 * SPACING], [0.0, 0.0, 0.0])
SQUARE = ([0.0, 0.0, SPACING, SPACING], [0.0, SPACING, 0.0, SPACING])

from tests.regression_baselines import baseline_row, baseline_square, yawed_baseline_row  # noqa: E402


def farm(layout, wind_directions=WIND_DIRECTIONS, wind_speeds=WIND_SPEEDS, yaw=None):
    # Table 1's SBL-6 state (mu = 148.49, h = 110-144 m at 8-10 m/s: a veered rotor layer with
    # the hub inside the ABL); the input's -1 K/h puts h at 71-92 m there, below the hub, where
    # the rotor sees the unveered geostrophic wind (tests.conftest.table1_sbl6).
    cfg = config("farm_sbl6", atmosphere={"stability_parameter": TABLE1_SBL6_MU},
                 wind_directions=list(wind_directions), wind_speeds=list(wind_speeds),
                 turbulence_intensities=[0.06] * len(wind_speeds))
    cfg["farm"]["layout_x"], cfg["farm"]["layout_y"] = list(layout[0]), list(layout[1])
    # The baselines pin the paper's model: its k_w and its Gaussian inside the potential core,
    # with FLORIS's free-stream sum of squares (the farm input's array coupling is pinned by
    # test_array_coupling_*, the near wake by tests/physics/test_near_wake.py).
    cfg["wake"]["wake_velocity_parameters"]["ekman_veer"].update(
        wake_expansion="ambient", deficit_velocity="free_stream", near_wake="potential_core")
    cfg["wake"]["model_strings"]["combination_model"] = "sosfs"
    fmodel = FlorisModel(cfg)
    if yaw is not None:
        fmodel.set(yaw_angles=np.tile(yaw, (len(wind_speeds), 1)))
    fmodel.run()
    return fmodel


def test_regression_row():
    fmodel = farm(ROW)
    results = results_array(fmodel)
    if DEBUG:
        print_baseline(results)
    assert_results_arrays(results, baseline_row)

    # Physics: the first turbine is unwaked at every direction; at 270 deg the others are waked.
    no_wake = farm(ROW)
    no_wake.run_no_wake()
    np.testing.assert_array_equal(results[:, 0], results_array(no_wake)[:, 0])
    waked = np.array(WIND_DIRECTIONS) == 270.0
    assert np.all(results[waked, 1:, 0] < 0.9 * results[waked, :1, 0])
    assert np.all(results[waked, 1:, 2] < 0.75 * results[waked, :1, 2])


def test_regression_row_yawed():
    yaw = [20.0, 0.0, 0.0]
    fmodel = farm(ROW, yaw=yaw)
    results = results_array(fmodel)
    if DEBUG:
        print_baseline(results)
    assert_results_arrays(results, yawed_baseline_row)

    # Physics: the yawed turbine sees the same inflow, its Ct is the cosine-loss Ct cos(20 deg)
    # times the veer-aware rotor's <u_n^2>/<(U cos b)^2>, below 1 at +20 deg in this veer
    # (docs/yaw_steering.md#the-veer-aware-rotor), it produces less; the downstream turbines
    # change because the wake moved.
    straight = results_array(farm(ROW))
    np.testing.assert_array_equal(results[:, 0, 0], straight[:, 0, 0])
    veer_factor = results[:, 0, 1] / (straight[:, 0, 1] * np.cos(np.deg2rad(20.0)))
    assert np.all((veer_factor > 0.85) & (veer_factor < 0.999)), veer_factor
    assert np.all(results[:, 0, 2] < 0.95 * straight[:, 0, 2])
    waked = np.array(WIND_DIRECTIONS) == 270.0
    assert np.all(np.abs(results[waked, 1, 0] - straight[waked, 1, 0]) > 0.05)


def test_regression_square():
    fmodel = farm(SQUARE)
    results = results_array(fmodel)
    if DEBUG:
        print_baseline(results)
    assert_results_arrays(results, baseline_square)
    # At 270 deg turbines 0 and 1 are upstream, 2 and 3 waked.
    waked = np.array(WIND_DIRECTIONS) == 270.0
    assert np.all(results[waked][:, 2:, 2] < 0.75 * results[waked][:, :2, 2])


def test_regression_rotation():
    """Layout rotated by 90 deg with the wind from 360 instead of 270: same turbine powers
    (relative 1e-8). Square: 270's turbines 0, 1, 2, 3 are 360's 1, 3, 0, 2. Row: along -y,
    first turbine yawed."""
    speeds = [8.0, 10.0]
    west = farm(SQUARE, [270.0] * 2, speeds).get_turbine_powers()
    north = farm(SQUARE, [360.0] * 2, speeds).get_turbine_powers()
    np.testing.assert_allclose(north[:, [1, 3, 0, 2]], west, rtol=1e-8)

    rotated_row = (ROW[1], [-x for x in ROW[0]])  # (x, y) -> (y, -x)
    for yaw in ([0.0, 0.0, 0.0], [20.0, 0.0, 0.0]):
        west = farm(ROW, [270.0] * 2, speeds, yaw=yaw).get_turbine_powers()
        north = farm(rotated_row, [360.0] * 2, speeds, yaw=yaw).get_turbine_powers()
        np.testing.assert_allclose(north, west, rtol=1e-8)


def test_vectorised_conditions_equal_one_at_a_time():
    yaw = [20.0, 0.0, 0.0]
    together = results_array(farm(ROW, yaw=yaw))
    for i, (wd, ws) in enumerate(zip(WIND_DIRECTIONS, WIND_SPEEDS)):
        alone = results_array(farm(ROW, [wd], [ws], yaw=yaw))
        np.testing.assert_allclose(alone[0], together[i], rtol=1e-10)


# ==============================================================================================
# 6. Bad input


@pytest.mark.parametrize("block", ["wake_velocity_parameters", "wake_deflection_parameters"])
def test_unknown_model_parameter_fails_at_build(block):
    """ValueError naming the block's input path and the key (FLORIS's own from_dict check would
    raise AttributeError)."""
    cfg = config("cnbl")
    cfg["wake"][block]["ekman_veer"]["no_such_key"] = 1.0
    with pytest.raises(ValueError, match=rf"wake\.{block}\.ekman_veer: unknown key\(s\) \['no_such_key'\]"):
        FlorisModel(cfg)


def test_unknown_atmosphere_key_fails_at_build():
    cfg = config("cnbl", atmosphere={"no_such_key": 1.0})
    with pytest.raises(ValueError, match=r"atmosphere: unknown key\(s\) \['no_such_key'\]"):
        FlorisModel(cfg)


def test_thrust_coefficient_beyond_momentum_theory():
    """NREL 5 MW at 3 m/s (the user's copy: a warning, not FLORIS's own turbine's notice):
    FLORIS hands C_T = 0.9999 (its clip of the table's value); the wake is
    evaluated at max_thrust_coefficient = 0.96 with a RuntimeWarning, i.e. it is BP14 at
    C_T = 0.96 (veer off, zero yaw), and everything is finite."""
    cfg = own_turbine(config("farm_sbl6", veer=False, wind_speeds=[3.0],
                             reference_wind_height=HUB_5MW))
    cfg["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"] = copy.deepcopy(
        config("cnbl")["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"])
    cfg["farm"]["layout_x"], cfg["farm"]["layout_y"] = [0.0], [0.0]
    abl = atmosphere_of(cfg)
    fmodel = FlorisModel(cfg)
    with pytest.warns(RuntimeWarning, match="max_thrust_coefficient"):
        fmodel.run()
    assert fmodel.get_turbine_thrust_coefficients()[0, 0] > 0.99
    k_w = paper_k_w(abl, HUB_5MW)
    x0 = potential_core_length(k_w, 0.5 * D_5MW, 0.96, 0.0)
    assert 0.0 < x0 < 0.5 * D_5MW  # a = 0.4: a short potential core
    x_d = np.array([1.0, 3.0, 6.0, 10.0])[:, None]
    z = np.linspace(10.0, 200.0, 9)[None, :]
    with pytest.warns(RuntimeWarning, match="max_thrust_coefficient"):
        u = sample(fmodel, x_d * D_5MW, 20.0, z)
    c, sigma_d = bp2014(x_d, 0.96, k_w)
    expected = (abl.hub_aligned_velocity(z, HUB_5MW)[0] - c * abl.speed(HUB_5MW)
                * np.exp(-(20.0**2 + (z - HUB_5MW) ** 2) / (2.0 * (sigma_d * D_5MW) ** 2)))
    np.testing.assert_allclose(u, expected, rtol=0.0, atol=1e-9)
    assert np.all(np.isfinite(fmodel.get_turbine_powers()))


def test_heavily_loaded_yawed_rotor_limits_the_normal_loading():
    """Yawed by 20 deg, the NREL 5 MW at 3 m/s (C_T = 0.9999) loads its rotor normal with
    C_T cos^2 = 0.883 < 0.96: M-1 evaluates it as it is, and M-3, which takes that rotor-normal
    loading as its thrust coefficient (docs/wake_model.md#m-3), too (no warning); un-yawed, the
    same rotor is limited (warning) by both. All stay finite."""
    for velocity_model, yaw, warns in (
        ("ekman_veer", 20.0, False), ("bastankhah2014", 20.0, False),
        ("ekman_veer", 0.0, True), ("bastankhah2014", 0.0, True),
    ):
        # (the user's copy of the NREL 5 MW: the limit is a warning, not FLORIS's own's notice)
        cfg = own_turbine(config("farm_sbl6", wind_speeds=[3.0], reference_wind_height=HUB_5MW))
        cfg["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"] = copy.deepcopy(
            config("cnbl")["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"])
        cfg["wake"]["model_strings"]["velocity_model"] = velocity_model
        cfg["farm"]["layout_x"], cfg["farm"]["layout_y"] = [0.0, 630.0], [0.0, 0.0]
        fmodel = FlorisModel(cfg)
        fmodel.set(yaw_angles=[[yaw, 0.0]])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            fmodel.run()
        limited = [w for w in caught if "max_thrust_coefficient" in str(w.message)]
        assert bool(limited) is warns
        velocities = fmodel.turbine_average_velocities
        assert np.all(np.isfinite(velocities)) and velocities[0, 1] < velocities[0, 0]


@pytest.mark.parametrize("yaw", [90.0, -90.0, 120.0])
def test_yaw_of_90_degrees_or_more_is_refused(yaw):
    fmodel = FlorisModel(config("cnbl"))
    fmodel.set(yaw_angles=[[yaw]])
    with pytest.raises(ValueError, match="yaw"):
        fmodel.run()


@pytest.mark.filterwarnings("ignore:.*max_thrust_coefficient:RuntimeWarning")  # C_T(3 m/s)
@pytest.mark.filterwarnings("ignore::floris_ekman_veer.plugin.inflow.shallow.ShallowBoundaryLayerWarning")
def test_hub_above_the_boundary_layer_takes_the_floor_expansion():
    """SBL-6 stability at 3 m/s: h = 47 m, below the 90 m hub and below h exp(B1/A1) = 76 m:
    no ambient turbulence at the hub, k_w is the floor (docs/atmosphere.md#shallow-boundary-layer)."""
    cfg = config("farm_sbl6", wind_speeds=[3.0])
    cfg["farm"]["layout_x"], cfg["farm"]["layout_y"] = [0.0, 630.0], [0.0, 0.0]
    abl = atmosphere_of(cfg)
    assert abl.boundary_layer_height * np.exp(0.6 / 1.25) < HUB_5MW
    fmodel = FlorisModel(cfg)
    fmodel.run()
    powers = fmodel.get_turbine_powers()
    assert np.all(np.isfinite(powers)) and powers[0, 1] < powers[0, 0]
    k_w = fmodel.core.wake.velocity_model.expansion_rate(abl, HUB_5MW, abl.speed(HUB_5MW), 0.06,
                                                         0.06)
    assert float(k_w) == pytest.approx(0.021, rel=1e-15)



def test_local_turbulence_adds_only_the_wake_added_turbulence():
    """wake_expansion: local_turbulence (docs/coupling.md#wake-expansion-in-farms):
    I^2 = I_u(z_h)^2 + (TI^2 - TI_0^2), FLORIS's wake-added part on top of the ABL's I_u."""
    cfg = config("farm_sbl6", atmosphere={"stability_parameter": 0.0}, wind_speeds=[8.0],
                 turbulence_intensities=[0.06])
    cfg["farm"]["layout_x"], cfg["farm"]["layout_y"] = [0.0, 882.0, 1764.0], [0.0] * 3
    abl = atmosphere_of(cfg)
    speed = abl.speed(HUB_5MW)
    cfg["wake"]["wake_velocity_parameters"]["ekman_veer"]["wake_expansion"] = "local_turbulence"
    model = FlorisModel(cfg).core.wake.velocity_model
    ambient = float(abl.wake_expansion_rate(HUB_5MW))
    i_u = float(abl.turbulence_intensity(HUB_5MW, reference_height=HUB_5MW))
    for floris_ti in (0.03, 0.06, 0.11):  # unwaked: the paper's k_w, whatever FLORIS's TI
        assert float(model.expansion_rate(abl, HUB_5MW, speed, floris_ti, floris_ti)) == ambient
    added = 0.08  # waked: sqrt(TI_0^2 + 0.08^2) at the turbine
    expected = (0.021**6 + (0.33 * math.hypot(i_u, added)) ** 6) ** (1 / 6)
    for floris_ti in (0.03, 0.11):
        local = model.expansion_rate(abl, HUB_5MW, speed, math.hypot(floris_ti, added), floris_ti)
        assert float(local) == pytest.approx(expected, rel=1e-12)
    # Through FLORIS: the front turbine is unchanged, the waked ones recover faster.
    powers = {}
    for mode in ("ambient", "local_turbulence"):
        cfg["wake"]["wake_velocity_parameters"]["ekman_veer"]["wake_expansion"] = mode
        fmodel = FlorisModel(cfg)
        fmodel.run()
        powers[mode] = fmodel.get_turbine_powers()[0]
    assert powers["local_turbulence"][0] == powers["ambient"][0]
    assert np.all(powers["local_turbulence"][2:] > 1.05 * powers["ambient"][2:])


def test_array_coupling_is_the_default_and_adds_what_a_second_wake_brings():
    """The farm input's defaults (docs/coupling.md#wakes-deep-in-an-array): array_turbulence,
    incoming, the cumulative wake summed by fls (the variants here with the plain sum,
    ``wake_superposition: combination_model``: the cumulative wake carries the thrust with the
    incoming speed whatever ``deficit_velocity`` says). A row of four NREL 5 MW at 7 D, neutral, 8 m/s: turbine 2 stands
    in one wake from an unwaked rotor, so every coupling gives it the same power (fraction 1,
    and one wake's added turbulence is the same summed or maximal); turbine 3's wake source,
    turbine 2, is waked: scaled with its incoming speed, turbine 3 gets more power than with the
    free stream; turbine 4 mixes the added turbulence of two wakes, so its power rises when
    their variances are summed rather than the larger kept."""
    cfg = config("farm_sbl6", atmosphere={"stability_parameter": 0.0}, wind_speeds=[8.0],
                 turbulence_intensities=[0.06])
    cfg["farm"]["layout_x"], cfg["farm"]["layout_y"] = [0.0, 882.0, 1764.0, 2646.0], [0.0] * 4
    default = FlorisModel(cfg).core.wake.velocity_model
    assert (default.wake_expansion, default.deficit_velocity, default.wake_superposition) == (
        "array_turbulence", "incoming", "cumulative")
    assert cfg["wake"]["model_strings"]["combination_model"] == "fls"
    powers = {}
    for expansion in ("local_turbulence", "array_turbulence"):
        for scale in ("free_stream", "incoming"):
            cfg["wake"]["wake_velocity_parameters"]["ekman_veer"].update(
                wake_expansion=expansion, deficit_velocity=scale,
                wake_superposition="combination_model")
            fmodel = FlorisModel(cfg)
            fmodel.run()
            powers[expansion, scale] = fmodel.get_turbine_powers()[0]
    for variant in powers.values():
        np.testing.assert_array_equal(variant[:2], powers["array_turbulence", "incoming"][:2])
    for expansion in ("local_turbulence", "array_turbulence"):
        assert powers[expansion, "incoming"][2] > 1.02 * powers[expansion, "free_stream"][2]
    for scale in ("free_stream", "incoming"):
        assert powers["array_turbulence", scale][2] == powers["local_turbulence", scale][2]
        assert powers["array_turbulence", scale][3] > 1.01 * powers["local_turbulence", scale][3]


def test_added_turbulence_and_incoming_speed_by_hand():
    """RotorWakes: ``quadrature`` adds each wake's variance, TI^2 = TI_0^2 + sum added^2,
    ``max`` keeps FLORIS's max(TI, sqrt(added^2 + TI_0^2)); the incoming fraction is the
    cells' mean waked over ambient speed, 1 without a wake."""
    from types import SimpleNamespace

    from floris_ekman_veer.plugin.rotor.rotor_wakes import RotorWakes

    for rule, expected in (("quadrature", math.sqrt(0.05**2 + 0.1**2 + 0.08**2)),
                           ("max", math.hypot(0.1, 0.05))):
        wakes = SimpleNamespace(turbulence=np.full((1, 2), 0.05))
        for added in (0.1, 0.08):
            RotorWakes.add_turbulence(wakes, np.array([0]), np.array([1]), np.array([added]),
                                      np.array([0.05]), rule)
        assert wakes.turbulence[0, 1] == pytest.approx(expected, rel=1e-15)
        assert wakes.turbulence[0, 0] == 0.05
    wakes = SimpleNamespace(wake=np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]))
    u = np.array([[8.0, 9.0, 10.0], [8.0, 9.0, 10.0]])
    np.testing.assert_allclose(RotorWakes.incoming_fraction(wakes, np.array([0, 1]), u),
                               [1.0, 1.0 - 6.0 / 27.0], rtol=1e-15)


def test_summed_wakes_are_asked_for_with_incoming_deficits():
    """deficit_velocity: incoming with FLORIS's sosfs (its default) or max gives one
    ModelSettingsWarning naming both settings; fls, or free_stream, is silent."""
    cfg = config("farm_sbl6")
    for combination, scale, warned in (("sosfs", "incoming", True), ("max", "incoming", True),
                                       ("fls", "incoming", False), ("sosfs", "free_stream", False)):
        cfg["wake"]["model_strings"]["combination_model"] = combination
        cfg["wake"]["wake_velocity_parameters"]["ekman_veer"]["deficit_velocity"] = scale
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            FlorisModel(cfg)
        messages = [str(w.message) for w in caught
                    if issubclass(w.category, floris_ekman_veer.ModelSettingsWarning)]
        assert len(messages) == int(warned), (combination, scale)
        if warned:
            assert f"combination_model = '{combination}'" in messages[0]
            assert "deficit_velocity = 'incoming'" in messages[0]



@pytest.mark.parametrize("lateral, same", [(0.0, True), (1.4, False)])
def test_turbulence_overlap_counts_the_rotor_inside_the_wake_radius(lateral, same):
    """``turbulence_overlap``: a wake's added turbulence is weighted with the part of the rotor
    inside the wake radius 2 sigma (wake_radius, Niayifar & Porte-Agel 2016) or where its
    velocity exceeds 0.05 m/s (wake_velocity, FLORIS's count). A rotor on the wake's axis lies
    inside 2 sigma whole at 5 D: both count all of it and every power is the same. One 1.4 D
    aside lies mostly beyond 2 sigma but in the 0.05 m/s tail: it gets less added turbulence
    with wake_radius, so its own power is unchanged (turbulence acts on its wake) and its wake,
    expanding more slowly, leaves less power to the rotor behind it."""
    powers = {}
    for overlap in ("wake_radius", "wake_velocity"):
        cfg = config("farm_sbl6", veer=False, atmosphere={"stability_parameter": 0.0})
        diameter = 126.0  # the NREL 5 MW of the farm input
        cfg["farm"]["layout_x"] = [0.0, 5.0 * diameter, 10.0 * diameter]
        cfg["farm"]["layout_y"] = [0.0, lateral * diameter, lateral * diameter]
        cfg["wake"]["wake_velocity_parameters"]["ekman_veer"]["turbulence_overlap"] = overlap
        fmodel = FlorisModel(cfg)
        fmodel.set(wind_directions=[270.0], wind_speeds=[8.0], turbulence_intensities=[0.06])
        fmodel.run()
        powers[overlap] = fmodel.get_turbine_powers()[0]
    np.testing.assert_array_equal(powers["wake_radius"][:2], powers["wake_velocity"][:2])
    if same:
        np.testing.assert_array_equal(powers["wake_radius"], powers["wake_velocity"])
    else:
        assert powers["wake_radius"][2] < powers["wake_velocity"][2] * (1.0 - 1e-4)


def _neutral_row(spacings, **velocity_settings):
    """farm_sbl6's NREL 5 MW along the wind at ``spacings`` [D] in a neutral ABL without veer,
    at 8 m/s, with ``velocity_settings`` in the ekman_veer block; run."""
    cfg = config("farm_sbl6", veer=False, atmosphere={"stability_parameter": 0.0})
    cfg["farm"]["layout_x"] = [126.0 * s for s in spacings]
    cfg["farm"]["layout_y"] = [0.0] * len(spacings)
    cfg["wake"]["wake_velocity_parameters"]["ekman_veer"].update(velocity_settings)
    fmodel = FlorisModel(cfg)
    fmodel.set(wind_directions=[270.0], wind_speeds=[8.0], turbulence_intensities=[0.06])
    fmodel.run()
    return fmodel


def test_ishihara_qian_turbulence_is_its_rotor_average(monkeypatch):
    """``wake_turbulence: ishihara_qian``: the added turbulence a wake hands a rotor is Ishihara
    & Qian's (2018) Delta I averaged over the rotor (the cells' sub-points), equal to an
    independent polar quadrature of the published form computed here; 15 D on, none (FLORIS's
    cut-off). A single wake is unchanged (turbulence acts on the wake of the rotor it reaches)."""
    from floris_ekman_veer.plugin.rotor import rotor_wakes
    from floris_ekman_veer.wake.added_turbulence import ishihara_qian_added_turbulence

    diameter, hub = 126.0, 90.0  # the NREL 5 MW of the farm input
    added, powers = [], {}
    original = rotor_wakes.RotorWakes.add_turbulence

    def spy(self, f, j, values, ambient, rule="max"):
        added.append(dict(zip(j.tolist(), np.asarray(values).tolist())))
        return original(self, f, j, values, ambient, rule)

    monkeypatch.setattr(rotor_wakes.RotorWakes, "add_turbulence", spy)
    for form in ("ishihara_qian", "crespo_hernandez"):
        added.clear()
        fmodel = _neutral_row((0.0, 5.0, 15.0), wake_turbulence=form)
        powers[form] = fmodel.get_turbine_powers()[0]
        if form == "ishihara_qian":
            ct = fmodel.get_turbine_thrust_coefficients()[0, 0]
            first = added[0]
    n = 400
    r = (np.arange(n) + 0.5) / n * 0.5 * diameter
    theta = (np.arange(n) + 0.5) * 2.0 * np.pi / n
    r, theta = np.meshgrid(r, theta)
    z = hub + r * np.sin(theta)
    point = ishihara_qian_added_turbulence(5.0 * diameter, r, z, ct, 0.06, diameter, hub)
    assert first[1] == pytest.approx(np.sum(point * r) / np.sum(r), rel=2e-3)
    assert first[1] > 0.05
    assert first[2] == 0.0
    np.testing.assert_array_equal(powers["ishihara_qian"][:2], powers["crespo_hernandez"][:2])
    assert powers["ishihara_qian"][2] != powers["crespo_hernandez"][2]


@pytest.mark.parametrize("superposition", ["momentum_conserving", "cumulative"])
def test_published_superpositions_on_the_rotor_cells(superposition):
    """``wake_superposition``: one wake behind an unwaked rotor is the model's wake with both, so
    the second turbine's power is the summed wakes' (to the single-precision sub-point sum of
    momentum_conserving, 1e-7). Behind two aligned wakes, momentum_conserving (Zong &
    Porte-Agel 2020): the second wake, shed by a waked rotor (incoming speed about 0.7 U_0),
    convects slower than the combined wake, weighs less than 1 and dominates at the third
    turbine, which gets more than the plain sum gives; cumulative (Bastankhah et al. 2021): the
    second wake's thrust is carried through the first wake's centre-line overlap
    a = U_0 - lambda C_1 (6.6 m/s), faster than the second rotor's disk-averaged incoming speed
    U_n (6.2 m/s) that the plain sum scales it with, so its centre deficit
    C_2 = K U_n^2 / (a + sqrt(a^2 - K U_n^2)) is smaller and the third turbine gets more.
    FLORIS's sosfs cannot carry Zong & Porte-Agel's weights (ValueError naming fls); the
    cumulative wake (the sum of the deficits) then leaves each wake to sosfs alone."""
    powers = {}
    for setting in ("combination_model", superposition):
        fmodel = _neutral_row((0.0, 5.0, 10.0), wake_superposition=setting)
        powers[setting] = fmodel.get_turbine_powers()[0]
    summed, other = powers["combination_model"], powers[superposition]
    assert other[0] == summed[0]
    assert other[1] == pytest.approx(summed[1], rel=1e-7)
    assert other[2] > summed[2] * (1.0 + 0.02)
    cfg = config("farm_sbl6", veer=False, atmosphere={"stability_parameter": 0.0})
    cfg["farm"].update(layout_x=[0.0, 630.0, 1260.0], layout_y=[0.0, 0.0, 0.0])
    cfg["wake"]["model_strings"]["combination_model"] = "sosfs"
    cfg["wake"]["wake_velocity_parameters"]["ekman_veer"].update(
        deficit_velocity="free_stream", wake_superposition=superposition)
    fmodel = FlorisModel(cfg)
    if superposition == "momentum_conserving":
        with pytest.raises(ValueError, match="combination_model: fls"):
            fmodel.run()
        return
    fmodel.run()
    cfg["wake"]["wake_velocity_parameters"]["ekman_veer"]["wake_superposition"] = (
        "combination_model")
    plain = FlorisModel(cfg)
    plain.run()
    np.testing.assert_array_equal(fmodel.get_turbine_powers(), plain.get_turbine_powers())
