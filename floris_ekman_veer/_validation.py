"""Input checks shared by the physics modules: a clear ValueError naming the parameter, its
valid range and the offending values, never NaN and never a silent clip."""

from __future__ import annotations

import numpy as np


def require(ok, name: str, valid: str, value) -> None:
    """Raise ValueError("<name> must be <valid>; got <offending values>") unless ``ok`` holds
    everywhere. The message is built only on failure (formatting large arrays is costly)."""
    ok = np.asarray(ok)
    if not np.all(ok):
        offending = np.broadcast_to(np.asarray(value, dtype=float), ok.shape)[~ok].ravel()
        shown = ", ".join(f"{v:.6g}" for v in offending[:5])
        more = f" (and {offending.size - 5} more)" if offending.size > 5 else ""
        raise ValueError(f"{name} must be {valid}; got {shown}{more}")


def finite(name: str, value) -> np.ndarray:
    """``value`` as a float array, required finite."""
    array = np.asarray(value, dtype=float)
    require(np.isfinite(array), name, "finite", array)
    return array


def positive(value, name: str) -> np.ndarray:
    """``value`` as a float array, required finite and > 0."""
    array = np.asarray(value, dtype=float)
    require(np.isfinite(array) & (array > 0.0), name, "finite and > 0", array)
    return array
