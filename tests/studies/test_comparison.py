"""Fair-comparison helpers and the native heterogeneous-inflow exporter (studies/comparison.py)."""

import numpy as np
import pytest
from floris import FlorisModel, UncertainFlorisModel

from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.studies import comparison
from floris_ekman_veer.plugin.inflow import inflow

from conftest import STABLE_ATMOSPHERE, make_config

# The stable atmospheres of these farms give, in some conditions and by design, boundary layers
# shallower than the NREL 5 MW rotor top (153 m); their ShallowBoundaryLayerWarning is not what
# is tested here (tests/physics/test_shallow_abl.py and tests/test_user_inputs_and_warnings.py are).
pytestmark = [pytest.mark.usefixtures("inflow_hook"), pytest.mark.filterwarnings("ignore::floris_ekman_veer.ShallowBoundaryLayerWarning")]

SPEEDS = (6.0, 8.0, 11.0)
HUB, DIAMETER = 90.0, 126.0


def test_settings_follow_the_atmosphere():
    settings = comparison.builtin_inflow_settings(STABLE_ATMOSPHERE, SPEEDS, 90.0, HUB, DIAMETER)
    for i, speed in enumerate(SPEEDS):
        abl = EkmanABL.from_reference_wind(speed, 90.0, **STABLE_ATMOSPHERE)
        np.testing.assert_allclose(settings["turbulence_intensities"][i],
                                   abl.turbulence_intensity(HUB, reference_height=HUB), rtol=1e-12)
        np.testing.assert_allclose(settings["wind_veer"][i],
                                   abl.wind_direction_change(HUB - 63.0, HUB + 63.0), rtol=1e-12)
    assert np.all(settings["wind_veer"] > 0)  # northern hemisphere: veering


def test_shear_exponent_is_the_chord_weighted_fit():
    settings = comparison.builtin_inflow_settings(STABLE_ATMOSPHERE, [8.0], 90.0, HUB, DIAMETER)
    alpha = settings["wind_shear"][0]
    abl = EkmanABL.from_reference_wind(8.0, 90.0, **STABLE_ATMOSPHERE)
    offsets = np.linspace(-63.0, 63.0, 2001)[1:-1]
    weights = np.sqrt(63.0**2 - offsets**2)
    U, _ = abl.hub_aligned_velocity(HUB + offsets, 90.0)

    def misfit(exponent):
        return np.sum(weights * (np.log(U / 8.0) - exponent * np.log((HUB + offsets) / 90.0))**2)

    assert misfit(alpha) < min(misfit(alpha - 0.01), misfit(alpha + 0.01))
    assert misfit(alpha) < 0.05 * misfit(0.0)


def test_positive_wind_veer_tilts_gauss_wakes_like_northern_hemisphere_veer():
    """FLORIS's gauss tilts the wake top to -y for wind_veer > 0; Ekman veer in the northern
    hemisphere blows the upper rotor half to -y too (V < 0 above hub in the hub-aligned frame)."""
    abl = EkmanABL.from_reference_wind(8.0, 90.0, **STABLE_ATMOSPHERE)
    _, V = abl.hub_aligned_velocity(np.array([HUB - 63.0, HUB + 63.0]), 90.0)
    assert V[1] < 0 < V[0]
    veer = comparison.builtin_inflow_settings(STABLE_ATMOSPHERE, [8.0], 90.0, HUB, DIAMETER)
    fmodel = FlorisModel(make_config("gauss", None, layout_x=[0.0], layout_y=[0.0]))
    fmodel.set(wind_veer=float(veer["wind_veer"][0]), wind_shear=0.0)
    plane = fmodel.calculate_cross_plane(downstream_dist=630.0, y_resolution=60, z_resolution=60,
                                         y_bounds=(-200, 200), z_bounds=(1, 200)).df
    weight = (8.0 - plane.u) / (8.0 - plane.u).sum()
    y, z = plane.x1 - (weight * plane.x1).sum(), plane.x2 - (weight * plane.x2).sum()
    assert (weight * y * z).sum() < 0


