"""The veer-aware yawed rotor (plugin/rotor/yawed_rotor.py, plugin/rotor/crossflow.py, the actuator disk
in plugin/rotor/turbine.py; docs/yaw_steering.md).

References built here, independent of the rotor cells: the disk integral of u_n = U cos b +
V sin b over a polar Gauss-Legendre quadrature (200 radii x 400 angles) of the ambient profile.
"""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest
from floris import FlorisModel
from floris.core.turbine.operation_models import CosineLossTurbine
from floris.utilities import load_yaml

import floris_ekman_veer  # noqa: F401
from floris_ekman_veer import EkmanABL
from floris_ekman_veer.plugin.floris_hooks import patching
from floris_ekman_veer.plugin.rotor import turbine as adt
from floris_ekman_veer.plugin.rotor.crossflow import CROSSFLOW, MOMENTS
from floris_ekman_veer.plugin.inflow.inflow import set_atmosphere
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning

from conftest import assert_as_plain_floris
from tests.conftest import table1_sbl6

from pathlib import Path

REPO = Path(__file__).resolve().parents[3]
FARM = REPO / "inputs" / "farm_sbl6.yaml"


def atmosphere(name):
    return load_yaml(REPO / "inputs" / f"{name}.yaml")["wake"]["wake_velocity_parameters"][
        "ekman_veer"]["atmosphere"]


def polar_disk(hub, radius, n_r=200, n_theta=400):
    """Heights and area weights (summing to 1) of a polar Gauss-Legendre disk quadrature."""
    x, w = np.polynomial.legendre.leggauss(n_r)
    r = 0.5 * (x + 1.0)
    theta = (np.arange(n_theta) + 0.5) * 2.0 * np.pi / n_theta
    weight = np.repeat((w * r)[:, None] / n_theta, n_theta, axis=1)  # int_0^1 2 r dr = 1
    return hub + radius * np.outer(r, np.sin(theta)), weight / weight.sum()


def nrel_power(fmodel):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        fmodel.run()
    return fmodel.get_turbine_powers()[:, 0]


@pytest.fixture(scope="module")
def nrel_sbl4():
    fmodel = FlorisModel(FARM)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        set_atmosphere(fmodel, atmosphere("sbl4"), layout_x=[0.0], layout_y=[0.0],
                       wind_directions=[270.0] * 3, wind_speeds=[8.0] * 3,
                       turbulence_intensities=[0.06] * 3, yaw_angles=[[20.0], [-20.0], [0.0]])
    return fmodel


def reference_nrel(yaw_deg, quantity="power"):
    """NREL 5 MW at 8 m/s (90 m) in SBL-4 from the fine disk integral of u_n."""
    table = FlorisModel(FARM).core.farm.turbine_definitions[0]["power_thrust_table"]
    p = table["cosine_loss_exponent_yaw"]
    abl = EkmanABL.from_reference_wind(8.0, 90.0, **atmosphere("sbl4"))
    z, w = polar_disk(90.0, 63.0)
    U, V = abl.hub_aligned_velocity(z, 90.0)
    b = np.radians(yaw_deg)
    normal = U * np.cos(b) + V * np.sin(b)
    if quantity == "power":
        u_eff = (np.sum(w * normal**3) * np.cos(b) ** (p - 3.0)) ** (1.0 / 3.0)
        return 1e3 * np.interp(u_eff, table["wind_speed"], table["power"])
    # Thrust: C_T at the cubic-mean speed, the rotor-normal force <u_n^2> over <U^2>.
    u_mean = np.sum(w * U**3) ** (1.0 / 3.0)
    ct = np.interp(u_mean, table["wind_speed"], table["thrust_coefficient"])
    return ct * np.sum(w * normal**2) / (np.sum(w * U**2) * np.cos(b))


