"""The validation API as a new user meets it (floris_ekman_veer.studies.validation,
docs/validation.md#your-own-farm): the farm efficiency averaged over the direction uncertainty
with the no-wake power and the reference's standard error, the total-TI conversion, labels
that carry the settings, power and C_T on separate speed grids, ``offshore`` required, and bad
input refused at construction naming the field (docs/validation.md#bad-input): every item of
issue 40's list by name, and a property test that walks the API with bad values.
"""

import math
from pathlib import Path

import floris
import numpy as np
import pytest
import yaml
from floris import FlorisModel
from hypothesis import given
from hypothesis import strategies as st

from floris_ekman_veer.studies.validation import (
    atmospheres,
    cases,
    farm_case,
    metrics,
    models,
    references,
    turbines,
)

SPEED = [4.0, 8.0, 12.0, 25.0]
POWER = [60.0, 700.0, 2000.0, 2000.0]
THRUST = [0.82, 0.80, 0.45, 0.06]
SCADA = np.array([[1, 1.0, 0.02], [2, 0.62, 0.03], [3, 0.58, 0.03]])


def turbine(**changes):
    arguments = dict(name="T", rotor_diameter=80.0, hub_height=70.0, wind_speed=SPEED,
                     power=POWER, thrust_coefficient=THRUST)
    return turbines.turbine_from_table(**{**arguments, **changes})


def row(**changes):
    arguments = dict(label="row A", wind_direction=270.0, turbines=[0, 1, 2], measured=SCADA)
    return references.RowReference(**{**arguments, **changes})


def efficiency(**changes):
    arguments = dict(directions=[260.0, 270.0, 280.0], efficiency=[0.9, 0.7, 0.9],
                     source="SCADA", standard_error=[0.01, 0.02, 0.01])
    return references.EfficiencyReference(**{**arguments, **changes})


def uncertainty(**changes):
    return references.DirectionUncertainty(**{"constant": 3.0, **changes})


LAYOUT = (np.array([0.0, 400.0, 800.0]), np.zeros(3))  # a row along 270 deg, 5 D apart


def farm(**changes):
    arguments = dict(name="my farm", layout=LAYOUT, turbine=turbine(), wind_speed=8.0,
                     latitude=54.0, turbulence=0.06, direction_uncertainty=uncertainty(),
                     rows=(row(),), efficiency=efficiency(), offshore=True)
    return farm_case.FarmCase(**{**arguments, **changes})


# ----------------------------------------------------------------------- what a user gets
def test_farm_efficiency_averages_each_turbine_over_the_direction_uncertainty():
    """The averaged efficiency is the Gaussian-weighted farm power (computed here from plain
    FLORIS runs at each offset) over the no-wake power; the raw one is the plain run; the
    no-wake power is every turbine's unwaked power; the table and efficiency_errors carry the
    reference's standard error (RMS over the directions, NaN without one)."""
    case = farm(direction_uncertainty=uncertainty(constant=4.0))
    table = models.farm_efficiency(case, ["M-1"], sample_step=2.0)
    raw = table[table["kind"] == "raw"]
    averaged = table[table["kind"] == "averaged"]

    fmodel = models.build_model(case, "matched", "M-1")
    offsets = np.arange(-12.0, 13.0, 2.0)
    weights = np.exp(-offsets**2 / (2 * 4.0**2))
    weights /= weights.sum()
    directions = (np.array([260.0, 270.0, 280.0])[:, None] + offsets).ravel()
    n = directions.size
    fmodel.set(wind_directions=directions, wind_speeds=np.full(n, 8.0),
               turbulence_intensities=np.full(n, fmodel.core.flow_field.turbulence_intensities[0]))
    fmodel.run()
    farm_power = fmodel.get_farm_power().reshape(3, offsets.size)
    fmodel.run_no_wake()
    unwaked = fmodel.get_turbine_powers()
    np.testing.assert_allclose(unwaked, unwaked[0, 0], rtol=1e-10)  # uniform inflow, no wake
    no_wake = 3 * unwaked[0, 0]

    np.testing.assert_allclose(averaged["efficiency"], farm_power @ weights / no_wake, rtol=1e-10)
    np.testing.assert_allclose(raw["efficiency"], farm_power[:, 6] / no_wake, rtol=1e-10)
    np.testing.assert_allclose(raw["no_wake_power"], no_wake, rtol=1e-12)
    assert averaged["efficiency"].iloc[1] > raw["efficiency"].iloc[1]  # the aligned minimum
    np.testing.assert_array_equal(raw["standard_error"], [0.01, 0.02, 0.01])

    errors = metrics.efficiency_errors(table)
    (row_,) = errors[errors["kind"] == "averaged"].itertuples()
    error = averaged["efficiency"].to_numpy() - [0.9, 0.7, 0.9]
    assert (row_.n, row_.rmse, row_.bias) == pytest.approx((3, np.sqrt(np.mean(error**2)),
                                                            error.mean()), rel=1e-12)
    assert row_.standard_error == pytest.approx(np.sqrt((0.01**2 + 0.02**2 + 0.01**2) / 3))
    without = models.farm_efficiency(farm(efficiency=efficiency(standard_error=None)), ["M-1"],
                                     sample_step=2.0)
    assert np.isnan(metrics.efficiency_errors(without)["standard_error"]).all()
    # A table built elsewhere (a peer model's) without kind or standard error is scored too.
    other = metrics.efficiency_errors(raw.drop(columns=["kind", "standard_error"]))
    assert other[["rmse", "bias"]].to_numpy().tolist() == errors[errors["kind"] == "raw"][
        ["rmse", "bias"]].to_numpy().tolist()


