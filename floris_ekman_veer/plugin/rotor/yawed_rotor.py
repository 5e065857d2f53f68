"""The veer-aware yawed rotor: FLORIS's power-curve turbines and the actuator disk see u_n.

Across a veered rotor the wind direction changes with height, so the velocity normal to a
rotor yawed by beta is, per rotor cell, u_n = U cos beta + V sin beta (hub-aligned wake frame,
:mod:`floris_ekman_veer.plugin.rotor.crossflow`, docs/yaw_steering.md). FLORIS's cosine-loss model
takes U alone, so its yawed power is symmetric in beta; with veer the two signs differ (an NREL
5 MW at 8 m/s in the SBL-4 atmosphere: 1179 kW at +20 deg, 1288 kW at -20 deg).

Power-curve turbines (FLORIS's ``cosine-loss`` operation model, e.g. the NREL 5 MW; also the
models that call it: ``mixed``, ``awc``, ``peak-shaving``). The power-effective speed is

    u_eff^3 = <u_n^3> cos^(p - 3)(beta),    p = cosine_loss_exponent_yaw,

which is FLORIS's cosine-loss law <U^3> cos^p(beta) when V = 0 and today's power at beta = 0. It is
applied by scaling the velocities FLORIS's own model receives by the veer ratio
r = avg(u_n) / avg(U cos beta) (avg: the grid's own rotor average, FLORIS's cubic mean by
default), so that air density, tilt and the power curve stay FLORIS's. Thrust, consistently: the
rotor-normal force is C_T(U) <u_n^2> over the disk, so FLORIS's ct_i = C_T cos beta is scaled by
<u_n^2> / <(U cos beta)^2>, with C_T read from the power curve's table at FLORIS's rotor-average
speed as FLORIS does; the axial induction FLORIS derives from ct_i follows.

The actuator disk (``actuator-disk``, :mod:`floris_ekman_veer.plugin.rotor.turbine`) takes the disk
mean <u_n> = <U> cos beta + <V> sin beta where it took <U> cos beta.

Where V comes from: the ambient V(z) of the atmosphere, averaged over each rotor cell of FLORIS's
turbine grid (the cells of :mod:`floris_ekman_veer.plugin.rotor.rotor`), or at the points of a
cubature grid. The wakes of FLORIS's and this package's models are streamwise deficits, so a
waked cell has u_n = (U - Delta u) cos beta + V sin beta. Heterogeneous speed multipliers scale U,
not V. FLORIS allows one definition per ``turbine_type`` name, so the V cells are per type.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import inspect

import numpy as np
from floris.core.grid import TurbineCubatureGrid
from floris.core.rotor_velocity import average_velocity

from floris_ekman_veer.plugin.inflow.atmosphere_block import atmosphere_of
from floris_ekman_veer.plugin.rotor.crossflow import (
    CROSSFLOW,
    ambient_crossflow,
    cell_moments,
    normal_cubes,
    normal_means,
    normal_squares,
    veer_ratio,
)
from floris_ekman_veer.plugin.inflow.inflow_profile import ambient_velocity
from floris_ekman_veer.plugin.rotor.rotor_cells import (
    AMBIENT_NODES,
    AMBIENT_ROWS,
    rotor_cells,
    row_cell_sums,
)
from floris_ekman_veer.plugin.inflow.solve_cache import solve


def _plain_method(average_method):
    return "simple-cubature" if "cubature" in str(average_method) else "simple-mean"


def power_veer_ratio(velocities, crossflow, yaw_angles, average_method="cubic-mean",
                     cubature_weights=None):
    """r = avg(u_n) / avg(U cos beta) per turbine, avg the grid's rotor average: for FLORIS's
    cubic mean r^3 <U^3> cos^p beta = <u_n^3> cos^(p-3) beta."""
    velocities = np.asarray(velocities, dtype=float)
    if "cubic" in str(average_method):
        normal = np.cbrt(normal_cubes(velocities, crossflow, yaw_angles))
    else:
        normal = normal_means(velocities, crossflow, yaw_angles)
    aligned = velocities * np.cos(np.radians(
        np.asarray(yaw_angles, dtype=float)[(...,) + (None,) * (velocities.ndim - 2)]))
    return veer_ratio(
        average_velocity(normal, method=average_method, cubature_weights=cubature_weights),
        average_velocity(aligned, method=average_method, cubature_weights=cubature_weights),
        yaw_angles,
    )


def thrust_veer_ratio(velocities, crossflow, yaw_angles, average_method="cubic-mean",
                      cubature_weights=None):
    """<u_n^2> / <(U cos beta)^2> per turbine: the rotor-normal momentum flux with veer over
    the one of the cosine law."""
    velocities = np.asarray(velocities, dtype=float)
    aligned = velocities * np.cos(np.radians(
        np.asarray(yaw_angles, dtype=float)[(...,) + (None,) * (velocities.ndim - 2)]))
    method = _plain_method(average_method)
    return veer_ratio(
        average_velocity(normal_squares(velocities, crossflow, yaw_angles), method=method,
                         cubature_weights=cubature_weights),
        average_velocity(aligned**2, method=method, cubature_weights=cubature_weights),
        yaw_angles,
    )


#: The thrust coefficients computed inside :func:`sharing_thrust`, (function, its named
#: arguments and the crossflow look-up, result) per call; None outside it.
_SHARED_THRUST: contextvars.ContextVar = contextvars.ContextVar("shared_thrust", default=None)


@contextlib.contextmanager
def sharing_thrust():
    """One step of FLORIS's sequential solver asks for turbine i's thrust coefficient, then for
    its axial induction, which FLORIS's cosine-loss model derives from the thrust coefficient
    it computes again from the same arguments. Inside this context a thrust coefficient is
    computed once per set of arguments and the later call with equal arguments gets the same
    array (the same bits, half the thrust's cost per step)."""
    token = _SHARED_THRUST.set([])
    try:
        yield
    finally:
        _SHARED_THRUST.reset(token)


#: FLORIS's interpolants of the turbine tables built inside :func:`sharing_interpolants`, by
#: (id(x), id(y), settings) -> (x, y, interpolant); None outside it.
_SHARED_INTERPOLANTS: contextvars.ContextVar = contextvars.ContextVar("shared_interpolants",
                                                                      default=None)


@contextlib.contextmanager
def sharing_interpolants():
    """FLORIS's power-curve turbines build scipy's interpolant of their table at every thrust
    and power call, i.e. at every step of its sequential solver. Inside this context (the
    package's solver, plugin/floris_hooks/solver.py) one is built per table and settings and
    handed to the later calls: the same interpolant, the same bits."""
    token = _SHARED_INTERPOLANTS.set({})
    try:
        yield
    finally:
        _SHARED_INTERPOLANTS.reset(token)


def sharing_interpolant(original):
    """FLORIS's operation models' ``interp1d`` (the name in their module): inside
    :func:`sharing_interpolants` one interpolant per table (its x and y arrays by identity,
    held while the context lasts) and keyword settings; scipy's own call otherwise."""

    @functools.wraps(original)
    def interp1d(x, y, *args, **kwargs):
        shared = _SHARED_INTERPOLANTS.get()
        if shared is None or args:
            return original(x, y, *args, **kwargs)
        try:
            key = (id(x), id(y), tuple(sorted(kwargs.items())))
            entry = shared.get(key)
        except TypeError:  # an unhashable setting: not shared
            return original(x, y, **kwargs)
        if entry is None:
            # (x and y are held with it: their ids cannot be reused while the context lasts)
            entry = shared[key] = (x, y, original(x, y, **kwargs))
        return entry[2]

    return interp1d


def _equal_arguments(a, b) -> bool:
    """Whether two calls' named arguments are equal: the same objects (tables, interpolants,
    the crossflow) or arrays with equal values."""
    if a.keys() != b.keys():
        return False
    for name, value in a.items():
        other = b[name]
        if value is other:
            continue
        if isinstance(value, np.ndarray) and isinstance(other, np.ndarray):
            if value.shape != other.shape or not np.array_equal(value, other):
                return False
        elif isinstance(value, str) and isinstance(other, str):
            if value != other:
                return False
        else:
            return False
    return True


def veer_aware_operation(original, kind):
    """Wrap a cosine-loss static method (``kind``: "power" or "thrust"): without a crossflow it
    is FLORIS's own, bitwise. Inside :func:`sharing_thrust` a thrust coefficient is computed
    once per set of arguments."""
    signature = inspect.signature(original)
    parameters = {name for name, p in signature.parameters.items()
                  if p.kind is not inspect.Parameter.VAR_KEYWORD}

    @functools.wraps(original)
    def wrapper(*args, **kwargs):
        # FLORIS passes keywords only: then they are the arguments as they are (the names
        # the model does not declare go to its ``**_``).
        arguments = signature.bind(*args, **kwargs).arguments if args else kwargs
        shared = _SHARED_THRUST.get() if kind == "thrust" else None
        if shared is None:
            return _veer_aware(original, kind, arguments)
        # The result depends on the arguments the model declares (not on those its ``**_``
        # discards) and on the crossflow look-up the call sees.
        named = {k: v for k, v in arguments.items() if k in parameters}
        named["crossflow"] = CROSSFLOW.get()
        for function, earlier, result in shared:
            if function is original and _equal_arguments(named, earlier):
                return result
        result = _veer_aware(original, kind, arguments)
        shared.append((original, named, result))
        return result

    return wrapper


def _veer_aware(original, kind, arguments):
    """:func:`veer_aware_operation`'s call of ``original`` with its ``arguments`` by name."""
    arguments = dict(arguments)
    extra = arguments.pop("_", {})
    if not np.any(arguments["yaw_angles"]):
        # The ratios are exactly 1 on un-yawed rotors (veer_ratio): the rotor cells' V
        # moments, the hook's largest cost on small farms with many conditions, are not
        # needed where no rotor of the batch is yawed.
        return original(**arguments, **extra)
    velocities = np.asarray(arguments["velocities"], dtype=float)
    crossflow = ambient_crossflow(arguments["power_thrust_table"], velocities)
    if crossflow is None:
        return original(**arguments, **extra)
    common = (velocities, crossflow, arguments["yaw_angles"],
              arguments.get("average_method", "cubic-mean"),
              arguments.get("cubature_weights"))
    if kind == "power":
        ratio = power_veer_ratio(*common)
        arguments["velocities"] = velocities * ratio[(...,) + (None,) * (velocities.ndim - 2)]
        return original(**arguments, **extra)
    cosine_law = original(**arguments, **extra)
    return bounded_thrust(cosine_law * thrust_veer_ratio(*common), cosine_law,
                          arguments["yaw_angles"])


#: FLORIS's cosine-loss model clips the table's C_T to [0.0001, 0.9999] before it multiplies by
#: cos(beta): momentum theory's largest thrust coefficient (a = 1/2) less a margin that keeps
#: every wake model's sqrt(1 - ct_i) and sqrt(1 - ct_i cos beta) real.
MAX_THRUST_COEFFICIENT = 0.9999


def bounded_thrust(veer_aware, cosine_law, yaw_angles):
    """The veer-aware ct_i with its C_T = ct_i / cos(beta) held to FLORIS's own clip.

    The ratio <u_n^2>/<(U cos beta)^2> raises ct_i above the cosine law's on the side facing the
    veered wind; where the table's C_T is already near its clip (light wind) the product would
    leave momentum theory (C_T > 1: a > 1/2, the far wake flowing backwards) and FLORIS's gauss,
    GCH, cc and turbopark take the root of 1 - ct_i (NaN). So the veer-aware C_T is clipped as
    FLORIS clips the table's: ct_i <= 0.9999 cos(beta), and never below the cosine law's own
    ct_i (FLORIS's tilt correction may put that slightly above; it stays FLORIS's). Elementwise:
    a condition's thrust does not depend on the rest of its batch.
    """
    yaw = np.asarray(yaw_angles, dtype=float)
    ceiling = MAX_THRUST_COEFFICIENT * np.cos(np.radians(yaw))
    return np.minimum(veer_aware, np.maximum(cosine_law, ceiling))


# ---------------------------------------------------------------------------------------------
# The ambient V per rotor cell of a Core


def crossflow_lookup(core):
    """The look-up of :data:`~floris_ekman_veer.plugin.rotor.crossflow.CROSSFLOW` for a Core, or
    None without an atmosphere. V cells are computed once per (rotor, shape).

    A table is known by identity: the Core's farm's tables, and those of every farm initialised
    while the Core solves (:func:`registering_farm`). FLORIS's full-flow solvers (planes,
    ``sample_flow_at_points``) pre-solve the turbines on a deep copy of the farm whose tables
    are new objects; registered, they get the same V cells, so a flow field carries the wakes of
    the thrust the turbine powers see.
    """
    spec = atmosphere_of(core)
    if spec is None or not core.flow_field.n_findex:
        return None
    flow_field = core.flow_field
    rotors: dict[int, tuple] = {}  # id(table) -> (table, {(hub, diameter, turbine index)})

    def add_farm(farm):
        first.clear()
        for index, turbine in enumerate(farm.turbine_map):
            table = farm.turbine_power_thrust_tables[turbine.turbine_type]
            for t in [table] + [t for t in table.values() if isinstance(t, dict)]:
                # Holding the table keeps its id from being reused while the look-up lives.
                rotors.setdefault(id(t), (t, set()))[1].add(
                    (float(turbine.hub_height), float(turbine.rotor_diameter), index))

    first: dict = {}  # id(table) -> (hub, diameter, its first turbine), per set of farms
    add_farm(core.farm)
    cache: dict = {}

    def lookup(power_thrust_table, shape):
        entry = rotors.get(id(power_thrust_table))
        if entry is None or entry[0] is not power_thrust_table:
            return None
        rotor = first.get(id(power_thrust_table))
        if rotor is None:
            # FLORIS allows one definition per turbine_type name: one hub height and diameter.
            rotor = first[id(power_thrust_table)] = (
                *next(iter(entry[1]))[:2], min(index for _, _, index in entry[1]))
        hub, diameter, turbine = rotor
        key = (hub, diameter, turbine, tuple(shape))
        if key not in cache:
            abl = solve(spec, flow_field.wind_speeds, flow_field.reference_wind_height)
            cache[key] = _cells_crossflow(abl, flow_field.reference_wind_height, hub, diameter,
                                          turbine, shape, core.grid)
        return cache[key]

    lookup.add_farm = add_farm
    return lookup


def _cells_crossflow(abl, reference_height, hub, diameter, turbine, shape, grid):
    """The ambient moments (crossflow.MOMENTS) per rotor cell, (n_findex, 1, *cells) each:
    over the cells of plugin/rotor/rotor.py for an n x n turbine grid, at the points of a cubature
    grid; None for any other shape."""
    n_findex = shape[0]
    if isinstance(grid, TurbineCubatureGrid) and tuple(shape[2:]) == grid.z_sorted.shape[2:]:
        position = int(np.flatnonzero(grid.sorted_indices[0, :, 0, 0] == turbine)[0])
        z = grid.z_sorted[0, position].reshape(-1)
        cell_sums, area, cells_shape = None, 1.0, grid.z_sorted.shape[2:]
    elif len(shape) == 4 and shape[2] == shape[3]:
        cells = rotor_cells(shape[2], AMBIENT_ROWS, AMBIENT_NODES)
        z = hub + 0.5 * diameter * cells.row_z
        cell_sums = functools.partial(row_cell_sums, cells=cells)
        area, cells_shape = cells.area, (cells.n, cells.n)
    else:
        return None
    u, v = ambient_velocity(abl, z.reshape(1, 1, 1, -1), reference_height)
    u, v = (np.broadcast_to(x, (n_findex, 1, 1, z.size)).reshape(n_findex, z.size) for x in (u, v))
    return {name: value.reshape(n_findex, 1, *cells_shape)
            for name, value in cell_moments(u, v, cell_sums, area).items()}


@contextlib.contextmanager
def veer_aware(core):
    """Operation models called inside see the Core's ambient V (None: FLORIS's own)."""
    token = CROSSFLOW.set(crossflow_lookup(core))
    try:
        yield
    finally:
        CROSSFLOW.reset(token)


def with_crossflow(method):
    """FlorisModel's turbine getters: the operation models see the Core's ambient V."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        with veer_aware(self.core):
            return method(self, *args, **kwargs)

    return wrapper


def registering_farm(method):
    """Farm.initialize: a farm initialised while a Core solves (the full-flow solvers' deep
    copy) joins the Core's crossflow look-up."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        result = method(self, *args, **kwargs)
        lookup = CROSSFLOW.get()
        if lookup is not None:
            lookup.add_farm(self)
        return result

    return wrapper
