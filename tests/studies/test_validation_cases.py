"""Validation against measured wakes and farms (floris_ekman_veer.studies.validation, examples/validate.py).

The shipped reference data load as published; the TI-matched atmosphere gives the measured
turbulence; the FLORIS models built per case see one inflow, without a warning about settings
the study made; the direction average through FLORIS's UncertainFlorisModel is a plain run at
zero offset and, for a farm a user builds from a layout and a power/C_T table, the Gaussian
average of plain runs computed here; and regression baselines pin the error tables
(FLORIS-baseline style) on a reduced set: the matched atmosphere, M-1 and GCH, each row's
direction only with 2-degree samples (the script runs the +-3 deg bin with 1-degree samples,
docs/validation.md#measured-wakes-and-farms).
"""

import warnings
from pathlib import Path

import numpy as np
import pytest
from floris import FlorisModel

from floris_ekman_veer.warnings import FlorisEkmanVeerWarning

from floris_ekman_veer.studies.validation import atmospheres, cases, metrics, models

import validate  # noqa: E402

RTOL = 1e-6


# ------------------------------------------------------------------------------------- data
def test_single_wake_data_load_as_published():
    """Every arc has its LES; measured arcs where the references measured; directions within
    +-30 deg, U/U0 in a physical range, the Wieringermeer speeds normalised by U0."""
    measured = {name: [a.x_over_d for a in case.arcs if a.measured is not None]
                for name, case in cases.SINGLE_WAKE_CASES.items()}
    assert measured == {"Wieringermeer-West": [3.5], "Wieringermeer-East": [2.5],
                        "Nibe": [2.5, 4.0, 7.5], "Nordtank-500": [1.0, 2.0, 3.0, 4.0, 5.0],
                        "NREL-5MW_TIlow": [], "NREL-5MW_TIhigh": []}
    for case in cases.SINGLE_WAKE_CASES.values():
        for arc in case.arcs:
            assert arc.les is not None and arc.les.shape[1] == 4
            if arc.measured is not None:
                assert np.all(np.abs(arc.measured[:, 0]) <= 30.0)
                assert 0.3 < arc.measured[:, 1].min() and arc.measured[:, 1].max() < 1.25
    west = cases.SINGLE_WAKE_CASES["Wieringermeer-West"].arcs[1].measured
    assert west.shape == (30, 4)  # 286-344 deg of the 284-346 deg file
    assert west[0, :2] == pytest.approx([286.0 - 315.0, 10.766424 / 10.7], rel=1e-12)
    nordtank = cases.SINGLE_WAKE_CASES["Nordtank-500"].arcs[1].measured
    assert nordtank[3].tolist() == pytest.approx([0.0, 0.586674, 0.010258, 74.0])


def test_horns_rev_data_and_direction_uncertainty():
    """80 turbines in 10 columns of 8 with rows along x (the 270-deg wind runs along them, 7 D
    apart); measured P_i/P_1 with row 1 = 1; sigma = sqrt(2.1^2 + 2.5^2) at G2, growing with
    distance; the V80 table as given."""
    hr = cases.HORNS_REV
    x, y = hr.layout
    (rows,) = hr.rows
    assert x.shape == (80,) and rows.turbines.shape == (10, 6) and not rows.gaps.any()
    row = np.arange(10) * 8 + 3
    np.testing.assert_allclose(y[row], y[row[0]])
    np.testing.assert_allclose(np.diff(x[row]), 560.0, rtol=0.01)
    assert rows.measured.shape == (10, 3) and rows.measured[0, 1] == 1.0
    assert rows.measured[1, 1] == pytest.approx(0.687317 / 0.985987, rel=1e-12)
    sigma = hr.direction_sigma()
    assert sigma[6] == pytest.approx(np.hypot(2.1, 2.5), rel=1e-12)
    assert sigma.min() == sigma[6] and sigma[79] > 4.0
    assert rows.rans.shape == (10, 3) and hr.efficiency.efficiency.shape == (67,)
    table = hr.turbine["power_thrust_table"]
    assert np.interp(8.0, table["wind_speed"], table["power"]) == 696.0
    assert np.interp(8.0, table["wind_speed"], table["thrust_coefficient"]) == 0.806


