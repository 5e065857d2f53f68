"""Property-based tests (hypothesis): valid inputs over the ranges users meet, through FLORIS.

Each example draws an atmosphere (|latitude| 5-80 degrees either hemisphere, z0 1e-4 to 1 m,
every stability input kind: neutral, ``stability_parameter``, ``cooling_rate``,
``surface_heat_flux``, ``obukhov_length``; the free atmosphere as ``brunt_vaisala_frequency`` or
``lapse_rate``), one or two conditions (wind 2-30 m/s at the reference height, any direction,
turbulence intensity 3-15 %), a random layout of 1-4 NREL 5 MW or of 1-4 of the paper's actuator
disks (one type per farm, see :func:`layouts`; at least 3 D apart, any arrangement), yaw -30 to
30 degrees per turbine, and a wake set-up (``ekman_veer`` M-1/M-2 with random switches, ``bastankhah2014`` M-3, FLORIS's
gauss/GCH on the Ekman inflow). Through ``run()``, ``run_no_wake()``,
``sample_flow_at_points`` and the horizontal, cross and y planes it asserts:

* no NaN or inf in any power, velocity or plane;
* u >= 0 everywhere (turbines, points, planes);
* a turbine that no other turbine stands upstream of has exactly its no-wake power;
* every turbine's rotor-averaged speed is at most its no-wake one, and so its power (where the
  power curve is monotone: the NREL 5 MW below its 25 m/s cut-out, the disk everywhere).

Valid by construction. The wind at the reference height is not drawn directly: a geostrophic
wind G is, the ABL is solved forward from G (``EkmanABL``) and FLORIS is given that ABL's speed
at the reference height, so an ABL with that speed exists and ``from_reference_wind`` (which
FLORIS runs) must find one. Inputs the package refuses on purpose, as documented
(docs/coupling.md#input-validation, README "Valid input ranges"), are discarded with ``assume``:
a forward solve that finds no stable boundary layer (it collapses: matching height below z0),
and a collapsed layer a few metres deep whose inflow runs against the reference direction near
the ground (its Ekman spiral turns by more than 90 degrees: U(z) < 0 there by design,
docs/atmosphere.md; u >= 0 cannot hold for it).
The equator is excluded by the latitude range. Boundary layers shallower than the rotor are
kept: they run with a ShallowBoundaryLayerWarning (docs/atmosphere.md) and must be as physical.
``hypothesis.event`` counts discards and shallow cases (``--hypothesis-show-statistics``).
Sample points span z = 0 and 1 micrometre to 400 m, except that FLORIS's gauss is asked only for z > 0: at z = 0
it returns NaN with FLORIS's own power-law inflow too (FLORIS's grid warns of non-positive z).

Profiles (registered in tests/conftest.py): ``ci`` (the default: few examples, derandomised, so
CI is fast and reproducible) and ``long`` (2,000 examples, random), selected with the environment
variable HYPOTHESIS_PROFILE, e.g. ``HYPOTHESIS_PROFILE=long python -m pytest
tests/plugin/test_properties.py --hypothesis-show-statistics``.
"""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest
from floris import FlorisModel
from floris.utilities import load_yaml, rotate_coordinates_rel_west
from hypothesis import assume, event, given
from hypothesis import strategies as st

import floris_ekman_veer
import floris_ekman_veer.plugin.inflow.inflow
from floris_ekman_veer import EkmanABL
from floris_ekman_veer.plugin.inflow.shallow import ShallowBoundaryLayerWarning
from floris_ekman_veer.plugin.rotor.turbine import actuator_disk_turbine

#: NREL 5 MW: power rises with speed up to its 25 m/s cut-out (FLORIS's table).
NREL_5MW_CUT_OUT = 25.0
#: Turbines at least this many (larger) rotor diameters apart, hub to hub, horizontally.
MIN_SPACING_D = 3.0
TURBINES = {"nrel_5MW": (126.0, 90.0), "disk": (100.0, 100.0)}  # D, hub height [m]
BASE = load_yaml("inputs/farm_sbl6.yaml")
DISK = actuator_disk_turbine()

