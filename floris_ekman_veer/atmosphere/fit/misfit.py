"""Why a record fits no atmosphere of the model, as a person reads it (docs/measurements.md): calm,
falling speeds, a convective shear deficit, backing directions, a stable top the data do not
show (docs/measurements.md#a-top-the-data-show), and the refusal's message."""

from __future__ import annotations

import numpy as np

from floris_ekman_veer.atmosphere.fit.fit_residuals import noise_text, wrap_angle

#: Below this speed [m/s] at every height a record is calm: cup anemometers and vanes start
#: at about 0.5 to 1 m/s, and a vane below it points anywhere.
CALM_SPEED = 1.0


def misfit_reason(heights, speeds, directions, speed_noise, direction_noise, hemisphere,
                  roughness_length, stability="stable"):
    """(kind, text): why one record (heights, speeds, directions or None: its data) fits no
    atmosphere of the model, as a person reads it. ``hemisphere``: the sign of the Coriolis
    parameter.

    Kinds, in this order: ``calm`` (every speed below :data:`CALM_SPEED`), ``falling speeds``,
    ``convective`` (``stability="stable"`` only: less shear between the lowest and highest
    speeds than the neutral surface layer's log law, by more than three standard deviations of
    the noise: an unstable layer, a class the stable fit does not have), ``backing`` (the direction turns the other way than an Ekman layer),
    ``misfit``.
    """
    order = np.argsort(heights)
    z, s = heights[order], speeds[order]
    ok = np.isfinite(s)
    zs, ss = z[ok], s[ok]
    if zs.size and np.max(ss) < CALM_SPEED:
        return "calm", (f"calm: every speed below {CALM_SPEED:g} m/s (at most {np.max(ss):.2g} "
                        "m/s), where the vanes point anywhere and the layer has no Ekman profile")
    if zs.size >= 2:
        drops = ss[1:] - ss[:-1]
        if ss[-1] < ss[0] - 2.0 * speed_noise:
            return "falling speeds", (
                f"the speed falls from {ss[0]:.3g} m/s at {zs[0]:.4g} m to {ss[-1]:.3g} m/s at "
                f"{zs[-1]:.4g} m (the model's wind grows with height from the ground up to its "
                "low-level jet)")
        if drops[0] < -2.0 * speed_noise:
            return "falling speeds", (f"the speed falls with height from {zs[0]:.4g} m to "
                                      f"{zs[1]:.4g} m by {-drops[0]:.3g} m/s")
    if zs.size >= 2 and ss[0] > 0:
        log_law = np.log(zs[-1] / roughness_length) / np.log(zs[0] / roughness_length)
        spread = 3.0 * speed_noise * np.hypot(1.0, ss[-1] / ss[0]) / ss[0]
        if stability == "stable" and ss[-1] / ss[0] < log_law - spread:
            return "convective", (
                f"less shear than a neutral boundary layer, the least the model has (the speed "
                f"grows {ss[-1] / ss[0]:.3g} times from {zs[0]:.4g} m to {zs[-1]:.4g} m, the "
                f"neutral log law {log_law:.3g} times): an unstable (convective) layer, outside "
                "the stable fit's classes (neutral CNBL and stable SBL; stability=\"either\" "
                "fits convective layers too, docs/atmosphere.md#convective-boundary-layer)")
    if directions is not None:
        d = directions[order]
        okd = np.isfinite(d)
        zd, dd = z[okd], d[okd]
        if zd.size >= 2:
            change = wrap_angle(dd[-1] - dd[0])
            north = hemisphere > 0
            # (beyond three standard deviations of a difference of two vane readings)
            if hemisphere * change < -3.0 * np.sqrt(2.0) * direction_noise:
                return "backing", (
                    f"the direction {'backs' if north else 'veers'} with height by "
                    f"{abs(change):.3g} deg from {zd[0]:.4g} m to {zd[-1]:.4g} m (a front or "
                    f"cold-air advection; an Ekman layer in the "
                    f"{'northern' if north else 'southern'} hemisphere "
                    f"{'veers' if north else 'backs'}: the direction turns "
                    f"{'clockwise' if north else 'anticlockwise'} with height)"
                )
    looks = ""
    if zs.size >= 2 and ss[0] > 0:
        looks = (f": the speed grows {ss[-1] / ss[0]:.3g} times from {zs[0]:.4g} m to "
                 f"{zs[-1]:.4g} m (the neutral log law {log_law:.3g} times)")
        if directions is not None and zd.size >= 2:
            looks += (f" and the direction turns {wrap_angle(dd[-1] - dd[0]):+.3g} deg from "
                      f"{zd[0]:.4g} m to {zd[-1]:.4g} m")
    return "misfit", ("the shape of its profile is outside the model's (speed and direction "
                      "change together set u*, L and z0; a profile kinked beyond the model's, "
                      "or directions turning more than its stability allows with that shear)"
                      + looks)


