"""Which stability class ``EkmanABL.fit_profile(..., stability="either")`` gives records of a known
class. Hand-run script, not a test:

    python -m benchmarks.fit_stability_classes [n_per_class]

Records: n_per_class (default 200) per class of the model's own profiles driven by 5-12 m/s at
90 m (uniform), f_c = 1e-4 1/s, z0 = 0.1 m, N = 6.1e-3 1/s: convective (the surface sensible
heat flux log-uniform in 20..700 W/m^2, inside the physical domain of
docs/atmosphere.md#physical-domain; the default mixed-layer depth), neutral (L infinite) and
stable (L log-uniform in 50..400 m); speeds and meteorological directions at 30, 50, ..., 150 m with 0.1 m/s and 0.5 deg of
Gaussian noise (seed 1), fitted in one call with those noises. Printed: per true class, the
fitted classes (convective -500 m <= L < 0, neutral |L| > 500 m, stable 0 < L <= 500 m), the
records refused by the chi-square test, and the largest hub-height (90 m) speed error.

Then the same for n_per_class records per class written from published forms, not by the model
(``published_records``): convective, a Businger-Dyer surface layer (Paulson 1970's psi_m with
gamma 16) up to a top log-uniform in 50..200 m with a well-mixed layer above it (uniform speed
and direction), L log-uniform in -400..-20 m; neutral, the log law with a constant direction
(no stable class: a surface-layer form does not reach 150 m in a stable layer, which is
shallow); u* uniform in 0.2..0.6 m/s; mixed_layer_height 1000 m; the same noise. Printed as
above plus, for the convective class, the share and the largest of the relative errors of the
fitted I_u(90 m) against Panofsky et al. (1977)'s sigma_u/u* = (12 - 0.5 z_i/L)^(1/3), z_i =
1000 m, without and with that I_u given as measured (``turbulence_intensity``), how many have
Panofsky's value inside the fit's two-sigma interval (``ProfileFit.turbulence_intensity_interval``)
and the largest hub speed error of the accepted convective records at hub speeds >= 6 m/s. Then
why the I_u misses without the measurement (``intensity_sources``): the records within 20 % at the
true state by the model's law, with the fitted u* or the fitted L alone, as fitted with and
without the noise, the median fitted / true L, and the convective fits with z_i fixed at 700,
1500 and 2500 m (records within 20 %, median misfit).

Last, neutral records whose direction turns with height more than the model's neutral layer does
(``turning_records``, docs/measurements.md#direction-model-error): the log law (u* 0.2-0.6 m/s in
12 steps, 7 records each: 84 records, hub speeds 3.4-10.2 m/s) with the direction turning
linearly by +5 deg (veering), -5 deg (backing) or 0 from 30 to 150 m, the same noise (seed 3);
printed per turning: the records accepted with the default ``direction_model_error`` (1 deg) and
with 0, the fitted classes, and the largest hub speed error of the accepted records with hub
speed >= 6 m/s and below.
"""

import sys

import numpy as np

from floris_ekman_veer.atmosphere.ekman import EkmanABL

SITE = dict(coriolis_parameter=1e-4, brunt_vaisala_frequency=6.1e-3,
            reference_potential_temperature=265.0, roughness_length=0.1)
HEIGHTS = np.arange(30.0, 151.0, 20.0)
CLASSES = ("convective", "neutral", "stable")


def records(n, seed=1):
    """(true class, hub speed, speeds, directions) of n records per class."""
    rng = np.random.default_rng(seed)
    heat_flux = np.exp(rng.uniform(np.log(20.0), np.log(700.0), n))
    lengths = np.concatenate([np.full(n, np.inf),
                              np.exp(rng.uniform(np.log(50.0), np.log(400.0), n))])
    hub = rng.uniform(5.0, 12.0, 3 * n)
    truths = (EkmanABL.from_reference_wind(hub[:n], 90.0, sensible_heat_flux=heat_flux, **SITE),
              EkmanABL.from_reference_wind(hub[n:], 90.0, obukhov_length=lengths, **SITE))
    speeds = np.concatenate([t.speed(HEIGHTS[:, None]).T for t in truths])
    angles = np.concatenate([t.wind_angle(HEIGHTS[:, None]).T for t in truths])
    speeds = speeds + rng.normal(0.0, 0.1, (3 * n, HEIGHTS.size))
    directions = 270.0 - angles + rng.normal(0.0, 0.5, (3 * n, HEIGHTS.size))
    return np.repeat(CLASSES, n), hub, speeds, directions


