"""Annual energy per stability class (floris_ekman_veer.studies.energy.energy)."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel, TimeSeries, WindRose
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

from floris_ekman_veer.studies.energy import condition_chunks, energy, energy_results
from floris_ekman_veer.studies.comparison import builtin_inflow_settings, builtin_model
from floris_ekman_veer.studies.energy.energy import annual_energy
from floris_ekman_veer.plugin.inflow.inflow import atmosphere_of, set_atmosphere
from tests.conftest import table1_sbl6

FARM = Path(__file__).resolve().parents[3] / "inputs" / "farm_sbl6.yaml"
YAW = dict(minimum_yaw_angle=-20.0, maximum_yaw_angle=20.0, Ny_passes=[5, 4])


# The stable atmospheres of these farms give, in some conditions and by design, boundary layers
# shallower than the NREL 5 MW rotor top (153 m); their ShallowBoundaryLayerWarning is not what
# is tested here (tests/physics/test_shallow_abl.py and tests/test_user_inputs_and_warnings.py are).
pytestmark = pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")


@pytest.fixture(scope="module")
def row():
    """The SBL-6 farm input cut to a 3-turbine row at 7 D (wind from 270 deg along it), in
    Table 1's SBL-6 state mu = 148.49 fixed (the input's stability until issue 39; it now gives
    SBL-6 by its cooling rate, whose layer is below the hub at 8-9 m/s): these tests pin the
    study's machinery and the steering skip on the paper's LES state."""
    fmodel = FlorisModel(table1_sbl6(FARM))
    fmodel.set(layout_x=[0.0, 882.0, 1764.0], layout_y=[0.0, 0.0, 0.0])
    return fmodel


@pytest.fixture(scope="module")
def atmospheres(row):
    night = atmosphere_of(row.core).sliced(slice(None))
    return {"day": dict(night, stability_parameter=0.0), "night": night}


ROSE = WindRose(wind_directions=np.array([265.0, 270.0, 275.0]),
                wind_speeds=np.array([8.0, 10.0]), ti_table=0.06,
                freq_table=np.array([[0.1, 0.2], [0.25, 0.15], [0.2, 0.1]]))


def _floris_aep(fmodel, wind_data):
    model = copy.deepcopy(fmodel)
    model.set(wind_data=wind_data)
    model.run()
    return model.get_farm_AEP() / 1e9


@pytest.mark.parametrize("model", ["ekman_veer", "gch"])
def test_one_class_is_floris_get_farm_aep(row, atmospheres, model):
    result = annual_energy(row, ROSE, {"night": {"frequency": 1.0,
                                                 "atmosphere": atmospheres["night"]}},
                           models=[model], turbulence_intensities="wind_data")
    reference = row if model == "ekman_veer" else builtin_model(row, model)
    expected = _floris_aep(reference, ROSE)
    table = result.table.set_index("stability")
    assert table.loc["night", "aep_baseline_gwh"] == pytest.approx(expected, rel=1e-12)
    assert table.loc["all", "aep_baseline_gwh"] == pytest.approx(expected, rel=1e-12)
    assert np.isnan(table.loc["all", "aep_steered_gwh"])


def test_classes_weight_the_rose(row, atmospheres):
    stability = {"day": {"frequency": 0.3, "atmosphere": atmospheres["day"]},
                 "night": {"frequency": 0.7, "atmosphere": atmospheres["night"]}}
    result = annual_energy(row, ROSE, stability, models=["ekman_veer"],
                           turbulence_intensities="wind_data")
    alone = {}
    for name, atmosphere in atmospheres.items():
        model = copy.deepcopy(row)
        set_atmosphere(model, atmosphere)
        alone[name] = _floris_aep(model, ROSE)
    table = result.table.set_index("stability")["aep_baseline_gwh"]
    assert table["day"] == pytest.approx(0.3 * alone["day"], rel=1e-12)
    assert table["night"] == pytest.approx(0.7 * alone["night"], rel=1e-12)
    assert table["all"] == pytest.approx(0.3 * alone["day"] + 0.7 * alone["night"], rel=1e-12)


def test_time_series_records_equal_per_condition_atmosphere(row, atmospheres):
    directions = np.array([270.0, 268.0, 272.0, 270.0, 275.0, 270.0])
    speeds = np.array([8.0, 9.0, 10.0, 11.0, 8.0, 9.0])
    series = TimeSeries(directions, speeds, turbulence_intensities=0.06)
    records = ["night", "day", "day", "night", "night", "day"]
    result = annual_energy(row, series, {name: {"atmosphere": a} for name, a in atmospheres.items()},
                           records=records, models=["ekman_veer"],
                           turbulence_intensities="wind_data")
    # The same year as one model with a per-condition atmosphere, through FLORIS's AEP.
    per_condition = copy.deepcopy(row)
    mu = [atmospheres[name]["stability_parameter"] for name in records]
    set_atmosphere(per_condition, dict(atmospheres["night"], stability_parameter=mu),
                   wind_data=series)
    per_condition.run()
    table = result.table.set_index("stability")
    assert table.loc["all", "aep_baseline_gwh"] == pytest.approx(
        per_condition.get_farm_AEP() / 1e9, rel=1e-12)
    assert table.loc["day", "frequency"] == pytest.approx(0.5)
    assert table.loc["day", "n_conditions"] == 3


def test_steered_energy_is_the_optimisers_power(row, atmospheres):
    stability = {"day": {"frequency": 0.5, "atmosphere": atmospheres["day"]},
                 "night": {"frequency": 0.5, "atmosphere": atmospheres["night"]}}
    result = annual_energy(row, ROSE, stability, YawOptimizationSR, models=["ekman_veer", "gch"],
                           progress=False, **YAW)
    freq = ROSE.unpack_freq()
    for (model, name), df_opt in result.optima.items():
        row_ = result.table.set_index(["model", "stability"]).loc[(model, name)]
        expected = 0.5 * energy_results.HOURS_PER_YEAR * np.sum(freq * df_opt["farm_power_opt"]) / 1e9
        assert row_["aep_steered_gwh"] == pytest.approx(expected, rel=1e-12)
        assert row_["aep_steered_gwh"] >= row_["aep_baseline_gwh"] * (1 - 1e-12)
    # Every model on the same inflow: the class's I_u(z_h) per condition, for both models.
    for name, atmosphere in atmospheres.items():
        expected = builtin_inflow_settings(atmosphere, ROSE.unpack_for_reinitialize()[1], 90.0,
                                           90.0, float(row.core.farm.rotor_diameters.flat[0]))
        for model in ("ekman_veer", "gch"):
            np.testing.assert_allclose(result.inflow[model, name]["turbulence_intensities"],
                                       expected["turbulence_intensities"], rtol=1e-12)
        # The comparison: GCH without FLORIS's scalar veer (the Ekman inflow carries the veer).
        assert result.inflow["gch", name]["wind_veer"] == 0.0
    ax = result.plot()
    assert len(ax.patches) == 2 * 2 * 3  # (baseline, gain) x models x (day, night, all)


# ------------------------------------------------------------------------- bad input


@pytest.fixture
def no_work(monkeypatch):
    """Fail if any class model is built: the errors must come before any work."""
    def fail(*args, **kwargs):
        raise AssertionError("a FLORIS model was built before the input was checked")

    monkeypatch.setattr(condition_chunks, "_chunk_model", fail)


def _classes(atmospheres, **changes):
    stability = {"day": {"frequency": 0.4, "atmosphere": atmospheres["day"]},
                 "night": {"frequency": 0.6, "atmosphere": atmospheres["night"]}}
    for name, entry in changes.items():
        stability[name] = entry
    return stability


@pytest.mark.parametrize("case, match", [
    ("sum", r"must sum to 1; got 0\.9 \('day': 0\.4, 'night': 0\.5\)"),
    ("unknown_key", r"stability\['night'\]: unknown key\(s\) \['freq'\]"),
    ("negative", r"stability\['night'\]\['frequency'\] must be a number in \[0, 1\], got -0\.6"),
    ("atmosphere_key", r"stability\['night'\]\['atmosphere'\]: .*unknown key\(s\) \['mu'\]"),
    ("per_condition", r"stability\['night'\]\['atmosphere'\] must hold scalars"),
    ("no_atmosphere", r"stability\['night'\]\['atmosphere'\] must be a mapping"),
])
def test_bad_stability_distribution(row, atmospheres, no_work, case, match):
    night = atmospheres["night"]
    entry = {
        "sum": {"frequency": 0.5, "atmosphere": night},
        "unknown_key": {"frequency": 0.6, "freq": 0.6, "atmosphere": night},
        "negative": {"frequency": -0.6, "atmosphere": night},
        "atmosphere_key": {"frequency": 0.6, "atmosphere": dict(night, mu=1.0)},
        "per_condition": {"frequency": 0.6,
                          "atmosphere": dict(night, stability_parameter=[0.0] * 6)},
        "no_atmosphere": {"frequency": 0.6},
    }[case]
    with pytest.raises(ValueError, match=match):
        annual_energy(row, ROSE, _classes(atmospheres, night=entry), YawOptimizationSR)


def test_bad_records(row, atmospheres, no_work):
    series = TimeSeries(np.full(3, 270.0), np.full(3, 8.0), turbulence_intensities=0.06)
    classes = {name: {"atmosphere": a} for name, a in atmospheres.items()}
    with pytest.raises(ValueError, match=r"records\[1\] = 'dusk' is not a class"):
        annual_energy(row, series, classes, records=["day", "dusk", "night"])
    with pytest.raises(ValueError, match=r"one stability class per TimeSeries record \(3\); got 2"):
        annual_energy(row, series, classes, records=["day", "night"])
    with pytest.raises(ValueError, match="need a floris.TimeSeries"):
        annual_energy(row, ROSE, classes, records=["day"] * 6)
    with pytest.raises(ValueError, match=r"remove 'frequency'"):
        annual_energy(row, series, _classes(atmospheres), records=["day", "day", "night"])


def test_bad_models_and_options(row, atmospheres, no_work):
    stability = _classes(atmospheres)
    with pytest.raises(ValueError, match="models must be distinct names"):
        annual_energy(row, ROSE, stability, models=["ekman_veer", "jensen"])
    with pytest.raises(ValueError, match="Ny_passes"):
        annual_energy(row, ROSE, stability, YawOptimizationSR, Ny_passes=[4, 3])
    with pytest.raises(ValueError, match="without an optimizer_class"):
        annual_energy(row, ROSE, stability, minimum_yaw_angle=-20.0)
    with pytest.raises(ValueError, match="turbulence_intensities must be one of"):
        annual_energy(row, ROSE, stability, turbulence_intensities="input")
    with pytest.raises(ValueError, match=r"steering_chunk_size must be an integer >= 1; got 0"):
        annual_energy(row, ROSE, stability, YawOptimizationSR, steering_chunk_size=0)
    with pytest.raises(ValueError, match="WindRose or floris.TimeSeries"):
        annual_energy(row, {"wind_speeds": [8.0]}, stability)


# ------------------------------------------------------------ one vectorised model per chunk


def _per_class_reference(row, atmospheres, series, records, model):
    """The per-class path (one FLORIS model per class, before the vectorised study): each
    class's conditions with its scalar atmosphere, I_u(z_h) per condition and the comparison's
    wind_veer for the built-ins; AEP by FLORIS's get_farm_AEP."""
    from floris_ekman_veer.studies.comparison import comparison_set_kwargs

    directions, speeds, ti, _ = series.unpack_for_reinitialize()
    freq = series.unpack_freq()
    out = {}
    for name, atmosphere in atmospheres.items():
        index = np.flatnonzero(np.asarray(records) == name)
        case = row.copy() if model == "ekman_veer" else builtin_model(row, model)
        set_atmosphere(case, atmosphere, wind_directions=directions[index],
                       wind_speeds=speeds[index], turbulence_intensities=ti[index])
        kwargs = comparison_set_kwargs(atmosphere, speeds[index], 90.0, 90.0,
                                       float(row.core.farm.rotor_diameters.flat[0]))
        if model == "ekman_veer":
            kwargs.pop("wind_veer")
        case.set(**kwargs)
        case.run()
        out[name] = case.get_farm_AEP(freq=freq[index]) / 1e9
    return out


