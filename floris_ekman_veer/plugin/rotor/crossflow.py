"""The ambient crossflow V at a turbine's rotor cells, as the operation models read it.

A yawed rotor in a veered inflow sees, per rotor cell, the rotor-normal velocity

    u_n = U cos(beta) + V sin(beta)

(U, V in the hub-aligned wake frame, docs/conventions.md#hub-aligned-frame; FLORIS's positive yaw
sends the wake to -y, so the rotor normal is (cos beta, sin beta); docs/yaw_steering.md). FLORIS
hands its operation models the streamwise velocities only, and the ambient V must not enter
FLORIS's ``v`` field (GCH would read it as the sidewash of a yawed rotor,
docs/coupling.md#floris-inflow). So V reaches the operation models through
:data:`CROSSFLOW`: a context variable holding, while a Core solves or FlorisModel evaluates its
turbines, a look-up ``(power_thrust_table, velocities_shape) -> V`` of the ambient V per rotor
cell of the turbines using that table, shaped ``(n_findex, 1, *cells)`` so that it broadcasts
against the velocities FLORIS passes (sorted or not, filtered to one turbine or not: every turbine
of one turbine type has the same hub height and diameter, hence the same V cells). Outside such a
context, and for FLORIS inputs without an atmosphere, the look-up is None and every operation
model is exactly FLORIS's. :mod:`floris_ekman_veer.plugin.rotor.yawed_rotor` sets it.

The formulas here are plain numpy (no FLORIS state): the rotor-normal velocity per cell and the
two factors by which the veer-aware rotor differs from the cosine law.
"""

from __future__ import annotations

import contextvars

import numpy as np

#: Look-up (power_thrust_table, velocities shape) -> ambient V per rotor cell, or None.
CROSSFLOW: contextvars.ContextVar = contextvars.ContextVar("ambient_crossflow", default=None)

#: power_thrust_table key switching the veer-aware rotor off for one turbine type (default on):
#: ``veer_aware_rotor: false`` gives the cosine law of FLORIS (or of the paper's disk formulas).
VEER_AWARE_KEY = "veer_aware_rotor"


def ambient_crossflow(power_thrust_table, velocities):
    """Ambient V per rotor cell for the turbines of this table, or None (no atmosphere, no
    veer-aware context, or ``veer_aware_rotor: false`` in the table)."""
    lookup = CROSSFLOW.get()
    if lookup is None or not bool(np.all(power_thrust_table.get(VEER_AWARE_KEY, True))):
        return None
    return lookup(power_thrust_table, np.shape(velocities))


#: The ambient moments each rotor cell carries (means over the cell): ``U1`` = <U>,
#: ``U3`` = <U^3>^(1/3) (the cell's u_initial for a power curve), ``V`` = <V>, ``UV`` = <U V>,
#: ``VV`` = <V^2>, ``UUV`` = <U^2 V>, ``UVV`` = <U V^2>, ``VVV`` = <V^3>.
MOMENTS = ("U1", "U3", "V", "UV", "VV", "UUV", "UVV", "VVV")


def cell_moments(u_rows, v_rows, cell_sums=None, area=1.0):
    """The :data:`MOMENTS` of each cell from U, V at sub-point rows ``u_rows``, ``v_rows``
    (..., rows): ``cell_sums(values)`` sums the rows' area weights into each cell (e.g.
    :func:`~floris_ekman_veer.plugin.rotor.rotor.row_cell_sums`), of total ``area`` per cell; None:
    every row is a cell of its own (the points of a cubature grid), the moments are point
    values, in O(points) work and memory."""
    def mean(values):
        return values if cell_sums is None else cell_sums(values) / area

    return {
        "U1": mean(u_rows), "U3": np.cbrt(mean(u_rows**3)), "V": mean(v_rows),
        "UV": mean(u_rows * v_rows), "VV": mean(v_rows**2), "UUV": mean(u_rows**2 * v_rows),
        "UVV": mean(u_rows * v_rows**2), "VVV": mean(v_rows**3),
    }


def _trig(yaw_angles, ndim):
    beta = np.radians(np.asarray(yaw_angles, dtype=float)[(...,) + (None,) * (ndim - 2)])
    return np.cos(beta), np.sin(beta)


def _relative(moment, scale):
    positive = scale > 0.0
    return np.where(positive, moment / np.where(positive, scale, 1.0), 0.0)


def normal_cubes(velocities, crossflow, yaw_angles):
    """<u_n^3> per cell, u_n = u cos beta + V sin beta with u the cell's (waked) velocity:

        c^3 u^3 + 3 c^2 s u^2 <U^2 V>/U3^2 + 3 c s^2 u <U V^2>/U3 + s^3 <V^3>,

    exact for the unwaked cell (u = U3) and the cube of u c + V s where V is uniform over the
    cell; never negative."""
    u = np.asarray(velocities, dtype=float)
    c, s = _trig(yaw_angles, u.ndim)
    scale = crossflow["U3"]
    cubes = (
        (c * u) ** 3
        + 3.0 * c**2 * s * u**2 * _relative(crossflow["UUV"], scale**2)
        + 3.0 * c * s**2 * u * _relative(crossflow["UVV"], scale)
        + s**3 * crossflow["VVV"]
    )
    return np.maximum(cubes, 0.0)


def normal_squares(velocities, crossflow, yaw_angles, scale_name="U3"):
    """<u_n^2> per cell: c^2 u^2 + 2 c s u <U V>/U + s^2 <V^2> (U the cell's ambient u_initial,
    named by ``scale_name``); never negative."""
    u = np.asarray(velocities, dtype=float)
    c, s = _trig(yaw_angles, u.ndim)
    squares = (
        (c * u) ** 2
        + 2.0 * c * s * u * _relative(crossflow["UV"], crossflow[scale_name])
        + s**2 * crossflow["VV"]
    )
    return np.maximum(squares, 0.0)


def normal_means(velocities, crossflow, yaw_angles):
    """<u_n> per cell: u cos beta + <V> sin beta (linear: exact for any u)."""
    u = np.asarray(velocities, dtype=float)
    c, s = _trig(yaw_angles, u.ndim)
    return u * c + crossflow["V"] * s


def veer_ratio(numerator, denominator, yaw_angles):
    """numerator / denominator per turbine, exactly 1 where the rotor is not yawed (the veer
    cannot change an un-yawed rotor) or where the denominator vanishes (no flow)."""
    yaw = np.asarray(yaw_angles, dtype=float)
    valid = (yaw != 0.0) & (denominator > 0.0)
    return np.where(valid, numerator / np.where(valid, denominator, 1.0), 1.0)
