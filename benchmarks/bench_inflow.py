"""Time the Ekman inflow initialisation: 1000 conditions x 100 turbines (3 x 3 rotor grid).

Hand-run script (not a test), from the repository root with the package importable
(``pip install -e .`` or ``python -m benchmarks.bench_inflow``). Goal: < 0.1 s per
``FlowField.initialize_velocity_field`` with the hook (the ABL solve happens once, when the model
is built, and is cached; it is timed separately). For reference it also times FLORIS's power law
and FLORIS's native 3-D heterogeneous inflow carrying the same profile.
"""

import time

import numpy as np
from floris import FlorisModel

from floris_ekman_veer.studies import comparison
from floris_ekman_veer.plugin.inflow import inflow, solve_cache

N_CONDITIONS, N_TURBINES, REPEATS = 1000, 100, 5
ATMOSPHERE = {
    "coriolis_parameter": 1.0e-4,
    "roughness_length": 0.1,
    "cooling_rate": -0.25,
    "brunt_vaisala_frequency": 6.1e-3,
    "reference_potential_temperature": 265.0,
}


def build(atmosphere, hub_heights=None):
    config = FlorisModel.get_defaults()
    side = int(np.sqrt(N_TURBINES))
    x, y = np.meshgrid(np.arange(side) * 630.0, np.arange(side) * 630.0)
    config["farm"]["layout_x"] = x.ravel().tolist()
    config["farm"]["layout_y"] = y.ravel().tolist()
    config["flow_field"]["reference_wind_height"] = 90.0
    rng = np.random.default_rng(0)
    config["flow_field"]["wind_speeds"] = rng.uniform(4.0, 20.0, N_CONDITIONS).tolist()
    config["flow_field"]["wind_directions"] = rng.uniform(0.0, 360.0, N_CONDITIONS).tolist()
    config["flow_field"]["turbulence_intensities"] = [0.06] * N_CONDITIONS
    if atmosphere is not None:
        config["wake"]["wake_velocity_parameters"]["ekman_veer"] = {"atmosphere": atmosphere}
    fmodel = FlorisModel(config)
    if hub_heights is not None:
        # One turbine type per hub height is needed in FLORIS; shift the rotor grid instead.
        fmodel.core.grid.z_sorted = fmodel.core.grid.z_sorted + hub_heights
    return fmodel


def best_time(fmodel):
    core = fmodel.core
    times = []
    for _ in range(REPEATS):
        token = inflow.ACTIVE_ATMOSPHERE.set(inflow.atmosphere_of(core))
        try:
            start = time.perf_counter()
            core.flow_field.initialize_velocity_field(core.grid)
            times.append(time.perf_counter() - start)
        finally:
            inflow.ACTIVE_ATMOSPHERE.reset(token)
    return min(times)


def main():
    inflow.install_inflow_hook()
    print(f"{N_CONDITIONS} conditions x {N_TURBINES} turbines x 9 rotor points "
          f"(best of {REPEATS})")

    start = time.perf_counter()
    ekman = build(ATMOSPHERE)
    print(f"  build incl. ABL solve (once, cached): {time.perf_counter() - start:.3f} s")
    spec = inflow.atmosphere_of(ekman.core)
    solve_cache.clear()
    start = time.perf_counter()
    inflow.solve(spec, ekman.core.flow_field.wind_speeds, 90.0)
    print(f"  ABL solve alone:                      {time.perf_counter() - start:.3f} s")

    print(f"  hook, one hub height:                 {best_time(ekman):.3f} s")
    varied = build(ATMOSPHERE, hub_heights=np.random.default_rng(1).uniform(
        -10.0, 10.0, (1, N_TURBINES, 1, 1)))
    print(f"  hook, 100 distinct hub heights:       {best_time(varied):.3f} s")
    print(f"  FLORIS power law (no atmosphere):     {best_time(build(None)):.3f} s")

    native = ekman.copy()
    inflow.set_atmosphere(native, None, **comparison.native_inflow_set_kwargs(ekman))
    print(f"  FLORIS native 3-D heterogeneous:      {best_time(native):.3f} s")


if __name__ == "__main__":
    main()
