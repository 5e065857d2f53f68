"""Robustness of the ABL inflow over random valid inputs (run by hand; docs/atmosphere.md#reference-wind-solve).

Usage::

    python -m benchmarks.abl_robustness [n_per_kind] [seed]

Draws ``n_per_kind`` random inputs for each stability input kind (neutral, stability parameter,
cooling rate, surface heat flux, Obukhov length) over the ranges a user meets: reference wind
2-30 m/s at 20-200 m, |latitude| 5-80 deg (both hemispheres), z0 1e-4 to 1 m (log-uniform),
N 0-0.02 1/s. For each it reports

* ``from_reference_wind`` refusals of states outside the physical domain
  (docs/atmosphere.md#physical-domain), counted apart;
* ``from_reference_wind`` failures, and how many of them have a solution. Existence is decided
  independently of the root solve: the ABL is parametrised by u* (mu, h_hat, A, B and G are
  explicit in u*), a log-spaced u* scan keeps the states with a physical branch (ln Ro > A) and
  a surface layer (0.2 h > z0), the forward solve ``EkmanABL(geostrophic_wind=G(u*))`` gives the
  speed at the reference height, and a solution exists if the target speed lies between the
  scan's smallest and largest speeds;
* the hub-aligned streamwise U just above the ground (heights z0 * [0.01 .. 30]) where the solve
  succeeds: count of cases with U < 0 anywhere, the minimum U/G and the deepest ABL among them.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from floris_ekman_veer.atmosphere.ekman import MIN_BOUNDARY_LAYER_HEIGHT, EkmanABL

KINDS = ("neutral", "stability_parameter", "cooling_rate", "surface_heat_flux", "obukhov_length")


def draw(rng, kind):
    inputs = dict(
        latitude=rng.choice([-1.0, 1.0]) * rng.uniform(5.0, 80.0),
        roughness_length=10.0 ** rng.uniform(-4.0, 0.0),
        brunt_vaisala_frequency=rng.uniform(0.0, 0.02),
    )
    if kind == "stability_parameter":
        inputs[kind] = rng.uniform(0.0, 300.0)
    elif kind == "cooling_rate":
        inputs[kind] = -rng.uniform(0.0, 2.0)
    elif kind == "surface_heat_flux":
        inputs[kind] = -rng.uniform(0.0, 0.05)
    elif kind == "obukhov_length":
        inputs[kind] = 10.0 ** rng.uniform(1.0, 3.5)
    return rng.uniform(2.0, 30.0), rng.uniform(20.0, 200.0), inputs


def solution_exists(speed, height, inputs):
    """Whether some valid ABL has |(U, V)(height)| = speed (scan in u*, see the module doc)."""
    probe = EkmanABL.check_inputs(**inputs)
    params, _ = probe._parameters(1000.0)
    p = {k: np.asarray(v).ravel()[0] for k, v in params.items()}
    log_u = np.log(np.logspace(-5, 1, 3000))
    u_star, _, h_hat, _, b, along = probe._state(log_u, p)
    depth = h_hat * u_star / p["f"]
    # a model state: a physical branch, a surface layer, and h at least the shallowest accepted
    valid = ((along > 0) & (probe.matching_fraction * depth > p["z0"])
             & (depth >= MIN_BOUNDARY_LAYER_HEIGHT))
    if not np.any(valid):
        return False
    g = u_star[valid] * np.hypot(along[valid], b[valid]) / probe.von_karman
    # the states themselves (explicit in u*), the physical domain aside: existence of a root
    speeds = EkmanABL.solved_at(log_u[valid], g, **inputs).speed(height)
    return bool(speeds.min() <= speed <= speeds.max())


def main(n_per_kind=800, seed=0):
    rng = np.random.default_rng(seed)
    total = failed = solvable = negative = outside = 0
    worst = 0.0
    deepest_negative = 0.0  # largest h among the cases with U < 0
    examples = []
    start = time.perf_counter()
    for kind in KINDS:
        kind_failed = kind_solvable = kind_outside = 0
        for _ in range(n_per_kind):
            speed, height, inputs = draw(rng, kind)
            total += 1
            try:
                abl = EkmanABL.from_reference_wind(speed, height, **inputs)
            except ValueError as refusal:
                if "physical domain" in str(refusal):  # solved, then refused for what it implies
                    kind_outside += 1
                    continue
                kind_failed += 1
                if solution_exists(speed, height, inputs):
                    kind_solvable += 1
                    if len(examples) < 3:
                        examples.append((speed, height, inputs))
                continue
            z = inputs["roughness_length"] * np.geomspace(0.01, 30.0, 200)
            if _old_api():  # before the roughness sublayer the profile raised below z0
                z = z[z >= inputs["roughness_length"]]
            u, _ = abl.hub_aligned_velocity(z, height)
            if np.min(u) < 0:
                negative += 1
                worst = min(worst, float(np.min(u) / abl.geostrophic_wind))
                deepest_negative = max(deepest_negative, float(abl.boundary_layer_height))
                if len(examples) < 6:
                    examples.append(("U < 0", speed, height, inputs))
        failed += kind_failed
        solvable += kind_solvable
        outside += kind_outside
        print(f"{kind:20s} inputs {n_per_kind}: from_reference_wind failures {kind_failed} "
              f"(with a solution: {kind_solvable}), outside the physical domain {kind_outside}")
    print(f"all kinds: inputs {total}, failures {failed}, of which solvable {solvable}; "
          f"outside the physical domain {outside}; "
          f"hub-aligned U < 0 near the ground in {negative} solved cases (min U/G {worst:.3g}, "
          f"largest h among them {deepest_negative:.3g} m); "
          f"{time.perf_counter() - start:.0f} s")
    for example in examples:
        print("solvable failure:", example)


def _old_api():
    import inspect

    return "below_roughness" in inspect.signature(EkmanABL.velocity).parameters


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:]))
