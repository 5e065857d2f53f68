"""The inputs that set an atmosphere's stability, one definition for the whole package.

An :class:`~floris_ekman_veer.atmosphere.ekman.EkmanABL` takes at most one of them (the others
follow from it, docs/atmosphere.md); the site fit determines them and so refuses them as fixed
inputs; the FLORIS atmosphere block accepts at most one of them.
"""

#: The stability parameter mu, the cooling rate C_r [K/h], the kinematic surface heat flux Q0
#: [K m/s], the Obukhov length L [m] and the sensible heat flux H [W/m^2].
STABILITY_INPUTS = (
    "stability_parameter", "cooling_rate", "surface_heat_flux", "obukhov_length",
    "sensible_heat_flux",
)