def test_lillgrund_rows_lie_along_the_wind_with_the_gap():
    """Lillgrund: 48 SWT-2.3-93s; rows B and D run from the south-west along 222 deg, 4.3 D
    apart; row D's fourth position is the gap (NaN); the measured ratios are the files'
    (P_1 = 1), their error bars std/sqrt(n); sigma is 3.3 deg for every turbine."""
    lg = cases.LILLGRUND
    x, y = lg.layout
    assert x.shape == (48,) and lg.rotor_diameter == 92.6 and lg.hub_height == 65.0
    assert [r.label for r in lg.rows] == ["row B", "row D"] * 2
    assert [r.wind_direction for r in lg.rows] == [222.0, 222.0, 207.0, 207.0]
    row_b = lg.rows[0].turbines[:, 0]
    step = np.hypot(np.diff(x[row_b]), np.diff(y[row_b])) / lg.rotor_diameter
    np.testing.assert_allclose(step, 4.3, atol=0.05)
    bearing = np.degrees(np.arctan2(x[row_b[0]] - x[row_b[-1]], y[row_b[0]] - y[row_b[-1]])) % 360
    assert bearing == pytest.approx(222.0, abs=1.0)  # the first turbine is upwind at 222 deg
    row_d = lg.rows[1]
    assert row_d.gaps.tolist() == [False] * 3 + [True] + [False] * 4
    assert np.isnan(row_d.measured[3, 1]) and row_d.measured[4, 1] == pytest.approx(0.5717)
    assert row_d.measured[1, 2] == pytest.approx(0.1658 / np.sqrt(266), rel=1e-12)
    np.testing.assert_array_equal(lg.direction_sigma(), 3.3)
    assert lg.thrust_coefficient == pytest.approx(0.87)


# ------------------------------------------------------------------------------ atmospheres
@pytest.mark.parametrize("name", [*cases.SINGLE_WAKE_CASES, *cases.FARM_CASES])
def test_matched_atmosphere_gives_the_measured_turbulence(name):
    """The matched neutral ABL's I_u(z_h) (Eq. Iu_model) is the measured streamwise TI
    (TI_total/0.8 for single wakes, 0.056 at Horns Rev, 0.048 at Lillgrund); a rougher surface
    gives more turbulence, so the match is unique."""
    case = {**cases.SINGLE_WAKE_CASES, **cases.FARM_CASES}[name]
    z0 = atmospheres.matched_roughness(case)
    assert atmospheres.hub_turbulence(case, z0) == pytest.approx(case.streamwise_turbulence, rel=1e-9)
    assert atmospheres.hub_turbulence(case, 0.5 * z0) < case.streamwise_turbulence
    assert atmospheres.hub_turbulence(case, 2.0 * z0) > case.streamwise_turbulence
    site = atmospheres.atmosphere(case, "site")
    assert site["roughness_length"] == (2e-4 if case.offshore else 0.03)


def test_every_model_sees_the_atmospheres_turbulence():
    """FLORIS's ambient TI of every model is I_u(z_h) of the case's atmosphere; unknown
    readings and models are refused."""
    case = cases.SINGLE_WAKE_CASES["Nibe"]
    expected = atmospheres.hub_turbulence(case, atmospheres.matched_roughness(case))
    for model in ("M-1", "GCH", "TurbOPark", "empirical_gauss"):
        fmodel = models.build_model(case, "matched", model)
        assert fmodel.core.flow_field.turbulence_intensities[0] == pytest.approx(expected, rel=1e-12)
    with pytest.raises(ValueError, match="reading"):
        atmospheres.atmosphere(case, "measured")
    with pytest.raises(ValueError, match="model"):
        models.floris_input(case, "site", "jensen")


