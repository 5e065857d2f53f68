"""The reference-wind solve (docs/atmosphere.md#reference-wind-solve): the ABL whose wind speed at
a reference height is given, instead of its geostrophic wind, as FLORIS drives a farm. For a
given u* the closure, h_hat, A, B and hence G are explicit, so the speed at the height is an
explicit function of u*: one scalar root per condition in ln u*, bracketed by the collapse
threshold below, found for all conditions at once.

It works on the ABL class's public solver interface (`EkmanABL.check_inputs`,
`EkmanABL.condition_parameters`, `EkmanABL.state_at`, `EkmanABL.set_state`, ...,
docs/atmosphere.md#the-solvers-interface); `EkmanABL.from_reference_wind` passes its class in.
"""

from __future__ import annotations

import numpy as np

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer._validation import require_at
from floris_ekman_veer.atmosphere.inputs.input_ranges import (
    MIN_BOUNDARY_LAYER_HEIGHT,
    checked,
    require_broadcastable,
)
from floris_ekman_veer.atmosphere.root_finding import secant_root

#: The tightest tolerance of the reference-wind solve (in ln speed): a few times the spacing of
#: doubles, below which no state is closer.
MIN_REFERENCE_WIND_TOLERANCE = 1e-15
#: Points of the scan in ln u* that brackets the largest root of the reference-wind solve.
_SCAN_POINTS = 64
#: Residual (in ln speed) accepted where round-off, not the method, stops the reference-wind solve.
_ROUNDOFF_ACCEPTANCE = 1e-7


def solve_reference_wind(abl_class, speed, height, tolerance, inputs):
    """The solved ``abl_class`` of ``inputs`` whose wind speed at ``height`` is ``speed``
    (`EkmanABL.from_reference_wind`, which documents the method and the arguments)."""
    speed = checked("speed", speed, lambda s: s > 0, "> 0 m/s")
    tolerance = float(checked(
        "tolerance", tolerance,
        lambda t: (np.ndim(t) == 0) & (t >= MIN_REFERENCE_WIND_TOLERANCE) & (t <= 1e-3),
        f"one number from {MIN_REFERENCE_WIND_TOLERANCE:g} to 1e-3, the tolerance on "
        "ln(speed) at the height (default 1e-13)",
    ))
    template = abl_class.check_inputs(**inputs)
    height = checked("height", height, lambda h: h > 0, "> roughness_length z0")
    require_broadcastable({"speed": speed, "height": height, **{
        name: value for name, value in inputs.items() if value is not None
    }})
    z0 = template.roughness_length
    require_at(
        height > z0, "height", "> roughness_length z0",
        np.broadcast_to(height, np.broadcast_shapes(height.shape, np.shape(z0))),
    )

    # Conditions repeat (a wind rose has few distinct speeds): solve each distinct
    # (speed, height, atmosphere) once.
    per_condition = dict(
        coriolis_parameter=template.coriolis_parameter,
        roughness_length=template.roughness_length,
        brunt_vaisala_frequency=template.brunt_vaisala_frequency,
        reference_potential_temperature=template.reference_potential_temperature,
        **{template.stability_input: template.stability_value},
        **({} if template.mixed_layer_height is None
           else {"mixed_layer_height": template.mixed_layer_height}),
    )
    shape = np.broadcast_shapes(
        speed.shape, height.shape, *(np.shape(v) for v in per_condition.values())
    )
    columns = np.stack(
        [np.broadcast_to(a, shape).ravel() for a in (speed, height, *per_condition.values())],
        axis=1,
    )
    distinct, first, inverse = np.unique(columns, axis=0, return_index=True, return_inverse=True)
    constants = {
        k: getattr(template, k)
        for k in ("von_karman", "c_g", "stress_decay", "c_tn", "c_cn", "c_ns", "matching_fraction",
                  "businger_dyer_gamma")
    }
    rows = abl_class.check_inputs(
        **{k: distinct[:, 2 + i] for i, k in enumerate(per_condition)}, **constants
    )
    target, at = distinct[:, 0], distinct[:, 1]
    p, _ = rows.condition_parameters(np.nan)

    def exists(log_u_star):
        u_star, _, h_hat, _, _, along = rows.state_at(log_u_star, p)
        return (along > 0) & rows.surface_layer_exists(u_star, h_hat, p)

    def log_speed_error(log_u_star):
        with np.errstate(all="ignore"):
            rows.set_state(log_u_star, p)
            error = np.log(np.hypot(*rows.velocity(at))) - np.log(target)
        return np.where(exists(log_u_star) & np.isfinite(error), error, -np.inf)

    log_u_star, slowest = _largest_root(log_speed_error, exists, rows, target, at, p, tolerance)
    if np.any(np.isnan(log_u_star)):
        failing = np.flatnonzero(np.isnan(log_u_star))
        bad = failing[np.argmin(first[failing])]  # the first condition that fails
        raise _no_reference_wind(
            target[bad], at[bad], slowest[bad],
            np.unravel_index(first[bad], shape), shape, inputs,
        )
    rows.set_state(log_u_star, p)
    u_star = rows.friction_velocity
    _, _, _, _, b, along = rows.state_at(log_u_star, p)
    g = (u_star * np.hypot(along, b) / rows.von_karman)[inverse.ravel()].reshape(shape)

    abl = template
    abl.geostrophic_wind = g
    abl.set_state(log_u_star[inverse.ravel()].reshape(shape), abl.condition_parameters(g, shape)[0])
    abl.require_depth(lambda mask: _reference_wind_refusal(
        abl, mask, speed, height, inputs,
        f"is h = {{h}} m deep, below the {MIN_BOUNDARY_LAYER_HEIGHT:g} m the model accepts (the "
        "stable boundary layer collapses; docs/atmosphere.md#shallow-boundary-layer): check the "
        "units of the inputs (cooling rate in K/h, heat flux in K m/s, lapse rate in K/m) or "
        "give weaker stratification",
    ))
    abl.require_domain(lambda mask, reason: _reference_wind_refusal(
        abl, mask, speed, height, inputs, f"leaves the physical domain: {reason}"))
    residual = np.abs(log_speed_error(log_u_star))
    #: |ln(speed at height / speed asked)| of each condition's solution
    abl.reference_wind_residual = residual[inverse.ravel()].reshape(shape)[()]
    missed = residual > tolerance
    if np.any(missed):
        package_warnings.warn(
            f"from_reference_wind: {np.count_nonzero(missed)} of {residual.size} distinct "
            f"conditions (wind speeds {package_warnings.speeds_text(target[missed])} at "
            f"{package_warnings.range_text(at[missed], 'm')}) meet their speed only to "
            f"{residual[missed].max():.2g} in ln speed, above the tolerance {tolerance:g}: "
            "the speed lies in the step of the profile where the top of the boundary layer "
            "crosses the height (docs/atmosphere.md#reference-wind-solve); the closest state "
            "is taken, its residual in reference_wind_residual",
            package_warnings.ReferenceWindWarning,
            items=tuple(zip(target[missed].round(6), at[missed].round(6))))
    return abl