def test_nrel_5mw_sbl4_asymmetry_matches_the_disk_integral(nrel_sbl4):
    powers = nrel_power(nrel_sbl4)
    plus, minus, aligned = powers
    ref_plus, ref_minus = reference_nrel(20.0), reference_nrel(-20.0)
    # The fine integral: 1179 kW at +20 deg, 1288 kW at -20 deg (9 % apart).
    assert ref_plus == pytest.approx(1179.2e3, abs=1e3)
    assert ref_minus == pytest.approx(1287.8e3, abs=1e3)
    assert plus == pytest.approx(ref_plus, rel=1e-3)
    assert minus == pytest.approx(ref_minus, rel=1e-3)
    assert plus / minus == pytest.approx(ref_plus / ref_minus, abs=2e-4)
    assert aligned == pytest.approx(reference_nrel(0.0), rel=1e-3)


def test_nrel_5mw_thrust_sees_the_normal_momentum_flux(nrel_sbl4):
    nrel_power(nrel_sbl4)
    ct = nrel_sbl4.get_turbine_thrust_coefficients()[:, 0]
    for value, yaw in zip(ct, (20.0, -20.0)):
        assert value == pytest.approx(reference_nrel(yaw, "thrust"), rel=2e-3)
    assert ct[1] > ct[0] * 1.03  # the rotor facing the veered wind carries more thrust
    # The induction FLORIS derives from ct_i follows it.
    ai = nrel_sbl4.get_turbine_ais()[:, 0]
    assert ai[1] > ai[0]


def _lookup(moments):
    return lambda table, shape: moments


def _cosine_loss_call(method, velocities, yaw):
    """(the package's cosine-loss method, FLORIS's own) on the same inputs."""
    from floris.core.turbine.turbine import Turbine

    turbine = Turbine.from_dict(FlorisModel(FARM).core.farm.turbine_definitions[0])
    kwargs = dict(power_thrust_table=turbine.power_thrust_table, velocities=velocities,
                  air_density=1.225, yaw_angles=yaw, tilt_angles=np.zeros_like(yaw),
                  tilt_interp=None, average_method="cubic-mean", cubature_weights=None,
                  correct_cp_ct_for_tilt=np.zeros_like(yaw, dtype=bool))
    # FLORIS's axial induction calls the (patched) thrust coefficient: it has no original.
    original = patching.ORIGINALS.get((CosineLossTurbine, method), getattr(CosineLossTurbine,
                                                                          method))
    return getattr(CosineLossTurbine, method)(**kwargs), original(**kwargs)


@pytest.mark.parametrize("method", ["power", "thrust_coefficient", "axial_induction"])
def test_no_crossflow_is_floris_bitwise(method):
    rng = np.random.default_rng(3)
    velocities = rng.uniform(4.0, 14.0, (5, 2, 3, 3))
    yaw = rng.uniform(-30.0, 30.0, (5, 2))
    zero = {name: np.zeros((5, 1, 3, 3)) for name in MOMENTS}
    zero["U3"] = zero["U1"] = np.full((5, 1, 3, 3), 8.0)
    veered = {name: np.full((5, 1, 3, 3), 1.5) for name in MOMENTS}
    veered["U3"] = veered["U1"] = np.full((5, 1, 3, 3), 8.0)
    ours, floris_own = _cosine_loss_call(method, velocities, yaw)  # no context
    np.testing.assert_array_equal(ours, floris_own)
    token = CROSSFLOW.set(_lookup(zero))
    try:
        with_zero_v, _ = _cosine_loss_call(method, velocities, yaw)
    finally:
        CROSSFLOW.reset(token)
    token = CROSSFLOW.set(_lookup(veered))
    try:
        veered_yaw0, _ = _cosine_loss_call(method, velocities, np.zeros_like(yaw))
        veered_yawed, _ = _cosine_loss_call(method, velocities, yaw)
    finally:
        CROSSFLOW.reset(token)
    unyawed, _ = _cosine_loss_call(method, velocities, np.zeros_like(yaw))
    np.testing.assert_array_equal(with_zero_v, floris_own)  # V = 0: exactly FLORIS
    np.testing.assert_array_equal(veered_yaw0, unyawed)  # beta = 0: exactly today's
    # A uniform V > 0 helps the rotor yawed towards it (beta > 0) and hurts the other sign.
    helped = np.sign(yaw) * (veered_yawed - floris_own)
    assert np.all(helped[np.abs(yaw) > 1.0] > 0.0)


