"""Time the EkmanABL solver. Hand-run script, not a test:

    python -m benchmarks.bench_abl

1. 100,000 distinct conditions solved at once (random G, z0, cooling rate; then with mu given),
   reported as conditions per second, best of 3.
2. ``EkmanABL.from_reference_wind`` for 1000 distinct speeds at 100 m, and for a 1000-condition
   wind rose (40 directions x 25 speeds: the ABL does not depend on direction, so 25 distinct
   solves, which the driver finds by de-duplication).
"""

import time

import numpy as np

from floris_ekman_veer.atmosphere.ekman import EkmanABL

N, REPEATS = 100_000, 3
ATMOSPHERE = dict(latitude=45.0, roughness_length=0.1, cooling_rate=-0.5)


def best_of(function, repeats=REPEATS):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), result


def main():
    rng = np.random.default_rng(0)
    g = rng.uniform(4.0, 30.0, N)
    z0 = np.exp(rng.uniform(np.log(1e-3), np.log(0.5), N))
    c_r = rng.uniform(-1.0, 0.0, N)
    # to mu = 133: with G to 30 m/s, mu up to 200 implies H below -300 W/m^2 in 0.14 % of the
    # draws, outside the physical domain (docs/atmosphere.md#physical-domain)
    mu = rng.uniform(0.0, 200.0, N) / 1.5
    common = dict(geostrophic_wind=g, roughness_length=z0, latitude=45.0)

    for label, stability in (("cooling rate", dict(cooling_rate=c_r)),
                             ("mu given", dict(stability_parameter=mu))):
        t, abl = best_of(lambda: EkmanABL(**common, **stability))
        assert np.all(np.isfinite(abl.friction_velocity))
        print(f"solve {N:,} conditions ({label:12s}): {t:7.3f} s  ->  {N / t:12,.0f} conditions/s")

    speeds = np.linspace(3.0, 25.0, 1000)
    t, abl = best_of(lambda: EkmanABL.from_reference_wind(speeds, 100.0, **ATMOSPHERE))
    error = np.max(np.abs(abl.speed(100.0) / speeds - 1))
    print(f"from_reference_wind, 1000 distinct speeds:        {t:7.3f} s  "
          f"(max rel. speed error {error:.1e})")

    rose_speeds = np.tile(np.linspace(3.0, 25.0, 25), 40)  # 40 directions x 25 speeds
    t, abl = best_of(lambda: EkmanABL.from_reference_wind(rose_speeds, 100.0, **ATMOSPHERE))
    error = np.max(np.abs(abl.speed(100.0) / rose_speeds - 1))
    print(f"from_reference_wind, wind rose 40 x 25 = 1000:    {t:7.3f} s  "
          f"(max rel. speed error {error:.1e})")


if __name__ == "__main__":
    main()