def test_total_turbulence_converts_with_the_neutral_surface_layer_ratio():
    """sqrt((2.39^2 + 1.92^2 + 1.25^2)/3)/2.39 is 0.80 to two digits (the ratio cited), and
    streamwise_turbulence divides by it; the single wakes read their total TI so."""
    ratio = math.sqrt((2.39**2 + 1.92**2 + 1.25**2) / 3.0) / 2.39
    assert round(ratio, 2) == atmospheres.TOTAL_OVER_STREAMWISE == 0.8
    assert atmospheres.streamwise_turbulence(0.048) == pytest.approx(0.06, rel=1e-15)
    nibe = cases.SINGLE_WAKE_CASES["Nibe"]
    assert nibe.streamwise_turbulence == pytest.approx(0.08 / 0.8, rel=1e-15)
    for bad in (0.0, -0.1, 0.8, float("nan"), "0.1"):
        with pytest.raises(ValueError, match="total_turbulence"):
            atmospheres.streamwise_turbulence(bad)


def test_labels_carry_the_settings_and_make_good_keys():
    """M-1 and its FLORIS-style coupling share a name stem but not a label; each label names
    the resolved wake_expansion and combination and the package's constants; a user's changed
    constant shows; no label
    has a comma or a space; the row table carries the label of every model."""
    case = farm()
    labels = {}
    for name in ("M-1", "M-1, FLORIS-style", "GCH"):
        labels[name] = models.model_label(name, models.build_model(case, "matched", name))
    strings, gch, parameters = models.WAKE_MODELS["M-1"]
    mine = ("M-1 wide", (strings, gch, {**parameters, "velocity": {"k_w_floor": 0.03}}))
    labels["mine"] = models.model_label(mine[0], models.build_model(case, "matched", mine))
    assert labels["M-1"].startswith("M-1[velocity=ekman_veer;")
    assert "wake_expansion=array_turbulence" in labels["M-1"] and "combination=fls" in labels["M-1"]
    assert "wake_expansion=local_turbulence" in labels["M-1, FLORIS-style"]
    assert "combination=sosfs" in labels["M-1, FLORIS-style"]
    assert labels["M-1, FLORIS-style"].startswith("M-1_FLORIS-style[")
    assert "transverse_velocities" in labels["GCH"] and "velocity=gauss" in labels["GCH"]
    assert "deflection.veer=True" in labels["M-1"]
    assert "k_w_floor=0.03" in labels["mine"] and "k_w_floor=0.021" in labels["M-1"]
    assert "alpha=" not in labels["GCH"]  # FLORIS's numbers at FLORIS's defaults
    assert len(set(labels.values())) == 4
    assert not any(c in label for label in labels.values() for c in ", ")
    ratios = models.row_ratios(case, ["M-1", mine], sample_step=2.0, offsets=(0.0,))
    assert set(ratios["label"]) == {labels["M-1"], labels["mine"]}


