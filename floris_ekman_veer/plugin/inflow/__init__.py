"""The inflow FLORIS takes from the package: the input's ``atmosphere`` block read and grouped
(atmosphere_block), the ABL of each condition solved once (solve_cache), its U, V and dU/dz on
FLORIS's grids (inflow_profile), FLORIS's flow-field initialisation (inflow), the checks and the
atmosphere of each solve around a Core (core_build, core_solve), the solved atmosphere at a wake
model's grid (ambient) and the shallow-boundary-layer policy (shallow).

May import: the base, the physics (atmosphere/, wake/), FLORIS, and the plugin's other
sub-packages; never the studies, the registry or the package's top (docs/architecture.md)."""