def confusion(n=200, **options):
    """{true class: ({fitted class: count}, refused, max |hub speed error|)} (``options``: the
    fit's, e.g. ``stability_prior``)."""
    truth, hub, speeds, directions = records(n)
    fit = EkmanABL.fit_profile(HEIGHTS, speeds, directions, on_misfit="flag", stability="either",
                               speed_noise=0.1, direction_noise=0.5, **SITE,
                               **options).profile_fit
    error = np.abs(fit.speed(np.array([90.0]))[:, 0] / hub - 1.0)
    return {
        c: ({k: int(np.sum(fit.stability_class[truth == c] == k)) for k in CLASSES},
            int(np.sum(~fit.fits[truth == c])), float(np.max(error[truth == c])))
        for c in CLASSES
    }


def _psi_m(z, length):
    x = (1.0 - 16.0 * z / length) ** 0.25
    return 2 * np.log((1 + x) / 2) + np.log((1 + x * x) / 2) - 2 * np.arctan(x) + np.pi / 2


def published_records(n, seed=2, noise=True):
    """(true class, hub speed, speeds, directions, true L, u*) from the published forms
    (``noise=False``: the same records without their noise)."""
    rng = np.random.default_rng(seed)
    z0, kappa = SITE["roughness_length"], 0.4
    u_star = rng.uniform(0.2, 0.6, 2 * n)[:, None]
    convective = -np.exp(rng.uniform(np.log(20.0), np.log(400.0), n))
    top = np.exp(rng.uniform(np.log(50.0), np.log(200.0), n))[:, None]
    z = np.minimum(HEIGHTS[None, :], top)
    L = convective[:, None]
    shapes = [np.log(z / z0) - _psi_m(z, L) + _psi_m(z0, L),
              np.broadcast_to(np.log(HEIGHTS / z0), (n, HEIGHTS.size))]
    speeds = u_star / kappa * np.concatenate(shapes)
    hub_shapes = [np.log(np.minimum(90.0, top[:, 0]) / z0) - _psi_m(np.minimum(90.0, top[:, 0]), convective)
                  + _psi_m(z0, convective), np.full(n, np.log(90.0 / z0))]
    hub = u_star[:, 0] / kappa * np.concatenate(hub_shapes)
    speeds = speeds + noise * rng.normal(0.0, 0.1, speeds.shape)
    directions = 250.0 + noise * rng.normal(0.0, 0.5, speeds.shape)
    lengths = np.concatenate([convective, np.full(n, np.inf)])
    return np.repeat(CLASSES[:2], n), hub, speeds, directions, lengths, u_star[:, 0]


def published_confusion(n=200):
    """As :func:`confusion` for :func:`published_records`, the convective class's
    |I_u(90 m) / Panofsky - 1| without and with the measured I_u, and how many of the convective
    records have Panofsky's I_u inside the fit's two-sigma interval
    (``ProfileFit.turbulence_intensity_interval``)."""
    truth, hub, speeds, directions, lengths, u_star = published_records(n)
    conv = truth == "convective"
    panofsky = u_star[conv] * (12.0 - 0.5 * 1000.0 / lengths[conv]) ** (1 / 3) / hub[conv]
    measured = np.full(truth.size, np.nan)
    measured[conv] = panofsky
    out = []
    for given in (None, (90.0, measured)):
        abl = EkmanABL.fit_profile(HEIGHTS, speeds, directions, on_misfit="flag",
                                   stability="either", speed_noise=0.1, direction_noise=0.5,
                                   mixed_layer_height=1000.0, turbulence_intensity=given, **SITE)
        fit = abl.profile_fit
        error = np.abs(fit.speed(np.array([90.0]))[:, 0] / hub - 1.0)
        intensity = np.reshape(abl.turbulence_intensity(90.0), -1)[conv]
        low, high = (np.reshape(a, -1)[conv] for a in fit.turbulence_intensity_interval(90.0))
        inside = int(np.sum((low <= panofsky) & (panofsky <= high)))
        # the largest hub error of the accepted convective records at hub speeds >= 6 m/s
        strong = conv & np.asarray(fit.fits) & (hub >= 6.0)
        inside = (inside, float(np.max(error[strong], initial=0.0)))
        out.append(({
            c: ({k: int(np.sum(fit.stability_class[truth == c] == k)) for k in CLASSES},
                int(np.sum(~fit.fits[truth == c])), float(np.max(error[truth == c])))
            for c in CLASSES[:2]
        }, np.abs(intensity / panofsky - 1.0), inside))
    return out