def test_shared_thrust_is_computed_once_per_arguments(monkeypatch):
    """Inside ``sharing_thrust`` (one step of the rotor solver) FLORIS's axial induction reuses
    the veer-aware thrust coefficient computed for the same arguments: the same bits as
    without sharing, one thrust computation per distinct arguments."""
    from floris.core.turbine.turbine import Turbine

    from floris_ekman_veer.plugin.rotor import yawed_rotor

    rng = np.random.default_rng(4)
    velocities = rng.uniform(4.0, 14.0, (5, 1, 3, 3))
    yaw = rng.uniform(-30.0, 30.0, (5, 1))
    veered = {name: np.full((5, 1, 3, 3), 1.5) for name in MOMENTS}
    veered["U3"] = veered["U1"] = np.full((5, 1, 3, 3), 8.0)
    table = Turbine.from_dict(FlorisModel(FARM).core.farm.turbine_definitions[0]
                              ).power_thrust_table

    def call(method, velocities, yaw):
        # New arrays of equal values each call, as FLORIS's per-turbine selection makes them.
        return getattr(CosineLossTurbine, method)(
            power_thrust_table=table, velocities=velocities.copy(), air_density=1.225,
            yaw_angles=yaw.copy(), tilt_angles=np.zeros_like(yaw), tilt_interp=None,
            average_method="cubic-mean", cubature_weights=None,
            correct_cp_ct_for_tilt=np.zeros_like(yaw, dtype=bool))

    calls = []
    computed = yawed_rotor.thrust_veer_ratio
    monkeypatch.setattr(yawed_rotor, "thrust_veer_ratio",
                        lambda *a, **k: calls.append(1) or computed(*a, **k))
    token = CROSSFLOW.set(_lookup(veered))
    try:
        alone = [call(m, velocities, yaw) for m in ("thrust_coefficient", "axial_induction")]
        assert len(calls) == 2
        with yawed_rotor.sharing_thrust():
            thrust = call("thrust_coefficient", velocities, yaw)
            induction = call("axial_induction", velocities, yaw)
            assert len(calls) == 3
            other = call("thrust_coefficient", velocities, -yaw)
            assert len(calls) == 4
        # Outside the context nothing is shared.
        again = call("thrust_coefficient", velocities, yaw)
        assert len(calls) == 5
    finally:
        CROSSFLOW.reset(token)
    np.testing.assert_array_equal(thrust, alone[0])
    np.testing.assert_array_equal(induction, alone[1])
    np.testing.assert_array_equal(again, alone[0])
    assert not np.array_equal(other, thrust)


def test_table_interpolant_is_built_once_per_solve(monkeypatch):
    """FLORIS's cosine-loss turbines build scipy's interpolant of their table at every call;
    inside ``sharing_interpolants`` (the package's solver) one is built per table and settings:
    the same object for the same arrays and settings, another for other ones, scipy's own call
    outside; a farm's solve builds the thrust interpolant once and gives the same bits as
    with one per step."""
    from floris.core.turbine import operation_models

    from floris_ekman_veer.plugin.rotor import yawed_rotor

    wind_speed, thrust = np.array([3.0, 10.0, 25.0]), np.array([0.9, 0.8, 0.1])
    with yawed_rotor.sharing_interpolants():
        first = operation_models.interp1d(wind_speed, thrust, fill_value=0.0001,
                                          bounds_error=False)
        assert operation_models.interp1d(wind_speed, thrust, fill_value=0.0001,
                                         bounds_error=False) is first
        assert operation_models.interp1d(wind_speed, thrust.copy(), fill_value=0.0001,
                                         bounds_error=False) is not first
        assert operation_models.interp1d(wind_speed, thrust, fill_value=0.5,
                                         bounds_error=False) is not first
    assert operation_models.interp1d(wind_speed, thrust, fill_value=0.0001,
                                     bounds_error=False) is not first
    np.testing.assert_allclose(first([5.0, 30.0]), [0.9 - 0.1 * 2.0 / 7.0, 0.0001], rtol=1e-15)

    scipy_own = patching.ORIGINALS[(operation_models, "interp1d")]
    built = []
    counting = yawed_rotor.sharing_interpolant(
        lambda *a, **k: built.append(1) or scipy_own(*a, **k))
    config = copy.deepcopy(load_yaml(FARM))
    config["farm"]["layout_x"], config["farm"]["layout_y"] = [0.0, 630.0, 1260.0], [0.0] * 3
    powers = []
    for interpolant in (counting, lambda *a, **k: built.append(1) or scipy_own(*a, **k)):
        monkeypatch.setattr(operation_models, "interp1d", interpolant)
        built.clear()
        model = FlorisModel(config)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model.set(wind_directions=[270.0, 275.0], wind_speeds=[8.0, 9.0],
                      turbulence_intensities=[0.06, 0.06], yaw_angles=[[20.0, -10.0, 0.0]] * 2)
            model.run()
        solve_builds = len(built)
        powers.append(model.get_turbine_powers())
        # Shared: the thrust's interpolant once per solve; unshared: once per turbine's step.
        assert solve_builds == (1 if interpolant is counting else 3)
    np.testing.assert_array_equal(powers[0], powers[1])