@pytest.mark.parametrize("model", ["ekman_veer", "gch"])
def test_vectorised_study_equals_per_class_models(row, atmospheres, model):
    directions = np.array([270.0, 268.0, 272.0, 270.0, 275.0, 270.0, 266.0])
    speeds = np.array([8.0, 9.0, 10.0, 11.0, 8.0, 9.0, 12.0])
    series = TimeSeries(directions, speeds, turbulence_intensities=0.06)
    records = ["night", "day", "day", "night", "night", "day", "night"]
    result = annual_energy(row, series, {k: {"atmosphere": a} for k, a in atmospheres.items()},
                           records=records, models=[model], chunk_size=3)
    expected = _per_class_reference(row, atmospheres, series, records, model)
    table = result.table.set_index("stability")["aep_baseline_gwh"]
    for name, aep in expected.items():
        assert table[name] == pytest.approx(aep, rel=1e-12, abs=0.0)
    assert table["all"] == pytest.approx(sum(expected.values()), rel=1e-12)


def test_chunking_is_bitwise_invariant(row, atmospheres):
    rng = np.random.default_rng(3)
    n = 7
    series = TimeSeries(rng.uniform(260.0, 280.0, n), rng.uniform(6.0, 13.0, n),
                        turbulence_intensities=0.06)
    records = list(rng.choice(["day", "night"], n))
    stability = {k: {"atmosphere": a} for k, a in atmospheres.items()}
    results = [annual_energy(row, series, stability, YawOptimizationSR, records=records,
                             models=["ekman_veer", "gch"], chunk_size=size, progress=False,
                             minimum_yaw_angle=-20.0, maximum_yaw_angle=20.0, Ny_passes=[3])
               for size in (2, n)]
    first = results[0]
    for other in results[1:]:
        for model in ("ekman_veer", "gch"):
            a, b = first.conditions[model], other.conditions[model]
            assert np.array_equal(a.index, b.index)
            assert np.array_equal(a["farm_power_baseline"], b["farm_power_baseline"])
            assert np.array_equal(a["farm_power_steered"], b["farm_power_steered"])
        assert np.array_equal(first.table["aep_baseline_gwh"], other.table["aep_baseline_gwh"])
        assert np.array_equal(first.table["aep_steered_gwh"], other.table["aep_steered_gwh"])
    # Per record, the steered power is the optimiser's and never below the baseline.
    powers = first.conditions["ekman_veer"]
    assert np.all(powers["farm_power_steered"] >= powers["farm_power_baseline"] * (1 - 1e-12))


