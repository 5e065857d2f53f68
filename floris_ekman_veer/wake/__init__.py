"""Physics of one wake: pure numpy functions of the paper's Section 2 (no FLORIS import)."""
