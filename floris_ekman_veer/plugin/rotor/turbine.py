"""Actuator-disk turbine for FLORIS 4.7, defined by its local thrust coefficient C_T'.

The LES of Narasimhan, Gayme & Meneveau (JRSE 2025, Section 3) represents the turbine by an
actuator disk with a fixed local thrust coefficient C_T' = 1.33 (D = z_h = 100 m). This module
turns that disk into a FLORIS *operation model*, so that the paper's single-turbine and
two-turbine power cases can be run through FLORIS, and registers it in FLORIS's
``TURBINE_MODEL_MAP["operation_model"]`` under the name ``"actuator-disk"``.

Momentum theory of the disk
---------------------------
A disk of fixed C_T' in a wind U, yawed by beta (FLORIS's yaw angle, which is the paper's beta,
docs/conventions.md#frames-and-signs), feels the disk-normal force F = 1/2 rho A C_T' u_n^2 with the disk-normal
velocity u_n = (1 - a) U cos(beta). One-dimensional momentum balance F = 1/2 rho A U^2 4a(1 - a)
then gives (Shapiro, Gayme & Meneveau 2018; Bastankhah et al. 2022)

    a(beta)   = C_T' cos^2(beta) / (4 + C_T' cos^2(beta)),
    C_T(beta) = 16 C_T' / (4 + C_T' cos^2(beta))^2,

where C_T(beta) is the thrust coefficient *on the un-yawed basis* that the paper's formulas take:
they apply cos^2(beta) and cos^3(beta) themselves, and the paper's Eq. (ind_factor),
a = (1 - sqrt(1 - C_T cos^2 beta))/2, evaluated with C_T(beta), returns exactly a(beta) above.
Un-yawed: a = C_T'/(4 + C_T') = 0.24953 and C_T = 4a(1 - a) = 0.74906 for C_T' = 1.33; at
beta = 20 deg, C_T(beta) = 0.79478 (docs/conventions.md#thrust-coefficient-and-yaw).

The power is the disk-normal force times the disk-normal velocity,

    P = 1/2 rho A C_T' [(1 - a(beta)) U_disk cos(beta)]^3,

which at beta = 0 is the paper's Eq. (P0_ref) for U_disk = U_h, and Eq. (P_hyp) with the
disk velocity of Eq. (Ud), U_d = (1 - a) U_disk, in a wake. U_disk is the *plain* area average of
the streamwise velocity over FLORIS's rotor points, as Eq. (Ud) prescribes: not FLORIS's default
cubic mean, which belongs to power curves and would overstate the disk's power in shear.

Veer-aware yawed disk
---------------------
In a veered inflow the disk-normal velocity is u_n = U cos beta + V sin beta per rotor cell (U, V
hub-aligned; plugin/rotor/yawed_rotor.py, docs/yaw_steering.md), and the disk takes its disk mean
<u_n> = <U> gamma, gamma = cos beta + sin beta <V>/<U>, wherever the formulas above take
<U> cos beta: a(gamma) = C_T' gamma^2 / (4 + C_T' gamma^2), P = 1/2 rho A C_T' [(1 - a) <U> gamma]^3,
and ct_i = C_T(gamma) gamma^2 / cos beta, so that the wake sees the rotor-normal loading
C_T cos^2 beta = 4a(1 - a). Without an ambient V (no atmosphere), gamma = cos beta exactly.

Yaw convention handed to the wake model (the decision)
-------------------------------------------------------
``thrust_coefficient`` returns ct_i = C_T(beta) cos(beta): C_T' is held fixed under yaw, as in the
paper's LES and in the authors' own figures, and the value is packed in the convention of FLORIS's
cosine-loss model (ct_i = C_T cos beta). So the wake model keeps doing what it does for every FLORIS
turbine, C_T = ct_i / cos(beta), and obtains the yawed-disk C_T(beta) its formulas expect (and
a(beta) from Eq. ind_factor). It must not divide by cos^2 or use ct_i directly as C_T (at 20 deg
that would be 0.7468 instead of 0.7948). FLORIS's own Gaussian model, which multiplies ct_i by
cos(beta), sees the disk-normal thrust coefficient C_T(beta) cos^2(beta) = 4a(1 - a): consistent
too. The alternative, holding C_T (not C_T') at its un-yawed 0.7491, would describe a controller
that raises C_T' under yaw, which is not the disk of the LES being reproduced.

``axial_induction`` returns a(beta), the disk-normal induction of the paper's Eq. (ind_factor).
(FLORIS's cosine-loss model returns a/cos(beta) from its own formula; the velocity models that use
the induction, e.g. Jensen, take it as the disk's deficit, which is a(beta).)

power_thrust_table keys
-----------------------
``ct_prime`` (0 < C_T' <= 4, momentum theory: see ``MAX_CT_PRIME``), ``rotor_diameter`` [m] (the operation model is never told the turbine's
diameter by FLORIS, so the area enters here, as for FLORIS's controller-dependent model; it must
equal the turbine's ``rotor_diameter``), ``ref_air_density`` [kg/m^3], ``ref_tilt`` (must be 0:
the disk has no tilt, and FLORIS then always passes tilt 0 for these turbines), and the arrays
``wind_speed``, ``power`` [kW], ``thrust_coefficient`` that FLORIS's Turbine insists on. The
arrays are descriptive (FLORIS's previewer and utilities read them); they are checked against
ct_prime, rotor_diameter and ref_air_density on every call so a stale table cannot disagree with
the analytic model; build them with :func:`actuator_disk_power_thrust_table`. The density in the
power is FLORIS's flow ``air_density`` (power is linear in it), as FLORIS's own models correct
their tables from ``ref_air_density``. Not modelled: tilt, cut-in/out, rated power, derating
setpoints, AWC (the LES disk has none of these); |yaw| must stay below 90 deg. FLORIS's
``disable_turbines`` is honoured (no power, no thrust, no induction); any other power set-point
below FLORIS's default raises ValueError (a fixed-C_T' disk has no controller to derate).

Registration: importing ``floris_ekman_veer`` registers the model (in every process, including
ParFlorisModel workers); :func:`floris_ekman_veer.registry.register_operation_model`
does it alone.
"""