def test_veer_at_zero_yaw_is_floris_bitwise(nrel_sbl4):
    """beta = 0 with a veered inflow: the power FLORIS's own cosine-loss model gives."""
    model = nrel_sbl4.copy()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        model.set(yaw_angles=np.zeros((3, 1)))
        model.run()
    ours = model.get_turbine_powers()
    token = CROSSFLOW.set(None)
    try:
        plain = model.core.farm.turbine_map[0]
        floris_own = patching.ORIGINALS[(CosineLossTurbine, "power")](
            power_thrust_table=plain.power_thrust_table, velocities=model.core.flow_field.u,
            air_density=1.225, yaw_angles=np.zeros((3, 1)),
            tilt_angles=model.core.farm.tilt_angles,
            tilt_interp=model.core.farm.turbine_tilt_interps["nrel_5MW"],
            average_method="cubic-mean", cubature_weights=None,
            correct_cp_ct_for_tilt=model.core.farm.correct_cp_ct_for_tilt)
    finally:
        CROSSFLOW.reset(token)
    np.testing.assert_array_equal(ours, floris_own)


def test_unconfigured_yawed_farm_is_bitwise_floris():
    """Without an atmosphere, a yawed FLORIS farm is bitwise what FLORIS gives alone."""
    config = copy.deepcopy(load_yaml(FARM))
    del config["wake"]["wake_velocity_parameters"]["ekman_veer"]
    config["wake"]["model_strings"].update(velocity_model="gauss", deflection_model="gauss")
    config["wake"]["enable_secondary_steering"] = True

    def outputs():
        fmodel = FlorisModel(copy.deepcopy(config))
        fmodel.set(wind_directions=[270.0, 275.0], wind_speeds=[8.0, 8.0],
                   turbulence_intensities=[0.06, 0.06], yaw_angles=np.full((2, 9), 15.0))
        fmodel.run()
        return (fmodel.get_turbine_powers(), fmodel.get_turbine_thrust_coefficients(),
                fmodel.get_turbine_ais())

    assert_as_plain_floris(outputs)


# --------------------------------------------------------------------------------- the disk
def disk_model(yaws, name="sbl6", veer_aware=True):
    """The paper's case input with the LES disk, veer-aware (the package's default) or as the
    paper's cases ship it (cos beta)."""
    fmodel = FlorisModel(REPO / "inputs" / f"{name}.yaml")
    speed = fmodel.core.flow_field.wind_speeds[0]
    n = len(yaws)
    fmodel.set(wind_directions=[270.0] * n, wind_speeds=[speed] * n,
               turbulence_intensities=[0.05] * n, yaw_angles=np.array(yaws, float)[:, None],
               turbine_type=[adt.actuator_disk_turbine(veer_aware_rotor=veer_aware)])
    return fmodel, speed


