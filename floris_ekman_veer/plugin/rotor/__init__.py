"""The rotor: the rotor cells and the inflow's cell means (rotor_cells), one wake over the cells it
reaches (rotor), the wakes superposed at the cells (rotor_wakes), and the operation models: the
actuator disk (turbine) and the veer-aware yawed rotor (yawed_rotor, crossflow).

May import: the base, the physics, FLORIS and the plugin's other sub-packages; never the studies,
the registry or the package's top (docs/architecture.md)."""
