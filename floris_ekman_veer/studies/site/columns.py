"""Stage 1 of the site fit (pipeline.py): the instruments the records hold, read from their
column names (docs/measurements.md#a-real-mast).

The names carry the measurement point's height, as the IEA Wind Task 43 data model's measurement
points carry ``height_m``, and the boom as its ``boom_orientation_deg``:

* ``speed_<h>m``: the mean speed [m/s] of the one cup at ``h`` m; or ``speed_<h>m_<boom>``, one
  per boom at that height (e.g. ``speed_80m_a``, ``speed_80m_b``), the booms' orientations given
  as ``booms={"a": 135.0, "b": 315.0}`` [deg, from the mast to the cup, clockwise from north];
* ``speed_<h>m_std`` or ``speed_<h>m_<boom>_std``: the cup's standard deviation [m/s] over the
  record (Task 43's statistic ``sd``): the measured turbulence intensity sigma_u / U;
* ``direction_<h>m``: a vane's mean direction [deg, meteorological] at its own height;
* ``..._min``, ``..._max`` (and a vane's ``_std``): other statistics, left alone.
"""

from __future__ import annotations

import re

import attrs
import numpy as np
import pandas as pd

#: Column names: the height in metres, a cup's boom, a cup's standard deviation.
_NUMBER = r"(\d+(?:\.\d+)?)"
#: Statistics of a record other than the mean (Task 43's statistic types): the cups' ``std`` is
#: read; ``min`` and ``max`` and the vanes' statistics are left alone.
STATISTICS = ("std", "min", "max")
_STATISTIC = "|".join(STATISTICS)
SPEED_COLUMN = re.compile(
    rf"^speed_{_NUMBER}m(?:_(?!(?:{_STATISTIC})$)([A-Za-z][A-Za-z0-9]*))?(?:_({_STATISTIC}))?$")
DIRECTION_COLUMN = re.compile(rf"^direction_{_NUMBER}m(?:_({_STATISTIC}))?$")


@attrs.frozen(eq=False)
class MastColumns:
    """The instruments of the records: per cup height the (boom, speed column, std column or
    None) of its cups, per vane height its column."""

    cups: dict
    vanes: dict

    @property
    def cup_heights(self):
        return np.array(sorted(self.cups))

    @property
    def vane_heights(self):
        return np.array(sorted(self.vanes))

    @property
    def has_std(self):
        return any(std is not None for cups in self.cups.values() for _, _, std in cups)


def mast_columns(records: pd.DataFrame, booms=None) -> MastColumns:
    """The instruments in ``records``' columns (module docstring); ValueError naming a column
    that begins like one but is none, a boom without its orientation, or too few heights."""
    if not isinstance(records, pd.DataFrame):
        raise ValueError(f"records must be a pandas DataFrame; got {type(records).__name__}")
    booms = {} if booms is None else dict(booms)
    for name, orientation in booms.items():
        if (isinstance(orientation, (bool, np.bool_))
                or not isinstance(orientation, (int, float, np.integer, np.floating))
                or not np.isfinite(orientation)):
            raise ValueError(f"fit_site: booms[{name!r}] must be the boom's orientation in deg "
                             f"(from the mast to the cup, clockwise from north); got "
                             f"{orientation!r}")
    cups, stds, vanes, unknown = {}, {}, {}, []

    def put(table, where, column):
        # Two names of one instrument (speed_90m and speed_90.0m): which one is the reading
        # is unknown, and keeping either would drop the other silently.
        if where in table:
            height = where[0] if isinstance(where, tuple) else where
            raise ValueError(f"records: columns {table[where]!r} and {column!r} name the same "
                             f"instrument (height {height:g} m): keep one of them (or name the "
                             "booms, speed_<h>m_<boom>)")
        table[where] = column

    for column in map(str, records.columns):
        if (m := SPEED_COLUMN.match(column)):
            where = (float(m[1]), m[2])
            if m[3] is None:
                put(cups, where, column)
            elif m[3] == "std":
                put(stds, where, column)
        elif (m := DIRECTION_COLUMN.match(column)):
            if m[2] is None:
                put(vanes, float(m[1]), column)
        elif column.startswith(("speed_", "direction_")):
            unknown.append(column)
    if unknown:
        raise ValueError(
            f"records: columns {unknown} are named like measurements but read as none: name "
            "them speed_<height>m, speed_<height>m_<boom>, speed_<height>m[_<boom>]_std (or _min, "
            "_max) or direction_<height>m with the height a number >= 0 in metres (e.g. "
            "speed_80m_a)")
    lone = sorted(set(stds) - set(cups))
    if lone:
        raise ValueError(f"records: standard-deviation columns {[stds[k] for k in lone]} have "
                         "no mean-speed column of their cup")
    by_height = {}
    for (height, boom), column in sorted(cups.items(), key=lambda kv: (kv[0][0], kv[0][1] or "")):
        by_height.setdefault(height, []).append((boom, column, stds.get((height, boom))))
    for height, group in by_height.items():
        named = [boom for boom, _, _ in group if boom is not None]
        if named and len(named) < len(group):
            raise ValueError(f"records: at {height:g} m the cups {[c for _, c, _ in group]} mix "
                             "a cup without a boom and cups with one: name every cup's boom")
        missing = [c for boom, c, _ in group if boom is not None and boom not in booms]
        if missing:
            raise ValueError(f"records: columns {missing} name booms without an orientation: "
                             f"give fit_site(..., booms={{name: orientation_deg}}) (got booms="
                             f"{booms})")
    if len(by_height) < 2:
        raise ValueError(
            "records need speed columns at two heights or more, named speed_<height>m (e.g. "
            f"speed_90m); got columns {list(records.columns)}")
    return MastColumns(cups=by_height, vanes=vanes)
