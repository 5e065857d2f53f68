"""A dead cup beside a working partner (studies/site/readings.py,
docs/measurements.md#a-real-mast): replaced by the partner and named "dead cup", not the whole
height removed as "cups disagree"."""

import numpy as np
import pandas as pd
import pytest

from floris_ekman_veer import fit_site
from floris_ekman_veer.studies.site.columns import mast_columns
from floris_ekman_veer.studies.site.readings import read_instruments

BOOMS = {"n": 0.0, "s": 180.0}


def records(south_80m=0.0):
    return pd.DataFrame({"time": ["2017-09-01 12:00"], "speed_80m_n": [8.04],
                         "speed_80m_s": [south_80m], "speed_60m_n": [7.8], "speed_60m_s": [7.75],
                         "speed_40m_n": [7.4], "speed_40m_s": [7.35], "direction_78m": [250.0],
                         "direction_58m": [249.0], "direction_38m": [247.0]})


@pytest.mark.parametrize("reading", [0.0, 0.3])
def test_a_dead_or_stalled_cup_is_replaced_by_its_partner(reading):
    frame = records(reading)
    got = read_instruments(frame, mast_columns(frame, BOOMS), booms=BOOMS,
                           direction_offsets=None)
    # The 80 m height keeps its partner's reading (the wind from 250 deg: neither cup in the
    # mast's wake); the other heights average their pairs.
    np.testing.assert_allclose(got.speeds[0], [7.375, 7.775, 8.04])
    assert got.flags["kind"].tolist() == ["dead cup"]
    assert got.flags["column"].tolist() == ["speed_80m_s"]
    assert got.flags["reason"].iloc[0] == (
        f"the cup reads {reading:g} m/s beside speed_80m_n 8.04 m/s at 80 m (a dead or stalled "
        "cup, not a calm): the partner is used")


def test_the_issues_record_keeps_its_80_m_height():
    site = fit_site(records(), 80.0, on_misfit="drop", booms=BOOMS, latitude=53.3,
                    roughness_length=0.05, direction_offsets=None)
    assert len(site.labels) == 1 and site.excluded.empty
    assert site.wind_speeds[0] == pytest.approx(8.04, abs=0.1)
    flags = site.summary().flags
    assert flags.index.tolist() == [("dead cup", "speed_80m_s")]


def test_a_calm_is_no_dead_cup_and_a_half_low_cup_still_disagrees():
    calm = records(0.0)
    calm["speed_80m_n"] = 1.5  # both cups light: a calm, not a dead cup
    got = read_instruments(calm, mast_columns(calm, BOOMS), booms=BOOMS, direction_offsets=None)
    assert "dead cup" not in got.flags["kind"].tolist()
    low = records(4.0)  # half the partner's reading: a spike or a partly stalled cup
    got = read_instruments(low, mast_columns(low, BOOMS), booms=BOOMS, direction_offsets=None)
    assert got.flags["kind"].tolist() == ["cups disagree"] and np.isnan(got.speeds[0, 2])
