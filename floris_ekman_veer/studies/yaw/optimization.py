"""Yaw optimisation with FLORIS's optimisers on models whose atmosphere varies per condition.

FLORIS's yaw optimisers tile, mask and re-order their model's conditions internally (the Serial
Refine evaluates ``Ny`` copies of every condition at once and skips those already in memory;
the SciPy optimiser sets one condition at a time), so a per-condition atmosphere list
(docs/coupling.md#yaw-optimisation), which binds to conditions by position, cannot follow them.
Every condition's optimum depends on that condition alone, so :func:`optimize_yaw` runs the
optimiser once per distinct atmosphere (and per chunk of conditions, for the progress bar) on
a model holding just those conditions with that atmosphere as scalars, and puts the rows of
FLORIS's ``df_opt`` frames back in the caller's order. The result is, by construction, the
result of running each distinct atmosphere on its own (tests/studies/yaw/test_optimization.py measures it):
plugin/floris_tools/optimizer_conditions.py runs them, plugin/floris_tools/optimizer_options.py checks the options
first. The default search over both signs of yaw is studies/yaw/yaw_search.py.
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import io

import numpy as np
import pandas as pd
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

from floris_ekman_veer.plugin.inflow.inflow import warn_shallow
from floris_ekman_veer.plugin.floris_tools.optimizer_conditions import (
    DEFAULT_CHUNK_SIZE,
    optimize_each_atmosphere,
)
from floris_ekman_veer.plugin.floris_tools.optimizer_options import checked_options
from floris_ekman_veer.studies.yaw.yaw_search import both_signs_class


#: The searches :func:`optimize_yaw` runs: ``"both_signs"`` (default) one run of FLORIS's serial
#: refine over the given bounds, started from steering seeds of both signs and refined by
#: quadratic-model steps in all turbines' yaws at once, its mirror beside it
#: (:class:`~floris_ekman_veer.studies.yaw.yaw_search.BothSignsRefinement`); ``"single"`` one run
#: of the optimiser as given (FLORIS's own behaviour).
SEARCHES = ("both_signs", "single")

#: Half-width of the refinement window around the best yaw found, as a fraction of each
#: turbine's bound range, for optimisers other than the serial refine (which
#: :class:`~floris_ekman_veer.studies.yaw.yaw_search.BothSignsRefinement` refines instead): 1/8 of
#: +-25 deg is +-6.25 deg, which FLORIS's default serial-refine passes [5, 4] resolve to 0.8 deg.
REFINE_FRACTION = 1.0 / 8.0


def optimize_yaw(
    fmodel,
    optimizer_class,
    *,
    search: str = "both_signs",
    progress: bool | None = None,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    **optimizer_kwargs,
) -> pd.DataFrame:
    """Optimal yaw angles for every condition of ``fmodel`` with a FLORIS yaw optimiser.

    Veer makes the two signs of yaw differ, and FLORIS's serial-refine optimiser, moving one
    turbine at a time from zero yaw on grids that end 3.1 deg apart (-25..25 deg, [5, 4]),
    stays at zero where steering pays only when turbines turn together and stops short of the
    optimum where turbines' yaws are coupled. The default ``search="both_signs"`` runs a serial
    refine (``YawOptimizationSR`` or a subclass) once, with the given options, started per
    condition and turbine from the best steering seed of either sign, refined by quadratic-model
    steps in all yaws together and beside them from its mirror, batched over all conditions as
    the serial refine batches its grids (studies/yaw/yaw_search.py,
    docs/yaw_steering.md#how-both-signs-are-searched): measured within 0.05 % of farm power of
    a brute-force 1-degree search refined by Nelder-Mead on held-out 3-turbine rows
    (tests/studies/yaw/test_yaw_search.py), evaluating at most twice the conditions of the serial refine's
    own run on a 3 x 3 farm and on 3-turbine rows (tests/studies/yaw/test_yaw_search.py,
    benchmarks/bench_yaw_search.py). Other
    optimisers reporting farm power (``YawOptimizationScipy``) run over the given bounds, over
    their negative and positive parts, and once more within +-:data:`REFINE_FRACTION` of each
    turbine's bound range around each result, keeping per condition the best;
    ``YawOptimizationGeometric`` (no farm power) runs once.

    Args:
        fmodel: FlorisModel, ParFlorisModel or UncertainFlorisModel, with a scalar or a
            per-condition atmosphere (or none: plain FLORIS).
        optimizer_class: A FLORIS yaw optimiser class (``YawOptimizationSR``,
            ``YawOptimizationScipy``, ``YawOptimizationGeometric``...).
        search: ``"both_signs"`` (default) or ``"single"`` (:data:`SEARCHES`).
        progress: Show a tqdm progress bar over conditions; None (default) shows it when the
            study takes more than one optimiser run.
        chunk_size: Conditions per optimiser run (results do not depend on it).
        **optimizer_kwargs: The optimiser's own options (``minimum_yaw_angle``,
            ``maximum_yaw_angle``, ``Ny_passes``, ``opt_options``...). The options in
            ``PER_CONDITION_OPTIONS`` may be (n_findex, n_turbines) arrays. Bounds not
            given are -25 and 25 deg (``DEFAULT_YAW_BOUNDS``, plugin/floris_tools/optimizer_options.py):
            both signs of yaw are searched, where FLORIS's own default, 0..25 deg, searches
            one; bounds given are kept.

    Returns:
        FLORIS's ``df_opt`` frame: one row per condition of ``fmodel``, in its order (index
        0..n_findex-1), with ``wind_direction``, ``wind_speed``, ``turbulence_intensity``,
        ``yaw_angles_opt``, ``farm_power_opt`` and ``farm_power_baseline``.

    Raises:
        ValueError: for a model without conditions, and for options the optimiser does not
            accept or would reject, before any FLORIS evaluation.

    Example (a 3-turbine row 5 D apart on the shipped stable night, 8 m/s from the west):

        >>> import floris_ekman_veer
        >>> from floris import FlorisModel
        >>> from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR
        >>> fmodel = FlorisModel(floris_ekman_veer.example_input("farm_night"))
        >>> fmodel.set(layout_x=[0.0, 630.0, 1260.0], layout_y=[0.0, 0.0, 0.0],
        ...            wind_directions=[270.0], wind_speeds=[8.0], turbulence_intensities=[0.06])
        >>> df_opt = floris_ekman_veer.optimize_yaw(fmodel, YawOptimizationSR, progress=False)
        >>> df_opt.yaw_angles_opt[0].round(1).tolist()      # deg, both signs searched
        [12.5, -21.5, -6.1]
        >>> round(float(df_opt.farm_power_opt[0] / df_opt.farm_power_baseline[0]), 3)
        1.021
    """
    optimizer_kwargs = checked_options(fmodel, optimizer_class, progress, optimizer_kwargs)
    if search not in SEARCHES:
        raise ValueError(f"optimize_yaw: search must be one of {list(SEARCHES)}; got {search!r}")
    # Its shallow conditions counted once here, at the user's call (the re-built models' runs
    # below are silenced: they would repeat the count in ever different numbers).
    warn_shallow(fmodel.core)
    run = functools.partial(optimize_each_atmosphere, fmodel, progress=progress, chunk_size=chunk_size)
    # A serial refine searches both signs in its one run (BothSignsRefinement); other
    # optimisers are run per sign and refined within a window around each result below.
    refines_itself = search == "both_signs" and issubclass(optimizer_class, YawOptimizationSR)
    defaults = inspect.signature(optimizer_class.__init__).parameters
    if refines_itself:
        optimizer_class = both_signs_class(optimizer_class)
    first = run(optimizer_class, **optimizer_kwargs)
    if search == "single" or refines_itself or first["farm_power_opt"].isna().any():
        return first

    shape = (fmodel.core.flow_field.n_findex, fmodel.core.farm.n_turbines)
    lower, upper = (
        np.broadcast_to(np.asarray(optimizer_kwargs.get(name, defaults[name].default),
                                   dtype=float), shape)
        for name in ("minimum_yaw_angle", "maximum_yaw_angle")
    )
    def run_within(lower, upper):
        # The restricted bounds exclude the zero-yaw baseline by design; FLORIS prints an
        # "INFO: yaw_angles_baseline exceed ... constraints" line for each such run.
        with contextlib.redirect_stdout(io.StringIO()):
            return run(optimizer_class, **_with_bounds(optimizer_kwargs, lower, upper))

    candidates = [first]
    if np.any((lower < 0.0) & (upper > 0.0)):
        for bounds in ((lower, np.minimum(upper, 0.0)), (np.maximum(lower, 0.0), upper)):
            candidates.append(run_within(*bounds))
    width = REFINE_FRACTION * (upper - lower)
    refined = []
    for candidate in candidates:
        centre = np.clip(np.vstack(candidate["yaw_angles_opt"].to_numpy()), lower, upper)
        refined.append(run_within(np.maximum(centre - width, lower),
                                  np.minimum(centre + width, upper)))
    return _best_of(candidates + refined)


def _with_bounds(options, lower, upper):
    """The options with per-condition bounds (and no x0 outside them)."""
    bounded = {**options, "minimum_yaw_angle": lower, "maximum_yaw_angle": upper}
    if options.get("x0") is not None:
        bounded["x0"] = np.clip(np.broadcast_to(np.asarray(options["x0"], dtype=float),
                                                lower.shape), lower, upper)
    return bounded


def _best_of(frames):
    """Per condition, the row of the frame with the highest farm_power_opt (the first on ties)."""
    powers = np.stack([f["farm_power_opt"].to_numpy(dtype=float) for f in frames])
    choice = np.argmax(powers, axis=0)
    best = frames[0].copy()
    for k, frame in enumerate(frames[1:], start=1):
        rows = choice == k
        best.loc[rows, "yaw_angles_opt"] = frame.loc[rows, "yaw_angles_opt"]
        best.loc[rows, "farm_power_opt"] = frame.loc[rows, "farm_power_opt"]
    return best

