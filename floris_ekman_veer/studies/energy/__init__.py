"""Annual energy: the study's driver (energy: `annual_energy`, `record_energy`,
`energy_by_period`), the stability distribution checked against the wind data
(stability_classes), one chunk of conditions run as one FLORIS model (condition_chunks), the
results (energy_results), and the chunks as Dask tasks (distributed: ParFlorisModel on a
cluster).

May import: the base, the physics, the plugin, FLORIS and the other studies; never the registry
or the package's top (docs/architecture.md)."""