pytestmark = [
    pytest.mark.filterwarnings("ignore::RuntimeWarning"),
    pytest.mark.filterwarnings(
        "ignore::floris_ekman_veer.plugin.inflow.shallow.ShallowBoundaryLayerWarning"
    ),
    # drawn turbulence intensities, which the ekman_veer model does not read (that notice is
    # tested in tests/plugin/wake_models/test_floris_input_messages.py)
    pytest.mark.filterwarnings(
        "ignore:flow_field.turbulence_intensities:floris_ekman_veer.ModelSettingsWarning"),
]


def finite(x) -> st.SearchStrategy:
    return st.floats(*x, allow_nan=False, allow_infinity=False)


@st.composite
def atmospheres(draw) -> dict:
    """EkmanABL inputs without the wind speed, over the ranges users meet."""
    atmosphere = {
        "latitude": draw(st.sampled_from([-1.0, 1.0])) * draw(finite((5.0, 80.0))),
        "roughness_length": 10.0 ** draw(finite((-4.0, 0.0))),
    }
    kind = draw(st.sampled_from(
        ["neutral", "stability_parameter", "cooling_rate", "surface_heat_flux", "obukhov_length"]
    ))
    if kind != "neutral":
        atmosphere[kind] = draw({
            "stability_parameter": finite((0.0, 300.0)),
            "cooling_rate": finite((-1.5, 0.0)),  # K/h
            "surface_heat_flux": finite((-0.05, 0.0)),  # K m/s
            "obukhov_length": st.builds(lambda e: 10.0**e, finite((1.0, 4.0))),  # m
        }[kind])
    free = draw(st.sampled_from(["default", "brunt_vaisala_frequency", "lapse_rate"]))
    if free == "brunt_vaisala_frequency":
        atmosphere[free] = draw(finite((1e-3, 2e-2)))  # 1/s
    elif free == "lapse_rate":
        atmosphere[free] = draw(finite((5e-4, 1e-2)))  # K/m
    if draw(st.booleans()):
        atmosphere["reference_potential_temperature"] = draw(finite((250.0, 310.0)))
    return atmosphere


@st.composite
def layouts(draw):
    """1-4 turbines, all NREL 5 MW or all actuator disks, at least MIN_SPACING_D apart.

    Not mixed: FLORIS 4.7 sums each turbine type's axial induction times a mask
    (``turbine.axial_induction``), and the NREL 5 MW's cosine-loss induction evaluated at a disk's
    entries (tilt 0 against its ref_tilt of 5 deg, C_T = 0.9999 between 2.9 and 4 m/s) is NaN,
    which NaN * 0 carries into the disk's induction; GCH and the turbulence models read it.
    """
    n = draw(st.integers(1, 4))
    kinds = [draw(st.sampled_from(sorted(TURBINES)))] * n
    xy = np.array(draw(st.lists(
        st.tuples(finite((0.0, 3000.0)), finite((-1000.0, 1000.0))), min_size=n, max_size=n
    )))
    diameter = np.array([TURBINES[k][0] for k in kinds])
    distance = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
    spacing = MIN_SPACING_D * np.maximum(diameter[:, None], diameter)
    assume(np.all(np.triu(distance >= spacing, k=1) | np.tri(n, dtype=bool)))
    return kinds, xy


#: Heights at which the inflow is required to run downstream (U(z) >= 0).
GROUND_HEIGHTS = np.concatenate([[0.0], np.geomspace(1e-6, 400.0, 400)])
#: Sample heights: the ground itself, or 1 micrometre to 400 m (not the subnormal heights, below
#: 1e-300 m, that a float draw would otherwise favour).
heights = st.one_of(st.just(0.0), finite((1e-6, 400.0)))

WAKES = {
    "M-1/M-2": dict(velocity_model="ekman_veer", deflection_model="ekman_veer"),
    "M-3": dict(velocity_model="bastankhah2014", deflection_model="ekman_veer"),
    "gauss": dict(velocity_model="gauss", deflection_model="gauss"),
}


