"""The threads a wake step's compiled pass over its rotors runs on
(docs/performance.md#threads).

A pass (the rotor-cell kernel, plugin/rotor/rotor_kernel.py) is a compiled function that
releases the GIL (``nogil``) and takes
its share of the rotors as its last two arguments, ``first`` and ``stride``: the blocks of
ROTOR_BLOCK consecutive rotors first, first + stride, ... (block-cyclic: each thread gets near
and far rotors alike, and threads write to different cache lines). :func:`split_over_threads`
runs share 0 on the calling thread and the others on a pool of Python threads, one share per
thread of numba's thread count (``numba.get_num_threads()``: NUMBA_NUM_THREADS, all cores by
default, or ``numba.set_num_threads``). Every rotor's arithmetic is the same on any thread, so
1 and N threads give the same bits.

Why not numba's ``prange``: a step's pass lasts about 3 ms between the solver's Python and
numexpr work, and numba's fork-safe workqueue layer then gained nothing from the second core
(its idle workers wake too late: a 0.8 ms loop took the same time on 1 and 2 threads once 1 ms of
other work separated the calls); TBB gained the wall time but spent 13 % more CPU spinning, and
GNU OpenMP's pool does not survive the fork of FLORIS's ``ParFlorisModel``. The calling thread
working its own share while one pool thread works the other halves the pass in the solve.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numba

#: Consecutive rotors a thread takes at a time (the shares' blocks; the compiled passes read it
#: as a global).
ROTOR_BLOCK = 64

_pool: ThreadPoolExecutor | None = None
_pool_owner = (0, 0)  # (process id, pool threads): a forked child builds its own pool
_pool_lock = threading.Lock()


def _executor(workers: int) -> ThreadPoolExecutor:
    """A pool of at least ``workers`` threads of this process."""
    global _pool, _pool_owner
    with _pool_lock:
        pid, size = _pool_owner
        if _pool is None or pid != os.getpid() or size < workers:
            _pool = ThreadPoolExecutor(workers, thread_name_prefix="floris_ekman_veer")
            _pool_owner = (os.getpid(), workers)
        return _pool


@numba.njit(inline="always")
def in_share(rotor, first, stride):
    """Whether rotor index ``rotor`` is in share ``first`` of ``stride`` (module docstring)."""
    return (rotor // ROTOR_BLOCK) % stride == first


@numba.njit(inline="always")
def next_in_share(rotor, first, stride):
    """The rotor index after ``rotor`` in share ``first`` of ``stride`` (``rotor`` in it): the
    next one, or past the other shares' blocks where ``rotor`` ends its block."""
    following = rotor + 1
    if in_share(following, first, stride):
        return following
    return following + (stride - 1) * ROTOR_BLOCK


def shares(rotors: int) -> int:
    """The threads a pass over ``rotors`` rotors runs on: numba's thread count, at most one per
    block of rotors."""
    return max(1, min(numba.get_num_threads(), -(-rotors // ROTOR_BLOCK)))


def split_over_threads(compiled_pass, rotors: int, *arguments) -> None:
    """``compiled_pass(*arguments, first, stride)`` for every share (module docstring) of
    ``rotors`` rotors, the first on the calling thread; returns when all are done (an error in a
    share is raised here)."""
    stride = shares(rotors)
    if stride == 1:
        compiled_pass(*arguments, 0, 1)
        return
    pool = _executor(stride - 1)
    others = [pool.submit(compiled_pass, *arguments, first, stride)
              for first in range(1, stride)]
    try:
        compiled_pass(*arguments, 0, stride)
    finally:
        for share in others:
            share.result()
