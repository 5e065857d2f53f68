"""Stability distributions of a wind climate: named classes, each an atmosphere (the
``ekman_veer.atmosphere`` block of the FLORIS input, scalars) with its frequency, checked
against the wind data they go with (docs/coupling.md#annual-energy).

* with a ``WindRose`` (directions x speeds) or a ``TimeSeries``, each class has a ``frequency``
  (the frequencies sum to 1) and the frequency of (class, direction, speed) is the product of
  the class frequency and the wind's: stability is taken as independent of the wind, as a
  frequency per class states;
* with a ``TimeSeries`` and ``records`` (a class name per record), each record has its own
  class and the class frequencies follow from the records.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import attrs
import numpy as np
from floris.wind_data import TimeSeries, WindRose

from floris_ekman_veer.plugin.inflow.inflow import AtmosphereSpec

#: Keys of one class of a stability distribution.
CLASS_KEYS = ("frequency", "atmosphere")
#: Tolerance on the sum of the class frequencies.
FREQUENCY_TOLERANCE = 1e-9


@attrs.frozen
class StabilityClass:
    """One stability class: its name, atmosphere (scalar EkmanABL inputs without the wind speed)
    and, per condition of the wind data, the frequency of (this class, that condition)."""

    name: str
    atmosphere: dict
    frequency: float
    condition_frequencies: np.ndarray


def stability_classes(stability: Mapping, wind_data, records=None) -> list[StabilityClass]:
    """Validate a stability distribution against ``wind_data`` (the module docstring).

    Args:
        stability: ``{name: {"frequency": f, "atmosphere": {...}}}``; without ``frequency``
            when ``records`` are given.
        wind_data: A FLORIS ``WindRose`` or ``TimeSeries``.
        records: With a TimeSeries: the class name of every record.

    Raises:
        ValueError: naming the class, the key and the value, for unknown keys, frequencies out
            of [0, 1] or not summing to 1, atmospheres EkmanABL rejects or that vary per
            condition, records of unknown classes or of the wrong length.
    """
    if not isinstance(wind_data, (WindRose, TimeSeries)):
        raise ValueError(
            "annual energy: wind_data must be a floris.WindRose or floris.TimeSeries, got "
            f"{type(wind_data).__name__}"
        )
    if not isinstance(stability, Mapping) or not stability:
        raise ValueError(
            "annual energy: stability must be a non-empty mapping {class name: {'frequency': f, "
            f"'atmosphere': {{...}}}}}}, got {stability!r}"
        )
    wind_frequencies = np.asarray(wind_data.unpack_freq(), dtype=float).reshape(-1)
    if records is not None:
        if not isinstance(wind_data, TimeSeries):
            raise ValueError(
                "annual energy: records (a stability class per record) need a floris.TimeSeries; "
                f"got a {type(wind_data).__name__} (give a frequency per class instead)"
            )
        records = np.asarray(records, dtype=object).reshape(-1)
        if records.size != wind_frequencies.size:
            raise ValueError(
                f"annual energy: records must give one stability class per TimeSeries record "
                f"({wind_frequencies.size}); got {records.size}"
            )
        unknown = [i for i, name in enumerate(records) if name not in stability]
        if unknown:
            raise ValueError(
                f"annual energy: records[{unknown[0]}] = {records[unknown[0]]!r} is not a class "
                f"of stability {sorted(stability)} ({len(unknown)} such records)"
            )
    classes = []
    for name, entry in stability.items():
        where = f"stability[{name!r}]"
        if not isinstance(entry, Mapping):
            raise ValueError(f"annual energy: {where} must be a mapping with keys "
                             f"{list(CLASS_KEYS)}, got {entry!r}")
        unknown = sorted(set(entry) - set(CLASS_KEYS))
        if unknown:
            raise ValueError(f"annual energy: {where}: unknown key(s) {unknown}; "
                             f"allowed: {list(CLASS_KEYS)}")
        if "atmosphere" not in entry or not isinstance(entry["atmosphere"], Mapping):
            raise ValueError(f"annual energy: {where}['atmosphere'] must be a mapping of "
                             f"EkmanABL inputs without the wind speed, got "
                             f"{entry.get('atmosphere')!r}")
        try:
            spec = AtmosphereSpec.from_mapping(entry["atmosphere"])
        except ValueError as error:
            raise ValueError(f"annual energy: {where}['atmosphere']: {error}") from None
        if spec.n_conditions is not None:
            raise ValueError(
                f"annual energy: {where}['atmosphere'] must hold scalars (a class is one "
                "atmosphere); give each atmosphere its own class"
            )
        if records is not None:
            if "frequency" in entry:
                raise ValueError(
                    f"annual energy: {where}: with records the class frequencies follow from the "
                    f"records; remove 'frequency' (got {entry['frequency']!r})"
                )
            mask = records == name
            frequency = float(np.sum(wind_frequencies[mask]))
            condition_frequencies = np.where(mask, wind_frequencies, 0.0)
        else:
            frequency = entry.get("frequency")
            if (isinstance(frequency, bool) or not isinstance(frequency, (int, float, np.number))
                    or not 0.0 <= frequency <= 1.0):
                raise ValueError(
                    f"annual energy: {where}['frequency'] must be a number in [0, 1], got "
                    f"{frequency!r}"
                )
            frequency = float(frequency)
            condition_frequencies = frequency * wind_frequencies
        classes.append(StabilityClass(str(name), spec.sliced(slice(None)), frequency,
                                      condition_frequencies))
    total = math.fsum(c.frequency for c in classes)
    if abs(total - 1.0) > FREQUENCY_TOLERANCE:
        given = ", ".join(f"{c.name!r}: {c.frequency:g}" for c in classes)
        raise ValueError(f"annual energy: the stability class frequencies must sum to 1; got "
                         f"{total:.12g} ({given})")
    return classes
