"""The atmosphere block of a FLORIS input: read, validated, sliced and replaced.

The atmosphere lives in the FLORIS input at::

    wake:
      wake_velocity_parameters:
        ekman_veer:
          atmosphere:
            coriolis_parameter: 1.0e-4
            roughness_length: 0.1
            cooling_rate: -1.0
            brunt_vaisala_frequency: 6.1e-3
            reference_potential_temperature: 265.0

i.e. the keyword inputs of :class:`~floris_ekman_veer.atmosphere.ekman.EkmanABL` without the
geostrophic wind. The block is read whatever ``velocity_model`` is selected (FLORIS only builds the
selected model's block, so the entry may sit there next to ``gauss``, ``cc``, ``jensen``,
``turbopark``...), and because it is part of the input dictionary it survives ``set()``,
``copy()``, ``as_dict()``/YAML, ParFlorisModel workers and UncertainFlorisModel. Without the block
(or without its ``atmosphere`` key) every wrapper calls FLORIS's own method and nothing else:
results are bitwise those of plain FLORIS.

Any atmosphere value may instead be a list of length ``n_findex`` (e.g. a day/night cycle of
cooling rates); it binds by position to FLORIS's conditions. ParFlorisModel and the
visualisation methods slice them (:meth:`AtmosphereSpec.sliced`); UncertainFlorisModel, which
expands and deduplicates conditions, carries them through (plugin/floris_tools/uncertain_conditions.py), and
the yaw optimisers, which tile and mask them, run once per distinct atmosphere
(:func:`atmosphere_groups`).
"""

from __future__ import annotations

import contextlib
import inspect
from collections.abc import Mapping

import attrs
import numpy as np
from floris.core import Core

from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.atmosphere.inputs.stability_inputs import STABILITY_INPUTS

PARAMETER_BLOCK = "ekman_veer"
ATMOSPHERE_KEY = "atmosphere"
CONFIG_PATH = f"wake.wake_velocity_parameters.{PARAMETER_BLOCK}.{ATMOSPHERE_KEY}"

# Inputs of which at most one may be given (EkmanABL's contract).
EXCLUSIVE_INPUTS = (
    ("coriolis_parameter", "latitude"),
    STABILITY_INPUTS,
    ("brunt_vaisala_frequency", "lapse_rate"),
)


def _abl_inputs() -> tuple[frozenset[str], frozenset[str]]:
    """(allowed, required) EkmanABL keyword inputs, minus the geostrophic wind (FLORIS's wind
    speed drives the ABL)."""
    parameters = [
        p for p in inspect.signature(EkmanABL).parameters.values()
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and p.name != "geostrophic_wind"
    ]
    return (
        frozenset(p.name for p in parameters),
        frozenset(p.name for p in parameters if p.default is p.empty),
    )


def read_atmosphere(wake_velocity_parameters: Mapping | None) -> Mapping | None:
    """The raw atmosphere mapping of a ``wake_velocity_parameters`` dict, or None if absent."""
    block = (wake_velocity_parameters or {}).get(PARAMETER_BLOCK)
    if block is None:
        return None
    if not isinstance(block, Mapping):
        raise ValueError(f"wake.wake_velocity_parameters.{PARAMETER_BLOCK} must be a mapping")
    atmosphere = block.get(ATMOSPHERE_KEY)
    if atmosphere is not None and not isinstance(atmosphere, Mapping):
        raise ValueError(
            f"{CONFIG_PATH} must be a mapping of EkmanABL inputs, got {type(atmosphere).__name__}"
        )
    return atmosphere