def test_gch_comparison_is_the_yaw_studys(row, atmospheres):
    """One comparison everywhere: annual_energy's GCH is the yaw study's GCH (wind_veer 0 and
    I_u(z_h) of the atmosphere per condition)."""
    import importlib.util

    path = Path(__file__).resolve().parents[3] / "examples" / "yaw_study.py"
    spec = importlib.util.spec_from_file_location("yaw_study_comparison", path)
    study = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(study)
    speeds = np.array([8.0, 10.0])
    series = TimeSeries(np.full(2, 270.0), speeds, turbulence_intensities=0.06)
    night = atmospheres["night"]
    result = annual_energy(row, series, {"night": {"atmosphere": night}},
                           records=["night", "night"], models=["gch"])
    model = study.model_on(row, "gch", night, speeds)
    assert model.core.flow_field.wind_veer == 0.0
    model.run()
    np.testing.assert_array_equal(result.conditions["gch"]["farm_power_baseline"],
                                  np.sum(model.get_turbine_powers(), axis=1))
    np.testing.assert_array_equal(result.inflow["gch", "night"]["turbulence_intensities"],
                                  model.core.flow_field.turbulence_intensities)


def _year_of_records(row, n=7, seed=5):
    """``n`` records, each with its own atmosphere (stability from neutral to SBL-6)."""
    rng = np.random.default_rng(seed)
    series = TimeSeries(rng.uniform(262.0, 278.0, n), rng.uniform(6.0, 13.0, n),
                        turbulence_intensities=0.06)
    atmosphere = atmosphere_of(row.core).sliced(slice(None))
    atmosphere["stability_parameter"] = rng.uniform(0.0, 148.49, n).tolist()
    return series, atmosphere, [f"record {k}" for k in range(n)]