from __future__ import annotations

import numpy as np
from attrs import define
from floris.core.rotor_velocity import average_velocity
from floris.core.turbine.operation_models import (
    POWER_SETPOINT_DEFAULT,
    POWER_SETPOINT_DISABLED,
    BaseOperationModel,
)
from floris.type_dec import NDArrayFloat

from floris_ekman_veer._validation import number
from floris_ekman_veer.plugin.rotor.crossflow import VEER_AWARE_KEY, ambient_crossflow

OPERATION_MODEL_NAME = "actuator-disk"

#: Default wind-speed samples of the descriptive power/thrust arrays [m/s].
DEFAULT_WIND_SPEEDS = np.arange(0.0, 31.0, 1.0)

# The descriptive arrays are compared with the analytic model at this relative tolerance: loose
# enough for tables written to YAML with ~8 significant digits, tight enough to catch a table
# left behind after ct_prime, rotor_diameter or ref_air_density were edited.
_TABLE_RTOL = 1e-6


def induction_factor(ct_prime, yaw_angles=0.0):
    """Disk-normal induction a(beta) = C_T' cos^2 beta / (4 + C_T' cos^2 beta) (yaw in degrees).

    Equals the paper's Eq. (ind_factor) evaluated with C_T = :func:`disk_thrust_coefficient`.
    """
    return _induction(ct_prime, np.cos(np.radians(yaw_angles)) ** 2)


def _induction(ct_prime, c2):
    # a from the squared effective cosine (cos^2 beta, or gamma^2 with veer).
    return ct_prime * c2 / (4.0 + ct_prime * c2)


def disk_thrust_coefficient(ct_prime, yaw_angles=0.0):
    """The paper's C_T (un-yawed basis) of a fixed-C_T' disk: 16 C_T' / (4 + C_T' cos^2 beta)^2.

    At beta = 0 this is 4a(1 - a) with a = C_T'/(4 + C_T'); C_T cos^2 beta is the disk-normal
    force over 1/2 rho A U^2.
    """
    c2 = np.cos(np.radians(yaw_angles)) ** 2
    return 16.0 * ct_prime / (4.0 + ct_prime * c2) ** 2


