"""The Ekman inflow hook (plugin/inflow/inflow.py, plugin/floris_tools/parallel.py)."""

import copy
import multiprocessing
from pathlib import Path

import numpy as np
import pytest
import yaml
from floris import FlorisModel, ParFlorisModel, UncertainFlorisModel
from floris.core import FlowField
from floris.core.wake import MODEL_MAP
from floris.core.wake_velocity.none import NoneVelocityDeficit
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.plugin.floris_hooks import patching
from floris_ekman_veer.plugin.floris_tools import parallel
from floris_ekman_veer.plugin.inflow import inflow
from floris_ekman_veer import registry

from conftest import EXAMPLE_WAKES, STABLE_ATMOSPHERE, make_config

# The stable atmospheres of these farms give, in some conditions and by design, boundary layers
# shallower than the NREL 5 MW rotor top (153 m); their ShallowBoundaryLayerWarning is not what
# is tested here (tests/physics/test_shallow_abl.py and tests/test_user_inputs_and_warnings.py are).
pytestmark = [pytest.mark.usefixtures("inflow_hook"), pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")]

SPEEDS = (6.0, 8.0, 11.0)


def ekman_model(wake="gch", atmosphere=STABLE_ATMOSPHERE, **kwargs):
    kwargs.setdefault("wind_speeds", SPEEDS)
    kwargs.setdefault("wind_directions", (270.0,) * len(kwargs["wind_speeds"]))
    return FlorisModel(make_config(wake, atmosphere, **kwargs))


def expected_profile(fmodel, z):
    """Hub-aligned U evaluated directly at every height (no distinct-height shortcut)."""
    flow_field = fmodel.core.flow_field
    abl = EkmanABL.from_reference_wind(
        flow_field.wind_speeds[:, None, None, None], flow_field.reference_wind_height,
        **STABLE_ATMOSPHERE,
    )
    U, _ = inflow.ambient_velocity(abl, z, flow_field.reference_wind_height)
    return U


def _cells_3x3_quadrature(n_radial=96, n_angle=256):
    """An independent quadrature of the 3 x 3 turbine grid's rotor cells
    (docs/coupling.md#rotor-average): the centre disk r < R/3 (point (1, 1)) and eight
    45-degree sectors of the annulus R/3 < r < R, centred on the outer points (point (iy, iz) at
    the angle atan2(iz - 1, iy - 1)). Gauss-Legendre in r^2 on each annulus times uniform angles
    whose cells' edges fall between nodes. Returns (y, z, weight, cell index iy*3+iz)."""
    x, w = np.polynomial.legendre.leggauss(n_radial)
    ys, zs, ws, cells = [], [], [], []
    theta = (np.arange(n_angle) + 0.5) * 2 * np.pi / n_angle
    for lower, upper in ((0.0, 1 / 9), (1 / 9, 1.0)):
        s = lower + (upper - lower) * 0.5 * (x + 1)
        r, t = np.meshgrid(np.sqrt(s), theta, indexing="ij")
        weight = np.outer((upper - lower) * 0.5 * w, np.full(n_angle, 1.0 / n_angle))
        if lower == 0.0:
            iy = iz = np.ones_like(r, dtype=int)
        else:
            sector = np.floor(np.mod(t + np.pi / 8, 2 * np.pi) / (np.pi / 4)).astype(int)
            iy = np.choose(sector, [2, 2, 1, 0, 0, 0, 1, 2])  # 0, 45, ..., 315 deg
            iz = np.choose(sector, [1, 2, 2, 2, 1, 0, 0, 0])
        ys.append((r * np.cos(t)).ravel()), zs.append((r * np.sin(t)).ravel())
        ws.append(weight.ravel()), cells.append((3 * iy + iz).ravel())
    return (np.concatenate(a) for a in (ys, zs, ws, cells))


def expected_turbine_grid_inflow(fmodel):
    """u_initial of a 3 x 3 turbine grid: the cubic mean of U over each rotor cell."""
    grid = fmodel.core.grid
    hub = grid.z_sorted[:, :, 1, 1]
    radius = grid.z_sorted[:, :, 1, 2] - hub  # the points sit at +-R/2
    radius = 2.0 * radius
    _, z, weight, cell = _cells_3x3_quadrature()
    U = expected_profile(fmodel, hub[..., None, None] + radius[..., None, None] * z)[:, :, 0]
    cubes = np.stack([np.sum(weight[cell == k] * U[..., cell == k] ** 3, axis=-1)
                      / np.sum(weight[cell == k]) for k in range(9)], axis=-1)
    return np.cbrt(cubes).reshape(*hub.shape, 3, 3)


# ------------------------------------------------------------------------- installation


def test_floris_version_check():
    patching.check_floris_version("4.7")
    patching.check_floris_version("4.7.3")
    for version in ("4.6.2", "4.8", "5.0.0", "dev"):
        with pytest.raises(ImportError, match="floris>=4.7,<4.8"):
            patching.check_floris_version(version)


def test_install_is_idempotent():
    before = dict(patching.ORIGINALS)
    wrapper = FlowField.__dict__["initialize_velocity_field"]
    inflow.install_inflow_hook()
    inflow.install_inflow_hook()
    assert patching.ORIGINALS == before
    assert FlowField.__dict__["initialize_velocity_field"] is wrapper


# ------------------------------------------------------------------------- the inflow itself


@pytest.mark.parametrize("solver", ["turbine_grid", "turbine_cubature_grid"])
def test_u_initial_equals_profile_at_rotor_points(solver):
    fmodel = ekman_model()
    settings = dict(fmodel.core.solver, type=solver)
    fmodel.set(solver_settings=settings)
    fmodel.run()
    flow_field, grid = fmodel.core.flow_field, fmodel.core.grid
    points = expected_profile(fmodel, grid.z_sorted)
    if solver == "turbine_cubature_grid":
        np.testing.assert_allclose(flow_field.u_initial_sorted, points, rtol=0, atol=1e-12)
    else:
        # Each turbine-grid point carries its rotor cell's cubic mean
        # (docs/coupling.md#rotor-average); the quadratures differ (strips there, rings here).
        np.testing.assert_allclose(flow_field.u_initial_sorted,
                                   expected_turbine_grid_inflow(fmodel), rtol=2e-4)
        # ...which is not the point value where the profile curves (strongly, in this SBL)
        assert np.max(np.abs(flow_field.u_initial_sorted / points - 1)) > 0.01
    assert not np.allclose(points, flow_field.wind_speeds[:, None, None, None])


def test_speed_at_reference_height_is_floris_wind_speed():
    fmodel = ekman_model()  # hub height = reference height
    u = fmodel.sample_flow_at_points(np.array([-2000.0]), np.array([0.0]), np.array([90.0]))
    np.testing.assert_allclose(u[:, 0], SPEEDS, rtol=1e-12)


def test_dudz_initial_is_gradient_of_profile():
    fmodel = ekman_model()
    fmodel.run()
    z = fmodel.core.grid.z_sorted
    step = 1e-3
    slope = (expected_profile(fmodel, z + step) - expected_profile(fmodel, z - step)) / (2 * step)
    np.testing.assert_allclose(fmodel.core.flow_field.dudz_initial_sorted, slope, rtol=1e-5)


def test_v_and_w_initial_stay_zero():
    fmodel = ekman_model()
    fmodel.run()
    assert not fmodel.core.flow_field.v_initial_sorted.any()
    assert not fmodel.core.flow_field.w_initial_sorted.any()


@pytest.mark.filterwarnings("ignore:invalid value encountered in divide:RuntimeWarning")  # FLORIS's
# gauss divides by u_initial, which is 0 at and below the ground (as FLORIS's power law is at z = 0)
def test_points_use_profile_with_roughness_sublayer():
    """Below the ground U = 0; in the roughness sublayer (z < z_s ~ e z0) U is linear in z,
    positive, docs/atmosphere.md#roughness-sublayer; above it the profile."""
    fmodel = ekman_model()
    z = np.array([-1.0, 0.0, 0.05, 0.1, 1.0, 40.0, 90.0, 300.0])
    x = np.full_like(z, -2000.0)  # far upstream: free stream only
    u = fmodel.sample_flow_at_points(x, np.zeros_like(z), z)
    np.testing.assert_allclose(u, expected_profile(fmodel, z)[:, 0, 0, :], rtol=0, atol=1e-12)
    assert not u[:, :2].any() and np.all(u[:, 2:] > 0)
    abl = inflow.solved_atmosphere(fmodel.core.flow_field)
    z_s = abl.roughness_sublayer_height[:, 0, 0, 0]
    assert np.all((z_s > 0.1) & (z_s < 0.3))  # about e z0, z0 = 0.1 m
    u_s = inflow.ambient_velocity(abl, z_s[:, None, None, None], 90.0)[0][:, 0, 0, 0]
    np.testing.assert_allclose(u[:, 2:4], u_s[:, None] * z[2:4] / z_s[:, None], rtol=1e-12)


# FLORIS's horizontal-plane grid carries helper points on or below the ground, which the plane
# discards; its gauss divides by the inflow there (plain FLORIS: a NaN power law; here 0).
@pytest.mark.filterwarnings("ignore:invalid value encountered in divide:RuntimeWarning")
@pytest.mark.parametrize("wake", list(EXAMPLE_WAKES))
def test_no_nan_near_the_ground_in_any_floris_model(wake):
    """The inflow brings no NaN into any FLORIS model: cross, y and horizontal planes down to 1 mm
    and points just above the ground and inside the roughness, behind a yawed turbine (FLORIS has
    no planes or points for the legacy turbopark: its run only). Upstream of the farm u is the inflow, > 0 down to 1 mm; in the wake
    FLORIS's cc, whose deficit scales with the hub speed, may go below 0 near the ground, where
    the log-law inflow is far weaker than a power law's."""
    atmosphere = dict(STABLE_ATMOSPHERE, roughness_length=0.5, cooling_rate=-0.5)
    fmodel = ekman_model(wake, atmosphere=atmosphere, layout_x=(0.0, 630.0),
                         layout_y=(0.0, 40.0), wind_speeds=(8.0,))
    fmodel.set(yaw_angles=[[20.0, 0.0]])
    if wake != "turbopark":
        planes = [
            fmodel.calculate_cross_plane(downstream_dist=300.0, y_resolution=9, z_resolution=9,
                                         y_bounds=(-150.0, 150.0), z_bounds=(0.001, 200.0)),
            fmodel.calculate_y_plane(x_resolution=9, z_resolution=9, crossstream_dist=0.0,
                                     x_bounds=(-200.0, 1200.0), z_bounds=(0.001, 200.0)),
            fmodel.calculate_horizontal_plane(height=0.3, x_resolution=9, y_resolution=5,
                                              x_bounds=(-200.0, 1200.0), y_bounds=(-100.0, 100.0)),
        ]
        for plane in planes:
            assert np.all(np.isfinite(plane.df.u.to_numpy()))
        upstream = planes[1].df[planes[1].df.x1 < -100.0]
        assert len(upstream) and np.all(upstream.u > 0)
    z = np.array([0.001, 0.01, 0.3, 0.6, 2.0, 90.0])
    for x in (-300.0, 300.0) if wake != "turbopark" else ():
        u = fmodel.sample_flow_at_points(np.full_like(z, x), np.zeros_like(z), z)
        assert np.all(np.isfinite(u)) and (x > 0 or np.all(u > 0))
    fmodel.run()
    assert np.all(np.isfinite(fmodel.get_turbine_powers()))


def test_vertical_plane_uses_profile():
    fmodel = ekman_model(wind_speeds=(8.0,))
    plane = fmodel.calculate_y_plane(x_resolution=5, z_resolution=30, crossstream_dist=0.0,
                                     x_bounds=(-1000.0, -500.0), z_bounds=(0.01, 400.0))
    df = plane.df
    np.testing.assert_allclose(df.u, expected_profile(fmodel, df.x2.to_numpy())[0, 0, 0],
                               atol=1e-12)


# The map given with the atmosphere warns how they combine: tested in
# tests/test_user_inputs_and_warnings.py::test_heterogeneous_map_with_the_atmosphere_warns_how_they_combine.
@pytest.mark.filterwarnings("ignore::floris_ekman_veer.HeterogeneousInflowWarning")
def test_heterogeneous_speed_ups_multiply_the_profile():
    fmodel = ekman_model(wind_speeds=(8.0,))
    fmodel.set(heterogeneous_inflow_config={
        "x": [-1000.0, -1000.0, 3000.0, 3000.0], "y": [-1000.0, 1000.0, -1000.0, 1000.0],
        "speed_multipliers": [[1.1, 1.1, 1.1, 1.1]],
    })
    fmodel.run()
    grid = fmodel.core.grid
    np.testing.assert_allclose(fmodel.core.flow_field.u_initial_sorted,
                               1.1 * expected_turbine_grid_inflow(fmodel), rtol=2e-4)
    del grid


# ------------------------------------------------------------------------- round trips


def test_round_trips_keep_the_inflow(tmp_path):
    fmodel = ekman_model()
    fmodel.set(yaw_angles=np.full((3, 3), 10.0))
    fmodel.run()
    reference = fmodel.get_turbine_powers()

    copied = fmodel.copy()
    copied.set(yaw_angles=np.full((3, 3), 10.0))
    from_dict = FlorisModel(fmodel.core.as_dict())
    from_dict.set(yaw_angles=np.full((3, 3), 10.0))
    path = tmp_path / "ekman.yaml"
    as_dict = fmodel.core.as_dict()
    as_dict["farm"]["turbine_library_path"] = str(as_dict["farm"]["turbine_library_path"])
    path.write_text(yaml.safe_dump(as_dict))  # (Core.to_file writes a Path object safe_load rejects)
    from_yaml = FlorisModel(path)
    from_yaml.set(yaw_angles=np.full((3, 3), 10.0))
    for other in (copied, from_dict, from_yaml):
        other.run()
        np.testing.assert_array_equal(other.get_turbine_powers(), reference)

    fmodel.set(wind_speeds=[9.0, 7.0], wind_directions=[270.0, 275.0],
               turbulence_intensities=[0.06, 0.06], yaw_angles=np.zeros((2, 3)))
    fmodel.run()
    assert fmodel.core.wake.wake_velocity_parameters["ekman_veer"]["atmosphere"] \
        == STABLE_ATMOSPHERE
    np.testing.assert_allclose(fmodel.core.flow_field.u_initial_sorted,
                               expected_turbine_grid_inflow(fmodel), rtol=2e-4)


# ------------------------------------------------------------------------- FLORIS's models


@pytest.mark.parametrize("wake", ["gauss", "gch", "cc", "jensen", "turbopark", "empirical_gauss"])
def test_builtin_models_run_on_ekman_inflow(wake):
    ekman = ekman_model(wake)
    power_law = ekman_model(wake, atmosphere=None)
    for fmodel in (ekman, power_law):
        fmodel.run()
    p_ekman, p_law = ekman.get_turbine_powers(), power_law.get_turbine_powers()
    assert np.all(np.isfinite(p_ekman)) and np.all(p_ekman[:, 0] > 0)
    assert np.all(p_ekman[:, 1:] < p_ekman[:, :1])  # the wakes are there
    assert np.max(np.abs(p_ekman - p_law) / p_law[:, :1]) > 0.01


def _unconfigured_outputs(config):
    fmodel = FlorisModel(config)
    fmodel.set(yaw_angles=np.array([[15.0, -10.0, 0.0]] * 3))
    fmodel.run()
    powers = fmodel.get_turbine_powers()
    u = fmodel.core.flow_field.u.copy()
    if config["wake"]["model_strings"]["velocity_model"] == "turbopark":
        return powers, u  # FLORIS offers no point sampling or planes for the legacy turbopark
    points = fmodel.sample_flow_at_points(np.array([300.0, 900.0]), np.array([0.0, 20.0]),
                                          np.array([90.0, 60.0]))
    fmodel.set(wind_speeds=[8.0], wind_directions=[270.0], turbulence_intensities=[0.06],
               yaw_angles=np.array([[15.0, -10.0, 0.0]]))
    plane = fmodel.calculate_horizontal_plane(90.0, x_resolution=20, y_resolution=10).df.u
    return powers, u, points, plane.to_numpy()


@pytest.mark.parametrize("wake", sorted(EXAMPLE_WAKES))
def test_unconfigured_floris_is_bitwise_unchanged(wake):
    config = make_config(wake, atmosphere=None, wind_speeds=SPEEDS,
                         wind_directions=(270.0, 272.0, 268.0))
    hooked = _unconfigured_outputs(config)
    block_without_atmosphere = copy.deepcopy(config)
    block_without_atmosphere["wake"]["wake_velocity_parameters"]["ekman_veer"] = {}
    hooked_empty_block = _unconfigured_outputs(block_without_atmosphere)
    inflow.uninstall_inflow_hook()
    try:
        plain = _unconfigured_outputs(config)
    finally:
        registry.register()
    for a, b, c in zip(hooked, hooked_empty_block, plain, strict=True):
        np.testing.assert_array_equal(a, c)
        np.testing.assert_array_equal(b, c)


# ------------------------------------------------------------------------- wake-model access


def test_abl_is_solved_once(monkeypatch):
    calls = []
    original = EkmanABL.from_reference_wind.__func__

    def counting(cls, *args, **kwargs):
        calls.append(1)
        return original(cls, *args, **kwargs)

    monkeypatch.setattr(EkmanABL, "from_reference_wind", classmethod(counting))
    atmosphere = dict(STABLE_ATMOSPHERE, roughness_length=0.1234)  # not cached by other tests
    fmodel = ekman_model(atmosphere=atmosphere)
    assert len(calls) == 1  # validation at build
    fmodel.run()
    fmodel.run()
    abl = inflow.solved_atmosphere(fmodel.core.flow_field)
    fmodel.sample_flow_at_points(np.array([500.0]), np.array([0.0]), np.array([90.0]))
    assert len(calls) == 1
    assert abl.friction_velocity.shape == (3, 1, 1, 1)


def test_solved_atmosphere_reaches_prepare_function(monkeypatch):
    seen = []

    class Probe(NoneVelocityDeficit):
        def prepare_function(self, grid, flow_field):
            abl = inflow.solved_atmosphere(flow_field)
            seen.append((type(grid).__name__, flow_field.n_findex, abl))
            return super().prepare_function(grid, flow_field)

    monkeypatch.setitem(MODEL_MAP["velocity_model"], "probe", Probe)
    config = make_config("gauss", wind_speeds=SPEEDS, wind_directions=(270.0,) * 3)
    config["wake"]["model_strings"]["velocity_model"] = "probe"
    config["wake"]["wake_velocity_parameters"]["probe"] = {}
    fmodel = FlorisModel(config)
    fmodel.run()
    fmodel.sample_flow_at_points(np.array([500.0]), np.array([0.0]), np.array([90.0]))
    grids = {name for name, _, _ in seen}
    assert grids == {"TurbineGrid", "PointsGrid"}  # the full-flow solver's deep copy included
    for _, n_findex, abl in seen:
        assert abl.friction_velocity.shape == (n_findex, 1, 1, 1)
    assert len({id(abl) for _, _, abl in seen}) == 1  # one solve shared by all


def test_solved_atmosphere_without_atmosphere_raises():
    fmodel = ekman_model(atmosphere=None)
    fmodel.run()
    with pytest.raises(ValueError, match="wake.wake_velocity_parameters.ekman_veer.atmosphere"):
        inflow.solved_atmosphere(fmodel.core.flow_field)


# ------------------------------------------------------------------------- per-condition atmospheres


DAY_NIGHT = dict(STABLE_ATMOSPHERE, cooling_rate=[0.0, -0.25, -0.5])


def test_per_condition_atmosphere_equals_single_runs():
    together = ekman_model(atmosphere=DAY_NIGHT, wind_speeds=(8.0, 8.0, 10.0),
                           wind_directions=(270.0, 272.0, 268.0))
    together.run()
    for i, (ws, wd) in enumerate(zip((8.0, 8.0, 10.0), (270.0, 272.0, 268.0))):
        alone = ekman_model(atmosphere=dict(STABLE_ATMOSPHERE, cooling_rate=DAY_NIGHT["cooling_rate"][i]),
                            wind_speeds=(ws,), wind_directions=(wd,))
        alone.run()
        np.testing.assert_allclose(together.get_turbine_powers()[i], alone.get_turbine_powers()[0],
                                   rtol=1e-12)
        np.testing.assert_allclose(together.core.flow_field.u_initial_sorted[i],
                                   alone.core.flow_field.u_initial_sorted[0], rtol=1e-12)


def test_per_condition_length_mismatch_raises():
    with pytest.raises(ValueError, match="cooling_rate.*n_findex = 2"):
        ekman_model(atmosphere=DAY_NIGHT, wind_speeds=(8.0, 9.0))
    fmodel = ekman_model(atmosphere=DAY_NIGHT)
    with pytest.raises(ValueError, match="n_findex = 1"):
        fmodel.set(wind_speeds=[8.0], wind_directions=[270.0], turbulence_intensities=[0.06])
    with pytest.raises(ValueError, match="same length|length n_findex"):
        ekman_model(atmosphere=dict(DAY_NIGHT, roughness_length=[0.1, 0.2]))


def test_set_atmosphere_replaces_lists_and_conditions_together():
    fmodel = ekman_model(atmosphere=DAY_NIGHT)
    inflow.set_atmosphere(fmodel, dict(STABLE_ATMOSPHERE, cooling_rate=[-0.1, -0.2]),
                          wind_speeds=[8.0, 9.0], wind_directions=[270.0, 270.0],
                          turbulence_intensities=[0.06, 0.06])
    fmodel.run()
    assert fmodel.n_findex == 2
    with pytest.raises(ValueError):  # inconsistent: the model is left as it was
        inflow.set_atmosphere(fmodel, DAY_NIGHT)
    assert fmodel.core.wake.wake_velocity_parameters["ekman_veer"]["atmosphere"]["cooling_rate"] \
        == [-0.1, -0.2]
    inflow.set_atmosphere(fmodel, None)
    assert "ekman_veer" not in fmodel.core.wake.wake_velocity_parameters


def test_per_condition_atmosphere_in_flow_planes():
    fmodel = ekman_model(atmosphere=DAY_NIGHT, wind_speeds=(8.0, 8.0, 8.0))
    fmodel.calculate_horizontal_plane(90.0, x_resolution=10, y_resolution=5, findex_for_viz=1)
    plane = fmodel.calculate_y_plane(x_resolution=3, z_resolution=20, crossstream_dist=0.0,
                                     x_bounds=(-1000.0, -500.0), z_bounds=(1.0, 300.0),
                                     findex_for_viz=2)
    abl = EkmanABL.from_reference_wind(8.0, 90.0, **dict(STABLE_ATMOSPHERE, cooling_rate=-0.5))
    U, _ = abl.hub_aligned_velocity(plane.df.x2.to_numpy(), 90.0)
    np.testing.assert_allclose(plane.df.u, U, rtol=1e-12)
    assert len(fmodel.core.wake.wake_velocity_parameters["ekman_veer"]["atmosphere"]
               ["cooling_rate"]) == 3  # the user's model is untouched


# ------------------------------------------------------------------------- FLORIS's tools


def test_uncertain_floris_model_runs_on_ekman_inflow():
    powers = {}
    for name, atmosphere in (("ekman", STABLE_ATMOSPHERE), ("power_law", None)):
        ufmodel = UncertainFlorisModel(make_config("gch", atmosphere, wind_speeds=SPEEDS,
                                                   wind_directions=(270.0,) * 3), wd_std=3.0)
        ufmodel.run()
        powers[name] = ufmodel.get_turbine_powers()
    assert np.all(np.isfinite(powers["ekman"]))
    assert np.max(np.abs(powers["ekman"] / powers["power_law"] - 1)) > 0.01


def test_yaw_optimizer_sr_runs_on_ekman_inflow():
    fmodel = ekman_model(wind_speeds=(8.0, 8.0), wind_directions=(270.0, 275.0))
    optimizer = YawOptimizationSR(fmodel, minimum_yaw_angle=-25.0, maximum_yaw_angle=25.0,
                                  Ny_passes=[5, 4])
    result = optimizer.optimize(print_progress=False)
    assert np.all(result.farm_power_opt >= result.farm_power_baseline * (1 - 1e-12))


@pytest.mark.parametrize("start_method", ["default", "spawn"])
def test_par_floris_model_matches_serial(start_method):
    config = make_config("gch", DAY_NIGHT, wind_speeds=SPEEDS, wind_directions=(270.0, 272.0, 268.0))
    serial = FlorisModel(config)
    serial.set(yaw_angles=np.full((3, 3), 5.0))
    serial.run()
    par = ParFlorisModel(config, interface="multiprocessing", max_workers=2)
    if start_method == "spawn":
        # ParFlorisModel has no start-method option; its pool class is an attribute.
        par._PoolExecutor = multiprocessing.get_context("spawn").Pool
    par.set(yaw_angles=np.full((3, 3), 5.0))
    par.run()
    # Workers solve their share of conditions: same numbers up to the solver's round-off.
    np.testing.assert_allclose(par.get_turbine_powers(), serial.get_turbine_powers(), rtol=1e-12)
    points = (np.array([300.0, 900.0]), np.array([0.0, 10.0]), np.array([90.0, 50.0]))
    np.testing.assert_allclose(par.sample_flow_at_points(*points),
                               serial.sample_flow_at_points(*points), rtol=1e-12)


def test_par_floris_model_spawn_workers_know_the_package_models():
    """docs/coupling.md#parallel-workers: spawn workers start without the parent's registrations."""
    path = Path(__file__).parents[3] / "inputs" / "farm_sbl6.yaml"
    serial = FlorisModel(path)
    assert serial.core.wake.model_strings["velocity_model"] == "ekman_veer"
    serial.set(wind_speeds=[8.0, 9.0, 10.0], wind_directions=[270.0, 275.0, 280.0],
               turbulence_intensities=[0.06] * 3)
    serial.run()
    par = ParFlorisModel(serial, interface="multiprocessing", max_workers=2)
    par._PoolExecutor = multiprocessing.get_context("spawn").Pool
    par.run()
    np.testing.assert_allclose(par.get_turbine_powers(), serial.get_turbine_powers(), rtol=1e-12)


def test_worker_dict_prepares_the_unpickling_process(monkeypatch):
    import pickle

    called = []
    monkeypatch.setattr(parallel, "prepare_worker", lambda: called.append(1))
    data = pickle.loads(pickle.dumps(parallel.WorkerDict({"a": 1})))
    assert called == [1] and type(data) is dict and data == {"a": 1}


# ------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "change, message",
    [
        ({"roughness_lenght": 0.1}, "unknown key.*roughness_lenght"),
        ({"latitude": 45.0}, "contradictory keys.*coriolis_parameter.*latitude"),
        ({"stability_parameter": 10.0}, "contradictory keys.*stability_parameter.*cooling_rate"),
        ({"obukhov_length": 100.0}, "contradictory keys.*cooling_rate.*obukhov_length"),
        ({"lapse_rate": 0.003}, "contradictory keys.*brunt_vaisala_frequency.*lapse_rate"),
        ({"geostrophic_wind": 12.0}, "geostrophic_wind is not allowed"),
        ({"roughness_length": "rough"}, "atmosphere.roughness_length must be a real number"),
        ({"cooling_rate": [[-0.1, -0.2]]}, "atmosphere.cooling_rate must be a number or a 1-D list"),
        ({"cooling_rate": float("nan")}, r"atmosphere.cooling_rate must be -10 to 10 K/h.*got nan"),
        ({"cooling_rate": 11.0}, r"ekman_veer.atmosphere.cooling_rate must be -10 to 10 K/h.*got 11"),
        ({"roughness_length": None}, "missing required key.*roughness_length"),
    ],
)
def test_bad_atmosphere_raises_at_build(change, message):
    atmosphere = {k: v for k, v in dict(STABLE_ATMOSPHERE, **change).items() if v is not None}
    with pytest.raises(ValueError, match=message):
        ekman_model(atmosphere=atmosphere)