def test_per_record_results_do_not_depend_on_the_chunking(row):
    """A record's numbers are its own: chunks of 1, 3 and all records give them bitwise."""
    series, atmosphere, labels = _year_of_records(row)
    results = [energy.record_energy(row, series, atmosphere, labels, models=["ekman_veer", "gch"],
                                    chunk_size=size) for size in (1, 3, 7)]
    first = results[0]
    assert len(first.conditions["ekman_veer"]) == 7
    for other in results[1:]:
        for model in ("ekman_veer", "gch"):
            np.testing.assert_array_equal(other.conditions[model]["farm_power_baseline"],
                                          first.conditions[model]["farm_power_baseline"])
            for key in first.inflow:
                np.testing.assert_array_equal(other.inflow[key]["turbulence_intensities"],
                                              first.inflow[key]["turbulence_intensities"])
        np.testing.assert_array_equal(other.table["aep_baseline_gwh"],
                                      first.table["aep_baseline_gwh"])
    # The per-record atmospheres matter: a record run alone in its own model gives its power.
    alone = row.copy()
    set_atmosphere(alone, {k: v if np.ndim(v) == 0 else v[4:5] for k, v in atmosphere.items()},
                   wind_directions=series.wind_directions[4:5],
                   wind_speeds=series.wind_speeds[4:5],
                   turbulence_intensities=first.inflow["ekman_veer", "record 4"][
                       "turbulence_intensities"])
    alone.run()
    assert first.conditions["ekman_veer"]["farm_power_baseline"].iloc[4] == np.sum(
        alone.get_turbine_powers())