@pytest.mark.parametrize("name", ["NREL-5MW_TIhigh", "Lillgrund"])
def test_site_measured_turbulence_reading_is_the_site_workflow(name):
    """The option "site_measured_turbulence" is what fit_site gives a user with the site's data
    (docs/validation.md#the-atmosphere-of-a-case): the site's roughness, and the block's
    turbulence_factor = measured I_u(z_h) / the site ABL's I_u(z_h) (1.80 for the high-TI LES on
    farmland, 0.85 at Lillgrund). The M-1 wake's ambient I_u(z_h), as FLORIS solves the block,
    is the measured one, its k_w Eq. (kw_CNBL_SBL_model) of it by hand, FLORIS's built-ins get
    the same TI; the rotor's U(z), V(z) are the site roughness's, not the matched reading's;
    validity_report flags the factor as beyond the paper."""
    from floris_ekman_veer.plugin.inflow.atmosphere_block import atmosphere_of
    from floris_ekman_veer.plugin.inflow.solve_cache import solve
    from floris_ekman_veer.studies.validity import validity_report

    case = {**cases.SINGLE_WAKE_CASES, **cases.FARM_CASES}[name]
    reading = atmospheres.SITE_MEASURED_TURBULENCE
    block, site = atmospheres.atmosphere(case, reading), atmospheres.atmosphere(case, "site")
    measured = case.streamwise_turbulence
    assert block["roughness_length"] == site["roughness_length"] == case.site_roughness
    assert block["turbulence_factor"] == pytest.approx(
        measured / atmospheres.hub_turbulence(case, site), rel=1e-12)
    assert block["turbulence_factor"] == pytest.approx(
        {"NREL-5MW_TIhigh": 1.80, "Lillgrund": 0.85}[name], abs=0.005)

    fmodel = models.build_model(case, reading, "M-1")
    speeds = np.array([case.wind_speed])
    abl = solve(atmosphere_of(fmodel.core), speeds, case.hub_height)
    ambient = np.asarray(abl.turbulence_intensity(case.hub_height,
                                                  reference_height=case.hub_height)).reshape(-1)
    np.testing.assert_allclose(ambient, measured, rtol=1e-10)
    at_hub = np.full((1, 1, 1, 1), case.hub_height)
    k_w = fmodel.core.wake.velocity_model.expansion_rate(
        abl, at_hub, speeds.reshape(1, 1, 1, 1), ambient.reshape(1, 1, 1, 1),
        ambient.reshape(1, 1, 1, 1))
    np.testing.assert_allclose(np.asarray(k_w).reshape(-1),
                               (0.021**6 + (0.33 * measured) ** 6) ** (1 / 6), rtol=1e-10)
    for model in ("GCH", "cc", "M-3"):
        ti = models.build_model(case, reading, model).core.flow_field.turbulence_intensities[0]
        assert ti == pytest.approx(measured, rel=1e-10), model

    # Shear and veer across the rotor: the site roughness's ABL (the factor touches only the
    # turbulence), measurably not the matched roughness's.
    heights = case.hub_height + 0.5 * case.rotor_diameter * np.linspace(-1.0, 1.0, 5)
    def rotor_wind(b):
        return np.array(solve(atmosphere_of(models.build_model(case, b, "M-1").core), speeds,
                              case.hub_height).hub_aligned_velocity(heights, case.hub_height))
    np.testing.assert_allclose(np.array(abl.hub_aligned_velocity(heights, case.hub_height)),
                               rotor_wind("site"), rtol=1e-12, atol=1e-12)
    assert np.abs(rotor_wind(reading) - rotor_wind("matched")).max() > 0.01

    report = validity_report(fmodel)
    assert bool(report["ambient_turbulence_beyond_paper"].iloc[0])
    assert not bool(validity_report(models.build_model(case, "site", "M-1"))
                    ["ambient_turbulence_beyond_paper"].iloc[0])


