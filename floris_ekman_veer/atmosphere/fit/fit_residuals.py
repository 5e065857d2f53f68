"""The residuals of the profile fit and their noise model (docs/measurements.md#noise-model): the
default noise of 10-minute mean speeds and directions, the noise of each measured speed, the
speed and direction residuals normalised by it (the directions' free rotation eliminated), and a
measured turbulence intensity's residual (docs/measurements.md#measured-turbulence)."""

from __future__ import annotations

import numpy as np

#: Default noise of a 10-minute mean speed (docs/measurements.md#noise-model): (absolute [m/s],
#: relative to the speed), sigma_U = sqrt(0.1^2 + (0.02 U)^2): the cup's calibration (about
#: 0.05 m/s + 0.5 %) and operational class (1.7/sqrt(3) = 1.0 %, IEC 61400-12-1 class 1.7A),
#: its mounting on a boom (0.5-1 %, IEC 61400-12-1 Annex G), the part of the 10-minute mean's
#: sampling error not shared by the heights (about 1.3 %), and the model's own error in a
#: profile's shape (1 %), in quadrature; 0.1 m/s of resolution and starting threshold below.
DEFAULT_SPEED_NOISE = (0.1, 0.02)
#: Default noise of a 10-minute mean direction [deg]: the vane's resolution (1.4 deg steps,
#: sigma 0.4 deg), its alignment after a boom survey or the offsets estimated from the records
#: (about 0.7 deg), the 10-minute mean's sampling (about 0.5 deg), in quadrature about 1 deg
#: (docs/measurements.md#noise-model). A vane offset not removed is a few degrees: remove it
#: first or state it here.
DEFAULT_DIRECTION_NOISE = 1.0
#: Default model error of the directions [deg], added in variance to ``direction_noise`` in the
#: chi-square refusal only (docs/measurements.md#direction-model-error): a neutral layer with 5 deg
#: of thermal-wind turning between 30 and 150 m is accepted at 0.5 deg of vane noise.
DEFAULT_DIRECTION_MODEL_ERROR = 1.0
#: A state whose chi-square exceeds the fit's by at most this lies in the fit's two-sigma
#: confidence region (one parameter): the data cannot tell it from the fit.
CONFIDENCE_CHI_SQUARE = 4.0


def wrap_angle(angle):
    """Angle difference in (-180, 180] degrees."""
    return angle - 360.0 * np.round(angle / 360.0)


def noise_pair(speed_noise):
    """(absolute [m/s], relative) of ``speed_noise``: a number is absolute alone."""
    if np.ndim(speed_noise) == 0:
        return float(speed_noise), 0.0
    absolute, relative = speed_noise
    return float(absolute), float(relative)


def speed_sigma(speeds, speed_noise):
    """[m/s] the noise of each measured speed, sqrt(a^2 + (r U)^2) (a where missing)."""
    absolute, relative = noise_pair(speed_noise)
    return np.hypot(absolute, relative * np.where(np.isfinite(speeds), speeds, 0.0))


def record_sigma(speeds, speed_noise):
    """[m/s] per record (rows of ``speeds``), the noise at its largest speed: the scale of the
    tests on what its data show (a speed maximum, a fall, a shear deficit)."""
    absolute, relative = noise_pair(speed_noise)
    largest = np.max(np.where(np.isfinite(speeds), speeds, 0.0), axis=-1)
    return np.hypot(absolute, relative * largest)


def noise_text(speed_noise):
    absolute, relative = noise_pair(speed_noise)
    return (f"{absolute:g} m/s" if relative == 0 else
            f"({absolute:g} m/s, {relative:g}): {absolute:g} m/s and {100 * relative:g} % of the "
            "speed in quadrature")


def turbulence_residual(abl, turbulence, index):
    """(k, 1): the model's I_u = sigma_u/U at the measured height (Eq. Iu_model, with the
    convective variance of docs/atmosphere.md#convective-turbulence) minus the measured one,
    divided by its noise; 0 where none is measured."""
    heights, values, noise = (np.asarray(a)[index] for a in turbulence)
    measured = np.isfinite(values)
    model = np.asarray(abl.turbulence_intensity(heights), float).reshape(-1)
    return np.where(measured, (model - np.where(measured, values, 0.0))
                    / (noise * np.where(measured, values, 1.0)), 0.0)[:, None]


def normalised_residuals(speed, angle, speeds, directions, sigma_s, sigma_d, offset=False):
    """Normalised residuals (k, n_obs) of model speeds and flow angles (k, m) against measured
    speeds and directions (NaN: missing), the number of observations per record, and (with
    ``offset``) the free rotation of the directions: measured direction plus the model's flow
    angle is constant for a perfect fit; its mean is eliminated."""
    ms = np.isfinite(speeds)
    r_s = np.where(ms, (speed - np.where(ms, speeds, 0.0)) / sigma_s, 0.0)
    observations = np.sum(ms, axis=1)
    if directions is None:
        return r_s, observations, np.zeros(len(speeds))
    md = np.isfinite(directions)
    e = np.where(md, directions, 0.0) + angle
    first = np.argmax(md, axis=1)
    e_ref = e[np.arange(len(speeds)), first]
    relative = np.where(md, wrap_angle(e - e_ref[:, None]), 0.0)
    count = np.maximum(np.sum(md, axis=1), 1)
    mean = np.sum(relative, axis=1) / count
    r_d = np.where(md, (relative - mean[:, None]) / sigma_d, 0.0)
    observations = observations + np.maximum(np.sum(md, axis=1) - 1, 0)
    return np.concatenate([r_s, r_d], axis=1), observations, e_ref + mean
