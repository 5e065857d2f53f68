"""The examples' computations at reduced resolution (no figures): what each figure shows.

examples/abl_profiles.py (profiles, turbulence), examples/paper_cases.py (C(x), x0, wake planes)
and examples/paper_power.py (P/P0 of Eq. P_ratio through FLORIS, checked against a direct disk
integration), for the paper's cases (Narasimhan, Gayme & Meneveau, JRSE 2025, Table 1).
"""


import numpy as np
import pytest
from floris import FlorisModel
from floris.utilities import load_yaml

import abl_profiles  # examples/ is on pytest's pythonpath (pyproject.toml)
import paper_cases
import paper_power
from paper_cases import Case

D = 100.0
STABLE = ("SBL-4", "SBL-5", "SBL-6")


# The paper's case inputs keep FLORIS's turbulence_intensities, which the ekman_veer model does not
# read (it takes I_u from the atmosphere): the ModelSettingsWarning saying so is tested in
# tests/plugin/wake_models/test_floris_input_messages.py, not here.
pytestmark = pytest.mark.filterwarnings(
    "ignore:flow_field.turbulence_intensities:floris_ekman_veer.ModelSettingsWarning")


@pytest.fixture(scope="module")
def cases():
    return {name: Case(name) for name in paper_cases.CASE_FILES}


def test_abl_table_trends(cases):
    """Table 1's trends: cooling lowers h, u* and I_u(z_h) and turns the rotor-layer veer from
    nil (CNBL: -0.6 deg) to 22.5 deg (SBL-6); k_w is Eq. (kw_CNBL_SBL_model) of I_u(z_h)."""
    table = abl_profiles.case_table(cases)
    rows = [table[name] for name in paper_cases.CASE_FILES]
    for key in ("h", "u*", "I_u", "k_w"):
        assert all(a[key] > b[key] for a, b in zip(rows, rows[1:])), key
    assert all(a["veer"] < b["veer"] for a, b in zip(rows[1:], rows[2:]))
    assert abs(table["CNBL"]["veer"]) < 1.0 and table["SBL-6"]["veer"] == pytest.approx(22.48, abs=0.01)
    for row in rows:
        assert row["k_w"] == pytest.approx((0.021**6 + (0.33 * row["I_u"]) ** 6) ** (1 / 6),
                                           rel=1e-12)
    for name, case in cases.items():  # the file's wind gives back G = 15 m/s
        assert case.abl.geostrophic_wind == pytest.approx(15.0, rel=1e-9), name


def test_profiles_are_in_the_hub_height_frame(cases):
    """The profile figure's curves: V = 0 and no direction change at z_h, the speed |(U, V)|;
    above h the geostrophic wind G = 15 m/s, turned by the veer from z_h to h (more in SBL-6)."""
    turn = {}
    for name in ("CNBL", "SBL-6"):
        case = cases[name]
        h = float(case.abl.boundary_layer_height)
        u, v, speed, direction = abl_profiles.profiles(case, [case.hub_height, 1.05 * h])
        assert abs(v[0]) < 1e-12 and abs(direction[0]) < 1e-9
        assert speed[0] == pytest.approx(case.hub_speed, rel=1e-12)
        assert speed[1] == pytest.approx(15.0, rel=1e-9)
        np.testing.assert_allclose(speed, np.hypot(u, v))
        turn[name] = direction[1]
    assert 0.0 < turn["CNBL"] < turn["SBL-6"]


def test_potential_core_grows_with_stability_and_c_matches_floris(cases):
    """x0 (Eq. x0_transition) orders CNBL < SBL-4 < SBL-5 < SBL-6 (the paper: about 3 D to 5 D),
    and the largest deficit sampled through FLORIS is C(x) of Eq. (Cx)."""
    x0 = [paper_cases.cx_curve(cases[name], 0.0, [1.0])[1] for name in paper_cases.WAKE_CASES]
    assert x0 == sorted(x0) and len(set(x0)) == 4
    assert 2.5 < x0[0] < 3.5 and 4.5 < x0[-1] < 5.5
    x_d = np.array([2.0, 8.0, 12.0])
    for name in ("CNBL", "SBL-6"):
        c, _ = paper_cases.cx_curve(cases[name], 0.0, x_d)
        sampled = paper_cases.sampled_max_deficit(cases[name], 0.0, x_d, resolution=0.05)
        np.testing.assert_allclose(sampled, c, rtol=0.0, atol=1e-9)
    c_yawed, _ = paper_cases.cx_curve(cases["SBL-6"], 20.0, x_d)
    assert np.all(c_yawed < paper_cases.cx_curve(cases["SBL-6"], 0.0, x_d)[0])