def _largest_root(log_speed_error, exists, abl, target, height, p, tolerance):
    """ln u* of the deepest ABL whose speed at ``height`` is ``target`` (the reference-wind
    solve, docs/atmosphere.md#reference-wind-solve), NaN where no ABL reaches it, and the
    slowest speed the scanned states reach (for the message when none does).

    Bounds from the physics: below, the collapse threshold (the smallest u* with a physical
    GDL branch and a surface layer, found by bisection, the state being explicit in u*) or a
    twentieth of the log-law guess, whichever is larger; above, the guess raised until the
    speed exceeds the target (the speed grows without bound with u*). Near collapse the
    speed at a fixed height can fall while u* and h grow, so two states may give one speed: a
    scan of the bracket picks its last sign change (the state continuous with stronger winds),
    which bracketed secant steps then refine.
    """
    # Neutral log law at the reference height: within a factor ~2 of the root.
    guess = np.log(abl.von_karman * target / np.log(height / p["z0"]))
    # Collapse threshold: bisection between a collapsed state and an existing one (states
    # exist for all u* above it); e^-45 of the guess stands for "no threshold".
    high = guess.copy()
    for _ in range(60):
        missing = ~exists(high)
        if not np.any(missing):
            break
        high = np.where(missing, high + 1.0, high)
    low = np.minimum(guess - 3.0, high - 3.0)
    for _ in range(15):
        above = exists(low)
        if not np.any(above):
            break
        low = np.where(above, low - 3.0, low)
    for _ in range(100):
        active = high - low > 1e-13 * np.maximum(1.0, np.abs(high))  # the others are frozen
        if not np.any(active):
            break
        mid = 0.5 * (low + high)
        ok = exists(mid)
        high, low = np.where(active & ok, mid, high), np.where(active & ~ok, mid, low)
    threshold = high
    # Scan from a twentieth of the guess, or lower where the speed there still exceeds the target.
    lower = np.maximum(guess - 3.0, threshold)
    for _ in range(20):
        step = (lower > threshold) & (log_speed_error(lower) >= 0)
        if not np.any(step):
            break
        lower = np.where(step, np.maximum(lower - 3.0, threshold), lower)
    upper = np.maximum(guess + 0.5, lower + 0.5)
    for _ in range(60):
        short = log_speed_error(upper) < 0
        if not np.any(short):
            break
        upper = np.where(short, upper + 1.0, upper)
    grid = lower + (upper - lower) * np.linspace(0.0, 1.0, _SCAN_POINTS)[:, None]
    errors = log_speed_error(grid)
    slowest = target * np.exp(np.min(errors, axis=0))
    crossing = np.isfinite(errors[:-1]) & (errors[:-1] < 0) & (errors[1:] >= 0)
    found = np.any(crossing, axis=0)
    last = _SCAN_POINTS - 2 - np.argmax(crossing[::-1], axis=0)
    columns = np.arange(target.size)
    lo, hi = grid[last, columns], grid[last + 1, columns]
    root, converged = secant_root(log_speed_error, lo, hi, tolerance)
    # Where h crosses the height, U(height) has a square-root slope in u*: adjacent doubles of
    # ln u* then differ by ~sqrt(eps) in speed, and the secant steps end with the bracket at
    # machine precision and a residual above the tolerance; that state is taken if within
    # _ROUNDOFF_ACCEPTANCE in ln speed (a true step of the profile stays refused).
    converged |= np.abs(log_speed_error(root)) <= max(tolerance, _ROUNDOFF_ACCEPTANCE)
    return np.where(found & converged, root, np.nan), slowest