def test_bad_atmosphere_block_type_raises():
    config = make_config()
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"] = [1.0]
    with pytest.raises(ValueError, match="must be a mapping"):
        FlorisModel(config)


def test_reference_height_below_roughness_raises():
    with pytest.raises(ValueError, match="reference_wind_height.*roughness_length"):
        ekman_model(atmosphere=dict(STABLE_ATMOSPHERE, roughness_length=0.5),
                    reference_wind_height=0.3)


def test_negative_wind_speed_raises_at_set():
    fmodel = ekman_model()  # a calm condition (0 m/s) is at rest (tests/test_user_inputs_and_warnings.py)
    with pytest.raises(ValueError, match=r"wind_speeds must be finite and >= 0.*-1 at condition 1"):
        fmodel.set(wind_speeds=[8.0, -1.0, 9.0])


def test_conditions_can_come_later():
    config = make_config()
    for key in ("wind_speeds", "wind_directions", "turbulence_intensities"):
        config["flow_field"][key] = []
    config["wake"]["wake_velocity_parameters"]["ekman_veer"]["atmosphere"] = DAY_NIGHT
    fmodel = FlorisModel(config)
    fmodel.set(wind_speeds=SPEEDS, wind_directions=(270.0,) * 3, turbulence_intensities=[0.06] * 3)
    fmodel.run()
    assert np.all(fmodel.get_turbine_powers() > 0)