def test_power_and_thrust_on_separate_speed_grids():
    """C_T on its own grid: the turbine runs where both curves are given, on the union of the
    grids there, each curve interpolated linearly; one grid gives the table as before."""
    t = turbines.turbine_from_table("T", 80.0, 70.0, [3.0, 6.0, 12.0, 25.0],
                                      [0.0, 300.0, 2000.0, 2000.0], [0.9, 0.75, 0.1],
                                      thrust_wind_speed=[4.0, 9.0, 20.0])
    table = t["power_thrust_table"]
    assert table["wind_speed"] == [0.0, 3.9, 4.0, 6.0, 9.0, 12.0, 20.0, 20.1, 50.0]
    assert table["power"][2:7] == pytest.approx([300.0 / 3, 300.0, 300 + 1700 / 2, 2000.0, 2000.0])
    assert table["thrust_coefficient"][2:7] == pytest.approx(
        [0.9, 0.9 - 0.15 * 2 / 5, 0.75, 0.75 - 0.65 * 3 / 11, 0.1])
    assert turbine()["power_thrust_table"]["wind_speed"] == [0.0, 3.9, *SPEED, 25.1, 50.0]
    with pytest.raises(ValueError, match="overlap"):
        turbines.turbine_from_table("T", 80.0, 70.0, [3.0, 6.0], [10.0, 300.0], [0.8, 0.7],
                                      thrust_wind_speed=[6.0, 9.0])
    with pytest.raises(ValueError, match="thrust_coefficient must have one value per "
                                         "thrust_wind_speed"):
        turbines.turbine_from_table("T", 80.0, 70.0, SPEED, POWER, THRUST,
                                      thrust_wind_speed=[4.0, 9.0])


def test_offshore_is_required_and_sets_the_site_roughness():
    """No default: an onshore farm that forgets offshore is refused; given, it picks the site
    reading's roughness (sea 2e-4 m, farmland 0.03 m) unless roughness_length says otherwise."""
    arguments = dict(name="f", layout=LAYOUT, turbine=turbine(), wind_speed=8.0, latitude=54.0,
                     turbulence=0.06)
    with pytest.raises(TypeError, match="offshore"):
        farm_case.FarmCase(**arguments)
    assert farm_case.FarmCase(**arguments, offshore=False).site_roughness == 0.03
    assert farm_case.FarmCase(**arguments, offshore=True).site_roughness == 2e-4
    assert farm_case.FarmCase(**arguments, offshore=False, roughness_length=0.1).site_roughness == 0.1


def test_a_farm_given_its_own_atmosphere_runs_the_given_reading():
    """A case with an atmosphere block and no turbulence runs the "given" reading: its models
    see the block's I_u(z_h) (lower in the stable block than in the neutral one of the same
    roughness), the waked turbines lose power; the "matched" reading is refused naming the
    missing turbulence, as is the "site_measured_turbulence" option."""
    block = {"latitude": 54.0, "roughness_length": 0.01}
    stable = farm(turbulence=None, atmosphere={**block, "cooling_rate": -0.25})
    neutral = farm(turbulence=None, atmosphere=block)
    seen = [models.build_model(case, "given", "M-1").core.flow_field.turbulence_intensities[0]
            for case in (stable, neutral)]
    assert seen[0] == pytest.approx(atmospheres.hub_turbulence(stable, stable.atmosphere), rel=1e-12)
    assert seen[0] < seen[1]
    table = models.row_ratios(stable, ["M-1"], readings=("given",), offsets=(0.0,), sample_step=2.0)
    ratios = table[table["kind"] == "raw"]["ratio"].to_numpy()
    assert ratios[0] == 1.0 and np.all((ratios[1:] > 0.3) & (ratios[1:] < 0.9))
    with pytest.raises(ValueError, match="turbulence"):
        models.row_ratios(stable, ["M-1"], offsets=(0.0,))
    with pytest.raises(ValueError, match=r"reading 'site_measured_turbulence' needs the case's "
                                         r"turbulence"):
        atmospheres.atmosphere(stable, atmospheres.SITE_MEASURED_TURBULENCE)