def reference_disk(yaw_deg, speed, name="sbl6"):
    """1/2 rho A C_T' ((1 - a(gamma)) <U> gamma)^3, gamma = cos b + sin b <V>/<U>."""
    abl = EkmanABL.from_reference_wind(speed, 100.0, **atmosphere(name))
    z, w = polar_disk(100.0, 50.0)
    U, V = abl.hub_aligned_velocity(z, 100.0)
    b = np.radians(yaw_deg)
    gamma = np.cos(b) + np.sin(b) * np.sum(w * V) / np.sum(w * U)
    a = 1.33 * gamma**2 / (4.0 + 1.33 * gamma**2)
    return 0.5 * 1.225 * np.pi * 50.0**2 * 1.33 * ((1 - a) * np.sum(w * U) * gamma) ** 3


def test_actuator_disk_sbl6_asymmetry_matches_the_disk_integral():
    fmodel, speed = disk_model([20.0, -20.0, 0.0])
    plus, minus, aligned = nrel_power(fmodel)
    ref = [reference_disk(b, speed) for b in (20.0, -20.0, 0.0)]
    assert plus == pytest.approx(ref[0], rel=1e-3)
    assert minus == pytest.approx(ref[1], rel=1e-3)
    assert plus / minus == pytest.approx(ref[0] / ref[1], abs=2e-4)
    assert plus / minus < 0.995  # the disk-mean V is small: a 1 % asymmetry
    # beta = 0: the plain disk mean, exactly the un-yawed formula.
    assert aligned == pytest.approx(ref[2], rel=1e-3)


def test_actuator_disk_thrust_and_induction_follow_gamma():
    fmodel, speed = disk_model([20.0, -20.0])
    nrel_power(fmodel)
    ct = fmodel.get_turbine_thrust_coefficients()[:, 0]
    ai = fmodel.get_turbine_ais()[:, 0]
    abl = EkmanABL.from_reference_wind(speed, 100.0, **atmosphere("sbl6"))
    z, w = polar_disk(100.0, 50.0)
    U, V = abl.hub_aligned_velocity(z, 100.0)
    for value, induction, yaw in zip(ct, ai, (20.0, -20.0)):
        b = np.radians(yaw)
        gamma = np.cos(b) + np.sin(b) * np.sum(w * V) / np.sum(w * U)
        a = 1.33 * gamma**2 / (4.0 + 1.33 * gamma**2)
        assert induction == pytest.approx(a, rel=1e-3)
        # ct_i cos(b) is the rotor-normal loading 4a(1 - a) (relative to <U>^2).
        assert value * np.cos(b) == pytest.approx(4.0 * a * (1.0 - a), rel=2e-3)


def test_paper_cases_ship_the_cos_beta_disk():
    """inputs/turbines/actuator_disk_les.yaml switches the veer-aware rotor off: the paper's
    cases give the paper's formulas; the default disk gives the veer-aware power."""
    shipped = FlorisModel(REPO / "inputs" / "sbl6.yaml")
    assert not shipped.core.farm.turbine_definitions[0]["power_thrust_table"]["veer_aware_rotor"]
    speed = shipped.core.flow_field.wind_speeds[0]
    shipped.set(wind_directions=[270.0] * 2, wind_speeds=[speed] * 2,
                turbulence_intensities=[0.05] * 2, yaw_angles=[[20.0], [-20.0]])
    plain = nrel_power(shipped)
    assert plain[0] == plain[1]  # the cosine law is symmetric
    veer_aware = nrel_power(disk_model([20.0, -20.0])[0])
    assert veer_aware[0] < veer_aware[1]


