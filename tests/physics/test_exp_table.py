"""The compiled functions' exp(-e) (wake/fused.py, docs/performance.md#the-exponential)."""

from __future__ import annotations

import numba
import numpy as np

from floris_ekman_veer.wake.fused import EXP_RANGE, EXP_STEPS, negative_exp, table_exp


def _elementwise(scalar):
    """The compiled scalar function ``scalar`` on every element of an array (compiled)."""
    @numba.njit
    def on(values):
        out = np.empty(values.size)
        for k in range(values.size):
            out[k] = scalar(values[k])
        return out
    return on


_on, _unchecked = _elementwise(negative_exp), _elementwise(table_exp)


def test_the_table_exp_is_numpys_to_round_off():
    """On [0, EXP_RANGE), at the table's nodes, just either side of them and near 0, within 2
    units in the last place of numpy's exp."""
    nodes = np.arange(int(EXP_RANGE) * EXP_STEPS) / EXP_STEPS
    e = np.concatenate([np.linspace(0.0, EXP_RANGE, 200001, endpoint=False), nodes,
                        np.nextafter(nodes, 0.0)[1:], np.nextafter(nodes, np.inf),
                        np.geomspace(1e-300, 1.0, 301)])
    np.testing.assert_allclose(_on(e), np.exp(-e), rtol=4.5e-16, atol=0.0)
    assert _on(np.zeros(1))[0] == 1.0
    # the unchecked form (the cumulative sum's, its exponents bounded by its caller): the same
    np.testing.assert_array_equal(_unchecked(e), _on(e))


def test_the_table_exp_is_zero_from_its_range_and_numpys_outside_the_deficits_domain():
    """0 from EXP_RANGE on (exp(-64) = 1.6e-28 of a deficit: below any velocity's round-off);
    NaN stays NaN and a negative e (no deficit has one) gets numpy's exp, never a table read
    out of bounds."""
    beyond = np.array([EXP_RANGE, np.nextafter(EXP_RANGE, np.inf), 1e3, np.inf])
    np.testing.assert_array_equal(_on(beyond), 0.0)
    assert np.exp(-np.nextafter(EXP_RANGE, 0.0)) < 1.7e-28
    assert np.isnan(_on(np.array([np.nan]))[0])
    negative = np.array([-1e-300, -0.5, -3.0])
    np.testing.assert_array_equal(_on(negative), np.exp(-negative))
