"""The package's solver (plugin/floris_hooks/solver.py) against FLORIS's own sequential solver running the
same wake models: random layouts, hub heights, yaw, wind and atmospheres, every shipped farm
input, each combination rule and both wake expansions. The comparison runs FLORIS's solver
itself, so it stays valid whatever the models' physics becomes."""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel
from floris.core import core as floris_core
from floris.core import solver as floris_solver
from floris.utilities import load_yaml
from hypothesis import given
from hypothesis import strategies as st

import floris_ekman_veer  # noqa: F401
from floris_ekman_veer.plugin.floris_hooks import solver

INPUTS = Path(__file__).resolve().parents[3] / "inputs"
FARMS = ("farm_sbl6", "farm_night", "farm_day")
#: (velocity model, veer): M-1, M-2, M-3.
MODELS = (("ekman_veer", True), ("ekman_veer", False), ("bastankhah2014", False))


def farm_config(farm, model, veer, combination, expansion, seed, n_turbines=8):
    """A shipped farm input with a random layout (some hub heights raised) and the model."""
    rng = np.random.default_rng(seed)
    config = copy.deepcopy(load_yaml(INPUTS / f"{farm}.yaml"))
    wake = config["wake"]
    wake["model_strings"]["velocity_model"] = model
    wake["model_strings"]["combination_model"] = combination
    wake["wake_deflection_parameters"]["ekman_veer"]["veer"] = veer
    block = wake["wake_velocity_parameters"].setdefault(model, {})
    block["wake_expansion"] = expansion  # (the atmosphere stays in the ekman_veer block)
    # Rows along x with random spacing and stagger: many rotors in partial wakes.
    side = int(np.ceil(np.sqrt(n_turbines)))
    column, row = np.divmod(np.arange(n_turbines), side)
    config["farm"]["layout_x"] = (column * 126.0 * rng.uniform(3.0, 8.0, n_turbines)).tolist()
    config["farm"]["layout_y"] = (row * 126.0 * rng.uniform(1.0, 4.0)
                                  + rng.uniform(-60.0, 60.0, n_turbines)).tolist()
    return config


def solve(config, speeds, directions, yaw, floris_own):
    """Turbine powers, velocities and turbulence of one run, by FLORIS's sequential solver
    (``floris_own``) or the package's."""
    original = floris_core.sequential_solver
    if floris_own:
        floris_core.sequential_solver = solver.floris_sequential_solver()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fmodel = FlorisModel(copy.deepcopy(config))
            fmodel.set(wind_speeds=speeds, wind_directions=directions,
                       turbulence_intensities=np.full(len(speeds), 0.06), yaw_angles=yaw)
            fmodel.run()
    finally:
        floris_core.sequential_solver = original
    flow = fmodel.core.flow_field
    return (fmodel.get_turbine_powers(), flow.u_sorted, flow.turbulence_intensity_field_sorted,
            flow.turbulence_intensity_field_sorted_avg)


@given(
    farm=st.sampled_from(FARMS),
    model=st.sampled_from(MODELS),
    combination=st.sampled_from(("sosfs", "fls", "max")),
    expansion=st.sampled_from(("ambient", "local_turbulence")),
    seed=st.integers(0, 2**16),
)
def test_solver_equals_floris_sequential_solver(farm, model, combination, expansion, seed):
    config = farm_config(farm, *model, combination, expansion, seed)
    rng = np.random.default_rng(seed + 1)
    n = 6
    speeds = rng.uniform(4.0, 15.0, n)
    directions = rng.uniform(0.0, 360.0, n)
    yaw = rng.uniform(-25.0, 25.0, (n, len(config["farm"]["layout_x"])))
    new = solve(config, speeds, directions, yaw, floris_own=False)
    old = solve(config, speeds, directions, yaw, floris_own=True)
    # Waked and unwaked rotors both present: the comparison covers the reach.
    assert np.any(old[0] < 0.95 * np.max(old[0], axis=1, keepdims=True))
    for a, b in zip(new, old, strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=0.0)


def test_solver_equals_floris_on_the_shipped_farms_and_a_large_batch():
    """The shipped inputs as they are, 40 conditions, every rotor yawed; speeds up to 19 m/s,
    where the stable inputs' fixed stability stays inside the physical domain
    (docs/atmosphere.md#physical-domain)."""
    rng = np.random.default_rng(3)
    n = 40
    speeds, directions = rng.uniform(3.0, 19.0, n), rng.uniform(0.0, 360.0, n)
    for farm in FARMS:
        config = load_yaml(INPUTS / f"{farm}.yaml")
        yaw = rng.uniform(-30.0, 30.0, (n, len(config["farm"]["layout_x"])))
        new = solve(config, speeds, directions, yaw, floris_own=False)
        old = solve(config, speeds, directions, yaw, floris_own=True)
        for a, b in zip(new, old, strict=True):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=0.0, err_msg=farm)