def test_no_warning_about_the_studys_own_settings():
    """Building every model of the study for a farm raises none of the package's warnings
    (the study sets FLORIS's veer only for FLORIS's models, its power-law shear only where
    GCH's terms read it); the built-ins keep FLORIS's rotor veer of the atmosphere."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", FlorisEkmanVeerWarning)
        built = {m: models.build_model(cases.LILLGRUND, "matched", m) for m in models.WAKE_MODELS}
    assert built["GCH"].core.flow_field.wind_veer != 0.0
    assert built["M-1"].core.flow_field.wind_veer == 0.0
    for name, fmodel in built.items():
        gch = fmodel.core.wake.enable_transverse_velocities
        assert (fmodel.core.flow_field.wind_shear != 0.0) == gch, name


def test_arcs_are_free_stream_outside_the_wake_and_waked_at_the_centre():
    """U/U0 -> 1 at +-30 deg on the far arc (3.75 D aside at 7.5 D) and is lowest near the
    wake centre, for the package's and FLORIS's models: the frame and normalisation are right."""
    case = cases.SINGLE_WAKE_CASES["NREL-5MW_TIhigh"]
    theta = models.arc_directions()
    for model in ("M-1", "GCH"):
        profile = models.arc_profiles(case, "matched", model)
        assert profile[-1, [0, -1]] == pytest.approx([1.0, 1.0], abs=2e-3)
        assert abs(theta[np.argmin(profile[-1])]) <= 1.0
        assert profile[:, 60].tolist() == sorted(profile[:, 60])  # recovers downstream


# ------------------------------------------------------------------------- direction average
def test_zero_offset_of_the_uncertain_model_is_the_plain_run():
    """The "raw" rows from UncertainFlorisModel's zero offset equal a plain FlorisModel run at
    270 deg; row 1 is 1; averaging raises the waked rows; row 2 is the same for M-1 with
    the array coupling and with ambient k_w (turbine 1 is unwaked, so its k_w is the paper's in
    both)."""
    hr = cases.HORNS_REV
    table = models.row_ratios(hr, ["M-1", "M-1, ambient k_w"], sample_step=2.0, offsets=(0.0,))
    pick = lambda model, kind: table[(table["model"] == model)  # noqa: E731
                                     & (table["kind"] == kind)]["ratio"].to_numpy()
    fmodel = models.build_model(hr, "matched", "M-1")
    fmodel.run()
    power = fmodel.get_turbine_powers()[0][hr.rows[0].turbines].mean(axis=1)
    np.testing.assert_allclose(pick("M-1", "raw"), power / power[0], rtol=1e-12)
    assert pick("M-1", "raw")[0] == pick("M-1", "averaged")[0] == 1.0
    assert np.all(pick("M-1", "averaged")[1:] > pick("M-1", "raw")[1:])
    assert pick("M-1, ambient k_w", "raw")[1] == pytest.approx(pick("M-1", "raw")[1], rel=1e-12)
    assert np.all(pick("M-1, ambient k_w", "raw")[2:] < pick("M-1", "raw")[2:])


def test_a_new_farm_in_a_few_lines_is_the_gaussian_average_of_plain_runs():
    """A user's farm from a layout and a power/C_T table: four turbines in a row 6 D apart
    along 250 deg, a gap, a constant 4-deg direction uncertainty and invented "SCADA" ratios.
    The averaged ratios are the Gaussian-weighted mean (computed here) of plain FlorisModel
    runs at each offset; RMSE and bias are the hand values over the waked positions."""
    table = np.array([[4.0, 100.0, 0.85], [8.0, 1000.0, 0.8], [12.0, 2000.0, 0.4]])
    turbine = cases.turbine_from_table("T", 100.0, 90.0, *table.T)
    bearing = np.radians(250.0)  # the row runs downwind from turbine 0
    along = np.arange(5) * 600.0
    x, y = 5e5 - along * np.sin(bearing), 6e6 - along * np.cos(bearing)  # UTM-like
    measured = np.array([[1, 1.0, 0.01], [2, 0.6, 0.02], [3, 0.55, 0.02], [4, np.nan, np.nan],
                         [5, 0.5, 0.03]])
    case = cases.FarmCase(
        "my farm", (x, y), turbine, wind_speed=8.0, latitude=54.0, turbulence=0.07,
        direction_uncertainty=cases.DirectionUncertainty(4.0), direction_offsets=(0.0,),
        rows=(cases.RowReference("row 1", 250.0, [0, 1, 2, -1, 4], measured),), offshore=False)
    ratios = models.row_ratios(case, ["M-1", "GCH"], sample_step=2.0)
    errors = metrics.row_errors(ratios)

    assert turbine["power_thrust_table"]["wind_speed"][:3] == [0.0, 3.9, 4.0]
    assert turbine["power_thrust_table"]["power"][-2:] == [0.0, 0.0]
    offsets = np.arange(-12.0, 13.0, 2.0)
    weights = np.exp(-offsets**2 / (2 * 4.0**2))
    weights /= weights.sum()
    fmodel = models.build_model(case, "matched", "M-1")
    n = offsets.size
    fmodel.set(wind_directions=250.0 + offsets, wind_speeds=np.full(n, 8.0),
               turbulence_intensities=np.full(n, fmodel.core.flow_field.turbulence_intensities[0]))
    fmodel.run()
    power = weights @ fmodel.get_turbine_powers()
    expected = power[[0, 1, 2, 0, 4]] / power[0]
    expected[3] = np.nan
    m1 = ratios[(ratios["model"] == "M-1") & (ratios["kind"] == "averaged")]
    np.testing.assert_allclose(m1["ratio"], expected, rtol=1e-12)
    error = expected[[1, 2, 4]] - measured[[1, 2, 4], 1]
    (row,) = errors[(errors["model"] == "M-1") & (errors["kind"] == "averaged")].itertuples()
    assert (row.n, row.rmse, row.bias) == pytest.approx((3, np.sqrt(np.mean(error**2)), error.mean()),
                                                        rel=1e-12)
    assert row.standard_error == pytest.approx(np.sqrt(np.mean([0.02**2, 0.02**2, 0.03**2])))
    assert np.all(m1["ratio"].to_numpy()[[1, 2, 4]] < 0.8)  # every waked turbine loses
    with pytest.raises(ValueError, match="turbine index 7"):
        cases.FarmCase("bad", (x, y), turbine, 8.0, 54.0, 0.07, cases.DirectionUncertainty(4.0),
                       rows=(cases.RowReference("r", 250.0, [0, 7], measured[:2]),), offshore=False)
    with pytest.raises(ValueError, match="wind_speed must increase"):
        cases.turbine_from_table("T", 100.0, 90.0, [8.0, 4.0], [1.0, 2.0], [0.8, 0.8])


# --------------------------------------------------------------------- regression baselines
from tests.regression_baselines import ARC_BASELINE, EFFICIENCY_BASELINE, ROWS_BASELINE  # noqa: E402


def test_regression_single_wake_errors():
    """RMSE and bias of U/U0 pooled over each case's arcs, against measurements and LES."""
    errors = validate.single_wake_errors(
        validate.single_wakes(models=("M-1", "GCH"), readings=("matched",)))
    for (case, model), expected in ARC_BASELINE.items():
        rows = errors[(case, "matched", model)]
        for reference, values in expected.items():
            chosen = [r for r in rows if r["reference"] == reference]
            assert metrics.pooled(chosen)[:2] == pytest.approx(values, rel=RTOL), (case, model)
        assert {r["reference"] for r in rows} == set(expected)


