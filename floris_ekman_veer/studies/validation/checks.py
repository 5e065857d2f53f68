"""The input checks of the validation API (docs/validation.md#bad-input), on top of the package's
one validation path (``floris_ekman_veer._validation``).

Every public class and function of ``studies.validation`` refuses bad input when it is built,
with a ValueError (a TypeError for a value of the wrong kind: a string where a number or a
reference is due) whose message names the field (``FarmCase 'my farm': wind_speed``), its valid
range and the value; never NaN in the results, never a failure later inside FLORIS.
"""

from __future__ import annotations

import numbers

import numpy as np

from floris_ekman_veer._validation import number, real_array

#: Wind directions are meteorological degrees, the direction the wind blows from.
DIRECTION_RANGE = "in [0, 360] deg (the direction the wind blows from)"


def text(value, name: str) -> str:
    """``value`` required a non-empty string (TypeError otherwise)."""
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a string; got {value!r} ({type(value).__name__})")
    if not value.strip():
        raise ValueError(f"{name} must be a non-empty string; got {value!r}")
    return value


def scalar(value, name: str, valid: str, ok) -> float:
    """``value`` as a float, required a real number (not a string or boolean) with ``ok``."""
    return number(value, name, valid, ok)


def direction(value, name: str) -> float:
    """A wind direction [deg]: a number in [0, 360]."""
    return scalar(value, name, DIRECTION_RANGE, lambda d: np.isfinite(d) and 0.0 <= d <= 360.0)


def array(value, name: str, ndim: int, valid: str, ok=np.isfinite, allow=None) -> np.ndarray:
    """``value`` as a float array of ``ndim`` dimensions and at least one entry, required real
    numbers with ``ok`` at every entry (``allow``: a boolean mask of entries left unchecked,
    e.g. a row's gaps)."""
    values = real_array(name, value, valid)
    if values.ndim != ndim or values.size == 0:
        raise ValueError(f"{name} must be a non-empty {ndim}-D array ({valid}); got shape "
                         f"{values.shape}")
    with np.errstate(invalid="ignore"):
        good = np.isfinite(values) & np.asarray(ok(values), dtype=bool)
    if allow is not None:
        good |= allow
    if not good.all():
        bad = np.argwhere(~good)[0]
        where = ", ".join(str(i) for i in bad)
        raise ValueError(f"{name} must be {valid}; got {values[tuple(bad)]!r} at index [{where}]")
    return values


def indices(value, name: str, valid: str) -> np.ndarray:
    """``value`` as an int array: real numbers that are whole (1.5 is refused, not truncated)."""
    values = real_array(name, value, valid)
    with np.errstate(invalid="ignore"):
        whole = np.isfinite(values) & (values == np.round(values))
    if values.size and not whole.all():
        raise ValueError(f"{name} must be whole numbers ({valid}); got "
                         f"{values[~whole].ravel()[0]!r}")
    return values.astype(int)


def whole_number(value, name: str, valid: str, ok) -> int:
    """``value`` as an int: an integer (not a boolean, not 1.5) with ``ok``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, np.integer)):
        raise TypeError(f"{name} must be an integer ({valid}); got {value!r} "
                        f"({type(value).__name__})")
    if not ok(int(value)):
        raise ValueError(f"{name} must be {valid}; got {value!r}")
    return int(value)


def instance(value, name: str, kind: type, optional: bool = False):
    """``value`` required an instance of ``kind`` (or None when ``optional``)."""
    if (value is None and optional) or isinstance(value, kind):
        return value
    allowed = f"a {kind.__name__}" + (" or None" if optional else "")
    raise TypeError(f"{name} must be {allowed}; got {value!r} ({type(value).__name__})")
