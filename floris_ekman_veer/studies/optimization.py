"""Yaw optimisation with FLORIS's optimisers on models whose atmosphere varies per condition.

FLORIS's yaw optimisers tile, mask and re-order their model's conditions internally (the Serial
Refine evaluates ``Ny`` copies of every condition at once and skips those already in memory;
the SciPy optimiser sets one condition at a time), so a per-condition atmosphere list
(docs/coupling.md#yaw-optimisation), which binds to conditions by position, cannot follow them.
Every condition's optimum depends on that condition alone, so :func:`optimize_yaw` runs the
optimiser once per distinct atmosphere (and per chunk of conditions, for the progress bar) on
a model holding just those conditions with that atmosphere as scalars, and puts the rows of
FLORIS's ``df_opt`` frames back in the caller's order. The result is, by construction, the
result of running each distinct atmosphere on its own (tests/studies/test_optimization.py measures it).
"""

from __future__ import annotations

import contextlib
import copy
import functools
import io
import inspect
import types
import warnings
from collections.abc import Mapping

import numpy as np
import pandas as pd
from floris import FlorisModel
from floris.core import FlowField, TurbineCubatureGrid, TurbineGrid, WakeModelManager
from floris.optimization.yaw_optimization.yaw_optimization_base import YawOptimization
from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

from floris_ekman_veer._validation import real_array, require_floris_model
from floris_ekman_veer.plugin.inflow import _patch, atmosphere_of, set_atmosphere, warn_shallow
from floris_ekman_veer.plugin.shallow import ShallowBoundaryLayerWarning

#: Optimiser options that may be given per condition, as (n_findex, n_turbines) arrays.
PER_CONDITION_OPTIONS = (
    "minimum_yaw_angle", "maximum_yaw_angle", "yaw_angles_baseline", "x0", "turbine_weights",
)

#: Methods of scipy.optimize.minimize (YawOptimizationScipy's ``opt_method``).
SCIPY_METHODS = (
    "nelder-mead", "powell", "cg", "bfgs", "newton-cg", "l-bfgs-b", "tnc", "cobyla", "cobyqa",
    "slsqp", "trust-constr", "dogleg", "trust-ncg", "trust-exact", "trust-krylov",
)

#: The yaw bounds [deg] :func:`optimize_yaw` searches where the caller gives none: both signs.
#: FLORIS's optimisers default to 0..25 deg, one sign only; with veer the two signs differ and
#: the gain can lie on the negative side (docs/yaw_steering.md#both-signs-by-default). A bound the
#: caller gives is kept as given.
DEFAULT_YAW_BOUNDS = {"minimum_yaw_angle": -25.0, "maximum_yaw_angle": 25.0}

#: Conditions per optimiser run: large enough to keep FLORIS's vectorisation efficient, small
#: enough for the progress bar to move on long studies.
DEFAULT_CHUNK_SIZE = 256


#: The searches :func:`optimize_yaw` runs: ``"both_signs"`` (default) one run of FLORIS's serial
#: refine over the given bounds, started from steering seeds of both signs and refined by
#: quadratic-model steps in all turbines' yaws at once, its mirror beside it
#: (:class:`BothSignsRefinement`); ``"single"`` one run of the optimiser as given (FLORIS's own
#: behaviour).
SEARCHES = ("both_signs", "single")

#: Half-width of the refinement window around the best yaw found, as a fraction of each
#: turbine's bound range, for optimisers other than the serial refine (which
#: :class:`BothSignsRefinement` refines instead): 1/8 of +-25 deg is +-6.25 deg, which FLORIS's
#: default serial-refine passes [5, 4] resolve to 0.8 deg.
REFINE_FRACTION = 1.0 / 8.0

#: Steering seeds of the both-signs search, per sign, as fractions of each turbine's reach (its
#: largest |bound|): 4 common yaws, 6.25 to 25 deg for +-25 deg, each sign; the serial
#: refine's first pass then spans each steering turbine's whole range from the best of them
#: (docs/yaw_steering.md#how-both-signs-are-searched).
SEED_FRACTIONS = np.array([0.25, 0.5, 0.75, 1.0])

#: Single-turbine moves from the best seed, as a fraction of the reach: +-6.25 deg for +-25 deg.
SEED_MOVE_FRACTION = 0.25

#: The mirror of the best yaws (all signs flipped) is refined beside them where its farm power
#: is within this fraction of the best (0.2 %).
MIRROR_WINDOW = 2e-3