@st.composite
def cases(draw) -> dict:
    atmosphere = draw(atmospheres())
    kinds, xy = draw(layouts())
    hub_heights = [TURBINES[k][1] for k in kinds]
    reference_height = draw(st.sampled_from([90.0, 100.0, hub_heights[0]]))
    n_findex = draw(st.integers(1, 2))
    speeds = []
    for _ in range(n_findex):
        g = draw(finite((2.5, 40.0)))
        try:
            abl = EkmanABL(geostrophic_wind=g, **atmosphere)
        except ValueError as error:
            # The documented refusal: no stable boundary layer (it collapses).
            event(f"discarded: forward ABL refused ({str(error)[:40]}...)")
            assume(False)
        if float(abl.boundary_layer_height) <= max(h + d / 2 for d, h in map(TURBINES.get, kinds)):
            event("boundary layer shallower than a rotor (ShallowBoundaryLayerWarning)")
        speed = float(abl.speed(reference_height))
        assume(2.0 <= speed <= 30.0)
        # The state FLORIS will use (the deepest with this speed). A collapsed layer a few metres
        # deep whose spiral turns by more than 90 degrees blows against the reference direction
        # near the ground, U(z) < 0 by design (docs/atmosphere.md): u >= 0 does not apply there.
        state = EkmanABL.from_reference_wind(speed, reference_height, **atmosphere)
        if np.min(state.hub_aligned_velocity(GROUND_HEIGHTS, reference_height)[0]) < 0.0:
            event("discarded: inflow against the reference direction near the ground")
            assume(False)
        speeds.append(speed)
    wake = draw(st.sampled_from(sorted(WAKES)))
    event(f"wake {wake}; {atmosphere.keys() - {'latitude', 'roughness_length'}}")
    return {
        "atmosphere": atmosphere,
        "kinds": kinds,
        "xy": xy,
        "reference_height": reference_height,
        "speeds": speeds,
        "directions": draw(st.lists(finite((0.0, 360.0)), min_size=n_findex, max_size=n_findex)),
        "intensities": draw(st.lists(finite((0.03, 0.15)), min_size=n_findex, max_size=n_findex)),
        "yaw": draw(st.lists(finite((-30.0, 30.0)), min_size=len(kinds), max_size=len(kinds))),
        "wake": wake,
        "switches": {
            "curl": draw(st.booleans()),
            "veer": draw(st.booleans()),
            "yaw_deflection": draw(st.booleans()),
            "ground_image": draw(st.booleans()),
            "polar_angle_centre": draw(st.sampled_from(["wake_centre", "yaw_centre"])),
            "wake_expansion": draw(st.sampled_from(["ambient", "local_turbulence",
                                                    "array_turbulence"])),
            "deficit_velocity": draw(st.sampled_from(["incoming", "free_stream"])),
            "gch": draw(st.booleans()),
        },
        "points": draw(st.lists(
            st.tuples(finite((-1000.0, 4000.0)), finite((-1500.0, 1500.0)), heights),
            min_size=1, max_size=12,
        )),
        "plane_height": draw(finite((1.0, 300.0))),
        "plane_x": draw(finite((-200.0, 3500.0))),
        "plane_y": draw(finite((-800.0, 800.0))),
    }


def floris_model(case) -> FlorisModel:
    config = copy.deepcopy(BASE)
    switches = case["switches"]
    wake = config["wake"]
    wake["model_strings"].update(WAKES[case["wake"]])
    for flag in ("enable_secondary_steering", "enable_yaw_added_recovery",
                 "enable_transverse_velocities"):
        wake[flag] = case["wake"] == "gauss" and switches["gch"]
    velocity = wake["wake_velocity_parameters"]
    velocity["ekman_veer"] = {
        "atmosphere": case["atmosphere"],
        "curl": switches["curl"],
        "polar_angle_centre": (
            switches["polar_angle_centre"] if case["wake"] == "M-1/M-2" else "wake_centre"
        ),
        "wake_expansion": switches["wake_expansion"],
        "deficit_velocity": switches["deficit_velocity"],
    }
    velocity["bastankhah2014"] = {"wake_expansion": switches["wake_expansion"],
                                  "deficit_velocity": switches["deficit_velocity"]}
    wake["wake_deflection_parameters"]["ekman_veer"] = {
        k: switches[k] for k in ("veer", "yaw_deflection", "ground_image")
    }
    if switches["polar_angle_centre"] == "yaw_centre" and case["wake"] == "M-1/M-2":
        # The yaw-only centre is measured from the ekman_veer deflection with veer.
        wake["wake_deflection_parameters"]["ekman_veer"]["veer"] = True
    config["farm"]["layout_x"] = case["xy"][:, 0].tolist()
    config["farm"]["layout_y"] = case["xy"][:, 1].tolist()
    disk = copy.deepcopy(DISK)  # one object: FLORIS 4.7 refuses equal copies of a definition
    config["farm"]["turbine_type"] = [k if k == "nrel_5MW" else disk for k in case["kinds"]]
    config["logging"]["console"]["enable"] = False
    config["flow_field"].update(
        wind_speeds=case["speeds"], wind_directions=case["directions"],
        turbulence_intensities=case["intensities"], reference_wind_height=case["reference_height"],
    )
    fmodel = FlorisModel(config)
    fmodel.set(yaw_angles=np.tile(case["yaw"], (len(case["speeds"]), 1)))
    return fmodel


