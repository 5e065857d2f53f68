"""Tests of the actuator-disk operation model (floris_ekman_veer.plugin.rotor.turbine).

Hand numbers: the paper's LES disk, C_T' = 1.33, D = z_h = 100 m, rho = 1.225 kg/m^3.
"""

import math
import shutil
from pathlib import Path

import floris
import numpy as np
import pytest
from floris import FlorisModel
from floris.core.turbine import turbine as floris_turbine
from floris.utilities import load_yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from floris_ekman_veer import registry
from floris_ekman_veer.plugin.rotor import turbine as adt

REPO = Path(__file__).resolve().parents[3]
TURBINE_YAML = REPO / "inputs" / "turbines" / "actuator_disk_les.yaml"

CT_PRIME = 1.33
RHO = 1.225
RADIUS = 50.0
A0 = 1.33 / 5.33  # a = C_T'/(4 + C_T')
CT0 = 4 * A0 * (1 - A0)  # 0.7491
COS20 = math.cos(math.radians(20.0))
A20 = 1.33 * COS20**2 / (4 + 1.33 * COS20**2)
CT20 = 16 * 1.33 / (4 + 1.33 * COS20**2) ** 2  # 0.7948, docs/conventions.md#thrust-coefficient-and-yaw


def hand_power(u, a=A0, cos_yaw=1.0, rho=RHO):
    """1/2 rho pi R^2 C_T' ((1 - a) U cos beta)^3, Eq. (P0_ref) (beta = 0) in watts."""
    return 0.5 * rho * math.pi * RADIUS**2 * CT_PRIME * ((1 - a) * u * cos_yaw) ** 3


@pytest.fixture(autouse=True, scope="module")
def _registered():
    registry.register_operation_model()


def table():
    return adt.actuator_disk_power_thrust_table(CT_PRIME, 2 * RADIUS, RHO)


def uniform(u, n_findex=1, n_turbines=1, n_grid=3):
    return np.full((n_findex, n_turbines, n_grid, n_grid), float(u))


def call(method, u=10.0, yaw=0.0, **kwargs):
    velocities = uniform(u)
    kwargs.setdefault("power_thrust_table", table())
    return getattr(adt.ActuatorDiskTurbine, method)(
        velocities=velocities,
        air_density=RHO,
        yaw_angles=np.full(velocities.shape[:2], yaw),
        tilt_angles=np.zeros(velocities.shape[:2]),
        tilt_interp=None,
        **kwargs,
    )


def floris_model(n_turbines=1, wake="none", wind_speeds=(8.0, 10.0), turbine=None, shear=0.0):
    config = FlorisModel.get_defaults()
    if wake == "none":
        # FLORIS's "none" deflection refuses yaw; gauss deflection is harmless without a deficit.
        config["wake"]["model_strings"].update(velocity_model="none", turbulence_model="none")
        config["wake"]["enable_secondary_steering"] = False
    config["farm"].update(
        layout_x=[0.0, 700.0][:n_turbines],
        layout_y=[0.0] * n_turbines,
        turbine_type=[turbine or adt.actuator_disk_turbine()],
    )
    config["flow_field"].update(
        wind_shear=shear,
        reference_wind_height=100.0,
        wind_speeds=list(wind_speeds),
        wind_directions=[270.0] * len(wind_speeds),
        turbulence_intensities=[0.06] * len(wind_speeds),
    )
    return FlorisModel(config)


# --- the un-yawed disk -------------------------------------------------------------------------


def test_unyawed_thrust_coefficient_is_0_7491():
    assert CT0 == pytest.approx(0.7491, abs=5e-5)
    assert adt.disk_thrust_coefficient(CT_PRIME) == pytest.approx(CT0, rel=1e-14)
    np.testing.assert_allclose(call("thrust_coefficient"), [[CT0]], rtol=1e-14)


def test_axial_induction():
    assert A0 == pytest.approx(0.249531, abs=1e-6)
    np.testing.assert_allclose(call("axial_induction"), [[A0]], rtol=1e-14)
    # Eq. (ind_factor) of the paper from the disk's C_T gives the same a.
    assert 0.5 * (1 - math.sqrt(1 - CT0)) == pytest.approx(A0, rel=1e-12)


@pytest.mark.parametrize("u", [4.0, 8.0, 10.0, 12.5])
def test_power_is_eq_p0_ref(u):
    np.testing.assert_allclose(call("power", u=u), [[hand_power(u)]], rtol=1e-12)


def test_power_at_10_m_s_number():
    # 0.5 * 1.225 * pi * 50^2 * 1.33 * (10 * 4/5.33)^3 W
    assert hand_power(10.0) == pytest.approx(2.7042445e6, rel=1e-7)