#: The fraction of a fitted top within which a measurement height counts as at the top, not
#: below it: far above the fit's convergence onto a height (measured: a top 2.6e-7 of it above
#: the 30 m cup, tests/studies/site/test_site_year.py's 2025-08-26 12:00), far below any real
#: layer's distance from a cup (3 mm at 30 m).
TOP_RESOLUTION = 1e-4


def _top_changes(heights, speeds, directions, depth):
    """Per record: the speed and direction changes from the lowest height to the lowest one at
    or above ``depth`` (across the layer) and from there to the highest (above it), the largest
    speed minus the highest one's, and whether a measurement lies below ``depth``."""
    z = np.where(np.isfinite(speeds), heights, np.nan)
    rows = np.arange(len(z))
    low = np.nanargmin(z, axis=1)
    high = np.nanargmax(z, axis=1)
    above = np.where(z >= depth[:, None], z, np.inf)
    cross = np.where(np.isfinite(np.min(above, axis=1)), np.argmin(above, axis=1), high)
    s = np.where(np.isfinite(speeds), speeds, np.nan)
    changes = {
        "speed_below": s[rows, cross] - s[rows, low],
        "speed_above": s[rows, high] - s[rows, cross],
        "peak": np.nanmax(s, axis=1) - s[rows, high],
        # A measurement at the top itself (the fit's top converged onto a measurement height,
        # the misfit's kink where that height leaves the layer) reads the top's own wind: the
        # model's deficit below the top vanishes there, so only a height below the top by more
        # than TOP_RESOLUTION of it lies inside the layer and can show it.
        "below": z[rows, low] < depth * (1.0 - TOP_RESOLUTION),
    }
    if directions is not None:
        # (the vanes' own heights: a vane need not stand at a cup's height)
        measured = np.isfinite(directions)
        d = np.where(measured, directions, np.nan)
        zd = np.where(measured, heights, np.nan)
        low_d = np.argmin(np.where(measured, zd, np.inf), axis=1)
        high_d = np.argmax(np.where(measured, zd, -np.inf), axis=1)
        above_d = np.where(measured & (zd >= depth[:, None]), zd, np.inf)
        cross_d = np.where(np.isfinite(np.min(above_d, axis=1)), np.argmin(above_d, axis=1),
                           high_d)
        changes["turn_below"] = wrap_angle(d[rows, cross_d] - d[rows, low_d])
        changes["turn_above"] = wrap_angle(d[rows, high_d] - d[rows, cross_d])
    return changes


def hidden_top(heights, speeds, directions, depth, sigma_s, sigma_d):
    """Records whose boundary layer top ``depth`` lies below their highest measurement although
    their data show no top there: none of a speed maximum below the highest height (by more
    than two noise standard deviations), the shear stopping at the top (the speed grows from the
    lowest height to the first one at or above the top by more than three standard deviations of
    a difference more than it changes from there to the highest) or the veer stopping (the same
    for the direction's turning). A top below the lowest measurement is never shown: above it
    the model's wind is uniform, and no measurement reaches below it."""
    top = np.nanmax(np.where(np.isfinite(speeds), heights, np.nan), axis=1)
    shallow = np.isfinite(depth) & (depth < top)
    if not np.any(shallow):
        return shallow
    c = _top_changes(heights, speeds, directions, np.where(shallow, depth, np.inf))
    step_s, step_d = 3.0 * np.sqrt(2.0) * sigma_s, 3.0 * np.sqrt(2.0) * sigma_d
    shown = c["below"] & (c["peak"] > 2.0 * sigma_s)
    shown |= c["below"] & (c["speed_below"] - np.abs(c["speed_above"]) > step_s)
    if directions is not None:
        shown |= c["below"] & (np.abs(c["turn_below"]) - np.abs(c["turn_above"]) > step_d)
    return shallow & ~shown


