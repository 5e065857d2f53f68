"""Old import path: ``floris_ekman_veer.validation`` and its modules (0.1.0) are aliases of
``floris_ekman_veer.studies.validation`` (docs/architecture.md#old-import-paths). New code imports
the new path."""

from floris_ekman_veer._old_paths import keep_old_paths

keep_old_paths(__name__, {
    "cases": "floris_ekman_veer.studies.validation.cases",
    "atmospheres": "floris_ekman_veer.studies.validation.atmospheres",
    "models": "floris_ekman_veer.studies.validation.models",
    "metrics": "floris_ekman_veer.studies.validation.metrics",
})
