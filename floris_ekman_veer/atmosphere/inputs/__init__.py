"""The atmosphere's inputs: `EkmanABL`'s keyword inputs checked (abl_inputs), the valid ranges of
every input and their checks (input_ranges), and the inputs that set the stability
(stability_inputs).

May import: the base and the physics; never FLORIS, the plugin or the studies
(docs/architecture.md)."""
