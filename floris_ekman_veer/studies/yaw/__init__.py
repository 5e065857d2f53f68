"""Yaw optimisation: the study's driver (optimization: `optimize_yaw`) and the both-signs search
(yaw_search).

May import: the base, the physics, the plugin, FLORIS and the other studies; never the registry
or the package's top (docs/architecture.md)."""