#: Valid local thrust coefficients: 0 < C_T' <= 4. One-dimensional momentum theory, on which the
#: disk's a(beta) and C_T(beta) rest, holds for a <= 1/2 (far-wake speed (1 - 2a) U >= 0);
#: a = C_T'/(4 + C_T') reaches 1/2 at C_T' = 4. Beyond it C_T = 4a(1 - a) falls again (C_T' = 40:
#: a = 0.91, C_T = 0.33), so the wake model, which inverts C_T to the lower branch a < 1/2
#: (Eq. ind_factor), would see a lightly loaded rotor while the power uses a = 0.91.
MAX_CT_PRIME = 4.0


def _ct_prime(value, name):
    return number(value, name, f"in (0, {MAX_CT_PRIME:g}] (momentum theory: a <= 1/2)",
                  lambda v: 0.0 < v <= MAX_CT_PRIME)


def _positive(value, name):
    return number(value, name, "finite and > 0", lambda v: np.isfinite(v) and v > 0.0)


def actuator_disk_power_thrust_table(
    ct_prime: float,
    rotor_diameter: float,
    ref_air_density: float = 1.225,
    wind_speed=DEFAULT_WIND_SPEEDS,
    veer_aware_rotor: bool = True,
) -> dict:
    """A FLORIS power_thrust_table for the disk, with arrays consistent with Eq. (P0_ref).

    power [kW] = 1/2 rho_ref (pi D^2/4) C_T' ((1 - a) U)^3 / 1000 and thrust_coefficient = 4a(1 - a)
    at each wind speed U (the un-yawed disk in uniform inflow).
    """
    ct_prime = _ct_prime(ct_prime, "ct_prime")
    rotor_diameter = _positive(rotor_diameter, "rotor_diameter")
    ref_air_density = _positive(ref_air_density, "ref_air_density")
    ws = np.asarray(wind_speed, dtype=float)
    return {
        "ct_prime": ct_prime,
        "rotor_diameter": rotor_diameter,
        "ref_air_density": ref_air_density,
        "ref_tilt": 0.0,
        "wind_speed": ws.tolist(),
        "power": _tabulated_power_kw(ct_prime, rotor_diameter, ref_air_density, ws).tolist(),
        "thrust_coefficient": np.full(ws.shape, disk_thrust_coefficient(ct_prime)).tolist(),
        VEER_AWARE_KEY: bool(veer_aware_rotor),
    }


def actuator_disk_turbine(
    ct_prime: float = 1.33,
    rotor_diameter: float = 100.0,
    hub_height: float = 100.0,
    ref_air_density: float = 1.225,
    turbine_type: str = "actuator_disk_les",
    wind_speed=DEFAULT_WIND_SPEEDS,
    veer_aware_rotor: bool = True,
) -> dict:
    """A complete FLORIS turbine definition (dict) for the disk; defaults are the paper's LES."""
    hub_height = _positive(hub_height, "hub_height")
    return {
        "turbine_type": turbine_type,
        "rotor_diameter": float(rotor_diameter),
        "hub_height": hub_height,
        # FLORIS requires a TSR; the disk has no rotor, and no wake model in use reads it.
        "TSR": 8.0,
        "operation_model": OPERATION_MODEL_NAME,
        "power_thrust_table": actuator_disk_power_thrust_table(
            ct_prime, rotor_diameter, ref_air_density, wind_speed, veer_aware_rotor
        ),
    }


def _tabulated_power_kw(ct_prime, rotor_diameter, air_density, wind_speed):
    area = np.pi * rotor_diameter**2 / 4.0
    u_d = (1.0 - induction_factor(ct_prime)) * np.asarray(wind_speed, dtype=float)
    return 0.5 * air_density * area * ct_prime * u_d**3 / 1e3


