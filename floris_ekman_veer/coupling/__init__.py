"""Old import path: ``floris_ekman_veer.coupling.<module>`` (0.1.0) is an alias of the module in
its new place, the FLORIS plugin (``floris_ekman_veer.plugin``), the studies
(``floris_ekman_veer.studies``) or ``floris_ekman_veer.registry`` (docs/architecture.md#old-import-paths).
New code imports the new paths."""

from floris_ekman_veer._old_paths import keep_old_paths

keep_old_paths(__name__, {
    "names": "floris_ekman_veer.plugin.names",
    "models": "floris_ekman_veer.plugin.models",
    "inflow": "floris_ekman_veer.plugin.inflow",
    "rotor": "floris_ekman_veer.plugin.rotor",
    "crossflow": "floris_ekman_veer.plugin.crossflow",
    "yawed_rotor": "floris_ekman_veer.plugin.yawed_rotor",
    "turbine": "floris_ekman_veer.plugin.turbine",
    "wake_settings": "floris_ekman_veer.plugin.wake_settings",
    "input_checks": "floris_ekman_veer.plugin.input_checks",
    "shallow": "floris_ekman_veer.plugin.shallow",
    "parallel": "floris_ekman_veer.plugin.parallel",
    "registry": "floris_ekman_veer.registry",
    "optimization": "floris_ekman_veer.studies.optimization",
    "energy": "floris_ekman_veer.studies.energy",
    "site": "floris_ekman_veer.studies.site",
    "comparison": "floris_ekman_veer.studies.comparison",
    "uncertain": "floris_ekman_veer.plugin.uncertain_conditions",
    "distributed": "floris_ekman_veer.studies.distributed",
    "validity": "floris_ekman_veer.studies.validity",
    "tables": "floris_ekman_veer.studies.tables",
})