def intensity_sources(n=200):
    """Why the fitted I_u(90 m) of :func:`published_records`' convective class misses Panofsky's
    without a measured I_u: of n records, how many are within 20 % with (a) the model's own
    variance law (Eq. Iu_model with the convective excess) at the TRUE u*, L and z_i = 1000 m,
    (b) the fitted u* and the true L, (c) the true u* and the fitted L, (d) the fit of the same
    records without noise, and the median fitted L / true L (with noise, and without)."""
    from floris_ekman_veer.atmosphere.turbulence import (TOWNSEND_PERRY_A1, TOWNSEND_PERRY_B1,
                                                         convective_variance)

    def law(u_star, length, hub):
        variance = (TOWNSEND_PERRY_A1 * np.log(1000.0 / 90.0) + TOWNSEND_PERRY_B1
                    + convective_variance(1000.0, length))
        return np.sqrt(variance) * u_star / hub

    out = {"depths": {}}
    truth, hub, speeds, directions, lengths, u_star = published_records(n)
    conv = truth == "convective"
    panofsky = u_star[conv] * (12.0 - 0.5 * 1000.0 / lengths[conv]) ** (1 / 3) / hub[conv]
    for depth in (700.0, 1500.0, 2500.0):
        abl = EkmanABL.fit_profile(HEIGHTS, speeds[conv], directions[conv], on_misfit="flag",
                                   stability="convective", speed_noise=0.1, direction_noise=0.5,
                                   mixed_layer_height=depth, **SITE)
        intensity = np.reshape(abl.turbulence_intensity(90.0), -1)
        out["depths"][depth] = (int(np.sum(np.abs(intensity / panofsky - 1.0) <= 0.2)),
                                float(np.median(abl.profile_fit.misfit)))
    for noise in (True, False):
        truth, hub, speeds, directions, lengths, u_star = published_records(n, noise=noise)
        conv = truth == "convective"
        hub, lengths, u_star = hub[conv], lengths[conv], u_star[conv]
        panofsky = u_star * (12.0 - 0.5 * 1000.0 / lengths) ** (1 / 3) / hub
        abl = EkmanABL.fit_profile(HEIGHTS, speeds[conv], directions[conv], on_misfit="flag",
                                   stability="either", speed_noise=0.1, direction_noise=0.5,
                                   mixed_layer_height=1000.0, **SITE)
        fit = abl.profile_fit
        within = lambda i: int(np.sum(np.abs(i / panofsky - 1.0) <= 0.2))  # noqa: E731
        key = "noisy" if noise else "noise-free"
        out[key] = dict(fitted=within(np.reshape(abl.turbulence_intensity(90.0), -1)),
                        length_ratio=float(np.median(fit.obukhov_length / lengths)))
        if noise:
            out[key] |= dict(true_state=within(law(u_star, lengths, hub)),
                             fitted_u_star=within(law(fit.friction_velocity, lengths, hub)),
                             fitted_length=within(law(u_star, fit.obukhov_length, hub)))
    return out


TURNING_FRICTION_VELOCITIES = np.repeat(np.linspace(0.2, 0.6, 12), 7)


