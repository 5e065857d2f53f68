"""Eq. (du_model) fused into one pass over many points, for rotor-cell averages.

The readable form of the deficit is :func:`floris_ekman_veer.wake.deficit.normalised_deficit`;
this module evaluates the same formula where most factors are shared: per wake (C(x), k_w x,
the stream-tube radius, beta) and per height (t_hat and the three tanh of Eq. xi_emp depend on
z only, through U(z)), leaving per point only the polar harmonics, the width and the Gaussian.
numexpr (a FLORIS dependency) runs that per-point part in a single pass without temporaries.
tests/plugin/rotor/test_rotor_average.py checks it against ``normalised_deficit`` to round-off.
"""

from __future__ import annotations

import threading

import numexpr as ne
import numpy as np

from .deficit import (
    CURL_ALPHA,
    WIDTH_FACTOR,
    initial_radius,
    max_deficit,
    time_like_growth,
    time_like_strength,
)


class Program:
    """A numexpr expression compiled once, for float64 operands (``ne.evaluate`` without its
    per-call parsing, validation and cache look-up: the same compiled program, the same bits).
    Call it with the operands by name; they broadcast as in ``ne.evaluate``."""

    #: ``ne.evaluate``'s context in a module without ``from __future__ import division``.
    CONTEXT = {"optimization": "aggressive", "truediv": False}

    def __init__(self, expression: str):
        self.names, self.uses_vml = ne.necompiler.getExprNames(expression, self.CONTEXT)
        self.compiled = ne.NumExpr(expression, [(name, np.double) for name in self.names],
                                   **self.CONTEXT)

    def __call__(self, **operands) -> np.ndarray:
        return self.compiled(*(np.asarray(operands[name], dtype=float) for name in self.names),
                             out=None, order="K", casting="same_kind",
                             ex_uses_vml=self.uses_vml)


#: The compiled programs of each thread: a compiled numexpr program holds its temporaries, so
#: threads never share one (as numexpr's own cache).
_PROGRAMS = threading.local()


def program(expression: str) -> Program:
    """The compiled :class:`Program` of ``expression`` (compiled once per thread)."""
    programs = getattr(_PROGRAMS, "programs", None)
    if programs is None:
        programs = _PROGRAMS.programs = {}
    compiled = programs.get(expression)
    if compiled is None:
        compiled = programs[expression] = Program(expression)
    return compiled


def curl_coefficients(t_hat, alpha=CURL_ALPHA):
    """(a2, a3, a4) with xi_hat = 1 - (a2 cos 2theta + a3 cos 3theta + a4 cos 4theta), Eq. (xi_emp):

    a2 = alpha (tanh(t^2/4alpha)/2 - 5/48 tanh(t^4/16alpha)), a3 = -alpha/4 tanh(t^3/8alpha),
    a4 = 7 alpha/48 tanh(t^4/16alpha).
    """
    t = np.asarray(t_hat, dtype=float)
    tanh2, tanh3, tanh4 = (program(f"tanh(t**{k} / ({2.0**k} * alpha))")(t=t, alpha=alpha)
                           for k in (2, 3, 4))
    return (
        alpha * (0.5 * tanh2 - 5.0 / 48.0 * tanh4),
        -0.25 * alpha * tanh3,
        7.0 / 48.0 * alpha * tanh4,
    )


# Per point, with c = cos(theta) (theta := 0 at the centre, where the Gaussian is 1 whatever the
# width) and sin^2(theta) = 1 - c^2: xi_hat of Eq. (xi_emp) as the quartic in c of
# :func:`rows_deficit_parameters` (Chebyshev: cos 2t = 2c^2 - 1, cos 3t = 4c^3 - 3c,
# cos 4t = 8c^4 - 8c^2 + 1), the width of Eqs. (sigma_width), (xi0_theta) and the Gaussian.
_COSINE = "where(dy**2 + dz**2 > 0, dy / sqrt(where(dy**2 + dz**2 > 0, dy**2 + dz**2, 1)), 1)"
_CURL = "(q0 + c * (q1 + c * (q2 + c * (q3 + c * q4))))"
_SIGMA = f"(kx + xi0 / sqrt(1 - sin2b * (1 - c**2)) * {_CURL})"
_DEFICIT = f"amplitude * exp(-(dy**2 + dz**2) / (2 * {_SIGMA}**2))"
# The near wake's super-Gaussian of order n (wake/near_wake.py; its width factor is in kx, xi0).
_SHAPED = f"amplitude * exp(-((dy**2 + dz**2) / (2 * {_SIGMA}**2))**(0.5 * order))"