def test_stable_wakes_tilt_with_veer(cases):
    """Unyawed, veer shears the wake to +y below the hub and to -y above it (the paper's SBL-4
    horizontal planes), more as the veer grows; the CNBL wake stays nearly upright."""
    heights = D + np.array([-0.25, 0.0, 0.25]) * D
    tilts = []
    for name in STABLE:
        centres, _ = paper_cases.wake_centres(cases[name], cases[name].model("M-1", 0.0), 8 * D,
                                              heights, resolution=0.02)
        assert centres[0] > 0.2 * D and abs(centres[1]) < 0.01 * D and centres[2] < -0.2 * D
        tilts.append(centres[0] - centres[2])
    assert tilts == sorted(tilts)
    centres, _ = paper_cases.wake_centres(cases["CNBL"], cases["CNBL"].model("M-1", 0.0), 8 * D,
                                          heights, resolution=0.02)
    assert abs(centres[0] - centres[2]) < 0.05 * D
    # M-2 has no veer: no tilt
    centres, _ = paper_cases.wake_centres(cases["SBL-6"], cases["SBL-6"].model("M-2", 0.0), 8 * D,
                                          heights, resolution=0.02)
    assert abs(centres[0] - centres[2]) < 0.02 * D


def test_planes_show_the_wake(cases):
    """The plane functions return Delta u/U_h on FLORIS cut planes: zero upstream, the core
    deficit 2a behind the rotor (CNBL x/D = 1, M-1)."""
    plane = paper_cases.cross_plane(cases["CNBL"], "M-1", 0.0, 1.0, resolution=(41, 21))
    a = 1.33 / 5.33
    assert plane.df.u.max() == pytest.approx(2 * a, abs=0.02)
    vertical = paper_cases.vertical_plane(cases["SBL-6"], 20.0, resolution=(31, 11))
    assert np.all(vertical.df.u[vertical.df.x1 < -0.05] == 0.0)
    horizontal = paper_cases.horizontal_plane(cases["SBL-6"], 0.0, -0.5, resolution=(31, 21))
    below = horizontal.df[horizontal.df.x1 > 8.0]
    # half a diameter below the hub, veer has moved the SBL-6 wake to +y
    assert below.x2[below.u.idxmax()] > 0.5


@pytest.fixture(scope="module")
def power(cases):
    """P/P0 for CNBL and SBL-6, beta = 0, +20, -20, x_T/D = 6 and 10, y_T/D in [-2, 2]."""
    chosen = [cases["CNBL"], cases["SBL-6"]]
    y_t = np.linspace(-2.0, 2.0, 21)
    results = {name: paper_power.floris_power_ratios(chosen, name, x_t=(6.0, 10.0), y_t=y_t)
               for name in ("M-1", "M-2", "M-3")}
    disk = paper_power.disk_power_ratios(chosen, "M-1", x_t=(6.0, 10.0), y_t=y_t)
    return y_t, results, disk


def test_power_minimum_follows_the_yaw_in_cnbl(power):
    """The paper: in CNBL the P/P0 minimum moves to -y for beta = +20 deg and to +y for
    beta = -20 deg (yaw deflection), and M-3 keeps it at y_T = 0."""
    y_t, results, _ = power
    y_min, _ = paper_power.minima(results["M-1"][0], y_t)  # (betas, x_t)
    assert np.all(np.abs(y_min[0]) < 0.02)
    assert np.all(y_min[1] < -0.2) and np.all(y_min[2] > 0.2)
    np.testing.assert_allclose(y_min[1], -y_min[2], atol=0.03)
    m3_min, _ = paper_power.minima(results["M-3"][0], y_t)
    assert np.all(np.abs(m3_min) < 1e-6)


def test_veer_raises_the_power_far_downstream_in_sbl6(power):
    """In SBL-6 veer shears the wake off the aligned rotor: at y_T = 0, 10 D behind, M-1 gives
    more power than M-2 and M-3 for every yaw; in CNBL (no veer) M-1 and M-2 agree."""
    y_t, results, _ = power
    centre = int(np.argmin(np.abs(y_t)))
    m1, m2, m3 = (results[name][1, :, 1, centre] for name in ("M-1", "M-2", "M-3"))
    assert np.all(m1 > m2 + 0.05) and np.all(m1 > m3 + 0.05)
    np.testing.assert_allclose(results["M-1"][0, 0], results["M-2"][0, 0], atol=5e-3)
    # M-3 behind a yawed disk (rotor-normal loading) loses less than behind the unyawed one
    m3_all = results["M-3"][:, :, :, centre]
    assert np.all(m3_all[:, 1:] > m3_all[:, :1])