def test_regression_farm_rows():
    """P_i/P_1 along Horns Rev's inner rows and Lillgrund's rows B and D, raw and averaged over
    the direction uncertainty; the error measure is the RMSE over the waked positions against
    the measured means."""
    rows = validate.farm_rows(models=("M-1", "M-1, ambient k_w", "GCH"), readings=("matched",),
                              sample_step=2.0, offsets=(0.0,))
    for (case, model), expected in ROWS_BASELINE.items():
        for (row, direction), (raw, averaged) in expected.items():
            chosen = rows[(rows["case"] == case) & (rows["model"] == model)
                          & (rows["row"] == row) & (rows["wind_direction"] == direction)]
            for kind, values in (("raw", raw), ("averaged", averaged)):
                np.testing.assert_allclose(chosen[chosen["kind"] == kind]["ratio"], values,
                                           rtol=RTOL, err_msg=f"{case} {model} {row} {kind}")
    errors = metrics.row_errors(rows[rows["case"] == "Lillgrund"])
    lillgrund = rows[(rows["case"] == "Lillgrund") & (rows["model"] == "GCH")
                     & (rows["kind"] == "averaged") & (rows["position"] > 1)].dropna()
    error = lillgrund["ratio"].to_numpy() - lillgrund["measured"].to_numpy()
    (gch,) = errors[(errors["model"] == "GCH") & (errors["kind"] == "averaged")].itertuples()
    assert (gch.n, gch.rmse) == pytest.approx((26, np.sqrt(np.mean(error**2))), rel=1e-12)


