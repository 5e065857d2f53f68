"""FLORIS's yaw optimisers on per-condition atmospheres: the patches, in rows of the patch table.

A user may build FLORIS's ``YawOptimizationSR``, ``YawOptimizationScipy`` or
``YawOptimizationGeometric`` on a model with a per-condition atmosphere and call its
``optimize()`` (docs/coupling.md#yaw-optimisation). The optimisers tile, mask and re-order the
model's conditions, which a per-condition atmosphere cannot follow, so on such a model
``optimize()`` runs :func:`~floris_ekman_veer.plugin.floris_tools.optimizer_conditions.optimize_each_atmosphere`
with the options the optimiser was built with (recorded by its ``__init__``) and stores the
results as FLORIS stores them. On a scalar atmosphere, or none, FLORIS's own ``optimize()`` runs.

:data:`PATCHES` lists the patched attributes; ``registry.register()`` installs them.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable

import attrs
import numpy as np
from floris.optimization.yaw_optimization.yaw_optimization_base import YawOptimization
from floris.optimization.yaw_optimization.yaw_optimizer_geometric import YawOptimizationGeometric
from floris.optimization.yaw_optimization.yaw_optimizer_scipy import YawOptimizationScipy
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

from floris_ekman_veer.plugin.inflow.inflow import atmosphere_of, warn_shallow
from floris_ekman_veer.plugin.floris_tools.optimizer_conditions import (
    DEFAULT_CHUNK_SIZE,
    optimize_each_atmosphere,
)
from floris_ekman_veer.plugin.floris_tools.optimizer_options import checked_options
from floris_ekman_veer.plugin.floris_hooks.patches import Patch, wrapped




def _recording_init(original):
    """Keep the user's own constructor call (the outermost ``__init__``): its options are those
    the optimiser is rebuilt with per atmosphere."""

    @functools.wraps(original)
    def wrapper(self, *args, **kwargs):
        if type(self).__init__ is wrapper and "_optimize_yaw_options" not in self.__dict__:
            signature = inspect.signature(original)
            own, model = list(signature.parameters)[:2]
            arguments = signature.bind(self, *args, **kwargs).arguments
            self._optimize_yaw_options = {
                k: v for k, v in arguments.items() if k not in (own, model)
            }
        return original(self, *args, **kwargs)

    return wrapper


def _dispatching_optimize(original):
    """On a per-condition atmosphere, ``optimize()`` is one run of the optimiser per atmosphere
    (as ``optimize_yaw(..., search="single")``) with the options the optimiser was built with;
    its results are also stored as FLORIS stores them."""

    @functools.wraps(original)
    def wrapper(self, *args, **kwargs):
        # The model's shallow conditions counted once, in its own numbers: the optimiser's
        # tiled copies then report nothing new.
        warn_shallow(self.fmodel.core)
        spec = atmosphere_of(self.fmodel.core)
        if (spec is None or spec.n_conditions is None
                or "_atmosphere_rows" in self.fmodel.__dict__):  # a row_following_subset
            return original(self, *args, **kwargs)
        options = self.__dict__.get("_optimize_yaw_options")
        if options is None:
            raise ValueError(
                f"{type(self).__name__} on a per-condition atmosphere: call "
                "floris_ekman_veer.optimize_yaw(fmodel, optimizer_class, **options) (the "
                "options of this subclass's constructor are not known here)"
            )
        bound = inspect.signature(original).bind(self, *args, **kwargs).arguments
        progress = bound.get("print_progress")
        options = checked_options(self.fmodel, type(self), progress, options)
        warn_shallow(self.fmodel.core)
        df = optimize_each_atmosphere(self.fmodel, type(self), progress=progress,
                                      chunk_size=DEFAULT_CHUNK_SIZE, **options)
        self.yaw_angles_opt = np.vstack(df.yaw_angles_opt.to_numpy())
        self.farm_power_opt = (
            None if df.farm_power_opt.isna().all() else df.farm_power_opt.to_numpy(dtype=float)
        )
        return df

    return wrapper


_RECORD = ("keeps the options of the user's constructor call, with which {name} "
           "rebuilds the optimiser per atmosphere on a per-condition atmosphere")
_DISPATCH = ("the optimiser tiles, masks and re-orders its model's conditions, which a "
             "per-condition atmosphere cannot follow: on one, optimize() runs the optimiser "
             "once per distinct atmosphere (plugin/floris_tools/optimizer_conditions.py)")

#: FLORIS's yaw optimisers' patched attributes (FLORIS 4.7: the base class defines
#: ``__init__``, each of its three optimisers ``__init__`` and ``optimize``).
PATCHES: tuple[Patch, ...] = (
    wrapped(YawOptimization, "__init__", _recording_init, _RECORD.format(name="a subclass's optimize()")),
    *(row for cls in (YawOptimizationSR, YawOptimizationScipy, YawOptimizationGeometric)
      for row in (wrapped(cls, "__init__", _recording_init, _RECORD.format(name=f"{cls.__name__}.optimize()")),
                  wrapped(cls, "optimize", _dispatching_optimize, _DISPATCH))),
)


def install_optimizer_hook() -> None:
    """Install :data:`PATCHES` (idempotent; ``register()`` calls it)."""
    for row in PATCHES:
        row.install()