def test_per_condition_atmosphere_settings_equal_single_ones():
    atmosphere = dict(STABLE_ATMOSPHERE, cooling_rate=[0.0, -0.5])
    together = comparison.builtin_inflow_settings(atmosphere, [8.0, 9.0], 90.0, HUB, DIAMETER)
    for i, (cooling, speed) in enumerate(zip((0.0, -0.5), (8.0, 9.0))):
        alone = comparison.builtin_inflow_settings(
            dict(STABLE_ATMOSPHERE, cooling_rate=cooling), [speed], 90.0, HUB, DIAMETER)
        for key in alone:
            np.testing.assert_allclose(together[key][i], alone[key][0], rtol=1e-10)


def test_fair_builtin_set_kwargs_feed_floris():
    fmodel = FlorisModel(make_config("gch", wind_speeds=SPEEDS, wind_directions=(270.0,) * 3))
    fmodel.run()
    default = fmodel.get_turbine_powers()
    kwargs = comparison.fair_builtin_set_kwargs(fmodel)
    diameter = fmodel.core.farm.rotor_diameters[0, 0]  # NREL 5 MW: 125.88 m
    settings = comparison.builtin_inflow_settings(STABLE_ATMOSPHERE, SPEEDS, 90.0, HUB, diameter)
    np.testing.assert_array_equal(kwargs["turbulence_intensities"],
                                  settings["turbulence_intensities"])
    assert kwargs["wind_veer"] == pytest.approx(np.mean(settings["wind_veer"]), rel=1e-12)
    assert kwargs["wind_shear"] == pytest.approx(np.mean(settings["wind_shear"]), rel=1e-12)
    fmodel.set(**kwargs)
    fmodel.run()
    assert not np.allclose(fmodel.get_turbine_powers(), default)
    power_law = fmodel.copy()
    inflow.set_atmosphere(power_law, None, **kwargs)
    assert power_law.core.flow_field.wind_shear == pytest.approx(kwargs["wind_shear"])
    power_law.run()
    assert np.all(np.isfinite(power_law.get_turbine_powers()))


def test_missing_atmosphere_raises():
    with pytest.raises(ValueError, match="ekman_veer.atmosphere"):
        comparison.fair_builtin_set_kwargs(FlorisModel(make_config(atmosphere=None)))


# ------------------------------------------------------------------------- native exporter


def native_copy(fmodel):
    native = fmodel.copy()
    inflow.set_atmosphere(native, None, **comparison.native_inflow_set_kwargs(fmodel))
    return native


def test_native_export_reproduces_u_at_rotor_points():
    """The export carries point values of the profile: at FLORIS's cubature points they are the
    hook's inflow exactly; on the turbine grid the hook's points carry rotor-cell means instead
    (docs/coupling.md#rotor-average), which the export cannot."""
    hooked = FlorisModel(make_config("jensen", wind_speeds=SPEEDS, wind_directions=(270.0, 280.0, 300.0)))
    cubature = {"type": "turbine_cubature_grid", "turbine_grid_points": 3}
    hooked.set(solver_settings=cubature)
    native = native_copy(hooked)
    native.set(solver_settings=cubature)
    assert "ekman_veer" not in native.core.wake.wake_velocity_parameters
    for fmodel in (hooked, native):
        fmodel.run()
    np.testing.assert_allclose(native.core.flow_field.u_initial_sorted,
                               hooked.core.flow_field.u_initial_sorted, rtol=0, atol=1e-12)
    # jensen uses neither v nor dU/dz: the same powers
    np.testing.assert_allclose(native.get_turbine_powers(), hooked.get_turbine_powers(),
                               rtol=1e-12)
    # ...but the export's limits: no dU/dz,
    assert not native.core.flow_field.dudz_initial_sorted.any()
    assert hooked.core.flow_field.dudz_initial_sorted.any()


def test_native_export_breaks_uncertain_floris_model():
    native = native_copy(FlorisModel(make_config("gch", wind_speeds=SPEEDS,
                                                 wind_directions=(270.0,) * 3)))
    with pytest.raises(IndexError):
        UncertainFlorisModel(native).run()
