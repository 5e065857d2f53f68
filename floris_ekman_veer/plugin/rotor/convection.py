"""The wakes kept at each rotor during one solve, for the momentum-conserving superposition of
Zong & Porte-Agel (2020) on the rotor cells (``wake_superposition: momentum_conserving``,
wake/superposition.py, docs/coupling.md#wakes-deep-in-an-array); the cumulative wake of
Bastankhah et al. (2021) keeps its own (plugin/rotor/upstream_wakes.py).

The rotor cells superpose wakes point-wise at their sub-points (plugin/rotor/rotor_wakes.py);
Zong & Porte-Agel's weights U_c,i / U_c need the combined wake's convection velocity U_c, a
cross-plane integral that no rotor's sub-points hold. Each wake's Gaussian equivalent (centre
deficit u_c,i, width sigma_i, centre at the rotor's plane) is kept per rotor, so that the plane
integrals are the Gaussians' closed forms; the sub-points hold sum_i U_c,i u_i (summed by the
kernel's ``fls``) and the combined wake there is that sum over U_c. Each wake step
updates U_c of the rotors it reaches and recomputes their cells' removed moment from the
sub-points (every sub-point's combined wake changes with U_c). Numpy; no FLORIS import. The tables
are dense, (rotors, n_turbines) per quantity: one value per kept wake (the Gaussian's centre, not
per row), an option beyond the default whose cost (turbines^2 per condition) is that of its
updates of every reached rotor's moments anyway (``removed_moments``).
"""

from __future__ import annotations

import attrs
import numpy as np

from floris_ekman_veer.plugin.rotor.rotor_cells import RotorCells
from floris_ekman_veer.wake.superposition import (
    convection_velocity,
    gaussian_product_integral,
)


@attrs.define(eq=False)
class WakeConvection:
    """Per rotor (flat index condition * n_turbines + turbine): the wakes that joined it,
    (pairs, n_turbines, 1) their s_i = U_c,i u_c,i [m^2/s^2], sigma_i^2 [m^2] and centre (y, z)
    [m] at the rotor's plane, their count, the sums sum_ij s_i s_j G_ij and
    sum_i s_i 2 pi sigma_i^2 and U_c [m/s] (wake/superposition.py)."""

    strength: np.ndarray
    width_squared: np.ndarray
    centre_y: np.ndarray
    centre_z: np.ndarray
    count: np.ndarray
    momentum: np.ndarray
    deficit: np.ndarray
    velocity: np.ndarray

    @classmethod
    def start(cls, pairs: int, n_turbines: int) -> WakeConvection:
        table = lambda: np.zeros((pairs, n_turbines, 1))  # noqa: E731
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

    def keep(self, pair, strength, width_squared, centre_y, centre_z):
        """Keep one wake (its s_i, sigma^2, centre; (pairs, 1)) at rotors ``pair`` (each
        once)."""
        slot = self.count[pair]
        for table, value in ((self.strength, strength), (self.width_squared, width_squared),
                             (self.centre_y, centre_y), (self.centre_z, centre_z)):
            table[pair, slot] = value
        self.count[pair] += 1


def removed_moments(cells: RotorCells, combined, pair, convection, ambient_u, moment,
                    slots=None):
    """sum_{s in k} w_s (U_s^m - (U_s - c_s)^m) of every cell of rotors ``pair`` (flat indices),
    with c_s = (sum_i U_c,i u_i) / U_c the combined wake at the sub-points (``combined``:
    RotorWakes.combined, one block of row slots per rotor), ``convection`` (pairs,) U_c,
    ``ambient_u`` (pairs, rows) U at the rows (0 where there is no flow), ``moment`` (pairs,)
    3 or 1. Returns (pairs, n^2), as the kernel's ``removed``. ``slots``: None (the shared
    strips' rows), or per rotor and row slot (pairs, rows + 1) the strip whose sub-points it
    takes and its share of that strip's area (plugin/rotor/strip_split.py ``pair_rows``: the
    strip a layer top cuts as its two parts; ``ambient_u`` then (pairs, rows + 1))."""
    blocks = combined.reshape(-1, cells.slots, cells.sub_y.shape[1])[pair]
    if slots is not None:
        strips, fraction = slots
        wake = blocks.astype(float) / convection[:, None, None]
        u = ambient_u[:, :, None]
        after = u - wake
        cubic = (moment == 3.0)[:, None, None]
        removed = np.where(cubic, wake * (u * u + u * after + after * after), wake)
        removed = (np.where(u > 0.0, removed, 0.0) * cells.weight[strips]
                   * fraction[:, :, None])
        cell = np.arange(pair.size)[:, None, None] * cells.n**2 + cells.cell_grid[strips]
        return np.bincount(cell.ravel(), weights=removed.ravel(),
                           minlength=pair.size * cells.n**2).reshape(pair.size, cells.n**2)
    blocks = blocks[:, :cells.rows].astype(float)
    wake = blocks / convection[:, None, None]
    u = ambient_u[:, :, None]
    cubic = (moment == 3.0)[:, None, None]
    after = u - wake
    removed = np.where(cubic, wake * (u * u + u * after + after * after), wake)
    removed = np.where(u > 0.0, removed, 0.0) * cells.weight
    cell = np.eye(cells.n**2)[cells.cell_grid]  # (rows, columns, n^2): each sub-point's cell
    return np.einsum("prs,rsk->pk", removed, cell)
