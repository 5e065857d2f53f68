"""Where the package meets FLORIS's own code: the patch table, one row per FLORIS attribute the
package patches (patches), the mechanism that installs and restores them and checks FLORIS's
version (patching), and the solver of the package's velocity models (solver).

May import: the base, the physics, FLORIS and the plugin's other sub-packages; never the studies,
the registry or the package's top (docs/architecture.md)."""