def _reference_wind_refusal(abl, mask, speed, height, inputs, reason):
    """The ValueError of a reference wind whose ABL the model refuses (too shallow, or outside
    the physical domain), at the first offending condition; ``{h}`` in ``reason`` is its depth."""
    index = tuple(np.argwhere(mask)[0]) if mask.ndim else ()
    shape = mask.shape
    varying = [i for i, n in zip(index, shape) if n > 1]
    where = "" if not varying else f" at condition {varying[0] if len(varying) == 1 else index}"
    pick = lambda v: float(np.broadcast_to(np.asarray(v, float), shape)[index])  # noqa: E731
    given = ", ".join(f"{k}={pick(v):.6g}" for k, v in inputs.items())
    return ValueError(
        f"from_reference_wind: the ABL with {pick(speed):.6g} m/s at {pick(height):.6g} m{where} "
        f"({given}) " + reason.replace("{h}", f"{pick(abl.boundary_layer_height):.3g}")
    )


def _no_reference_wind(speed, height, slowest, index, shape, inputs):
    """The ValueError of a reference wind that no ABL of the inputs reaches, in the caller's
    terms: the speed and height asked for, the condition index and the inputs there, and the
    slowest wind these inputs support at that height."""
    varying = [i for i, n in zip(index, shape) if n > 1]
    where = (
        "" if not varying
        else f" at condition {varying[0] if len(varying) == 1 else tuple(int(i) for i in index)}"
    )
    given = ", ".join(
        f"{k}={np.broadcast_to(np.asarray(v, float), shape)[index]:.6g}" for k, v in inputs.items()
    )
    if slowest < speed:
        reason = (
            f"the speed at {height:.6g} m steps past it as the boundary-layer top crosses that "
            "height (V steps onto V_g at 0.9973 h, docs/atmosphere.md#lateral-velocity-near-the-abl-top); "
            "give a slightly different speed or height"
        )
    elif np.isfinite(slowest):
        reason = (
            f"the slowest wind these inputs support at {height:.6g} m is {slowest:.4g} m/s; "
            "at lower speeds the stable boundary layer collapses (its surface layer, "
            "matching_fraction * h, shrinks to the roughness length, or the geostrophic drag law "
            "loses its physical branch). Give a higher speed, a lower reference height or "
            "weaker stratification"
        )
    else:
        reason = "the stable boundary layer collapses at every speed for these inputs"
    return ValueError(
        f"from_reference_wind: no ABL has a wind speed of {speed:.6g} m/s at {height:.6g} m"
        f"{where} ({given}): {reason}"
    )
