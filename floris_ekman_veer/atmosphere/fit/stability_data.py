"""What the profile fit knows of a record's stability beyond its wind profile
(docs/measurements.md#reading-stability): a weak prior on 1/L, a measured 1/L (from temperatures
through a bulk Richardson number, or a sonic anemometer's L or heat flux) as a datum, and the
largest heat flux the sun allows (an onshore site's nights: none). Their residuals join the
speeds' and directions' in the fit; the prior is no datum (it counts in no degree of freedom and
in no refusal), the measured 1/L is one."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from floris_ekman_veer._validation import real_array, require_at
from floris_ekman_veer.atmosphere.richardson import model_richardson_number

#: [1/m] The default standard deviation of the weak prior on 1/L (normal, mean 0): |L| = 50 m
#: at one standard deviation. Long-term distributions of 1/L measured at flat and coastal sites
#: spread over about +-0.01 to 0.02 1/m (Kelly & Gryning 2010, Boundary-Layer Meteorol. 136,
#: 377-390, Figs. 3-4; Gryning et al. 2007, BLM 124, 251-268): a prior of this width holds a
#: record whose profile does not tell its stability near neutral, its uncertainty the prior's,
#: and moves a record whose data do tell it by less than its own noise.
DEFAULT_STABILITY_PRIOR = 0.02


class StabilityTerms(NamedTuple):
    """Per record (n,): the prior's standard deviation of 1/L [1/m] (inf: none), a measured
    1/L [1/m] and its noise (NaN: none), and the largest sensible heat flux [W/m^2] (inf: the
    physical domain's own bound; 0: no convective state)."""

    prior: np.ndarray
    inverse_length: np.ndarray
    inverse_length_noise: np.ndarray
    max_heat_flux: np.ndarray
    #: a measured bulk Richardson number and its noise (NaN: none), and the heights
    #: ((temperature low, high), (speed low, high)) [m] it is measured between
    richardson: np.ndarray
    richardson_noise: np.ndarray
    richardson_heights: tuple = ((10.0, 80.0), (10.0, 80.0))

    def at(self, index):
        return StabilityTerms(*(a[index] for a in self[:-1]), self.richardson_heights)

    @property
    def data(self):
        """Per record: the measured 1/L and Richardson number given (0, 1 or 2 data)."""
        return np.isfinite(self.inverse_length).astype(int) + np.isfinite(self.richardson)


def _per_record(name, value, n):
    array = real_array(name, value)
    if array.ndim > 1 or (array.ndim == 1 and array.size != n):
        raise ValueError(f"fit_profile: {name} must be a number or one per record ({n}); got "
                         f"shape {array.shape}")
    return np.broadcast_to(array, (n,)).astype(float)


def checked_richardson(bulk_richardson, n):
    """(values, noise, heights) of ``bulk_richardson=(value, noise, (z_T1, z_T2), (z_U1,
    z_U2))``, or NaN data; ValueError naming what is wrong."""
    if bulk_richardson is None:
        return np.full(n, np.nan), np.full(n, np.inf), ((10.0, 80.0), (10.0, 80.0))
    try:
        value, noise, temperature_heights, speed_heights = bulk_richardson
        heights = tuple(tuple(float(z) for z in pair) for pair in (temperature_heights,
                                                                   speed_heights))
        assert all(len(pair) == 2 and 0 < pair[0] < pair[1] for pair in heights)
    except (TypeError, ValueError, AssertionError):
        raise ValueError("fit_profile: bulk_richardson must be (value, noise, (lower, upper "
                         "temperature height [m]), (lower, upper speed height [m])), value and "
                         f"noise a number or one per record ({n}); got {bulk_richardson!r}"
                         ) from None
    value = _per_record("bulk_richardson value", value, n)
    noise = _per_record("bulk_richardson noise", noise, n)
    require_at(~np.isinf(value), "bulk_richardson value", "finite (NaN: none)", value)
    require_at(np.isnan(value) | (noise > 0), "bulk_richardson noise", "> 0 where a value is "
               "given", noise)
    return value, np.where(np.isfinite(value), noise, np.inf), heights


def checked_stability_terms(stability_prior, inverse_obukhov_length, max_heat_flux, n,
                            bulk_richardson=None):
    """`StabilityTerms` of the fit's options, or ValueError naming the option and the value:
    ``stability_prior`` a number > 0 [1/m] or None (no prior); ``inverse_obukhov_length``
    (value [1/m], noise [1/m] > 0), each a number or one per record (NaN value: none);
    ``max_heat_flux`` [W/m^2] >= 0, a number or one per record (inf: no bound)."""
    if stability_prior is None:
        prior = np.full(n, np.inf)
    else:
        value = real_array("stability_prior", stability_prior)
        if value.ndim != 0 or not (np.isfinite(value) and value > 0):
            raise ValueError(f"fit_profile: stability_prior must be a number > 0 (the standard "
                             f"deviation of 1/L [1/m]) or None; got {stability_prior!r}")
        prior = np.full(n, float(value))
    values, noise = np.full(n, np.nan), np.full(n, np.inf)
    if inverse_obukhov_length is not None:
        try:
            value, sigma = inverse_obukhov_length
        except (TypeError, ValueError):
            raise ValueError("fit_profile: inverse_obukhov_length must be (value [1/m], noise "
                             f"[1/m]), each a number or one per record ({n}); got "
                             f"{inverse_obukhov_length!r}") from None
        values = _per_record("inverse_obukhov_length value", value, n)
        noise = _per_record("inverse_obukhov_length noise", sigma, n)
        require_at(~np.isinf(values), "inverse_obukhov_length value", "finite (NaN: none)",
                   values)
        require_at(np.isnan(values) | (noise > 0), "inverse_obukhov_length noise",
                   "> 0 [1/m] where a value is given", noise)
        noise = np.where(np.isfinite(values), noise, np.inf)
    cap = np.full(n, np.inf)
    if max_heat_flux is not None:
        cap = _per_record("max_heat_flux", max_heat_flux, n)
        require_at(cap >= 0, "max_heat_flux", ">= 0 W/m^2 (inf: no bound)", cap)
    return StabilityTerms(prior, values, noise, cap, *checked_richardson(bulk_richardson, n))


def stability_residuals(terms, inverse_length):
    """(k, 3): the measured 1/L's residual (model minus measured over its noise; 0 where
    none), the measured bulk Richardson number's (the Businger-Dyer one of the model's 1/L,
    `model_richardson_number`, minus the measured, over its noise) and the prior's (1/L over
    its standard deviation; 0 without a prior): the prior last."""
    measured = np.isfinite(terms.inverse_length)
    datum = np.where(measured, (inverse_length - np.where(measured, terms.inverse_length, 0.0))
                     / terms.inverse_length_noise, 0.0)
    read = np.isfinite(terms.richardson)
    richardson = np.where(read, (model_richardson_number(inverse_length, *terms.richardson_heights)
                                 - np.where(read, terms.richardson, 0.0))
                          / terms.richardson_noise, 0.0)
    return np.stack([datum, richardson, inverse_length / terms.prior], axis=1)
