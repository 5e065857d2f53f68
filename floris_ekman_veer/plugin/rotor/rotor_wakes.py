"""The wakes superposed at the rotor cells' sub-points during one solve, and the deficit each
cell returns to FLORIS.

The ``ekman_veer`` velocity models return at a point of FLORIS's turbine grid the deficit ``d_k``
whose cube removes the exact power deficit of the point's cell (plugin/rotor/rotor_cells.py),
``U_k^3 (1 - (1 - d_k)^3) = n^2 sum_s w_s (U_s^3 - (U_s - Delta u_s)^3)`` over the cell's
sub-points s (:func:`equivalent_deficit`), with Delta u_s all wakes so far superposed point-wise
at the sub-points by FLORIS's own rule (:class:`RotorWakes`; each call returns the increment that
FLORIS's combination of the point values turns into the combined cell deficit). FLORIS's
equal-weight cubic mean of ``U_k (1 - d_k)`` is then the sub-quadrature of the disk integral of
u^3 (ambient and all wakes), and its thrust and power follow (the first moment for the actuator
disk, plugin/rotor/rotor_cells.py ``TURBINE_MOMENTS``). The point-wise rules are compiled (numba:
:func:`superposed`, :func:`removed_moment`, called by the rotor-cell kernel,
plugin/rotor/rotor_kernel.py, at every sub-point); numpy elsewhere; no FLORIS import.
"""

from __future__ import annotations

import attrs
import numba
import numpy as np

from floris_ekman_veer.plugin.rotor.convection import WakeConvection
from floris_ekman_veer.plugin.rotor.upstream_wakes import UpstreamWakes
from floris_ekman_veer.plugin.rotor.rotor_cells import RotorCells
from floris_ekman_veer.wake.fused import JIT


def equivalent_deficit(removed, u_cell, moment) -> np.ndarray:
    """d_k of each cell from the cell's removed moment n^2 sum_{s in k} w_s (U_s^m - u_s^m)
    (m = 3: power; m = 1: the velocity deficit itself): U_k^m (1 - (1 - d_k)^m) = removed.

    ``removed``, ``u_cell`` (the cells' U_k): (..., n^2); ``moment`` (..., 1). A cell without
    inflow (U_k = 0) has no wake.
    """
    cubic = moment == 3.0
    ambient = np.where(cubic, u_cell**3, u_cell)
    flowing = ambient > 0.0
    fraction = np.where(flowing, removed / np.where(flowing, ambient, 1.0), 0.0)
    # The cells' quadrature areas are exact to the strips' resolution (a few per cent for the
    # wake cells): a wake that stops nearly all flow through a cell could exceed it by as much.
    # The cell then has no flow (d = 1) rather than a negative one.
    fraction = np.minimum(fraction, 1.0)
    return np.where(cubic, 1.0 - np.cbrt(1.0 - fraction), fraction)


#: FLORIS's combination models (class names) as the point-wise rules that superpose wake
#: velocities du [m/s] at the cells' sub-points: sum of squares (sosfs), linear sum (fls), max.
COMBINATION_RULES = {"SOSFS": "sosfs", "FLS": "fls", "MAX": "max"}

#: FLORIS's Crespo-Hernandez turbulence model (class name) and its parameters, in the order of
#: the compiled form (wake/added_turbulence.py ``crespo_hernandez``).
CRESPO_HERNANDEZ = ("CrespoHernandez", ("constant", "ai", "initial", "downstream"))


def crespo_hernandez_parameters(turbulence_model) -> tuple | None:
    """FLORIS's Crespo-Hernandez parameters of ``turbulence_model`` for the compiled form of its
    function, or None for another model (whose own function is then called)."""
    name, parameters = CRESPO_HERNANDEZ
    if type(turbulence_model).__name__ != name:
        return None
    return tuple(float(getattr(turbulence_model, k)) for k in parameters)


#: Each rule's number in the compiled kernel (:func:`superposed`; 0: no rule, each wake alone).
#: A new rule is a row here and a branch there.
RULE_CODES = {None: 0, "sosfs": 1, "fls": 2, "max": 3}

#: The velocity models' ``wake_superposition`` choices: FLORIS's combination model point-wise
#: at the sub-points, or Zong & Porte-Agel's (2020) momentum-conserving weights, on FLORIS's
#: ``fls``, or Bastankhah et al.'s (2021) cumulative wake, summed by ``fls``
#: (plugin/rotor/convection.py, docs/coupling.md#wakes-deep-in-an-array).
WAKE_SUPERPOSITIONS = ("combination_model", "momentum_conserving", "cumulative")

#: FLORIS's sequential solver counts a rotor point as overlapped by a wake where the wake's
#: velocity there exceeds this [m/s]; the rotor cells take the area of the disk where it does.
WAKE_OVERLAP_VELOCITY = 0.05