@attrs.frozen(eq=False)
class AtmosphereSpec:
    """A validated atmosphere block.

    Attributes:
        inputs: EkmanABL keyword inputs; scalars as floats, per-condition lists as arrays shaped
            ``(n_conditions, 1, 1, 1)`` so that they broadcast against FLORIS's 4-D grids.
        n_conditions: Length of the per-condition lists, or None if every value is a scalar.
        key: Hashable fingerprint of ``inputs`` (for the solve cache).
    """

    inputs: dict
    n_conditions: int | None
    key: tuple
    #: Wind speeds at or below this one may be at rest (calm; below every turbine's cut-in):
    #: see :func:`floris_ekman_veer.plugin.inflow.solve_cache.solve`. Set from the Core's turbines by :func:`atmosphere_of`.
    rest_below: float = 0.0

    @classmethod
    def from_mapping(cls, atmosphere: Mapping) -> AtmosphereSpec:
        """Validate keys and values (not yet against FLORIS's conditions)."""
        given = {k: v for k, v in atmosphere.items() if v is not None}
        if "geostrophic_wind" in given:
            raise ValueError(
                f"{CONFIG_PATH}.geostrophic_wind is not allowed: FLORIS's wind speed at "
                "reference_wind_height drives the ABL (EkmanABL.from_reference_wind)"
            )
        allowed, required = _abl_inputs()
        unknown = sorted(set(given) - allowed)
        if unknown:
            raise ValueError(f"{CONFIG_PATH}: unknown key(s) {unknown}; allowed: {sorted(allowed)}")
        missing = sorted(required - set(given))
        if missing:
            raise ValueError(f"{CONFIG_PATH}: missing required key(s) {missing}")
        for group in EXCLUSIVE_INPUTS:
            clash = [k for k in group if k in given]
            if len(clash) > 1:
                raise ValueError(
                    f"{CONFIG_PATH}: contradictory keys {clash}, give at most one of {list(group)}"
                )
        arrays = {name: _as_float_array(name, value) for name, value in given.items()}
        lengths = {name: a.size for name, a in arrays.items() if a.ndim == 1}
        if len(set(lengths.values())) > 1:
            listed = ", ".join(f"{CONFIG_PATH}.{k} has {n}" for k, n in lengths.items())
            raise ValueError(
                "per-condition lists must all have one value per condition (length n_findex); "
                f"got {listed}"
            )
        # Ranges, once, by EkmanABL's own checks (per-condition entries named by condition index).
        _check_ranges(arrays)
        inputs = {
            name: float(a) if a.ndim == 0 else a.reshape(-1, 1, 1, 1) for name, a in arrays.items()
        }
        n_conditions = next(iter(lengths.values()), None)
        key = tuple(sorted(
            (k, v if isinstance(v, float) else v.tobytes()) for k, v in inputs.items()
        ))
        return cls(inputs=inputs, n_conditions=n_conditions, key=key)

    def check_conditions(self, n_findex: int) -> None:
        """Raise ValueError if per-condition lists do not have length ``n_findex``.

        ``n_findex = 0`` (an input file whose conditions are set later with ``set()``) passes.
        """
        if self.n_conditions is not None and n_findex and self.n_conditions != n_findex:
            per_condition = ", ".join(
                f"{CONFIG_PATH}.{k}" for k, v in sorted(self.inputs.items())
                if not isinstance(v, float)
            )
            raise ValueError(
                f"{per_condition} must have one value per condition (length n_findex = "
                f"{n_findex}) or be a single number; got {self.n_conditions} values (replace the "
                "atmosphere and the conditions together with "
                "floris_ekman_veer.plugin.inflow.inflow.set_atmosphere)"
            )

    def sliced(self, index) -> dict:
        """A plain atmosphere mapping (lists, YAML-safe) restricted to conditions ``index``."""
        return {
            k: v if isinstance(v, float) else v.reshape(-1)[index].tolist()
            for k, v in self.inputs.items()
        }


def _as_float_array(name: str, value) -> np.ndarray:
    """A number or a 1-D list of numbers (one per condition) as a float array; strings ("0.1",
    "ten") and booleans are refused, never coerced."""
    from floris_ekman_veer._validation import real_array

    valid = f"{EkmanABL.valid_range(name)}; one number, or a list of one per condition"
    array = real_array(f"{CONFIG_PATH}.{name}", value, valid)
    if array.ndim > 1:
        raise ValueError(f"{CONFIG_PATH}.{name} must be a number or a 1-D list ({valid}); got {value!r}")
    return array


