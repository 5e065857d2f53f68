"""The options of FLORIS's yaw optimisers as :func:`~floris_ekman_veer.optimize_yaw` and the
optimisers' ``optimize()`` on a per-condition atmosphere take them: checked before any FLORIS
evaluation, with both signs of yaw searched where the caller gives no bounds, and cut to a
subset of conditions where they are given per condition.
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping

import numpy as np
from floris.optimization.yaw_optimization.yaw_optimization_base import YawOptimization

from floris_ekman_veer._validation import real_array, require_floris_model

#: Optimiser options that may be given per condition, as (n_findex, n_turbines) arrays.
PER_CONDITION_OPTIONS = (
    "minimum_yaw_angle", "maximum_yaw_angle", "yaw_angles_baseline", "x0", "turbine_weights",
)

#: Methods of scipy.optimize.minimize (YawOptimizationScipy's ``opt_method``).
SCIPY_METHODS = (
    "nelder-mead", "powell", "cg", "bfgs", "newton-cg", "l-bfgs-b", "tnc", "cobyla", "cobyqa",
    "slsqp", "trust-constr", "dogleg", "trust-ncg", "trust-exact", "trust-krylov",
)

#: The yaw bounds [deg] :func:`~floris_ekman_veer.optimize_yaw` searches where the caller gives
#: none: both signs. FLORIS's optimisers default to 0..25 deg, one sign only; with veer the two
#: signs differ and the gain can lie on the negative side
#: (docs/yaw_steering.md#both-signs-by-default). A bound the caller gives is kept as given.
DEFAULT_YAW_BOUNDS = {"minimum_yaw_angle": -25.0, "maximum_yaw_angle": 25.0}


def checked_options(fmodel, optimizer_class, progress, options: Mapping) -> dict:
    """``options`` with :data:`DEFAULT_YAW_BOUNDS` where no bound is given, after checking the
    model (it has conditions), ``progress`` and every option (:func:`check_optimizer_options`),
    before any FLORIS evaluation."""
    require_floris_model(fmodel, "optimize_yaw")
    n_findex = fmodel.core.flow_field.n_findex
    if n_findex == 0:
        raise ValueError(
            "optimize_yaw: the model has no conditions (n_findex = 0): give at least one wind "
            "direction, wind speed and turbulence intensity with fmodel.set(...)"
        )
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise TypeError(f"optimize_yaw: progress must be True, False or None; got {progress!r}")
    options = with_default_yaw_bounds(optimizer_class, options)
    check_optimizer_options(optimizer_class, options, n_findex, fmodel.core.farm.n_turbines)
    return options


def options_for_conditions(options: Mapping, index) -> dict:
    """The options for the conditions ``index``: those of :data:`PER_CONDITION_OPTIONS` given as
    (n_findex, n_turbines) arrays cut to their rows, the others as given."""
    return {name: np.asarray(value, dtype=float)[index]
            if name in PER_CONDITION_OPTIONS and np.ndim(value) == 2 else value
            for name, value in options.items()}


def with_default_yaw_bounds(optimizer_class, options: Mapping) -> dict:
    """``options`` with :data:`DEFAULT_YAW_BOUNDS` for the bounds the caller did not give (for
    optimisers that take them): without bounds the search covers both signs of yaw."""
    options = dict(options)
    if inspect.isclass(optimizer_class):
        accepted = inspect.signature(optimizer_class.__init__).parameters
        for name, bound in DEFAULT_YAW_BOUNDS.items():
            if name in accepted and name not in options:
                options[name] = bound
    return options


def check_optimizer_options(optimizer_class, options: Mapping, n_findex: int, n_turbines: int):
    """Raise ValueError for options ``optimizer_class`` does not take or would reject.

    FLORIS checks some options only after its baseline farm evaluation (``Ny_passes``), passes
    others on to SciPy at the first optimisation (``opt_method``), or fails with a TypeError
    (unknown names); here all of them fail before any work, with the option named.
    """
    if not (inspect.isclass(optimizer_class) and issubclass(optimizer_class, YawOptimization)):
        raise ValueError(
            "optimize_yaw: optimizer_class must be a FLORIS yaw optimiser class (a subclass of "
            "floris.optimization.yaw_optimization.yaw_optimization_base.YawOptimization); got "
            f"{optimizer_class!r}"
        )
    name = optimizer_class.__name__
    accepted = [
        p.name for p in list(inspect.signature(optimizer_class.__init__).parameters.values())[2:]
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
    ]
    unknown = sorted(set(options) - set(accepted))
    if unknown:
        raise ValueError(
            f"optimize_yaw: {name} has no option(s) {unknown}; its options are {accepted} "
            "(the model is optimize_yaw's first argument)"
        )

    def angles(option, default):
        value = options.get(option, default)
        if value is None:
            return None
        array = real_array(f"optimize_yaw: {name} option {option}", value,
                           "a number, a list of one per turbine or an (n_findex, n_turbines) array")
        if array.shape not in ((), (n_turbines,), (n_findex, n_turbines)) or not np.all(
            np.isfinite(array)
        ):
            raise ValueError(
                f"optimize_yaw: {name} option {option} must be a finite number, a list of "
                f"n_turbines = {n_turbines} numbers or an (n_findex, n_turbines) = "
                f"({n_findex}, {n_turbines}) array; got {value!r}"
            )
        return array

    defaults = inspect.signature(optimizer_class.__init__).parameters
    lower = angles("minimum_yaw_angle", defaults["minimum_yaw_angle"].default)
    upper = angles("maximum_yaw_angle", defaults["maximum_yaw_angle"].default)
    if np.any(lower > upper):
        raise ValueError(
            f"optimize_yaw: {name} minimum_yaw_angle must not exceed maximum_yaw_angle; got "
            f"{options.get('minimum_yaw_angle')!r} > {options.get('maximum_yaw_angle')!r}"
        )
    if np.any(np.abs(lower) >= 90.0) or np.any(np.abs(upper) >= 90.0):
        raise ValueError(
            f"optimize_yaw: {name} yaw bounds must lie within (-90, 90) degrees; got "
            f"minimum_yaw_angle={options.get('minimum_yaw_angle')!r}, "
            f"maximum_yaw_angle={options.get('maximum_yaw_angle')!r}"
        )
    for option in ("yaw_angles_baseline", "turbine_weights"):
        angles(option, None)
    x0 = angles("x0", None)
    if x0 is not None and (np.any(x0 < lower) or np.any(x0 > upper)):
        raise ValueError(
            f"optimize_yaw: {name} option x0 must lie within [minimum_yaw_angle, "
            f"maximum_yaw_angle]; got {options['x0']!r}"
        )
    if "Ny_passes" in options:
        passes = options["Ny_passes"]
        if (
            not isinstance(passes, (list, tuple)) or not passes
            or not all(isinstance(n, int) and not isinstance(n, bool) and n >= 2 for n in passes)
            or any(n % 2 for n in passes[1:])
        ):
            raise ValueError(
                f"optimize_yaw: {name} option Ny_passes must be a non-empty list of integers "
                f">= 2, all but the first even; got {passes!r}"
            )
    if "opt_method" in options:
        method = options["opt_method"]
        if not callable(method) and str(method).lower() not in SCIPY_METHODS:
            raise ValueError(
                f"optimize_yaw: {name} option opt_method must be a scipy.optimize.minimize "
                f"method {list(SCIPY_METHODS)} or a callable; got {method!r}"
            )
    if options.get("opt_options") is not None and not isinstance(options["opt_options"], Mapping):
        raise ValueError(
            f"optimize_yaw: {name} option opt_options must be a dict of "
            f"scipy.optimize.minimize options; got {options['opt_options']!r}"
        )

