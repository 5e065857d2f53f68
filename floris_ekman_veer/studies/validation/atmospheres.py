"""From a validation case to the atmosphere every model runs on (docs/validation.md#the-atmosphere-of-a-case).

Two readings, both neutral (the references are near-neutral) with the paper's free atmosphere
(N_inf = 6.1e-3 1/s, Theta0 = 265 K) at the site's latitude, driven by the case's hub-height
wind speed:

``site``
    The paper's pure ABL with the site's roughness (open sea 2e-4 m, farmland 0.03 m): I_u(z_h)
    is what Eq. (Iu_model) gives, whatever was measured.
``matched``
    The decision this study makes to bring the measured turbulence in: the roughness length z0 of
    the neutral Ekman-surface-layer ABL whose I_u(z_h) (Eq. Iu_model) equals the case's measured
    streamwise turbulence intensity (TI_total / 0.8 for the single wakes). z0 is an effective
    parameter here, not the terrain's: it stands for everything that made the measured
    turbulence (upwind terrain, unresolved stability). The paper's constants (A1, B1, alpha',
    the k_w floor) are left as they are; k_w then follows from the matched I_u through
    Eq. (kw_CNBL_SBL_model).

``site_measured_turbulence`` (an option, not among :data:`ATMOSPHERES`)
    What the product does at a site with measured turbulence (``fit_site``): the site's
    roughness for the ABL's shear and veer, and the atmosphere block's ``turbulence_factor`` =
    measured I_u(z_h) / the site ABL's I_u(z_h), so that the wake's ambient I_u(z_h), hence k_w
    (Eq. kw_CNBL_SBL_model), is the measured one (docs/atmosphere.md#ambient-turbulence).
    Beyond the paper's validation (``validity_report`` flags the factor). It was not made the
    "site" reading: FLORIS's gauss, GCH and cc and M-3 do worse with the measured TI at
    Wieringermeer-East and Nibe (docs/validation.md#the-atmosphere-of-a-case).
``given``
    A case's own ``atmosphere`` block (e.g. a stable one), as a user's FLORIS input has it.

FLORIS's own models run on the same inflow (the atmosphere's U(z)) with FLORIS's ambient
turbulence intensity = I_u(z_h) of the same atmosphere, so every model sees one turbulence level.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from floris_ekman_veer._validation import number
from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.studies.site.atmospheres import turbulence_factors
from floris_ekman_veer.wake.deficit import potential_core_length

#: The two atmospheres of a case from its measured TI (see the module docstring).
ATMOSPHERES = ("site", "matched")
#: ...and the reading of a case's own atmosphere block.
GIVEN = "given"
#: The site's roughness with the measured hub turbulence in the wake, as ``fit_site`` does.
SITE_MEASURED_TURBULENCE = "site_measured_turbulence"
#: Search range of the matched roughness length [m].
ROUGHNESS_RANGE = (1.0e-6, 5.0)
#: Roughness lengths of the "site" atmospheres [m]: open sea and open farmland.
SEA_ROUGHNESS = 2.0e-4
LAND_ROUGHNESS = 0.03
#: Total over streamwise turbulence intensity, sqrt((s_u^2 + s_v^2 + s_w^2)/3) / s_u, with the
#: neutral surface layer's s_u : s_v : s_w = 2.39 : 1.92 : 1.25 (Panofsky & Dutton 1984): 0.80,
#: the reading PyWake's validation gives its single-wake cases' TI
#: (docs/validation.md#turbulence-intensity).
TOTAL_OVER_STREAMWISE = 0.8


def streamwise_turbulence(total_turbulence: float) -> float:
    """The hub-height streamwise I_u of a published total turbulence intensity (of the
    turbulent kinetic energy, sqrt(2k/3)/U): I_u = TI_total / :data:`TOTAL_OVER_STREAMWISE`
    (docs/validation.md#turbulence-intensity). A cup anemometer's TI (of the horizontal speed)
    is already I_u to within a few per cent and needs no conversion."""
    total = number(total_turbulence, "streamwise_turbulence: total_turbulence", "in (0, 0.8)",
                   lambda ti: 0.0 < ti < TOTAL_OVER_STREAMWISE)
    return total / TOTAL_OVER_STREAMWISE


def site_roughness_length(offshore: bool) -> float:
    """z0 [m] of the "site" reading: open sea offshore, open farmland onshore."""
    return SEA_ROUGHNESS if offshore else LAND_ROUGHNESS


def _abl(case, roughness_length) -> EkmanABL:
    # The neutral ABL with ``roughness_length`` [m] at the case's latitude, or an atmosphere
    # block (dict), at the case's hub-height speed.
    inputs = (roughness_length if isinstance(roughness_length, dict)
              else {"latitude": case.latitude, "roughness_length": roughness_length})
    return EkmanABL.from_reference_wind(case.wind_speed, case.hub_height, **inputs)


def site_turbulence_factor(case) -> float:
    """The atmosphere block's ``turbulence_factor`` a user with the site's data gets
    (docs/atmosphere.md#ambient-turbulence): the case's measured I_u(z_h) over the site ABL's
    I_u(z_h) (Eq. Iu_model), by the site pipeline's own ``turbulence_factors`` (1 where the
    ratio leaves the factor's range). The ABL's shear and veer stay the site roughness's."""
    abl = _abl(case, case.site_roughness)
    (factor,) = turbulence_factors(abl, (case.hub_height, [case.streamwise_turbulence]), [0])
    return float(factor)


def hub_turbulence(case, roughness_length) -> float:
    """I_u(z_h) (Eq. Iu_model) of the case's atmosphere at its hub-height speed and latitude:
    the neutral ABL with ``roughness_length`` [m], or an ``atmosphere`` block (dict)."""
    abl = _abl(case, roughness_length)
    return float(abl.turbulence_intensity(case.hub_height, reference_height=case.hub_height))


def wake_scales(case, roughness_length, thrust_coefficient: float) -> tuple[float, float]:
    """(k_w, x0/D) of an unwaked turbine of the case: Eqs. (kw_CNBL_SBL_model), (x0_transition)
    with the paper's constants, in the neutral ABL with ``roughness_length`` [m] or an
    ``atmosphere`` block (dict); arcs closer than x0 lie in the potential core."""
    k_w = float(_abl(case, roughness_length).wake_expansion_rate(case.hub_height))
    radius = 0.5 * case.rotor_diameter
    return k_w, float(potential_core_length(k_w, radius, thrust_coefficient, 0.0)) / case.rotor_diameter


def matched_turbulence_range(case) -> tuple[float, float]:
    """The I_u(z_h) the "matched" reading can reach: those of :data:`ROUGHNESS_RANGE`'s ends
    (I_u grows monotonically with z0)."""
    low, high = (hub_turbulence(case, z) for z in ROUGHNESS_RANGE)
    return low, high


def matched_roughness(case) -> float:
    """z0 [m] of the neutral ABL whose I_u(z_h) is the case's measured streamwise TI.

    ValueError if no z0 in :data:`ROUGHNESS_RANGE` reaches it (I_u grows monotonically with z0).
    """
    target = case.streamwise_turbulence
    low, high = (np.log(z) for z in ROUGHNESS_RANGE)

    def mismatch(log_z0):
        return hub_turbulence(case, float(np.exp(log_z0))) - target

    if mismatch(low) > 0 or mismatch(high) < 0:
        raise ValueError(f"{case.name}: turbulence: no neutral roughness length in "
                         f"{ROUGHNESS_RANGE} m gives I_u(z_h) = {target:.4g}")
    return float(np.exp(brentq(mismatch, low, high, xtol=1e-12, rtol=1e-12)))


def atmosphere(case, reading: str) -> dict:
    """The ``ekman_veer.atmosphere`` input block of ``case`` for ``reading`` (``site``,
    ``matched`` or, for a case with its own atmosphere, ``given``)."""
    if reading == GIVEN:
        if getattr(case, "atmosphere", None) is None:
            raise ValueError(f"{case.name}: reading {GIVEN!r} needs the case's atmosphere block")
        return dict(case.atmosphere)
    readings = ATMOSPHERES + (SITE_MEASURED_TURBULENCE, GIVEN)
    if reading not in readings:
        raise ValueError(f"reading must be one of {readings}, got {reading!r}")
    if reading != "site" and case.streamwise_turbulence is None:
        raise ValueError(f"{case.name}: reading {reading!r} needs the case's turbulence (the "
                         f"measured I_u); this case gives an atmosphere block: use reading {GIVEN!r}")
    z0 = matched_roughness(case) if reading == "matched" else case.site_roughness
    block = {"latitude": float(case.latitude), "roughness_length": float(z0)}
    if reading == SITE_MEASURED_TURBULENCE:
        block["turbulence_factor"] = site_turbulence_factor(case)
    return block
