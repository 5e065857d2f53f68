"""The threads of a wake step's compiled passes (plugin/rotor/rotor_threads.py): every rotor in
exactly one share, every share run, errors raised at the caller, and a forked worker (FLORIS's
ParFlorisModel) running them on its own pool."""

from __future__ import annotations

import copy
import signal
import warnings
from pathlib import Path

import numba
import numpy as np
import pytest
from floris import FlorisModel, ParFlorisModel
from floris.utilities import load_yaml

import floris_ekman_veer  # noqa: F401  (registers the models)
from floris_ekman_veer.plugin.rotor import rotor_threads
from floris_ekman_veer.plugin.rotor.rotor_threads import (
    ROTOR_BLOCK,
    in_share,
    next_in_share,
    shares,
    split_over_threads,
)

INPUTS = Path(__file__).resolve().parents[3] / "inputs"


@numba.njit(nogil=True)
def _count_shares(visits, first, stride):
    for k in range(visits.size):
        if in_share(k, first, stride):
            visits[k] += 1


@pytest.mark.parametrize("stride", [1, 2, 3, 5])
def test_every_rotor_is_in_exactly_one_share_of_whole_blocks(stride):
    rotors = 7 * ROTOR_BLOCK + 5
    owner = np.full(rotors, -1)
    for first in range(stride):
        visits = np.zeros(rotors, dtype=np.int64)
        _count_shares(visits, first, stride)
        assert np.all(owner[visits == 1] == -1)
        owner[visits == 1] = first
    assert np.all(owner >= 0)
    # Block-cyclic: block b (ROTOR_BLOCK consecutive rotors) belongs to share b mod stride.
    np.testing.assert_array_equal(owner, (np.arange(rotors) // ROTOR_BLOCK) % stride)


@numba.njit
def _next_in_shares(first, stride, rotors):
    following = np.full(rotors, -1)
    for k in range(rotors):
        if in_share(k, first, stride):
            following[k] = next_in_share(k, first, stride)
    return following


@pytest.mark.parametrize("stride", [1, 2, 3, 5])
def test_the_next_rotor_of_a_share_is_its_next_member(stride):
    # (the cumulative pass prefetches the next wake's entries of its own share)
    rotors = 7 * ROTOR_BLOCK + 5
    owner = (np.arange(3 * rotors) // ROTOR_BLOCK) % stride
    for first in range(stride):
        members = np.flatnonzero(owner == first)
        following = _next_in_shares(first, stride, rotors)
        inside = members[members < rotors]
        np.testing.assert_array_equal(following[inside],
                                      members[np.searchsorted(members, inside) + 1])
        assert np.all(following[owner[:rotors] != first] == -1)


def test_shares_follow_numbas_thread_count_and_the_blocks():
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        assert shares(10 * ROTOR_BLOCK) == 1
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        assert shares(1) == 1  # one block: nothing to share
        assert shares(ROTOR_BLOCK + 1) == min(2, numba.config.NUMBA_NUM_THREADS)
        assert shares(100 * ROTOR_BLOCK) == numba.config.NUMBA_NUM_THREADS
    finally:
        numba.set_num_threads(before)


def test_split_runs_every_share_once_on_several_threads(monkeypatch):
    monkeypatch.setattr(rotor_threads, "shares", lambda rotors: 3)
    visits = np.zeros(5 * ROTOR_BLOCK, dtype=np.int64)
    split_over_threads(_count_shares, visits.size, visits)
    np.testing.assert_array_equal(visits, 1)


def test_an_error_in_another_threads_share_is_raised_at_the_call(monkeypatch):
    monkeypatch.setattr(rotor_threads, "shares", lambda rotors: 2)

    def failing(first, stride):
        if first == 1:
            raise ZeroDivisionError("share 1")

    with pytest.raises(ZeroDivisionError, match="share 1"):
        split_over_threads(failing, 4 * ROTOR_BLOCK)


def _farm(n_conditions):
    """The shipped SBL-6 farm input (M-1, its defaults) on a 3 x 3 farm at 5 D, and conditions
    whose wake steps reach more than one block of rotors."""
    config = copy.deepcopy(load_yaml(INPUTS / "farm_sbl6.yaml"))
    x, y = np.meshgrid(np.arange(3) * 630.0, np.arange(3) * 630.0)
    config["farm"]["layout_x"], config["farm"]["layout_y"] = x.ravel().tolist(), y.ravel().tolist()
    rng = np.random.default_rng(3)
    conditions = dict(wind_speeds=rng.uniform(6.0, 12.0, n_conditions),
                      wind_directions=rng.uniform(250.0, 290.0, n_conditions),
                      turbulence_intensities=np.full(n_conditions, 0.06))
    return config, conditions, rng.uniform(-20.0, 20.0, (n_conditions, 9))


def test_a_forked_worker_runs_the_shares_on_its_own_pool():
    """The parent's pool threads do not exist in a forked child (ParFlorisModel's
    multiprocessing workers on Linux): the child builds its own and gives the serial numbers."""
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one core: nothing is shared")
    config, conditions, yaw = _farm(40)  # 40 conditions x 8 rotors downstream > ROTOR_BLOCK
    assert 40 * 8 > ROTOR_BLOCK
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        serial = FlorisModel(config)
        serial.set(**conditions, yaw_angles=yaw)
        serial.run()  # the parent's pool is started here
        par = ParFlorisModel(config, interface="multiprocessing", max_workers=2)
        par.set(**conditions, yaw_angles=yaw)

        def hung(signum, frame):
            raise TimeoutError("a forked worker waited for the parent's pool threads")

        previous = signal.signal(signal.SIGALRM, hung)
        signal.alarm(300)
        try:
            par.run()
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, previous)
    np.testing.assert_allclose(par.get_turbine_powers(), serial.get_turbine_powers(),
                               rtol=1e-12, atol=0.0)