def test_actuator_disk_without_veer_is_todays_formula_bitwise():
    velocities = np.full((2, 1, 3, 3), 9.0)
    yaw = np.array([[20.0], [-15.0]])
    table = adt.actuator_disk_power_thrust_table(1.33, 100.0)
    zero = {name: np.zeros((2, 1, 3, 3)) for name in MOMENTS}
    token = CROSSFLOW.set(_lookup(zero))
    try:
        power = adt.ActuatorDiskTurbine.power(table, velocities, 1.225, yaw)
        ct = adt.ActuatorDiskTurbine.thrust_coefficient(table, velocities, yaw)
        ai = adt.ActuatorDiskTurbine.axial_induction(table, velocities, yaw)
    finally:
        CROSSFLOW.reset(token)
    c = np.cos(np.radians(yaw))
    a = adt.induction_factor(1.33, yaw)
    np.testing.assert_array_equal(
        power, 0.5 * 1.225 * (np.pi * 100.0**2 / 4.0) * 1.33 * ((1.0 - a) * 9.0 * c) ** 3)
    np.testing.assert_array_equal(ct, adt.disk_thrust_coefficient(1.33, yaw) * c)
    np.testing.assert_array_equal(ai, a)


def test_actuator_disk_honours_disable_turbines_and_refuses_derating():
    fmodel = FlorisModel(REPO / "inputs" / "sbl4.yaml")
    fmodel.set(layout_x=[0.0, 500.0], layout_y=[0.0, 0.0])
    fmodel.run()
    both = fmodel.get_turbine_powers()[0]
    fmodel.set(disable_turbines=[[True, False]])
    fmodel.run()
    disabled = fmodel.get_turbine_powers()[0]
    assert disabled[0] == 0.0
    assert fmodel.get_turbine_thrust_coefficients()[0, 0] == 0.0
    # The front disk switched off: the back one stands in the undisturbed inflow.
    assert disabled[1] > 1.3 * both[1]
    fmodel.set(disable_turbines=[[False, False]], power_setpoints=[[2e6, None]])
    with pytest.raises(ValueError, match=r"power_setpoints: the actuator-disk turbine .* "
                                         r"cannot be derated; got 2e\+06 W at \(condition, "
                                         r"turbine\) \(0, 0\)"):
        fmodel.run()


def test_each_turbine_type_sees_its_own_rotor_layer():
    """Two turbine types of different hub heights side by side (not waked): each yawed rotor
    gives the power it gives alone. (FLORIS refuses one turbine_type name with two definitions,
    so a type has one hub height and diameter: the V cells are per type.)"""
    base = FlorisModel(FARM)
    low = copy.deepcopy(base.core.farm.turbine_definitions[0])
    high = {**copy.deepcopy(low), "turbine_type": "nrel_5MW_120m", "hub_height": 120.0}
    settings = dict(wind_directions=[270.0, 270.0], wind_speeds=[9.0, 9.0],
                    turbulence_intensities=[0.06, 0.06])

    def powers(types, layout_y, yaw):
        fmodel = base.copy()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
            set_atmosphere(fmodel, atmosphere("sbl4"), layout_x=[0.0] * len(types),
                           layout_y=layout_y, turbine_type=types, yaw_angles=yaw,
                           reference_wind_height=90.0, **settings)
            fmodel.run()
        return fmodel.get_turbine_powers()

    together = powers([low, high], [0.0, 2000.0], [[20.0, -20.0], [-20.0, 20.0]])
    alone_low = powers([low], [0.0], [[20.0], [-20.0]])[:, 0]
    alone_high = powers([high], [0.0], [[-20.0], [20.0]])[:, 0]
    np.testing.assert_allclose(together[:, 0], alone_low, rtol=1e-12)
    np.testing.assert_allclose(together[:, 1], alone_high, rtol=1e-12)
    assert alone_low[0] != pytest.approx(alone_low[1], rel=1e-2)
    with pytest.raises(ValueError, match="Two different turbine definitions have the same name"):
        powers([low, {**low, "hub_height": 120.0}], [0.0, 2000.0], [[0.0, 0.0]] * 2)


