"""The site fit's quiet cases said (issue: a newcomer's first day): two columns of one
instrument, a speed column in km/h, fitted layer tops below the reference height (I_u = 0 there),
repeated heights in fit_profile."""

import numpy as np
import pandas as pd
import pytest

from floris_ekman_veer import EkmanABL, ShallowBoundaryLayerWarning, fit_site
from floris_ekman_veer.studies.site.columns import mast_columns
from floris_ekman_veer.studies.site.readings import check_speed_units

SITE = dict(latitude=52.0, roughness_length=0.05)
Z = np.arange(30.0, 151.0, 20.0)


def model_records(speeds=(6.0, 8.0, 10.0), obukhov_length=np.inf):
    abl = EkmanABL.from_reference_wind(np.asarray(speeds), 90.0,
                                       obukhov_length=obukhov_length, **SITE)
    columns = {}
    for z in Z:
        columns[f"speed_{z:g}m"] = np.asarray(abl.speed(z), float)
        columns[f"direction_{z:g}m"] = 270.0 - np.asarray(abl.wind_angle(z), float)
    return pd.DataFrame(columns)


@pytest.mark.parametrize("kind", ["speed", "direction"])
def test_two_columns_of_one_height_are_refused_naming_both(kind):
    records = model_records()
    records[f"{kind}_90.0m"] = records[f"{kind}_90m"] + 0.1
    with pytest.raises(ValueError, match=rf"'{kind}_90m' and '{kind}_90.0m' name the same "
                                         r"instrument \(height 90 m\)"):
        fit_site(records, 90.0, **SITE)


def test_a_speed_column_in_km_per_h_is_refused_with_its_unit():
    records = model_records()
    records["speed_50m"] *= 3.6
    # 3.6 / (U90/U50 of the neutral profile, about 1.08) read against the cups above it
    ratio = np.median(records["speed_50m"]) / np.median(
        np.median(records[[f"speed_{z:g}m" for z in Z if z > 50]], axis=0))
    assert 3.0 < ratio < 3.6
    with pytest.raises(ValueError, match=rf"'speed_50m' reads {ratio:.2f} times the cups above "
                                         r"it .*likely in km/h"):
        fit_site(records, 90.0, **SITE)
    # The top cup in km/h, read against the cups below it over a day of records.
    day = model_records(np.linspace(5.0, 12.0, 24))
    day["speed_150m"] *= 3.6
    with pytest.raises(ValueError, match=r"'speed_150m' reads .* times the cups below it"):
        fit_site(day, 90.0, **SITE)
    # A steep but real profile (speeds rising 2.5 times from the lowest cup) is no unit error.
    steep = model_records()
    steep["speed_30m"] /= 2.5
    assert check_speed_units(steep, mast_columns(steep)) is None


def test_layer_tops_below_the_reference_height_are_said():
    """Stable light-wind records (3 m/s, L about 30 m) whose fitted top lies at 70-76 m: the
    model's I_u ends at 1.62 times that (Eq. upup_var continued), below a 130 m reference
    height, where their I_u is 0; fit_site says so."""
    heights = (30, 70, 110, 150)
    speeds = np.array([[2.71, 3.33, 3.06, 3.0], [2.7, 3.21, 2.79, 3.0], [2.72, 3.06, 2.96, 2.89]])
    directions = np.array([[139.7, 162.3, 166.6, 167.6], [118.6, 141.7, 146.1, 145.0],
                           [31.4, 54.8, 59.2, 60.2]])
    records = pd.DataFrame({**{f"speed_{z}m": speeds[:, k] for k, z in enumerate(heights)},
                            **{f"direction_{z}m": directions[:, k]
                               for k, z in enumerate(heights)}})
    with pytest.warns(ShallowBoundaryLayerWarning,
                      match=r"3 of 3 fitted records have their boundary layer top so far below "
                            r"the reference height 130 m \(0 \(top 7\d m\)"):
        site = fit_site(records, 130.0, speed_noise=0.1, direction_noise=0.5,
                        direction_offsets=None, **SITE)
    assert np.all(1.62 * site.abl.boundary_layer_height < 130.0)
    np.testing.assert_array_equal(site.turbulence_intensities, 0.0)
    assert site.summary().tops_below_reference == 3
    assert "3 fitted records have their boundary layer top so far below" in str(site.summary())
    # Below the top the same fits have turbulence: the zero is the layer's top, not the fit;
    # at 90 m, between h and 1.62 h, it is tapered, not zero, and nothing is said.
    assert np.all(np.asarray(site.abl.turbulence_intensity(50.0)) > 0.0)
    at_90 = fit_site(records, 90.0, speed_noise=0.1, direction_noise=0.5,
                     direction_offsets=None, **SITE)
    assert np.all(at_90.turbulence_intensities > 0.0) and at_90.summary().tops_below_reference == 0


@pytest.mark.parametrize("name", ["heights", "direction_heights"])
def test_fit_profile_refuses_repeated_heights(name):
    heights = np.array([40.0, 60.0, 60.0, 80.0])
    data = dict(heights=np.array([40.0, 60.0, 80.0, 100.0]), speeds=np.array([6.0, 6.5, 6.9, 7.2]),
                directions=np.array([260.0, 261.0, 262.0, 263.0]))
    data[name] = heights
    with pytest.raises(ValueError, match=rf"fit_profile: {name} repeat 60 m \(columns \[1, 2\]\)"):
        EkmanABL.fit_profile(**data, **SITE)
    # Per record: the second record's heights repeat.
    two = np.array([[40.0, 60.0, 80.0, 100.0], [40.0, 40.0, 80.0, 100.0]])
    with pytest.raises(ValueError, match=r"heights of record 1 repeat 40 m \(columns \[0, 1\]\)"):
        EkmanABL.fit_profile(two, np.vstack([data["speeds"]] * 2),
                             np.vstack([data["directions"]] * 2), **SITE)
