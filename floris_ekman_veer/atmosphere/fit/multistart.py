"""Where the profile fit starts (docs/measurements.md#fit-time): the multi-start over stabilities,
the restarts next to the profile's kinks and step near the ABL top, the dense restart of records
the first start leaves refused, and the convective fit of the mixed-layer depth where the data
reach it (docs/measurements.md#mixed-layer-depth)."""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.atmosphere.fit.fit_model import (
    LENGTH_SCALE,
    DefaultDepth,
    ProfileModel,
    SubsetModel,
)
from floris_ekman_veer.atmosphere.fit.fit_residuals import CONFIDENCE_CHI_SQUARE
from floris_ekman_veer.atmosphere.fit.least_squares import levenberg_marquardt
from floris_ekman_veer.atmosphere.fit.misfit import hidden_top

#: Starting Obukhov lengths [m] of the multi-start (inf: neutral).
STARTING_OBUKHOV_LENGTHS = (np.inf, 400.0, 200.0, 100.0, 50.0, 25.0)
#: Starting Obukhov lengths [m] of the second, dense start of records the first one leaves
#: refused: 40 from 10 m to 2 km, geometric.
RESTART_OBUKHOV_LENGTHS = tuple(np.geomspace(10.0, 2000.0, 40))
#: Factors on the best end point's 1/L of the restarts across the profile's step near h.
_POLISH_FACTORS = (0.9, 0.97, 1.03, 1.1)
#: ... for records whose fitted ABL top is below this times their highest measurement.
_POLISH_HEIGHT_RATIO = 1.2


def starting_points(model, lams):
    """Starting unknowns (n * k, p) for stabilities lam (n, k): u* from the lowest speed by the
    log-linear law U = (u*/kappa) (ln(z/z0) + 5 z/L), z0 its given (starting) value."""
    n, k = lams.shape
    rows = np.arange(n)
    lowest = np.argmin(np.where(model.ms, model.z, np.inf), axis=1)
    z1, s1 = model.z[rows, lowest][:, None], model.s[rows, lowest][:, None]
    # (convective fits start from the neutral log law: the log-linear form is the stable one)
    stable = 5.0 * z1 * lams / LENGTH_SCALE * (model.sign > 0)
    u_star = model.kappa * s1 / (np.log(z1 / model.z0[:, None]) + stable)
    columns = [np.log(u_star), lams]
    if model.fit_roughness:
        columns.append(np.broadcast_to(np.log(model.z0)[:, None], (n, k)))
    return np.stack([np.asarray(c, float) for c in columns], axis=-1).reshape(n * k, -1)


def best_end_points(x, cost, n, k):
    """Index (into n * k rows) of each record's best end point; among equally good ones (data
    that do not pin the state, e.g. one speed and one direction change) the weakest stability:
    a deeper boundary layer rather than one collapsed below the heights."""
    cost = cost.reshape(n, k)
    tie = cost <= np.min(cost, axis=1, keepdims=True) * (1.0 + 1e-6) + 1e-12
    best = np.argmin(np.where(tie, x.reshape(n, k, -1)[:, :, 1], np.inf), axis=1)
    return np.arange(n) * k + best


def multistart(model, n, max_iterations):
    """Levenberg-Marquardt from each starting stability, all records and starts in one batch,
    then from a few stabilities next to the best end point; the best end point per record.

    Several starts because the objective has kinks and a step: where the ABL top h, or the
    matching height 0.2 h, crosses a measurement height the profile's slope jumps, and where
    0.9973 h does the direction steps (docs/atmosphere.md#lateral-velocity-near-the-abl-top);
    an iteration can stop there, a local minimum, while a start on the other side reaches the
    fit.
    """
    rows = np.arange(n)
    grid = np.broadcast_to(LENGTH_SCALE / np.asarray(STARTING_OBUKHOV_LENGTHS), (n, len(STARTING_OBUKHOV_LENGTHS)))
    x, cost, converged, iterations = levenberg_marquardt(
        model, starting_points(model, grid), max_iterations, np.repeat(rows, grid.shape[1])
    )
    pick = best_end_points(x, cost, n, grid.shape[1])
    x, cost, converged, iterations = x[pick], cost[pick], converged[pick], iterations[pick]
    # Records whose fitted ABL top lies within or just above the heights, where the step is:
    # restarts next to the end point, its 1/L times a few factors either side, with u* from
    # the log-linear law and from the end point's own state, u* moved with the stability as at
    # a fixed speed aloft (u* ~ L^-1/2 there).
    _, _, _, valid, h = model.state(x, rows)
    near_top = np.flatnonzero(valid & (x[:, 1] > 0)
                              & (h < _POLISH_HEIGHT_RATIO * np.max(model.z, axis=1)))
    if near_top.size:
        factors = np.asarray(_POLISH_FACTORS)
        m, k = near_top.size, 2 * factors.size
        best = x[near_top]
        near = np.repeat(best, factors.size, axis=0)
        near[:, 1] *= np.tile(factors, m)
        near[:, 0] += 0.5 * np.log(np.tile(factors, m))
        sub = SubsetModel(model, near_top)
        starts = np.concatenate([
            starting_points(sub, best[:, 1][:, None] * factors[None, :]).reshape(m, factors.size, -1),
            near.reshape(m, factors.size, -1),
        ], axis=1).reshape(m * k, -1)
        x2, cost2, converged2, iterations2 = levenberg_marquardt(
            model, starts, max_iterations, np.repeat(near_top, k)
        )
        pick = best_end_points(x2, cost2, m, k)
        better = cost2[pick] < cost[near_top] * (1.0 - 1e-6) - 1e-12
        chosen = near_top[better]
        x[chosen], cost[chosen] = x2[pick][better], cost2[pick][better]
        converged[chosen], iterations[chosen] = converged2[pick][better], iterations2[pick][better]
    return x, cost, converged, iterations