# --------------------------------------------------------------------------- bad input
NAN = float("nan")
#: Issue 40's list of bad calls, each with the field its message must name.
ISSUE_LIST = [
    ("turbine diameter negative", lambda: turbine(rotor_diameter=-80.0), "rotor_diameter"),
    ("turbine diameter NaN", lambda: turbine(rotor_diameter=NAN), "rotor_diameter"),
    ("hub below D/2", lambda: turbine(hub_height=30.0), "hub_height"),
    ("C_T 1.5", lambda: turbine(thrust_coefficient=[1.5, 0.8, 0.45, 0.06]), "thrust_coefficient"),
    ("C_T negative", lambda: turbine(thrust_coefficient=[0.8, -0.1, 0.45, 0.06]),
     "thrust_coefficient"),
    ("power NaN", lambda: turbine(power=[60.0, NAN, 2000.0, 2000.0]), "power"),
    ("power negative", lambda: turbine(power=[-60.0, 700.0, 2000.0, 2000.0]), "power"),
    ("power in W", lambda: turbine(power=[1e3 * p for p in POWER]), "power"),
    ("name not a string", lambda: turbine(name=5), "name"),
    ("turbines repeated", lambda: row(turbines=[0, 0, 1]), "turbines"),
    ("turbines fractional", lambda: row(turbines=[0, 1.5, 2]), "turbines"),
    ("turbines empty", lambda: row(turbines=[], measured=np.zeros((0, 3))), "turbines"),
    ("ratio NaN", lambda: row(measured=[[1, 1.0, 0.02], [2, NAN, 0.03], [3, 0.58, 0.03]]),
     "measured"),
    ("ratio in percent", lambda: row(measured=SCADA * [1, 100, 1]), "measured"),
    ("standard error negative", lambda: row(measured=SCADA * [1, 1, -1]), "measured"),
    ("direction NaN", lambda: row(wind_direction=NAN), "wind_direction"),
    ("direction 'W'", lambda: row(wind_direction="W"), "wind_direction"),
    ("direction in radians", lambda: farm(rows=(row(wind_direction=1.5 * math.pi),)),
     "wind_direction"),
    ("efficiency lengths", lambda: efficiency(efficiency=[0.9, 0.7]), "efficiency"),
    ("efficiency empty", lambda: efficiency(directions=[], efficiency=[], standard_error=None),
     "directions"),
    ("efficiency NaN", lambda: efficiency(efficiency=[0.9, NAN, 0.9]), "efficiency"),
    ("efficiency above 1", lambda: efficiency(efficiency=[0.9, 1.2, 0.9]), "efficiency"),
    ("efficiency 2-D", lambda: efficiency(efficiency=[[0.9, 0.7, 0.9]]), "efficiency"),
    ("efficiency standard error negative",
     lambda: efficiency(standard_error=[0.01, -0.02, 0.01]), "standard_error"),
    ("wind speed negative", lambda: farm(wind_speed=-8.0), "wind_speed"),
    ("wind speed NaN", lambda: farm(wind_speed=NAN), "wind_speed"),
    ("wind speed string", lambda: farm(wind_speed="8"), "wind_speed"),
    ("latitude 540", lambda: farm(latitude=540.0), "latitude"),
    ("latitude NaN", lambda: farm(latitude=NAN), "latitude"),
    ("latitude 0", lambda: farm(latitude=0.0), "latitude"),
    ("layout NaN", lambda: farm(layout=(np.array([0.0, NAN, 800.0]), np.zeros(3))), "layout"),
    ("layout coincident", lambda: farm(layout=(np.array([0.0, 0.0, 800.0]), np.zeros(3))),
     "layout"),
    ("turbine {}", lambda: farm(turbine={}), "turbine"),
    ("turbine a name", lambda: farm(turbine="nrel_5MW"), "turbine"),
    ("rows a list of indices", lambda: farm(rows=[0, 1, 2]), "rows"),
    ("rows a dict", lambda: farm(rows={"row A": row()}), "rows"),
    ("direction_offsets empty", lambda: farm(direction_offsets=()), "direction_offsets"),
    ("direction_offsets NaN", lambda: farm(direction_offsets=(NAN,)), "direction_offsets"),
    ("roughness negative", lambda: farm(roughness_length=-0.1), "roughness_length"),
    ("atmosphere entry not a number",
     lambda: farm(atmosphere={"latitude": 54.0, "roughness_length": "rough"}), "atmosphere"),
    ("uncertainty reference negative", lambda: uncertainty(reference_turbine=-1),
     "reference_turbine"),
    ("uncertainty reference fractional", lambda: uncertainty(reference_turbine=1.5),
     "reference_turbine"),
    ("uncertainty reference out of range",
     lambda: farm(direction_uncertainty=uncertainty(reference_turbine=3)), "reference_turbine"),
    ("uncertainty 1e4 deg", lambda: uncertainty(constant=1e4), "constant"),
    ("uncertainty a string", lambda: references.DirectionUncertainty("x"), "constant"),
    ("offshore a string", lambda: farm(offshore="yes"), "offshore"),
    ("turbulence unreachable", lambda: farm(turbulence=0.9), "turbulence"),
]


