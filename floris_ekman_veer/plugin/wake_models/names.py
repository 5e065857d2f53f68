"""Names under which the package's wake models appear in ``floris.core.wake.MODEL_MAP`` (and so
in a FLORIS input's ``model_strings`` and parameter blocks). Not cc, turbopark or
empirical_gauss: those names select their own solvers (docs/coupling.md#registry).

A leaf module: the registry, the models (whose input paths carry the names) and the input checks
all read them without importing one another.
"""

VELOCITY_MODEL_NAME = "ekman_veer"
DEFLECTION_MODEL_NAME = "ekman_veer"
GAUSSIAN_2014_NAME = "bastankhah2014"
#: Where a FLORIS input gives the atmosphere.
ATMOSPHERE_PATH = f"wake.wake_velocity_parameters.{VELOCITY_MODEL_NAME}.atmosphere"
