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
        rows=(cases.RowReference("row 1", 250.0, [0, 1, 2, -1, 4], measured),))
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
                       rows=(cases.RowReference("r", 250.0, [0, 7], measured[:2]),))
    with pytest.raises(ValueError, match="wind_speed must increase"):
        cases.turbine_from_table("T", 100.0, 90.0, [8.0, 4.0], [1.0, 2.0], [0.8, 0.8])


# --------------------------------------------------------------------- regression baselines
ARC_BASELINE = {  # (case, model): {reference: (rmse, bias)} of U/U0, matched atmosphere
    ("Wieringermeer-West", "M-1"): {"measured": (0.06064655427544252, -0.005799271926240701),
                                    "les": (0.035818098423714126, 0.001353710802309095)},
    ("Wieringermeer-East", "M-1"): {"measured": (0.09210570737482607, 0.06870950923010367),
                                    "les": (0.04778688235215872, 0.006484919849671998)},
    ("Nibe", "M-1"): {"measured": (0.05237201382224569, -0.016139459650627175),
                      "les": (0.025254576312654126, -0.00256431514205809)},
    ("Nordtank-500", "M-1"): {"measured": (0.07305278354029246, 0.017006088808244543),
                              "les": (0.06846233322780786, 0.0071721461264622356)},
    ("NREL-5MW_TIlow", "M-1"): {"les": (0.06590789203721119, -0.006218957391897042)},
    ("NREL-5MW_TIhigh", "M-1"): {"les": (0.014643631153365418, -0.0012450745483887802)},
    ("Wieringermeer-West", "GCH"): {"measured": (0.06588910355291576, -0.011432773825253754),
                                    "les": (0.043935576575153214, -0.01150260114332525)},
    ("Wieringermeer-East", "GCH"): {"measured": (0.06266635183666248, 0.017612937017735),
                                    "les": (0.058386198250386614, -0.01610905964561695)},
    ("Nibe", "GCH"): {"measured": (0.05911468074295459, -0.026452630830996807),
                      "les": (0.0415497289215358, -0.012269840121557032)},
    ("Nordtank-500", "GCH"): {"measured": (0.09411886380750081, -0.028314789680945432),
                              "les": (0.08234949660989326, -0.013297496959876068)},
    ("NREL-5MW_TIlow", "GCH"): {"les": (0.07714355440299886, -0.026091311953275593)},
    ("NREL-5MW_TIhigh", "GCH"): {"les": (0.024587581738582494, -0.004156068898391205)},
}

