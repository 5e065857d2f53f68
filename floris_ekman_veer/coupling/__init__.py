"""The only layer that imports FLORIS."""
