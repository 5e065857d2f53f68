"""The package's warnings from ParFlorisModel workers reach the user as a serial run's do: once,
at the user's line, with the counts of the whole run (floris_ekman_veer/warnings.py,
plugin/floris_tools/parallel.py). Before, each worker printed its own, located at the pool's frame and
counting its share of the conditions."""

from __future__ import annotations

import json
import os
import pickle
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel

import floris_ekman_veer as fev
from floris_ekman_veer import ParFlorisModel, registry
from floris_ekman_veer.plugin.floris_tools import parallel
from floris_ekman_veer.plugin.inflow import inflow
from floris_ekman_veer.warnings import ThrustLimitWarning


@pytest.fixture(scope="module")
def light_wind_farm():
    rng = np.random.default_rng(1)
    n = 40
    wd, ws, yaw = rng.uniform(0, 360, n), rng.uniform(3, 8, n), rng.uniform(-30, 30, (n, 9))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fmodel = FlorisModel(fev.example_input("farm_sbl6"))
        fmodel.set(wind_directions=wd, wind_speeds=ws, turbulence_intensities=np.full(n, 0.06),
                   yaw_angles=yaw)
    return fmodel


def caught(run):
    with warnings.catch_warnings(record=True) as records:
        warnings.simplefilter("always")
        run()
    return [w for w in records if issubclass(w.category, ThrustLimitWarning)]


def test_worker_warnings_are_said_once_at_the_users_line(light_wind_farm):
    serial = caught(light_wind_farm.run)
    parallel_model = ParFlorisModel(light_wind_farm, interface="multiprocessing",
                                    max_workers=2, n_wind_condition_splits=4)
    parallel = caught(parallel_model.run)
    assert len(serial) == 1 and "of 40 conditions" in str(serial[0].message)
    assert len(parallel) == 1
    assert str(parallel[0].message) == str(serial[0].message)
    assert parallel[0].filename == __file__
    np.testing.assert_array_equal(parallel_model.get_turbine_powers(),
                                  light_wind_farm.get_turbine_powers())


# Run by ``python -c``: there is no main module for a spawned worker to import, so, as in an
# interactive session, a worker knows nothing of the package until it unpickles its chunk.
SPAWN_SCRIPT = textwrap.dedent(
    """
    import json, multiprocessing, warnings
    import numpy as np
    from floris import FlorisModel
    import floris_ekman_veer as fev
    from floris_ekman_veer import ParFlorisModel, ThrustLimitWarning
    n = 8
    rng = np.random.default_rng(1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        serial = FlorisModel(fev.example_input("farm_sbl6"))
        serial.set(wind_directions=rng.uniform(0, 360, n), wind_speeds=rng.uniform(3, 8, n),
                   turbulence_intensities=np.full(n, 0.06))
    par = ParFlorisModel(serial, interface="multiprocessing", max_workers=2)
    par._PoolExecutor = multiprocessing.get_context("spawn").Pool
    out = {}
    for name, model in (("serial", serial), ("spawn", par)):
        with warnings.catch_warnings(record=True) as records:
            warnings.simplefilter("always")
            model.run()
        out[name] = [[str(w.message), w.filename, w.lineno] for w in records
                     if issubclass(w.category, ThrustLimitWarning)]
    # The serial model's powers, up to the solver's round-off.
    out["powers"] = bool(np.allclose(par.get_turbine_powers(), serial.get_turbine_powers(),
                                     rtol=1e-12, atol=0.0))
    print("RESULT " + json.dumps(out))
    """
)


def test_spawn_worker_warnings_are_said_once_by_the_parent():
    """docs/coupling.md#parallel-workers: a spawned worker unpickles the wrapped worker function
    only after importing the package, so it records its warnings instead of printing them."""
    repository = Path(__file__).resolve().parents[3]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(repository)] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    done = subprocess.run([sys.executable, "-c", SPAWN_SCRIPT], capture_output=True, text=True,
                          env=env, timeout=300)
    lines = [line for line in done.stdout.splitlines() if line.startswith("RESULT ")]
    assert done.returncode == 0 and lines, done.stderr[-3000:]
    out = json.loads(lines[-1][len("RESULT "):])
    users_line = next(number for number, line in enumerate(SPAWN_SCRIPT.splitlines(), 1)
                      if line.strip() == "model.run()")
    # The serial run's one summary counts all 8 conditions; the spawn run gives that very
    # summary once, located at the user's line of the script, and the workers print nothing.
    assert len(out["serial"]) == 1 and "of 8 conditions" in out["serial"][0][0]
    assert out["spawn"] == [[out["serial"][0][0], "<string>", users_line]]
    assert done.stderr == ""
    assert out["powers"]


def test_wrapped_worker_functions_unpickle_through_the_package(monkeypatch):
    """The wrapped worker functions pickle as a call into the package, which prepares the
    unpickling process; uninstalled, FLORIS's own functions pickle by FLORIS's name again, and
    installing twice wraps them once (docs/coupling.md#parallel-workers)."""
    import floris.par_floris_model as par

    wrapped = {name: getattr(par, name) for name in parallel.WORKER_FUNCTIONS}
    called = []
    monkeypatch.setattr(parallel, "prepare_worker", lambda: called.append(1))
    for function in wrapped.values():
        assert b"floris_ekman_veer.plugin.floris_tools.parallel" in pickle.dumps(function)
        assert pickle.loads(pickle.dumps(function)) is function
    assert len(called) == len(wrapped)
    monkeypatch.undo()
    inflow.uninstall_inflow_hook()
    try:
        for name, function in wrapped.items():
            original = getattr(par, name)
            assert original is function.__wrapped__
            assert b"floris_ekman_veer" not in pickle.dumps(original)
            assert pickle.loads(pickle.dumps(original)) is original
    finally:
        registry.register()
    registry.register()
    for name, function in wrapped.items():
        assert getattr(par, name).__wrapped__ is function.__wrapped__