ROWS_BASELINE = {  # (case, model): {(row, direction): (raw, averaged)} P_i/P_1, 2-degree samples, matched
    ('Hornsrev1', 'M-1'): {
        ('inner rows', 270.0): ([1.0, 0.4023908302179945, 0.425677161201434, 0.48120319753544644, 0.5051468241355155, 0.5168710802555235, 0.5229600605711895, 0.5258442690222267, 0.5265884259978285, 0.5258809640584229],
            [1.0, 0.5482485797770484, 0.5875576236405351, 0.6223335959051206, 0.6328902098370175, 0.6327624743982431, 0.6260730627822807, 0.618120260598924, 0.6122449871653922, 0.6084488306618281]),
    },
    ('Hornsrev1', 'M-1, ambient k_w'): {
        ('inner rows', 270.0): ([1.0, 0.4023908302179945, 0.2924696979703687, 0.24197633485106257, 0.2160946600728557, 0.20321513585441303, 0.1939860807946629, 0.18701445590100454, 0.18153812801021557, 0.17710353784773905],
            [1.0, 0.5482485797770484, 0.4887310747672547, 0.4715677581778416, 0.46641202374058344, 0.464412300857671, 0.46063873862808774, 0.4549223994895808, 0.44846099794105676, 0.4426258462167675]),
    },
    ('Hornsrev1', 'GCH'): {
        ('inner rows', 270.0): ([1.0, 0.35462281638985854, 0.5297319367945017, 0.5902614740072087, 0.6124117467566873, 0.6218889184761228, 0.6264837498517564, 0.6289831301349558, 0.6304887108297905, 0.6314806302615903],
            [1.0, 0.5149043820206376, 0.6539514610241017, 0.6856149147713543, 0.6966752530878672, 0.7018387301348096, 0.705120937488022, 0.7088226316075775, 0.7130953036153481, 0.7172009171534495]),
    },
    ('Lillgrund', 'M-1'): {
        ('row B', 222.0): ([1.0, 0.2506624796469871, 0.2652132515668002, 0.3055659791250896, 0.34709551385391624, 0.36609888571592125, 0.3734368122022061, 0.37482425281665654],
            [1.0, 0.32954481276784947, 0.3820518397656245, 0.41745853617343864, 0.43886004094674724, 0.43401747858533085, 0.4200741550564748, 0.40701728047768443]),
        ('row D', 222.0): ([1.0, 0.2506624796471809, 0.2651854910281499, np.nan, 0.5103697513916302, 0.35281701091494744, 0.34279874554877515, 0.34504434270904005],
            [1.0, 0.3295448199501723, 0.3821222290426371, np.nan, 0.6332578519755048, 0.42739352586863827, 0.3988992911068901, 0.3855636143020988]),
        ('row B', 207.0): ([1.0, 0.9273124153797161, 0.9157030063433076, 0.8712674925525435, 0.4863019170164696, 0.4663452334131935, 0.53316960234456, 0.5548042533993157],
            [1.0, 0.8894177682726175, 0.8939679032175428, 0.7910551347272319, 0.5295212651674668, 0.46639443707102146, 0.4984945646079842, 0.5172693360106331]),
        ('row D', 207.0): ([1.0, 0.9273119834356011, 0.8805807645061758, np.nan, 0.5310506507626814, 0.5342438168752429, 0.46570974740276744, 0.4466339342469274],
            [1.0, 0.8893909353301164, 0.8008381162385249, np.nan, 0.5517333826886655, 0.49920042172727347, 0.4739037795702687, 0.4564918703494256]),
    },
    ('Lillgrund', 'M-1, ambient k_w'): {
        ('row B', 222.0): ([1.0, 0.2506624796469871, 0.1399110215781514, 0.10628910163789204, 0.08721228103333149, 0.0774914426706544, 0.07007398587096235, 0.06422606067732398],
            [1.0, 0.32954481276784947, 0.2642515025698955, 0.2425593135240012, 0.22462910712143067, 0.20773067084377086, 0.18796347625335283, 0.16963718741412573]),
        ('row D', 222.0): ([1.0, 0.2506624796471809, 0.13984079522844456, np.nan, 0.2604437168384032, 0.1122959091622689, 0.08483562336991145, 0.07236366434131598],
            [1.0, 0.3295448199501723, 0.26432482259134865, np.nan, 0.4693799282104229, 0.2357043346758973, 0.20082110647016296, 0.18122418571012092]),
        ('row B', 207.0): ([1.0, 0.9273124153797161, 0.9292902869308942, 0.8942309219309996, 0.5257053401662237, 0.4121416669634144, 0.40786720394073844, 0.40748998582483603],
            [1.0, 0.8894177682726175, 0.8936162977646581, 0.8004632190570035, 0.5516645487765466, 0.44235349885486824, 0.41434704569705755, 0.4048366724414586]),
        ('row D', 207.0): ([1.0, 0.9273119834356011, 0.8943698762557697, np.nan, 0.44649872596014023, 0.39013532733052037, 0.32878707561269704, 0.27687014720758396],
            [1.0, 0.8893909353301164, 0.8006781435561974, np.nan, 0.5073086099842594, 0.36725470149856076, 0.3245426186465549, 0.29041187075567537]),
    },
    ('Lillgrund', 'GCH'): {
        ('row B', 222.0): ([1.0, 0.12744243897800964, 0.2815116972475198, 0.361387111163825, 0.3967434815357856, 0.42202488928225473, 0.43509684675871635, 0.4440395588806763],
            [1.0, 0.22684537068044858, 0.4026362385022305, 0.45496918312178064, 0.4753856402557542, 0.4876242519591412, 0.49206681961029286, 0.4960000744435502]),
        ('row D', 222.0): ([1.0, 0.1271149478517183, 0.2807035314043629, np.nan, 0.5897011927009922, 0.37943042385848447, 0.4304023751605315, 0.43951773848734355],
            [1.0, 0.2264436539570121, 0.4022793209737801, np.nan, 0.7007535541449508, 0.44678779578371786, 0.4890811775842078, 0.49243374014634667]),
        ('row B', 207.0): ([1.0, 0.9487184317523272, 0.9160175636992133, 0.8959281712393918, 0.5476401882332663, 0.6982127777863382, 0.7386782492246287, 0.7357208541239338],
            [1.0, 0.9009344172625645, 0.8952533114549626, 0.8010823189977162, 0.5978650685939488, 0.6244562945458596, 0.6655830609542496, 0.6804956365376114]),
        ('row D', 207.0): ([1.0, 0.9473647712734706, 0.897383545758023, np.nan, 0.7223356766469298, 0.7372886431511075, 0.6899485830170491, 0.7283950661813604],
            [1.0, 0.901754543820013, 0.8056565087102798, np.nan, 0.6784208442066237, 0.6904066019977914, 0.6872113795623832, 0.6989279098229058]),
    },
}
EFFICIENCY_BASELINE = {  # farm efficiency at 222, 270, 312 deg, matched
    'M-1': [0.6354290026110677, 0.5433313664430555, 0.666143416078126],
    'GCH': [0.7146960643492307, 0.6226137519886916, 0.7484765886172087],
}


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
    the deepest losses); the efficiency is below 1 and FLORIS's no-wake run is its reference."""
    directions = np.array([222.0, 270.0, 312.0])
    effs = validate.efficiency(models=tuple(EFFICIENCY_BASELINE), readings=("matched",),
                               directions=directions)
    for model, expected in EFFICIENCY_BASELINE.items():
        values = effs[effs["model"] == model]["efficiency"].to_numpy()
        np.testing.assert_allclose(values, expected, rtol=RTOL)
        assert np.argmin(values) == 1


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