def test_thrust_is_half_rho_a_ct_prime_ud_squared():
    u = 9.0
    ct = call("thrust_coefficient", u=u)[0, 0]
    thrust = 0.5 * RHO * math.pi * RADIUS**2 * ct * u**2
    assert thrust == pytest.approx(0.5 * RHO * math.pi * RADIUS**2 * CT_PRIME * ((1 - A0) * u) ** 2)


def test_power_uses_plain_disk_average_not_cubic_mean():
    # Eq. (Ud): U_d = (1 - a) <u>, with <u> the plain area average over the rotor points.
    rng = np.random.default_rng(1)
    velocities = 8.0 + 2.0 * rng.random((2, 3, 4, 4))
    kw = dict(
        power_thrust_table=table(),
        velocities=velocities,
        air_density=RHO,
        yaw_angles=np.zeros((2, 3)),
        tilt_angles=np.zeros((2, 3)),
        tilt_interp=None,
    )
    power = adt.ActuatorDiskTurbine.power(average_method="cubic-mean", **kw)
    expected = hand_power(velocities.mean(axis=(2, 3)))
    np.testing.assert_allclose(power, expected, rtol=1e-12)
    assert power.shape == (2, 3)
    assert adt.ActuatorDiskTurbine.thrust_coefficient(**kw).shape == (2, 3)
    assert adt.ActuatorDiskTurbine.axial_induction(**kw).shape == (2, 3)


def test_cubature_weights_are_kept():
    velocities = np.array([[[[6.0, 9.0, 12.0]]]])
    weights = np.array([1.0, 2.0, 1.0])
    power = adt.ActuatorDiskTurbine.power(
        power_thrust_table=table(),
        velocities=velocities,
        air_density=RHO,
        yaw_angles=np.zeros((1, 1)),
        average_method="cubic-cubature",
        cubature_weights=weights,
    )
    assert power[0, 0] == pytest.approx(hand_power(9.0), rel=1e-12)


def test_power_scales_with_flow_air_density():
    p1 = call("power", u=10.0)
    p2 = adt.ActuatorDiskTurbine.power(
        power_thrust_table=table(), velocities=uniform(10.0), air_density=1.0, yaw_angles=[[0.0]]
    )
    np.testing.assert_allclose(p2, p1 / RHO, rtol=1e-12)


# --- yaw ----------------------------------------------------------------------------------------


def test_yawed_ct_i_over_cos_is_fixed_ct_prime_disk_ct():
    ct_i = call("thrust_coefficient", yaw=20.0)[0, 0]
    assert CT20 == pytest.approx(0.7948, abs=5e-5)
    assert ct_i / COS20 == pytest.approx(CT20, rel=1e-12)
    assert ct_i == pytest.approx(0.746851, abs=1e-6)
    assert call("thrust_coefficient", yaw=-20.0)[0, 0] == pytest.approx(ct_i, rel=1e-14)


def test_yawed_induction_and_power():
    assert call("axial_induction", yaw=20.0)[0, 0] == pytest.approx(A20, rel=1e-13)
    assert A20 == pytest.approx(0.226966, abs=1e-6)
    # The paper's Eq. (ind_factor) with C_T = ct_i / cos(beta) returns the same a.
    ct_i = call("thrust_coefficient", yaw=20.0)[0, 0]
    assert 0.5 * (1 - math.sqrt(1 - ct_i / COS20 * COS20**2)) == pytest.approx(A20, rel=1e-12)
    p20 = call("power", u=10.0, yaw=20.0)[0, 0]
    assert p20 == pytest.approx(hand_power(10.0, a=A20, cos_yaw=COS20), rel=1e-12)
    # Less loss than cos^3 because the induction falls under yaw at fixed C_T'.
    assert p20 / hand_power(10.0) == pytest.approx(0.906889, abs=1e-6)
    assert call("power", u=10.0, yaw=-20.0)[0, 0] == pytest.approx(p20, rel=1e-14)


@settings(max_examples=200, deadline=None)
@given(
    ct_prime=st.floats(0.05, 4.0),
    yaw=st.floats(-80.0, 80.0),
)
def test_recovered_ct_reproduces_eq_ind_factor(ct_prime, yaw):
    tab = adt.actuator_disk_power_thrust_table(ct_prime, 100.0)
    cos = math.cos(math.radians(yaw))
    ct_i = call("thrust_coefficient", yaw=yaw, power_thrust_table=tab)[0, 0]
    a = call("axial_induction", yaw=yaw, power_thrust_table=tab)[0, 0]
    ct = ct_i / cos  # what the wake model does
    assert ct == pytest.approx(16 * ct_prime / (4 + ct_prime * cos**2) ** 2, rel=1e-12)
    assert 0.5 * (1 - math.sqrt(max(0.0, 1 - ct * cos**2))) == pytest.approx(a, rel=1e-6, abs=1e-9)
    # disk-normal force balance: C_T' (1 - a)^2 cos^2 = C_T cos^2
    assert ct_prime * (1 - a) ** 2 == pytest.approx(ct, rel=1e-12)