def unwaked(fmodel) -> np.ndarray:
    """(n_findex, n_turbines): no other turbine stands upstream (in FLORIS's rotated frame,
    where a wake starts 0.1 m behind its rotor plane) of the turbine."""
    coordinates = np.asarray(fmodel.core.farm.coordinates, dtype=float)
    x, _, _, _, _ = rotate_coordinates_rel_west(fmodel.core.flow_field.wind_directions, coordinates)
    behind = x[:, :, None] - x[:, None, :]  # [f, j, i] = x_j - x_i
    n = x.shape[1]
    behind[:, np.arange(n), np.arange(n)] = -np.inf
    return np.max(behind, axis=2) <= 0.0


def assert_flow(where: str, u, *others, z=None):
    """No NaN/inf in ``u`` and ``others``, u >= 0; the message says where (and at which z)."""
    if z is not None:
        z = np.broadcast_to(z, np.shape(u))
    for array in (u, *others):
        bad = ~np.isfinite(array)
        assert not np.any(bad), f"NaN or inf in the {where}" + (
            f" at z = {np.unique(np.asarray(z)[bad])[:5]} m" if z is not None else ""
        )
    negative = np.asarray(u) < 0.0
    assert not np.any(negative), f"negative streamwise velocity {np.min(u):.6g} m/s in the {where}" + (
        f" at z = {np.unique(np.asarray(z)[negative])[:5]} m" if z is not None else ""
    )


@given(case=cases())
def test_farm_runs_points_and_planes_are_physical(case):
    with warnings.catch_warnings():
        # Heavy loading (NREL 5 MW near cut-in) is evaluated at max_thrust_coefficient with a
        # RuntimeWarning, shallow boundary layers run with a ShallowBoundaryLayerWarning, both by
        # design (README, "Conventions and invalid physics").
        warnings.simplefilter("ignore", RuntimeWarning)
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        fmodel = floris_model(case)
        fmodel.run()
        power = fmodel.get_turbine_powers()
        speed = fmodel.turbine_average_velocities
        rotor_u = np.array(fmodel.core.flow_field.u)
        fmodel.run_no_wake()
        power_0 = fmodel.get_turbine_powers()
        speed_0 = fmodel.turbine_average_velocities
        rotor_u_0 = np.array(fmodel.core.flow_field.u)

        assert_flow("turbine powers and rotor velocities", rotor_u, power, rotor_u_0, power_0)
        assert np.all(power >= 0.0)
        free = unwaked(fmodel)
        np.testing.assert_allclose(power[free], power_0[free], rtol=1e-12, atol=1e-9)
        assert np.all(speed <= speed_0 * (1.0 + 1e-12) + 1e-12)
        monotone = np.array([k == "disk" for k in case["kinds"]])[None, :] | (
            np.max(rotor_u_0, axis=(2, 3)) <= NREL_5MW_CUT_OUT
        )
        assert np.all((power <= power_0 * (1.0 + 1e-12) + 1e-9) | ~monotone)

        x, y, z = np.array(case["points"]).T
        if case["wake"] == "gauss":
            # FLORIS's own gauss is NaN at z = 0 with its own power law too (its grid warns of
            # non-positive z): only z > 0 is asked of it.
            x, y, z = x[z > 0], y[z > 0], z[z > 0]
        if z.size:
            assert_flow("sampled points", np.asarray(fmodel.sample_flow_at_points(x, y, z)), z=z)

        resolution = dict(findex_for_viz=0)
        planes = {
            "horizontal plane": fmodel.calculate_horizontal_plane(
                case["plane_height"], x_resolution=8, y_resolution=6, **resolution
            ),
            "cross plane": fmodel.calculate_cross_plane(
                case["plane_x"], y_resolution=6, z_resolution=8, **resolution
            ),
            "y plane": fmodel.calculate_y_plane(
                case["plane_y"], x_resolution=8, z_resolution=6, **resolution
            ),
        }
    for where, plane in planes.items():
        df = plane.df
        assert len(df) > 0
        # FLORIS names the vertical planes' height column x2.
        z = df["x2"] if where != "horizontal plane" else np.full(len(df), case["plane_height"])
        assert_flow(f"{case['wake']} {where}", df["u"].to_numpy(), df["v"].to_numpy(),
                    df["w"].to_numpy(), z=z.to_numpy() if hasattr(z, "to_numpy") else z)