# ------------------------------------------------------------------------- the v decision


def test_ambient_v_would_change_gch(monkeypatch):
    """Why v_initial stays zero: GCH reads v as wake-induced sidewash. With the hub-aligned V(z)
    put into v_initial, the powers of waked turbines change (ambient veer is taken for the
    sidewash of a yawed rotor), whereas unwaked ones do not."""
    def powers(wind_direction):
        fmodel = ekman_model("gch", layout_x=(0.0, 882.0, 1764.0), wind_speeds=(8.0,),
                             wind_directions=(wind_direction,))
        fmodel.run()
        return fmodel.get_turbine_powers()

    reference = {wd: powers(wd) for wd in (270.0, 300.0)}
    hooked = FlowField.initialize_velocity_field

    def with_ambient_v(self, grid):
        hooked(self, grid)
        abl = inflow.solved_atmosphere(self)
        _, V = inflow.ambient_velocity(abl, grid.z_sorted, self.reference_wind_height)
        self.v_initial_sorted = np.broadcast_to(V, self.u_initial_sorted.shape).copy()
        self.v_sorted = self.v_initial_sorted.copy()

    monkeypatch.setattr(FlowField, "initialize_velocity_field", with_ambient_v)
    waked = powers(270.0) / reference[270.0] - 1
    unwaked = powers(300.0) / reference[300.0] - 1
    assert np.max(np.abs(waked)) > 0.02
    np.testing.assert_allclose(unwaked, 0.0, atol=1e-12)


