"""Physical constants of the atmosphere model (paper Section 2.5 and the published forms beyond
it, docs/atmosphere.md): gravity, the Earth's rotation, the paper's free atmosphere, the
Businger-Dyer and entrainment constants, and the heat capacity of dry air."""

from __future__ import annotations

import numpy as np

#: Gravitational acceleration [m/s^2] (paper Section 2.5).
GRAVITY = 9.81
#: Earth's rotation rate Omega [1/s] (paper Section 2.5).
EARTH_ROTATION_RATE = 7.27e-5

#: Paper's free-atmosphere Brunt-Vaisala frequency N_inf [1/s] (Table 1 caption).
PAPER_BRUNT_VAISALA_FREQUENCY = 6.1e-3
#: Paper's reference potential temperature Theta_0 [K] (Table 1 caption).
PAPER_POTENTIAL_TEMPERATURE = 265.0

#: Businger-Dyer unstable surface layer phi_m = (1 - gamma z/L)^(-1/4): gamma = 16 (Dyer 1974;
#: Businger et al. 1971's form), or 19.3 (Hogstrom 1988) through ``businger_dyer_gamma``
#: (docs/atmosphere.md#convective-boundary-layer).
BUSINGER_DYER_GAMMA = 16.0
HOGSTROM_GAMMA = 19.3
#: Entrainment heat flux at z_i as a fraction of the surface flux, -A_e Q0 (Tennekes 1973):
#: a mixed layer of depth z_i warms at (1 + A_e) Q0 / z_i.
ENTRAINMENT_RATIO = 0.2
#: Specific heat of dry air c_p [J/(kg K)], gas constant R_d [J/(kg K)] and the reference
#: pressure [Pa] of the potential temperature: rho c_p = c_p p0 / (R_d Theta0) turns a sensible
#: heat flux H [W/m^2] into the kinematic flux Q0 = H/(rho c_p) [K m/s].
SPECIFIC_HEAT_AIR = 1005.0
GAS_CONSTANT_DRY_AIR = 287.05
REFERENCE_PRESSURE = 1.0e5


def air_heat_capacity(reference_potential_temperature):
    """rho c_p [J/(m^3 K)] of dry air at the potential temperature's reference pressure:
    c_p p0/(R_d Theta0) (1321 at the paper's 265 K, 1216 at 288 K)."""
    return SPECIFIC_HEAT_AIR * REFERENCE_PRESSURE / (
        GAS_CONSTANT_DRY_AIR * np.asarray(reference_potential_temperature, dtype=float)
    )