def test_regression_farm_efficiency():
    """Farm power over 80 unwaked turbines at three directions (aligned rows at 270 deg give
    the deepest losses); the efficiency is below 1 and FLORIS's no-wake run is its reference;
    averaged over the direction uncertainty the aligned minimum is shallower."""
    directions = np.array([222.0, 270.0, 312.0])
    effs = validate.efficiency(models=tuple(EFFICIENCY_BASELINE), readings=("matched",),
                               directions=directions)
    for model, expected in EFFICIENCY_BASELINE.items():
        chosen = effs[effs["model"] == model]
        raw = chosen[chosen["kind"] == "raw"]
        values = raw["efficiency"].to_numpy()
        np.testing.assert_allclose(values, expected, rtol=RTOL)
        assert np.argmin(values) == 1
        np.testing.assert_allclose(values, raw["farm_power"] / raw["no_wake_power"], rtol=1e-15)
        averaged = chosen[chosen["kind"] == "averaged"]["efficiency"].to_numpy()
        assert averaged[1] > values[1] and np.all(averaged < 1.0)


def test_reference_simulations_against_measurements_are_the_published_files():
    """The LES/RANS rows of the tables: the published simulations interpolated to the measured
    directions, here recomputed by hand for Nibe at 4 D."""
    case = cases.SINGLE_WAKE_CASES["Nibe"]
    (row,) = [r for r in metrics.reference_arc_errors(case) if r["x/D"] == 4.0 and r["simulation"] == "LES"]
    arc = case.arcs[1]
    model = np.interp(arc.measured[:, 0], arc.les[:, 0], arc.les[:, 1])
    error = model - arc.measured[:, 1]
    assert (row["rmse"], row["bias"]) == pytest.approx((np.sqrt(np.mean(error**2)), error.mean()),
                                                      rel=1e-12)


def test_docs_tables_that_need_no_wake_model_are_the_scripts():
    """docs/validation.md carries examples/validate.py's atmosphere table and the published
    RANS's row errors as the script writes them (the model tables come from the same script;
    the regression baselines above pin the models)."""
    text = (Path(__file__).resolve().parents[2] / "docs" / "validation.md").read_text()
    assert validate.atmosphere_table() in text
    rows = validate.farm_rows(models=("GCH",), readings=("site", "matched"), sample_step=2.0,
                              offsets=(0.0,))
    for case in cases.FARM_CASES:
        lines = validate.rows_error_table(rows, case).splitlines()
        for line in lines[-2:]:  # the RANS and the measurements' standard error
            assert line in text, (case, line)