def disk_parameters(
    power_thrust_table: dict, path: str = "actuator-disk power_thrust_table"
) -> tuple[float, float]:
    """Validate the table; return (ct_prime, rotor_diameter). ``path`` names the table in the
    input (the Core's build check passes ``farm.turbine_type[i].power_thrust_table``)."""
    for key in ("ct_prime", "rotor_diameter", "ref_air_density"):
        if key not in power_thrust_table:
            raise ValueError(
                f"{path} needs '{key}' (build the table with "
                "floris_ekman_veer.plugin.rotor.turbine.actuator_disk_power_thrust_table)"
            )
    ct_prime = _ct_prime(power_thrust_table["ct_prime"], f"{path}.ct_prime")
    diameter = _positive(power_thrust_table["rotor_diameter"], f"{path}.rotor_diameter")
    rho_ref = _positive(power_thrust_table["ref_air_density"], f"{path}.ref_air_density")
    tilt = power_thrust_table.get("ref_tilt", 0.0)
    number(tilt, f"{path}.ref_tilt", "0 (the disk has no tilt)", lambda v: v == 0.0)

    ws = np.asarray(power_thrust_table["wind_speed"], dtype=float)
    power = np.asarray(power_thrust_table["power"], dtype=float)
    ct = np.asarray(power_thrust_table["thrust_coefficient"], dtype=float)
    expected_power = _tabulated_power_kw(ct_prime, diameter, rho_ref, ws)
    if (
        power.shape != ws.shape
        or ct.shape != ws.shape
        or not np.allclose(power, expected_power, rtol=_TABLE_RTOL, atol=1e-9)
        or not np.allclose(ct, disk_thrust_coefficient(ct_prime), rtol=_TABLE_RTOL, atol=0.0)
    ):
        raise ValueError(
            f"{path}: the power/thrust_coefficient arrays do not match "
            f"ct_prime={ct_prime}, rotor_diameter={diameter}, ref_air_density={rho_ref}; "
            "regenerate them with actuator_disk_power_thrust_table()"
        )
    return ct_prime, diameter


def _disk_average(velocities, average_method, cubature_weights):
    # Eq. (Ud) averages u itself over the disk; keep FLORIS's cubature weights when the grid has
    # them, but never its cubic averages.
    method = "simple-cubature" if "cubature" in str(average_method) else "simple-mean"
    return average_velocity(velocities, method=method, cubature_weights=cubature_weights)


def _cos_yaw(yaw_angles):
    # Past 90 deg the disk would face away from the wind; treat it as edge-on (no thrust, no
    # power) instead of producing negative thrust and power.
    return np.clip(np.cos(np.radians(yaw_angles)), 0.0, None)


def _normal_cosine(power_thrust_table, velocities, yaw_angles, u_disk, average_method,
                   cubature_weights):
    """gamma = <u_n> / <U> = cos beta + sin beta <V> / <U>, the disk's effective cosine.

    Exactly cos beta without an ambient crossflow V (plain FLORIS, or no atmosphere), exactly 1
    at beta = 0 (module docstring, docs/yaw_steering.md)."""
    cos_yaw = _cos_yaw(yaw_angles)
    crossflow = ambient_crossflow(power_thrust_table, velocities)
    if crossflow is None:
        return cos_yaw
    v_disk = _disk_average(np.broadcast_to(crossflow["V"], np.shape(velocities)),
                           average_method, cubature_weights)
    flowing = u_disk > 0.0
    ratio = np.where(flowing, v_disk / np.where(flowing, u_disk, 1.0), 0.0)
    return np.clip(cos_yaw + np.sin(np.radians(yaw_angles)) * ratio, 0.0, None)


def _disabled(power_setpoints, shape):
    """Turbines FLORIS's ``disable_turbines`` switched off; ValueError for any other power
    set-point (a fixed-C_T' disk has no controller to derate)."""
    if power_setpoints is None:
        return np.zeros(shape, dtype=bool)
    setpoints = np.broadcast_to(np.asarray(power_setpoints, dtype=float), shape)
    disabled = setpoints <= POWER_SETPOINT_DISABLED
    derated = ~disabled & (setpoints < POWER_SETPOINT_DEFAULT)
    if np.any(derated):
        index = tuple(int(i) for i in np.argwhere(derated)[0])
        raise ValueError(
            f"power_setpoints: the actuator-disk turbine (fixed C_T', no controller) cannot be "
            f"derated; got {setpoints[index]:g} W at (condition, turbine) {index}. Valid: the "
            f"default {POWER_SETPOINT_DEFAULT:g} W (not derated) or disable_turbines (set-point "
            f"{POWER_SETPOINT_DISABLED:g} W: no power, no thrust)"
        )
    return disabled