@numba.njit(inline="always", **JIT)
def superposed(rule, old, du):
    """The combined wake velocity at a sub-point after adding ``du`` to ``old`` by the rule
    numbered ``rule`` (:data:`RULE_CODES`): sqrt(old^2 + du^2), old + du, max(old, du), or du
    alone. (The momentum-conserving superposition sums U_c,i u_i by ``fls``, ``du`` being the
    wake's deficit times its convection velocity: plugin/rotor/convection.py.)"""
    if rule == 1:
        return np.sqrt(old * old + du * du)
    if rule == 2:
        return old + du
    if rule == 3:
        return du if du > old else old
    return du


@numba.njit(inline="always", **JIT)
def removed_moment(weight, ambient_u, old, new, moment):
    """weight (u_old^m - u_new^m) with u = U - wake: the moment a wake removes at a sub-point
    whose combined wake goes from ``old`` to ``new`` (m = 3 written as one product, so that it
    keeps its precision for small increments); 0 where there is no flow (U = 0)."""
    if not ambient_u > 0.0:
        return 0.0
    if moment > 2.0:
        before, after = ambient_u - old, ambient_u - new
        return weight * ((new - old) * (before * before + before * after + after * after))
    return weight * (new - old)


@numba.njit(**JIT)
def _superpose_rows(rule, combined, index, du, ambient_u, moment, weight, rows):
    """:meth:`RotorWakes.superpose` compiled: entry e's sub-points in row ``rows[e]`` of block
    ``index[e]`` of ``combined``."""
    removed = np.zeros(du.shape)
    for e in range(du.shape[0]):
        for s in range(du.shape[1]):
            old = np.float64(combined[index[e], s]) if rule else 0.0
            new = superposed(rule, old, du[e, s])
            removed[e, s] = removed_moment(weight[rows[e], s], ambient_u[e], old, new,
                                           moment[e])
            if rule:
                combined[index[e], s] = new
    return removed


