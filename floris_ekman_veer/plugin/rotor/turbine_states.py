"""The turbine grid's per-rotor states handed to the solves on FLORIS's other grids
(docs/coupling.md#one-physics-on-every-grid).

With ``deficit_velocity: incoming`` a wake's C(x) scales with its rotor's incoming speed, and
with ``wake_expansion: array_turbulence`` its k_w takes the upstream wakes' added turbulence
summed in quadrature (docs/coupling.md#wakes-deep-in-an-array). Both are tracked on the rotor
cells of a turbine grid (plugin/rotor/rotor_wakes.py); FLORIS's point-wise solvers on other grids
(cubature grids, planes, sampled points) carry neither. As FLORIS's full-flow solver hands its
turbine-grid solve's thrust and turbulence to the flow-field grid, the turbine-grid solve's
U_i / U_i,0 and turbulence of every rotor are handed here to the wake models' point path, so
that every grid runs one physics: a plane sampled at the rotor points gives the turbine
velocities, a cubature grid the turbine grid's powers.

:func:`handing` opens a slot for one solve; the turbine-grid solve (plugin/floris_hooks/solver.py
``rotor_solver``) fills it, the velocity models' ``prepare_function`` on the other grid reads it.
No FLORIS import.
"""

from __future__ import annotations

import contextlib
import contextvars

import attrs
import numpy as np

#: The slot of the solve under way (a dict with key "states"), None outside one.
_SLOT: contextvars.ContextVar = contextvars.ContextVar("ekman_veer_turbine_states",
                                                       default=None)


@attrs.frozen(eq=False)
class TurbineStates:
    """Per rotor (n_findex, n_turbines), in the turbine grid's sorted order: its centre ``x``,
    ``y`` (FLORIS's rotated frame), ``speed_fraction`` U_i / U_i,0 (the mean rotor speed in the
    upstream wakes over the ambient one; 1 unwaked or with ``free_stream``) and ``turbulence``
    (the turbulence intensity its wake's k_w takes)."""

    x: np.ndarray
    y: np.ndarray
    speed_fraction: np.ndarray
    turbulence: np.ndarray

    def at(self, x_i, y_i):
        """(speed_fraction, turbulence) of the turbine centred at (x_i, y_i) (shapes
        (n_findex, 1, 1, 1)): per condition the rotor nearest to it, as the rotor cells find
        the turbine whose wake they integrate."""
        distance = (self.x - x_i[:, 0, 0]) ** 2 + (self.y - y_i[:, 0, 0]) ** 2
        index = np.argmin(distance, axis=1)
        rows = np.arange(self.x.shape[0])
        return tuple(a[rows, index][:, None, None, None]
                     for a in (self.speed_fraction, self.turbulence))


@contextlib.contextmanager
def handing():
    """Open a slot for the turbine-grid states of the solve in the ``with`` block."""
    token = _SLOT.set({"states": None})
    try:
        yield
    finally:
        _SLOT.reset(token)


def collecting() -> bool:
    """Whether a solve under way waits for a turbine grid's states."""
    slot = _SLOT.get()
    return slot is not None and slot["states"] is None


def hand(states: TurbineStates) -> None:
    """Hand ``states`` to the solve under way (ignored outside one, or once it has them)."""
    if collecting():
        _SLOT.get()["states"] = states


def handed() -> TurbineStates | None:
    """The turbine-grid states handed to the solve under way, or None."""
    slot = _SLOT.get()
    return None if slot is None else slot["states"]
