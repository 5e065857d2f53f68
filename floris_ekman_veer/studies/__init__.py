"""The studies: what a user calls on top of FLORIS and the plugin (docs/architecture.md). Yaw
optimisation, annual energy, site records, the comparison with FLORIS's own models, the
validity envelope, uncertain and distributed runs, and the validation against measured wakes."""