def restart_misfits(model, x, cost, converged, iterations, refused_cost, max_iterations):
    """Records whose best end point the chi-square test would refuse start again from a dense
    set of stabilities (:data:`RESTART_OBUKHOV_LENGTHS`): in a strongly stable light wind the
    objective's valleys, between the kinks where h crosses a measurement height, are narrower
    than the multi-start's spacing. Only the refused records pay for it; in place."""
    refused = np.flatnonzero(~(cost <= refused_cost))
    if refused.size == 0:
        return
    sub = SubsetModel(model, refused)
    lams = LENGTH_SCALE / np.asarray(RESTART_OBUKHOV_LENGTHS)
    k = lams.size
    x2, cost2, converged2, iterations2 = levenberg_marquardt(
        model, starting_points(sub, np.broadcast_to(lams, (refused.size, k))), max_iterations,
        np.repeat(refused, k))
    pick = best_end_points(x2, cost2, refused.size, k)
    better = cost2[pick] < cost[refused] * (1.0 - 1e-6) - 1e-12
    chosen = refused[better]
    x[chosen], cost[chosen] = x2[pick][better], cost2[pick][better]
    converged[chosen], iterations[chosen] = converged2[pick][better], iterations2[pick][better]


#: Starting Obukhov lengths [m] of the fit of the mixed-layer depth (with the default-z_i fit's
#: own end point), each with z_i at these fractions of the record's highest measurement.
MIXED_LAYER_STARTING_LENGTHS = (400.0, 100.0, 30.0)
MIXED_LAYER_STARTING_FRACTIONS = (0.5, 0.75, 1.0)


def fit_mixed_layer(model, x, cost, converged, iterations, refused_cost, max_iterations,
                     model_error):
    """The convective fit with the mixed-layer depth z_i as a further unknown, for the records
    whose default-z_i fit the chi-square test would refuse (``cost`` above ``refused_cost``: the
    default depth cannot follow their data), kept per record only where the data reach z_i
    (docs/measurements.md#mixed-layer-depth): the fitted z_i at or below the highest
    measurement, the data showing that top (a speed maximum, or the shear or the veer stopping
    at it: the test of a stable top, `hidden_top`), and the chi-square below the default-z_i
    fit's by more than :data:`CONFIDENCE_CHI_SQUARE`. ``model``: the `ProfileModel` with
    ``fit_mixed_layer``; x, cost, ...: the default-z_i fit (2 or 3 unknowns). Returns the
    states with ln z_i appended (the default's own depth where not fitted: the same state) and
    whether fitted."""
    n = x.shape[0]
    rows = np.arange(n)
    # The default fit's depth: for a convective state its z_i, else the neutral height (unused).
    _, _, _, _, depth = ProfileModel.state(DefaultDepth(model), x, rows)
    base = np.concatenate([x, np.log(np.where(np.isfinite(depth) & (depth > 0), depth,
                                              1000.0))[:, None]], axis=1)
    fitted = np.zeros(n, bool)
    cost, converged, iterations = cost.copy(), converged.copy(), iterations.copy()
    candidates = np.flatnonzero(~(cost <= refused_cost))
    m = candidates.size
    if m == 0:
        return base, cost, converged, iterations, fitted
    top = np.nanmax(np.where(model.ms, model.z, np.nan), axis=1)[candidates]
    lams = np.concatenate([x[candidates, 1:2], np.broadcast_to(
        LENGTH_SCALE / np.asarray(MIXED_LAYER_STARTING_LENGTHS), (m, len(MIXED_LAYER_STARTING_LENGTHS)))],
        axis=1)
    fractions = np.asarray(MIXED_LAYER_STARTING_FRACTIONS)
    k_l, k_f = lams.shape[1], fractions.size
    starts = starting_points(SubsetModel(model, candidates), lams).reshape(m, k_l, -1)
    # the default fit's own u* at its end point
    starts[:, 0, 0] = x[candidates, 0]
    starts = np.repeat(starts, k_f, axis=1)
    log_zi = np.log(np.maximum(top[:, None] * np.tile(fractions, k_l)[None, :],
                               2.0 * model.min_depth))
    starts = np.concatenate([starts, log_zi[:, :, None]], axis=2).reshape(m * k_l * k_f, -1)
    x2, cost2, converged2, iterations2 = levenberg_marquardt(
        model, starts, max_iterations, np.repeat(candidates, k_l * k_f))
    pick = best_end_points(x2, cost2, m, k_l * k_f)
    x2, cost2 = x2[pick], cost2[pick]
    _, _, _, valid, h = model.state(x2, candidates)
    reached = valid & (x2[:, 1] > 0) & (np.exp(x2[:, -1]) <= top * (1.0 + 1e-9))
    better = cost2 < cost[candidates] - CONFIDENCE_CHI_SQUARE
    d = None if model.d is None else model.d[candidates]
    shown = ~hidden_top(model.z[candidates], model.s[candidates], d,
                         np.where(reached, h, np.inf), model.sigma_record[candidates],
                         float(np.hypot(model.sigma_d, model_error)))
    keep = reached & better & shown
    chosen = candidates[keep]
    fitted[chosen] = True
    base[chosen], cost[chosen] = x2[keep], cost2[keep]
    converged[chosen], iterations[chosen] = converged2[pick][keep], iterations2[pick][keep]
    return base, cost, converged, iterations, fitted