# ----------------------------------------------------------------------------- steered year


def _steered_records(row):
    """Four records of their own atmospheres along the row: two at 19 m/s, where every turbine,
    waked or not, is at rated power (steering cannot gain), two below rated that steer."""
    series, atmosphere, labels = _year_of_records(row, n=4, seed=3)
    speeds = series.wind_speeds.copy()
    speeds[[1, 3]] = 19.0
    series = TimeSeries(series.wind_directions, speeds, turbulence_intensities=0.06)
    return series, atmosphere, labels


def _steered(result):
    """Per record: steered and baseline farm power, optimal yaws, the optimiser's powers."""
    frames = [result.optima["ekman_veer", name] for name in
              dict.fromkeys(result.conditions["ekman_veer"]["stability"])]
    return (result.conditions["ekman_veer"]["farm_power_steered"].to_numpy(),
            result.conditions["ekman_veer"]["farm_power_baseline"].to_numpy(),
            np.vstack([np.vstack(f["yaw_angles_opt"]) for f in frames]),
            np.concatenate([f["farm_power_opt"].to_numpy(float) for f in frames]),
            np.concatenate([f["farm_power_baseline"].to_numpy(float) for f in frames]))


def test_steered_records_do_not_depend_on_the_chunking(row, monkeypatch):
    """The optimiser's result for a record is its own: chunks of 1 record, optimiser runs of
    1 within a chunk of all and a chunk of all give every number bitwise; the records at rated
    skip the optimiser and get exactly what it gives them (zero yaw, the baseline power)."""
    series, atmosphere, labels = _steered_records(row)
    optimised = []
    original = condition_chunks.optimize_yaw

    def counting(fmodel, *args, **kwargs):
        speeds = fmodel.core.flow_field.wind_speeds
        optimised.append((speeds.size, int(np.sum(speeds == 19.0)), kwargs["chunk_size"]))
        return original(fmodel, *args, **kwargs)

    monkeypatch.setattr(condition_chunks, "optimize_yaw", counting)

    def study(**sizes):
        return energy.record_energy(row, series, atmosphere, labels, YawOptimizationSR,
                                    models=["ekman_veer"], progress=False, **YAW, **sizes)

    results = [study(chunk_size=1), study(steering_chunk_size=1)]
    # Without the skip every record is optimised, in one run, with the same numbers.
    monkeypatch.setattr(condition_chunks, "_cannot_gain", lambda fmodel, powers, *_: np.zeros(
        powers.shape[0], dtype=bool))
    results.append(study())
    # (records optimised, of them at rated, conditions per optimiser run): the records at rated
    # never reach the optimiser; by default one run per chunk (4,608 conditions x turbines over
    # 3 turbines).
    assert optimised == [(1, 0, 1536), (1, 0, 1536), (2, 0, 1), (4, 2, 1536)]
    first = _steered(results[0])
    for other in results[1:]:
        for a, b in zip(first, _steered(other)):
            np.testing.assert_array_equal(a, b)
    steered, baseline, yaws, _, _ = first
    rated = series.wind_speeds == 19.0
    assert np.all(yaws[rated] == 0.0) and np.all(steered[rated] == baseline[rated])
    assert np.all(steered[rated] == 3 * 5e6)
    assert np.all(steered[~rated] > baseline[~rated])  # the others steer and gain