def test_unwaked_criterion():
    """The oracle above: in a row along the wind only the front turbine is free."""
    config = copy.deepcopy(BASE)
    config["farm"].update(layout_x=[0.0, 882.0, 0.0], layout_y=[0.0, 0.0, 882.0])
    fmodel = FlorisModel(config)
    fmodel.set(wind_directions=[270.0, 90.0], wind_speeds=[9.0, 9.0],
               turbulence_intensities=[0.06, 0.06])
    np.testing.assert_array_equal(unwaked(fmodel), [[True, False, True], [False, True, False]])



def test_wake_never_reverses_the_flow_near_the_ground():
    """The paper's CNBL disk: far downstream the Gaussian, scaled by U_h, reaches the ground,
    where the inflow U(z) -> 0; there Delta u is limited to U(z) (a wake at most stops the flow,
    docs/wake_model.md#which-velocity-goes-where). Unlimited, u fell to -0.21 m/s on this grid."""
    fmodel = FlorisModel("inputs/cnbl.yaml")
    u, ambient, z = near_ground_flow(fmodel, np.linspace(50.0, 3000.0, 40))
    assert np.all((u >= 0.0) & (u <= ambient * (1 + 1e-12)))
    stopped = (u == 0.0) & (ambient > 0.0)
    assert 0 < np.count_nonzero(stopped) < u.size // 2  # the limit acts in a thin layer only
    assert np.max(z[stopped]) < 0.2


def near_ground_flow(fmodel, x):
    """u and the ambient inflow U(z) on a grid x by y = -300..300 m by z = 1 mm..3 m."""
    x, y, z = (a.ravel() for a in np.meshgrid(
        x, np.linspace(-300.0, 300.0, 21), np.geomspace(1e-3, 3.0, 30), indexing="ij"
    ))
    u = fmodel.sample_flow_at_points(x, y, z)[0]
    abl = floris_ekman_veer.plugin.inflow.inflow.solved_atmosphere(fmodel.core.flow_field)
    ambient, _ = floris_ekman_veer.plugin.inflow.inflow.inflow_profile(abl, z, 100.0)
    return u, np.ravel(ambient), z


def test_superposed_wakes_never_reverse_the_flow():
    """Two CNBL disks in a row: where both wakes are limited to U(z) next to the ground, FLORIS's
    sum of squares would give (1 - sqrt(2)) U(z); points and planes are bounded by u >= 0
    (docs/wake_model.md#which-velocity-goes-where), and above that layer they are untouched."""
    fmodel = FlorisModel("inputs/cnbl.yaml")
    fmodel.set(layout_x=[0.0, 500.0], layout_y=[0.0, 0.0])
    u, ambient, _ = near_ground_flow(fmodel, np.linspace(600.0, 3000.0, 25))
    assert np.all((u >= 0.0) & (u <= ambient * (1 + 1e-12)))
    plane = fmodel.calculate_y_plane(0.0, x_resolution=20, z_resolution=15,
                                     x_bounds=(600.0, 3000.0), z_bounds=(0.001, 2.0)).df
    assert plane.u.min() >= 0.0
    hub = fmodel.sample_flow_at_points(np.linspace(600.0, 3000.0, 25), np.zeros(25),
                                       np.full(25, 100.0))[0]
    speed = floris_ekman_veer.plugin.inflow.inflow.solved_atmosphere(fmodel.core.flow_field).speed(100.0)
    assert np.all(hub < speed) and hub.min() < 0.6 * speed  # the wakes are there