@pytest.mark.parametrize("build, field_name", [(b, f) for _, b, f in ISSUE_LIST],
                         ids=[name for name, _, _ in ISSUE_LIST])
def test_issue_list_of_bad_calls_is_refused_naming_the_field(build, field_name):
    with pytest.raises((ValueError, TypeError), match=field_name):
        build()


def test_the_valid_calls_build():
    """The helpers above build valid objects (so each bad call fails for its one bad field), and
    FLORIS's own NREL 5 MW definition (C_T 1.13 at cut-in) passes the turbine checks."""
    case = farm()
    assert case.rows[0].turbines.shape == (3, 1) and case.efficiency.standard_error.size == 3
    library = Path(floris.__file__).parent / "turbine_library" / "nrel_5MW.yaml"
    nrel = yaml.safe_load(library.read_text())
    assert max(nrel["power_thrust_table"]["thrust_coefficient"]) > 1.1
    assert farm(turbine=nrel, layout=(LAYOUT[0] * 2, LAYOUT[1])).rotor_diameter == 125.88


def _bad_number(low=None, high=None, optional=False):
    """Numbers outside [low, high], NaN, infinities, strings, booleans and (unless the field is
    ``optional``, None meaning "not given") None."""
    options = [st.just(NAN), st.just(math.inf), st.just(-math.inf), st.text(max_size=3),
               st.booleans()] + ([] if optional else [st.none()])
    # (-0.0 equals a bound 0.0: it is inside the range, hence the filters)
    if low is not None:
        options.append(st.floats(max_value=low, exclude_max=True, allow_nan=False,
                                 allow_infinity=False).filter(lambda v: v != low))
    if high is not None:
        options.append(st.floats(min_value=high, exclude_min=True, allow_nan=False,
                                 allow_infinity=False).filter(lambda v: v != high))
    return st.one_of(*options)


def _spoil(values, bad):
    """``values`` with one entry replaced by a bad number."""
    return st.tuples(st.integers(0, len(values) - 1), bad).map(
        lambda pair: [pair[1] if i == pair[0] else v for i, v in enumerate(values)])