def test_velocity_deficit_profiles_use_the_inflow():
    fmodel = ekman_model("gauss", wind_speeds=(8.0,))
    profiles = fmodel.sample_velocity_deficit_profiles(
        direction="vertical", downstream_dists=[-500.0], profile_range=[-60.0, 60.0],
        resolution=5, homogeneous_wind_speed=8.0)
    z = profiles[0].z.to_numpy()
    upstream = 8.0 * (1.0 - profiles[0].velocity_deficit.to_numpy())
    np.testing.assert_allclose(upstream, expected_profile(fmodel, z)[0, 0, 0], rtol=1e-12)


def test_profile_in_pieces_of_heights_is_bitwise_one_evaluation():
    """The rotor cells' rows of heights for many conditions are evaluated a few heights at a time
    with the conditions innermost (inflow.ambient_rows, inflow._PROFILE_PIECE): elementwise in
    height and condition, the pieces give the same bits as one evaluation, stable and
    convective alike, below the ground included; ambient_velocity gives them in FLORIS's
    layout."""
    from floris_ekman_veer import EkmanABL
    from floris_ekman_veer.plugin.inflow import inflow_profile as inflow

    speeds = np.random.default_rng(0).uniform(3.0, 19.0, 3000).reshape(-1, 1, 1, 1)
    z = np.concatenate([[-1.0, 0.0, 0.01], np.linspace(1.0, 400.0, 253)]).reshape(1, 1, 1, -1)
    for stability in ({"obukhov_length": 100.0}, {"sensible_heat_flux": 200.0}):
        abl = EkmanABL.from_reference_wind(speeds, 90.0, latitude=52.0, roughness_length=0.1,
                                           **stability)
        assert speeds.size * z.size > 2 * inflow._PROFILE_PIECE  # evaluated in pieces
        rows = inflow.ambient_rows(abl, z.reshape(-1), 90.0)
        pieces = inflow.ambient_velocity(abl, z, 90.0)
        whole = abl.hub_aligned_velocity(np.maximum(z, 0.0), 90.0)
        for row, piece, one, name in zip(rows, pieces, whole, "UV"):
            assert row.shape == (z.size, speeds.size) and piece.shape == one.shape
            np.testing.assert_array_equal(row.T, piece.reshape(speeds.size, -1), err_msg=name)
            np.testing.assert_array_equal(piece[..., 1:], one[..., 1:], err_msg=name)
            assert np.all(piece[..., 0] == 0.0)  # below the ground


def test_profile_pieces_of_one_height_for_more_conditions_than_a_piece(monkeypatch):
    """More conditions than a piece holds (n_findex > 2 _PROFILE_PIECE: 131,072 hourly records
    with the shipped piece) go one height per piece, the same bits; the pieces once split
    themselves again without end (RecursionError)."""
    from floris_ekman_veer import EkmanABL
    from floris_ekman_veer.plugin.inflow import inflow_profile as inflow

    monkeypatch.setattr(inflow, "_PROFILE_PIECE", 8)
    speeds = np.random.default_rng(1).uniform(3.0, 20.0, 40).reshape(-1, 1, 1, 1)
    z = np.linspace(20.0, 160.0, 5).reshape(1, 1, 1, -1)
    abl = EkmanABL.from_reference_wind(speeds, 90.0, latitude=52.0, roughness_length=0.1,
                                       obukhov_length=200.0)
    assert speeds.size > 2 * inflow._PROFILE_PIECE
    for piece, one in zip(inflow.ambient_velocity(abl, z, 90.0),
                          abl.hub_aligned_velocity(z, 90.0)):
        np.testing.assert_array_equal(piece, one)