def test_what_steering_cannot_gain(row):
    """The skip: every turbine at the maximum of its power table, zero yaw allowed, the
    baseline at zero yaw and weights not negative; for the farm-power optimisers only. Its
    bound is the rated power, not the no-wake power: a lone turbine in the veered SBL-6 wind
    (no wake loss) gains by turning 2 deg against the veer."""
    from floris.optimization.yaw_optimization.yaw_optimizer_geometric import (
        YawOptimizationGeometric,
    )

    lone = row.copy()
    lone.set(layout_x=[0.0], layout_y=[0.0], wind_directions=[270.0] * 2,
             wind_speeds=[8.0] * 2, turbulence_intensities=[0.06] * 2,
             yaw_angles=[[0.0], [-2.0]])
    lone.run()
    unyawed, against_veer = lone.get_turbine_powers()[:, 0]
    assert against_veer > unyawed
    case = row.copy()
    case.set(wind_directions=[270.0] * 3, wind_speeds=[19.0, 8.0, 12.0],
             turbulence_intensities=[0.06] * 3)
    case.run()
    powers = case.get_turbine_powers()
    # 12 m/s: the front turbine at rated, the waked ones below.
    assert powers[2, 0] == 5e6 and np.all(powers[2, 1:] < 5e6)

    def skip(optimizer=YawOptimizationSR, **options):
        return condition_chunks._cannot_gain(case, powers, optimizer, options).tolist()

    assert skip() == [True, False, False]
    assert skip(**YAW) == [True, False, False]
    assert skip(minimum_yaw_angle=5.0) == [False, False, False]  # zero yaw not allowed
    assert skip(yaw_angles_baseline=[[0.0, 0.0, 0.0], [0.0] * 3, [0.0] * 3]) == [True, False,
                                                                                   False]
    assert skip(yaw_angles_baseline=[2.0, 0.0, 0.0]) == [False, False, False]
    assert skip(turbine_weights=[1.0, -1.0, 1.0]) == [False, False, False]
    assert skip(YawOptimizationGeometric) == [False, False, False]


def test_the_comparison_solves_each_chunks_abl_once(row, monkeypatch):
    """The GCH comparison's I_u(z_h) and the inflow hook share one ABL solve per chunk."""
    from floris_ekman_veer.plugin.inflow import solve_cache as inflow

    series, atmosphere, labels = _year_of_records(row, n=6, seed=9)
    solved = []
    original = inflow._solve_moving

    def counting(spec, wind_speeds, *args):
        solved.append(np.asarray(wind_speeds).size)
        return original(spec, wind_speeds, *args)

    monkeypatch.setattr(inflow, "_solve_moving", counting)
    inflow._SOLVE_CACHE.clear()
    energy.record_energy(row, series, atmosphere, labels, models=["gch"], chunk_size=2)
    # Three chunks of two records: three solves of two conditions (the template's own
    # conditions are solved once more, when the GCH copy of the model is built).
    assert [size for size in solved if size == 2] == [2, 2, 2]


def test_client_must_be_a_dask_client(row, atmospheres, no_work):
    pytest.importorskip("distributed")
    series, atmosphere, labels = _year_of_records(row, n=2)
    with pytest.raises(ValueError, match=r"client must be a dask.distributed.Client.*got str"):
        energy.record_energy(row, series, atmosphere, labels, client="tcp://127.0.0.1:8786")
    with pytest.raises(ValueError, match=r"client must be a dask.distributed.Client.*got int"):
        annual_energy(row, ROSE, {"night": {"frequency": 1.0, "atmosphere":
                                            atmospheres["night"]}}, client=8786)
    # A ParFlorisModel already runs its own chunks in parallel: not both at once.
    from floris_ekman_veer import ParFlorisModel

    par = ParFlorisModel(row, interface=None)
    with pytest.raises(ValueError, match=r"fmodel must be a FlorisModel, got ParFlorisModel"):
        energy.record_energy(par, series, atmosphere, labels, client=object())