def _check_ranges(arrays: Mapping) -> None:
    """Check the atmosphere's values with EkmanABL's own input checks (the one validation path),
    naming the parameter by its place in the FLORIS input."""
    try:
        EkmanABL.check_inputs(**arrays)
    except ValueError as error:
        message = str(error)
        named = any(message.startswith(f"{name} ") for name in arrays)
        raise ValueError(f"{CONFIG_PATH}.{message}" if named else f"{CONFIG_PATH}: {message}") from None


def atmosphere_of(core: Core) -> AtmosphereSpec | None:
    """The validated atmosphere of a Core (checked against its n_findex), or None."""
    atmosphere = read_atmosphere(core.wake.wake_velocity_parameters)
    if atmosphere is None:
        return None
    spec = farm_atmosphere(atmosphere, core.farm)
    spec.check_conditions(core.flow_field.n_findex)
    return spec


def farm_atmosphere(atmosphere, farm) -> AtmosphereSpec:
    """The ``ekman_veer.atmosphere`` block as the inflow hook solves it for ``farm``: its
    conditions at rest below the farm's zero-power speed. A study that solves the same block
    before the model is built (the GCH comparison) finds its solve in the solve cache."""
    from floris_ekman_veer.plugin.wake_models.input_checks import zero_power_speed

    return attrs.evolve(AtmosphereSpec.from_mapping(atmosphere),
                        rest_below=zero_power_speed(farm.turbine_definitions))


@contextlib.contextmanager
def replaced_atmosphere(core: Core, atmosphere: Mapping | None):
    """Temporarily swap a Core's atmosphere mapping (None removes it) for a rebuild from it."""
    wake = core.wake
    old = wake.wake_velocity_parameters
    block = {k: v for k, v in (old.get(PARAMETER_BLOCK) or {}).items() if k != ATMOSPHERE_KEY}
    if atmosphere is not None:
        block[ATMOSPHERE_KEY] = dict(atmosphere)
    new = {k: v for k, v in old.items() if k != PARAMETER_BLOCK}
    if block:
        new[PARAMETER_BLOCK] = block
    wake.wake_velocity_parameters = new
    try:
        yield
    finally:
        # On success the model holds a new Core built from `new`; restoring the old Core's dict
        # keeps anyone still holding that Core consistent, and undoes everything on failure.
        wake.wake_velocity_parameters = old


def set_atmosphere(fmodel, atmosphere: Mapping | None, **set_kwargs) -> None:
    """Replace the atmosphere (None removes it) and call ``fmodel.set(**set_kwargs)`` at once.

    Needed when the number of conditions changes together with per-condition atmosphere lists
    (neither change alone would be consistent). Works for FlorisModel, ParFlorisModel and
    UncertainFlorisModel. On error the model is left unchanged.
    """
    with replaced_atmosphere(fmodel.core, atmosphere):
        fmodel.set(**set_kwargs)


def atmosphere_groups(fmodel) -> list[tuple[Mapping | None, np.ndarray]]:
    """[(scalar atmosphere mapping or None, condition indices)] of ``fmodel``.

    One group holding every condition when the atmosphere is scalar (its mapping is returned
    unchanged) or absent (None); otherwise one group per distinct row of the per-condition
    values, in order of first appearance.
    """
    n_findex = fmodel.core.flow_field.n_findex
    spec = atmosphere_of(fmodel.core)
    if spec is None or spec.n_conditions is None:
        return [(None if spec is None else spec.sliced(slice(None)), np.arange(n_findex))]
    names = sorted(k for k, v in spec.inputs.items() if not isinstance(v, float))
    rows = np.stack([spec.inputs[k].reshape(-1) for k in names], axis=1)
    _, first, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    groups = []
    for label in np.argsort(first):
        index = np.flatnonzero(inverse == label)
        groups.append((spec.sliced(index[0]), index))
    return groups
