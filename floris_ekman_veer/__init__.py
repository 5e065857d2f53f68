"""floris-ekman-veer: the veer-corrected curled-wake model of Narasimhan, Gayme & Meneveau
(JRSE 2025) and its coupled Ekman-surface-layer inflow, for FLORIS v4.

Importing the package registers, in FLORIS's model tables, the velocity and deflection models
``ekman_veer`` (the paper's M-1; M-2 with veer off), the velocity model ``bastankhah2014`` (M-3),
the turbine operation model ``actuator-disk``, and installs the Ekman inflow hook, a no-op for
FLORIS inputs without ``wake.wake_velocity_parameters.ekman_veer.atmosphere``.

``floris_ekman_veer.ParFlorisModel`` is FLORIS's ParFlorisModel plus ``interface="dask"``
(conditions chunked over a dask.distributed cluster; optional extra ``dask``).
``floris_ekman_veer.optimize_yaw(fmodel, optimizer_class, **options)`` runs FLORIS's yaw
optimisers on scalar and per-condition atmospheres alike and returns FLORIS's ``df_opt``.
``floris_ekman_veer.annual_energy(fmodel, wind_data, stability, optimizer_class, ...)`` gives the
AEP per stability class, baseline and with wake steering, for ekman_veer and FLORIS's GCH.
``floris_ekman_veer.example_input("farm_sbl6")`` is the path of one of the package's FLORIS
inputs, installed with it. Every warning class of the package is importable from here, and
``floris_ekman_veer.silence_warnings()`` silences them in this process and its workers
(docs/user_guide.md#warnings).
``floris_ekman_veer.validity_report(fmodel)`` says per condition whether the atmosphere lies inside
the paper's validated envelope (docs/yaw_steering.md#the-validated-envelope).
"""

from floris_ekman_veer._version import __version__
from floris_ekman_veer.atmosphere.ekman import EkmanABL
from floris_ekman_veer.example_inputs import example_input, example_inputs
from floris_ekman_veer.registry import register
from floris_ekman_veer.studies.energy.distributed import ParFlorisModel
from floris_ekman_veer.studies.energy.energy import annual_energy
from floris_ekman_veer.studies.yaw.optimization import optimize_yaw
from floris_ekman_veer.studies.site.pipeline import fit_site
from floris_ekman_veer.studies.validity import validity_report
from floris_ekman_veer.warnings import (
    DirectionUnitsWarning,
    FlorisEkmanVeerWarning,
    HeterogeneousInflowWarning,
    ModelSettingsWarning,
    ReferenceWindWarning,
    ShallowBoundaryLayerWarning,
    ThrustLimitWarning,
    TurbinePlacementWarning,
    silence_warnings,
)

__all__ = ["DirectionUnitsWarning", "EkmanABL", "FlorisEkmanVeerWarning",
           "HeterogeneousInflowWarning", "ModelSettingsWarning", "ParFlorisModel",
           "ReferenceWindWarning", "ShallowBoundaryLayerWarning",
           "ThrustLimitWarning", "TurbinePlacementWarning", "__version__", "annual_energy",
           "example_input", "example_inputs", "fit_site", "optimize_yaw", "register", "silence_warnings",
           "validity_report"]

register()
