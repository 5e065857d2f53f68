"""FLORIS's tools on per-condition atmospheres: ParFlorisModel workers (parallel),
UncertainFlorisModel (uncertain_conditions), and the yaw optimisers: their options
(optimizer_options), one run per atmosphere and chunk (optimizer_conditions) and their rows of
the patch table (optimizer_hooks).

May import: the base, the physics, FLORIS and the plugin's other sub-packages; never the studies,
the registry or the package's top (docs/architecture.md)."""
