"""Which stability class ``EkmanABL.fit_profile(..., stability="either")`` gives records of a known
class. Hand-run script, not a test:

    PYTHONPATH=. python benchmarks/fit_stability_classes.py [n_per_class]

Records: n_per_class (default 200) per class of the model's own profiles driven by 5-12 m/s at
90 m (uniform), f_c = 1e-4 1/s, z0 = 0.1 m, N = 6.1e-3 1/s: convective (L log-uniform in
-400..-20 m, the default mixed-layer depth), neutral (L infinite) and stable (L log-uniform in
50..400 m); speeds and meteorological directions at 30, 50, ..., 150 m with 0.1 m/s and 0.5 deg of
Gaussian noise (seed 1), fitted in one call with those noises. Printed: per true class, the
fitted classes (convective -500 m <= L < 0, neutral |L| > 500 m, stable 0 < L <= 500 m), the
records refused by the chi-square test, and the largest hub-height (90 m) speed error.
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
    lengths = np.concatenate([-np.exp(rng.uniform(np.log(20.0), np.log(400.0), n)),
                              np.full(n, np.inf),
                              np.exp(rng.uniform(np.log(50.0), np.log(400.0), n))])
    hub = rng.uniform(5.0, 12.0, 3 * n)
    true = EkmanABL.from_reference_wind(hub, 90.0, obukhov_length=lengths, **SITE)
    speeds = true.speed(HEIGHTS[:, None]).T + rng.normal(0.0, 0.1, (3 * n, HEIGHTS.size))
    directions = 270.0 - true.wind_angle(HEIGHTS[:, None]).T + rng.normal(0.0, 0.5, (3 * n, HEIGHTS.size))
    return np.repeat(CLASSES, n), hub, speeds, directions


def confusion(n=200):
    """{true class: ({fitted class: count}, refused, max |hub speed error|)}."""
    truth, hub, speeds, directions = records(n)
    fit = EkmanABL.fit_profile(HEIGHTS, speeds, directions, on_misfit="flag", stability="either",
                               speed_noise=0.1, direction_noise=0.5, **SITE).profile_fit
    error = np.abs(fit.speed(np.array([90.0]))[:, 0] / hub - 1.0)
    return {
        c: ({k: int(np.sum(fit.stability_class[truth == c] == k)) for k in CLASSES},
            int(np.sum(~fit.fits[truth == c])), float(np.max(error[truth == c])))
        for c in CLASSES
    }


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    print(f"{n} records per class; fitted class counts, refused, max hub speed error")
    for true, (counts, refused, error) in confusion(n).items():
        print(f"  {true:10s} " + "  ".join(f"{k} {v:3d}" for k, v in counts.items())
              + f"  refused {refused}  max error {100 * error:.2f} %")
