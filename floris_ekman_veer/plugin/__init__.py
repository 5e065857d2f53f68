"""The FLORIS plugin: what FLORIS calls (docs/architecture.md). The wake models and the
operation model registered in FLORIS's tables, the inflow hook that solves the atmosphere once
per condition, the rotor cells, the input checks. The only layer besides the studies that imports
FLORIS; it imports the physics and nothing of the studies."""
