"""Input checks, the one validation path of the package: a clear ValueError naming the parameter
(by its path in the input where it has one), its valid range or type and the offending values;
never NaN, never a silent clip or coercion.

The physics modules check arrays with :func:`require`; the FLORIS models declare their typed
parameters with :func:`number_field`, :func:`boolean_field` and :func:`choice_field`, checked when
the model is built (from YAML or Python alike, docs/coupling.md#input-validation).
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping

import attrs
import numpy as np


def require(ok, name: str, valid: str, value) -> None:
    """Raise ValueError("<name> must be <valid>; got <offending values>") unless ``ok`` holds
    everywhere. The message is built only on failure (formatting large arrays is costly)."""
    ok = np.asarray(ok)
    if not np.all(ok):
        offending = np.broadcast_to(np.asarray(value, dtype=float), ok.shape)[~ok].ravel()
        shown = ", ".join(f"{v:.6g}" for v in offending[:5])
        more = f" (and {offending.size - 5} more)" if offending.size > 5 else ""
        raise ValueError(f"{name} must be {valid}; got {shown}{more}")


def finite(name: str, value) -> np.ndarray:
    """``value`` as a float array, required finite."""
    array = np.asarray(value, dtype=float)
    require(np.isfinite(array), name, "finite", array)
    return array


def positive(value, name: str) -> np.ndarray:
    """``value`` as a float array, required finite and > 0."""
    array = np.asarray(value, dtype=float)
    require(np.isfinite(array) & (array > 0.0), name, "finite and > 0", array)
    return array


# ------------------------------------------------------------------ typed inputs (model build)
# YAML and Python inputs alike: a string is never read as a number or a boolean ("false" is a
# truthy string, so bool("false") is True), and a boolean is never read as a number.


def _describe(value) -> str:
    return f"{value!r} ({type(value).__name__})"


def number(value, name: str, valid: str = "finite", ok=np.isfinite) -> float:
    """``value`` as a float, required a real number (not a string or boolean) with ``ok(value)``.

    ``name`` is the input's full path (e.g. ``wake.wake_velocity_parameters.ekman_veer.A1``);
    ``valid`` describes the range for the message, ``ok`` tests it.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.number)):
        raise ValueError(f"{name} must be a number ({valid}); got {_describe(value)}")
    value = float(value)
    if not ok(value):
        raise ValueError(f"{name} must be {valid}; got {value!r}")
    return value


def boolean(value, name: str) -> bool:
    """``value`` as a bool, required a boolean (YAML true/false, unquoted; Python True/False)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(
            f"{name} must be a boolean (true or false, unquoted in YAML); got {_describe(value)}"
        )
    return bool(value)


def choice(value, name: str, options) -> str:
    """``value`` required one of the strings ``options``."""
    if not isinstance(value, str) or value not in options:
        raise ValueError(f"{name} must be one of {list(options)}; got {_describe(value)}")
    return value


def input_block(data, name: str, allowed) -> None:
    """Require an input block to be a mapping whose keys are all in ``allowed``."""
    if not isinstance(data, Mapping):
        raise ValueError(
            f"{name} must be a mapping of parameters (allowed keys {sorted(allowed)}); "
            f"got {_describe(data)}"
        )
    unknown = sorted(str(k) for k in data if k not in allowed)
    if unknown:
        raise ValueError(f"{name}: unknown key(s) {unknown}; allowed: {sorted(allowed)}")


def require_each(ok, name: str, valid: str, value, labels=("condition",)) -> None:
    """As :func:`require` for a per-entry input, naming the offending entries by their index
    along each axis (``labels``: one name per axis, e.g. ("condition", "turbine"))."""
    ok = np.asarray(ok)
    if not np.all(ok):
        value = np.broadcast_to(np.asarray(value, dtype=float), ok.shape)
        labels = (labels,) if isinstance(labels, str) else tuple(labels)
        bad = np.argwhere(~ok)
        shown = ", ".join(
            f"{value[tuple(i)]:.6g} at "
            + ", ".join(f"{label} {j}" for label, j in zip(labels, i))
            for i in bad[:5]
        )
        more = f" (and {len(bad) - 5} more)" if len(bad) > 5 else ""
        raise ValueError(f"{name} must be {valid}; got {shown}{more}")


def _input_path(instance, attribute) -> str:
    return f"{getattr(type(instance), 'input_path', type(instance).__name__)}.{attribute.name}"


def number_field(default, valid: str, ok=np.isfinite, optional: bool = False):
    """An attrs field holding a number checked by :func:`number` on init and on assignment; the
    message carries the input path ``<class input_path>.<field name>``. ``optional``: None
    allowed (meaning "not given")."""

    def convert(value, instance, attribute):
        if optional and value is None:
            return None
        return number(value, _input_path(instance, attribute), valid, ok)

    return attrs.field(default=default, converter=attrs.Converter(
        convert, takes_self=True, takes_field=True
    ))


def boolean_field(default: bool):
    """An attrs field holding a boolean checked by :func:`boolean` (see :func:`number_field`)."""

    def convert(value, instance, attribute):
        return boolean(value, _input_path(instance, attribute))

    return attrs.field(default=default, converter=attrs.Converter(
        convert, takes_self=True, takes_field=True
    ))


def choice_field(default: str, options):
    """An attrs field holding one of the strings ``options`` (see :func:`number_field`)."""

    def convert(value, instance, attribute):
        return choice(value, _input_path(instance, attribute), options)

    return attrs.field(default=default, converter=attrs.Converter(
        convert, takes_self=True, takes_field=True
    ))


# ------------------------------------------------------------------ real-valued arrays (physics)
# The physics classes take numbers or arrays of them (one entry per condition); a string or a
# boolean is refused there too, where numpy would silently read "10" as 10.0 and True as 1.0.


def _plain_numbers(values) -> bool:
    """True when every item of ``values`` is a Python int or float or a numpy integer or
    floating scalar (never a bool): the common case of a long flat list (a year of per-record
    values), decided by the few distinct types instead of item by item. False means "not
    decided here" (the item-by-item check follows)."""
    return all(t is float or t is int or issubclass(t, (np.floating, np.integer))
               for t in set(map(type, values)))