def turning_records(turn, seed=3):
    """(hub speed, speeds, directions) of the 84 neutral log-law records with the direction
    turning linearly by ``turn`` [deg] from 30 to 150 m, 0.1 m/s and 0.5 deg of noise."""
    rng = np.random.default_rng(seed)
    u_star = TURNING_FRICTION_VELOCITIES[:, None]
    z0 = SITE["roughness_length"]
    speeds = u_star / 0.4 * np.log(HEIGHTS / z0) + rng.normal(0.0, 0.1, (u_star.size, HEIGHTS.size))
    directions = (250.0 + turn * (HEIGHTS - HEIGHTS[0]) / (HEIGHTS[-1] - HEIGHTS[0])
                  + rng.normal(0.0, 0.5, speeds.shape))
    return u_star[:, 0] / 0.4 * np.log(90.0 / z0), speeds, directions


def turning_acceptance(turn, **options):
    """(accepted, {fitted class: count}, largest hub error of the accepted at hub >= 6 m/s, and
    below) for :func:`turning_records` fitted with ``stability="either"``."""
    hub, speeds, directions = turning_records(turn)
    fit = EkmanABL.fit_profile(HEIGHTS, speeds, directions, on_misfit="flag", stability="either",
                               speed_noise=0.1, direction_noise=0.5, **SITE,
                               **options).profile_fit
    error = np.abs(fit.speed(np.array([90.0]))[:, 0] / hub - 1.0)
    fits = np.asarray(fit.fits)
    largest = [float(np.max(error[fits & part], initial=0.0)) for part in (hub >= 6.0, hub < 6.0)]
    return (int(np.sum(fits)), {k: int(np.sum(fit.stability_class[fits] == k)) for k in CLASSES},
            *largest)


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    print(f"{n} records per class; fitted class counts, refused, max hub speed error")
    for true, (counts, refused, error) in confusion(n).items():
        print(f"  {true:10s} " + "  ".join(f"{k} {v:3d}" for k, v in counts.items())
              + f"  refused {refused}  max error {100 * error:.2f} %")
    for title, (table, intensity, (inside, strong)) in zip(
            ("published forms", "published forms, I_u(90 m) given"), published_confusion(n)):
        print(f"{title}: convective class |I_u(90 m)/Panofsky - 1| <= 20 % in "
              f"{int(np.sum(intensity <= 0.2))} of {intensity.size}, largest "
              f"{100 * np.max(intensity):.1f} %; Panofsky inside the fit's two-sigma interval "
              f"in {inside}; largest hub error of the accepted at hub >= 6 m/s "
              f"{100 * strong:.2f} %")
        for true, (counts, refused, error) in table.items():
            print(f"  {true:10s} " + "  ".join(f"{k} {v:3d}" for k, v in counts.items())
                  + f"  refused {refused}  max error {100 * error:.2f} %")
    sources = intensity_sources(n)
    print(f"published convective records, I_u(90 m) within 20 % of Panofsky (of {n}): model law "
          f"at the true state {sources['noisy']['true_state']}, fitted u* with true L "
          f"{sources['noisy']['fitted_u_star']}, true u* with fitted L "
          f"{sources['noisy']['fitted_length']}, fitted {sources['noisy']['fitted']}, fitted "
          f"without noise {sources['noise-free']['fitted']}; median fitted L / true L "
          f"{sources['noisy']['length_ratio']:.2f} ({sources['noise-free']['length_ratio']:.2f} "
          "without noise); convective fits with z_i fixed at "
          + ", ".join(f"{d:g} m: {w} within 20 %, median misfit {m:.2f}"
                      for d, (w, m) in sources["depths"].items()))
    print(f"neutral log law turning with height, {TURNING_FRICTION_VELOCITIES.size} records each: "
          "accepted with direction_model_error 1 deg (default) and 0; classes and largest hub "
          "speed error of the accepted (hub >= 6 m/s / below)")
    for turn in (5.0, -5.0, 0.0):
        accepted, classes, high, low = turning_acceptance(turn)
        alone = turning_acceptance(turn, direction_model_error=0.0)[0]
        print(f"  turning {turn:+g} deg: accepted {accepted} (with 0: {alone})  "
              + "  ".join(f"{k} {v:2d}" for k, v in classes.items())
              + f"  max error {100 * high:.2f} % / {100 * low:.2f} %")
