"""ParFlorisModel(interface="dask") on a LocalCluster of two worker processes.

The cluster test runs a script in a fresh interpreter that imports floris_ekman_veer only inside
``main()``: Dask's worker processes are spawned from a fresh interpreter too, so they know the
package's models only if ParFlorisModel registers them there (docs/coupling.md#parallel-workers).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("distributed")

from floris_ekman_veer import ParFlorisModel  # noqa: E402
from floris_ekman_veer.studies.energy import distributed as cluster_module  # noqa: E402

REPOSITORY = Path(__file__).resolve().parents[3]

SCRIPT = textwrap.dedent(
    """
    import json
    import sys
    import time

    import numpy as np


    def main():
        started = time.perf_counter()
        from distributed import Client, LocalCluster
        from floris import FlorisModel, UncertainFlorisModel, WindRose
        from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

        from floris_ekman_veer import ParFlorisModel, annual_energy
        from floris_ekman_veer.plugin.inflow import inflow

        farm = sys.argv[1]
        wind_speeds = np.array([7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 9.0])
        wind_directions = np.array([262.0, 266.0, 270.0, 274.0, 278.0, 270.0, 95.0])
        conditions = dict(wind_speeds=wind_speeds, wind_directions=wind_directions,
                          turbulence_intensities=np.full(7, 0.06))
        out = {}
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=":0") as cluster, Client(cluster) as client:
            serial = FlorisModel(farm)
            serial.set(yaw_angles=np.tile([10.0, -5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                                          (7, 1)), **conditions)
            serial.run()
            par = ParFlorisModel(serial, interface="dask", client=client)
            par.run()
            out["max_workers"] = par.max_workers
            out["interface"] = par.interface
            out["run"] = np.max(np.abs(par.get_turbine_powers()
                                       - serial.get_turbine_powers())).item()
            points = (np.array([300.0, 900.0, 1500.0]), np.array([0.0, 20.0, -30.0]),
                      np.array([90.0, 60.0, 120.0]))
            out["points"] = np.max(np.abs(par.sample_flow_at_points(*points)
                                          - serial.sample_flow_at_points(*points))).item()
            # The package's warnings raised on the workers (the thrust limit at light wind) are
            # reported by the parent once, as the serial run reports them.
            import warnings

            from floris_ekman_veer import ThrustLimitWarning

            rng = np.random.default_rng(1)
            from tests.conftest import own_turbine  # the user's turbine: a warning, not a notice

            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                light = FlorisModel(own_turbine(farm))
                light.set(wind_directions=rng.uniform(0, 360, 8), wind_speeds=rng.uniform(3, 8, 8),
                          turbulence_intensities=np.full(8, 0.06))
            said = {}
            for name, model in (("serial", light),
                                ("dask", ParFlorisModel(light, interface="dask", client=client))):
                with warnings.catch_warnings(record=True) as records:
                    warnings.simplefilter("always")
                    model.run()
                said[name] = [str(w.message) for w in records
                              if issubclass(w.category, ThrustLimitWarning)]
            out["warnings"] = said
            # The package's models ran on the workers (a worker without them would have raised).
            out["worker_models"] = sorted(set(client.run(_velocity_models).values()))

            by_address = ParFlorisModel(serial, interface="dask",
                                        client=cluster.scheduler_address,
                                        return_turbine_powers_only=True)
            by_address.run()
            out["powers_only"] = np.max(np.abs(by_address.get_turbine_powers()
                                               - serial.get_turbine_powers())).item()
            by_address.client.close()

            # Per-condition atmosphere lists are cut with the conditions.
            day_night = FlorisModel(farm)
            atmosphere = inflow.atmosphere_of(day_night.core).sliced(slice(None))
            atmosphere["cooling_rate"] = [0.0, -1.0] * 3 + [-0.375]
            inflow.set_atmosphere(day_night, atmosphere, **conditions)
            day_night.run()
            par_day_night = ParFlorisModel(day_night, interface="dask", client=client)
            par_day_night.run()
            out["per_condition"] = np.max(np.abs(par_day_night.get_turbine_powers()
                                                 - day_night.get_turbine_powers())).item()

            # FLORIS's optimiser and annual energy take the Dask model as any ParFlorisModel
            # (a 3-turbine row of the farm: each optimiser pass is a round trip to the cluster).
            row = FlorisModel(farm)
            row.set(layout_x=[0.0, 882.0, 1764.0], layout_y=[0.0, 0.0, 0.0],
                    wind_speeds=[8.0, 10.0], wind_directions=[266.0, 274.0],
                    turbulence_intensities=[0.06, 0.06])
            par_row = ParFlorisModel(row, interface="dask", client=client)
            kwargs = dict(minimum_yaw_angle=-20.0, maximum_yaw_angle=20.0, Ny_passes=[5, 4])
            reference = YawOptimizationSR(row, **kwargs).optimize(print_progress=False)
            on_cluster = YawOptimizationSR(par_row, **kwargs).optimize(print_progress=False)
            out["yaw_angles"] = np.max(np.abs(np.vstack(on_cluster.yaw_angles_opt)
                                              - np.vstack(reference.yaw_angles_opt))).item()
            out["yaw_power"] = np.max(np.abs(on_cluster.farm_power_opt.to_numpy()
                                             - reference.farm_power_opt.to_numpy())).item()
            out["yaw_steered"] = np.max(np.abs(np.vstack(reference.yaw_angles_opt))).item()

            rose = WindRose(np.array([266.0, 274.0]), np.array([9.0]), ti_table=0.06)
            aep = []
            for model in (row.copy(), par_row.copy()):
                model.set(wind_data=rose)
                model.run()
                aep.append(model.get_farm_AEP())
            out["floris_aep"] = abs(aep[1] - aep[0])
            uncertain = [UncertainFlorisModel(model, wd_std=3.0) for model in (row, par_row)]
            for model in uncertain:
                model.run()
            out["uncertain"] = np.max(np.abs(uncertain[1].get_turbine_powers()
                                             - uncertain[0].get_turbine_powers())).item()
            atmosphere = inflow.atmosphere_of(row.core).sliced(slice(None))
            stability = {"night": {"frequency": 1.0, "atmosphere": atmosphere}}
            tables = [annual_energy(model, rose, stability, YawOptimizationSR,
                                    models=["ekman_veer"], progress=False, **kwargs).table
                      for model in (row, par_row)]
            columns = ["aep_baseline_gwh", "aep_steered_gwh"]
            out["aep"] = np.max(np.abs(tables[1][columns].to_numpy()
                                       - tables[0][columns].to_numpy())).item()
            out["aep_gain"] = tables[0]["gain_percent"].iloc[-1].item()
            # A steered year of per-record atmospheres (one vectorised model per chunk, every
            # atmosphere of a chunk in one optimiser run) on the cluster: bitwise the serial.
            from floris import TimeSeries

            series = TimeSeries(np.array([266.0, 274.0]), np.array([8.0, 10.0]),
                                turbulence_intensities=0.06)
            classes = {"night": {"atmosphere": atmosphere},
                       "day": {"atmosphere": dict(atmosphere, cooling_rate=0.0)}}
            years = [annual_energy(model, series, classes, YawOptimizationSR,
                                   records=["night", "day"], models=["ekman_veer"],
                                   progress=False, minimum_yaw_angle=-20.0,
                                   maximum_yaw_angle=20.0, Ny_passes=[3])
                     for model in (row, par_row)]
            powers = [y.conditions["ekman_veer"][["farm_power_baseline", "farm_power_steered"]]
                      .to_numpy() for y in years]
            out["records_aep"] = np.max(np.abs(powers[1] - powers[0])).item()
            out["records_steered"] = bool(np.all(powers[0][:, 1] >= powers[0][:, 0]))
            # annual_energy(client=): whole chunks (model, run, yaw optimisation) as Dask tasks,
            # each record with its own atmosphere; gathered in order, bitwise the serial study.
            from floris_ekman_veer.studies.energy.energy import record_energy

            client_started = time.perf_counter()
            series = TimeSeries(np.array([266.0, 274.0, 95.0]), np.array([8.0, 10.0, 9.0]),
                                turbulence_intensities=0.06)
            per_record = dict(atmosphere, cooling_rate=[-1.0, 0.0, -0.375])
            labels = [f"record {k}" for k in range(3)]
            studies = [record_energy(row, series, per_record, labels, YawOptimizationSR,
                                     models=["ekman_veer"], chunk_size=2, progress=False,
                                     client=on, minimum_yaw_angle=-20.0, maximum_yaw_angle=20.0,
                                     Ny_passes=[3])
                       for on in (None, client)]
            columns = ["farm_power_baseline", "farm_power_steered"]
            out["client_study"] = np.max(np.abs(
                studies[1].conditions["ekman_veer"][columns].to_numpy(dtype=float)
                - studies[0].conditions["ekman_veer"][columns].to_numpy(dtype=float))).item()
            out["client_yaw"] = max(
                np.max(np.abs(np.vstack(studies[1].optima[key]["yaw_angles_opt"])
                              - np.vstack(studies[0].optima[key]["yaw_angles_opt"]))).item()
                for key in studies[0].optima)
            out["client_table"] = bool(studies[1].table.equals(studies[0].table))
            out["client_steered"] = np.max(np.abs(np.vstack(
                studies[0].optima["ekman_veer", "record 0"]["yaw_angles_opt"]))).item()
            # FLORIS's GCH on the same per-record inflow (its template and wind_veer travel too).
            baselines = [record_energy(row, series, per_record, labels, models=["gch"],
                                       chunk_size=2, client=on) for on in (None, client)]
            out["client_gch"] = bool(baselines[1].table.equals(baselines[0].table)) and bool(
                baselines[1].conditions["gch"].equals(baselines[0].conditions["gch"]))
            out["client_seconds"] = time.perf_counter() - client_started
        out["seconds"] = time.perf_counter() - started
        print("RESULT " + json.dumps(out))


    def _velocity_models():
        from floris.core.wake import MODEL_MAP

        return "ekman_veer" in MODEL_MAP["velocity_model"]


    if __name__ == "__main__":
        main()
    """
)


# The stable atmospheres of these farms give, in some conditions and by design, boundary layers
# shallower than the NREL 5 MW rotor top (153 m); their ShallowBoundaryLayerWarning is not what
# is tested here (tests/physics/test_shallow_abl.py and tests/test_user_inputs_and_warnings.py are).
pytestmark = pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")


# The cluster run is a long study (a fresh interpreter, a LocalCluster of two worker processes, a
# FLORIS optimiser and steered annual-energy studies on it, each against its serial run): its
# tests carry the marker study and run in .ci/run after the fast suite (README, "Set up"); the
# bad-input tests below stay in the fast suite.
@pytest.fixture(scope="module")
def cluster_results(tmp_path_factory):
    # 325 s measured at a load average of 10-12 on the 2-core machine: the timeout catches a hang,
    # not a load.
    script = tmp_path_factory.mktemp("dask") / "run_on_cluster.py"
    script.write_text(SCRIPT)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(REPOSITORY)] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    done = subprocess.run(
        [sys.executable, str(script), str(REPOSITORY / "inputs" / "farm_sbl6.yaml")],
        capture_output=True, text=True, env=env, timeout=600, cwd=script.parent,
    )
    lines = [line for line in done.stdout.splitlines() if line.startswith("RESULT ")]
    assert done.returncode == 0 and lines, done.stderr[-3000:]
    return json.loads(lines[-1][len("RESULT "):])


@pytest.mark.study
def test_dask_model_is_the_serial_model(cluster_results):
    assert cluster_results["interface"] == "dask"
    assert cluster_results["max_workers"] == 2  # two single-threaded workers
    assert cluster_results["worker_models"] == [True]
    # Each condition is computed on its own, so the chunks give the serial numbers exactly.
    for key in ("run", "points", "powers_only", "per_condition"):
        assert cluster_results[key] == 0.0, key


@pytest.mark.study
def test_dask_worker_warnings_are_said_once_by_the_parent(cluster_results):
    """The thrust-limit warnings of light-wind conditions run on the cluster's workers reach the
    parent as one summary, the serial run's, counting all 8 conditions
    (docs/coupling.md#parallel-workers)."""
    said = cluster_results["warnings"]
    assert len(said["serial"]) == 1 and "of 8 conditions" in said["serial"][0]
    assert said["dask"] == said["serial"]


@pytest.mark.study
def test_dask_model_in_floris_optimiser(cluster_results):
    assert cluster_results["yaw_steered"] > 0.0  # the case does steer
    assert cluster_results["yaw_angles"] == 0.0
    assert cluster_results["yaw_power"] == 0.0


@pytest.mark.study
def test_dask_model_in_annual_energy(cluster_results):
    assert cluster_results["aep_gain"] > 0.0
    assert cluster_results["aep"] == 0.0
    # Per-record atmospheres, steered, on the cluster: bitwise the serial study.
    assert cluster_results["records_aep"] == 0.0
    assert cluster_results["records_steered"]
    assert cluster_results["floris_aep"] == 0.0  # FLORIS's get_farm_AEP on a wind rose


@pytest.mark.study
def test_annual_energy_chunks_as_dask_tasks(cluster_results):
    """annual_energy(client=) sends the chunks with client.map: bitwise the serial study."""
    assert cluster_results["client_steered"] > 0.0  # the record steers
    assert cluster_results["client_study"] == 0.0
    assert cluster_results["client_yaw"] == 0.0
    assert cluster_results["client_table"]
    assert cluster_results["client_gch"]


@pytest.mark.study
def test_dask_model_in_uncertain_floris_model(cluster_results):
    assert cluster_results["uncertain"] == 0.0


# ------------------------------------------------------------------------- bad input


def test_client_requires_dask_interface():
    with pytest.raises(ValueError, match='only used with interface="dask"'):
        ParFlorisModel(REPOSITORY / "inputs" / "farm_sbl6.yaml", interface="multiprocessing",
                       client="tcp://127.0.0.1:8786")


def test_dask_interface_without_a_client():
    with pytest.raises(ValueError, match="needs client="):
        ParFlorisModel(REPOSITORY / "inputs" / "farm_sbl6.yaml", interface="dask")


def test_dask_interface_rejects_other_client_objects():
    with pytest.raises(ValueError, match="got int"):
        ParFlorisModel(REPOSITORY / "inputs" / "farm_sbl6.yaml", interface="dask", client=8786)


def test_unknown_interface_lists_every_interface_with_dask():
    with pytest.raises(ValueError, match=r"interface='dask2' is not one of 'multiprocessing', "
                                         r"'pathos', 'concurrent', 'dask' .* or None"):
        ParFlorisModel(REPOSITORY / "inputs" / "farm_sbl6.yaml", interface="dask2")


@pytest.mark.parametrize("address", ["x", "tcp://scheduler"])
def test_dask_client_string_that_is_no_address_names_the_form(address):
    with pytest.raises(ValueError, match=rf"client='{address}' is not a Dask scheduler address: "
                                         r"give one such as 'tcp://scheduler:8786'"):
        ParFlorisModel(REPOSITORY / "inputs" / "farm_sbl6.yaml", interface="dask", client=address)


@pytest.mark.parametrize("address", ["x", "tcp://scheduler", "tls://scheduler"])
def test_a_client_string_without_a_port_builds_no_client(address, monkeypatch):
    """The address's form is checked before a Client exists: a Client whose constructor failed
    was left to the garbage collector, whose close() of it deadlocked the next Client's start
    in the same thread (a CI run hung in the test above)."""
    distributed = pytest.importorskip("distributed")

    class NoClient:
        def __init__(self, *args, **kwargs):
            raise RuntimeError(f"a Client was built for {address!r}")

    monkeypatch.setattr(distributed, "Client", NoClient)
    with pytest.raises(ValueError, match="is not a Dask scheduler address"):
        ParFlorisModel(REPOSITORY / "inputs" / "farm_sbl6.yaml", interface="dask", client=address)


class _FakeClient:
    """What _check_workers reads of a Client: run() on every worker, the scheduler address."""

    class scheduler:
        address = "tcp://fake:8786"

    def __init__(self, versions):
        self.versions = versions

    def run(self, function):
        return {"tcp://worker:1": self.versions}


def test_worker_with_other_versions_is_rejected():
    local = cluster_module._versions()
    cluster_module._check_workers(_FakeClient(local))
    with pytest.raises(ValueError, match=r"tcp://worker:1 has floris_ekman_veer 0\.0\.0"):
        cluster_module._check_workers(_FakeClient(("0.0.0", local[1])))


def test_other_interfaces_are_floris_parflorismodel():
    par = ParFlorisModel(REPOSITORY / "inputs" / "farm_sbl6.yaml", interface=None)
    par.run()
    assert par.client is None and par.interface is None
    assert np.all(np.isfinite(par.get_turbine_powers()))


class _BatchedGreetingDistributed:
    """A stand-in for the distributed module whose Client fails its handshake ``failures`` times."""

    def __init__(self, failures):
        self.failures = failures
        self.attempts = 0

    def Client(self, address, set_as_default):  # noqa: N802 - distributed's name
        self.attempts += 1
        if self.attempts <= self.failures:
            raise AssertionError  # what distributed's handshake raises on a batched greeting
        return ("client of", address, set_as_default)


def test_scheduler_address_handshake_is_retried_then_reported():
    recovering = _BatchedGreetingDistributed(failures=cluster_module.HANDSHAKE_ATTEMPTS - 1)
    assert cluster_module._connect(recovering, "tcp://s:8786") == ("client of", "tcp://s:8786", False)
    assert recovering.attempts == cluster_module.HANDSHAKE_ATTEMPTS
    broken = _BatchedGreetingDistributed(failures=cluster_module.HANDSHAKE_ATTEMPTS)
    with pytest.raises(AssertionError):
        cluster_module._connect(broken, "tcp://s:8786")
    assert broken.attempts == cluster_module.HANDSHAKE_ATTEMPTS