#: (field named in the message, strategy of a call that is bad in that field).
WALK = [
    ("rotor_diameter", _bad_number(low=0.0).map(lambda v: lambda: turbine(rotor_diameter=v))),
    ("hub_height", _bad_number(low=40.0).map(lambda v: lambda: turbine(hub_height=v))),
    ("power", _spoil(POWER, _bad_number(low=0.0)).map(lambda p: lambda: turbine(power=p))),
    ("thrust_coefficient", _spoil(THRUST, _bad_number(low=0.0, high=1.2)).map(
        lambda c: lambda: turbine(thrust_coefficient=c))),
    ("wind_speed", _spoil(SPEED, _bad_number(low=0.1, high=49.9)).map(
        lambda s: lambda: turbine(wind_speed=s))),
    ("wind_direction", _bad_number(low=0.0, high=360.0).map(
        lambda d: lambda: row(wind_direction=d))),
    ("turbines", st.one_of(_spoil([0, 1, 2], st.floats(0.01, 0.99)), st.permutations([0, 0, 1]),
                           _spoil([0, 1, 2], st.integers(max_value=-2))).map(
        lambda t: lambda: row(turbines=t))),
    ("measured", _spoil([0.62, 0.58], _bad_number(low=0.0, high=1.5)).map(
        lambda r: lambda: row(measured=[[1, 1.0, 0.02], [2, r[0], 0.03], [3, r[1], 0.03]]))),
    ("efficiency", _spoil([0.9, 0.7, 0.9], _bad_number(low=0.0, high=1.0)).map(
        lambda e: lambda: efficiency(efficiency=e))),
    ("directions", _spoil([260.0, 270.0, 280.0], _bad_number(low=0.0, high=360.0)).map(
        lambda d: lambda: efficiency(directions=d))),
    ("constant", _bad_number(low=0.0, high=30.0).map(lambda c: lambda: uncertainty(constant=c))),
    ("growth", _bad_number(low=0.0, high=0.01).map(lambda g: lambda: uncertainty(growth=g))),
    ("reference_turbine", st.one_of(st.integers(max_value=-1), st.integers(min_value=3),
                                    st.floats(0.1, 2.9), st.text(max_size=2)).map(
        lambda i: lambda: farm(direction_uncertainty=uncertainty(reference_turbine=i)))),
    ("wind_speed", _bad_number(low=0.0, high=50.0).map(lambda u: lambda: farm(wind_speed=u))),
    ("latitude", st.one_of(_bad_number(low=-90.0, high=90.0), st.floats(-0.99, 0.99)).map(
        lambda lat: lambda: farm(latitude=lat))),
    ("turbulence", _bad_number(low=0.0, high=1.0).map(lambda ti: lambda: farm(turbulence=ti))),
    ("layout", st.one_of(_spoil([0.0, 400.0, 800.0], _bad_number()),
                         st.floats(-79.0, 79.0).map(lambda d: [0.0, d, 800.0])).map(
        lambda x: lambda: farm(layout=(x, [0.0, 0.0, 0.0])))),
    ("direction_offsets", st.one_of(st.just(()), _spoil([-1.0, 0.0, 1.0], _bad_number(-30, 30))).map(
        lambda o: lambda: farm(direction_offsets=o))),
    ("roughness_length", _bad_number(low=1e-6, high=5.0, optional=True).map(
        lambda z: lambda: farm(roughness_length=z))),
    ("sample_step", _bad_number(low=0.0, high=10.0).map(
        lambda s: lambda: models.row_ratios(farm(), ["M-1"], sample_step=s))),
    ("offsets", _spoil([0.0], _bad_number(-30, 30)).map(
        lambda o: lambda: models.row_ratios(farm(), ["M-1"], offsets=o))),
    ("directions", _spoil([270.0], _bad_number(0.0, 360.0)).map(
        lambda d: lambda: models.farm_efficiency(farm(), ["M-1"], directions=d))),
]


@given(st.data())
def test_bad_input_is_refused_naming_the_field(data):
    """Walk the validation API with one bad value at a time (out of range, NaN, infinite, a
    string, a boolean, None; in a scalar or one entry of a table): each call raises a ValueError
    or TypeError naming the field, at construction, before any model runs."""
    field_name, strategy = data.draw(st.sampled_from(WALK), label="field")
    call = data.draw(strategy, label="bad call")
    with pytest.raises((ValueError, TypeError), match=field_name):
        call()
