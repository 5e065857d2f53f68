"""Atmospheric boundary layer physics (no FLORIS import)."""
