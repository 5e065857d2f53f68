"""The Levenberg-Marquardt iteration of the profile fit (docs/measurements.md#fit-time): all records
and starting points at once, forward-difference Jacobians from the model's vectorised profile, a
small normal system per record solved as one stacked array, the stability unknown held on its
bound 1/L = 0, converged rows frozen; and the linearised covariance at the fit."""

from __future__ import annotations

import numpy as np

_JACOBIAN_STEP = 1e-7
_STEP_TOLERANCE = 1e-10


def _solve_normal(jtj, jtr, damping, x_lam, bounded):
    """LM step of stacked systems (k, p, p); where ``bounded`` the stability unknown (index 1)
    is held at its bound 0 (step -x_lam) and the others solved with it fixed."""
    p = jtj.shape[-1]
    diag = np.einsum("kii->ki", jtj)
    a = jtj + (damping[:, None] * diag + 1e-30)[:, :, None] * np.eye(p)
    rhs = -jtr
    if np.any(bounded):
        fixed_step = -x_lam
        column = a[:, :, 1].copy()
        rhs = np.where(bounded[:, None], rhs - column * fixed_step[:, None], rhs)
        a = a.copy()
        a[bounded, :, 1] = 0.0
        a[bounded, 1, :] = 0.0
        a[bounded, 1, 1] = 1.0
        rhs[bounded, 1] = fixed_step[bounded]
    return _stacked_solve(a, rhs)


def _stacked_solve(a, rhs):
    """x of a x = rhs for stacked systems (k, p, p), each record on its own: the
    minimum-norm least-squares step (pseudo-inverse) where a record's system is singular to
    round-off (a Jacobian of rank below p: e.g. a state whose speeds do not move with its
    stability, the damping spent), no step where it is not finite. One record's system never
    aborts the others' (NumPy's stacked solve raises for the whole stack)."""
    finite = np.all(np.isfinite(a), axis=(1, 2)) & np.all(np.isfinite(rhs), axis=1)
    a = np.where(finite[:, None, None], a, np.eye(a.shape[-1]))
    rhs = np.where(finite[:, None], rhs, 0.0)
    try:
        # (the stack at once where no system is singular: the usual case, and the cheapest)
        return np.linalg.solve(a, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:
        pass
    singular_values = np.linalg.svd(a, compute_uv=False)
    regular = singular_values[:, -1] > 1e-13 * singular_values[:, 0]
    x = np.zeros_like(rhs)
    if np.any(regular):
        x[regular] = np.linalg.solve(a[regular], rhs[regular][..., None])[..., 0]
    if not np.all(regular):
        x[~regular] = np.einsum("kpq,kq->kp", np.linalg.pinv(a[~regular]), rhs[~regular])
    return x


def jacobian(model, x, r, records):
    """(k, p, m): the forward-difference Jacobian of ``model``'s normalised residuals r (k, m)
    at unknowns x (k, p) of ``records`` (k,), all unknowns and records in one evaluation; 0
    where a step leaves the model's states."""
    k, p = x.shape
    steps = _JACOBIAN_STEP * np.eye(p)[None]
    trial = (x[:, None, :] + steps).reshape(-1, p)
    rows = np.repeat(records, p)
    rt, vt, _ = model.residuals(trial, rows)
    jac = (rt - np.repeat(r, p, axis=0)) / _JACOBIAN_STEP
    # A state on a bound of the physical domain (or next to a collapse): its forward step
    # leaves the model's states, the backward one gives the slope inside.
    out = np.flatnonzero(~vt)
    if out.size:
        back = (x[:, None, :] - steps).reshape(-1, p)[out]
        rb, vb, _ = model.residuals(back, rows[out])
        jac[out] = (np.repeat(r, p, axis=0)[out] - rb) / _JACOBIAN_STEP
        vt = vt.copy()
        vt[out] = vb
    jac = jac.reshape(k, p, -1)
    return np.where(vt.reshape(k, p)[:, :, None], jac, 0.0)


def levenberg_marquardt(model, x, max_iterations, records):
    """LM iterations for unknowns x (k, p) of ``records`` (k,) (a record may appear with
    several starting points); converged rows are frozen."""
    n, p = x.shape
    r, valid, _ = model.residuals(x, records)
    cost = np.where(valid, np.sum(r**2, axis=1), np.inf)
    damping = np.full(n, 1e-3)
    active = valid.copy()
    converged = np.zeros(n, bool)
    iterations = np.zeros(n, int)
    for _ in range(max_iterations):
        index = np.flatnonzero(active)
        if index.size == 0:
            break
        xa, ra = x[index], r[index]
        jac = jacobian(model, xa, ra, records[index])
        jtj = np.einsum("kpm,kqm->kpq", jac, jac)
        jtr = np.einsum("kpm,km->kp", jac, ra)
        step = _solve_normal(jtj, jtr, damping[index], xa[:, 1], np.zeros(index.size, bool))
        # The stability bound: a step below 1/L = 0 is replaced by one held on the bound.
        bounded = xa[:, 1] + step[:, 1] < 0
        if np.any(bounded):
            held = _solve_normal(jtj, jtr, damping[index], xa[:, 1], bounded)
            step = np.where(bounded[:, None], held, step)
        x_new = xa + step
        x_new[:, 1] = np.maximum(x_new[:, 1], 0.0)
        r_new, v_new, _ = model.residuals(x_new, records[index])
        cost_new = np.where(v_new, np.sum(r_new**2, axis=1), np.inf)
        accept = cost_new <= cost[index]
        iterations[index] += 1
        small = np.max(np.abs(step), axis=1) < _STEP_TOLERANCE
        flat = accept & (cost[index] - cost_new <= 1e-14 * np.maximum(cost[index], 1e-300))
        x[index] = np.where(accept[:, None], x_new, xa)
        r[index] = np.where(accept[:, None], r_new, ra)
        cost[index] = np.where(accept, cost_new, cost[index])
        damping[index] = np.where(accept, damping[index] / 3.0, damping[index] * 4.0)
        done = (accept & (small | flat)) | (damping[index] > 1e12)
        converged[index] |= accept & (small | flat)
        active[index] = ~done
    return x, cost, converged, iterations


def covariance(model, x, valid, fitted_depth=None):
    """(n, p, p): (J^T J)^-1 of the noise-normalised residuals at the fitted unknowns x, the
    stability unknown signed (100 m/L); z_i's row and column 0 where ``fitted_depth`` is False
    (it was not an unknown there); NaN where ``valid`` is False."""
    rows = np.arange(x.shape[0])
    r0, _, _ = model.residuals(x, rows)
    # (forward steps: on the fit's own side of neutral for a fit held at 1/L = 0)
    jac = jacobian(model, x, r0, rows)
    jac[:, 1, :] *= model.sign
    if fitted_depth is not None:
        jac[~fitted_depth, -1, :] = 0.0
    jtj = np.einsum("kpm,kqm->kpq", jac, jac)
    if fitted_depth is not None:
        jtj[~fitted_depth, -1, -1] = 1.0
    # (a record whose Jacobian is not finite has no covariance: NaN, the others unaffected)
    finite = np.all(np.isfinite(jtj), axis=(1, 2))
    valid = valid & finite
    cov = np.linalg.pinv(np.where(finite[:, None, None], jtj, np.eye(jtj.shape[-1])))
    if fitted_depth is not None:
        cov[~fitted_depth, -1, :] = 0.0
        cov[~fitted_depth, :, -1] = 0.0
    cov[~valid] = np.nan
    return cov
