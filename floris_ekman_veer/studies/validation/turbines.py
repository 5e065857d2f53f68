"""FLORIS turbine definitions of the validation cases (docs/validation.md#your-own-farm).

:func:`turbine_from_table` builds one from a power and thrust-coefficient table (one speed grid,
or one for each), :func:`checked_turbine` checks a user's FLORIS turbine dictionary the same
way, :func:`constant_thrust_turbine` is a single wake's turbine (its C_T at every speed). Every
table is checked when it is given: a rotor, a hub above the ground, C_T in
:data:`THRUST_COEFFICIENT_RANGE`, power in kW that no wind could exceed.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from floris_ekman_veer.studies.validation.checks import array, scalar, text

#: Valid table C_T: real turbines stay below 1.2 (FLORIS's NREL 5 MW reaches 1.13 at cut-in);
#: beyond lies the turbulent-wake state, where no wake model of the study holds.
THRUST_COEFFICIENT_RANGE = (0.0, 1.2)
#: Air density of the kinetic-power bound on a power table [kg/m^3].
AIR_DENSITY = 1.225
#: Cut-in and cut-out ramps of a table: zero power and thrust from 0 m/s to RAMP below its first
#: speed, and from RAMP above its last to MAX_SPEED.
RAMP = 0.1
MAX_SPEED = 50.0


def _speeds(value, name: str) -> np.ndarray:
    speed = array(value, name, 1, f"finite, in ({RAMP}, {MAX_SPEED - RAMP}) m/s",
                  lambda v: (v > RAMP) & (v < MAX_SPEED - RAMP))
    if speed.size < 2 or np.any(np.diff(speed) <= 0):
        raise ValueError(f"{name} must increase strictly, with two speeds at least; got "
                         f"{speed.tolist()}")
    return speed


def _table(owner: str, rotor_diameter, hub_height, speed, power, thrust, thrust_speed=None):
    """The checked (D, z_h, speed, power [kW], C_T) of a table; C_T on ``thrust_speed`` if given."""
    diameter = scalar(rotor_diameter, f"{owner}: rotor_diameter", "finite and > 0 m",
                      lambda d: np.isfinite(d) and d > 0.0)
    hub = scalar(hub_height, f"{owner}: hub_height",
                 f"finite and above the blade tip's lowest point D/2 = {0.5 * diameter:g} m",
                 lambda z: np.isfinite(z) and z > 0.5 * diameter)
    speed = _speeds(speed, f"{owner}: wind_speed")
    thrust_speed = speed if thrust_speed is None else _speeds(thrust_speed, f"{owner}: thrust_wind_speed")
    area = 0.25 * np.pi * diameter**2
    wind_power = 0.5 * AIR_DENSITY * area * speed**3 / 1e3  # [kW]
    power = array(power, f"{owner}: power", 1,
                  "finite, >= 0 and in kW: at most the wind's kinetic power through the rotor, "
                  f"1/2 rho A U^3 with rho = {AIR_DENSITY} (a table in W is 1,000 times too large)",
                  lambda p: (p >= 0.0) & (p <= wind_power if p.shape == speed.shape else True))
    thrust = array(thrust, f"{owner}: thrust_coefficient", 1,
                   f"finite, in [{THRUST_COEFFICIENT_RANGE[0]:g}, {THRUST_COEFFICIENT_RANGE[1]:g}]",
                   lambda c: (c >= THRUST_COEFFICIENT_RANGE[0]) & (c <= THRUST_COEFFICIENT_RANGE[1]))
    for values, grid, label in ((power, speed, "power"), (thrust, thrust_speed, "thrust_coefficient")):
        if values.shape != grid.shape:
            axis = "wind_speed" if grid is speed else "thrust_wind_speed"
            raise ValueError(f"{owner}: {label} must have one value per {axis} "
                             f"({grid.size}); got {values.size}")
    if not np.any(power > 0.0):
        raise ValueError(f"{owner}: power must be > 0 at one speed at least; got all zeros")
    return diameter, hub, speed, power, thrust_speed, thrust


def turbine_from_table(name: str, rotor_diameter: float, hub_height: float, wind_speed,
                       power, thrust_coefficient, thrust_wind_speed=None) -> dict:
    """A FLORIS turbine definition from a power [kW] and thrust-coefficient table against wind
    speed [m/s] (cosine-loss operation model, FLORIS's defaults for the rest), zero power and
    thrust from 0 m/s to 0.1 m/s below the table's first speed and from 0.1 m/s above its last
    to 50 m/s (cut-in and cut-out).

    ``thrust_wind_speed``: C_T's own speed grid, when the manufacturer gives the two curves on
    different grids. The turbine then operates where both curves are given (from the later
    first speed to the earlier last one); each curve is interpolated linearly to every speed of
    either grid in that range.
    """
    owner = f"turbine_from_table {name!r}"
    text(name, "turbine_from_table: name")
    diameter, hub, speed, power, thrust_speed, thrust = _table(
        owner, rotor_diameter, hub_height, wind_speed, power, thrust_coefficient, thrust_wind_speed)
    if thrust_wind_speed is not None:
        low, high = max(speed[0], thrust_speed[0]), min(speed[-1], thrust_speed[-1])
        grid = np.union1d(speed, thrust_speed)
        grid = grid[(grid >= low) & (grid <= high)]
        if grid.size < 2:
            raise ValueError(f"{owner}: wind_speed ({speed[0]:g} to {speed[-1]:g} m/s) and "
                             f"thrust_wind_speed ({thrust_speed[0]:g} to {thrust_speed[-1]:g} m/s)"
                             " must overlap over two speeds at least")
        speed, power, thrust = grid, np.interp(grid, speed, power), np.interp(grid, thrust_speed, thrust)
    zeros = [0.0, 0.0]
    return turbine_definition(
        name, diameter, hub,
        np.concatenate([[0.0, speed[0] - RAMP], speed, [speed[-1] + RAMP, MAX_SPEED]]),
        np.concatenate([zeros, power, zeros]), np.concatenate([zeros, thrust, zeros]))


def checked_turbine(turbine, owner: str) -> dict:
    """``turbine``, a FLORIS turbine dictionary with a power/C_T table, checked as
    :func:`turbine_from_table` checks its table (the table's zero-power ramps allowed)."""
    if not isinstance(turbine, Mapping):
        raise TypeError(f"{owner}: turbine must be a FLORIS turbine definition (a dict, e.g. "
                        f"from turbine_from_table); got {turbine!r} ({type(turbine).__name__})")
    table = turbine.get("power_thrust_table")
    missing = [k for k in ("rotor_diameter", "hub_height") if k not in turbine]
    missing += ["power_thrust_table"] if not isinstance(table, Mapping) else [
        f"power_thrust_table.{k}" for k in ("wind_speed", "power", "thrust_coefficient")
        if k not in table]
    if missing:
        raise ValueError(f"{owner}: turbine is missing {missing} (a FLORIS turbine definition "
                         "with a 1-D power/C_T table, e.g. from turbine_from_table)")
    speed = array(table["wind_speed"], f"{owner}: turbine.power_thrust_table.wind_speed", 1,
                  "finite, >= 0 m/s", lambda v: v >= 0.0)
    inside = (speed > RAMP) & (speed < MAX_SPEED - RAMP)
    power = array(table["power"], f"{owner}: turbine.power_thrust_table.power", 1, "finite")
    thrust = array(table["thrust_coefficient"],
                   f"{owner}: turbine.power_thrust_table.thrust_coefficient", 1, "finite")
    if not power.shape == thrust.shape == speed.shape:
        raise ValueError(f"{owner}: turbine.power_thrust_table must give power and "
                         f"thrust_coefficient at each wind_speed; got lengths {speed.size}, "
                         f"{power.size}, {thrust.size}")
    _table(f"{owner}: turbine", turbine["rotor_diameter"], turbine["hub_height"], speed[inside],
           power[inside], thrust[inside])
    return turbine


def constant_thrust_turbine(case) -> dict:
    """A single-wake case's turbine: its C_T at every speed (the references give C_T only).
    Power, required by FLORIS and unused here, is the actuator disk's 1/2 rho A 4a(1-a)^2 U^3
    with a from C_T = 4a(1 - a)."""
    speed = np.arange(0.0, 31.0, 1.0)
    a = 0.5 * (1.0 - np.sqrt(1.0 - case.thrust_coefficient))
    area = 0.25 * np.pi * case.rotor_diameter**2
    power = 0.5 * AIR_DENSITY * area * 4.0 * a * (1.0 - a) ** 2 * speed**3 / 1e3
    thrust = np.full_like(speed, case.thrust_coefficient)
    return turbine_definition(case.name, case.rotor_diameter, case.hub_height, speed, power, thrust)


def turbine_definition(name, diameter, hub_height, speed, power, thrust) -> dict:
    """The FLORIS turbine dictionary of a checked table (cosine-loss operation model)."""
    return {
        "turbine_type": name,
        "rotor_diameter": float(diameter),
        "hub_height": float(hub_height),
        "TSR": 8.0,
        "operation_model": "cosine-loss",
        "power_thrust_table": {
            "ref_air_density": AIR_DENSITY,
            "ref_tilt": 0.0,
            "cosine_loss_exponent_yaw": 1.88,
            "cosine_loss_exponent_tilt": 1.88,
            "wind_speed": [float(v) for v in speed],
            "power": [float(v) for v in power],
            "thrust_coefficient": [float(v) for v in thrust],
        },
    }