#: Finite-difference steps [deg] of the quadratic-model refinement after the serial refine: the
#: first fits the full model (gradient and Hessian), the later ones the gradient only, with the
#: first's Hessian (docs/yaw_steering.md#how-both-signs-are-searched).
QUADRATIC_STEPS = (1.0, 0.5)


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
    the serial refine batches its grids (:class:`BothSignsRefinement`,
    docs/yaw_steering.md#how-both-signs-are-searched): measured within 0.05 % of farm power of
    a brute-force 1-degree search refined by Nelder-Mead on held-out 3-turbine rows
    (tests/studies/test_yaw_search.py), evaluating at most twice the conditions of the serial refine's
    own run on a 3 x 3 farm and on 3-turbine rows (tests/studies/test_yaw_search.py,
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
            :data:`PER_CONDITION_OPTIONS` may be (n_findex, n_turbines) arrays. Bounds not
            given are -25 and 25 deg (:data:`DEFAULT_YAW_BOUNDS`): both signs of yaw are
            searched, where FLORIS's own default, 0..25 deg, searches one; bounds given are
            kept.

    Returns:
        FLORIS's ``df_opt`` frame: one row per condition of ``fmodel``, in its order (index
        0..n_findex-1), with ``wind_direction``, ``wind_speed``, ``turbulence_intensity``,
        ``yaw_angles_opt``, ``farm_power_opt`` and ``farm_power_baseline``.

    Raises:
        ValueError: for a model without conditions, and for options the optimiser does not
            accept or would reject, before any FLORIS evaluation.
    """
    require_floris_model(fmodel, "optimize_yaw")
    n_findex = fmodel.core.flow_field.n_findex
    n_turbines = fmodel.core.farm.n_turbines
    if n_findex == 0:
        raise ValueError(
            "optimize_yaw: the model has no conditions (n_findex = 0): give at least one wind "
            "direction, wind speed and turbulence intensity with fmodel.set(...)"
        )
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise TypeError(f"optimize_yaw: progress must be True, False or None; got {progress!r}")
    optimizer_kwargs = with_default_yaw_bounds(optimizer_class, optimizer_kwargs)
    check_optimizer_options(optimizer_class, optimizer_kwargs, n_findex, n_turbines)
    if search not in SEARCHES:
        raise ValueError(f"optimize_yaw: search must be one of {list(SEARCHES)}; got {search!r}")
    # Its shallow conditions counted once here, at the user's call (the re-built models' runs
    # below are silenced: they would repeat the count in ever different numbers).
    warn_shallow(fmodel.core)
    run = functools.partial(_optimize_once, fmodel, progress=progress, chunk_size=chunk_size)
    # A serial refine searches both signs in its one run (BothSignsRefinement); other
    # optimisers are run per sign and refined within a window around each result below.
    refines_itself = search == "both_signs" and issubclass(optimizer_class, YawOptimizationSR)
    defaults = inspect.signature(optimizer_class.__init__).parameters
    if refines_itself:
        optimizer_class = _both_signs_class(optimizer_class)
    first = run(optimizer_class, **optimizer_kwargs)
    if search == "single" or refines_itself or first["farm_power_opt"].isna().any():
        return first

    shape = (n_findex, n_turbines)
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


@functools.cache
def _both_signs_class(optimizer_class):
    """``optimizer_class`` (a serial refine) with :class:`BothSignsRefinement` in front."""
    return type(f"BothSigns{optimizer_class.__name__}", (BothSignsRefinement, optimizer_class),
                {"__module__": __name__})


class BothSignsRefinement:
    """Mix-in for FLORIS's serial-refine optimiser (``YawOptimizationSR`` or a subclass): one
    run over both signs of yaw, started per condition and per turbine from the best steering
    seed, and refined in all turbines' yaws together (docs/yaw_steering.md#how-both-signs-are-searched).

    The serial refine (Fleming et al. 2022) moves one turbine at a time, with the others at
    their best so far, on grids that end ``(upper - lower) / (Ny_passes[0] - 1) /
    prod(Ny_passes[1:])`` apart (3.1 deg for +-25 deg and [5, 4]). Started from zero yaw it
    misses the optimum where steering pays only when upstream turbines turn together (the
    neutral day's row at 4 D, 8 m/s: no single turbine's move gains), and it stops on the ridge
    between coupled yaws. Here, all conditions in one FLORIS evaluation per stage, as the
    serial refine evaluates its grids (its ``_calc_powers_with_memory``, which skips yaws
    already evaluated):

    1. steering seeds (:data:`SEED_FRACTIONS` of each sign of each turbine's reach, its
       largest |bound|): every turbine that wakes another at one common yaw, the others at the
       start; where a seed beats the start, each of those turbines moved alone by
       +-:data:`SEED_MOVE_FRACTION` of its reach (2 x 4 + 2 x n_steering evaluations);
    2. the serial refine's own passes, from that start, over the steering turbines (those
       that wake none, as FLORIS's ``exclude_downstream_turbines`` would leave out, keep their
       start: their yaw moves their own power alone, which stage 3 places);
    3. per step h of :data:`QUADRATIC_STEPS`, a quadratic model of the farm power around the
       best yaws: in the first, two points along each turbine's yaw and one along each pair of
       steering turbines one in the other's wake (gradient and Hessian); in the later ones one
       point along each yaw (the gradient, with the first's Hessian); and the model's maximum,
       limited to 4 h in each yaw and to the bounds, together with each yaw's own move;
    4. the mirror of the serial refine's result (every sign flipped, clipped to the bounds),
       refined by the same steps beside it where its power is within :data:`MIRROR_WINDOW` of
       the best (a veered atmosphere makes the two signs differ by little where steering pays
       on both).

    Every evaluation is kept only where it beats the best so far, so the result is never below
    the start. Bounds that exclude zero yaw start the search at the allowed yaw closest to the
    baseline (FLORIS's own run would return the out-of-bounds baseline when no grid point beats
    it).
    """

    def __init__(self, fmodel, *args, **kwargs):
        super().__init__(fmodel, *args, **kwargs)
        start = np.clip(self._yaw_angles_baseline_subset, self._minimum_yaw_angle_subset,
                        self._maximum_yaw_angle_subset)
        if np.any(start != self._yaw_angles_baseline_subset):
            self._yaw_angles_opt_subset = start
            self._farm_power_opt_subset = self._calculate_farm_power(start)

    def optimize(self, print_progress=True):
        self.print_progress = print_progress  # read by _calc_powers_with_memory
        self._wakes = self._wake_pairs()
        self._seed_start()
        # The serial refine's passes move the steering turbines only: a turbine that wakes none
        # moves its own power alone, which the quadratic steps place (stage 3). Bounds closed
        # on its start make each of its grids the start, which the memory does not evaluate.
        steering = self._wakes.any(axis=2)
        self._yaw_lbs = np.where(steering, self._yaw_lbs, self._yaw_angles_opt_subset)
        self._yaw_ubs = np.where(steering, self._yaw_ubs, self._yaw_angles_opt_subset)
        return super().optimize(print_progress=print_progress)

    def _finalize(self, *args, **kwargs):
        if not args and not kwargs:
            self._refine_with_mirror()
        return super()._finalize(*args, **kwargs)

    def _seed_start(self):
        """Stage 1: the best steering seed of either sign, then single-turbine moves from it."""
        lower, upper = self._minimum_yaw_angle_subset, self._maximum_yaw_angle_subset
        start = self._yaw_angles_opt_subset.copy()
        reach = np.maximum(np.abs(lower), np.abs(upper))
        steering = self._wakes.any(axis=2)[None]
        common = np.concatenate([SEED_FRACTIONS, -SEED_FRACTIONS])[:, None, None] * reach[None]
        self._evaluate(np.clip(np.where(steering, common, start[None]), lower, upper)[:, None])
        won = np.any(self._yaw_angles_opt_subset != start, axis=1)
        best, n = self._yaw_angles_opt_subset, start.shape[1]
        moves = np.zeros((2 * n,) + best.shape)
        step = SEED_MOVE_FRACTION * reach
        moves[np.arange(n), :, np.arange(n)] = step.T
        moves[n + np.arange(n), :, np.arange(n)] = -step.T
        # Only the turbines that steer a wake: the serial refine's own passes find the others.
        moves *= (won[:, None] & steering[0])[None]
        self._evaluate(np.clip(best[None] + moves, lower, upper)[:, None])

    def _refine_with_mirror(self):
        """Stages 3 and 4: the quadratic steps from the best yaws and, beside them in the same
        evaluations, from their mirror where it is within MIRROR_WINDOW of the best."""
        lower, upper = self._minimum_yaw_angle_subset, self._maximum_yaw_angle_subset
        best, power = self._yaw_angles_opt_subset.copy(), self._farm_power_opt_subset.copy()
        mirror = np.clip(-best, lower, upper)
        distinct = np.any(np.abs(mirror - best) >= 0.01, axis=1)
        mirror_power = self._evaluate(mirror[None, None], distinct[None])[0, 0]
        close = distinct & (mirror_power >= (1.0 - MIRROR_WINDOW) * power)
        tracks = _Tracks(np.stack([best, mirror]), np.stack([power, mirror_power]),
                         np.stack([np.ones_like(close), close]), lower, upper)
        wakes = self._wakes
        # Cross terms of two steering turbines one of which is in the other's wake (the ridge
        # the serial refine stops on); a turbine that wakes none moves its own power alone (its
        # cross terms are small), and the SR's passes and the steps' curvatures place it.
        steering = wakes.any(axis=2)
        coupled = (wakes | np.swapaxes(wakes, 1, 2)) & steering[:, :, None] & steering[:, None, :]
        coupled = np.concatenate([coupled, coupled])
        hessian = None
        for k, step in enumerate(QUADRATIC_STEPS):
            centre, centre_power = tracks.yaws.copy(), tracks.power.copy()
            # The first step fits the whole model; the later ones its gradient only, one point
            # per yaw, with the curvatures and cross terms of the first.
            pairs = coupled if hessian is None else None
            stencil = _QuadraticStencil(centre, tracks.lower, tracks.upper, step, pairs, hessian)
            values = tracks.keep_best(stencil.points, self._evaluate)
            with np.errstate(invalid="ignore"):  # the inactive mirrors' -inf: no move
                gradient, hessian = stencil.fit(values - centre_power, hessian)
            moves = _newton_moves(gradient, hessian, centre, tracks.lower, tracks.upper,
                                  4.0 * step)
            tracks.keep_best(np.clip(centre + moves, tracks.lower, tracks.upper), self._evaluate)

    def _wake_pairs(self):
        """(n_findex, n, n): turbine i wakes turbine j, by FLORIS's conservative linear wake cone
        (half-width D + 0.3 x, ``derive_downstream_turbines``). The seeds steer the turbines
        that wake another; the quadratic model samples the cross terms of pairs of them one of
        which is in the other's wake."""
        fmodel = self.fmodel_subset
        angle = np.radians(fmodel.core.flow_field.wind_directions - 270.0)[:, None]
        x, y = fmodel.layout_x[None, :], fmodel.layout_y[None, :]
        x_rot = np.cos(angle) * x - np.sin(angle) * y
        y_rot = np.sin(angle) * x + np.cos(angle) * y
        diameter = np.broadcast_to(np.asarray(fmodel.core.farm.rotor_diameters, float),
                                   x_rot.shape)
        downstream = x_rot[:, None, :] - x_rot[:, :, None]                 # [f, i, j]: x_j - x_i
        wakes = (downstream > 0.01) & (np.abs(y_rot[:, None, :] - y_rot[:, :, None])
                                       < diameter[:, :, None] + 0.3 * downstream)
        return wakes

    def _evaluate(self, points, active=None):
        """Farm power of (K, T, n_findex, n_turbines) yaws (T candidate sets per condition) in
        one FLORIS run, -inf where ``active`` ((T, n_findex) booleans) is False; the best of
        them above the best so far becomes the best. Inactive points are given the best yaws,
        which the serial refine's memory does not evaluate again."""
        k, t, f, n = points.shape
        best = self._yaw_angles_opt_subset
        if active is not None:
            points = np.where(active[None, :, :, None], points, best[None, None])
        powers = self._calc_powers_with_memory(points.reshape(k * t, f, n)).reshape(k, t, f)
        powers = np.where(np.isfinite(powers), powers, -np.inf)
        if active is not None:
            powers = np.where(active[None], powers, -np.inf)
        flat = powers.reshape(k * t, f)
        pick = np.argmax(flat, axis=0)
        conditions = np.arange(f)
        better = flat[pick, conditions] > self._farm_power_opt_subset
        self._yaw_angles_opt_subset = np.where(
            better[:, None], points.reshape(k * t, f, n)[pick, conditions], best)
        self._farm_power_opt_subset = np.where(better, flat[pick, conditions],
                                               self._farm_power_opt_subset)
        return powers


class _Tracks:
    """T candidate yaw sets per condition refined side by side (:meth:`keep_best`), flattened
    to (T x n_findex) rows for :class:`_QuadraticStencil` and :func:`_newton_moves`."""

    def __init__(self, yaws, power, active, lower, upper):
        self.t, self.f, n = yaws.shape
        self.yaws = yaws.reshape(-1, n)
        self.power = np.where(active, power, -np.inf).reshape(-1)
        self.active = active
        self.lower, self.upper = np.tile(lower, (self.t, 1)), np.tile(upper, (self.t, 1))

    def keep_best(self, points, evaluate):
        """Evaluate (K, T x n_findex, n) yaws; each row keeps its best. Returns (K, T x n_findex)
        powers (-inf on inactive rows)."""
        k, _, n = points.shape
        powers = evaluate(points.reshape(k, self.t, self.f, n), self.active).reshape(k, -1)
        pick = np.argmax(powers, axis=0)
        rows = np.arange(powers.shape[1])
        better = powers[pick, rows] > self.power
        self.yaws = np.where(better[:, None], points[pick, rows], self.yaws)
        self.power = np.where(better, powers[pick, rows], self.power)
        return powers


class _QuadraticStencil:
    """Yaws around ``centre`` that determine a quadratic model of the farm power by finite
    differences: per turbine two points along its yaw inside its bounds (+-step, or step and
    2 step away from a bound it is within step of), or with ``curvature`` (the (n_findex, n, n)
    Hessian of a previous model) the first of them only, and per coupled pair (``pairs``,
    (n_findex, n, n) booleans, or None for none) one point moving both. Turbines whose range is
    below 3e-3 deg stay put. ``points`` is (K, n_findex, n); where a condition has fewer coupled
    pairs than K the remaining points are the centre (which the serial refine's memory does not
    evaluate again)."""

    def __init__(self, centre, lower, upper, step, pairs=None, curvature=None):
        reach = np.minimum(step, (upper - lower) / 3.0)
        self.free = reach >= 1e-3
        reach = np.where(self.free, reach, 1.0)
        self.first = np.where(centre + reach <= upper, reach, -reach)
        back = centre - self.first
        self.second = np.where((back >= lower) & (back <= upper), -self.first, 2.0 * self.first)
        self.curvature = None if curvature is None else np.einsum("fii->fi", curvature)
        n = centre.shape[1]
        sides = 2 if curvature is None else 1
        axes = np.zeros((sides, n) + centre.shape)
        axes[0, np.arange(n), :, np.arange(n)] = np.where(self.free, self.first, 0.0).T
        if sides == 2:
            axes[1, np.arange(n), :, np.arange(n)] = np.where(self.free, self.second, 0.0).T
        if pairs is None:
            self.pairs = (np.zeros(0, int),) * 4
            crossed = np.zeros((0,) + centre.shape)
        else:
            both = np.triu(pairs, 1) & self.free[:, :, None] & self.free[:, None, :]
            condition, i, j = np.nonzero(both)
            rank = np.arange(condition.size) - np.searchsorted(condition, condition)
            crossed = np.zeros((rank.max() + 1 if rank.size else 0,) + centre.shape)
            crossed[rank, condition, i] = self.first[condition, i]
            crossed[rank, condition, j] = self.first[condition, j]
            self.pairs = (rank, condition, i, j)
        self.n, self.sides = n, sides
        self.points = np.clip(centre + np.concatenate([*axes, crossed]), lower, upper)

    def fit(self, gains, hessian=None):
        """(gradient, Hessian) per condition from ``gains`` (K, n_findex): the farm power at
        ``points`` less that at the centre. The cross terms of pairs not sampled (and, with one
        point per yaw, the curvatures) are those of ``hessian`` (or zero). Conditions with a
        non-finite gain get a zero gradient."""
        n, a, b = self.n, self.first, self.second
        along_a = gains[:n].T
        if self.sides == 2:
            along_b = gains[n:2 * n].T
            curvature = 2.0 * (along_a / a - along_b / b) / (a - b)
        else:
            curvature = self.curvature
        gradient = along_a / a - 0.5 * curvature * a
        fitted = (np.zeros((gains.shape[1], n, n)) if hessian is None
                  else hessian * (1.0 - np.eye(n)))
        rank, condition, i, j = self.pairs
        offset = self.sides * n
        cross = (gains[offset + rank, condition] - along_a[condition, i]
                 - along_a[condition, j]) / (a[condition, i] * a[condition, j])
        fitted[condition, i, j] = cross
        fitted[condition, j, i] = cross
        fitted[:, np.arange(n), np.arange(n)] = np.where(self.free, curvature, 0.0)
        finite = np.all(np.isfinite(gradient), axis=1) & np.all(np.isfinite(fitted), axis=(1, 2))
        gradient = np.where(finite[:, None] & self.free, gradient, 0.0)
        fitted = np.where(finite[:, None, None], fitted, 0.0)
        return gradient, fitted


def _newton_moves(gradient, hessian, centre, lower, upper, radius):
    """(2, n_findex, n) moves towards the maximum of the quadratic model: the full Newton move
    and the move of each yaw alone (the Hessian's diagonal), both over the yaws not held at a
    bound and at most ``radius`` along each direction of the Hessian (or each yaw).

    The full move solves the model along the Hessian's eigenvectors, an eigenvalue that would
    move further than ``radius`` (or is not negative: no maximum) being lowered until the move
    is ``radius`` uphill; a yaw at a bound that the move would push out is held there and the
    move recomputed (an active set, twice at most)."""
    n = centre.shape[1]
    free = upper - lower >= 1e-3
    for _ in range(3):
        both = free[:, :, None] & free[:, None, :]
        values, vectors = np.linalg.eigh(np.where(both, hessian, -np.eye(n)))
        along = np.einsum("fkj,fk->fj", vectors, np.where(free, gradient, 0.0))
        values = np.minimum(values, -np.abs(along) / radius - 1e-300)
        move = -np.einsum("fij,fj->fi", vectors, along / values)
        held = free & (((centre <= lower) & (move < 0.0)) | ((centre >= upper) & (move > 0.0)))
        if not held.any():
            break
        free = free & ~held
    move = np.clip(np.where(free, move, 0.0), -radius, radius)
    curvature = np.einsum("fii->fi", hessian)
    alone = np.where(free & (curvature < 0.0),
                     np.clip(-gradient / np.where(curvature < 0.0, curvature, -1.0),
                             -radius, radius), 0.0)
    return np.stack([move, alone])


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


def _optimize_once(fmodel, optimizer_class, *, progress, chunk_size, **optimizer_kwargs):
    """One run of the optimiser over every condition (per atmosphere and chunk)."""
    n_findex = fmodel.core.flow_field.n_findex
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, (int, np.integer)) or chunk_size < 1:
        raise ValueError(f"optimize_yaw: chunk_size must be an integer >= 1; got {chunk_size!r}")

    groups = atmosphere_groups(fmodel)
    if len(groups) > 1 and _rows_follow(fmodel, optimizer_class, optimizer_kwargs):
        # Every atmosphere in one run per chunk (FLORIS's serial refine carries the condition
        # rows through its tiling, see row_following_subset): no model per atmosphere.
        groups = [(ROWS, np.arange(n_findex))]
    runs = [
        (atmosphere, chunk)
        for atmosphere, index in groups
        for chunk in np.array_split(index, -(-index.size // chunk_size))
    ]
    if progress is None:
        progress = len(runs) > 1
    optimize_takes_progress = "print_progress" in inspect.signature(optimizer_class.optimize).parameters

    from tqdm.auto import tqdm

    frames = []
    with tqdm(total=n_findex, desc=f"{optimizer_class.__name__}", unit="condition",
              disable=not progress) as bar, warnings.catch_warnings():
        # optimize_yaw counted fmodel's shallow conditions at its start; the optimiser's many
        # re-builds (tiled, masked condition sets) would repeat that count in other numbers.
        warnings.simplefilter("ignore", ShallowBoundaryLayerWarning)
        for atmosphere, index in runs:
            subset = (row_following_subset(fmodel, index) if atmosphere is ROWS
                      else condition_subset(fmodel, index, atmosphere))
            kwargs = {
                name: np.asarray(value, dtype=float)[index]
                if name in PER_CONDITION_OPTIONS and np.ndim(value) == 2 else value
                for name, value in optimizer_kwargs.items()
            }
            optimizer = optimizer_class(subset, **kwargs)
            # FLORIS's own per-pass prints would interleave with the bar.
            df = optimizer.optimize(print_progress=False) if optimize_takes_progress else optimizer.optimize()
            df.index = index
            frames.append(df)
            bar.update(index.size)
    return pd.concat(frames).sort_index()


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


#: Marks the run of :func:`_optimize_once` holding conditions of different atmospheres.
ROWS = object()


def _rows_follow(fmodel, optimizer_class, options) -> bool:
    """Whether ``optimizer_class`` on ``fmodel`` can run conditions of different atmospheres
    together (:func:`row_following_subset`): FLORIS's serial refine (which tiles a model's
    per-condition heterogeneous speed-ups with its conditions) without a heterogeneous map of
    its own or a convergence check (which re-evaluates without them), on a FlorisModel (a
    ParFlorisModel hands its workers the heterogeneous configuration as a map)."""
    from floris import FlorisModel, ParFlorisModel
    from floris.optimization.yaw_optimization.yaw_optimizer_sr import YawOptimizationSR

    return (issubclass(optimizer_class, YawOptimizationSR)
            and type(fmodel).set is FlorisModel.set and not isinstance(fmodel, ParFlorisModel)
            and fmodel.core.flow_field.heterogeneous_inflow_config is None
            and not options.get("verify_convergence", False))


def row_following_subset(fmodel, index):
    """:func:`condition_subset` of conditions ``index`` with their per-condition atmosphere,
    whose atmosphere follows its conditions through FLORIS's serial-refine optimiser.

    The serial refine evaluates tiled and masked copies of its model's conditions, and carries
    per-condition heterogeneous speed-ups the same way (``speed_multipliers`` tiled with the
    conditions). The subset holds, in that place, the row of each of its conditions (one
    column, never read as speed-ups: FLORIS builds its map only at construction), and its
    ``set()`` gives each condition set the atmosphere rows of the rows it carries. One model
    per chunk of conditions, whatever their atmospheres.
    """
    index = np.asarray(index)
    spec = atmosphere_of(fmodel.core)
    subset = condition_subset(fmodel, index, spec.sliced(index))
    subset._atmosphere_rows = {k: v if isinstance(v, float) else v.reshape(-1)[index]
                               for k, v in spec.inputs.items()}
    _mark_rows(subset, np.arange(index.size))
    subset.set = types.MethodType(_set_following_rows, subset)
    return subset


def _mark_rows(fmodel, rows) -> None:
    # Past FlowField's validator (which wants a map's x and y): the rows are no map.
    object.__setattr__(fmodel.core.flow_field, "heterogeneous_inflow_config",
                       {"speed_multipliers": np.asarray(rows, dtype=float).reshape(-1, 1)})


def _set_following_rows(self, **kwargs):
    """``set()`` of a :func:`row_following_subset`: the atmosphere of the rows it carries."""
    rows = np.asarray(self.core.flow_field.heterogeneous_inflow_config["speed_multipliers"],
                      dtype=float).reshape(-1).astype(int)
    n = np.size(kwargs.get("wind_directions", rows))
    if n != rows.size:
        raise ValueError(f"optimize_yaw: the optimiser set {n} conditions on a model "
                         f"carrying the atmospheres of {rows.size}")
    atmosphere = {k: v if isinstance(v, float) else v[rows].tolist()
                  for k, v in self._atmosphere_rows.items()}
    object.__setattr__(self.core.flow_field, "heterogeneous_inflow_config", None)
    set_atmosphere(_Plain(self), atmosphere, **kwargs)
    _mark_rows(self, rows)


class _Plain:
    """A model seen through its class's own ``set()`` (for :func:`set_atmosphere`)."""

    def __init__(self, fmodel):
        self.core, self._fmodel = fmodel.core, fmodel

    def set(self, **kwargs):
        type(self._fmodel).set(self._fmodel, **kwargs)


def condition_subset(fmodel, index, atmosphere: Mapping | None):
    """A copy of ``fmodel`` holding conditions ``index`` (in that order) and ``atmosphere``.

    Carries every per-condition input FLORIS has: wind directions, speeds, turbulence
    intensities, heterogeneous speed multipliers and the operation set-points (yaw angles,
    power set-points, active wake control), so that the subset's conditions are those of the
    parent.
    """
    index = np.asarray(index)
    core = fmodel.core
    flow_field, farm = core.flow_field, core.farm
    set_kwargs = dict(
        wind_directions=flow_field.wind_directions[index],
        wind_speeds=flow_field.wind_speeds[index],
        turbulence_intensities=flow_field.turbulence_intensities[index],
        yaw_angles=farm.yaw_angles[index],
        power_setpoints=farm.power_setpoints[index],
        awc_modes=farm.awc_modes[index],
        awc_amplitudes=farm.awc_amplitudes[index],
        awc_frequencies=farm.awc_frequencies[index],
    )
    heterogeneous = flow_field.heterogeneous_inflow_config
    if heterogeneous is not None and heterogeneous.get("speed_multipliers") is not None:
        set_kwargs["heterogeneous_inflow_config"] = {
            **heterogeneous,
            "speed_multipliers": np.asarray(heterogeneous["speed_multipliers"])[index],
        }
    subset = fmodel.copy()
    set_atmosphere(subset, atmosphere, **set_kwargs)
    if type(subset) is FlorisModel:
        # The optimiser's set() per evaluation gives only conditions (and set-points): rows
        # of this subset, checked when it was built above.
        subset._reinitialize = types.MethodType(_reinitialize_conditions, subset)
    return subset


#: The inputs :func:`_reinitialize_conditions` rebuilds; any other goes through FLORIS's own
#: ``_reinitialize``.
_CONDITION_INPUTS = frozenset({"wind_directions", "wind_speeds", "turbulence_intensities"})


def _reinitialize_conditions(self, **kwargs):
    """FlorisModel._reinitialize of an optimiser's subset, for new conditions only: the same
    Core as FLORIS's ``Core.from_dict(core.as_dict())`` with those conditions, reusing the
    farm's turbines and their tables.

    FLORIS's yaw optimisers set each evaluation's conditions (tiled and masked rows of the
    subset) on a copy of the subset, which rebuilds the whole Core: the farm re-reads every
    turbine's YAML file and builds its turbines anew, resolving the library path through
    ``inspect.stack`` twice per turbine type, and the package re-validates the conditions:
    38 % of a steered study's time (docs/yaw_steering.md#how-both-signs-are-searched). Neither the layout nor the turbines change here,
    and every condition is one of the subset's, already validated; the flow field, the wake
    models (with the atmosphere the subset now carries), the per-condition set-points and the
    grid are built as FLORIS builds them (``Core.__attrs_post_init__``). Results are bitwise
    those of the full rebuild (tests/studies/test_optimization.py).
    """
    given = {k for k, v in kwargs.items() if v is not None}
    core = self.core
    if (not given <= _CONDITION_INPUTS or self._wind_data is not None
            or core.solver["type"] not in ("turbine_grid", "turbine_cubature_grid")):
        return FlorisModel._reinitialize(self, **kwargs)
    floris_dict = core.as_dict()
    flow_field_dict = floris_dict["flow_field"]
    for name in given:
        flow_field_dict[name] = kwargs[name]
    new = copy.copy(core)
    farm = copy.copy(core.farm)
    # Past attrs' converters (they would rebuild from a dict): these are built objects.
    object.__setattr__(new, "wake", WakeModelManager.from_dict(floris_dict["wake"]))
    object.__setattr__(new, "flow_field", FlowField.from_dict(flow_field_dict))
    object.__setattr__(new, "farm", farm)
    n_findex = new.flow_field.n_findex
    farm.set_yaw_angles_to_ref_yaw(n_findex)
    farm.set_tilt_to_ref_tilt(n_findex)
    farm.set_power_setpoints_to_ref_power(n_findex)
    farm.set_awc_modes_to_ref_mode(n_findex)
    farm.set_awc_amplitudes_to_ref_amp(n_findex)
    farm.set_awc_frequencies_to_ref_freq(n_findex)
    grid_class = TurbineGrid if core.solver["type"] == "turbine_grid" else TurbineCubatureGrid
    object.__setattr__(new, "grid", grid_class(
        turbine_coordinates=farm.coordinates,
        turbine_diameters=farm.rotor_diameters,
        wind_directions=new.flow_field.wind_directions,
        grid_resolution=new.solver["turbine_grid_points"],
    ))
    farm.expand_farm_properties(n_findex, new.grid.sorted_coord_indices)
    self.core = new


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


# ---------------------------------------------------------------------------------------------
# FLORIS's optimiser classes on per-condition atmospheres


def _optimizer_classes() -> list[type]:
    """YawOptimization and every subclass defined so far (FLORIS's three are imported here)."""
    from floris.optimization.yaw_optimization import (  # noqa: F401  (define the subclasses)
        yaw_optimizer_geometric,
        yaw_optimizer_scipy,
        yaw_optimizer_sr,
    )

    found, pending = [], [YawOptimization]
    while pending:
        cls = pending.pop()
        found.append(cls)
        pending.extend(cls.__subclasses__())
    return found


def _recording_init(original):
    """Keep the user's own constructor call (the outermost ``__init__``): its options are those
    :func:`optimize_yaw` needs to rebuild the optimiser per atmosphere."""

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
    """On a per-condition atmosphere, ``optimize()`` is :func:`optimize_yaw` with the options
    the optimiser was built with; its results are also stored as FLORIS stores them."""

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
        df = optimize_yaw(self.fmodel, type(self), search="single", progress=progress, **options)
        self.yaw_angles_opt = np.vstack(df.yaw_angles_opt.to_numpy())
        self.farm_power_opt = (
            None if df.farm_power_opt.isna().all() else df.farm_power_opt.to_numpy(dtype=float)
        )
        return df

    return wrapper


def install_optimizer_hook() -> None:
    """FLORIS's yaw optimiser classes accept per-condition atmospheres (idempotent;
    ``register()`` calls it): their ``optimize()`` runs :func:`optimize_yaw`."""
    for cls in _optimizer_classes():
        if "__init__" in cls.__dict__:
            _patch(cls, "__init__", _recording_init)
        if "optimize" in cls.__dict__:
            _patch(cls, "optimize", _dispatching_optimize)