def _solver_calls(config, monkeypatch):
    calls = []
    monkeypatch.setattr(solver, "rotor_solver",
                        lambda *args: calls.append(args) or pytest.fail("not expected"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fmodel = FlorisModel(config)
        try:
            fmodel.run()
        except pytest.fail.Exception:
            pass
    return len(calls)


def test_dispatch_picks_the_solver_for_the_package_models_on_turbine_grids(monkeypatch):
    sbl6 = load_yaml(INPUTS / "farm_sbl6.yaml")
    assert _solver_calls(copy.deepcopy(sbl6), monkeypatch) == 1
    # FLORIS's gauss, GCH's whole-farm terms and a cubature grid keep FLORIS's solver.
    gauss = copy.deepcopy(sbl6)
    gauss["wake"]["model_strings"].update(velocity_model="gauss", deflection_model="gauss")
    gch = copy.deepcopy(sbl6)
    gch["wake"]["enable_secondary_steering"] = True
    cubature = copy.deepcopy(sbl6)
    cubature["solver"] = {"type": "turbine_cubature_grid", "turbine_grid_points": 3}
    point_wise = copy.deepcopy(cubature)
    # (the cumulative wake's thrust needs the rotors' incoming speeds: the point-wise settings
    # sum the wakes FLORIS's way)
    point_wise["wake"]["wake_velocity_parameters"]["ekman_veer"].update(
        wake_expansion="local_turbulence", deficit_velocity="free_stream",
        wake_superposition="combination_model")
    for config in (gauss, gch, point_wise):
        assert _solver_calls(config, monkeypatch) == 0
    # With the defaults the cubature grid's wakes take the rotor states of a turbine-grid solve
    # (plugin/turbine_states.py), solved once first.
    assert _solver_calls(cubature, monkeypatch) == 1


def test_full_flow_solver_gives_the_same_values(monkeypatch):
    """FLORIS's plane and point solvers solve the turbine grid first (with this solver now):
    the same plane and points as with FLORIS's own solver, with the settings FLORIS's
    point-wise solver expresses (with the defaults the planes also take the rotor states only
    this solver tracks: tests/plugin/floris_hooks/test_one_physics_on_every_grid.py)."""
    config = load_yaml(INPUTS / "farm_night.yaml")
    config["wake"]["model_strings"]["combination_model"] = "sosfs"
    config["wake"]["wake_velocity_parameters"]["ekman_veer"].update(
        wake_expansion="local_turbulence", deficit_velocity="free_stream")

    def outputs():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fmodel = FlorisModel(copy.deepcopy(config))
            fmodel.set(wind_speeds=[9.0], wind_directions=[275.0],
                       turbulence_intensities=[0.06], yaw_angles=[[20.0, -15.0, 5.0] * 3])
            plane = fmodel.calculate_horizontal_plane(height=90.0, x_resolution=40,
                                                      y_resolution=30)
            fmodel.set(wind_speeds=[9.0], wind_directions=[275.0],
                       turbulence_intensities=[0.06], yaw_angles=[[20.0, -15.0, 5.0] * 3])
            points = fmodel.sample_flow_at_points(np.full(5, 1400.0), np.linspace(-100, 900, 5),
                                                  np.full(5, 90.0))
        return plane.df.u.to_numpy(), points

    new = outputs()
    monkeypatch.setattr(floris_solver, "sequential_solver", solver.floris_sequential_solver())
    monkeypatch.setattr(floris_core, "sequential_solver", solver.floris_sequential_solver())
    old = outputs()
    for a, b in zip(new, old, strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=0.0)


@pytest.mark.parametrize("threads, combination", [(2, "sosfs"), (3, "sosfs"), (2, "fls")])
def test_threads_give_the_same_bits(threads, combination):
    """The rotor-cell kernel on 1 or N of numba's threads (plugin/rotor/rotor_kernel.py): bitwise
    equal (each rotor's sums in the same order on any thread); with fls the input's cumulative
    wake, whose C_n at its heights feeds the kernel's rows (plugin/rotor/upstream_wakes.py)."""
    import numba

    config = farm_config("farm_sbl6", "ekman_veer", True, combination, "local_turbulence", 7,
                         16)
    rng = np.random.default_rng(8)
    n = 10
    speeds, directions = rng.uniform(5.0, 13.0, n), rng.uniform(0.0, 360.0, n)
    yaw = rng.uniform(-25.0, 25.0, (n, 16))
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = solve(config, speeds, directions, yaw, floris_own=False)
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        many = solve(config, speeds, directions, yaw, floris_own=False)
    finally:
        numba.set_num_threads(before)
    for a, b in zip(one, many, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("option", [{"wake_superposition": "momentum_conserving"},
                                    {"wake_turbulence": "ishihara_qian"}])
def test_kernel_centre_at_every_row_where_it_is_read(monkeypatch, option):
    """The momentum-conserving superposition and Ishihara & Qian's turbulence read the wake's
    centre at every sub-point row of the rotors reached: there the kernel returns the compiled
    Eq. (yc_xz) at every row (wake/fused.py centre_offset, evaluated here on its own), not 0
    at the rows its bound put out of reach; the kernel's other outputs are those without it."""
    from floris_ekman_veer.plugin.rotor import rotor as rotor_module
    from floris_ekman_veer.plugin.rotor.rotor_kernel import CONDITION_COLUMNS, PAIR_COLUMNS
    from floris_ekman_veer.wake.fused import centre_offsets

    config = farm_config("farm_sbl6", "ekman_veer", True, "fls", "local_turbulence", 3, 16)
    config["wake"]["wake_velocity_parameters"]["ekman_veer"].update(option)
    rng = np.random.default_rng(4)
    n = 6
    speeds, directions = rng.uniform(5.0, 13.0, n), rng.uniform(0.0, 360.0, n)
    yaw = rng.uniform(-25.0, 25.0, (n, 16))
    original = rotor_module.integrate_wake
    original_step = rotor_module.cumulative_step
    checked, cut = [], []

    def compare(bounded, result, pair, per_condition, flat, kind, rotor, split):
        for a, b in zip(bounded[:3], result[:3], strict=True):
            np.testing.assert_array_equal(a, b)
        reached = result[2]
        f = (flat // rotor.x.shape[1])[reached]
        k = kind[reached]
        column = lambda name: per_condition[f, CONDITION_COLUMNS.index(name)][:, None]  # noqa: E731
        # (the row slots: the strip a layer top cuts as its two parts, the slots no part
        # takes left out; plugin/rotor/strip_split.py)
        assert split == rotor.split.any
        _, fraction, heights, u, v = rotor.split.pair_rows(
            rotor.cells, rotor.kind_heights, rotor.kind_u, rotor.kind_v, f, k)
        cos_a, sin_a = column("cos"), column("sin")
        exact = centre_offsets(
            pair[reached, PAIR_COLUMNS.index("x")][:, None], heights,
            u * cos_a + v * sin_a, v * cos_a - u * sin_a, column("centre_strength"),
            column("centre_r_tube"), column("centre_image_height"), column("radius"),
            column("friction_velocity"))
        taken = fraction > 0.0
        np.testing.assert_array_equal(result[3][reached][taken], exact[taken])
        assert np.all(result[3][reached][~taken] == 0.0)
        skipped = taken & (bounded[3][reached] != exact)
        assert np.all(bounded[3][reached][skipped] == 0.0)
        checked.append(np.count_nonzero(skipped))
        cut.append(np.count_nonzero(taken[:, -1]))

    def checking(*arguments, every_row=False, **options):
        # (the wakes summed: the kernel alone)
        wake, pair, per_condition, centre, flat, kind, rotor, wakes = arguments[:8]
        assert every_row and centre is None
        combined = wakes.combined.copy()
        bounded = original(*arguments, **options)
        wakes.combined[...] = combined
        result = original(*arguments, every_row=True, **options)
        compare(bounded, result, pair, per_condition, flat, kind, rotor, options["split"])
        return result

    def checking_step(*arguments, **options):
        # (the cumulative wake: its sums and the kernel in one step, rotor_kernel.cumulative_step)
        wake, pair, per_condition, centre, flat, kind, rotor, wakes, track, every_row, split = (
            arguments[:11])
        assert every_row and centre is None
        combined = wakes.combined.copy()
        bounded = original_step(*arguments[:9], False, *arguments[10:], **options)[1]
        wakes.combined[...] = combined
        result = original_step(*arguments, **options)
        compare(bounded, result[1], pair, per_condition, flat, kind, rotor, split)
        return result

    monkeypatch.setattr(rotor_module, "integrate_wake", checking)
    monkeypatch.setattr(rotor_module, "cumulative_step", checking_step)
    solve(config, speeds, directions, yaw, floris_own=False)
    assert len(checked) > 5 and sum(checked) > 0
    assert sum(cut) > 0  # (some rotors have their strip cut by the layer top)


def test_the_solver_hands_the_wakes_source_the_rotor_at_its_centre(monkeypatch):
    """The package's solver hands the model the sorted index of the turbine it steps
    (RotorWakes.source), which the model takes for the rotor at that turbine's centre: in every
    condition of a random farm with raised hubs, the rotor nearest the turbine's centre."""
    from floris_ekman_veer.plugin.rotor import rotor as rotor_module

    original = rotor_module.reached_rotor_cell_deficit
    checked = []

    def checking(model, x_i, y_i, *arguments):
        wakes, rotor = arguments[-1], arguments[-2].rotor
        nearest = np.argmin((rotor.x - x_i[:, 0, 0]) ** 2 + (rotor.y - y_i[:, 0, 0]) ** 2, axis=1)
        np.testing.assert_array_equal(nearest, wakes.source)
        checked.append(wakes.source)
        return original(model, x_i, y_i, *arguments)

    monkeypatch.setattr(rotor_module, "reached_rotor_cell_deficit", checking)
    config = farm_config("farm_night", "ekman_veer", True, "fls", "array_turbulence", 5, 9)
    rng = np.random.default_rng(5)
    solve(config, rng.uniform(5.0, 13.0, 6), rng.uniform(0.0, 360.0, 6),
          rng.uniform(-25.0, 25.0, (6, 9)), floris_own=False)
    assert sorted(checked) == list(range(9))
