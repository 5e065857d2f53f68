"""Every FLORIS attribute the package patches, in one table: what, why, and the FLORIS version it
was checked against (docs/coupling.md#what-is-patched, whose table is this one).

FLORIS 4.7 has no extension point for another inflow, another rotor, per-condition atmospheres
or a faster solver of the package's wakes, so the package wraps these attributes. Each row's
``install`` replaces its attribute once (idempotent) through the mechanism of
:mod:`floris_ekman_veer.plugin.floris_hooks.patching` (:func:`patch`, re-exported here with
:func:`original`, :func:`uninstall`, :func:`reinstall` and :func:`is_installed`);
``registry.register()`` installs the rows by walking the tables, and nothing else installs a
patch. Every wrapper calls FLORIS's own attribute, and nothing else, where no atmosphere is
configured or the package's models are not selected: results are then bitwise those of plain
FLORIS.

A table is a tuple of :class:`Patch` rows; this module's :data:`PATCHES` holds the plugin's.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import attrs
import floris.core.core as floris_core
import floris.par_floris_model as floris_parallel
from floris.core import Core, FlowField
from floris.core.farm import Farm
from floris.core.turbine import operation_models
from floris.core.turbine.operation_models import CosineLossTurbine
from floris.core.wake import WakeModelManager
from floris.floris_model import FlorisModel
from floris.par_floris_model import ParFlorisModel
from floris.uncertain_floris_model import UncertainFlorisModel

from floris_ekman_veer.plugin.floris_tools import parallel
from floris_ekman_veer.plugin.inflow import core_build, core_solve
from floris_ekman_veer.plugin.rotor import yawed_rotor
from floris_ekman_veer.plugin.inflow.inflow import initialize_velocity_field
from floris_ekman_veer.plugin.floris_hooks.patching import (
    is_installed,
    original,
    patch,
    reinstall,
    uninstall,
)
from floris_ekman_veer.plugin.floris_hooks.solver import handing_full_flow, install_solver_hook
from floris_ekman_veer.plugin.floris_tools.uncertain_conditions import per_condition_set_uncertain
from floris_ekman_veer.plugin.wake_models.wake_settings import converting_post_init

__all__ = ["CHECKED_AGAINST", "PATCHES", "Patch", "is_installed", "markdown_table", "original",
           "patch", "reinstall", "uninstall", "wrapped"]

#: The FLORIS version every row was checked against (the one the package requires, 4.7.x).
CHECKED_AGAINST = "4.7"


@attrs.define(frozen=True)
class Patch:
    """One patched FLORIS attribute."""

    #: Dotted path of what is patched, e.g. ``"floris.core.solver.sequential_solver"``.
    owner: str
    #: One sentence: why the package must patch it.
    why: str
    #: The FLORIS version it was checked against, e.g. ``"4.7"``.
    checked_against: str
    #: Installs it (idempotent); :func:`uninstall` restores FLORIS's own.
    install: Callable[[], None]


def _dotted(owner) -> str:
    """A class's or a module's dotted path."""
    if isinstance(owner, type):
        return f"{owner.__module__}.{owner.__qualname__}"
    return owner.__name__


def wrapped(owner, name: str, make_wrapper: Callable, why: str) -> Patch:
    """The row of ``owner.name`` replaced by ``make_wrapper(FLORIS's own)``."""
    return Patch(owner=f"{_dotted(owner)}.{name}", why=why, checked_against=CHECKED_AGAINST,
                 install=functools.partial(patch, owner, name, make_wrapper))


_SOLVE = ("makes the Core's atmosphere, its turbines' rotor averages and wake models and the "
          "veer-aware rotor active for the {what}, says the package's warnings once and keeps "
          "conditions at rest still")
_WORKER = ("records the package's warnings in the worker for the parent to report once, and "
           "pickles as a call into the package so that a spawn worker imports it first")
_GETTER = ("gives the operation models the Core's ambient V when FLORIS re-evaluates turbine "
           "{what} outside a solve")
_SOLVER = ("FLORIS's sequential solver updates every rotor at each step; on a turbine grid the "
           "package's velocity models update only the rotors each wake reaches, with the same "
           "results (plugin/floris_hooks/solver.py)")

PATCHES: tuple[Patch, ...] = (
    # The inflow (plugin/inflow/inflow.py) and the Core's builds and solves (core_build, core_solve).
    wrapped(FlowField, "initialize_velocity_field", initialize_velocity_field,
            "FLORIS builds a power-law inflow and has no extension point for another profile: "
            "the atmosphere's U(z) and dU/dz replace it when one is configured"),
    wrapped(Core, "__attrs_post_init__", core_build.validating_post_init,
            "validates the atmosphere block and the layout, conditions and turbines of a Core "
            "using the package when it is built, so that bad input fails early, named"),
    *(wrapped(Core, name, core_solve.with_core_atmosphere, _SOLVE.format(what=what) + more)
      for name, what, more in (
          ("initialize_domain", "flow-field initialisation of a run", ""),
          ("steady_state_atmospheric_condition", "turbine-grid solve of a run", ""),
          ("solve_for_viz", "plane solve", "; never reverses the flow"),
          ("solve_for_points", "point solve", "; checks the points, never reverses the flow"),
          ("solve_for_velocity_deficit_profiles", "deficit-profile solve", ""))),
    wrapped(FlorisModel, "set_for_viz", core_solve.slicing_set_for_viz,
            "keeps one condition for a plane: per-condition atmosphere lists are cut to it"),
    # ParFlorisModel (plugin/floris_tools/parallel.py).
    wrapped(ParFlorisModel, "_preprocessing", parallel.splitting_preprocessing,
            "cuts per-condition atmospheres to each worker's share of conditions and sends a "
            "dict whose unpickling prepares the worker"),
    *(wrapped(ParFlorisModel, name, parallel.reporting_parent,
              "counts the shallow conditions once in the parent and reports its workers' "
              "warnings once, at the user's line")
      for name in ("run", "_sample_value_at_points")),
    *(wrapped(floris_parallel, name, parallel.RecordingWorker, _WORKER)
      for name in parallel.WORKER_FUNCTIONS),
    # UncertainFlorisModel (plugin/floris_tools/uncertain_conditions.py).
    wrapped(UncertainFlorisModel, "_set_uncertain", per_condition_set_uncertain,
            "carries per-condition atmospheres through the expansion and de-duplication of "
            "conditions, never merging conditions of different atmospheres"),
    # The wake inputs (plugin/wake_models/wake_settings.py).
    wrapped(WakeModelManager, "__attrs_post_init__", converting_post_init,
            "completes the package's models' parameter blocks and warns when a FLORIS input "
            "mixes them with FLORIS's own settings"),
    # The veer-aware rotor (plugin/rotor/yawed_rotor.py).
    *(wrapped(CosineLossTurbine, name, functools.partial(yawed_rotor.veer_aware_operation,
                                                         kind=kind), why)
      for name, kind, why in (
          ("power", "power", "FLORIS's cosine loss takes U alone; a yawed rotor in veer sees the "
                             "normal velocity U cos(beta) + V sin(beta) per rotor cell"),
          ("thrust_coefficient", "thrust", "the rotor-normal force of a yawed rotor in veer "
                                           "follows the normal velocity's square per rotor "
                                           "cell, held to FLORIS's own clip"))),
    wrapped(operation_models, "interp1d", yawed_rotor.sharing_interpolant,
            "FLORIS's power-curve turbines build their table's interpolant at every call, "
            "i.e. at every step of a solve; the package's solver has them build it once per "
            "solve and table (the same interpolant, the same bits)"),
    *(wrapped(FlorisModel, name, yawed_rotor.with_crossflow, _GETTER.format(what=what))
      for name, what in (("_get_turbine_powers", "powers"),
                         ("get_turbine_thrust_coefficients", "thrust coefficients"),
                         ("get_turbine_ais", "axial inductions"))),
    wrapped(Farm, "initialize", yawed_rotor.registering_farm,
            "a farm deep-copied by FLORIS's full-flow solvers joins the Core's crossflow "
            "look-up, so that its flow field carries the wakes of the thrust the powers see"),
    # The solver (plugin/floris_hooks/solver.py).
    Patch(owner="floris.core.core.sequential_solver", why=_SOLVER + ": FLORIS's dispatch of a run",
          checked_against=CHECKED_AGAINST, install=install_solver_hook),
    Patch(owner="floris.core.solver.sequential_solver",
          why=_SOLVER + ": the turbine-grid solve inside FLORIS's full-flow solvers; on a "
                        "cubature grid the package's wakes take a turbine-grid solve's rotor "
                        "states (plugin/rotor/turbine_states.py)",
          checked_against=CHECKED_AGAINST, install=install_solver_hook),
    wrapped(floris_core, "full_flow_sequential_solver", handing_full_flow,
            "FLORIS hands its turbine-grid solve's thrust and turbulence to the flow-field grid "
            "but not the package's rotor states (incoming speeds, array turbulence): its planes "
            "and points take them too, so that they show the wakes the powers have "
            "(plugin/rotor/turbine_states.py)"),
)


def markdown_table(rows) -> str:
    """``rows`` (Patch) as the Markdown table of docs/coupling.md#what-is-patched."""
    lines = ["| What is patched | Why | FLORIS |", "|---|---|---|"]
    lines += [f"| `{row.owner}` | {row.why} | {row.checked_against} |" for row in rows]
    return "\n".join(lines)