def test_beyond_90_degrees_is_edge_on():
    assert call("thrust_coefficient", yaw=95.0)[0, 0] == 0.0
    assert call("power", yaw=95.0)[0, 0] == 0.0


# --- validation ---------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [0.0, -1.33, float("nan"), float("inf")])
def test_invalid_ct_prime_raises(bad):
    with pytest.raises(ValueError, match="ct_prime"):
        adt.actuator_disk_power_thrust_table(bad, 100.0)
    tab = table()
    tab["ct_prime"] = bad
    for method in ("power", "thrust_coefficient", "axial_induction"):
        with pytest.raises(ValueError, match="ct_prime"):
            call(method, power_thrust_table=tab)


def test_missing_ct_prime_raises():
    tab = table()
    del tab["ct_prime"]
    with pytest.raises(ValueError, match="ct_prime"):
        call("thrust_coefficient", power_thrust_table=tab)


def test_invalid_ct_prime_in_floris_model_raises_at_build():
    turbine = adt.actuator_disk_turbine()
    turbine["power_thrust_table"]["ct_prime"] = -0.5
    with pytest.raises(ValueError, match=r"farm\.turbine_type\[0\]\.power_thrust_table\.ct_prime"):
        floris_model(turbine=turbine)


@pytest.mark.parametrize("ct_prime", [3.99, 4.0])
def test_ct_prime_up_to_momentum_theory_limit_is_accepted(ct_prime):
    """C_T' = 4 is a = 1/2, the end of momentum theory (MAX_CT_PRIME): still one-to-one with C_T."""
    tab = adt.actuator_disk_power_thrust_table(ct_prime, 100.0)
    a = adt.induction_factor(ct_prime)
    assert tab["thrust_coefficient"][0] == pytest.approx(4 * a * (1 - a), rel=1e-12)
    assert a <= 0.5


def test_ct_prime_beyond_momentum_theory_raises():
    """C_T' = 40 would give a = 0.91 in the power but C_T = 4a(1 - a) = 0.33 to the wake."""
    assert adt.induction_factor(40.0) == pytest.approx(40 / 44)
    assert adt.disk_thrust_coefficient(40.0) == pytest.approx(640 / 44**2)
    with pytest.raises(ValueError, match=r"ct_prime must be in \(0, 4\]"):
        adt.actuator_disk_power_thrust_table(40.0, 100.0)


def test_stale_table_arrays_raise():
    tab = table()
    tab["ct_prime"] = 2.0  # arrays still describe 1.33
    with pytest.raises(ValueError, match="regenerate"):
        call("power", power_thrust_table=tab)
    tab = table()
    tab["rotor_diameter"] = 120.0
    with pytest.raises(ValueError, match="regenerate"):
        call("power", power_thrust_table=tab)


def test_nonzero_ref_tilt_raises():
    tab = table()
    tab["ref_tilt"] = 5.0
    with pytest.raises(ValueError, match="ref_tilt"):
        call("power", power_thrust_table=tab)


# --- registration -------------------------------------------------------------------------------


def test_registration_is_idempotent():
    operation_models = floris_turbine.TURBINE_MODEL_MAP["operation_model"]
    assert registry.register_operation_model() is adt.ActuatorDiskTurbine
    assert registry.register_operation_model() is adt.ActuatorDiskTurbine
    assert operation_models["actuator-disk"] is adt.ActuatorDiskTurbine
    assert operation_models["cosine-loss"].__name__ == "CosineLossTurbine"


def test_registration_refuses_to_overwrite_other_class(monkeypatch):
    operation_models = floris_turbine.TURBINE_MODEL_MAP["operation_model"]
    other = operation_models["cosine-loss"]
    monkeypatch.setitem(operation_models, "actuator-disk", other)
    with pytest.raises(ValueError, match="actuator-disk"):
        registry.register_operation_model()
    assert operation_models["actuator-disk"] is other


def test_registration_replaces_a_reloaded_copy_of_itself(monkeypatch):
    # importlib.reload of the module creates a new class object of the same origin.
    operation_models = floris_turbine.TURBINE_MODEL_MAP["operation_model"]
    stale = type(
        "ActuatorDiskTurbine",
        (),
        {"__module__": adt.__name__, "__qualname__": adt.ActuatorDiskTurbine.__qualname__},
    )
    monkeypatch.setitem(operation_models, "actuator-disk", stale)
    assert registry.register_operation_model() is adt.ActuatorDiskTurbine
    assert operation_models["actuator-disk"] is adt.ActuatorDiskTurbine


