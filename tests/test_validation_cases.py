"""Validation against measured wakes and farms (floris_ekman_veer.studies.validation, examples/validate.py).

The shipped reference data load as published; the TI-matched atmosphere gives the measured
turbulence; the FLORIS models built per case see one inflow; the direction average through
FLORIS's UncertainFlorisModel is a plain run at zero offset; and regression baselines pin the
error tables (FLORIS-baseline style) on a reduced set: the matched atmosphere, M-1 and GCH,
Horns Rev at 270 deg only with 2-degree samples (the script runs the 267-273 deg bin with
1-degree samples, docs/validation.md#measured-wakes-and-farms).
"""

import sys
from pathlib import Path

import numpy as np
import pytest

from floris_ekman_veer.studies.validation import atmospheres, cases, metrics, models

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
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
    assert x.shape == (80,) and hr.inner_rows.shape == (10, 6)
    row = np.arange(10) * 8 + 3
    np.testing.assert_allclose(y[row], y[row[0]])
    np.testing.assert_allclose(np.diff(x[row]), 560.0, rtol=0.01)
    assert hr.measured_rows.shape == (10, 3) and hr.measured_rows[0, 1] == 1.0
    assert hr.measured_rows[1, 1] == pytest.approx(0.687317 / 0.985987, rel=1e-12)
    sigma = hr.direction_sigma()
    assert sigma[6] == pytest.approx(np.hypot(2.1, 2.5), rel=1e-12)
    assert sigma.min() == sigma[6] and sigma[79] > 4.0
    assert hr.rans_rows.shape == (10, 3) and hr.les_efficiency.shape[1] == 2
    turbine = cases.v80_turbine()
    table = turbine["power_thrust_table"]
    assert np.interp(8.0, table["wind_speed"], table["power"]) == 696.0
    assert np.interp(8.0, table["wind_speed"], table["thrust_coefficient"]) == 0.806