def wake_deficit_parameters(x, k_w, radius, ct, yaw, friction_velocity, hub_speed, curl=True,
                            shape=None):
    """The per-wake factors of Eq. (du_model) (see :func:`rows_deficit_parameters`), evaluated
    once per wake: C(x), k_w x, xi0 / |cos beta|'s numerator, sin^2 beta and t_hat's prefactor;
    with ``shape`` = (n, m) of the near wake (wake/near_wake.py) also the order n, the width
    factor m scaling k_w x and xi0 (sigma is linear in both; m = 1 leaves them bit for bit)."""
    r_tube = initial_radius(radius, ct, yaw)
    parameters = {
        "amplitude": max_deficit(x, k_w, radius, ct, yaw),
        "kx": np.asarray(k_w) * np.asarray(x),
        "xi0": WIDTH_FACTOR * r_tube * np.abs(np.cos(yaw)),
        "sin2b": np.sin(yaw) ** 2,
    }
    if shape is not None:
        order, factor = shape
        parameters["kx"] = parameters["kx"] * factor
        parameters["xi0"] = parameters["xi0"] * factor
        parameters["order"] = order
    if curl:
        parameters["strength"] = time_like_strength(friction_velocity, hub_speed, ct, yaw)
    return parameters


def rows_deficit_parameters(x, k_w, radius, ct, yaw, friction_velocity, hub_speed, local_speed,
                            curl=True, wake=None):
    """The per-wake and per-height factors of Eq. (du_model) (see :func:`deficit_on_rows`).

    ``x`` (> 0), ``k_w``, ``radius``, ``ct``, ``yaw``, ``friction_velocity``, ``hub_speed``
    broadcast per wake; ``local_speed`` U(z) per height (> 0). ``wake``: the per-wake factors
    of :func:`wake_deficit_parameters` at the same points, if already evaluated (once per wake,
    then gathered to its heights). Returns a dict of arrays.
    """
    if wake is None:
        wake = wake_deficit_parameters(x, k_w, radius, ct, yaw, friction_velocity, hub_speed,
                                       curl)
    if curl:
        t_hat = wake["strength"] * time_like_growth(x, friction_velocity, local_speed, radius)
        a2, a3, a4 = curl_coefficients(t_hat)
    else:
        a2 = a3 = a4 = np.zeros(1)
    # xi_hat = 1 - (a2 (2c^2 - 1) + a3 (4c^3 - 3c) + a4 (8c^4 - 8c^2 + 1)) = sum_k q_k c^k.
    return {
        **{k: wake[k] for k in ("amplitude", "kx", "xi0", "sin2b", "order") if k in wake},
        "q0": 1.0 + a2 - a4, "q1": 3.0 * a3, "q2": 8.0 * a4 - 2.0 * a2, "q3": -4.0 * a3,
        "q4": -8.0 * a4,
    }


def deficit_on_rows(dy, dz, parameters):
    """Delta u / U_h of Eq. (du_model) at points (dy, dz) from the factors of
    :func:`rows_deficit_parameters` (two numexpr passes: cos(theta), then the deficit)."""
    c = program(_COSINE)(dy=dy, dz=dz)
    gaussian = {k: v for k, v in parameters.items() if k != "order"}
    deficit = program(_DEFICIT)(dy=dy, dz=dz, c=c, **gaussian)
    order = parameters.get("order")
    if order is None or not np.any(order != 2.0):
        return deficit
    # Inside a potential core: the super-Gaussian there, the Gaussian (bit for bit) elsewhere.
    shaped = program(_SHAPED)(dy=dy, dz=dz, c=c, **parameters)
    return np.where(order == 2.0, deficit, shaped)