def _is_real(value) -> bool:
    """True for a real number, or a (nested) sequence or numeric array of real numbers; False
    for strings, booleans, None and anything else numpy would silently coerce to float."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "iuf":
            return True
        return value.dtype.kind == "O" and (_plain_numbers(value.ravel())
                                            or all(_is_real(v) for v in value.ravel()))
    if isinstance(value, (list, tuple)):
        return _plain_numbers(value) or all(_is_real(v) for v in value)
    if hasattr(value, "__array__") and not isinstance(value, (str, bytes, np.generic)):
        # pandas Series and Index, xarray, and other array-likes: judged by their values
        return _is_real(np.asarray(value))
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def real_array(name: str, value, valid: str = "finite") -> np.ndarray:
    """``value`` as a float array, required real numbers (a number, a list or a numeric array):
    a string such as ``"10"``, a boolean or None raises instead of being coerced. ``valid``
    describes the valid range for the message."""
    if not _is_real(value):
        raise ValueError(
            f"{name} must be a real number or an array of real numbers ({valid}); got "
            f"{_describe(value)}{_yaml_hint(value)}"
        )
    try:
        return np.asarray(value, dtype=float)
    except ValueError:  # ragged nesting: lists of different lengths
        raise ValueError(
            f"{name} must be a real number or an array of real numbers of one shape ({valid}); "
            f"got lists of different lengths: {value!r}"
        ) from None


def _yaml_hint(value) -> str:
    """For a string YAML read from an infinity or a number: how to write it as a number."""
    if not isinstance(value, str):
        return ""
    text = value.strip().lower().lstrip("+")
    if text.lstrip("-") in ("inf", "infinity", ".inf"):
        sign = "-" if text.startswith("-") else ""
        return f" (YAML writes infinity as {sign}.inf, unquoted: {value!r} is a string there)"
    try:
        float(text)
    except ValueError:
        return ""
    return " (write the number unquoted: a quoted number is a string in YAML)"


def require_at(ok, name: str, valid: str, value) -> None:
    """:func:`require` for a scalar input, :func:`require_each` for an array one (entries named
    by their condition index: the first axis is the condition)."""
    ndim = np.ndim(ok)
    if ndim == 0:
        require(ok, name, valid, value)
    else:
        labels = ("condition",) + tuple(f"axis-{k} index" for k in range(1, ndim))
        require_each(ok, name, valid, value, labels)


def finite_real(name: str, value, valid: str = "finite") -> np.ndarray:
    """``value`` as a float array of real numbers (see :func:`real_array`), required finite."""
    array = real_array(name, value, valid)
    require_at(np.isfinite(array), name, valid, array)
    return array


def require_floris_model(fmodel, caller: str) -> None:
    """TypeError naming ``fmodel`` unless it is a FLORIS model (it has FLORIS's ``core``)."""
    if not hasattr(fmodel, "core") or not hasattr(fmodel.core, "flow_field"):
        raise TypeError(
            f"{caller}: fmodel must be a FlorisModel, ParFlorisModel or UncertainFlorisModel; "
            f"got {fmodel!r} ({type(fmodel).__name__})"
        )
