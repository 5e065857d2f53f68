"""ParFlorisModel support: registration in every worker, per-condition atmospheres split.

ParFlorisModel (FLORIS 4.7) sends each worker ``(fmodel_dict, set_args)`` and the worker builds a
plain ``FlorisModel(fmodel_dict)``. Two things must hold there:

* The package's models and the inflow hook must be installed in the worker. With the ``fork``
  start method they are inherited; with ``spawn`` or ``forkserver`` (the default on macOS and
  Windows, and from Python 3.14 on Linux) the worker starts from a fresh interpreter that imports
  only FLORIS, and a model registered in the parent is missing (docs/coupling.md#parallel-workers). ParFlorisModel
  offers no pool initializer, so the dictionary sent to each worker is a :class:`WorkerDict`,
  whose unpickling calls :func:`prepare_worker` before FLORIS sees it.
* Per-condition atmosphere lists (length n_findex of the parent) are cut to the worker's share of
  conditions, and so are the flow-field condition arrays of that dictionary, so that the worker's
  ``FlorisModel(fmodel_dict)`` is self-consistent before ``set(**set_args)`` is applied.

For a pool of your own, pass ``initializer=prepare_worker``.
"""

from __future__ import annotations

import functools

import numpy as np

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer.plugin.floris_hooks import patching
from floris_ekman_veer.plugin.inflow import shallow
from floris_ekman_veer.plugin.inflow.inflow import (
    ATMOSPHERE_KEY,
    PARAMETER_BLOCK,
    atmosphere_of,
    warn_shallow,
)


def prepare_worker() -> None:
    """Make this process ready to build the package's FLORIS models (idempotent).

    Reaching this function imports ``floris_ekman_veer`` (Python imports a package before its
    modules; unpickling looks the function up by module name), and that import registers the models
    and installs the package's FLORIS patches (plugin/floris_hooks/patches.py); this call then puts the
    patches back, should they have been uninstalled in this process. It imports nothing above it
    (docs/coupling.md#parallel-workers).
    """
    patching.reinstall()


def _unpickle_worker_dict(data: dict, warnings_setting: str | None = None) -> dict:
    prepare_worker()
    package_warnings.apply_setting(warnings_setting)
    return data


class WorkerDict(dict):
    """A FLORIS input dict that prepares the receiving process when it is unpickled, and carries
    the sender's silencing of the package's warnings (floris_ekman_veer.warnings)."""

    def __reduce__(self):
        return _unpickle_worker_dict, (dict(self), package_warnings.warnings_setting())


# Flow-field entries that are per condition in FloriS's input dict.
_CONDITION_KEYS = ("wind_directions", "wind_speeds", "turbulence_intensities")


def splitting_preprocessing(method):
    """ParFlorisModel._preprocessing: per-condition atmospheres cut to each worker's share, the
    shallow-layer count left to the parent, the dict sent as a :class:`WorkerDict`."""
    @functools.wraps(method)
    def wrapper(self):
        multiargs = method(self)
        spec = atmosphere_of(self.core)
        per_condition = spec is not None and spec.n_conditions is not None
        result, start = [], 0
        for fmodel_dict, set_args in multiargs:
            # ParFlorisModel splits conditions into contiguous, ordered chunks (np.array_split).
            share = slice(start, start + len(set_args["wind_speeds"]))
            start = share.stop
            block = fmodel_dict["wake"]["wake_velocity_parameters"].get(PARAMETER_BLOCK)
            if spec is not None and block.get(shallow.POLICY_KEY, "warn") == "warn":
                # The parent counts its shallow conditions once, at the user's run
                # (:func:`reporting_parent`): not again per chunk.
                block[shallow.POLICY_KEY] = "ignore"
            if per_condition:
                flow_field = fmodel_dict["flow_field"]
                for key in _CONDITION_KEYS:
                    flow_field[key] = np.asarray(flow_field[key])[share].tolist()
                block = fmodel_dict["wake"]["wake_velocity_parameters"][PARAMETER_BLOCK]
                block[ATMOSPHERE_KEY] = spec.sliced(share)
            result.append((WorkerDict(fmodel_dict), set_args))
        return result

    return wrapper


#: FLORIS's functions that run a chunk of conditions in a worker process.
WORKER_FUNCTIONS = ("_parallel_run", "_parallel_run_powers_only",
                     "_parallel_sample_flow_at_points", "_parallel_sample_ti_at_points")


class RecordingWorker:
    """A worker's chunk: the package's warnings are recorded and travel back with the result,
    for the parent to report once at the user's line (floris_ekman_veer.warnings), instead of
    being printed by each worker at the pool's frame with the worker's share of the counts.

    The pool pickles the function it runs ahead of its arguments (the :class:`WorkerDict`). By
    FLORIS's name, a ``spawn`` or ``forkserver`` worker that has not imported this package would
    unpickle FLORIS's function unwrapped; so it is pickled as a call of :func:`_worker_function`,
    which imports the package first (docs/coupling.md#parallel-workers)."""

    def __init__(self, function):
        functools.update_wrapper(self, function)

    def __call__(self, *args, **kwargs):
        with package_warnings.collecting() as records:
            result = self.__wrapped__(*args, **kwargs)
        return package_warnings.carrying(result, records)

    def __reduce__(self):
        return _worker_function, (self.__name__,)


def _worker_function(name: str):
    """Unpickle a :class:`RecordingWorker`: prepare this process, then hand over FLORIS's worker
    function ``name`` as this process has it wrapped."""
    import floris.par_floris_model as par

    prepare_worker()
    return getattr(par, name)


def reporting_parent(method):
    """ParFlorisModel.run / _sample_value_at_points: count the shallow conditions of all the
    parent's conditions once (its workers are sent the policy ``ignore``), and report what the
    workers recorded."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        warn_shallow(self.core)
        package_warnings.discard_from_workers()
        result = method(self, *args, **kwargs)
        package_warnings.report_from_workers(self.core.flow_field.n_findex)
        return result

    return wrapper