@attrs.define(eq=False)
class RotorWakes:
    """The wakes superposed so far at the cells' sub-points of every rotor, during one solve.

    FLORIS's solver combines the values the velocity model returns at the grid's points; on
    rotor cells, combining the cells' deficits would combine wakes that do not overlap inside
    a cell as if they did (two bands side by side), and the sum of squares of cube-equivalent
    deficits is not the sum of squares of the velocities. So the wakes are superposed here,
    point-wise at the sub-points by FLORIS's own rule, and each call returns the increment that
    FLORIS's combination of the cell values turns into the cell's exact share of the combined
    wakes' moment (docs/coupling.md#rotor-average). The turbulence at each rotor is the
    wake-added turbulence with the overlap as the area of the disk in the wake.

    Attributes:
        cells: the rotor cells.
        rule: "sosfs", "fls", "max" (FLORIS's combination model), or None: unknown, each call
            returns its own wake's cell deficits.
        combined: (n_findex * n_turbines * rows, columns) combined wake velocity [m/s] at the
            sub-points, one block per rotor and row slot (RotorCells.sub_y's rows and the
            slot of the part above a layer top of the strip it cuts, RotorCells.slots).
        removed: (n_findex * n_turbines, n^2) n^2 sum_{s in k} w_s (U_s^m - u_s^m) of the
            combined wakes.
        wake: (n_findex * n_turbines, n^2) the wake velocity U_k d_k FLORIS holds at each point.
        turbulence: (n_findex, n_turbines) turbulence intensity at each rotor, starting at the
            ambient one.
        turbulence_model: FLORIS's wake-added turbulence model, or None.
        convection: the wakes kept at each rotor (``superposition`` "momentum_conserving":
            plugin/rotor/convection.py; "cumulative": plugin/rotor/upstream_wakes.py), or
            None.
        superposition: the velocity model's ``wake_superposition``.
        reached: the rotors (f, j) the latest wake reached (plugin/rotor/rotor.py), a superset
            of those where its deficit is not 0, or None.
        source: the sorted index of the turbine whose wake the package's solver is stepping
            (plugin/floris_hooks/solver.py), or None (another solver: the model finds it).
    """

    cells: RotorCells
    rule: str | None
    combined: np.ndarray
    removed: np.ndarray
    wake: np.ndarray
    turbulence: np.ndarray
    turbulence_model: object = None
    convection: WakeConvection | UpstreamWakes | None = None
    superposition: str = "combination_model"
    reached: tuple | None = None
    source: int | None = None

    @classmethod
    def start(cls, cells: RotorCells, n_findex: int, n_turbines: int, wake_models,
              ambient_turbulence, superposition="combination_model") -> RotorWakes:
        """An empty farm for ``wake_models`` (FLORIS's WakeModelManager or None) and the
        velocity model's ``wake_superposition``."""
        rule = None
        turbulence_model = None
        if wake_models is not None:
            rule = COMBINATION_RULES.get(type(wake_models.combination_model).__name__)
            turbulence_model = wake_models.turbulence_model
        pairs = n_findex * n_turbines
        convection = None
        if superposition == "momentum_conserving" and rule not in (None, "fls"):
            raise ValueError(
                "wake_superposition: momentum_conserving returns the rotors' wakes as "
                "increments of a sum: it needs wake.model_strings.combination_model: fls, "
                f"got {rule!r} (docs/coupling.md#wakes-deep-in-an-array)")
        if superposition != "combination_model" and rule == "fls":
            # (Both are summed by fls; with another combination, each wake is combined by it
            # alone, as input_checks.warn_deficit_superposition says.)
            # (the cumulative wake keeps its upstream wakes at the grid-point heights of a rotor)
            convection = (UpstreamWakes.start(pairs, cells) if superposition == "cumulative"
                          else WakeConvection.start(pairs, n_turbines))
        # Single precision: a round-off of 1e-7 of the wake velocity, far below the cells'
        # quadrature error, for half the memory.
        combined = np.zeros((pairs * cells.slots if rule else 0, cells.sub_y.shape[1]),
                            dtype=np.float32)
        turbulence = np.broadcast_to(np.reshape(ambient_turbulence, (-1, 1)),
                                     (n_findex, n_turbines)).copy()
        return cls(cells, rule, combined, np.zeros((pairs, cells.n**2)),
                   np.zeros((pairs, cells.n**2)), turbulence, turbulence_model, convection,
                   superposition if convection is not None else "combination_model")

    @property
    def rule_code(self) -> int:
        """The rule's number in the compiled kernel (:data:`RULE_CODES`)."""
        return RULE_CODES[self.rule]

    def superpose(self, pair, row, du, ambient_u, moment) -> np.ndarray:
        """Add one wake at sub-point rows (what the rotor-cell kernel does at each sub-point,
        plugin/rotor/rotor_kernel.py, here on given arrays): ``pair`` (entries,) flat rotor index
        (condition * n_turbines + turbine), ``row`` (entries,) the row, ``du`` (entries, w) the
        wake's velocity deficit [m/s] at the row's first w sub-points (beyond each row's width,
        the zero-weight padding), ``ambient_u`` (entries, 1) U at the row (0 where there is no
        flow), ``moment`` (entries, 1). Returns (entries, w) the moment the wake removes at each
        sub-point, weight (u_before^m - u_after^m)."""
        pair, row = np.asarray(pair), np.asarray(row)
        return _superpose_rows(
            self.rule_code, self.combined, pair * self.cells.slots + row,
            np.ascontiguousarray(du, dtype=float), np.ravel(ambient_u).astype(float),
            np.ravel(moment).astype(float), self.cells.weight, row)

    def cell_returns(self, pair, removed, u_cell, moment) -> np.ndarray:
        """What the velocity model returns at the cells of rotors ``pair`` (flat indices, each
        once) after its wake was superposed, removing ``removed`` (pairs, n^2) of the cells'
        moment (sum_{s in k} w_s (u_before^m - u_after^m)): the deficit d whose combination by
        FLORIS's rule with the points' current wake velocity gives U_k d_k of the combined
        wakes; ``u_cell`` (pairs, n^2) the cells' U_k, ``moment`` (pairs, 1). Returns
        (pairs, n^2)."""
        removed = self.cells.n**2 * removed
        if self.rule is not None:
            removed += self.removed.take(pair, axis=0)
            self.removed[pair] = removed
        total = u_cell * equivalent_deficit(removed, u_cell, moment)
        if self.rule == "sosfs":
            increment = np.sqrt(np.maximum(total**2 - self.wake.take(pair, axis=0) ** 2, 0.0))
        elif self.rule == "fls":
            increment = total - self.wake.take(pair, axis=0)
        else:  # max, or each wake alone
            increment = total
        if self.rule is not None:
            self.wake[pair] = total
        flowing = u_cell > 0.0
        return np.where(flowing, increment / np.where(flowing, u_cell, 1.0), 0.0)

    def add_turbulence(self, f, j, added, ambient, rule="max") -> None:
        """One wake's added turbulence at rotors (f, j) (each once): ``max`` is FLORIS's
        combination, TI = max(TI, sqrt(added^2 + TI_0^2)); ``quadrature`` adds its variance,
        TI = sqrt(TI^2 + added^2), so that TI^2 = TI_0^2 + the sum over the upstream wakes
        (docs/coupling.md#wakes-deep-in-an-array)."""
        if rule == "quadrature":
            self.turbulence[f, j] = np.hypot(self.turbulence[f, j], added)
        else:
            self.turbulence[f, j] = np.maximum(self.turbulence[f, j], np.hypot(added, ambient))

    def incoming_fraction(self, pair, u_cell) -> np.ndarray:
        """U_i / U_i,0 of rotors ``pair`` (flat indices): the mean over their cells of the
        velocity in the wakes superposed so far, U_k - U_k d_k, over that of the inflow U_k
        (``u_cell``, (pairs, n^2)); 1 for a rotor no wake has reached."""
        ambient = u_cell.sum(axis=1)
        waked = self.wake.take(pair, axis=0).sum(axis=1)
        return 1.0 - waked / np.where(ambient > 0.0, ambient, 1.0)
