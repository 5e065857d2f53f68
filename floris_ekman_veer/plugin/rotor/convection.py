"""The wakes kept at each rotor during one solve, for the momentum-conserving superposition of
Zong & Porte-Agel (2020) and the cumulative wake of Bastankhah et al. (2021) on the rotor cells
(``wake_superposition: momentum_conserving`` or ``cumulative``, wake/superposition.py,
docs/coupling.md#wakes-deep-in-an-array). For the cumulative wake each rotor keeps the upstream
wakes' centre deficits C_i, widths and centres at its plane, and a new wake's C_n follows from
their overlap with it (``upstream``); its deficits are then summed (FLORIS's ``fls``).

The rotor cells superpose wakes point-wise at their sub-points (plugin/rotor/rotor_wakes.py);
Zong & Porte-Agel's weights U_c,i / U_c need the combined wake's convection velocity U_c, a
cross-plane integral that no rotor's sub-points hold. Each wake's Gaussian equivalent (centre
deficit u_c,i, width sigma_i, centre at the rotor's plane) is kept per rotor, so that the plane
integrals are the Gaussians' closed forms; the sub-points hold sum_i U_c,i u_i (the kernel's rule
"momentum_conserving", a sum) and the combined wake there is that sum over U_c. Each wake step
updates U_c of the rotors it reaches and recomputes their cells' removed moment from the
sub-points (every sub-point's combined wake changes with U_c). Numpy; no FLORIS import.
"""

from __future__ import annotations

import attrs
import numpy as np

from floris_ekman_veer.plugin.rotor.rotor_cells import RotorCells
from floris_ekman_veer.wake.superposition import (
    convection_velocity,
    gaussian_product_integral,
    overlap_weight,
)


@attrs.define(eq=False)
class WakeConvection:
    """Per rotor (flat index condition * n_turbines + turbine): the wakes that reached it,
    (pairs, n_turbines, points) their s_i = U_c,i u_c,i [m^2/s^2] (Zong & Porte-Agel, one point)
    or C_i [m/s] (Bastankhah et al., at each of the rotor's sub-point rows), sigma_i^2 [m^2] and
    centre (y, z) [m] at the rotor's plane, their count, and for Zong & Porte-Agel the sums
    sum_ij s_i s_j G_ij and sum_i s_i 2 pi sigma_i^2 and U_c [m/s] (wake/superposition.py)."""

    strength: np.ndarray
    width_squared: np.ndarray
    centre_y: np.ndarray
    centre_z: np.ndarray
    count: np.ndarray
    momentum: np.ndarray
    deficit: np.ndarray
    velocity: np.ndarray

    @classmethod
    def start(cls, pairs: int, n_turbines: int, points: int = 1) -> WakeConvection:
        table = lambda: np.zeros((pairs, n_turbines, points))  # noqa: E731
        return cls(table(), table(), table(), table(), np.zeros(pairs, dtype=int),
                   np.zeros(pairs), np.zeros(pairs), np.zeros(pairs))

    def add(self, pair, strength, width_squared, centre_y, centre_z, ambient_speed):
        """One wake at rotors ``pair`` (flat indices, each once): its s = U_c,i u_c,i,
        sigma^2 and centre; ``ambient_speed`` U_0. Returns (pairs,) the combined wake's U_c."""
        old = np.arange(self.strength.shape[1]) < self.count[pair][:, None]
        distance_squared = ((self.centre_y[pair, :, 0] - centre_y[:, None]) ** 2
                            + (self.centre_z[pair, :, 0] - centre_z[:, None]) ** 2)
        cross = np.where(old, self.strength[pair, :, 0] * gaussian_product_integral(
            self.width_squared[pair, :, 0], width_squared[:, None], distance_squared), 0.0)
        self.momentum[pair] += strength * (
            strength * np.pi * width_squared + 2.0 * np.sum(cross, axis=1))
        self.deficit[pair] += strength * 2.0 * np.pi * width_squared
        self.keep(pair, *(np.asarray(v)[:, None]
                          for v in (strength, width_squared, centre_y, centre_z)))
        self.velocity[pair] = convection_velocity(
            ambient_speed, self.momentum[pair] / self.deficit[pair])
        return self.velocity[pair]

    def upstream(self, pair, width_squared, centre_y, centre_z):
        """sum_i lambda_ni C_i [m/s] at rotors ``pair`` of a new wake (sigma_n^2 and centre,
        (pairs, points)) over the wakes kept there, at each point (Bastankhah et al. 2021;
        ``strength`` holds their C_i)."""
        old = (np.arange(self.strength.shape[1]) < self.count[pair][:, None])[:, :, None]
        distance_squared = ((self.centre_y[pair] - centre_y[:, None]) ** 2
                            + (self.centre_z[pair] - centre_z[:, None]) ** 2)
        weight = overlap_weight(width_squared[:, None], self.width_squared[pair],
                                distance_squared)
        return np.sum(np.where(old, weight * self.strength[pair], 0.0), axis=1)

    def keep(self, pair, strength, width_squared, centre_y, centre_z):
        """Keep one wake (its C_i or s_i, sigma^2, centre; (pairs, points)) at rotors
        ``pair`` (each once)."""
        slot = self.count[pair]
        for table, value in ((self.strength, strength), (self.width_squared, width_squared),
                             (self.centre_y, centre_y), (self.centre_z, centre_z)):
            table[pair, slot] = value
        self.count[pair] += 1


def removed_moments(cells: RotorCells, combined, pair, convection, ambient_u, moment):
    """sum_{s in k} w_s (U_s^m - (U_s - c_s)^m) of every cell of rotors ``pair`` (flat indices),
    with c_s = (sum_i U_c,i u_i) / U_c the combined wake at the sub-points (``combined``:
    RotorWakes.combined, one block of rows per rotor), ``convection`` (pairs,) U_c,
    ``ambient_u`` (pairs, rows) U at the rows (0 where there is no flow), ``moment`` (pairs,)
    3 or 1. Returns (pairs, n^2), as the kernel's ``removed``."""
    blocks = combined.reshape(-1, cells.rows, cells.sub_y.shape[1])[pair].astype(float)
    wake = blocks / convection[:, None, None]
    u = ambient_u[:, :, None]
    cubic = (moment == 3.0)[:, None, None]
    after = u - wake
    removed = np.where(cubic, wake * (u * u + u * after + after * after), wake)
    removed = np.where(u > 0.0, removed, 0.0) * cells.weight
    cell = np.eye(cells.n**2)[cells.cell_grid]  # (rows, columns, n^2): each sub-point's cell
    return np.einsum("prs,rsk->pk", removed, cell)
