"""The wake models registered in FLORIS's tables: the velocity models (models), the deflection
model (deflection_model), their parameter blocks and thrust coefficient (wake_inputs), a FLORIS
input's wake block completed and checked (wake_settings), the checks of a Core's layout,
conditions, turbines and operation (input_checks), and the names they are registered under
(names).

May import: the base, the physics, FLORIS and the plugin's other sub-packages; never the studies,
the registry or the package's top (docs/architecture.md)."""