# ------------------------------------------------------------------------------ atmospheres
@pytest.mark.parametrize("name", [*cases.SINGLE_WAKE_CASES, "Hornsrev1"])
def test_matched_atmosphere_gives_the_measured_turbulence(name):
    """The matched neutral ABL's I_u(z_h) (Eq. Iu_model) is the measured streamwise TI
    (TI_total/0.8 for single wakes, 0.056 at Horns Rev); a rougher surface gives more
    turbulence, so the match is unique."""
    case = cases.HORNS_REV if name == "Hornsrev1" else cases.SINGLE_WAKE_CASES[name]
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
        fmodel = models.build_model(case, "matched", model, cases.constant_thrust_turbine(case),
                                    ([0.0], [0.0]))
        assert fmodel.core.flow_field.turbulence_intensities[0] == pytest.approx(expected, rel=1e-12)
    with pytest.raises(ValueError, match="reading"):
        atmospheres.atmosphere(case, "measured")
    with pytest.raises(ValueError, match="model"):
        models.floris_input(case, "site", "jensen", {}, ([0.0], [0.0]))


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
    local_turbulence and ambient k_w (turbine 1 is unwaked, so its k_w is the paper's in both)."""
    rows = models.horns_rev_rows("M-1", "matched", sample_step=2.0, directions=(270.0,))
    hr = cases.HORNS_REV
    fmodel = models.build_model(hr, "matched", "M-1", cases.v80_turbine(), hr.layout)
    fmodel.run()
    power = fmodel.get_turbine_powers()[0][hr.inner_rows].mean(axis=1)
    np.testing.assert_allclose(rows["raw"], power / power[0], rtol=1e-12)
    assert rows["raw"][0] == rows["averaged"][0] == 1.0
    assert np.all(rows["averaged"][1:] > rows["raw"][1:])
    ambient = models.horns_rev_rows("M-1, ambient k_w", "matched", 2.0, (270.0,))
    assert ambient["raw"][1] == pytest.approx(rows["raw"][1], rel=1e-12)
    assert np.all(ambient["raw"][2:] < rows["raw"][2:])


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

ROWS_BASELINE = {  # model: (raw, averaged) P_i/P_1 at 270 deg, 2-degree samples, matched
    "M-1": (
        [1.0, 0.4023908302179945, 0.5199334433415267, 0.5662357489046164, 0.5855475981520666,
         0.5943019764722411, 0.5986155676898216, 0.6009034141443516, 0.6021943805504248,
         0.6029608440950018],
        [1.0, 0.5482485797770484, 0.6453710569672123, 0.670966809035689, 0.6809189952228341,
         0.6855098040476797, 0.6883066797193546, 0.6915419123775938, 0.6954882697301494,
         0.6995713460022192]),
    "M-1, ambient k_w": (
        [1.0, 0.4023908302179945, 0.3496906282999505, 0.32983593646776643, 0.3206140030583172,
         0.3157523551932397, 0.31295146919395844, 0.3112267321114447, 0.3101079052197579,
         0.3093510535772909],
        [1.0, 0.5482485797770484, 0.5226018387607626, 0.5195759220475451, 0.5224346940146325,
         0.5261174087871933, 0.5298766469518572, 0.5340139928206789, 0.5387426475945103,
         0.5440306528008596]),
    "GCH": (
        [1.0, 0.35462281638985854, 0.5297319367945017, 0.5902614740072087, 0.6124117467566874,
         0.6218889184761228, 0.6264837498517564, 0.6289831301349558, 0.6304887108297904,
         0.6314806302615903],
        [1.0, 0.5149043820206376, 0.6539514610241016, 0.6856149147713543, 0.6966752530878672,
         0.7018387301348098, 0.705120937488022, 0.7088226316075775, 0.7130953036153481,
         0.7172009171534495]),
}

EFFICIENCY_BASELINE = {  # farm efficiency at 222, 270, 312 deg, matched
    "M-1": [0.6994275759731423, 0.6073084234115745, 0.7289533050752394],
    "GCH": [0.7146960643492307, 0.6226137519886916, 0.7484765886172086],
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


def test_regression_horns_rev_rows():
    """P_i/P_1 along the inner rows, raw and averaged over the direction uncertainty; the error
    measure is the RMSE over rows 2-10 against the measured means."""
    rows = validate.horns_rev(models=tuple(ROWS_BASELINE), readings=("matched",),
                              sample_step=2.0, directions=(270.0,))
    for model, (raw, averaged) in ROWS_BASELINE.items():
        np.testing.assert_allclose(rows[("matched", model)]["raw"], raw, rtol=RTOL)
        np.testing.assert_allclose(rows[("matched", model)]["averaged"], averaged, rtol=RTOL)
    measured = cases.HORNS_REV.measured_rows[1:, 1]
    expected = np.sqrt(np.mean((np.array(averaged[1:]) - measured) ** 2))
    assert metrics.row_errors(np.array(averaged))[0] == pytest.approx(expected, rel=1e-12)


def test_regression_farm_efficiency():
    """Farm power over 80 unwaked turbines at three directions (aligned rows at 270 deg give
    the deepest losses); the efficiency is below 1 and FLORIS's no-wake run is its reference."""
    directions = np.array([222.0, 270.0, 312.0])
    effs = validate.efficiency(models=tuple(EFFICIENCY_BASELINE), readings=("matched",),
                               directions=directions)
    for model, expected in EFFICIENCY_BASELINE.items():
        np.testing.assert_allclose(effs[("matched", model)], expected, rtol=RTOL)
        assert np.argmin(effs[("matched", model)]) == 1


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
    text = (Path(__file__).resolve().parents[1] / "docs" / "validation.md").read_text()
    assert validate.atmosphere_table() in text
    rans = cases.HORNS_REV.rans_rows
    cells = [validate._cell(*metrics.row_errors(rans[:, col])) for _ in range(2) for col in (2, 1)]
    assert "| EllipSys3D RANS (published) | " + " | ".join(cells) + " |" in text
