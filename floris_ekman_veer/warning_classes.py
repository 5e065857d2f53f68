"""The package's warning classes and the setting that silences them (docs/user_guide.md#warnings).

Every warning of the package is a :class:`FlorisEkmanVeerWarning`, importable from the package's
top level (``from floris_ekman_veer import ShallowBoundaryLayerWarning``); how they reach the user
(located at the user's line, summarised, once per study, from worker processes) is
``floris_ekman_veer.warnings``.

Silencing, for this process and every worker process or Dask worker it starts or sends models
to::

    import floris_ekman_veer
    floris_ekman_veer.silence_warnings()                       # all of the package's warnings
    floris_ekman_veer.silence_warnings("ShallowBoundaryLayerWarning")  # or some classes

or, before Python starts, ``FLORIS_EKMAN_VEER_WARNINGS=ignore`` (or a comma-separated list of
class names) in the environment. The setting lives in that environment variable, which process
pools inherit; it travels with every model the package sends to a ParFlorisModel worker
(plugin/floris_tools/parallel.py) and is set on the Dask workers at each run (studies/energy/distributed.py). ``silence_warnings(None)`` restores the
default. Python's own
warning filters work as usual in the process where they are set.
"""

from __future__ import annotations

import os

#: The environment variable that silences the package's warnings ("ignore", or class names).
ENVIRONMENT_VARIABLE = "FLORIS_EKMAN_VEER_WARNINGS"


class FlorisEkmanVeerWarning(UserWarning):
    """Base class of every warning of floris_ekman_veer."""


class ShallowBoundaryLayerWarning(FlorisEkmanVeerWarning):
    """Some conditions have a boundary layer shallower than the rotor (outside the paper's
    validated range; the model's behaviour there is documented, continuous and finite)."""


class ThrustLimitWarning(FlorisEkmanVeerWarning, RuntimeWarning):
    """Some wakes have a rotor-normal loading C_T cos^2(yaw) above ``max_thrust_coefficient``,
    beyond momentum theory: they are evaluated at the limit."""


class ModelSettingsWarning(FlorisEkmanVeerWarning):
    """The input mixes the package's wake models with FLORIS's (a velocity model without its
    deflection model, GCH's switches on): it runs, but it is not the paper's model."""


class TurbinePlacementWarning(FlorisEkmanVeerWarning):
    """A layout the user gave has intersecting rotors, or a hub in the roughness sublayer."""


class HeterogeneousInflowWarning(FlorisEkmanVeerWarning):
    """A heterogeneous inflow map is given together with the atmosphere (how they combine:
    docs/user_guide.md#heterogeneous-inflow)."""


class DirectionUnitsWarning(FlorisEkmanVeerWarning):
    """A fitted record's directions all lie within 0 to 2 pi and its fitted veer is
    implausibly small: directions given in radians would look like this."""


class ReferenceWindWarning(FlorisEkmanVeerWarning):
    """The reference-wind solve met some speeds only to more than its tolerance (the speed lies
    in the profile's step where the boundary-layer top crosses the reference height); the
    closest state is taken."""


#: Every warning class, by name (what ``silence_warnings`` and the environment variable take).
CLASSES = {
    cls.__name__: cls
    for cls in (FlorisEkmanVeerWarning, ShallowBoundaryLayerWarning, ThrustLimitWarning,
                ModelSettingsWarning, TurbinePlacementWarning, HeterogeneousInflowWarning,
                DirectionUnitsWarning, ReferenceWindWarning)
}


# ------------------------------------------------------------------------------------ silencing
def _parse(setting: str | None) -> tuple[type, ...]:
    if not setting or not setting.strip():
        return ()
    names = [name.strip() for name in setting.split(",") if name.strip()]
    if names == ["ignore"]:
        return (FlorisEkmanVeerWarning,)
    unknown = sorted(set(names) - set(CLASSES))
    if unknown:
        raise ValueError(
            f"{ENVIRONMENT_VARIABLE}: unknown warning class(es) {unknown}; give 'ignore' or a "
            f"comma-separated list of {sorted(CLASSES)}"
        )
    return tuple(CLASSES[name] for name in names)


def warnings_setting() -> str | None:
    """The current silencing setting (the environment variable's value, or None)."""
    return os.environ.get(ENVIRONMENT_VARIABLE) or None


def silence_warnings(*categories) -> None:
    """Silence the package's warnings (all of them, or the given classes or class names) here
    and in every worker that runs this process's models; ``silence_warnings(None)`` restores
    them. The setting is the environment variable ``FLORIS_EKMAN_VEER_WARNINGS``."""
    if categories == (None,):
        os.environ.pop(ENVIRONMENT_VARIABLE, None)
        return
    names = [c if isinstance(c, str) else getattr(c, "__name__", repr(c)) for c in categories]
    unknown = sorted(set(names) - set(CLASSES) - {"ignore"})
    if unknown:  # an unknown name is an error now, not in a worker later
        raise ValueError(
            f"silence_warnings: unknown warning class(es) {unknown}; give none (all of them), "
            f"None (restore them) or classes or names among {sorted(CLASSES)}"
        )
    os.environ[ENVIRONMENT_VARIABLE] = ",".join(names) if names else "ignore"


def apply_setting(setting: str | None) -> None:
    """Adopt the setting of the process that sends this worker its models (None: the default)."""
    if setting:
        os.environ[ENVIRONMENT_VARIABLE] = setting
    else:
        os.environ.pop(ENVIRONMENT_VARIABLE, None)


def silenced(category: type) -> bool:
    """Whether the current setting silences warnings of ``category``."""
    return issubclass(category, _parse(warnings_setting()) or ())


# A setting that names no warning class is refused when the package is imported, not when a
# warning would first fire mid-study.
_parse(warnings_setting())