# --- inside FLORIS -------------------------------------------------------------------------------


def test_floris_model_single_turbine_returns_disk_numbers():
    fmodel = floris_model()
    fmodel.run()
    np.testing.assert_allclose(
        fmodel.get_turbine_powers()[:, 0], [hand_power(8.0), hand_power(10.0)], rtol=1e-10
    )
    np.testing.assert_allclose(fmodel.get_turbine_thrust_coefficients(), CT0, rtol=1e-12)
    np.testing.assert_allclose(fmodel.get_turbine_ais(), A0, rtol=1e-12)

    fmodel.set(yaw_angles=[[20.0], [20.0]])
    fmodel.run()
    np.testing.assert_allclose(
        fmodel.get_turbine_powers()[:, 0],
        [hand_power(u, a=A20, cos_yaw=COS20) for u in (8.0, 10.0)],
        rtol=1e-10,
    )
    np.testing.assert_allclose(fmodel.get_turbine_thrust_coefficients(), CT20 * COS20, rtol=1e-12)


def test_floris_model_sheared_inflow_uses_disk_average():
    fmodel = floris_model(shear=0.2)
    fmodel.run()
    u_mean = fmodel.core.flow_field.u.mean(axis=(2, 3))
    np.testing.assert_allclose(fmodel.get_turbine_powers(), hand_power(u_mean), rtol=1e-10)


def test_floris_gauss_two_turbines_runs():
    fmodel = floris_model(n_turbines=2, wake="gauss", wind_speeds=(10.0,))
    fmodel.set(yaw_angles=[[20.0, 0.0]])
    fmodel.run()
    powers = fmodel.get_turbine_powers()
    assert np.all(np.isfinite(powers))
    assert powers[0, 0] == pytest.approx(hand_power(10.0, a=A20, cos_yaw=COS20), rel=1e-10)
    assert 0.0 < powers[0, 1] < hand_power(10.0)


# --- the turbine file ----------------------------------------------------------------------------


def test_yaml_matches_the_generator():
    from_file = load_yaml(TURBINE_YAML)
    # The paper's cases reproduce the paper's cos(beta) disk (docs/yaw_steering.md).
    generated = adt.actuator_disk_turbine(veer_aware_rotor=False)
    ptt_file = from_file.pop("power_thrust_table")
    ptt_gen = generated.pop("power_thrust_table")
    assert from_file == generated
    assert from_file["rotor_diameter"] == 100.0 and from_file["hub_height"] == 100.0
    assert from_file["operation_model"] == "actuator-disk"
    assert set(ptt_file) == set(ptt_gen)
    for key, value in ptt_gen.items():
        np.testing.assert_allclose(ptt_file[key], value, rtol=1e-10, err_msg=key)
    assert ptt_file["ct_prime"] == 1.33
    assert ptt_file["rotor_diameter"] == from_file["rotor_diameter"]


def test_yaml_usable_via_include_from_floris_input(tmp_path):
    # FLORIS resolves !include relative to the including input file's directory.
    (tmp_path / "turbines").mkdir()
    shutil.copy(TURBINE_YAML, tmp_path / "turbines" / TURBINE_YAML.name)
    defaults = Path(floris.__file__).parent / "default_inputs.yaml"
    lines = defaults.read_text().splitlines()
    i = lines.index("  - nrel_5MW")
    lines[i] = "  - !include turbines/actuator_disk_les.yaml"
    (tmp_path / "case.yaml").write_text("\n".join(lines) + "\n")
    fmodel = FlorisModel(tmp_path / "case.yaml")
    fmodel.set(wind_speeds=[10.0], wind_directions=[270.0], turbulence_intensities=[0.06],
               wind_shear=0.0)
    fmodel.run()
    assert fmodel.get_turbine_powers()[0, 0] == pytest.approx(hand_power(10.0), rel=1e-10)


def test_yaml_usable_by_name_from_turbine_library_path():
    config = FlorisModel.get_defaults()
    config["farm"]["turbine_library_path"] = str(TURBINE_YAML.parent)
    config["farm"]["turbine_type"] = ["actuator_disk_les"]
    config["flow_field"].update(
        wind_speeds=[8.0], wind_directions=[270.0], turbulence_intensities=[0.06], wind_shear=0.0
    )
    fmodel = FlorisModel(config)
    fmodel.run()
    assert fmodel.get_turbine_powers()[0, 0] == pytest.approx(hand_power(8.0), rel=1e-10)