def test_floris_rotor_average_matches_the_disk_integral(power, cases):
    """FLORIS's power of the downstream actuator disk (its rotor average on the inputs' turbine
    grid, ``paper_power.ROTOR_SOLVERS``) against Eq. (P_ratio) integrated directly (polar Gauss
    rule, itself converged to 1e-4 against a 3 x finer rule), also on the thin, sheared SBL-6
    wake and behind a yawed disk, for M-1, M-2 and M-3."""
    y_t, results, disk = power
    assert np.abs(results["M-1"] - disk).max() < 1e-3
    chosen = [cases["CNBL"], cases["SBL-6"]]
    for name in ("M-2", "M-3"):
        direct = paper_power.disk_power_ratios(chosen, name, x_t=(6.0, 10.0), y_t=y_t[::2])
        assert np.abs(results[name][..., ::2] - direct).max() < 1e-3, name
    finer = paper_power.disk_power_ratios([cases["SBL-6"]], "M-1", betas=(20.0,), x_t=(6.0,),
                                          y_t=y_t[::4], radial=48, angular=144)
    np.testing.assert_allclose(disk[1:, 1:2, :1, ::4], finer, atol=1e-4)


@pytest.mark.parametrize("name", ["M-1", "GCH", "cc"])
def test_a_row_of_downstream_disks_equals_two_turbine_farms(cases, name):
    """paper_power puts the y_T of one x_T in rows of turbines (rotors apart): none wakes another,
    so each sees what it sees alone behind the yawed upstream turbine."""
    chosen = [cases["SBL-6"]]
    y_t = np.array([-1.5, 0.0, 1.2])
    assert len(paper_power.separated_rows(y_t)) == 1
    rows = paper_power.separated_rows(np.linspace(-4.0, 4.0, 81))
    assert sorted(np.concatenate(rows)) == list(range(81))
    assert all(np.all(np.diff(row) * 0.1 >= paper_power.ROW_SPACING - 1e-9) for row in rows)
    row = paper_power.floris_power_ratios(chosen, name, betas=(20.0,), x_t=(6.0,), y_t=y_t)
    pairs = [paper_power.floris_power_ratios(chosen, name, betas=(20.0,), x_t=(6.0,), y_t=[y])
             for y in y_t]
    np.testing.assert_allclose(row[..., 0, :], np.concatenate(pairs, axis=-1)[..., 0, :],
                               rtol=1e-12)


@pytest.mark.parametrize("gch", [True, False])
def test_floris_gch_turbine_solve_and_flow_sampling_differ_behind_yaw(gch):
    """Why paper_power's disk cross-check excludes yawed GCH and cc: plain FLORIS (no Ekman
    atmosphere, power-law inflow), NREL 5 MW 6 D behind one yawed by 20 deg: with GCH's
    yaw-added recovery and secondary steering on, the rotor velocities of FLORIS's turbine solve
    differ from FLORIS's flow sampled at the same points; with them off they are the same."""
    config = load_yaml(paper_cases.BUILTIN_BLOCKS)
    del config["wake"]["wake_velocity_parameters"]["ekman_veer"]
    config["wake"]["model_strings"].update(velocity_model="gauss", deflection_model="gauss")
    config["wake"].update(enable_secondary_steering=gch, enable_yaw_added_recovery=gch,
                          enable_transverse_velocities=gch)
    config["flow_field"].update(wind_speeds=[8.0], wind_directions=[270.0],
                                turbulence_intensities=[0.06], wind_shear=0.12)
    fmodel = FlorisModel(config)
    fmodel.set(layout_x=[0.0, 756.0], layout_y=[0.0, -60.0], yaw_angles=[[20.0, 0.0]])
    fmodel.run()
    grid, flow = fmodel.core.grid, fmodel.core.flow_field
    rotor = flow.u_sorted[0, 1].ravel()
    points = [a[0, 1].ravel() for a in (grid.x_sorted, grid.y_sorted, grid.z_sorted)]
    fmodel.set(layout_x=[0.0], layout_y=[0.0], yaw_angles=[[20.0]])
    sampled = fmodel.sample_flow_at_points(*points)[0]
    if gch:
        assert abs(rotor.mean() - sampled.mean()) > 0.01 * rotor.mean()
    else:
        np.testing.assert_allclose(rotor, sampled, rtol=1e-12)
