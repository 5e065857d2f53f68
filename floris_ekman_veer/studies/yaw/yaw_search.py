"""The both-signs search: FLORIS's serial refine started from steering seeds of both signs of yaw
and refined in all turbines' yaws together (docs/yaw_steering.md#how-both-signs-are-searched).

:func:`~floris_ekman_veer.optimize_yaw`'s default ``search="both_signs"`` runs a serial refine
(``YawOptimizationSR`` or a subclass) with :class:`BothSignsRefinement` in front
(:func:`both_signs_class`).
"""

from __future__ import annotations

import functools

import numpy as np

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


@functools.cache
def both_signs_class(optimizer_class):
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
    neutral day's row at 4 D, 8 m/s on the wakes of the time the seeds were introduced, before
    the array coupling of docs/coupling.md#wakes-deep-in-an-array), and it stops on the ridge
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
       limited to 4 h in each steering turbine's yaw (in the others' only by the bounds: their
       yaw moves their own power alone) and to the bounds, together with each yaw's own move;
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
        # The Newton moves go at most 4 steps in a steering turbine's yaw (its farm power couples
        # to the others' yaws), but across its whole range in the yaw of a turbine that wakes
        # none: that yaw moves its own power alone, a smooth single-rotor curve the model fits,
        # and on a veered night its optimum lies up to 8 deg from the start (the last turbine
        # of the held-out row at 273 deg), beyond the two steps' 4 + 2 deg.
        steers = np.concatenate([steering, steering])
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
                                  np.where(steers, 4.0 * step,
                                           np.maximum(tracks.upper - tracks.lower, 4.0 * step)))
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
    bound and at most ``radius`` ((n_findex, n) per yaw) along each yaw, and along each direction
    of the Hessian the radii weighted by the direction's squared components.

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
        reach = np.einsum("fkj,fk->fj", vectors ** 2, radius)
        values = np.minimum(values, -np.abs(along) / reach - 1e-300)
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