# ----------------------------------------------------------------- flow fields and turbines
@pytest.mark.parametrize("veer", [True, False], ids=["M-1", "M-2"])
@pytest.mark.parametrize("yaw", [20.0, -20.0])
@pytest.mark.parametrize("wind_direction", [270.0, 275.0])
def test_flow_field_carries_the_veer_aware_thrust(veer, yaw, wind_direction):
    """FLORIS's full-flow solve (sample_flow_at_points, planes) runs the same veer-aware rotor
    as the turbine solve: the rotor average of an NREL 5 MW 7 D behind a front yawed by +-20 deg
    (SBL-6, 9 m/s) equals, in power (the cube of FLORIS's cubic mean), the disk integral of the
    front's wake sampled with sample_flow_at_points (polar Gauss quadrature, 48 x 96) to 0.2 %.
    Before the full-flow solve ran the veer-aware rotor: 1.0 % (M-2, 270 deg) and 2.2 %
    (M-2, 275 deg), since its wake carried the cosine law's C_T."""
    config = table1_sbl6(FARM)  # Table 1's SBL-6 state: h = 125 m, above the hub
    config["wake"]["wake_deflection_parameters"]["ekman_veer"]["veer"] = veer
    D, hub = 126.0, 90.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        fmodel = FlorisModel(config)
        fmodel.set(layout_x=[0.0, 7 * D], layout_y=[0.0, 0.0], wind_directions=[wind_direction],
                   wind_speeds=[9.0], turbulence_intensities=[0.06], yaw_angles=[[yaw, 0.0]])
        fmodel.run()
        rotor = fmodel.turbine_average_velocities[0, 1] ** 3
        fmodel.set(layout_x=[0.0], layout_y=[0.0], yaw_angles=[[yaw]])
        z, w = polar_disk(hub, D / 2, n_r=48, n_theta=96)
        # The second rotor faces the wind: its plane is normal to the wind direction.
        wd = np.radians(wind_direction)
        x0, y0 = 7 * D, 0.0
        r = np.polynomial.legendre.leggauss(48)[0] * 0.5 + 0.5
        theta = (np.arange(96) + 0.5) * 2.0 * np.pi / 96
        across = (D / 2) * np.outer(r, np.cos(theta))
        # Flow direction (-sin wd, -cos wd); the rotor's lateral axis is normal to it.
        x = x0 + across * np.cos(wd)
        y = y0 - across * np.sin(wd)
        sampled = fmodel.sample_flow_at_points(x.ravel(), y.ravel(), z.ravel())[0]
    disk = np.sum(w.ravel() * sampled**3)
    assert rotor == pytest.approx(disk, rel=2e-3)


def test_cubature_crossflow_grows_with_the_points():
    """The ambient moments at a cubature grid's points are the point values themselves, in
    memory proportional to the points: 9,216 points (a 96 x 96 polar-size grid) and 4
    conditions stay within a few MB (an identity membership matrix, (n_findex, N, N), was
    680 MB per condition)."""
    import tracemalloc

    from floris_ekman_veer.plugin.rotor.yawed_rotor import _cells_crossflow

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        fmodel = FlorisModel(FARM)
        fmodel.set(layout_x=[0.0], layout_y=[0.0], solver_settings={
            "type": "turbine_cubature_grid", "turbine_grid_points": 3})
    grid = fmodel.core.grid
    n_points, n_findex = 9216, 4
    z = np.linspace(30.0, 150.0, n_points).reshape(1, 1, n_points, 1)
    grid.z_sorted, grid.sorted_indices = z, np.zeros((1, 1, n_points, 1), dtype=int)
    abl = EkmanABL.from_reference_wind(np.full((n_findex, 1, 1, 1), 9.0), 90.0,
                                       **atmosphere("sbl6"))
    tracemalloc.start()
    try:
        moments = _cells_crossflow(abl, 90.0, 90.0, 126.0, 0, (n_findex, 1, n_points, 1), grid)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 30 * n_findex * n_points * 8 * len(MOMENTS)  # ~9 MB, not N^2 (2.7 GB)
    U, V = abl.hub_aligned_velocity(z.reshape(-1), 90.0)
    np.testing.assert_allclose(moments["U1"][0, 0, :, 0], U[0, 0, 0] if U.ndim > 1 else U,
                               rtol=1e-12)
    np.testing.assert_allclose(moments["UV"][-1].ravel(), np.ravel(U * V)[-n_points:],
                               rtol=1e-12, atol=1e-15)
