"""exp(-e) for e >= 0 in the compiled kernels: a table and a short Taylor factor
(docs/performance.md#the-exponential).

exp(-e) = exp(-m / EXP_STEPS) exp(-y) with m = floor(e EXP_STEPS) and 0 <= y < 1 / EXP_STEPS: the
first factor is read from a table of numpy's exp, the second is the Taylor polynomial of
EXP_TAYLOR terms (truncation below 1e-18 of it), so the value is within 2 units in the last place
of numpy's exp [``test_the_table_exp_is_numpys_to_round_off``] with arithmetic and a table
look-up only: libm's exp, a call per value, took 8 % of the rotor-cell kernel's time and 2-4 x
the cumulative wake's sum (docs/performance.md). From e = EXP_RANGE on the value is 0:
exp(-64) = 1.6e-28 of a wake's centre deficit is far below the round-off of any velocity it is
added to. NaN and negative e (which no deficit has) get numpy's exp.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .fused import JIT

EXP_STEPS = 256
EXP_RANGE = 64.0
EXP_TABLE = np.exp(-np.arange(int(EXP_RANGE) * EXP_STEPS + 2) / EXP_STEPS)
EXP_TAYLOR = np.array([1.0 / math.factorial(k) for k in range(7)])


@numba.njit(inline="always", **JIT)
def negative_exp(e):
    """exp(-e) to round-off for 0 <= e < EXP_RANGE, 0 from EXP_RANGE on (module docstring)."""
    if not 0.0 <= e < EXP_RANGE:
        return 0.0 if e >= EXP_RANGE else np.exp(-e)
    return table_exp(e)


@numba.njit(inline="always", **JIT)
def table_exp(e):
    """exp(-e) for 0 <= e < EXP_RANGE, unchecked: for a caller that has bounded e already (the
    cumulative sum's exponents lie below OVERLAP_EXPONENT_LIMIT = 16); :func:`negative_exp`
    otherwise."""
    step = math.floor(e * EXP_STEPS)
    y = step * (1.0 / EXP_STEPS) - e
    value = EXP_TAYLOR[-1]
    for term in range(EXP_TAYLOR.size - 2, -1, -1):
        value = value * y + EXP_TAYLOR[term]
    return EXP_TABLE[int(step)] * value