@define
class ActuatorDiskTurbine(BaseOperationModel):
    """FLORIS operation model of an actuator disk with fixed local thrust coefficient C_T'.

    Static methods with FLORIS's operation-model signatures; see the module docstring for the
    momentum theory, the yaw convention, the veer-aware rotor and the power_thrust_table keys.
    """

    @staticmethod
    def power(
        power_thrust_table: dict,
        velocities: NDArrayFloat,
        air_density: float,
        yaw_angles: NDArrayFloat,
        average_method: str = "cubic-mean",
        cubature_weights: NDArrayFloat | None = None,
        power_setpoints: NDArrayFloat | None = None,
        **_,
    ) -> NDArrayFloat:
        """P = 1/2 rho A C_T' [(1 - a) <u_n>]^3 in W, <u_n> = <U> gamma (Eqs. P0_ref, P_hyp, Ud)."""
        ct_prime, diameter = disk_parameters(power_thrust_table)
        u_disk = _disk_average(velocities, average_method, cubature_weights)
        # A disk-averaged speed below zero only arises from over-subtracted wake deficits; such a
        # disk extracts nothing rather than producing negative power.
        u_disk = np.clip(u_disk, 0.0, None)
        gamma = _normal_cosine(power_thrust_table, velocities, yaw_angles, u_disk,
                               average_method, cubature_weights)
        u_normal = (1.0 - _induction(ct_prime, gamma**2)) * u_disk * gamma
        area = np.pi * diameter**2 / 4.0
        power = 0.5 * air_density * area * ct_prime * u_normal**3
        return np.where(_disabled(power_setpoints, np.shape(power)), 0.0, power)

    @staticmethod
    def thrust_coefficient(
        power_thrust_table: dict,
        velocities: NDArrayFloat,
        yaw_angles: NDArrayFloat,
        average_method: str = "cubic-mean",
        cubature_weights: NDArrayFloat | None = None,
        power_setpoints: NDArrayFloat | None = None,
        **_,
    ) -> NDArrayFloat:
        """ct_i = C_T(gamma) gamma^2 / cos beta (= C_T(beta) cos beta without veer), so that
        ct_i / cos beta is the C_T whose rotor-normal part C_T cos^2 beta is the disk's normal
        force coefficient 4a(1 - a).

        Independent of the wind speed without veer: the disk's C_T' is constant.
        """
        ct_prime, _diameter = disk_parameters(power_thrust_table)
        gamma = _normal_cosine(
            power_thrust_table, velocities, yaw_angles,
            np.clip(_disk_average(velocities, average_method, cubature_weights), 0.0, None),
            average_method, cubature_weights,
        )
        cos_yaw = _cos_yaw(yaw_angles)
        edge_on = cos_yaw <= 0.0
        ct = (16.0 * ct_prime / (4.0 + ct_prime * gamma**2) ** 2) * gamma * np.where(
            edge_on, 0.0, gamma / np.where(edge_on, 1.0, cos_yaw))
        ct = ct * np.ones(np.shape(velocities)[:2])  # (n_findex, n_turbines)
        return np.where(_disabled(power_setpoints, np.shape(ct)), 0.0, ct)

    @staticmethod
    def axial_induction(
        power_thrust_table: dict,
        velocities: NDArrayFloat,
        yaw_angles: NDArrayFloat,
        average_method: str = "cubic-mean",
        cubature_weights: NDArrayFloat | None = None,
        power_setpoints: NDArrayFloat | None = None,
        **_,
    ) -> NDArrayFloat:
        """a = C_T' gamma^2 / (4 + C_T' gamma^2), the paper's Eq. (ind_factor) (gamma = cos beta
        without veer)."""
        ct_prime, _diameter = disk_parameters(power_thrust_table)
        gamma = _normal_cosine(
            power_thrust_table, velocities, yaw_angles,
            np.clip(_disk_average(velocities, average_method, cubature_weights), 0.0, None),
            average_method, cubature_weights,
        )
        a = _induction(ct_prime, gamma**2) * np.ones(np.shape(velocities)[:2])
        return np.where(_disabled(power_setpoints, np.shape(a)), 0.0, a)