def hidden_top_reason(heights, speeds, directions, depth, sigma_s, sigma_d):
    """What the data of a record refused by `hidden_top` look like, as a sentence."""
    z = heights[np.isfinite(speeds)]
    s = speeds[np.isfinite(speeds)]
    order = np.argsort(z)
    z, s = z[order], s[order]
    turn = ""
    if directions is not None:
        okd = np.isfinite(directions[0])
        zd, dd = heights[okd], directions[0][okd]
        o = np.argsort(zd)
        if zd.size >= 2:
            turn = (f" and the direction turns {wrap_angle(dd[o][-1] - dd[o][0]):+.3g} deg from "
                    f"{zd[o][0]:.4g} to {zd[o][-1]:.4g} m")
    return (f"its best fit is a stable layer only {float(depth):.3g} m deep, below the highest "
            f"measurement ({z[-1]:.4g} m), but the data show no top there (no speed maximum, "
            f"and neither the shear nor the veer stops at it): the speed grows from "
            f"{s[0]:.3g} m/s at {z[0]:.4g} m to {s[-1]:.3g} m/s at {z[-1]:.4g} m{turn}. A layer "
            "mixed above its surface layer (a convective afternoon) looks like this: "
            "stability=\"either\" fits convective layers too "
            "(docs/measurements.md#a-top-the-data-show)")


def misfit_error(failing, labels, heights, speeds, directions, speed_rms, direction_rms, misfit,
                  model, tolerance, probability, depth=None, model_error=0.0, bound=None):
    i = int(failing[0])
    hemisphere = np.sign(np.broadcast_to(model.template.coriolis_parameter, (len(speeds),))[i])
    kind, reason = misfit_reason(heights[i], speeds[i],
                                 None if directions is None else directions[i],
                                 model.sigma_record[i], model.sigma_d, hemisphere, model.z0[i],
                              "stable" if np.all(model.sign > 0) else "convective")
    if bound is not None and bound[i] and kind == "misfit":
        reason = (f"its best fit inside the model's physical domain lies on the bound of the "
                  f"{bound[i]}: the data ask for a state beyond it "
                  "(docs/measurements.md#physical-domain)")
    if depth is not None and misfit[i] <= tolerance[i]:
        d = None if directions is None else directions[i:i + 1]
        reason = hidden_top_reason(heights[i], speeds[i], d, depth[i], None, model.sigma_d)
        return ValueError(
            f"fit_profile: record {labels[i]} fits no atmosphere of the model: {reason}"
            + (f"; {failing.size - 1} more record(s) fail" if failing.size > 1 else "")
            + ". Give on_misfit='flag' to keep the fits and read profile_fit.fits")
    more = ""
    if failing.size > 1:
        shown = ", ".join(str(labels[k]) for k in failing[1:6])
        more = (f"; {failing.size - 1} more record(s) fail ({shown}"
                f"{', ...' if failing.size > 6 else ''})")
    direction = "" if directions is None else f" and the directions by {direction_rms[i]:.3g} deg"
    if not np.isfinite(misfit[i]):
        return ValueError(
            f"fit_profile: record {labels[i]} fits no atmosphere of the model: no state of the "
            f"model reaches its data: {reason}{more}. Give on_misfit='flag' to keep the other "
            "records' fits and read profile_fit.fits")
    return ValueError(
        f"fit_profile: record {labels[i]} fits no atmosphere of the model: its best fit misses "
        f"the speeds by {speed_rms[i]:.3g} m/s{direction} rms, {misfit[i]:.3g} times the noise "
        f"(speed_noise={noise_text(model.noise)}, direction_noise={model.sigma_d:g} deg"
        + (f" with direction_model_error={model_error:g} deg" if directions is not None else "")
        + "; refused "
        f"above {tolerance[i]:.3g}, refusal_probability={probability:g}): "
        f"{reason}{more}. Give "
        "on_misfit='flag' to keep the fits and read profile_fit.fits"
    )
