"""Ekman inflow for every FLORIS wake model, defined once in the input dictionary.

FLORIS 4.7 builds its inflow as a power law (times optional speed multipliers) and has no
extension point for another profile. This module is the one place where the package reaches
into FLORIS to replace that inflow; everything it patches is listed in :func:`install_inflow_hook`.

Configuration
-------------
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

Per condition, the ABL is driven by FLORIS's wind speed at ``reference_wind_height``:
``EkmanABL.from_reference_wind(wind_speeds[:, None, None, None], reference_wind_height, **atm)``,
solved once for all conditions in one vectorised call. Any atmosphere value may instead be a list
of length ``n_findex`` (e.g. a day/night cycle of cooling rates); it binds by position to FLORIS's
conditions. ParFlorisModel and the visualisation methods slice them; UncertainFlorisModel, which
expands and deduplicates conditions, carries them through (studies/uncertain.py), and the yaw
optimisers, which tile and mask them, run once per distinct atmosphere (studies/optimization.py).

What the hook sets
------------------
* ``u_initial_sorted`` (and ``u_sorted``) = the hub-aligned streamwise component U(z) of the
  analytic profile at every grid height, in the frame rotated so that V(reference_wind_height) = 0:
  FLORIS's wind direction is read as the direction at its reference height, and
  U(reference_wind_height) equals FLORIS's wind speed. In the roughness sublayer (below about
  e z0) the profile falls linearly to 0 at the ground (docs/atmosphere.md#roughness-sublayer), so
  U > 0 at every z > 0 and no FLORIS model meets a zero inflow above the ground (FLORIS's gauss
  models divide by u_initial; at z = 0 U = 0, as with FLORIS's power law). Points below the
  ground get 0.
  ``wind_shear`` is ignored (the atmosphere defines the shear); 2-D/3-D heterogeneous speed
  multipliers, if also given, multiply the profile. On a ``turbine_grid`` each rotor point gets
  instead the mean of the profile over its rotor cell, <U^m>^(1/m) with m = 3 (power curves) or
  1 (the actuator disk) (:mod:`floris_ekman_veer.plugin.rotor`, docs/coupling.md#rotor-average).
* ``dudz_initial_sorted`` = dU/dz of that same hub-aligned U, by a centred difference of the
  analytic profile (relative step 1e-4: relative error about 1e-8; EkmanABL exposes no analytic
  gradient), 0 below the ground. GCH's secondary steering uses it.
* ``v_initial_sorted`` stays zero. FLORIS's solvers read ``v`` as *wake-induced* transverse
  velocity: GCH derives an effective yaw from the rotor-averaged ``v`` of each turbine (secondary
  steering) and feeds ``v``/``w`` into yaw-added recovery, so ambient veer in ``v_initial`` would
  be mistaken for the sidewash of a yawed rotor. Measured (GCH, NREL 5 MW row at 7 D, 8 m/s at
  90 m, f_c = 1e-4 1/s, z0 = 0.1 m, N = 6.1e-3 1/s; powers with V(z) in ``v_initial`` vs without):
  cooling rate -1 K/h (h = 71 m, 36 deg of veer across the rotor): downstream turbines +96 % and
  +67 % at zero yaw; -0.25 K/h (h = 197 m, 25 deg): +2.7 %, and +7.8 % with the first turbine
  yawed 20 deg; neutral (0 K/h, 0.5 deg of backing): +0.1 to +1.1 %. Unwaked turbines do not
  change (wind direction 300 deg: 0 %), i.e. the effect is purely a spurious wake steering. See
  ``tests/plugin/test_inflow.py::test_ambient_v_would_change_gch``. The veer reaches this package's own
  deflection model through :func:`solved_atmosphere` instead.
* Turbulence intensities remain FLORIS's inputs (see
  :func:`floris_ekman_veer.studies.comparison.builtin_inflow_settings` for values consistent with
  the atmosphere).

For wake models
---------------
``solved_atmosphere(flow_field)`` returns the EkmanABL solved for that flow field's conditions
(attributes shaped ``(n_findex, 1, 1, 1)``); call it from ``prepare_function(grid, flow_field)``.
The ABL is solved when the model is built (to validate the input) and cached by content, so each
flow-field initialisation reuses it: one solve per distinct (atmosphere, wind speeds, reference
height), never per turbine or per model. Deep copies made by the full-flow solvers are re-initialised
through the same hook and get their own entry.

Mechanism
---------
Class-level wrappers: ``FlowField.initialize_velocity_field`` replaces the inflow when an
atmosphere is active in a ``contextvars.ContextVar``; the Core entry points that (directly or through
the full-flow solvers) initialise flow fields set that variable from the Core's own wake parameters.
``Core.__attrs_post_init__`` validates the block at build time (FlorisModel construction, ``set()``,
``copy()``), so bad input fails early with the offending key named.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import inspect
import re
import threading
import weakref
from collections import OrderedDict
from collections.abc import Mapping

import attrs
import floris
import numpy as np


SUPPORTED_FLORIS = ((4, 7), (4, 8))  # [lower, upper): the hook relies on 4.7 internals


def _check_floris_version(version: str) -> None:
    """Raise ImportError unless ``version`` is in [4.7, 4.8)."""
    match = re.match(r"(\d+)\.(\d+)", version)
    lower, upper = SUPPORTED_FLORIS
    if match is None or not lower <= (int(match[1]), int(match[2])) < upper:
        raise ImportError(
            f"floris_ekman_veer.plugin.inflow patches FLORIS internals and supports "
            f"floris>={lower[0]}.{lower[1]},<{upper[0]}.{upper[1]}, but floris {version} is "
            f"installed. Install a supported FLORIS (pip install 'floris>=4.7,<4.8')."
        )


_check_floris_version(floris.__version__)

from floris.core import Core, FlowField, TurbineGrid  # noqa: E402  (only after the version check)
from floris.floris_model import FlorisModel  # noqa: E402

from floris_ekman_veer.atmosphere.stability_inputs import STABILITY_INPUTS  # noqa: E402
import floris_ekman_veer.warnings as package_warnings  # noqa: E402
from floris_ekman_veer.plugin.rotor import (  # noqa: E402
    TURBINE_MOMENTS,
    WAKE_MODELS,
    turbine_grid_inflow,
    turbine_moments,
)


PARAMETER_BLOCK = "ekman_veer"
ATMOSPHERE_KEY = "atmosphere"
CONFIG_PATH = f"wake.wake_velocity_parameters.{PARAMETER_BLOCK}.{ATMOSPHERE_KEY}"

# Inputs of which at most one may be given (EkmanABL's contract).
EXCLUSIVE_INPUTS = (
    ("coriolis_parameter", "latitude"),
    STABILITY_INPUTS,
    ("brunt_vaisala_frequency", "lapse_rate"),
)


def _abl_class():
    # Imported on use so that this module (and FLORIS's unconfigured behaviour) does not depend
    # on the ABL solver being importable.
    from floris_ekman_veer.atmosphere.ekman import EkmanABL

    return EkmanABL


def _abl_inputs() -> tuple[frozenset[str], frozenset[str]]:
    """(allowed, required) EkmanABL keyword inputs, minus the geostrophic wind (FLORIS's wind
    speed drives the ABL)."""
    parameters = [
        p for p in inspect.signature(_abl_class()).parameters.values()
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and p.name != "geostrophic_wind"
    ]
    return (
        frozenset(p.name for p in parameters),
        frozenset(p.name for p in parameters if p.default is p.empty),
    )


# ---------------------------------------------------------------------------------------------
# Reading and validating the atmosphere block


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
    #: see :func:`solve`. Set from the Core's turbines by :func:`atmosphere_of`.
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
                "floris_ekman_veer.plugin.inflow.set_atmosphere)"
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

    valid = f"{_abl_class().valid_range(name)}; one number, or a list of one per condition"
    array = real_array(f"{CONFIG_PATH}.{name}", value, valid)
    if array.ndim > 1:
        raise ValueError(f"{CONFIG_PATH}.{name} must be a number or a 1-D list ({valid}); got {value!r}")
    return array


def _check_ranges(arrays: Mapping) -> None:
    """Check the atmosphere's values with EkmanABL's own input checks (the one validation path),
    naming the parameter by its place in the FLORIS input."""
    try:
        _abl_class().check_inputs(**arrays)
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
    from floris_ekman_veer.plugin.input_checks import zero_power_speed

    return attrs.evolve(AtmosphereSpec.from_mapping(atmosphere),
                        rest_below=zero_power_speed(farm.turbine_definitions))


# ---------------------------------------------------------------------------------------------
# Solving (cached by content) and the profile on a grid


_SOLVE_CACHE: OrderedDict = OrderedDict()
_SOLVE_CACHE_SIZE = 32
_SOLVE_LOCK = threading.Lock()


def solve(spec: AtmosphereSpec, wind_speeds, reference_height: float):
    """EkmanABL for every condition: ``|(U, V)(reference_height)| = wind_speeds``.

    One vectorised ``from_reference_wind`` call with speeds shaped ``(n_findex, 1, 1, 1)``; the
    result is cached by (atmosphere, wind speeds, reference height), so building a model,
    initialising its flow fields and the wake models' look-ups share one solve.
    """
    wind_speeds = np.asarray(wind_speeds, dtype=float).reshape(-1)
    reference_height = float(reference_height)
    spec.check_conditions(wind_speeds.size)
    key = (spec.key, wind_speeds.tobytes(), reference_height, spec.rest_below)
    with _SOLVE_LOCK:
        if key in _SOLVE_CACHE:
            _SOLVE_CACHE.move_to_end(key)
            return _SOLVE_CACHE[key]
    # Calm conditions (0 m/s) are at rest: no ABL is solved for them (they take the ABL of a
    # moving condition, unused) and the inflow is 0, so they give zero power. Conditions below
    # every turbine's cut-in are at rest too when no valid ABL reaches their speed
    # (docs/user_guide.md#calm-and-weak-winds).
    at_rest = wind_speeds <= 0.0
    try:
        abl = _solve_moving(spec, wind_speeds, reference_height, at_rest)
    except ValueError:
        weak = at_rest | (wind_speeds <= spec.rest_below)
        if not np.any(weak & ~at_rest):
            raise
        at_rest = weak
        abl = _solve_moving(spec, wind_speeds, reference_height, at_rest)
    abl.at_rest = at_rest
    with _SOLVE_LOCK:
        _SOLVE_CACHE[key] = abl
        while len(_SOLVE_CACHE) > _SOLVE_CACHE_SIZE:
            _SOLVE_CACHE.popitem(last=False)
    return abl


def _solve_moving(spec: AtmosphereSpec, wind_speeds, reference_height: float, at_rest):
    """from_reference_wind for the conditions not at rest (those at rest take the fastest
    moving condition's speed, or 10 m/s when every condition is at rest)."""
    moving = wind_speeds[~at_rest]
    wind_speeds = np.where(at_rest, moving.max() if moving.size else 10.0, wind_speeds)
    z0 = spec.inputs.get("roughness_length")
    if z0 is not None and np.any(reference_height <= np.asarray(z0)):
        raise ValueError(
            f"flow_field.reference_wind_height = {reference_height} m must be above "
            f"{CONFIG_PATH}.roughness_length (max {np.max(z0)} m)"
        )
    try:
        abl = _abl_class().from_reference_wind(
            wind_speeds[:, None, None, None], reference_height, **spec.inputs
        )
    except ValueError as error:
        raise ValueError(
            f"{CONFIG_PATH} driven by flow_field.wind_speeds at flow_field.reference_wind_height: "
            f"{error}"
        ) from error
    return abl


def inflow_profile(abl, z, reference_height: float):
    """Hub-aligned streamwise velocity U(z) and dU/dz at heights ``z``.

    The frame is rotated so that V(reference_height) = 0; heights below the ground give
    U = dU/dz = 0 (see :func:`ambient_velocity`). ``z`` broadcasts against the ABL's ``(n_findex, 1, 1, 1)`` shape; the result
    has the broadcast shape. The profile is evaluated only at the distinct heights of ``z`` (a
    rotor grid of 100 turbines of one hub height has 3 of them, whatever n_findex and however
    FLORIS sorted the turbines) and gathered back, which gives the same numbers as evaluating at
    every point, at a fraction of the cost.
    """
    z = np.asarray(z, dtype=float)
    n_conditions = np.shape(abl.friction_velocity)[0] if np.ndim(abl.friction_velocity) else 1
    shape = np.broadcast_shapes(np.shape(abl.friction_velocity), z.shape)
    heights, inverse, reduced_shape = _distinct_heights(z)
    if n_conditions * heights.size >= z.size:
        U, dUdz = _profile_and_gradient(abl, z, reference_height)
        return np.broadcast_to(U, shape), np.broadcast_to(dUdz, shape)
    U, dUdz = _profile_and_gradient(abl, heights.reshape(1, 1, 1, -1), reference_height)
    rows = np.arange(n_conditions).reshape(-1, 1, 1, 1)
    inverse = inverse.reshape(reduced_shape)
    U = np.broadcast_to(U, (n_conditions, 1, 1, heights.size)).reshape(n_conditions, -1)
    dUdz = np.broadcast_to(dUdz, (n_conditions, 1, 1, heights.size)).reshape(n_conditions, -1)
    return (
        np.broadcast_to(U[rows, inverse], shape),
        np.broadcast_to(dUdz[rows, inverse], shape),
    )


def _distinct_heights(z: np.ndarray):
    """Distinct values of ``z`` after dropping the axes along which it is constant.

    Returns (sorted distinct heights, inverse indices, shape of the reduced array). Dropping
    constant axes first (the condition axis, the rotor's horizontal axis: cheap comparisons)
    keeps the sort small.
    """
    reduced = z
    for axis in range(z.ndim):
        if reduced.shape[axis] > 1:
            first = reduced.take([0], axis=axis)
            if np.array_equal(np.broadcast_to(first, reduced.shape), reduced):
                reduced = first
    heights, inverse = np.unique(reduced, return_inverse=True)
    return heights, inverse, reduced.shape


#: The last few (ABL, heights, reference height) -> (U, V) of :func:`ambient_velocity` on small
#: height sets, and of :func:`ambient_rows`: a solve's rotor cells are evaluated for the inflow
#: (plugin/rotor.py) and again for the crossflow (plugin/yawed_rotor.py) at the same heights.
_AMBIENT_CACHE: OrderedDict = OrderedDict()
_AMBIENT_CACHE_SIZE = 2
_AMBIENT_CACHED_HEIGHTS = 4096
_ROWS_CACHE: OrderedDict = OrderedDict()


def _cached(cache: OrderedDict, key, abl, compute):
    """``compute()`` (a pair of arrays, made read-only) under ``key`` for ``abl``, or the pair
    kept from the last call with the same key and the same ABL instance."""
    with _SOLVE_LOCK:
        entry = cache.get(key)
    if entry is not None and entry[0]() is abl:
        return entry[1], entry[2]
    U, V = compute()
    U.flags.writeable = False
    V.flags.writeable = False
    with _SOLVE_LOCK:
        cache[key] = (weakref.ref(abl), U, V)
        while len(cache) > _AMBIENT_CACHE_SIZE:
            cache.popitem(last=False)
    return U, V


def ambient_velocity(abl, z, reference_height: float):
    """Hub-aligned ambient (U, V)(z) on a FLORIS grid: the profile of
    :meth:`EkmanABL.hub_aligned_velocity` at z >= 0 (with its roughness sublayer,
    docs/atmosphere.md#roughness-sublayer, so U > 0 for every z > 0), and 0 below the ground
    (z < 0, where FLORIS's power law has no value either). Results for at most
    ``_AMBIENT_CACHED_HEIGHTS`` heights are kept for the next call with the same ABL and heights
    (read-only arrays). A row of heights ``(1, 1, 1, heights)`` for many conditions is
    evaluated by :func:`ambient_rows` (the same numbers)."""
    z = np.asarray(z, dtype=float)
    n_findex = _row_conditions(abl, z)
    if n_findex:
        return tuple(np.ascontiguousarray(values.T).reshape(n_findex, 1, 1, -1)
                     for values in ambient_rows(abl, z.reshape(-1), reference_height))
    if z.size > _AMBIENT_CACHED_HEIGHTS:
        return _ambient_velocity(abl, z, reference_height)
    key = (id(abl), z.shape, z.tobytes(), float(reference_height))
    return _cached(_AMBIENT_CACHE, key, abl,
                   lambda: _ambient_velocity(abl, z, reference_height))


#: Elements of the profile's work arrays per piece: a row of heights for many conditions (the
#: rotor cells' sub-point rows) is evaluated a few heights at a time, so that its temporaries
#: stay in cache instead of touching fresh memory for every one of the profile's operations.
_PROFILE_PIECE = 1 << 16


def _row_conditions(abl, z: np.ndarray) -> int:
    """n_findex if ``z`` is a row of heights (1, 1, 1, heights) that :func:`ambient_rows`
    evaluates for an ABL of n_findex conditions (attributes (n_findex, 1, 1, 1)) in pieces,
    else 0."""
    shape = np.shape(abl.friction_velocity)
    if len(shape) != 4 or shape[1:] != (1, 1, 1) or z.ndim != 4 or z.shape[:3] != (1, 1, 1):
        return 0
    return shape[0] if shape[0] * z.shape[3] > 2 * _PROFILE_PIECE else 0


def ambient_rows(abl, heights, reference_height: float):
    """:func:`ambient_velocity` at 1-D ``heights`` for every condition of an ABL with
    attributes (n_findex, 1, 1, 1): (U, V), each (heights, n_findex), read-only, kept for the
    next call with the same ABL and heights.

    The profile is elementwise in height and condition, so any grouping gives the same bits:
    it is evaluated ``_PROFILE_PIECE // n_findex`` heights at a time (at least one), with the
    conditions innermost (numpy's loops then run along the conditions, not along a few heights,
    and the temporaries stay in cache), the rotation to the hub frame computed once.
    """
    heights = np.asarray(heights, dtype=float).reshape(-1)
    key = (id(abl), heights.tobytes(), float(reference_height))
    return _cached(_ROWS_CACHE, key, abl, lambda: _rows_velocity(abl, heights, reference_height))


def _rows_velocity(abl, heights: np.ndarray, reference_height: float):
    n_findex = int(np.size(abl.friction_velocity))
    frame = abl.hub_frame(reference_height)
    U, V = np.empty((heights.size, n_findex)), np.empty((heights.size, n_findex))
    width = max(1, _PROFILE_PIECE // n_findex)
    for k in range(0, heights.size, width):
        # (heights, 1, 1, 1, 1) against the ABL's (n_findex, 1, 1, 1): (heights, n_findex, ...)
        u, v = _ambient_velocity(abl, heights[k:k + width].reshape(-1, 1, 1, 1, 1),
                                 reference_height, frame)
        U[k:k + width], V[k:k + width] = u.reshape(-1, n_findex), v.reshape(-1, n_findex)
    return U, V


def _ambient_velocity(abl, z, reference_height: float, frame=None):
    above = z >= 0.0
    if np.all(above):
        # Arrays also for a scalar height: callers cache them read-only.
        return tuple(np.asarray(a) for a in abl.hub_aligned_velocity(z, reference_height, frame))
    U, V = abl.hub_aligned_velocity(np.where(above, z, 0.0), reference_height, frame)
    return np.where(above, U, 0.0), np.where(above, V, 0.0)


# Relative height step of the centred difference for dU/dz: truncation ~ step^2 (1e-8 relative
# for the log law), round-off ~ 1e-16 U / (step z) (1e-12 relative at hub height).
_GRADIENT_STEP = 1e-4


def _profile_and_gradient(abl, z, reference_height):
    # dU/dz of the hub-aligned U by a centred difference of the profile (the ABL class exposes
    # no analytic gradient), with step 1e-4 max(z, z0): one-sided at the ground, where the
    # roughness sublayer's U is linear in z, and 0 below it. Across the kinks at 0.2 h and h
    # the difference averages the two slopes within +-1e-4 z of the kink.
    U, _ = ambient_velocity(abl, z, reference_height)
    step = _GRADIENT_STEP * np.maximum(z, np.asarray(abl.roughness_length))
    upper_z = z + step
    lower_z = np.maximum(z - step, 0.0)
    upper, _ = ambient_velocity(abl, upper_z, reference_height)
    lower, _ = ambient_velocity(abl, lower_z, reference_height)
    dUdz = np.where(z >= 0.0, (upper - lower) / (upper_z - lower_z), 0.0)
    return U, dUdz


# ---------------------------------------------------------------------------------------------
# What the wake models call


_ACTIVE: contextvars.ContextVar = contextvars.ContextVar("ekman_veer_atmosphere", default=None)

#: Context managers ``make(core)`` entered around every wrapped Core solve (the veer-aware rotor,
#: plugin/yawed_rotor.py, gives the operation models the Core's ambient V this way).
CORE_CONTEXTS: list = []
_SOLVED: dict = {}  # id(flow_field) -> (weakref to the flow field, EkmanABL)


def _remember(flow_field: FlowField, abl) -> None:
    key = id(flow_field)
    # FlowField is unhashable (attrs eq), so key on id and guard against id reuse with a weakref
    # whose callback drops the entry when the flow field is collected.
    _SOLVED[key] = (weakref.ref(flow_field, lambda _, key=key: _SOLVED.pop(key, None)), abl)


def solved_atmosphere(flow_field: FlowField):
    """The EkmanABL solved for ``flow_field``'s conditions (attributes ``(n_findex, 1, 1, 1)``).

    For wake models' ``prepare_function(grid, flow_field)``. Returns the instance built when the
    flow field was last initialised (no new solve). Raises ValueError if no atmosphere is
    configured.
    """
    entry = _SOLVED.get(id(flow_field))
    if entry is not None and entry[0]() is flow_field:
        return entry[1]
    spec = _ACTIVE.get()
    if spec is None:
        raise ValueError(
            f"the ekman_veer models need {CONFIG_PATH} in the FLORIS input (EkmanABL inputs "
            "without the wind speed); none is configured"
        )
    abl = solve(spec, flow_field.wind_speeds, flow_field.reference_wind_height)
    _remember(flow_field, abl)
    return abl


# ---------------------------------------------------------------------------------------------
# The wrappers


_ORIGINALS: dict = {}


def _initialize_velocity_field(self: FlowField, grid) -> None:
    original = _ORIGINALS[(FlowField, "initialize_velocity_field")]
    spec = _ACTIVE.get()
    if spec is None:
        return original(self, grid)
    abl = solve(spec, self.wind_speeds, self.reference_wind_height)
    # FLORIS's own initialisation with zero shear sets v, w, the TI fields and
    # u_initial = wind speed x heterogeneous speed-ups; only u needs the profile. (dudz from a
    # zero shear is 0 * z**-1, which warns at z = 0; it is overwritten.)
    wind_shear = self.wind_shear
    self.wind_shear = 0.0
    try:
        with np.errstate(divide="ignore", invalid="ignore"):
            original(self, grid)
    finally:
        self.wind_shear = wind_shear
    U, dUdz = inflow_profile(abl, grid.z_sorted, self.reference_wind_height)
    if isinstance(grid, TurbineGrid):
        # Each rotor point carries the cubic mean of U over its rotor cell (plugin/rotor.py).
        # (U alone: the gradient's two extra profile evaluations would be discarded.)
        U = turbine_grid_inflow(
            lambda heights: ambient_rows(abl, heights, self.reference_wind_height)[0], grid
        )
    shape = self.u_initial_sorted.shape
    if np.any(abl.at_rest):
        moving = ~abl.at_rest.reshape(-1, 1, 1, 1)
        U, dUdz = np.where(moving, U, 0.0), np.where(moving, dUdz, 0.0)
    if self.het_map is not None:
        speeds = self.wind_speeds[:, None, None, None]
        speed_ups = np.divide(self.u_initial_sorted, speeds, out=np.ones(shape), where=speeds > 0)
        U, dUdz = speed_ups * U, speed_ups * dUdz
    self.u_initial_sorted = np.broadcast_to(U, shape).copy()
    self.dudz_initial_sorted = np.broadcast_to(dUdz, shape).copy()
    self.u_sorted = self.u_initial_sorted.copy()
    _remember(self, abl)


def _with_core_atmosphere(method):
    """Run a Core method with the Core's atmosphere (or None) active for flow-field set-ups,
    after checking the operation (yaw) and, for ``solve_for_points``, the sample coordinates
    (:mod:`floris_ekman_veer.plugin.input_checks`)."""
    from floris_ekman_veer.plugin import input_checks

    points = method.__name__ == "solve_for_points"
    full_flow = points or method.__name__ == "solve_for_viz"

    @functools.wraps(method)
    def wrapper(self: Core, *args, **kwargs):
        atmosphere = atmosphere_of(self)
        if input_checks.uses_package(self, atmosphere):
            input_checks.check_operation(self)
            if points:
                input_checks.check_points(*args, **kwargs)
        with contextlib.ExitStack() as stack:
            # The atmosphere, which rotor average each turbine takes, and how the solver
            # combines wakes and adds turbulence (plugin/rotor.py), for the solve only.
            for variable, value in ((_ACTIVE, atmosphere),
                                    (TURBINE_MOMENTS,
                                     turbine_moments(self.farm.turbine_definitions)),
                                    (WAKE_MODELS, self.wake)):
                stack.callback(variable.reset, variable.set(value))
            # The package's per-wake warnings are said once, summarised, at the end of a solve.
            stack.enter_context(package_warnings.run_scope(self.flow_field.wind_speeds,
                                                           self.flow_field.reference_wind_height))
            rest = stack.enter_context(_at_rest(self, atmosphere))
            if method.__name__ != "steady_state_atmospheric_condition":
                # (run() initialises the domain first: said there, once)
                warn_shallow(self, atmosphere)
            for make in CORE_CONTEXTS:
                stack.enter_context(make(self))
            result = method(self, *args, **kwargs)
        if rest is not None:
            result = _still(self.flow_field, rest, result)
        if full_flow and input_checks.uses_wake_models(self):
            result = _without_reversed_flow(self.flow_field, result)
        return result

    return wrapper


@contextlib.contextmanager
def _at_rest(core: Core, atmosphere):
    """The conditions at rest of a Core's solve (None if there are none), FLORIS's divisions by
    their zero inflow quiet: their flow is set to 0 afterwards (:func:`_still`)."""
    rest = None
    if atmosphere is not None and core.flow_field.n_findex:
        abl = solve(atmosphere, core.flow_field.wind_speeds, core.flow_field.reference_wind_height)
        rest = abl.at_rest if np.any(abl.at_rest) else None
    if rest is None:
        yield None
        return
    with np.errstate(divide="ignore", invalid="ignore"):
        yield rest


def _still(flow_field: FlowField, rest, result):
    """No flow in the conditions at rest (FLORIS's own models divide by their zero inflow)."""
    for name in ("u_sorted", "v_sorted", "w_sorted", "u", "v", "w"):
        field = getattr(flow_field, name, None)
        if isinstance(field, np.ndarray) and field.ndim and field.shape[0] == rest.size:
            field[rest] = 0.0
    if isinstance(result, np.ndarray) and result.ndim and result.shape[0] == rest.size:
        result[rest] = 0.0
    return result


def _without_reversed_flow(flow_field: FlowField, result):
    """Superposed wakes at most stop the flow: u >= min(U(z), 0) on a full-flow grid (points,
    planes) of the package's wake models.

    Each wake's deficit is limited to the local inflow U(z) (the U_h-scaled Gaussian tail exceeds
    it next to the ground, docs/wake_model.md#which-velocity-goes-where), but FLORIS's
    sum-of-squares superposition of two such stopped wakes would give (1 - sqrt(2)) U(z). Where
    the inflow itself runs against the reference direction (collapsed layers a few metres deep,
    docs/atmosphere.md) the wake models add no deficit and u stays U(z). Rotor points lie far
    above that layer, so turbine grids need no bound.
    """
    floor = np.minimum(flow_field.u_initial_sorted, 0.0)
    flow_field.u_sorted = np.maximum(flow_field.u_sorted, floor)
    return None if result is None else np.maximum(result, floor[:, :, 0, 0])


def _validating_post_init(method):
    """Validate the atmosphere, and the layout, conditions and turbines of a Core using the
    package (:func:`floris_ekman_veer.plugin.input_checks.check_core`, before FLORIS builds
    its grid), when a Core is built (FlorisModel(), set(), copy())."""
    from floris_ekman_veer.plugin import input_checks, shallow

    @functools.wraps(method)
    def wrapper(self: Core) -> None:
        spec = atmosphere_of(self)
        if input_checks.uses_package(self, spec):
            input_checks.check_core(self, spec)
        method(self)
        if spec is not None and self.flow_field.n_findex:
            _check_solved_conditions(self, spec)
        elif spec is not None:
            # No conditions yet (n_findex = 0): nothing to solve until set() gives them.
            shallow.policy(self.wake.wake_velocity_parameters.get(PARAMETER_BLOCK))

    return wrapper


def _reference_height(core: Core) -> float | None:
    """The Core's reference wind height, FLORIS's "use the hub height" sentinel (-1, which
    FlorisModel replaces without a rebuild) read as the hub height; None where FLORIS refuses
    the sentinel (several hub heights)."""
    height = core.flow_field.reference_wind_height
    if abs(height + 1.0) < 1e-6:
        hubs = np.unique(core.farm.hub_heights)
        if hubs.size != 1:
            return None
        height = float(hubs[0])
    return height


def _check_shallow(core: Core, abl, height: float, stage: str) -> None:
    from floris_ekman_veer.plugin import shallow

    shallow.check_rotor_inside(
        core.wake.wake_velocity_parameters.get(PARAMETER_BLOCK),
        np.where(abl.at_rest, np.inf, np.reshape(abl.boundary_layer_height, -1)),
        core.flow_field.wind_speeds, height, core.farm.hub_heights, core.farm.rotor_diameters,
        stage=stage,
    )


def warn_shallow(core: Core, spec: AtmosphereSpec | None = None) -> None:
    """Count a Core's conditions whose boundary layer is shallower than a rotor top in one
    :class:`~floris_ekman_veer.warnings.ShallowBoundaryLayerWarning` (plugin/shallow.py), at
    the user's run: every Core solve, the ParFlorisModel parent before its workers (sent with
    the policy ``ignore``) and ``optimize_yaw`` before its many re-built models. ``spec``: the
    Core's atmosphere, if known (else read)."""
    spec = atmosphere_of(core) if spec is None else spec
    if spec is None or not core.flow_field.n_findex:
        return
    height = _reference_height(core)
    if height is not None:
        _check_shallow(core, solve(spec, core.flow_field.wind_speeds, height), height, "run")


def _check_solved_conditions(core: Core, spec: AtmosphereSpec) -> None:
    """At build: the shallow-boundary-layer policy ``raise`` (plugin/shallow.py; ``warn``
    counts them at the first run instead, :func:`warn_shallow`), hubs in the roughness
    sublayer, a heterogeneous map given with the atmosphere (warned), and FLORIS's turbulence
    intensities the ekman_veer model does not read (said)."""
    from floris_ekman_veer.plugin import input_checks

    flow_field = core.flow_field
    height = _reference_height(core)
    if height is None:
        return  # FLORIS refuses it
    abl = solve(spec, flow_field.wind_speeds, height)
    _check_shallow(core, abl, height, "build")
    input_checks.notice_unused_turbulence(core, abl, spec)
    sublayer = np.max(np.where(abl.at_rest, 0.0, np.reshape(abl.roughness_sublayer_height, -1)))
    low = np.flatnonzero(np.asarray(core.farm.hub_heights, dtype=float) < sublayer)
    if low.size:
        package_warnings.warn(
            f"{low.size} turbine(s) (turbine {', '.join(str(i) for i in low[:5])}) have the hub "
            f"in the roughness sublayer (below {sublayer:.3g} m), where the wind "
            "falls linearly to 0 at the ground (docs/atmosphere.md#roughness-sublayer): no "
            "measured wake or turbine stands there",
            package_warnings.TurbinePlacementWarning,
            items=[("sublayer", int(i)) for i in low],
        )
    if flow_field.heterogeneous_inflow_config is not None:
        package_warnings.warn(
            f"flow_field.heterogeneous_inflow_config is given with {CONFIG_PATH}: each "
            "condition's ABL is solved from flow_field.wind_speeds (the speed before the map's "
            "speed-ups) and its profile U(z) is multiplied by the speed-ups at each point, so h, "
            "veer and turbulence are those of the unmultiplied wind everywhere "
            "(docs/user_guide.md#heterogeneous-inflow)",
            package_warnings.HeterogeneousInflowWarning,
        )


@contextlib.contextmanager
def _replaced_atmosphere(core: Core, atmosphere: Mapping | None):
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
    with _replaced_atmosphere(fmodel.core, atmosphere):
        fmodel.set(**set_kwargs)


def _slicing_set_for_viz(method):
    """FlorisModel.set_for_viz keeps one condition: keep that condition's atmosphere too."""

    @functools.wraps(method)
    def wrapper(self, findex: int, solver_settings: dict) -> None:
        spec = atmosphere_of(self.core)
        if spec is None or spec.n_conditions is None:
            return method(self, findex, solver_settings)
        with _replaced_atmosphere(self.core, spec.sliced(slice(findex, findex + 1))):
            return method(self, findex, solver_settings)

    return wrapper


def _patch(owner, name: str, make_wrapper) -> None:
    """Replace ``owner.name`` by ``make_wrapper(original)`` once (idempotent); the original is
    kept for :func:`uninstall_inflow_hook`."""
    if (owner, name) in _ORIGINALS:
        return
    original = owner.__dict__[name]
    _ORIGINALS[(owner, name)] = original
    setattr(owner, name, make_wrapper(original))


def install_inflow_hook() -> None:
    """Install the class-level wrappers (idempotent). Without an atmosphere block they are no-ops.

    Patched: ``FlowField.initialize_velocity_field``; ``Core.__attrs_post_init__`` (validation),
    ``Core.initialize_domain``, ``steady_state_atmospheric_condition``, ``solve_for_viz``,
    ``solve_for_points``, ``solve_for_velocity_deficit_profiles`` (atmosphere context);
    ``FlorisModel.set_for_viz`` (slices per-condition lists). ParFlorisModel's condition
    splitting, UncertainFlorisModel's expansion and the yaw optimisers are installed by
    :func:`floris_ekman_veer.plugin.parallel.install_parallel_hook`,
    :func:`floris_ekman_veer.studies.uncertain.install_uncertain_hook` and
    :func:`floris_ekman_veer.studies.optimization.install_optimizer_hook` (this module imports
    none of them: imports point one way, docs/coupling.md#parallel-workers).
    """
    _patch(
        FlowField, "initialize_velocity_field",
        lambda original: functools.wraps(original)(_initialize_velocity_field),
    )
    _patch(Core, "__attrs_post_init__", _validating_post_init)
    for name in (
        "initialize_domain",
        "steady_state_atmospheric_condition",
        "solve_for_viz",
        "solve_for_points",
        "solve_for_velocity_deficit_profiles",
    ):
        _patch(Core, name, _with_core_atmosphere)
    _patch(FlorisModel, "set_for_viz", _slicing_set_for_viz)


def uninstall_inflow_hook() -> None:
    """Restore every patched FLORIS method (for tests and for comparisons with plain FLORIS)."""
    for (owner, name), original in list(_ORIGINALS.items()):
        setattr(owner, name, original)
        del _ORIGINALS[(owner, name)]


def is_installed() -> bool:
    return bool(_ORIGINALS)
